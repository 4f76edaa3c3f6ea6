// Cost of the grouped material update through the thickness
// (thickness/section_group.hpp) per stress point, as the assembler runs it: a
// SectionGroup of eight points at a time over many points, J2 through
// Gauss<5>, with the law states in lanes across points (StateLayout::
// lanes_across_points: one batched call per block of eight points, 40 lanes,
// states updated in place) and point by point (each point's Section::update),
// side by side in one program so that a run interleaves them
// (--benchmark_enable_random_interleaving with --benchmark_repetitions).
//
// The strains: point p follows bench_return_map.cpp's tension–shear stream
// from offset 37p (membrane increments of 2.5–7.5e-6) with curvature
// increments of the same stream half a pass later over half the thickness, from
// a state preloaded to 1.2× the uniaxial yield strain scaled through the
// thickness, so that integral points yield along the stream (`plastic`; the
// counter plastic_share is the share of integral-point updates that yield);
// or, from the unstressed state, the same stream a thousand times smaller,
// every step elastic (`elastic`). One iteration is one step over all
// points; the states are reset after each pass of the stream. The counter
// ns_per_stress_point is the CPU time of an iteration over the points.
#include <sphshell/core/simd.hpp>
#include <sphshell/material/all.hpp>
#include <sphshell/thickness/section_group.hpp>
#include <sphshell/thickness/all.hpp>

#include <benchmark/benchmark.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstddef>
#include <vector>

using namespace sphshell;

namespace {

const bool instruction_set_in_context = [] {
  benchmark::AddCustomContext("instruction_set", simd::instruction_set());
  return true;
}();

constexpr double youngs_modulus = 210e9;
constexpr double poisson_ratio = 0.3;
constexpr double yield_stress = 235e6;
constexpr double plastic_modulus = 1e9;
constexpr double wall_thickness = 0.01;
constexpr int stream_length = 500;
// Offset between consecutive points along the stream, so that the points of
// a group take different increments.
constexpr std::size_t point_stride = 37;
constexpr double pi = 3.14159265358979323846;
// Δt of an explicit step of the paper's plates (J2 does not read it).
constexpr double time_step = 1e-7;

using Rule = thickness::Gauss<5>;
using Law = material::J2Plasticity;
using Section = thickness::Section<Rule, Law>;
using Lanes = thickness::SectionGroup<Rule, Law, thickness::points_per_group, thickness::StateLayout::lanes_across_points>;
using PointByPoint = thickness::SectionGroup<Rule, Law, thickness::points_per_group, thickness::StateLayout::point_by_point>;
static_assert(Lanes::across_points && !PointByPoint::across_points,
              "bench_section_group compares the two layouts of the same group");

const Law j2_law({youngs_modulus, poisson_ratio, yield_stress, plastic_modulus});

std::vector<StrainVoigt> tension_shear_stream(double magnitude) {
  std::vector<StrainVoigt> stream;
  stream.reserve(stream_length);
  for (int k = 0; k < stream_length; ++k) {
    const double angle = 0.25 * pi * (1.0 - std::cos(4.0 * pi * k / stream_length));
    const double size = magnitude * (1.0 + 0.5 * std::sin(6.0 * pi * k / stream_length));
    stream.emplace_back(size * std::cos(angle), -0.5 * size * std::cos(angle),
                        std::sqrt(3.0) * size * std::sin(angle));
  }
  return stream;
}

enum class Loading { plastic, elastic };

// Point p's state at the start of a pass.
Section::State start_state(const Section& section, Loading loading) {
  Section::State state = section.initial_state();
  if (loading == Loading::elastic) return state;
  const StrainVoigt preload = 1.2 * yield_stress / youngs_modulus * StrainVoigt(1.0, -0.5, 0.0);
  constexpr int preload_steps = 100;
  for (int k = 0; k < Section::num_points; ++k)
    for (int step = 0; step < preload_steps; ++step)
      j2_law.update(state[std::size_t(k)],
                    preload * (1.0 + 0.3 * section.zeta(k) / wall_thickness) / double(preload_steps));
  return state;
}

template <class Group>
void BM_section_group(benchmark::State& benchmark_state, Loading loading) {
  const std::size_t points = std::size_t(benchmark_state.range(0));
  const std::size_t group_size = std::size_t(Group::group_size);
  const Section section(j2_law, wall_thickness);
  const std::vector<StrainVoigt> membrane = tension_shear_stream(loading == Loading::plastic ? 5e-6 : 5e-9);
  std::vector<StrainVoigt> curvature(membrane.size());
  for (std::size_t k = 0; k < membrane.size(); ++k)
    curvature[k] = membrane[(k + membrane.size() / 2) % membrane.size()] / (wall_thickness / 2);
  const Section::State start = start_state(section, loading);

  // The share of integral-point updates that yield over a pass, from the
  // first group's points alone (outside the timing).
  long yielded = 0, updates = 0;
  for (std::size_t p = 0; p < std::min(points, group_size); ++p) {
    Section::State state = start;
    for (std::size_t step = 0; step < membrane.size(); ++step) {
      const Section::State before = state;
      const std::size_t at = (step + point_stride * p) % membrane.size();
      section.update(state, membrane[at], curvature[at]);
      for (std::size_t k = 0; k < state.size(); ++k, ++updates) yielded += state[k].eps_p > before[k].eps_p;
    }
  }

  // The states in the layout the group works on.
  std::vector<Section::State> point_states;
  std::vector<typename Group::Block> blocks;
  const auto reset = [&] {
    if constexpr (Group::across_points) {
      blocks.assign((points + group_size - 1) / group_size, typename Group::Block{});
      for (auto& block : blocks)
        for (int g = 0; g < Group::group_size; ++g) Group::set_state_in(block, g, start);
    } else {
      point_states.assign(points, start);
    }
  };
  reset();
  Group group;
  std::size_t index = 0;
  for (auto _ : benchmark_state) {
    for (std::size_t first = 0; first < points; first += group_size) {
      group.clear();
      if constexpr (Group::across_points) group.use_block(blocks[first / group_size]);
      const std::size_t end = std::min(points, first + group_size);
      for (std::size_t p = first; p < end; ++p) {
        const std::size_t at = (index + point_stride * p) % membrane.size();
        if constexpr (Group::across_points)
          group.add(int(p - first), section, membrane[at], curvature[at]);
        else
          group.add(section, point_states[p], membrane[at], curvature[at]);
      }
      group.update(material::UpdateContext{time_step});
      for (int g = 0; g < group.size(); ++g) {
        if (group.failure(g)) benchmark_state.SkipWithError("a point's update failed");
        benchmark::DoNotOptimize(group.resultants(g));
      }
    }
    if (++index == membrane.size()) {
      index = 0;
      reset();
    }
  }
  benchmark_state.SetItemsProcessed(benchmark_state.iterations() * std::int64_t(points));
  benchmark_state.counters["ns_per_stress_point"] = benchmark::Counter(
      double(points) * 1e-9, benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kInvert);
  benchmark_state.counters["plastic_share"] = double(yielded) / double(updates);
}

// 4096 points: 512 blocks, about 0.8 MB of states (the paper plate's 2500
// stress points take about half that).
constexpr int benchmark_points = 4096;

void BM_plastic_lanes_across_points(benchmark::State& state) { BM_section_group<Lanes>(state, Loading::plastic); }
void BM_plastic_point_by_point(benchmark::State& state) { BM_section_group<PointByPoint>(state, Loading::plastic); }
void BM_elastic_lanes_across_points(benchmark::State& state) { BM_section_group<Lanes>(state, Loading::elastic); }
void BM_elastic_point_by_point(benchmark::State& state) { BM_section_group<PointByPoint>(state, Loading::elastic); }

}  // namespace

BENCHMARK(BM_plastic_lanes_across_points)->Arg(benchmark_points);
BENCHMARK(BM_plastic_point_by_point)->Arg(benchmark_points);
BENCHMARK(BM_elastic_lanes_across_points)->Arg(benchmark_points);
BENCHMARK(BM_elastic_point_by_point)->Arg(benchmark_points);

BENCHMARK_MAIN();
