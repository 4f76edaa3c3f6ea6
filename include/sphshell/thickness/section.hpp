#pragma once
// Section<Rule, Law>: the material state of one stress point through the thickness
// and its integration into resultants, eq. (2.8)-(2.9):
//   T = Σ_k σ_k A_k,   M = Σ_k σ_k ζ_k A_k.
// This primary template serves every integral rule (Gauss<N>, Simpson<N>); global.hpp
// specializes it for the resultant model Global. The strain at height ζ is the
// mid-surface strain plus ζ times the curvature (eq. 2.1-2.2, linear part), so a
// curvature κ > 0 stretches the fibres at ζ > 0.

#include <sphshell/core/error.hpp>
#include <sphshell/core/types.hpp>
#include <sphshell/material/lanes.hpp>
#include <sphshell/material/material.hpp>
#include <sphshell/thickness/thickness.hpp>

#include <array>
#include <cstddef>

// Whether Section<Rule, Law>::update batches its integral points through the
// law's update_lanes (material/lanes.hpp). Both paths give the same bits,
// unless the compiler fuses multiply-adds (FMA) in one and not the other
// (last-bit differences). The batched one pays for gathering the states into lanes, scattering them back
// and returning every lane when one yields, which the vector units repay only
// when they are wide: by default it is taken with AVX-512 and not otherwise
// (docs/performance.md, "Batched material updates"). Define SPHSHELL_BATCHED_SECTIONS to 1 or 0 before
// including to force either path.
#ifndef SPHSHELL_BATCHED_SECTIONS
#if defined(__AVX512F__)
#define SPHSHELL_BATCHED_SECTIONS 1
#else
#define SPHSHELL_BATCHED_SECTIONS 0
#endif
#endif

namespace sphshell::thickness {

template <class Rule, class Law>
class Section {
  static_assert(check_thickness_rule<Rule>());
  static_assert(Rule::num_points >= 1,
                "sphshell::thickness::Section: a rule with num_points = 0 needs its own "
                "Section; add `template <class Law> class Section<YourRule, Law>` as global.hpp does");

 public:
  static constexpr int num_points = Rule::num_points;
  static constexpr int output_points = Rule::num_points;
  // Contiguous per stress point so the loop over integral points stays in cache.
  using State = std::array<typename Law::State, std::size_t(num_points)>;
  // Whether update() takes the law's batched path.
  static constexpr bool batched = SPHSHELL_BATCHED_SECTIONS != 0 && material::has_update_lanes_v<Law, num_points> &&
                                  !material::is_rate_dependent_v<Law>;

  Section(const Law& law, double thickness) : law_(law), thickness_(thickness) {
    sphshell::detail::require_positive("thickness", thickness);
    for (int k = 0; k < num_points; ++k) {
      zeta_[std::size_t(k)] = Rule::zeta(k, thickness);
      weight_[std::size_t(k)] = Rule::weight(k, thickness);
    }
  }

  State initial_state() const {
    State state;
    state.fill(law_.initial_state());
    return state;
  }

  // Δε(ζ_k) = Δe + ζ_k Δκ at every integral point (Voigt, engineering shear), then the
  // new total resultants.
  // Batched (see SPHSHELL_BATCHED_SECTIONS above), the N points go through
  // the law's update_lanes at once: the increments are formed component by component into
  // structure-of-arrays form, the states gathered and scattered back. Without
  // FMA contraction the result is bitwise that of the point-by-point loop below.
  Resultants update(State& state, const StrainVoigt& d_membrane_strain,
                    const StrainVoigt& d_curvature) const {
    if constexpr (batched) {
      material::VoigtLanes<num_points> d_strain;
      for (std::size_t k = 0; k < std::size_t(num_points); ++k) {
        d_strain.xx[k] = d_membrane_strain.x() + zeta_[k] * d_curvature.x();
        d_strain.yy[k] = d_membrane_strain.y() + zeta_[k] * d_curvature.y();
        d_strain.xy[k] = d_membrane_strain.z() + zeta_[k] * d_curvature.z();
      }
      material::update_lanes<Law, num_points>(law_, state, d_strain);
    } else {
      for (int k = 0; k < num_points; ++k) {
        const StrainVoigt d_strain = d_membrane_strain + zeta_[std::size_t(k)] * d_curvature;
        law_.update(state[std::size_t(k)], d_strain);
      }
    }
    return resultants(state);
  }

  // The same with the step's context (material.hpp): a rate-dependent law
  // gets it at every integral point; every other law is updated exactly as
  // above (the context is not used).
  Resultants update(State& state, const StrainVoigt& d_membrane_strain, const StrainVoigt& d_curvature,
                    const material::UpdateContext& context) const {
    if constexpr (material::is_rate_dependent_v<Law>) {
      for (int k = 0; k < num_points; ++k) {
        const StrainVoigt d_strain = d_membrane_strain + zeta_[std::size_t(k)] * d_curvature;
        law_.update(state[std::size_t(k)], d_strain, context);
      }
      return resultants(state);
    } else {
      return update(state, d_membrane_strain, d_curvature);
    }
  }

  Resultants resultants(const State& state) const {
    // Component by component: GCC left Eigen's `+= w·σ` out of line here, a
    // call per integral point; the sums are the same, in the same order.
    double membrane[3] = {0.0, 0.0, 0.0}, moment[3] = {0.0, 0.0, 0.0};
    for (int k = 0; k < num_points; ++k) {
      const StressVoigt& stress = state[std::size_t(k)].stress;
      const double w = weight_[std::size_t(k)], w_zeta = weight_[std::size_t(k)] * zeta_[std::size_t(k)];
      for (int c = 0; c < 3; ++c) {
        membrane[c] += w * stress[c];
        moment[c] += w_zeta * stress[c];
      }
    }
    return Resultants{StressVoigt(membrane[0], membrane[1], membrane[2]), StressVoigt(moment[0], moment[1], moment[2])};
  }

  double equivalent_stress(const State& state, int k) const {
    return law_.equivalent_stress(point(state, k));
  }
  double equivalent_plastic_strain(const State& state, int k) const {
    return law_.equivalent_plastic_strain(point(state, k));
  }
  double damage(const State& state, int k) const { return law_.damage(point(state, k)); }

  // A stress point is damaged (section 2.4 of the paper, rule 1) once every one of its
  // integral points has failed.
  bool all_failed(const State& state) const {
    for (const auto& point_state : state)
      if (!law_.failed(point_state)) return false;
    return true;
  }

  // Per unit mid-surface area: ∫ w(ζ) dζ with the rule's weights.
  double elastic_energy(const State& state) const {
    double energy = 0.0;
    for (int k = 0; k < num_points; ++k)
      energy += weight_[std::size_t(k)] * law_.elastic_energy_density(state[std::size_t(k)]);
    return energy;
  }

  double zeta(int k) const { return zeta_[checked(k)]; }
  double weight(int k) const { return weight_[checked(k)]; }
  double thickness() const { return thickness_; }
  const Law& law() const { return law_; }

 private:
  static std::size_t checked(int k) {
    if (k < 0 || k >= num_points)
      sphshell::detail::invalid_parameter("integral point index", k,
                                          "must lie in [0, num_points)");
    return std::size_t(k);
  }
  static const typename Law::State& point(const State& state, int k) {
    return state[checked(k)];
  }

  Law law_;
  double thickness_;
  std::array<double, std::size_t(num_points)> zeta_{};
  std::array<double, std::size_t(num_points)> weight_{};
};

}  // namespace sphshell::thickness
