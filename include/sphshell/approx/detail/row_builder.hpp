#pragma once
// What MLS and NSPH share: input checks, neighbour search, the compressed
// layout, visibility filtering and the Shepard fallback. A method only turns
// the weights of one row's visible neighbours into Φ and ∇Φ.

#include <sphshell/approx/memory_estimate.hpp>
#include <sphshell/approx/neighbour_search.hpp>
#include <sphshell/approx/shape_functions.hpp>
#include <sphshell/core/error.hpp>
#include <sphshell/core/parallel.hpp>
#include <sphshell/core/statistics.hpp>
#include <sphshell/core/frame.hpp>
#include <sphshell/core/types.hpp>
#include <sphshell/kernel/kernel.hpp>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <exception>
#include <new>
#include <sstream>
#include <string>
#include <utility>
#include <vector>


namespace sphshell::approx::detail {

using sphshell::detail::invalid_parameter;
using sphshell::detail::require_positive;

// Per-neighbour data of the row being built, kept between rows so the build
// loop does not allocate. Only the first `count` entries are meaningful.
struct RowWorkspace {
  std::vector<int> ordered;              // visible neighbours first, then hidden ones
  std::vector<double> xi1, xi2;          // tangent-plane coordinates of x_j − x
  std::vector<double> weight;            // V_j W(|x_j − x|)
  std::vector<double> dweight_d1, dweight_d2;  // its derivative w.r.t. the evaluation point along e1, e2
  std::vector<double> phi, dphi_d1, dphi_d2;   // the method's Φ_j, ∇Φ_j, before they go to the row's slots
  std::size_t count = 0;

  void reserve(std::size_t n) {
    if (ordered.size() >= n) return;
    for (auto* v : {&xi1, &xi2, &weight, &dweight_d1, &dweight_d2, &phi, &dphi_d1, &dphi_d2}) v->resize(n);
    ordered.resize(n);
  }
};

// Two points of one set closer than this (relative to h) are "coincident".
inline constexpr double coincidence_tolerance_factor = 1e-9;
// Neighbours per row reserved up front (a support of two spacings holds about 12).
inline constexpr std::size_t expected_neighbours = 16;

// Names the cause: no particle within the support at all (the support is too
// small for the spacing: the solver's SolverOptions::support_radius_factor, or
// cells far longer than wide, whose spacing √A is far below their length), or
// every candidate hidden (by cracks).
[[noreturn]] inline void throw_no_visible_neighbour(std::size_t eval_index, const Vector3& x, double support,
                                                    std::size_t candidates) {
  std::ostringstream message;
  message.precision(6);
  message << "sphshell: evaluation point " << eval_index << " at (" << x.transpose()
          << ") has no visible neighbour within the kernel support (shape functions undefined): ";
  if (candidates == 0)
    message << "no particle lies within the support radius " << support
            << " m; the support is too small for the particle spacing there: raise "
               "SolverOptions::support_radius_factor (the support radius in units of the point's local spacing √A; "
               "allowed: enough to reach 3 particles not on one line), or refine cells that are far longer than "
               "wide";
  else
    message << "all " << candidates << " particles within the support radius " << support
            << " m are hidden (cut off by cracks)";
  throw Error(message.str());
}

inline void check_frame(const TangentFrame& frame, std::size_t eval_index) {
  const double length = frame.normal.norm();
  if (!(length > 0.0) || !std::isfinite(length) || !frame.e1.allFinite() ||
      !frame.e2.allFinite() || !(frame.e1.norm() > 0.0) || !(frame.e2.norm() > 0.0)) {
    std::ostringstream name;
    name << "normal length of the frame of evaluation point " << eval_index;
    invalid_parameter(name.str(), length, "a tangent frame needs finite, non-zero axes");
  }
}

inline void check_volumes(const std::vector<double>& volumes) {
  for (std::size_t j = 0; j < volumes.size(); ++j)
    if (!(volumes[j] > 0.0) || !std::isfinite(volumes[j])) {
      std::ostringstream name;
      name << "volume of particle " << j;
      invalid_parameter(name.str(), volumes[j], "must be finite and > 0");
    }
}

inline void check_sizes(std::size_t particles, std::size_t volumes, std::size_t positions,
                        std::size_t frames) {
  if (particles != volumes) {
    std::ostringstream value;
    value << volumes << " volumes for " << particles << " particles";
    invalid_parameter("particle_volumes.size()", value.str(), "one volume per particle");
  }
  if (positions != frames) {
    std::ostringstream value;
    value << frames << " frames for " << positions << " evaluation points";
    invalid_parameter("eval_frames.size()", value.str(), "one frame per evaluation point");
  }
}

// Fills one row from the candidate neighbours already stored in its slots
// (sorted by particle index). Visible candidates are moved to the front in
// index order, hidden ones follow with Φ = ∇Φ = 0. Throws before touching the
// row when nothing is visible.
template <class Kernel, class Method, class Visible>
void compute_row(ShapeFunctions& sf, std::size_t row, const std::vector<Vector3>& particles,
                 const std::vector<double>& volumes, const Vector3& x, const TangentFrame& frame,
                 double h, Visible& visible, RowWorkspace& ws) {
  const std::size_t begin = sf.row_begin[row];
  const std::size_t capacity = sf.row_begin[row + 1] - begin;
  ws.reserve(capacity);

  // Visible candidates fill ws.ordered from the front, hidden ones from the
  // back; reversing the back part restores index order for both.
  std::size_t visible_count = 0;
  std::size_t hidden_count = 0;
  for (std::size_t s = 0; s < capacity; ++s) {
    const int j = sf.neighbour[begin + s];
    if (visible(row, static_cast<std::size_t>(j)))
      ws.ordered[visible_count++] = j;
    else
      ws.ordered[capacity - 1 - hidden_count++] = j;
  }
  if (visible_count == 0) throw_no_visible_neighbour(row, x, Kernel::support_radius_factor * h, capacity);
  const auto ordered_begin = ws.ordered.begin();
  std::reverse(ordered_begin + static_cast<std::ptrdiff_t>(visible_count),
               ordered_begin + static_cast<std::ptrdiff_t>(capacity));
  std::copy(ordered_begin, ordered_begin + static_cast<std::ptrdiff_t>(capacity),
            sf.neighbour.begin() + static_cast<std::ptrdiff_t>(begin));

  const Vector3 e1 = frame.e1.normalized();
  const Vector3 e2 = frame.e2.normalized();
  double weight_sum = 0.0;
  for (std::size_t k = 0; k < visible_count; ++k) {
    const auto j = static_cast<std::size_t>(ws.ordered[k]);
    const Vector3 d = particles[j] - x;
    const double r = d.norm();
    const double xi1 = d.dot(e1);
    const double xi2 = d.dot(e2);
    const double volume = volumes[j];
    ws.xi1[k] = xi1;
    ws.xi2[k] = xi2;
    ws.weight[k] = volume * Kernel::value(r, h);
    // d|x_j − x|/dx·e_α = −ξ_α / r; every kernel has dW/dr = 0 at r = 0.
    const double radial = r > 0.0 ? -volume * Kernel::derivative(r, h) / r : 0.0;
    ws.dweight_d1[k] = radial * xi1;
    ws.dweight_d2[k] = radial * xi2;
    weight_sum += ws.weight[k];
  }
  ws.count = visible_count;

  // A first-order fit needs three neighbours not on one line; Method reports
  // a (nearly) singular system by returning false.
  const bool linear = visible_count >= 3 && weight_sum > 0.0 &&
                      Method::solve(ws, h, ws.phi.data(), ws.dphi_d1.data(), ws.dphi_d2.data());
  ShapeValue* const value = sf.value.data() + begin;
  if (linear) {
    for (std::size_t k = 0; k < visible_count; ++k) value[k] = ShapeValue{ws.phi[k], ws.dphi_d1[k], ws.dphi_d2[k]};
  } else {
    if (!(weight_sum > 0.0)) throw_no_visible_neighbour(row, x, Kernel::support_radius_factor * h, capacity);
    for (std::size_t k = 0; k < visible_count; ++k) value[k] = ShapeValue{ws.weight[k] / weight_sum, 0.0, 0.0};
  }
  for (std::size_t k = visible_count; k < capacity; ++k) value[k] = ShapeValue{};
  sf.row_size[row] = static_cast<int>(visible_count);
  sf.shepard[row] = linear ? 0 : 1;
}

// The smoothing lengths of a build: one for every row (uniform sheets, the
// approximation tests) or one per row (the solver's local support radius,
// docs/method.md "Support radius"). Rows use the gather form W(x_j − x_i, h_i).
class RowSmoothingLengths {
 public:
  RowSmoothingLengths(double h) : uniform_(h) {}
  RowSmoothingLengths(const std::vector<double>& h) : per_row_(&h) {}
  bool per_row() const { return per_row_ != nullptr; }
  double operator[](std::size_t row) const { return per_row_ ? (*per_row_)[row] : uniform_; }

  // Each h finite and > 0, one per row; then the smallest, the median and the
  // largest are known.
  void check(std::size_t rows) {
    if (!per_row_) {
      require_positive("h", uniform_);
      smallest_ = median_ = largest_ = uniform_;
      return;
    }
    if (per_row_->size() != rows) {
      std::ostringstream value;
      value << per_row_->size() << " smoothing lengths for " << rows << " evaluation points";
      invalid_parameter("h.size()", value.str(), "one smoothing length per evaluation point");
    }
    for (std::size_t row = 0; row < rows; ++row)
      if (!((*per_row_)[row] > 0.0) || !std::isfinite((*per_row_)[row]))
        invalid_parameter("h of evaluation point " + std::to_string(row), (*per_row_)[row], "must be finite and > 0");
    if (rows == 0) return;
    median_ = sphshell::detail::median(*per_row_);
    smallest_ = *std::min_element(per_row_->begin(), per_row_->end());
    largest_ = *std::max_element(per_row_->begin(), per_row_->end());
  }
  double smallest() const { return smallest_; }
  double median() const { return median_; }

 private:
  double uniform_ = 0.0;
  const std::vector<double>* per_row_ = nullptr;
  double smallest_ = 0.0, median_ = 0.0, largest_ = 0.0;
};

// Coincident particles would act as one particle of twice the volume, and
// coincident evaluation points as one point counted twice: both are refused
// unless the visibility predicate separates them, i.e. no row sees both
// particles of a coincident pair, and coincident evaluation points see
// different particles (the two faces of a slit hidden from each other by a cut).
inline void require_coincident_points_apart(const ShapeFunctions& sf, const std::vector<Vector3>& particles,
                                            const std::vector<std::pair<int, int>>& coincident_particles,
                                            const std::vector<std::pair<int, int>>& coincident_evaluation_points) {
  if (!coincident_particles.empty()) {
    std::vector<char> paired(particles.size(), 0);
    for (const auto& [i, j] : coincident_particles) paired[i] = paired[j] = 1;
    std::vector<int> seen;
    for (std::size_t row = 0; row < sf.rows(); ++row) {
      seen.clear();
      for (std::size_t s = sf.row_begin[row]; s < sf.row_begin[row] + sf.row_size[row]; ++s)
        if (paired[sf.neighbour[s]]) seen.push_back(sf.neighbour[s]);
      for (std::size_t a = 0; a < seen.size(); ++a)
        for (std::size_t b = a + 1; b < seen.size(); ++b) {
          const std::pair<int, int> pair{std::min(seen[a], seen[b]), std::max(seen[a], seen[b])};
          if (!std::binary_search(coincident_particles.begin(), coincident_particles.end(), pair)) continue;
          std::ostringstream message;
          message << "sphshell: coincident particles " << pair.first << " and " << pair.second << " (distance "
                  << (particles[pair.first] - particles[pair.second]).norm() << " m) are both visible from evaluation point "
                  << row << ": points of one set must be distinct, or hidden from each other's evaluation points "
                     "(a cut between the two faces of a slit)";
          throw Error(message.str());
        }
    }
  }
  for (const auto& [a, b] : coincident_evaluation_points) {
    const auto first = sf.neighbour.begin() + static_cast<std::ptrdiff_t>(sf.row_begin[a]);
    const auto second = sf.neighbour.begin() + static_cast<std::ptrdiff_t>(sf.row_begin[b]);
    if (sf.row_size[a] == sf.row_size[b] && std::equal(first, first + sf.row_size[a], second)) {
      std::ostringstream message;
      message << "sphshell: coincident evaluation points " << a << " and " << b
              << " see the same particles: points of one set must be distinct, unless a cut gives them different "
                 "neighbours";
      throw Error(message.str());
    }
  }
}

template <class Kernel, class Method, class Visible>
ShapeFunctions build_all_unguarded(const std::vector<Vector3>& particles,
                                   const std::vector<double>& volumes,
                                   const std::vector<Vector3>& eval_positions,
                                   const std::vector<TangentFrame>& eval_frames, RowSmoothingLengths h,
                                   Visible& visible) {
  static_assert(kernel::check_kernel<Kernel>());
  h.check(eval_positions.size());
  check_sizes(particles.size(), volumes.size(), eval_positions.size(), eval_frames.size());
  if (h.per_row() && eval_positions.empty()) {  // no rows, and no length to search the particles with
    ShapeFunctions none;
    none.row_begin.assign(1, 0);
    return none;
  }
  check_volumes(volumes);
  for (std::size_t i = 0; i < eval_positions.size(); ++i) {
    if (!eval_positions[i].allFinite()) {
      std::ostringstream name;
      name << "coordinates of evaluation point " << i;
      invalid_parameter(name.str(), eval_positions[i].transpose(), "must be finite");
    }
    check_frame(eval_frames[i], i);
  }

  // Cells as wide as the median support: a row with a wider one searches more
  // layers of them, so one large support does not slow every row's search.
  const double cell_width = Kernel::support_radius_factor * h.median();
  const double tolerance = coincidence_tolerance_factor * h.smallest();
  const CellList particle_cells(particles, cell_width);
  // Points at one place are refused unless visibility tells them apart (a cut
  // between the two edges of a slit): checked once the rows are built.
  const std::vector<std::pair<int, int>> coincident_particles = particle_cells.coincident_pairs(tolerance);
  const std::vector<std::pair<int, int>> coincident_evaluation_points =
      CellList(eval_positions, cell_width).coincident_pairs(tolerance);

  const std::size_t rows = eval_positions.size();
  ShapeFunctions sf;
  sf.row_begin.assign(rows + 1, 0);
  sf.row_size.assign(rows, 0);
  sf.shepard.assign(rows, 0);
  const auto row_count = static_cast<std::ptrdiff_t>(rows);

  // One search per row: each block of rows gathers its (sorted) neighbour
  // lists in its own buffer, and the buffers are then copied into place.
  std::ptrdiff_t block_count = 1;
#ifdef _OPENMP
  block_count = std::max(1, omp_get_max_threads());
#endif
  const auto block_first_row = [&](std::ptrdiff_t block) {
    return static_cast<std::size_t>(block) * rows / static_cast<std::size_t>(block_count);
  };
  std::vector<std::vector<int>> gathered(static_cast<std::size_t>(block_count));
  // An allocation failure in a block is rethrown after the loop (the lowest
  // block's), never inside the OpenMP region.
  parallel::for_each(std::ptrdiff_t{0}, block_count, [&](std::ptrdiff_t block) {
    std::vector<int>& list = gathered[static_cast<std::size_t>(block)];
    const std::size_t last = block_first_row(block + 1);
    list.reserve((last - block_first_row(block)) * expected_neighbours);
    for (std::size_t row = block_first_row(block); row < last; ++row) {
      const std::size_t first = list.size();
      particle_cells.for_each_within(eval_positions[row], Kernel::support_radius_factor * h[row],
                                     [&list](int j, double) { list.push_back(j); });
      std::sort(list.begin() + static_cast<std::ptrdiff_t>(first), list.end());
      sf.row_begin[row + 1] = list.size() - first;
    }
  });
  for (std::size_t r = 0; r < rows; ++r) sf.row_begin[r + 1] += sf.row_begin[r];
  const std::size_t slots = sf.row_begin[rows];
  sf.neighbour.resize(slots);
  sf.value.resize(slots);
  parallel::for_each(std::ptrdiff_t{0}, block_count, [&](std::ptrdiff_t block) noexcept {
    std::vector<int>& list = gathered[static_cast<std::size_t>(block)];
    std::copy(list.begin(), list.end(),
              sf.neighbour.begin() + static_cast<std::ptrdiff_t>(sf.row_begin[block_first_row(block)]));
    std::vector<int>().swap(list);
  });

  // Exceptions may not leave an OpenMP region; the one of the lowest row is
  // kept so the message does not depend on the thread count.
  std::exception_ptr error;
  std::ptrdiff_t error_row = row_count;
  SPHSHELL_OMP("omp parallel")
  {
    RowWorkspace ws;
    SPHSHELL_OMP("omp for schedule(static)")
    for (std::ptrdiff_t i = 0; i < row_count; ++i) {
      const auto row = static_cast<std::size_t>(i);
      try {
        compute_row<Kernel, Method>(sf, row, particles, volumes, eval_positions[row],
                                    eval_frames[row], h[row], visible, ws);
      } catch (...) {
        SPHSHELL_OMP("omp critical(sphshell_approx_error)")
        if (i < error_row) {
          error_row = i;
          error = std::current_exception();
        }
      }
    }
  }
  if (error) std::rethrow_exception(error);
  require_coincident_points_apart(sf, particles, coincident_particles, coincident_evaluation_points);
  return sf;
}

// The build, with an allocation failure turned into an Error that names the
// size asked for (rows, the slots expected from the particle density) and the
// memory the machine offers.
template <class Kernel, class Method, class Visible>
ShapeFunctions build_all(const std::vector<Vector3>& particles, const std::vector<double>& volumes,
                         const std::vector<Vector3>& eval_positions, const std::vector<TangentFrame>& eval_frames,
                         RowSmoothingLengths h, Visible& visible) {
  try {
    return build_all_unguarded<Kernel, Method>(particles, volumes, eval_positions, eval_frames, h, visible);
  } catch (const std::bad_alloc&) {
    double covered = 0.0;
    for (double volume : volumes) covered += volume;
    double slots = 0.0;
    for (std::size_t row = 0; row < eval_positions.size(); ++row)
      slots += expected_row_size(particles.size(), covered, Kernel::support_radius_factor * h[row]);
    std::ostringstream message;
    message << "sphshell: out of memory building the shape functions of " << eval_positions.size()
            << " evaluation points over " << particles.size() << " particles (std::bad_alloc): about " << slots
            << " neighbour slots, " << format_bytes(slots * bytes_per_slot) << " with the solver's per-slot data; "
            << format_bytes(available_memory()) << " available";
    throw Error(message.str());
  }
}

template <class Kernel, class Method, class Visible>
void rebuild_one_row(ShapeFunctions& sf, std::size_t row, const std::vector<Vector3>& particles,
                     const std::vector<double>& volumes, const Vector3& eval_position,
                     const TangentFrame& eval_frame, double h, Visible& visible) {
  static_assert(kernel::check_kernel<Kernel>());
  require_positive("h", h);
  if (row >= sf.rows()) invalid_parameter("row", row, "must be < rows()");
  if (particles.size() != volumes.size()) check_sizes(particles.size(), volumes.size(), 0, 0);
  if (!eval_position.allFinite())
    invalid_parameter("coordinates of the rebuilt evaluation point", eval_position.transpose(),
                      "must be finite");
  check_frame(eval_frame, row);
  const std::size_t begin = sf.row_begin[row];
  const std::size_t end = sf.row_begin[row + 1];
  for (std::size_t s = begin; s < end; ++s) {
    const auto j = static_cast<std::size_t>(sf.neighbour[s]);
    if (j >= particles.size()) invalid_parameter("neighbour index", j, "must be < particles.size()");
    if (!(volumes[j] > 0.0) || !std::isfinite(volumes[j])) check_volumes(volumes);
  }
  // Slots hold the row's whole geometric neighbour set; restoring index order
  // makes the result identical to a full build with the same predicate.
  std::sort(sf.neighbour.begin() + static_cast<std::ptrdiff_t>(begin),
            sf.neighbour.begin() + static_cast<std::ptrdiff_t>(end));
  RowWorkspace ws;
  compute_row<Kernel, Method>(sf, row, particles, volumes, eval_position, eval_frame, h, visible,
                              ws);
}

}  // namespace sphshell::approx::detail

