#pragma once
// The material update of a group of integration points side by side: the
// through-thickness elastic predictor, yield check and return map of
// points_per_group points at once, in structure-of-arrays form, a lane a
// (point, integral point) pair, then the resultants of every point, eq.
// (2.8)-(2.9): T = Σ_k σ_k A_k, M = Σ_k σ_k ζ_k A_k.
//
// Lane l = k·G + g holds integral point k of the block's point g, so the
// loops over g inside a loop over k (the strain at height ζ, eq. 2.1-2.2, and
// the resultant sums) run over consecutive lanes, and the law's batched kernel
// (material/lanes.hpp, update_lanes) sees G·N lanes instead of one point's N:
// wide enough to fill the vector registers of every instruction set even for
// thin rules (Gauss<2>: 16 lanes with G = 8).
//
// Across points, the law states are not moved: solver::SectionStates (solver/section_states.hpp)
// stores them in this layout, a block of G consecutive points of a point group
// per Lanes object, and the group updates a block in place. The block's lanes
// of points that are not in the group (inactive points, rows outside the run,
// the padding after a group's last point) carry a zero increment and are given
// back their states after the kernel, bit for bit.
//
// Each point's arithmetic is that of Section<Rule, Law>::update (the same
// operations in the same order); only the vector registers they run in change,
// so results agree with the point-by-point path to round-off, and bitwise
// where the compiler contracts no multiply-adds. When the law has no batched
// kernel, is rate-dependent (it needs the step's context at every integral
// point), the section is not a stack of integral points (the resultant model
// thickness::Global), or the layout asked for is point by point
// (SPHSHELL_LANES_ACROSS_POINTS 0 by default, below), the states are
// stored point by point and every point goes through its Section's own
// update, exactly as one point alone would.

#include <sphshell/core/types.hpp>
#include <sphshell/material/lanes.hpp>
#include <sphshell/material/material.hpp>
#include <sphshell/thickness/section.hpp>

#include <array>
#include <cstddef>
#include <exception>
#include <type_traits>

// Whether the grouped assembler stores the law states in lanes across points
// and updates them there (1), or point by point (0). By default as a section
// alone (SPHSHELL_BATCHED_SECTIONS, thickness/section.hpp: with AVX-512):
// with AVX2 the lanes, even with the states kept in them, measured no faster
// than the point-by-point update (docs/performance.md, "Batched material
// updates"). Define it (alike in every translation unit) before including to
// force either.
#ifndef SPHSHELL_LANES_ACROSS_POINTS
#define SPHSHELL_LANES_ACROSS_POINTS SPHSHELL_BATCHED_SECTIONS
#endif

namespace sphshell::thickness {

// The layout a SectionGroup asks for: the law states in lanes across points
// (taken where the law and section allow it, see SectionGroup::across_points)
// or point by point. The default follows SPHSHELL_LANES_ACROSS_POINTS; a
// program may name either explicitly to hold the two side by side (the
// benchmark bench/bench_section_group.cpp does).
enum class StateLayout { point_by_point, lanes_across_points };
inline constexpr StateLayout default_state_layout =
    SPHSHELL_LANES_ACROSS_POINTS != 0 ? StateLayout::lanes_across_points : StateLayout::point_by_point;

// Integration points the assembler integrates side by side. Eight points fill
// an AVX-512 register per integral point of the rule (and two AVX2 or four
// SSE2 registers); other sizes are yet to be measured against it.
inline constexpr int points_per_group = 8;

// Whether thickness::Section<Rule, Law> is the primary template (a stack of
// num_points ≥ 1 integral points with ζ_k and weights A_k, State an array of
// the law's states) whose update the group may run across points.
template <class Rule, class Law>
inline constexpr bool layered_section_v =
    thickness::Section<Rule, Law>::num_points >= 1 &&
    std::is_same_v<typename thickness::Section<Rule, Law>::State,
                   std::array<typename Law::State, std::size_t(thickness::Section<Rule, Law>::num_points)>>;

template <class Rule, class Law, int G = points_per_group, StateLayout Layout = default_state_layout>
class SectionGroup {
  static_assert(G >= 1, "sphshell::thickness::SectionGroup<Rule, Law, G>: G must be at least 1");

  template <bool, int L>
  struct LanesOf {
    struct type {};
  };
  template <int L>
  struct LanesOf<true, L> {
    using type = typename Law::template Lanes<L>;
  };

 public:
  using Section = thickness::Section<Rule, Law>;
  using State = typename Section::State;
  static constexpr int group_size = G;
  // Integral points per point (1 for a section that is not a stack of them).
  static constexpr int integral_points = layered_section_v<Rule, Law> ? Section::num_points : 1;

  // Whether the group runs its points' integral points through the law's
  // batched kernel together, on states stored in lanes (Block); otherwise
  // point by point through Section::update, on states stored per point.
  static constexpr bool across_points = [] {
    if constexpr (layered_section_v<Rule, Law>)
      return Layout == StateLayout::lanes_across_points && !material::is_rate_dependent_v<Law> &&
             material::has_update_lanes_v<Law, G * Section::num_points>;
    else
      return false;
  }();

  // The states of a block of G points in lanes: integral point k of the
  // block's point g at lane k·G + g (an empty type when not across_points).
  static constexpr int lane_count = across_points ? G * integral_points : 1;
  using Block = typename LanesOf<across_points, lane_count>::type;

  // Point g's state in a block, and the same written back.
  static State state_in(const Block& block, int g) {
    static_assert(across_points, "SectionGroup::state_in: only blocks of lanes across points hold states");
    State state;
    for (std::size_t k = 0; k < std::size_t(integral_points); ++k) state[k] = block.state(int(k) * G + g);
    return state;
  }
  static void set_state_in(Block& block, int g, const State& state) {
    static_assert(across_points, "SectionGroup::set_state_in: only blocks of lanes across points hold states");
    for (std::size_t k = 0; k < std::size_t(integral_points); ++k) block.set_state(int(k) * G + g, state[k]);
  }

  void clear() {
    count_ = 0;
    block_ = nullptr;
  }
  int size() const { return count_; }
  bool full() const { return count_ == G; }

  // Point by point (not across_points): adds a point, its section, its state
  // (updated in place by update()) and its strain increments. Returns its
  // index in the group.
  int add(const Section& section, State& state, const StrainVoigt& d_membrane, const StrainVoigt& d_curvature) {
    static_assert(!across_points, "SectionGroup::add(section, state, ...): across points, states live in a "
                                  "Block; call use_block() and add(lane, section, ...)");
    const int g = count_++;
    section_[std::size_t(g)] = &section;
    state_[std::size_t(g)] = &state;
    d_membrane_[std::size_t(g)] = d_membrane;
    d_curvature_[std::size_t(g)] = d_curvature;
    return g;
  }

  // Across points: the block whose points the next add() calls name (after
  // clear()), and a point of it, by its place `lane` in the block (0 ≤ lane
  // < G, each at most once), with its section and strain increments.
  // Returns its index in the group.
  void use_block(Block& block) {
    static_assert(across_points, "SectionGroup::use_block: only across points");
    block_ = &block;
  }
  int add(int lane, const Section& section, const StrainVoigt& d_membrane, const StrainVoigt& d_curvature) {
    static_assert(across_points, "SectionGroup::add(lane, section, ...): only across points; point by point, "
                                 "call add(section, state, ...)");
    const int g = count_++;
    lane_[std::size_t(g)] = lane;
    section_[std::size_t(g)] = &section;
    d_membrane_[std::size_t(g)] = d_membrane;
    d_curvature_[std::size_t(g)] = d_curvature;
    return g;
  }

  // Updates every point's state and forms its resultants. A point whose
  // update throws gets its exception in failure(g) and no resultants (its
  // state is left as Section::update leaves it when it throws); the others are
  // updated as if it were not there.
  void update([[maybe_unused]] const material::UpdateContext& context) {
    for (int g = 0; g < count_; ++g) failure_[std::size_t(g)] = nullptr;
    if constexpr (across_points) {
      if (count_ == 0) return;
      try {
        update_across_points();
        return;
      } catch (...) {
        // The kernel leaves every lane as it was when it throws
        // (material/lanes.hpp): redo the points one by one, which finds the
        // failing ones and updates the others.
      }
      for (int g = 0; g < count_; ++g) {
        const int lane = lane_[std::size_t(g)];
        State state = state_in(*block_, lane);
        try {
          resultants_[std::size_t(g)] = section_[std::size_t(g)]->update(state, d_membrane_[std::size_t(g)],
                                                                          d_curvature_[std::size_t(g)]);
        } catch (...) {
          failure_[std::size_t(g)] = std::current_exception();
        }
        set_state_in(*block_, lane, state);
      }
    } else {
      for (int g = 0; g < count_; ++g) {
        try {
          resultants_[std::size_t(g)] = update_one(g, context);
        } catch (...) {
          failure_[std::size_t(g)] = std::current_exception();
        }
      }
    }
  }

  const std::exception_ptr& failure(int g) const { return failure_[std::size_t(g)]; }
  const thickness::Resultants& resultants(int g) const { return resultants_[std::size_t(g)]; }

 private:
  thickness::Resultants update_one(int g, const material::UpdateContext& context) const {
    const Section& section = *section_[std::size_t(g)];
    State& state = *state_[std::size_t(g)];
    const StrainVoigt& d_membrane = d_membrane_[std::size_t(g)];
    const StrainVoigt& d_curvature = d_curvature_[std::size_t(g)];
    if constexpr (material::is_rate_dependent_v<Law>)
      return section.update(state, d_membrane, d_curvature, context);
    else
      return section.update(state, d_membrane, d_curvature);
  }

  void update_across_points() {
    if constexpr (across_points) {
      constexpr std::size_t n = std::size_t(N), group = std::size_t(G);
      Block& block = *block_;
      // Per lane: ζ_k and A_k of its point's section (kept from the last
      // block while the lane's section is the same) and the strain increment
      // Δε(ζ_k) = Δe + ζ_k Δκ, component by component as Section::update
      // forms it. Lanes of points not in the group: a zero increment.
      alignas(64) std::array<double, group> dm_xx{}, dm_yy{}, dm_xy{}, dk_xx{}, dk_yy{}, dk_xy{};
      std::array<bool, group> used{};
      for (std::size_t m = 0; m < std::size_t(count_); ++m) {
        const std::size_t g = std::size_t(lane_[m]);
        used[g] = true;
        const Section& section = *section_[m];
        if (lane_section_[g] != &section) {
          lane_section_[g] = &section;
          for (std::size_t k = 0; k < n; ++k) {
            zeta_[k * group + g] = section.zeta(int(k));
            weight_[k * group + g] = section.weight(int(k));
          }
        }
        dm_xx[g] = d_membrane_[m].x();
        dm_yy[g] = d_membrane_[m].y();
        dm_xy[g] = d_membrane_[m].z();
        dk_xx[g] = d_curvature_[m].x();
        dk_yy[g] = d_curvature_[m].y();
        dk_xy[g] = d_curvature_[m].z();
      }
      for (std::size_t k = 0; k < n; ++k)
        for (std::size_t g = 0; g < group; ++g) {
          const std::size_t l = k * group + g;
          d_strain_.xx[l] = dm_xx[g] + zeta_[l] * dk_xx[g];
          d_strain_.yy[l] = dm_yy[g] + zeta_[l] * dk_yy[g];
          d_strain_.xy[l] = dm_xy[g] + zeta_[l] * dk_xy[g];
        }
      // A zero increment may still change a lane's bits (−0 + 0 is +0, a
      // state on the yield surface may return again): the lanes not in the
      // group are kept aside and given back.
      const bool some_unused = count_ < G;
      if (some_unused)
        for (std::size_t g = 0; g < group; ++g)
          if (!used[g])
            for (std::size_t k = 0; k < n; ++k) kept_[k * group + g] = block.state(int(k * group + g));
      // Every section of a SectionStates holds the same law.
      section_[0]->law().update_lanes(block, d_strain_);
      if (some_unused)
        for (std::size_t g = 0; g < group; ++g)
          if (!used[g])
            for (std::size_t k = 0; k < n; ++k) block.set_state(int(k * group + g), kept_[k * group + g]);
      // The resultants, each point's sums in the order of Section::resultants.
      alignas(64) std::array<double, group> t_xx{}, t_yy{}, t_xy{}, m_xx{}, m_yy{}, m_xy{};
      for (std::size_t k = 0; k < n; ++k)
        for (std::size_t g = 0; g < group; ++g) {
          const std::size_t l = k * group + g;
          const double w = weight_[l], w_zeta = weight_[l] * zeta_[l];
          t_xx[g] += w * block.stress.xx[l];
          t_yy[g] += w * block.stress.yy[l];
          t_xy[g] += w * block.stress.xy[l];
          m_xx[g] += w_zeta * block.stress.xx[l];
          m_yy[g] += w_zeta * block.stress.yy[l];
          m_xy[g] += w_zeta * block.stress.xy[l];
        }
      for (std::size_t m = 0; m < std::size_t(count_); ++m) {
        const std::size_t g = std::size_t(lane_[m]);
        resultants_[m] = thickness::Resultants{StressVoigt(t_xx[g], t_yy[g], t_xy[g]),
                                               StressVoigt(m_xx[g], m_yy[g], m_xy[g])};
      }
    }
  }

  static constexpr int N = integral_points;
  // Across points (one per group object, so that a run of blocks sets them
  // up once): ζ_k and A_k per lane with the section they came from, the
  // strain increments, and the states of lanes outside the group.
  alignas(64) std::array<double, std::size_t(lane_count)> zeta_{}, weight_{};
  std::array<const Section*, std::size_t(G)> lane_section_{};
  material::VoigtLanes<lane_count> d_strain_;
  std::array<typename Law::State, std::size_t(lane_count)> kept_;
  Block* block_ = nullptr;
  std::array<int, std::size_t(G)> lane_{};

  int count_ = 0;
  std::array<const Section*, std::size_t(G)> section_{};
  std::array<State*, std::size_t(G)> state_{};
  std::array<StrainVoigt, std::size_t(G)> d_membrane_, d_curvature_;
  std::array<thickness::Resultants, std::size_t(G)> resultants_;
  std::array<std::exception_ptr, std::size_t(G)> failure_;
};

}  // namespace sphshell::thickness
