// Would the step's gather gain from another data layout? The gather
// (IntegrationPoints::gather) forms a1, a2, n, n1, n2 of a point from its
// neighbours' positions and directors; it is one of the step's two per-slot
// loops (the particles' force sums are the other), which together take about
// a third of the paper plate's step (docs/performance.md, the profile). This
// benchmark times, on the paper plate's own shape functions, the library's
// gather point by point (a particle's six numbers as one 6-vector) against
//  - padded: the same, each particle's position and director padded with a
//    zero to eight doubles (one 64-byte line, whole vector registers);
//  - lanes: eight points at a time in structure-of-arrays form (one lane per
//    point, slots padded with Φ = 0), the layout a point-batched assembler
//    would use; the compiler vectorises the lanes with the instructions the
//    build allows.
// All three give the same bits (checked before timing).
//  - gather_layouts/<n>: the n×n plate (the gather does not see the rule or
//    the law), the three passes over all of its points in turns, 30 turns;
//    counters ns_per_point_<layout> (medians of the turns) and
//    <layout>_over_by_point (medians of the per-turn ratios).
#include <sphshell/approx/mls.hpp>
#include <sphshell/kernel/cubic_spline.hpp>
#include <sphshell/shell/model.hpp>
#include <sphshell/solver/integration_points.hpp>
#include <sphshell/solver/options.hpp>

#include <Eigen/Core>
#include <benchmark/benchmark.h>

#include "bench_support.hpp"

#include <algorithm>
#include <array>
#include <cstddef>
#include <cstring>
#include <vector>

using namespace sphshell;
using sphshell::bench::median;
using sphshell::bench::thread_seconds;

namespace {

using Points = solver::IntegrationPoints<approx::MLS<kernel::CubicSpline>>;

constexpr std::size_t lanes = 8;  // one AVX-512 register of doubles
constexpr int components = 15;    // a1, a2, n, n1, n2
constexpr int packed_doubles = 6;  // a particle's position, then its director
static_assert(sizeof(solver::PackedKinematics) == packed_doubles * sizeof(double), "the lanes read six doubles a particle");

// Calls body(group, row, first) for every point: its component c goes to
// out[first + c × 8] in the lanes' order (out[(batch × 15 + c) × 8 + lane],
// each group's rows in batches of eight).
template <class Body>
void for_each_point(const Points& points, Body&& body) {
  std::size_t first_batch = 0;
  for (solver::PointGroup group : solver::point_groups) {
    const std::size_t rows = points.count(group);
    for (std::size_t row = 0; row < rows; ++row)
      body(group, row, (first_batch + row / lanes) * components * lanes + row % lanes);
    first_batch += (rows + lanes - 1) / lanes;
  }
}

// The points' shape functions rearranged for lanes: per batch of eight rows
// of a group, slot s of every lane side by side (a lane past its row's end
// reads its first neighbour with Φ = ∇Φ = 0, which adds +0 to its sums).
struct LaneLayout {
  std::vector<std::size_t> batch_begin{0};  // in slots of `lanes` entries
  std::vector<int> neighbour;
  std::vector<double> phi, dphi_d1, dphi_d2;

  explicit LaneLayout(const Points& points) {
    for (solver::PointGroup group : solver::point_groups) {
      const approx::ShapeFunctions& sf = points.shape(group);
      const std::size_t rows = points.count(group);
      for (std::size_t first = 0; first < rows; first += lanes) {
        std::size_t longest = 0;
        for (std::size_t l = 0; l < lanes; ++l)
          longest = std::max(longest, std::size_t(sf.row_size[std::min(rows - 1, first + l)]));
        for (std::size_t s = 0; s < longest; ++s)
          for (std::size_t l = 0; l < lanes; ++l) {
            const std::size_t row = std::min(rows - 1, first + l);
            const bool inside = s < std::size_t(sf.row_size[row]);
            const std::size_t slot = sf.row_begin[row] + (inside ? s : 0);
            neighbour.push_back(sf.neighbour[slot]);
            phi.push_back(inside ? sf.value[slot].phi : 0.0);
            dphi_d1.push_back(inside ? sf.value[slot].dphi_d1 : 0.0);
            dphi_d2.push_back(inside ? sf.value[slot].dphi_d2 : 0.0);
          }
        batch_begin.push_back(neighbour.size() / lanes);
      }
    }
  }
  std::size_t batches() const { return batch_begin.size() - 1; }
};

// Every batch's fifteen sums per lane, into out[(batch × 15 + component) × 8 + lane].
void gather_lanes(const LaneLayout& layout, const std::vector<solver::PackedKinematics>& packed,
                  std::vector<double>& out) {
  const double* const kinematics = packed.front().position.data();
  for (std::size_t b = 0; b < layout.batches(); ++b) {
    alignas(64) double sum[components][lanes] = {};
    for (std::size_t s = layout.batch_begin[b]; s < layout.batch_begin[b + 1]; ++s) {
      const int* const j = &layout.neighbour[s * lanes];
      const double* const phi = &layout.phi[s * lanes];
      const double* const d1 = &layout.dphi_d1[s * lanes];
      const double* const d2 = &layout.dphi_d2[s * lanes];
#pragma omp simd
      for (std::size_t l = 0; l < lanes; ++l) {
        const int at = packed_doubles * j[l];
        const double x = kinematics[at], y = kinematics[at + 1], z = kinematics[at + 2];
        const double dx = kinematics[at + 3], dy = kinematics[at + 4], dz = kinematics[at + 5];
        sum[0][l] += d1[l] * x;  // a1
        sum[1][l] += d1[l] * y;
        sum[2][l] += d1[l] * z;
        sum[3][l] += d2[l] * x;  // a2
        sum[4][l] += d2[l] * y;
        sum[5][l] += d2[l] * z;
        sum[6][l] += phi[l] * dx;  // n
        sum[7][l] += phi[l] * dy;
        sum[8][l] += phi[l] * dz;
        sum[9][l] += d1[l] * dx;  // n1
        sum[10][l] += d1[l] * dy;
        sum[11][l] += d1[l] * dz;
        sum[12][l] += d2[l] * dx;  // n2
        sum[13][l] += d2[l] * dy;
        sum[14][l] += d2[l] * dz;
      }
    }
    std::memcpy(&out[b * components * lanes], sum, sizeof sum);
  }
}

// Position and director of a particle padded to eight doubles: (x, 0, d, 0).
using Padded = Eigen::Matrix<double, 8, 1>;
using PaddedKinematics = std::vector<Padded, Eigen::aligned_allocator<Padded>>;

// The library's gather on padded kinematics, the sums in the lanes' order.
void gather_padded(const Points& points, const PaddedKinematics& padded, std::vector<double>& out) {
  for_each_point(points, [&](solver::PointGroup group, std::size_t row, std::size_t first) {
    // Local pointers and bounds, as in the library's gather: read through the
    // captured vectors, they would be reloaded at every slot.
    const approx::ShapeFunctions& sf = points.shape(group);
    const int* const neighbour = sf.neighbour.data();
    const approx::ShapeValue* const value = sf.value.data();
    const Padded* const particles = padded.data();
    const std::size_t begin = sf.row_begin[row], end = begin + sf.row_size[row];
    Padded d1_sum = Padded::Zero(), d2_sum = Padded::Zero();
    Eigen::Vector4d n = Eigen::Vector4d::Zero();
    for (std::size_t s = begin; s < end; ++s) {
      const Padded& particle = particles[std::size_t(neighbour[s])];
      d1_sum += value[s].dphi_d1 * particle;
      d2_sum += value[s].dphi_d2 * particle;
      n += value[s].phi * particle.tail<4>();
    }
    const std::array<double, components> sums{d1_sum[0], d1_sum[1], d1_sum[2], d2_sum[0], d2_sum[1],
                                              d2_sum[2], n[0],      n[1],      n[2],      d1_sum[4],
                                              d1_sum[5], d1_sum[6], d2_sum[4], d2_sum[5], d2_sum[6]};
    for (int c = 0; c < components; ++c) out[first + std::size_t(c) * lanes] = sums[std::size_t(c)];
  });
}

// The library's gather of every point, its fifteen sums in the lanes' order.
void gather_by_point(const Points& points, const std::vector<solver::PackedKinematics>& packed,
                     std::vector<double>& out) {
  for_each_point(points, [&](solver::PointGroup group, std::size_t row, std::size_t first) {
    const shell::SurfaceGradients g = points.gather(group, row, packed);
    const std::array<const Vector3*, 5> vectors{&g.a1, &g.a2, &g.n, &g.n1, &g.n2};
    for (int c = 0; c < components; ++c) out[first + std::size_t(c) * lanes] = (*vectors[c / 3])[c % 3];
  });
}

void gather_layouts(benchmark::State& state) {
  const int n = int(state.range(0));
  const ShellModel model = ShellModel::rectangular_plate(0.5, 0.5, n, n, 0.01);
  const SolverOptions options;
  constexpr double steel_shear_modulus = 210e9 / (2.0 * 1.3), steel_poisson_ratio = 0.3;
  const Points points(model, options.physics(), options.particle_integration(), steel_shear_modulus,
                      steel_poisson_ratio);
  // A bent configuration: positions lifted and directors tilted by a smooth field.
  std::vector<solver::PackedKinematics> packed(model.particle_count());
  for (std::size_t i = 0; i < packed.size(); ++i) {
    const Vector3& x = model.particle_position[i];
    const double lift = 0.01 * x.x() * (0.5 - x.x()) * x.y() * (0.5 - x.y());
    packed[i] = {x + Vector3(0.0, 0.0, lift), Vector3(0.1 * lift, -0.2 * lift, 1.0).normalized()};
  }
  const LaneLayout layout(points);
  PaddedKinematics padded(packed.size());
  for (std::size_t i = 0; i < packed.size(); ++i) padded[i] << packed[i].position, 0.0, packed[i].director, 0.0;
  std::vector<double> by_point(layout.batches() * components * lanes, 0.0), in_lanes(by_point.size(), 0.0),
      by_padded(by_point.size(), 0.0);
  gather_by_point(points, packed, by_point);
  gather_lanes(layout, packed, in_lanes);
  gather_padded(points, padded, by_padded);
  // Lanes past a group's last row repeat that row; compare the real ones.
  bool same = true;
  for_each_point(points, [&](solver::PointGroup, std::size_t, std::size_t first) {
    for (std::size_t at = first; at < first + components * lanes; at += lanes)
      same = same && by_point[at] == in_lanes[at] && by_point[at] == by_padded[at];
  });
  if (!same) {
    state.SkipWithError("a layout's sums differ from the library's gather");
    return;
  }
  const double point_count = double(points.size());
  constexpr int turns = 30;
  for (auto _ : state) {
    std::vector<double> by_point_ns, padded_ns, lanes_ns, padded_ratios, lanes_ratios;
    for (int turn = 0; turn < turns; ++turn) {
      double start = thread_seconds();
      gather_by_point(points, packed, by_point);
      const double a = 1e9 * (thread_seconds() - start) / point_count;
      start = thread_seconds();
      gather_padded(points, padded, by_padded);
      const double b = 1e9 * (thread_seconds() - start) / point_count;
      start = thread_seconds();
      gather_lanes(layout, packed, in_lanes);
      const double c = 1e9 * (thread_seconds() - start) / point_count;
      benchmark::DoNotOptimize(by_point.data());
      benchmark::DoNotOptimize(by_padded.data());
      benchmark::DoNotOptimize(in_lanes.data());
      by_point_ns.push_back(a);
      padded_ns.push_back(b);
      lanes_ns.push_back(c);
      padded_ratios.push_back(b / a);
      lanes_ratios.push_back(c / a);
    }
    state.counters["ns_per_point_by_point"] = median(by_point_ns);
    state.counters["ns_per_point_padded"] = median(padded_ns);
    state.counters["ns_per_point_lanes"] = median(lanes_ns);
    state.counters["padded_over_by_point"] = median(padded_ratios);
    state.counters["lanes_over_by_point"] = median(lanes_ratios);
    state.SetIterationTime(1e-9 * median(by_point_ns) * point_count);
  }
}

}  // namespace

BENCHMARK(gather_layouts)->Arg(51)->Arg(201)->UseManualTime()->Iterations(1)->Unit(benchmark::kMillisecond);

BENCHMARK_MAIN();
