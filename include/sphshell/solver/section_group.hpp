#pragma once
// The material update of a group of integration points side by side: the
// through-thickness elastic predictor, yield check and return map of
// points_per_group points at once, in structure-of-arrays form, a lane a
// (point, integral point) pair, then the resultants of every point, eq.
// (2.8)-(2.9): T = Σ_k σ_k A_k, M = Σ_k σ_k ζ_k A_k.
//
// Lane l = k·G + g holds integral point k of the group's point g, so the
// loops over g inside a loop over k (the strain at height ζ, eq. 2.1-2.2, and
// the resultant sums) run over consecutive lanes, and the law's batched kernel
// (material/lanes.hpp, update_lanes) sees G·N lanes instead of one point's N:
// wide enough to fill the vector registers of every instruction set even for
// thin rules (Gauss<2>: 16 lanes with G = 8).
//
// A point alone is the group of one (the assembler's last, partial group of a
// run): the unused lanes carry a zero increment on a copy of the first
// point's state and are never written back.
//
// Each point's arithmetic is that of Section<Rule, Law>::update (the same
// operations in the same order); only the vector registers they run in change,
// so results agree with the point-by-point path to round-off, and bitwise
// where the compiler contracts no multiply-adds. When the law has no batched
// kernel, is rate-dependent (it needs the step's context at every integral
// point), the section is not a stack of integral points (the resultant model
// thickness::Global), or SPHSHELL_BATCHED_SECTIONS is 0 (the default below
// AVX-512), every point goes through its Section's own update, exactly as one
// point alone would.

#include <sphshell/core/types.hpp>
#include <sphshell/material/lanes.hpp>
#include <sphshell/material/material.hpp>
#include <sphshell/thickness/section.hpp>

#include <array>
#include <cstddef>
#include <exception>
#include <type_traits>

namespace sphshell::solver {

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

template <class Rule, class Law, int G = points_per_group>
class SectionGroup {
 public:
  using Section = thickness::Section<Rule, Law>;
  using State = typename Section::State;
  static constexpr int group_size = G;

  // Whether the group runs its points' integral points through the law's
  // batched kernel together; otherwise point by point through Section::update.
  // SPHSHELL_BATCHED_SECTIONS (thickness/section.hpp) decides as it does for
  // one point: moving the states, stored point by point, into lanes and back
  // costs what the kernel saves unless the vector units are wide (with AVX2
  // the group's lanes measured slower than its points one by one;
  // docs/performance-history.md).
  static constexpr bool across_points = [] {
    if constexpr (layered_section_v<Rule, Law>)
      return SPHSHELL_BATCHED_SECTIONS != 0 && !material::is_rate_dependent_v<Law> &&
             material::has_update_lanes_v<Law, G * Section::num_points>;
    else
      return false;
  }();

  void clear() { count_ = 0; }
  int size() const { return count_; }
  bool full() const { return count_ == G; }

  // Adds a point: its section, its state (updated in place by update()) and
  // its strain increments. Returns its index in the group.
  int add(const Section& section, State& state, const StrainVoigt& d_membrane, const StrainVoigt& d_curvature) {
    const int g = count_++;
    section_[std::size_t(g)] = &section;
    state_[std::size_t(g)] = &state;
    d_membrane_[std::size_t(g)] = d_membrane;
    d_curvature_[std::size_t(g)] = d_curvature;
    return g;
  }

  // Updates every point's state and forms its resultants. A point whose
  // update throws gets its exception in failure(g) and no resultants (its
  // state is left as Section::update leaves it when it throws); the others are
  // updated as if it were not there.
  void update(const material::UpdateContext& context) {
    for (int g = 0; g < count_; ++g) failure_[std::size_t(g)] = nullptr;
    if constexpr (across_points) {
      try {
        update_across_points();
        return;
      } catch (...) {
        // Nothing was written back: redo the points one by one, which finds
        // the failing ones and updates the others.
      }
    }
    for (int g = 0; g < count_; ++g) {
      try {
        resultants_[std::size_t(g)] = update_one(g, context);
      } catch (...) {
        failure_[std::size_t(g)] = std::current_exception();
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
      // Per lane: ζ_k and A_k of its point's section and the strain increment
      // Δε(ζ_k) = Δe + ζ_k Δκ, component by component as Section::update forms
      // it; the states into lanes. Unused lanes: a zero increment on the first
      // point's state, never written back.
      alignas(64) std::array<double, group> dm_xx, dm_yy, dm_xy, dk_xx, dk_yy, dk_xy;
      for (std::size_t g = 0; g < group; ++g) {
        const bool used = g < std::size_t(count_);
        const Section& section = *section_[used ? g : 0];
        const State& state = *state_[used ? g : 0];
        for (std::size_t k = 0; k < n; ++k) {
          zeta_[k * group + g] = section.zeta(int(k));
          weight_[k * group + g] = section.weight(int(k));
          lanes_.set_state(int(k * group + g), state[k]);
        }
        const StrainVoigt zero = StrainVoigt::Zero();
        const StrainVoigt& d_membrane = used ? d_membrane_[g] : zero;
        const StrainVoigt& d_curvature = used ? d_curvature_[g] : zero;
        dm_xx[g] = d_membrane.x();
        dm_yy[g] = d_membrane.y();
        dm_xy[g] = d_membrane.z();
        dk_xx[g] = d_curvature.x();
        dk_yy[g] = d_curvature.y();
        dk_xy[g] = d_curvature.z();
      }
      for (std::size_t k = 0; k < n; ++k)
        for (std::size_t g = 0; g < group; ++g) {
          const std::size_t l = k * group + g;
          d_strain_.xx[l] = dm_xx[g] + zeta_[l] * dk_xx[g];
          d_strain_.yy[l] = dm_yy[g] + zeta_[l] * dk_yy[g];
          d_strain_.xy[l] = dm_xy[g] + zeta_[l] * dk_xy[g];
        }
      // Every section of a SectionStates holds the same law.
      section_[0]->law().update_lanes(lanes_, d_strain_);
      for (std::size_t g = 0; g < std::size_t(count_); ++g) {
        State& state = *state_[g];
        for (std::size_t k = 0; k < n; ++k) state[k] = lanes_.state(int(k * group + g));
      }
      // The resultants, each point's sums in the order of Section::resultants.
      alignas(64) std::array<double, group> t_xx{}, t_yy{}, t_xy{}, m_xx{}, m_yy{}, m_xy{};
      for (std::size_t k = 0; k < n; ++k)
        for (std::size_t g = 0; g < group; ++g) {
          const std::size_t l = k * group + g;
          const double w = weight_[l], w_zeta = weight_[l] * zeta_[l];
          t_xx[g] += w * lanes_.stress.xx[l];
          t_yy[g] += w * lanes_.stress.yy[l];
          t_xy[g] += w * lanes_.stress.xy[l];
          m_xx[g] += w_zeta * lanes_.stress.xx[l];
          m_yy[g] += w_zeta * lanes_.stress.yy[l];
          m_xy[g] += w_zeta * lanes_.stress.xy[l];
        }
      for (std::size_t g = 0; g < std::size_t(count_); ++g)
        resultants_[g] = thickness::Resultants{StressVoigt(t_xx[g], t_yy[g], t_xy[g]),
                                               StressVoigt(m_xx[g], m_yy[g], m_xy[g])};
    }
  }

  // The lanes of the batched update: G·N when the group runs across points
  // (one per group object, so that a run of groups sets them up once).
  static constexpr int N = layered_section_v<Rule, Law> ? Section::num_points : 1;
  static constexpr int lane_count = across_points ? G * N : 1;
  template <bool, int L>
  struct LanesOf {
    struct type {};
  };
  template <int L>
  struct LanesOf<true, L> {
    using type = typename Law::template Lanes<L>;
  };
  using LawLanes = typename LanesOf<across_points, lane_count>::type;
  alignas(64) std::array<double, std::size_t(lane_count)> zeta_, weight_;
  material::VoigtLanes<lane_count> d_strain_;
  LawLanes lanes_;

  int count_ = 0;
  std::array<const Section*, std::size_t(G)> section_{};
  std::array<State*, std::size_t(G)> state_{};
  std::array<StrainVoigt, std::size_t(G)> d_membrane_, d_curvature_;
  std::array<thickness::Resultants, std::size_t(G)> resultants_;
  std::array<std::exception_ptr, std::size_t(G)> failure_;
};

}  // namespace sphshell::solver
