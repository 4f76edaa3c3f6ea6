// The grouped material update (thickness/section_group.hpp) against the section of
// one point alone (thickness::Section::update): the same states and resultants
// for full and partial groups, points of two thicknesses, elastic and yielding
// integral points, and a failing point that leaves the others of its group as
// they would be alone; the lanes of a block that are not in the group keep
// their bits. SectionStates keeping the states in those blocks reads,
// subsets and checkpoints them as it does point by point.

// The group's lanes across points whatever the instruction set, so that they
// are tested here.
#define SPHSHELL_LANES_ACROSS_POINTS 1
#include <sphshell/io/binary_stream.hpp>
#include <sphshell/material/all.hpp>
#include <sphshell/shell/model.hpp>
#include <sphshell/thickness/section_group.hpp>
#include <sphshell/solver/section_states.hpp>
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
using sphshell::thickness::points_per_group;
using sphshell::thickness::SectionGroup;

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
  // Asked for point by point, the same group keeps the states per point.
  STATIC_REQUIRE(!SectionGroup<thickness::Gauss<5>, material::J2Plasticity, points_per_group,
                               sphshell::thickness::StateLayout::point_by_point>::across_points);
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

TEST_CASE("section states in lanes: each point's state, subsets and checkpoint bytes as point by point") {
  using sphshell::ShellModel;
  using sphshell::Vector2;
  using Law = material::J2Plasticity;
  using States = sphshell::solver::SectionStates<thickness::Gauss<5>, Law>;
  using State = States::State;
  STATIC_REQUIRE(States::in_lanes);
  const Law law{{E, nu, sigma_y0, Ep}};
  // 5 × 4 particles and 4 × 3 stress points: the particles' points start at a
  // block of their own (slot 16), the last blocks of both groups are partial.
  const ShellModel model = ShellModel::rectangular_plate(0.2, 0.1, 5, 4, 0.01);
  const std::size_t stress_points = model.stress_point_count(), particles = model.particle_count();
  REQUIRE(stress_points % points_per_group != 0);
  States states(model, law, particles);
  const std::size_t count = stress_points + particles;
  REQUIRE(states.size() == count);
  // A state of its own for every point and integral point, kept here point by point.
  std::vector<State> expected(count);
  for (std::size_t p = 0; p < count; ++p) {
    for (std::size_t k = 0; k < expected[p].size(); ++k) {
      const double x = double(p) + 0.1 * double(k);
      expected[p][k] = Law::State{StressVoigt(1e6 * x, -2e6 * x, 3e5 * x), 1e-4 * x, sigma_y0 + 1e5 * x};
    }
    states.set_state(p, expected[p]);
  }
  const auto require_states = [](const States& got, const std::vector<State>& want) {
    REQUIRE(got.size() == want.size());
    for (std::size_t p = 0; p < want.size(); ++p) {
      const State state = got.state(p);
      for (std::size_t k = 0; k < state.size(); ++k) REQUIRE(same_bits(state[k], want[p][k]));
    }
  };
  require_states(states, expected);
  // Block b of each group holds its rows b·G … b·G + G − 1 (the assembler's
  // groups are the blocks' rows).
  for (std::size_t p = 0; p < count; ++p)
    REQUIRE(states.lane_of(p) == int((p < stress_points ? p : p - stress_points) % points_per_group));
  CHECK(states.quantity(sphshell::solver::IntegralPointQuantity::equivalent_plastic_strain, 17, 3) ==
        expected[17][3].eps_p);
  CHECK(states.section(17).law().equivalent_stress(expected[17][3]) ==
        states.quantity(sphshell::solver::IntegralPointQuantity::equivalent_stress, 17, 3));

  // A subset across both groups: its points renumbered in order, the stress
  // points' first (a block boundary moves).
  const std::vector<std::size_t> picked{1, 2, 7, 9, 11, 12, 13, 20, 31};
  std::vector<State> picked_states;
  for (std::size_t p : picked) picked_states.push_back(expected[p]);
  const States part = states.subset(picked);
  require_states(part, picked_states);
  CHECK(part.lane_of(4) == 4);
  CHECK(part.lane_of(5) == 0);  // the first particle's point

  // The checkpoint holds the states point by point, then the other per-point
  // arrays (all as constructed): the same bytes as writing them directly.
  sphshell::io::BinaryWriter written, direct;
  states.save(written);
  direct(expected, std::vector<StrainVoigt>(count, StrainVoigt::Zero()), std::vector<StrainVoigt>(count, StrainVoigt::Zero()),
         std::vector<Vector2>(count, Vector2::Zero()), std::vector<Vector2>(count, Vector2::Zero()),
         std::vector<StressVoigt>(count, StressVoigt::Zero()), std::vector<StressVoigt>(count, StressVoigt::Zero()),
         std::vector<double>(count, 0.0), std::vector<unsigned char>(count, 1));
  REQUIRE(written.bytes() == direct.bytes());
  States loaded(model, law, particles);
  sphshell::io::BinaryReader reader(written.bytes(), "section states");
  loaded.load(reader);
  require_states(loaded, expected);
}
