// The grouped material update (solver/section_group.hpp) against the section of
// one point alone (thickness::Section::update): the same states and resultants
// for full and partial groups, points of two thicknesses, elastic and yielding
// integral points, and a failing point that leaves the others of its group as
// they would be alone; the lanes of a block that are not in the group keep
// their bits.

// The group's lanes across points whatever the instruction set, so that they
// are tested here.
#define SPHSHELL_LANES_ACROSS_POINTS 1
#include <sphshell/material/all.hpp>
#include <sphshell/solver/section_group.hpp>
#include <sphshell/thickness/all.hpp>

#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstring>
#include <limits>
#include <random>
#include <vector>

namespace {

using sphshell::StrainVoigt;
using sphshell::StressVoigt;
namespace material = sphshell::material;
namespace thickness = sphshell::thickness;
using sphshell::solver::points_per_group;
using sphshell::solver::SectionGroup;

constexpr double E = 210e9, nu = 0.3, sigma_y0 = 235e6, Ep = 2e9;
// Agreement to round-off: the group runs the same operations in vector
// registers, where the compiler may contract multiply-adds.
constexpr double relative_round_off = 1e-12;

double scale_of(const StressVoigt& a) { return std::max(a.cwiseAbs().maxCoeff(), 1.0); }

template <class Rule, class Law>
void require_same_section_state(const typename thickness::Section<Rule, Law>::State& group_state,
                                const typename thickness::Section<Rule, Law>::State& alone_state) {
  for (std::size_t k = 0; k < group_state.size(); ++k) {
    const StressVoigt difference = group_state[k].stress - alone_state[k].stress;
    REQUIRE(difference.cwiseAbs().maxCoeff() <= relative_round_off * scale_of(alone_state[k].stress));
    if constexpr (std::is_same_v<Law, material::J2Plasticity>) {
      REQUIRE(std::abs(group_state[k].eps_p - alone_state[k].eps_p) <=
              relative_round_off * std::max(alone_state[k].eps_p, 1e-6));
      REQUIRE(std::abs(group_state[k].sigma_y - alone_state[k].sigma_y) <= relative_round_off * alone_state[k].sigma_y);
    }
  }
}

void require_same_resultants(const thickness::Resultants& group, const thickness::Resultants& alone) {
  REQUIRE((group.membrane - alone.membrane).cwiseAbs().maxCoeff() <= relative_round_off * scale_of(alone.membrane));
  REQUIRE((group.moment - alone.moment).cwiseAbs().maxCoeff() <= relative_round_off * scale_of(alone.moment));
}

// The lanes of a block that `count` points take: spread over the block, so
// that a partial group leaves lanes before, between and after its points.
int lane_of_member(int g, int count) { return g * points_per_group / count; }

// Bitwise equality of two J2 states (−0 and +0 differ).
bool same_bits(const material::J2Plasticity::State& a, const material::J2Plasticity::State& b) {
  const double fields_a[5] = {a.stress.x(), a.stress.y(), a.stress.z(), a.eps_p, a.sigma_y};
  const double fields_b[5] = {b.stress.x(), b.stress.y(), b.stress.z(), b.eps_p, b.sigma_y};
  return std::memcmp(fields_a, fields_b, sizeof fields_a) == 0;
}

// Steps of random membrane and curvature increments on `count` points (two
// thicknesses, alternating), updated by the group in a block of lanes and,
// independently, point by point; returns how many integral-point updates
// yielded (so a test can require that the return map was exercised).
template <class Rule, class Law>
int compare_over_steps(const Law& law, int count, int steps) {
  using Section = thickness::Section<Rule, Law>;
  using Group = SectionGroup<Rule, Law>;
  const Section thin(law, 0.008), thick(law, 0.012);
  std::vector<const Section*> section(static_cast<std::size_t>(count));
  for (int g = 0; g < count; ++g) section[std::size_t(g)] = g % 2 == 0 ? &thin : &thick;
  typename Group::Block block;
  for (int g = 0; g < points_per_group; ++g) Group::set_state_in(block, g, thin.initial_state());
  std::vector<typename Section::State> alone(std::size_t(count), thin.initial_state());
  std::mt19937_64 random(20261207);
  // Strain increments of about 1e-4, curvatures of about 1e-2 1/m: a few steps
  // take the outer integral points past the 235 MPa yield stress (about 1.1e-3).
  std::uniform_real_distribution<double> strain(-2e-4, 3e-4), curvature(-2e-2, 3e-2);
  int yielded = 0;
  // One group object over the steps, as the assembler keeps one over a run's blocks.
  Group group;
  for (int step = 0; step < steps; ++step) {
    group.clear();
    group.use_block(block);
    std::vector<StrainVoigt> d_membrane(static_cast<std::size_t>(count)), d_curvature(static_cast<std::size_t>(count));
    for (int g = 0; g < count; ++g) {
      d_membrane[std::size_t(g)] = StrainVoigt(strain(random), strain(random), strain(random));
      d_curvature[std::size_t(g)] = StrainVoigt(curvature(random), curvature(random), curvature(random));
      REQUIRE(group.add(lane_of_member(g, count), *section[std::size_t(g)], d_membrane[std::size_t(g)],
                        d_curvature[std::size_t(g)]) == g);
    }
    group.update(material::UpdateContext{1e-6});
    for (int g = 0; g < count; ++g) {
      REQUIRE(!group.failure(g));
      const auto before = alone[std::size_t(g)];
      const thickness::Resultants reference =
          section[std::size_t(g)]->update(alone[std::size_t(g)], d_membrane[std::size_t(g)], d_curvature[std::size_t(g)]);
      require_same_section_state<Rule, Law>(Group::state_in(block, lane_of_member(g, count)), alone[std::size_t(g)]);
      require_same_resultants(group.resultants(g), reference);
      if constexpr (std::is_same_v<Law, material::J2Plasticity>)
        for (std::size_t k = 0; k < before.size(); ++k) yielded += alone[std::size_t(g)][k].eps_p > before[k].eps_p;
    }
  }
  return yielded;
}

}  // namespace

TEST_CASE("section group: J2 through Gauss<5>, a full group and a partial one, agree with each point alone") {
  const material::J2Plasticity law{{E, nu, sigma_y0, Ep}};
  STATIC_REQUIRE(SectionGroup<thickness::Gauss<5>, material::J2Plasticity>::across_points);
  CHECK(compare_over_steps<thickness::Gauss<5>>(law, points_per_group, 12) > 20);
  CHECK(compare_over_steps<thickness::Gauss<5>>(law, points_per_group - 1, 12) > 20);
  CHECK(compare_over_steps<thickness::Gauss<5>>(law, 3, 12) > 5);
  CHECK(compare_over_steps<thickness::Gauss<5>>(law, 1, 12) > 0);
}

TEST_CASE("section group: Simpson<3> with J2 and Gauss<2> with the elastic law agree with each point alone") {
  const material::J2Plasticity plastic{{E, nu, sigma_y0, Ep}};
  CHECK(compare_over_steps<thickness::Simpson<3>>(plastic, points_per_group, 10) > 10);
  const material::Elastic elastic{{E, nu}};
  STATIC_REQUIRE(SectionGroup<thickness::Gauss<2>, material::Elastic>::across_points);
  compare_over_steps<thickness::Gauss<2>>(elastic, 5, 6);
}

TEST_CASE("section group: the resultant model Global goes point by point, bitwise as alone") {
  const material::J2Plasticity law{{E, nu, sigma_y0, Ep}};
  STATIC_REQUIRE(!SectionGroup<thickness::Global, material::J2Plasticity>::across_points);
  const thickness::Section<thickness::Global, material::J2Plasticity> section(law, 0.01);
  auto grouped = section.initial_state(), alone = section.initial_state();
  const StrainVoigt d_membrane(1e-3, -4e-4, 2e-4), d_curvature(0.05, -0.02, 0.01);
  for (int step = 0; step < 4; ++step) {
    SectionGroup<thickness::Global, material::J2Plasticity> group;
    group.add(section, grouped, d_membrane, d_curvature);
    group.update(material::UpdateContext{1e-6});
    const thickness::Resultants reference = section.update(alone, d_membrane, d_curvature);
    REQUIRE(group.resultants(0).membrane == reference.membrane);
    REQUIRE(group.resultants(0).moment == reference.moment);
  }
}

TEST_CASE("section group: a point with a non-finite increment fails alone; the others update as alone") {
  const material::J2Plasticity law{{E, nu, sigma_y0, Ep}};
  using Section = thickness::Section<thickness::Gauss<5>, material::J2Plasticity>;
  using Group = SectionGroup<thickness::Gauss<5>, material::J2Plasticity>;
  const Section section(law, 0.01);
  constexpr int count = 4, failing = 2;
  Group::Block block;
  for (int g = 0; g < points_per_group; ++g) Group::set_state_in(block, g, section.initial_state());
  std::vector<Section::State> alone(count, section.initial_state());
  Group group;
  group.use_block(block);
  std::vector<StrainVoigt> d_membrane(count), d_curvature(count);
  for (int g = 0; g < count; ++g) {
    // Large enough that the outer integral points yield.
    d_membrane[std::size_t(g)] = StrainVoigt(1e-3 * (g + 1), -5e-4, 3e-4);
    d_curvature[std::size_t(g)] = StrainVoigt(0.3, 0.1 * g, -0.05);
  }
  d_membrane[failing].y() = std::numeric_limits<double>::quiet_NaN();
  for (int g = 0; g < count; ++g)
    group.add(lane_of_member(g, count), section, d_membrane[std::size_t(g)], d_curvature[std::size_t(g)]);
  group.update(material::UpdateContext{1e-6});
  for (int g = 0; g < count; ++g) {
    if (g == failing) {
      REQUIRE(group.failure(g));
      REQUIRE_THROWS_AS(std::rethrow_exception(group.failure(g)), sphshell::Error);
      continue;
    }
    REQUIRE(!group.failure(g));
    const thickness::Resultants reference =
        section.update(alone[std::size_t(g)], d_membrane[std::size_t(g)], d_curvature[std::size_t(g)]);
    require_same_section_state<thickness::Gauss<5>, material::J2Plasticity>(
        Group::state_in(block, lane_of_member(g, count)), alone[std::size_t(g)]);
    require_same_resultants(group.resultants(g), reference);
    REQUIRE(std::any_of(alone[std::size_t(g)].begin(), alone[std::size_t(g)].end(),
                        [](const material::J2Plasticity::State& state) { return state.eps_p > 0.0; }));
  }
}

TEST_CASE("section group: the lanes of a block outside the group keep their bits") {
  // States a zero increment would change: a −0 stress component (−0 + 0 is
  // +0) and a stress a little outside the yield surface (it would return).
  const material::J2Plasticity law{{E, nu, sigma_y0, Ep}};
  using Section = thickness::Section<thickness::Gauss<5>, material::J2Plasticity>;
  using Group = SectionGroup<thickness::Gauss<5>, material::J2Plasticity>;
  const Section section(law, 0.01);
  Section::State outside = section.initial_state();
  for (auto& state : outside) state.stress = StressVoigt(-0.0, 1.001 * sigma_y0, 0.0);
  Group::Block block;
  for (int g = 0; g < points_per_group; ++g) Group::set_state_in(block, g, outside);
  // The points at lanes 1 and 6 are in the group; every other lane is not.
  Group group;
  group.use_block(block);
  group.add(1, section, StrainVoigt(1e-3, 0.0, 0.0), StrainVoigt(0.1, 0.0, 0.0));
  group.add(6, section, StrainVoigt(-1e-3, 0.0, 0.0), StrainVoigt(0.0, 0.1, 0.0));
  group.update(material::UpdateContext{1e-6});
  for (int lane = 0; lane < points_per_group; ++lane) {
    INFO("lane " << lane);
    const Section::State state = Group::state_in(block, lane);
    bool unchanged = true;
    for (std::size_t k = 0; k < state.size(); ++k) unchanged = unchanged && same_bits(state[k], outside[k]);
    CHECK(unchanged == (lane != 1 && lane != 6));
  }
}

TEST_CASE("section group: one group over blocks of other thicknesses takes each point's heights and weights") {
  // As the assembler keeps one group over a run's blocks: the lanes' ζ_k and
  // A_k kept from the last block must follow each point's own section.
  const material::J2Plasticity law{{E, nu, sigma_y0, Ep}};
  using Section = thickness::Section<thickness::Gauss<5>, material::J2Plasticity>;
  using Group = SectionGroup<thickness::Gauss<5>, material::J2Plasticity>;
  const Section thin(law, 0.008), thick(law, 0.012);
  Group group;
  for (int block_index = 0; block_index < 3; ++block_index) {
    INFO("block " << block_index);
    Group::Block block;
    for (int g = 0; g < points_per_group; ++g) Group::set_state_in(block, g, thin.initial_state());
    group.clear();
    group.use_block(block);
    std::vector<Section::State> alone(std::size_t(points_per_group), thin.initial_state());
    std::vector<const Section*> section(static_cast<std::size_t>(points_per_group));
    const StrainVoigt d_membrane(4e-4, -1e-4, 2e-4), d_curvature(0.2, -0.1, 0.05);
    for (int g = 0; g < points_per_group; ++g) {
      section[std::size_t(g)] = (g + block_index) % 2 == 0 ? &thin : &thick;
      group.add(g, *section[std::size_t(g)], d_membrane, d_curvature);
    }
    group.update(material::UpdateContext{1e-6});
    for (int g = 0; g < points_per_group; ++g) {
      const thickness::Resultants reference = section[std::size_t(g)]->update(alone[std::size_t(g)], d_membrane, d_curvature);
      require_same_section_state<thickness::Gauss<5>, material::J2Plasticity>(Group::state_in(block, g),
                                                                               alone[std::size_t(g)]);
      require_same_resultants(group.resultants(g), reference);
    }
  }
}
