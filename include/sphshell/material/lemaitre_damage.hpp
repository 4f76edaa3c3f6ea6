#pragma once
// Lemaitre–Chaboche ductile damage coupled to plane-stress J2 plasticity
// (section 2.3 of the paper, eq. 2.40–2.46).
//
// Choices, and why:
// - Strain equivalence: σ = (1−D)Γεe, so the effective stress σ̃ = σ/(1−D)
//   is what yields (eq. 2.42: σ̄/(1−D) = σs), and the flow is associative in
//   σ̃: Δεp = (Δε̄p/σs)Ξσ̃. Then ε̄p is the von Mises equivalent of εp — the
//   same consistency argument as the consistent scaling of docs/method.md §5, which rules
//   out the paper's Δεp ∝ Ξσ (with it a damaged uniaxial bar would accumulate
//   (1−D)Δε̄p of axial plastic strain per Δε̄p).
// - Implicit in D: writing the step with D_{n+1} everywhere,
//     σ_{n+1} = (1−D_{n+1}) [σ̃_n + ΓΔε − ΓΔεp],
//   i.e. Lσ_{n+1} = σ* with σ* = σ_n + (1−D_n)ΓΔε and
//     L = (1 + ΔD/(1−D_{n+1})) (I + cΓΞ),
//   the form of eq. (2.46) with D_{n+1} and effective-stress flow (the
//   (1−D)cΓΞ term of the paper's L becomes (1−D_n)/(1−D_{n+1})·cΓΞ). The yield
//   equation σᵀΞσ/(1−D_{n+1})² − σs² = 0 then equals σ̃ᵀΞσ̃ − σs² = 0 with
//   (I + cΓΞ)σ̃ = σ̃* = σ̃_n + ΓΔε: ΔD cancels, so the scalar Newton for Δε̄p
//   is exactly the J2 one (return_map.hpp) and D = 0 reduces to J2 exactly.
// - Triaxiality T = σH/σ̄ with σH = (σx+σy)/3 is scale invariant, so it is the
//   same for σ and σ̃; it is evaluated at the returned stress σ̃_{n+1}
//   (fully implicit, and free because the return does not depend on D).
// - Damage increment, eq. (2.40)–(2.41) with Y(T) = ⅔(1+ν) + 3(1−2ν)T²:
//   damage grows only on the part of [ε̄p,n, ε̄p,n+1] above the threshold
//   ε̄sp/Y(T_{n+1}), so a step that crosses the threshold is split exactly;
//   ΔD = Dc/(ε̄cp − ε̄sp) · Y · (ε̄p,n+1 − max(ε̄p,n, ε̄sp/Y))⁺ ≥ 0.
// - Failure: a point whose D reaches Dc is failed, keeps D = Dc and zero
//   stress forever; update() of a failed state returns at once.

#include <sphshell/core/error.hpp>
#include <sphshell/core/types.hpp>
#include <sphshell/material/elastic.hpp>
#include <sphshell/material/j2_plasticity.hpp>
#include <sphshell/material/return_map.hpp>

#include <algorithm>
#include <cmath>
#include <sstream>

namespace sphshell::material {

struct LemaitreDamage {
  struct Parameters {
    double E;
    double nu;
    double sigma_y0;
    double Ep;
    double eps_s;  // damage threshold ε̄sp
    double eps_c;  // critical equivalent plastic strain ε̄cp
    double Dc;     // critical damage
  };
  struct State {
    StressVoigt stress;  // nominal (Cauchy) stress σ = (1−D)σ̃
    double eps_p;
    double sigma_y;
    double D;
    bool failed;
    // The fields a checkpoint stores (material.hpp).
    template <class S, class F>
    static void for_each_field(S& self, F&& field) {
      field(self.stress, self.eps_p, self.sigma_y, self.D, self.failed);
    }
  };
  struct UpdateResult {
    bool plastic;
    int iterations;
  };

  static constexpr bool has_plasticity = true;
  static constexpr bool has_damage = true;
  static constexpr const char* name = "Lemaitre damage";

  explicit LemaitreDamage(const Parameters& parameters)
      : parameters_((validate(parameters), parameters)),
        elasticity_(parameters.E, parameters.nu),
        return_map_constants_(elasticity_, parameters.Ep),
        damage_rate_(parameters.Dc / (parameters.eps_c - parameters.eps_s)) {}

  State initial_state() const {
    return State{StressVoigt::Zero(), 0.0, parameters_.sigma_y0, 0.0, false};
  }

  // Y(T) = ⅔(1+ν) + 3(1−2ν)T², the triaxiality function of eq. (2.40)–(2.41).
  double triaxiality_function(double triaxiality) const {
    return triaxiality_function_of_square(triaxiality * triaxiality);
  }
  double triaxiality_function_of_square(double triaxiality_squared) const {
    const double nu = parameters_.nu;
    return 2.0 / 3.0 * (1.0 + nu) + 3.0 * (1.0 - 2.0 * nu) * triaxiality_squared;
  }

  UpdateResult update(State& state, const StrainVoigt& d_eps) const {
    return update(state, d_eps, ReturnMapOptions{});
  }

  UpdateResult update(State& state, const StrainVoigt& d_eps,
                      const ReturnMapOptions& options) const {
    if (state.failed) {
      state.stress.setZero();
      return {false, 0};
    }
    detail::require_finite_strain(d_eps);
    const double intact_n = 1.0 - state.D;
    const StressVoigt effective_trial =
        state.stress / intact_n + elasticity_.stress_increment(d_eps);
    if (von_mises_squared(effective_trial) <= state.sigma_y * state.sigma_y) {
      state.stress = intact_n * effective_trial;  // elastic: D unchanged
      return {false, 0};
    }
    const return_map::Solution solution = return_map::solve(
        elasticity_, return_map_constants_, effective_trial, state.sigma_y, options);
    const double increment = solution.plastic_strain_increment;
    const double eps_p_new = state.eps_p + increment;

    // σ̄ of the returned effective stress is σs > 0, so T is well defined; only T² enters.
    const double hydrostatic = (solution.stress.x() + solution.stress.y()) / 3.0;
    const double weight = triaxiality_function_of_square(hydrostatic * hydrostatic /
                                                         von_mises_squared(solution.stress));
    // Y·(ε̄p,n+1 − max(ε̄p,n, ε̄sp/Y)) without dividing by Y: the part of the step above the
    // threshold Y ε̄p = ε̄sp of eq. (2.40), weighted as in eq. (2.41).
    const double weighted_damaging_strain =
        weight * eps_p_new - std::max(weight * state.eps_p, parameters_.eps_s);
    const double damage_new = weighted_damaging_strain > 0.0
                                  ? state.D + damage_rate_ * weighted_damaging_strain  // eq. (2.41)
                                  : state.D;

    state.eps_p = eps_p_new;
    state.sigma_y += parameters_.Ep * increment;
    if (damage_new >= parameters_.Dc) {
      state.D = parameters_.Dc;
      state.failed = true;
      state.stress.setZero();
    } else {
      state.D = damage_new;
      state.stress = (1.0 - damage_new) * solution.stress;
    }
    return {true, solution.iterations};
  }

  const Parameters& parameters() const { return parameters_; }
  double youngs_modulus() const { return parameters_.E; }
  double poisson_ratio() const { return parameters_.nu; }
  double shear_modulus() const { return elasticity_.shear_modulus(); }
  HardeningParameters hardening() const { return {parameters_.sigma_y0, parameters_.Ep}; }
  DamageParameters damage_parameters() const { return {parameters_.eps_s, parameters_.eps_c, parameters_.Dc}; }
  const PlaneStressElasticity& elasticity() const { return elasticity_; }
  // The undamaged Γ; the current stiffness of a point is (1−D)Γ.
  Matrix3 elasticity_matrix() const { return elasticity_.matrix(); }

  // Nominal σ̄; after a plastic return it equals (1−D)σs.
  double equivalent_stress(const State& state) const {
    return std::sqrt(von_mises_squared(state.stress));
  }
  double equivalent_plastic_strain(const State& state) const { return state.eps_p; }
  double damage(const State& state) const { return state.D; }
  bool failed(const State& state) const { return state.failed; }
  // ½(1−D)εeᵀΓεe = ½σᵀΓ⁻¹σ/(1−D); a failed point stores none.
  double elastic_energy_density(const State& state) const {
    if (state.failed) return 0.0;
    return elasticity_.complementary_energy_density(state.stress) / (1.0 - state.D);
  }

 private:
  static void validate(const Parameters& parameters) {
    detail::validate_plastic_constants(parameters.E, parameters.nu, parameters.sigma_y0,
                                       parameters.Ep);
    sphshell::detail::require_nonnegative("eps_s", parameters.eps_s);
    if (!(parameters.eps_c > parameters.eps_s) || !std::isfinite(parameters.eps_c)) {
      std::ostringstream requirement;
      requirement.precision(17);
      requirement << "must be finite and > eps_s = " << parameters.eps_s;
      sphshell::detail::invalid_parameter("eps_c", parameters.eps_c, requirement.str());
    }
    sphshell::detail::require_half_open_interval("Dc", parameters.Dc, 0.0, 1.0);
  }

  Parameters parameters_;
  PlaneStressElasticity elasticity_;
  return_map::ClosedFormConstants return_map_constants_;
  double damage_rate_;  // Dc/(ε̄cp − ε̄sp)
};

}  // namespace sphshell::material
