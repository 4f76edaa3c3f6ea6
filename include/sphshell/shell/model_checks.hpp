#pragma once
// The consistency checks a ShellModel runs on its geometry at construction
// (docs/method.md §1): finite coordinates, quads by index (distinct corners,
// not degenerate, not a bow-tie, counter-clockwise), normals out of the sheet
// and sharing one orientation, area sets covering the surface once, no
// near-coincident particles, a thin wall. Each failure is an Error naming the
// quad, particle or parameter, its value and the limit. The limits are named
// so a message can state them.

#include <sphshell/approx/memory_estimate.hpp>
#include <sphshell/approx/neighbour_search.hpp>
#include <sphshell/core/error.hpp>
#include <sphshell/core/statistics.hpp>
#include <sphshell/core/types.hpp>
#include <sphshell/shell/cell.hpp>

#include <Eigen/Eigenvalues>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <new>
#include <optional>
#include <sstream>
#include <string>
#include <unordered_map>
#include <utility>
#include <vector>

namespace sphshell::detail::model_checks {

// Geometry checks (docs/method.md §1; the limits are named so a message can state them).
// A quad whose area is below this fraction of its longest side squared is degenerate.
inline constexpr double degenerate_area_fraction = 1e-12;
// A normal closer than this to a cell's plane (cosine of the angle to the
// cell normal, cos 80°) lies "in the sheet's plane".
inline constexpr double in_plane_cosine = 0.17364817766693033;
// Particles closer than this fraction of the local spacing √A_i are near-coincident
// (small enough for cells a thousand times longer than wide).
inline constexpr double coincident_spacing_fraction = 1e-3;
// The two area sets (particles, stress points) cover the same surface: their
// sums may differ by at most this fraction.
inline constexpr double area_sum_tolerance = 0.02;
// Particles whose spread across their main line is below this fraction of
// their extent lie on one line; a sheet flat to this fraction is planar.
inline constexpr double collinear_fraction = 1e-6;
inline constexpr double planar_fraction = 1e-9;

inline std::string vector_text(const Vector3& v) {
  std::ostringstream text;
  text << v.transpose();
  return text.str();
}
inline void check_finite(const char* what, const char* quantity, const std::vector<Vector3>& values) {
  for (std::size_t i = 0; i < values.size(); ++i)
    if (!values[i].allFinite())
      detail::invalid_parameter(std::string(what) + " " + std::to_string(i) + " " + quantity,
                                values[i].transpose(), "must be finite");
}
inline std::string corners_text(const Quad& quad) {
  return "{" + std::to_string(quad[0]) + ", " + std::to_string(quad[1]) + ", " + std::to_string(quad[2]) + ", " +
         std::to_string(quad[3]) + "}";
}
// Every quad by index: corners in range and distinct, not degenerate, not
// self-intersecting, and counter-clockwise seen from its corners' normals.
inline void check_quads(const std::vector<Vector3>& positions, const std::vector<Vector3>& normals,
                        const std::vector<Quad>& quads) {
  if (quads.empty()) detail::invalid_parameter("quad count", 0, "a shell needs quads");
  check_finite("particle", "position", positions);
  check_finite("particle", "normal", normals);
  for (std::size_t q = 0; q < quads.size(); ++q) {
    const Quad& quad = quads[q];
    const auto quad_name = [q] { return "quad " + std::to_string(q); };
    for (std::size_t k = 0; k < 4; ++k) {
      if (quad[k] < 0 || static_cast<std::size_t>(quad[k]) >= positions.size())
        detail::invalid_parameter(quad_name() + " corner " + std::to_string(k), quad[k],
                                  "must lie in [0, " + std::to_string(positions.size()) + ")");
      for (std::size_t l = 0; l < k; ++l)
        if (quad[l] == quad[k])
          detail::invalid_parameter(quad_name() + " corners", corners_text(quad),
                                    "particle " + std::to_string(quad[k]) +
                                        " is listed twice: four distinct corners (a degenerate quad)");
    }
    const Vector3 doubled_area = (positions[quad[2]] - positions[quad[0]]).cross(positions[quad[3]] - positions[quad[1]]);
    double longest_squared = 0.0;
    for (std::size_t k = 0; k < 4; ++k)
      longest_squared = std::max(longest_squared, (positions[quad[(k + 1) % 4]] - positions[quad[k]]).squaredNorm());
    // The largest corner triangle: zero only when all four corners lie on one line.
    Vector3 largest_corner = Vector3::Zero();
    for (std::size_t k = 0; k < 4; ++k) {
      const Vector3& here = positions[quad[k]];
      const Vector3 corner = (positions[quad[(k + 1) % 4]] - here).cross(positions[quad[(k + 3) % 4]] - here);
      if (corner.norm() > largest_corner.norm()) largest_corner = corner;
    }
    const double area = 0.5 * doubled_area.norm();
    if (!(0.5 * largest_corner.norm() > degenerate_area_fraction * longest_squared))
      detail::invalid_parameter(quad_name() + " area", area,
                                "must be > 0: corners " + corners_text(quad) +
                                    " are collinear or coincident (a degenerate quad)");
    // A bow-tie's diagonals may have a zero cross product: then its largest corner gives the axis.
    const bool diagonals_span = area > degenerate_area_fraction * longest_squared;
    const Vector3 axis = diagonals_span ? doubled_area.normalized() : largest_corner.normalized();
    // Turning direction at each corner about the quad's own normal: a simple
    // quad turns one way at three or four corners, a bow-tie at two only.
    int reversed_turns = 0;
    for (std::size_t k = 0; k < 4; ++k) {
      const Vector3& here = positions[quad[k]];
      const Vector3 next = positions[quad[(k + 1) % 4]] - here, previous = positions[quad[(k + 3) % 4]] - here;
      if (next.cross(previous).dot(axis) < 0.0) ++reversed_turns;
    }
    if (reversed_turns >= 2 || !diagonals_span)
      detail::invalid_parameter(quad_name() + " corners", corners_text(quad),
                                "its edges cross (a bow-tie quad): list the corners in order around the quad");
    int against = 0;
    for (int corner : quad)
      if (normals[corner].dot(axis) < 0.0) ++against;
    if (against == 4)
      detail::invalid_parameter(quad_name() + " corners", corners_text(quad),
                                "run clockwise seen from the side the normals point to (an inverted quad): list "
                                "them counter-clockwise");
    for (int corner : quad) {
      const double length = normals[corner].norm();
      const double cosine = length > 0.0 ? normals[corner].dot(axis) / length : 0.0;
      if (cosine < 0.0)
        detail::invalid_parameter("particle " + std::to_string(corner) + " normal", normals[corner].transpose(),
                                  "points against " + quad_name() + " (corners " + corners_text(quad) +
                                      ") while its other corners' normals agree with it: neighbouring normals "
                                      "must share one orientation");
      if (length > 0.0 && cosine < in_plane_cosine)
        detail::invalid_parameter("particle " + std::to_string(corner) + " normal", normals[corner].transpose(),
                                  "lies (within 10°) in the plane of " + quad_name() +
                                      ": a normal must point out of the sheet");
    }
  }
}
// The bounding-box diagonal of the particles: a shell's thickness lies below it.
inline double extent(const std::vector<Vector3>& particle_position) {
  Vector3 lower = particle_position.front(), upper = lower;
  for (const Vector3& x : particle_position) lower = lower.cwiseMin(x), upper = upper.cwiseMax(x);
  return (upper - lower).norm();
}
inline void require_thin(const std::string& name, double d, double extent) {
  detail::require_positive(name, d);
  if (!(d < extent))
    detail::invalid_parameter(name, d,
                              "must be below the shell's extent " + std::to_string(extent) +
                                  " m (the diagonal of its particles' bounding box): a shell is thin");
}
using sphshell::detail::median;  // core/statistics.hpp
// The sheet spans a surface: not one line; a flat sheet's normals point out of its plane.
inline void check_spans_a_surface(const std::vector<Vector3>& particle_position,
                                  const std::vector<Vector3>& particle_normal,
                                  const std::vector<Vector3>& stress_point_normal) {
  Vector3 mean = Vector3::Zero();
  for (const Vector3& x : particle_position) mean += x;
  mean /= static_cast<double>(particle_position.size());
  Matrix3 scatter = Matrix3::Zero();
  for (const Vector3& x : particle_position) scatter += (x - mean) * (x - mean).transpose();
  const Eigen::SelfAdjointEigenSolver<Matrix3> principal(scatter);
  const Vector3 spread = principal.eigenvalues().cwiseMax(0.0).cwiseSqrt();  // ascending
  if (!(spread[1] > collinear_fraction * spread[2]))
    detail::invalid_parameter("particle positions", "(all on one line)",
                              "a shell needs particles spanning a surface, at least 3 not on one line");
  if (spread[0] > planar_fraction * spread[2]) return;
  const Vector3 plane_normal = principal.eigenvectors().col(0);
  auto check = [&](const std::vector<Vector3>& normals, const std::string& what) {
    for (std::size_t i = 0; i < normals.size(); ++i)
      if (std::abs(normals[i].dot(plane_normal)) < in_plane_cosine)
        detail::invalid_parameter(what + " " + std::to_string(i) + " normal", normals[i].transpose(),
                                  "lies (within 10°) in the plane of the flat sheet: a normal must point out of "
                                  "the sheet");
  };
  check(particle_normal, "particle");
  check(stress_point_normal, "stress point");
}
// Each particle's normal agrees in orientation with its nearest stress point's.
inline void check_orientation(const std::vector<Vector3>& particle_position, const std::vector<Vector3>& particle_normal,
                              const std::vector<Vector3>& stress_point_position,
                              const std::vector<Vector3>& stress_point_normal,
                              const std::vector<double>& particle_area) {
  // The nearest stress point of a grid lies within 0.71 spacings (0.71 √A_i
  // of an inner particle, 1.41 √A_i of a corner one, whose area is a quarter);
  // a particle with none within two of its own spacings √A_i is not checked.
  // Cells of the median reach keep a graded sheet's search local.
  std::vector<double> reach(particle_area.size());
  for (std::size_t i = 0; i < reach.size(); ++i) reach[i] = 2.0 * std::sqrt(particle_area[i]);
  const approx::CellList stress_points(stress_point_position, median(reach));
  for (std::size_t i = 0; i < particle_position.size(); ++i) {
    int nearest_point = -1;
    double nearest_distance = std::numeric_limits<double>::infinity();
    stress_points.for_each_within(particle_position[i], reach[i], [&](int p, double distance_squared) {
      if (distance_squared < nearest_distance) nearest_distance = distance_squared, nearest_point = p;
    });
    if (nearest_point >= 0 && particle_normal[i].dot(stress_point_normal[nearest_point]) < 0.0)
      detail::invalid_parameter("particle " + std::to_string(i) + " normal", particle_normal[i].transpose(),
                                "points against the normal (" +
                                    vector_text(stress_point_normal[nearest_point]) + ") of the nearest stress point " +
                                    std::to_string(nearest_point) +
                                    ": neighbouring normals must share one orientation");
  }
}
// Pairs of particles closer than coincident_spacing_fraction × √A_i. Such a
// pair is an Error when the particles share a cell, or always in a model
// without cells; pairs that share no cell are the two faces of a slit and are
// returned (i < j, sorted): a cut must separate them (shell/cuts.hpp).
inline std::vector<std::pair<int, int>> check_separation(const std::vector<Vector3>& particle_position,
                                                         const std::vector<double>& particle_area,
                                                         const std::vector<Cell>& cells) {
  // Cells about one (median) spacing wide: a few particles each (cells as
  // narrow as the tolerance would be mostly empty and slow to search).
  std::vector<double> spacing(particle_area.size());
  for (std::size_t i = 0; i < spacing.size(); ++i) spacing[i] = std::sqrt(particle_area[i]);
  const approx::CellList particles(particle_position, median(spacing));
  std::vector<std::pair<int, int>> pairs;
  for (std::size_t i = 0; i < particle_position.size(); ++i) {
    const double limit = coincident_spacing_fraction * std::sqrt(particle_area[i]);
    particles.for_each_within(particle_position[i], limit, [&](int j, double) {
      if (static_cast<std::size_t>(j) > i) pairs.emplace_back(static_cast<int>(i), j);
    });
  }
  std::sort(pairs.begin(), pairs.end());
  pairs.erase(std::unique(pairs.begin(), pairs.end()), pairs.end());
  std::vector<std::vector<int>> cells_of(pairs.empty() ? 0 : particle_position.size());
  for (std::size_t c = 0; c < cells.size() && !pairs.empty(); ++c)
    for (int corner : cells[c]) cells_of[static_cast<std::size_t>(corner)].push_back(static_cast<int>(c));
  for (const auto& [i, j] : pairs) {
    bool share_a_cell = cells.empty();
    for (int c : cells_of[static_cast<std::size_t>(i)])
      share_a_cell = share_a_cell || std::find(cells[static_cast<std::size_t>(c)].begin(),
                                               cells[static_cast<std::size_t>(c)].end(), j) !=
                                         cells[static_cast<std::size_t>(c)].end();
    if (!share_a_cell) continue;
    const auto first = static_cast<std::size_t>(i);
    detail::invalid_parameter(
        "distance between particles " + std::to_string(i) + " and " + std::to_string(j),
        (particle_position[first] - particle_position[static_cast<std::size_t>(j)]).norm(),
        "must be at least " + std::to_string(coincident_spacing_fraction) + " of the local spacing √A = " +
            std::to_string(std::sqrt(particle_area[first])) + " m: near-coincident particles (merge them)" +
            (cells.empty() ? "" : "; only particles that share no cell (the faces of a slit) may coincide"));
  }
  return pairs;
}
inline void check_area_sums(const std::vector<double>& particle_area, const std::vector<double>& stress_point_area) {
  double particles = 0.0, stress_points = 0.0;
  for (double area : particle_area) particles += area;
  for (double area : stress_point_area) stress_points += area;
  if (std::abs(particles - stress_points) > area_sum_tolerance * std::max(particles, stress_points)) {
    // The largest area of the set that covers too much, which is the fault
    // when one area alone is far off.
    const bool stress_larger = stress_points > particles;
    const std::vector<double>& larger = stress_larger ? stress_point_area : particle_area;
    const auto largest = static_cast<std::size_t>(std::max_element(larger.begin(), larger.end()) - larger.begin());
    detail::invalid_parameter("sum of the particle areas", particles,
                              "must equal the sum of the stress point areas " + std::to_string(stress_points) +
                                  " m² within " + std::to_string(100.0 * area_sum_tolerance) +
                                  " %: each set of areas covers the mid-surface once; the largest is " +
                                  (stress_larger ? "stress point " : "particle ") + std::to_string(largest) +
                                  " area = " + std::to_string(larger[largest]) + " m², " +
                                  std::to_string(larger[largest] / median(larger)) + " times the median of its set");
  }
}

inline void require_count(const char* name, int value, int minimum) {
  if (value < minimum)
    detail::invalid_parameter(name, value, "must be at least " + std::to_string(minimum));
}
// A structured grid's particle count, checked before anything is allocated:
// the library's particle indices are int.
inline void require_grid_size(const char* names, long long count) {
  if (count > static_cast<long long>(std::numeric_limits<int>::max()))
    detail::invalid_parameter(names, count, "must be at most 2^31 - 1 particles (the library's indices are int)");
}
// What building a model takes per particle and per cell (stress point), the
// checks' temporary structures included: positions, normals, areas and
// thicknesses (about 10 doubles each), the cell lists and neighbour grids of
// the checks, the edge map of the orientation check and the cells themselves.
inline constexpr double bytes_per_model_particle = 256;
inline constexpr double bytes_per_model_cell = 256;
// The memory a model of this size will take, checked before it is allocated:
// an Error with the estimate and the memory available, never std::bad_alloc
// after seconds of work.
inline double require_model_memory(const std::string& what, double particles, double cells) {
  const double needed = particles * bytes_per_model_particle + cells * bytes_per_model_cell;
  const double available = approx::available_memory();
  if (needed > available) {
    std::ostringstream text;
    text.precision(12);
    text << "sphshell: " << what << ": a model of " << particles << " particles and " << cells
         << " cells needs about " << approx::format_bytes(needed) << " of memory; "
         << approx::format_bytes(available) << " available (MemAvailable, the cgroup limit and ulimit -v)";
    throw Error(text.str());
  }
  return needed;
}
// Runs a builder's work; an allocation that fails anyway becomes an Error
// naming the estimate.
template <class Work>
auto guard_building(const std::string& what, double estimate, Work&& work) -> decltype(work()) {
  try {
    return work();
  } catch (const std::bad_alloc&) {
    throw Error("sphshell: " + what + ": out of memory (std::bad_alloc; estimated " +
                approx::format_bytes(estimate) + ", " + approx::format_bytes(approx::available_memory()) +
                " available)");
  }
}
inline void check_sizes(const std::vector<Vector3>& positions, const std::vector<Vector3>& normals) {
  if (normals.size() != positions.size())
    detail::invalid_parameter("normal count", normals.size(),
                              "must equal the particle count (" + std::to_string(positions.size()) + ")");
}
inline void check_cell(const Cell& cell, std::size_t index, std::size_t particle_count) {
  const std::string name = "cell " + std::to_string(index) + " corner index";
  for (std::size_t k = 0; k < cell.size(); ++k) {
    if (cell[k] < 0 || static_cast<std::size_t>(cell[k]) >= particle_count)
      detail::invalid_parameter(name, cell[k], "must lie in [0, " + std::to_string(particle_count) + ")");
    for (std::size_t l = 0; l < k; ++l)
      if (cell[l] == cell[k]) detail::invalid_parameter(name, cell[k], "listed twice (a degenerate cell)");
  }
}
inline void check_index(const char* what, std::size_t index, std::size_t count) {
  if (index >= count)
    detail::invalid_parameter(std::string(what) + " index", index,
                              "must be below the count (" + std::to_string(count) + ")");
}

// The first orientation flip or junction among cells in the order given, or
// none. Cells' corners must be valid and distinct (from_cells checks them).
inline std::optional<CellEdgeProblem> find_cell_edge_problem(const std::vector<Cell>& cells) {
  struct EdgeUse {
    int cell;
    bool ascending;  // the first cell runs from the lower to the higher index
    int count;
  };
  std::unordered_map<std::uint64_t, EdgeUse> uses;
  for (std::size_t c = 0; c < cells.size(); ++c) {
    const Cell& cell = cells[c];
    for (std::size_t k = 0; k < cell.size(); ++k) {
      const int from = cell[k], to = cell[(k + 1) % cell.size()];
      const int low = std::min(from, to), high = std::max(from, to);
      const std::uint64_t key = (static_cast<std::uint64_t>(static_cast<std::uint32_t>(low)) << 32) |
                                static_cast<std::uint32_t>(high);
      const EdgeUse use{static_cast<int>(c), from < to, 1};
      auto [found, inserted] = uses.try_emplace(key, use);
      if (inserted) continue;
      if (found->second.count >= 2)
        return CellEdgeProblem{CellEdgeProblem::Kind::junction, found->second.cell, use.cell, from, to};
      if (found->second.ascending == use.ascending)
        return CellEdgeProblem{CellEdgeProblem::Kind::flipped, found->second.cell, use.cell, from, to};
      ++found->second.count;
    }
  }
  return std::nullopt;
}

// A cell with its corners in the opposite order (the first corner kept):
// the same cell seen from the other side.
inline Cell turned(const Cell& cell) {
  return cell.is_triangle() ? Cell(cell[0], cell[2], cell[1]) : Cell(cell[0], cell[3], cell[2], cell[1]);
}

// Consistent orientation by propagation across shared edges (two cells on an
// edge must run along it in opposite directions): each connected part of the
// mesh keeps the orientation most of its cells have as given (the lowest
// cell's on a tie) and the others are turned. Returns the turned cells'
// indices, ascending, or a problem: the first two cells that no turning makes
// agree (a one-sided surface). Edges of three or more cells (junctions) are
// not crossed; find_cell_edge_problem names them. Corners must be valid.
struct Orientation {
  std::vector<int> turned;
  std::optional<CellEdgeProblem> problem;
};
inline Orientation orient_cells(const std::vector<Cell>& cells) {
  struct EdgeUse {
    int cell;
    bool ascending;  // the cell runs from the lower to the higher index
  };
  std::unordered_map<std::uint64_t, std::vector<EdgeUse>> uses;
  uses.reserve(2 * cells.size());
  const auto key = [](int a, int b) {
    return (static_cast<std::uint64_t>(static_cast<std::uint32_t>(std::min(a, b))) << 32) |
           static_cast<std::uint32_t>(std::max(a, b));
  };
  for (std::size_t c = 0; c < cells.size(); ++c)
    for (std::size_t k = 0; k < cells[c].size(); ++k) {
      const int from = cells[c][k], to = cells[c][(k + 1) % cells[c].size()];
      uses[key(from, to)].push_back({static_cast<int>(c), from < to});
    }
  Orientation result;
  std::vector<signed char> turn(cells.size(), -1);  // -1: not reached yet
  std::vector<int> part, queue;
  for (std::size_t seed = 0; seed < cells.size(); ++seed) {
    if (turn[seed] >= 0) continue;
    part.clear();
    queue.assign(1, static_cast<int>(seed));
    turn[seed] = 0;
    for (std::size_t next = 0; next < queue.size(); ++next) {
      const int c = queue[next];
      part.push_back(c);
      const Cell& cell = cells[static_cast<std::size_t>(c)];
      for (std::size_t k = 0; k < cell.size(); ++k) {
        const int from = cell[k], to = cell[(k + 1) % cell.size()];
        const std::vector<EdgeUse>& edge = uses.at(key(from, to));
        if (edge.size() != 2) continue;
        const EdgeUse& mine = edge[0].cell == c ? edge[0] : edge[1];
        const EdgeUse& other = edge[0].cell == c ? edge[1] : edge[0];
        if (other.cell == c) continue;
        // Opposite directions after turning: turn[other] = turn[c] xor (same direction as given).
        const signed char wanted = static_cast<signed char>(turn[static_cast<std::size_t>(c)] ^ (mine.ascending == other.ascending));
        signed char& seen = turn[static_cast<std::size_t>(other.cell)];
        if (seen < 0) {
          seen = wanted;
          queue.push_back(other.cell);
        } else if (seen != wanted && !result.problem) {
          result.problem = CellEdgeProblem{CellEdgeProblem::Kind::unorientable, std::min(c, other.cell),
                                           std::max(c, other.cell), from, to};
        }
      }
    }
    std::size_t turned_count = 0;
    for (int c : part) turned_count += turn[static_cast<std::size_t>(c)];
    if (2 * turned_count > part.size())
      for (int c : part) turn[static_cast<std::size_t>(c)] ^= 1;
  }
  for (std::size_t c = 0; c < cells.size(); ++c)
    if (turn[c] == 1) result.turned.push_back(static_cast<int>(c));
  return result;
}

// What went wrong, for a message; `corner_names` says what the edge's ends are
// ("particles", "nodes").
inline std::string describe_edge_problem(const CellEdgeProblem& problem, const std::string& corner_names) {
  const std::string edge = "the edge between " + corner_names + " " + std::to_string(problem.edge_start) +
                           " and " + std::to_string(problem.edge_end);
  if (problem.kind == CellEdgeProblem::Kind::flipped)
    return "they run along " + edge +
           " in the same direction, so their normals flip there; reverse the corner order of one side";
  if (problem.kind == CellEdgeProblem::Kind::unorientable)
    return "they meet at " + edge + " with opposite orientations however the cells are turned: the surface " +
           "is one-sided (a Möbius strip) and has no consistent normal";
  return "a third cell meets at " + edge + "; a junction of three or more cells is not supported";
}

}  // namespace sphshell::detail::model_checks
