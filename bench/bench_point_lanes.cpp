// Cost of a point's kinematics stages (shell/kinematics.hpp) one point at a
// time against a group of eight points in lanes, as the assembler runs them:
// from each point's gathered gradients, reference products and strains before
// the step, stored point by point (as the solver stores them), the Green
// strains and their increments, then the conjugate forces of given weighted
// stresses, stored point by point again.
//
//   by_point:        the one-point functions (the lanes' formulas at L = 1);
//   lanes:           groups of 8 copied into lanes, the lane loops, copied out
//                    (what the assembler does);
//   lanes_resident:  the lane loops alone, on lanes that stay put: the cost
//                    of the arithmetic without the copies, as if the
//                    per-point data were stored in lanes.
//
// Run with --benchmark_enable_random_interleaving --benchmark_repetitions=N
// so that the three take turns. The counter ns_per_point is the CPU time of
// one pass over the points.
#include <sphshell/core/simd.hpp>
#include <sphshell/core/types.hpp>
#include <sphshell/shell/kinematics.hpp>

#include <benchmark/benchmark.h>

#include <cstddef>
#include <random>
#include <vector>

using namespace sphshell;

namespace {

const bool instruction_set_in_context = [] {
  benchmark::AddCustomContext("instruction_set", simd::instruction_set());
  return true;
}();

constexpr int group_size = 8;
// About the stress points and particles of the paper's 51² plate.
constexpr std::size_t point_count = 5200;

struct Points {
  std::vector<shell::SurfaceGradients> current;
  std::vector<shell::ReferenceProducts> products;
  std::vector<shell::Strains> strains_before, stresses;
  std::vector<shell::Strains> increments;
  std::vector<shell::ConjugateForces> forces;

  Points() {
    std::mt19937_64 random(8);
    std::uniform_real_distribution<double> uniform(-1.0, 1.0);
    const auto vector = [&](double scale) -> Vector3 {
      return Vector3(uniform(random), uniform(random), uniform(random)) * scale;
    };
    for (std::size_t p = 0; p < point_count; ++p) {
      shell::SurfaceGradients reference{Vector3(1.0, 0.0, 0.0) + vector(0.1), Vector3(0.0, 1.0, 0.0) + vector(0.1),
                                        Vector3(0.0, 0.0, 1.0) + vector(0.1), vector(1.0), vector(1.0)};
      products.push_back(shell::reference_products(reference));
      current.push_back(shell::SurfaceGradients{reference.a1 + vector(1e-3), reference.a2 + vector(1e-3),
                                                reference.n + vector(1e-3), reference.n1 + vector(1e-2),
                                                reference.n2 + vector(1e-2)});
      strains_before.push_back(shell::green_strains(current.back(), products.back()));
      stresses.push_back(shell::Strains{vector(1e6), vector(1e3), Vector2(uniform(random), uniform(random)) * 1e5});
    }
    increments.resize(point_count);
    forces.resize(point_count);
  }
};

void by_point(benchmark::State& state) {
  Points points;
  for (auto _ : state) {
    for (std::size_t p = 0; p < point_count; ++p) {
      const shell::Strains s = shell::green_strains(points.current[p], points.products[p]);
      const shell::Strains& before = points.strains_before[p];
      points.increments[p] =
          shell::Strains{s.membrane - before.membrane, s.curvature - before.curvature, s.shear - before.shear};
      const shell::Strains& w = points.stresses[p];
      points.forces[p] = shell::conjugate_forces(points.current[p], shell::WeightedStresses{w.membrane, w.curvature, w.shear});
    }
    benchmark::ClobberMemory();
  }
  state.counters["ns_per_point"] =
      benchmark::Counter(double(point_count) * 1e-9, benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kInvert);
}

template <bool copies>
void in_lanes(benchmark::State& state) {
  Points points;
  constexpr int G = group_size;
  shell::SurfaceGradientLanes<G> current{};
  shell::ReferenceProductLanes<G> products{};
  shell::StrainLanes<G> strains{}, increments{}, stresses{};
  shell::ConjugateForceLanes<G> forces{};
  // Escaped, so that each pass reads the resident lanes again.
  benchmark::DoNotOptimize(current);
  benchmark::DoNotOptimize(products);
  benchmark::DoNotOptimize(stresses);
  benchmark::DoNotOptimize(increments);
  benchmark::DoNotOptimize(forces);
  for (auto _ : state) {
    for (std::size_t first = 0; first < point_count; first += G) {
      if (copies)
        for (int m = 0; m < G; ++m) {
          const std::size_t p = first + std::size_t(m);
          current.set(m, points.current[p]);
          products.set(m, points.products[p]);
          increments.set(m, points.strains_before[p]);
          stresses.set(m, points.stresses[p]);
        }
      shell::green_strains(current, products, strains);
      for (int l = 0; l < G; ++l) {
        for (int i = 0; i < 3; ++i) {
          increments.membrane.c[i][l] = strains.membrane.c[i][l] - increments.membrane.c[i][l];
          increments.curvature.c[i][l] = strains.curvature.c[i][l] - increments.curvature.c[i][l];
        }
        for (int i = 0; i < 2; ++i) increments.shear.c[i][l] = strains.shear.c[i][l] - increments.shear.c[i][l];
      }
      shell::conjugate_forces(current, stresses, forces);
      if (copies) {
        for (int m = 0; m < G; ++m) {
          const std::size_t p = first + std::size_t(m);
          points.increments[p] = increments.at(m);
          points.forces[p] = shell::ConjugateForces{forces.a1.at(m), forces.a2.at(m), forces.n.at(m), forces.n1.at(m),
                                                    forces.n2.at(m)};
        }
      } else {
        benchmark::ClobberMemory();
      }
    }
    benchmark::ClobberMemory();
  }
  state.counters["ns_per_point"] =
      benchmark::Counter(double(point_count) * 1e-9, benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kInvert);
}

}  // namespace

BENCHMARK(by_point);
BENCHMARK_TEMPLATE(in_lanes, true)->Name("lanes");
BENCHMARK_TEMPLATE(in_lanes, false)->Name("lanes_resident");

BENCHMARK_MAIN();
