#pragma once
// Johnson–Cook plasticity and failure in plane stress (Johnson & Cook 1983,
// "A constitutive model and data for metals subjected to large strains, high
// strain rates and high temperatures", 7th Int. Symp. Ballistics; Johnson &
// Cook 1985, "Fracture characteristics of three metals subjected to various
// strains, strain rates, temperatures and pressures", Eng. Fract. Mech. 21).
//
// Flow stress (1983, eq. 1):
//   σy = (A + B ε̄pⁿ)(1 + C ln ε̇*)(1 − T*ᵐ),  ε̇* = ε̄̇p/ε̇0,  T* = (T − Tr)/(Tm − Tr).
// Choices, and why:
// - The rate is the plastic one of the step itself, ε̄̇p = Δε̄p/Δt (backward
//   Euler), and it enters the consistency condition: the return solves
//   σ̄(Δε̄p) = σy(ε̄p,n + Δε̄p, Δε̄p/Δt) by Halley iteration (flow_stress_return.hpp), the
//   consistent form, not the rate of the previous step.
// - ln ε̇* is taken as 0 for ε̇* < 1, as in common practice (the rate factor
//   never softens; the fit is made for ε̇* ≥ 1). With no plastic flow the rate
//   is zero, so the elastic test is against the quasi-static surface
//   (A + B ε̄p,nⁿ)(1 − T*ᵐ).
// - Temperature is part of the state and lagged: the step uses T_n in the
//   thermal factor and in the damage, then adds the adiabatic rise of its
//   plastic work, ΔT = β σy Δε̄p/(ρ cp) (β the Taylor–Quinney coefficient; β =
//   0: isothermal). σy Δε̄p is exactly the plastic work per volume of the
//   backward-Euler step: σ·Δεp = (Δε̄p/σy) σᵀΞσ = σy Δε̄p. T0 ≥ Tr is required,
//   so T* ≥ 0; a point whose T reaches Tm has melted: it fails.
// - Damage (1985, eq. 2–3): D = Σ Δε̄p/εf with
//     εf = [D1 + D2 exp(D3 σ*)][1 + D4 ln ε̇*][1 + D5 T*],
//   σ* = σm/σ̄ the stress triaxiality of the returned plane-stress state
//   (σm = (σx + σy)/3 since σ33 = 0; σ* ∈ [−⅔, ⅔]), ε̇* this step's rate (ln
//   floored at 0 as above) and T* at T_n. The damage does not soften the
//   stress (uncoupled, as in the 1985 paper); a point whose D reaches 1 has
//   failed: it keeps zero stress for ever, and failed(state) reports it to
//   the crack handler (a stress point whose integral points have all failed
//   is damaged, thickness/section.hpp).
// - The steep start. For n < 1 the hardening Bε̄pⁿ rises with an infinite
//   slope at ε̄p = 0, and from ε̄p,n = 0 (or a tiny ε̄p,n) a small exponent puts
//   the root far below the return's start: n = 0.05 and σ̄* − A = 0.01B give
//   Δε̄p = 0.01²⁰ = 1e-40, where the iteration in Δε̄p would bisect down by
//   more halvings than the iteration limit. Where both ε̄p,n and the root lie
//   below 2⁻⁶⁴ of the return's bound on Δε̄p, the return iterates instead in
//   v = ε̄pⁿ (flow_stress_return.hpp's iteration variable; steep_return), in
//   which A + Bv is linear. Elsewhere (the ε̄p of a step from ε̄p = 0 with
//   n ≈ 0.26 and a usual excess) the iteration in Δε̄p is unchanged.

#include <sphshell/core/error.hpp>
#include <sphshell/core/types.hpp>
#include <sphshell/material/elastic.hpp>
#include <sphshell/material/flow_stress_return.hpp>
#include <sphshell/material/j2_plasticity.hpp>
#include <sphshell/material/material.hpp>
#include <sphshell/material/return_map.hpp>

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <string>

namespace sphshell::material {

struct JohnsonCook {
  // SI units throughout.
  struct Parameters {
    double E;                        // Young's modulus, Pa
    double nu;                       // Poisson's ratio
    double A;                        // yield stress at ε̄p = 0, ε̇* = 1, T = Tr, Pa
    double B;                        // hardening coefficient, Pa
    double n;                        // hardening exponent
    double C;                        // strain-rate coefficient
    double reference_strain_rate;    // ε̇0, 1/s
    double m;                        // thermal softening exponent
    double reference_temperature;    // Tr, K
    double melting_temperature;      // Tm, K
    double initial_temperature;      // T0 ∈ [Tr, Tm), K
    double taylor_quinney = 0.0;     // β ∈ [0, 1]; 0: no adiabatic heating
    double density = 0.0;            // ρ, kg/m³ (used only for the heating)
    double specific_heat = 0.0;      // cp, J/(kg·K) (used only for the heating)
    // Failure strain constants (1985); D1..D3 must keep D1 + D2 exp(D3 σ*)
    // positive on the plane-stress range σ* ∈ [−⅔, ⅔].
    double D1 = 0.0, D2 = 0.0, D3 = 0.0, D4 = 0.0, D5 = 0.0;
  };
  // A point where a function was evaluated exactly (argument 0: none yet),
  // with the reciprocal of its argument. The state keeps the last ones of
  // ε̄pⁿ, ln ε̇* and T*ᵐ: from one plastic step to the next ε̄p, ε̇* and T*
  // move by small fractions, and the next step's values follow from them by
  // the short series of nearby_power and nearby_log (each value a single
  // series from an exact evaluation, so nothing accumulates over steps).
  struct NearbyPoint {
    double argument = 0.0;
    double inverse = 0.0;
    double value = 0.0;
  };
  // σ* where exp(D3 σ*) of the failure strain was last evaluated exactly, and
  // that value (initially exp(0) = 1 at σ* = 0).
  struct ExponentialPoint {
    double triaxiality = 0.0;
    double value = 1.0;
  };
  struct State {
    StressVoigt stress;
    double eps_p;        // equivalent plastic strain ε̄p
    double sigma_y;      // flow stress of the last plastic step (initially the quasi-static one)
    double strain_rate;  // ε̄̇p = Δε̄p/Δt of the last step, 1/s (0 if it was elastic)
    double temperature;  // T, K
    double D;            // Johnson–Cook damage Σ Δε̄p/εf
    bool failed;
    // At the state's T and ε̄p, kept so that an elastic step costs no pow():
    double thermal_softening;  // 1 − T*ᵐ
    double yield_stress;       // quasi-static (A + B ε̄pⁿ)(1 − T*ᵐ): the next step's elastic limit
    // The anchors of the series (NearbyPoint, ExponentialPoint above): they
    // change the results only at round-off, and a restart needs them to
    // repeat the uninterrupted run bit for bit.
    NearbyPoint power_anchor{};        // ε̄pⁿ
    NearbyPoint log_anchor{};          // ln ε̇*
    NearbyPoint thermal_anchor{};      // T*ᵐ
    ExponentialPoint damage_anchor{};  // exp(D3 σ*)
    // ε̄̇p of the two steps before the last (0 where elastic): the return's
    // start extrapolates the rate from the last three steps.
    double previous_strain_rate = 0.0, before_previous_strain_rate = 0.0;
    // The fields a checkpoint stores (material.hpp).
    template <class S, class F>
    static void for_each_field(S& self, F&& field) {
      field(self.stress, self.eps_p, self.sigma_y, self.strain_rate, self.temperature, self.D, self.failed,
            self.thermal_softening, self.yield_stress, self.power_anchor.argument, self.power_anchor.inverse,
            self.power_anchor.value, self.log_anchor.argument, self.log_anchor.inverse, self.log_anchor.value,
            self.thermal_anchor.argument, self.thermal_anchor.inverse, self.thermal_anchor.value,
            self.damage_anchor.triaxiality, self.damage_anchor.value, self.previous_strain_rate,
            self.before_previous_strain_rate);
    }
  };
  struct UpdateResult {
    bool plastic;
    int iterations;
  };

  static constexpr bool has_plasticity = true;
  static constexpr bool has_damage = true;
  static constexpr bool rate_dependent = true;
  static constexpr const char* name = "Johnson-Cook";

  // The largest |σ*| of a plane-stress state (equibiaxial: σm/σ̄ = ⅔).
  static constexpr double max_plane_stress_triaxiality = 2.0 / 3.0;

  explicit JohnsonCook(const Parameters& parameters)
      : parameters_((validate(parameters), parameters)),
        elasticity_(parameters.E, parameters.nu),
        constants_(elasticity_, 0.0),
        inverse_temperature_range_(1.0 / (parameters.melting_temperature - parameters.reference_temperature)),
        heating_(parameters.taylor_quinney > 0.0
                     ? parameters.taylor_quinney / (parameters.density * parameters.specific_heat)
                     : 0.0),
        inverse_reference_strain_rate_(1.0 / parameters.reference_strain_rate),
        inverse_stress_scale_(1.0 / parameters.A),
        power_series_(parameters.n),
        thermal_series_(parameters.m),
        taylor_reach_(taylor_reach(parameters.n, parameters.C)) {}

  State initial_state() const {
    const double thermal = thermal_factor(homologous_temperature(parameters_.initial_temperature));
    return State{StressVoigt::Zero(), 0.0, parameters_.A * thermal, 0.0, parameters_.initial_temperature, 0.0,
                 false, thermal, parameters_.A * thermal};
  }

  // Quasi-static limit: Δt = +inf, no rate effect (material.hpp).
  UpdateResult update(State& state, const StrainVoigt& d_eps) const {
    return update(state, d_eps, UpdateContext{std::numeric_limits<double>::infinity()});
  }

  UpdateResult update(State& state, const StrainVoigt& d_eps, const UpdateContext& context) const {
    if (state.failed) {
      state.stress.setZero();
      record_strain_rate(state, 0.0);
      return {false, 0};
    }
    detail::require_finite_strain(d_eps);
    const StressVoigt trial = state.stress + elasticity_.stress_increment(d_eps);  // eq. (2.23)
    const double quasi_static = state.yield_stress;
    const double trial_squared = von_mises_squared(trial);
    if (trial_squared <= quasi_static * quasi_static) {
      state.stress = trial;
      record_strain_rate(state, 0.0);
      return {false, 0};
    }
    detail::require_time_step(context.time_step);
    const double homologous = homologous_temperature(state.temperature);
    const double thermal = state.thermal_softening;
    // 1/Δt (0 in the quasi-static limit) and ε̇* per unit Δε̄p, 1/(Δt ε̇0): the
    // step's one division for its rates.
    const double inverse_time_step = 1.0 / context.time_step;
    const double rate_per_increment = inverse_time_step * inverse_reference_strain_rate_;
    const double eps_p_n = state.eps_p;
    // A + Bε̄pⁿ and ln ε̇* (0 below ε̇* = 1) at the last Δε̄p the return evaluated,
    // which is the one it returns: the hardening of the next elastic limit and
    // the damage's rate term reuse them instead of a second pow() and log().
    double hardening_at_return = parameters_.A, log_rate_at_return = 0.0;
    // The iterates move by a small fraction of ε̄p and of Δε̄p from the last
    // step's return and from each other: ε̄pⁿ and ln ε̇* follow by short series
    // from their values at the last argument evaluated exactly (nearby_power,
    // nearby_log; the anchors are kept in the state across steps) instead of
    // another pow() and log(); each value is within round-off of theirs.
    NearbyPoint power_anchor = state.power_anchor, log_anchor = state.log_anchor;
    // The return's first iterate (its start) is evaluated by those series,
    // with the third derivatives of σs and A + Bε̄pⁿ (NearStart). The
    // correction then moves Δε̄p by a small fraction of itself (the start is
    // within ~2e-4 of the root on a smooth loading), and there the cubic
    // Taylor polynomials about the start give σs, A + Bε̄pⁿ and ln ε̇* within
    // 2⁻⁵⁴ of themselves (taylor_reach_): a later iterate costs a few
    // products instead of the series.
    NearStart near{};
    // Forced inline (its pow() and log() branches keep GCC from it): called, its
    // six results go through memory at each iterate.
    const auto flow = [&](double increment) __attribute__((always_inline)) {
      const double rate = increment * rate_per_increment;
      const bool rate_active = rate > 1.0;  // ln ε̇* taken as 0 below ε̇* = 1
      const double step = increment - near.increment;
      if (near.set && rate_active == near.rate_active && std::abs(step) <= taylor_reach_ * near.increment) {
        hardening_at_return = near.hardening.at(step);
        // ln ε̇* = ln ε̇*₀ + ln(1 + η), η = step/Δε̄p₀, to η⁵ (|η| ≤ 1e-3: the
        // first omitted term η⁶/6 is below 1.7e-19).
        const double eta = step * near.inverse_increment, eta_2 = eta * eta;
        log_rate_at_return =
            rate_active ? near.log_rate + eta * (((1.0 - 0.5 * eta) + eta_2 * (1.0 / 3.0 - 0.25 * eta)) + eta_2 * eta_2 * 0.2)
                        : 0.0;
        return return_map::FlowStressValue{increment, 1.0, 0.0, near.flow.at(step), near.flow.slope_at(step),
                                           near.flow.curvature_at(step)};
      }
      const double eps_p = eps_p_n + increment;
      const NearbyValue power = nearby_power(power_series_, parameters_.n, power_anchor, eps_p);
      const double hardening = parameters_.A + parameters_.B * power.value;
      // d(Bε̄pⁿ)/dε̄p and its derivative, (n − 1)/ε̄p times it; at ε̄p = 0 the
      // slope is +inf (n < 1), B (n = 1) or 0.
      const double hardening_slope = eps_p > 0.0 ? parameters_.n * parameters_.B * power.value * power.inverse
                                                 : parameters_.n * parameters_.B * std::pow(eps_p, parameters_.n - 1.0);
      const double hardening_curvature = (parameters_.n - 1.0) * hardening_slope * power.inverse;
      const NearbyValue log_rate = rate_active ? nearby_log(log_anchor, rate) : NearbyValue{0.0, 0.0};
      const double rate_factor = 1.0 + parameters_.C * log_rate.value;
      // d(1 + C ln ε̇*)/dΔε̄p = C/Δε̄p and its derivative −C/Δε̄p² (1/Δε̄p from 1/ε̇*).
      const double inverse_increment = rate_per_increment * log_rate.inverse;
      const double rate_slope = parameters_.C * inverse_increment;
      const double rate_curvature = -rate_slope * inverse_increment;
      hardening_at_return = hardening;
      log_rate_at_return = log_rate.value;
      const double flow_stress = hardening * rate_factor * thermal;
      const double flow_slope = (hardening_slope * rate_factor + hardening * rate_slope) * thermal;
      const double flow_curvature =
          (hardening_curvature * rate_factor + 2.0 * hardening_slope * rate_slope + hardening * rate_curvature) *
          thermal;
      if (!near.set && eps_p > 0.0 && increment > 0.0) {
        // The third derivatives: (Bε̄pⁿ)‴ = (n − 2)/ε̄p · (Bε̄pⁿ)″ and
        // (C ln Δε̄p)‴ = 2C/Δε̄p³ = −2/Δε̄p · (C ln Δε̄p)″; σs‴ by Leibniz's rule.
        const double hardening_third = (parameters_.n - 2.0) * hardening_curvature * power.inverse;
        const double rate_third = -2.0 * rate_curvature * inverse_increment;
        const double flow_third = (hardening_third * rate_factor + 3.0 * hardening_curvature * rate_slope +
                                   3.0 * hardening_slope * rate_curvature + hardening * rate_third) *
                                  thermal;
        near = NearStart{true,
                         rate_active,
                         increment,
                         inverse_increment,
                         log_rate.value,
                         {hardening, hardening_slope, hardening_curvature, hardening_third},
                         {flow_stress, flow_slope, flow_curvature, flow_third}};
      }
      return return_map::FlowStressValue{increment, 1.0, 0.0, flow_stress, flow_slope, flow_curvature};
    };
    // Started from Δε̄p at the rate extrapolated from the last three steps
    // (start_rate), or the last step's rate, or (0 after an elastic step or in
    // the quasi-static limit) from the perfectly plastic return.
    const double guess = start_rate(state) * context.time_step;
    const double trial_equivalent = std::sqrt(trial_squared);
    const double excess = trial_equivalent - quasi_static;
    // The steep start (see the top of the file): ε̄p,n and the root both lie
    // below steep_fraction of the return's bound on Δε̄p. The root lies below
    // the Δε̄p at which A + Bε̄pⁿ alone reaches σ̄*/θ, where ε̄pⁿ = hardening_limit:
    // the rate factor is ≥ 1 and uᵢ ≥ σs. Only a step from (nearly) ε̄p = 0
    // pays the test's pow().
    const double steep_reach = steep_fraction * excess * constants_.inverse_min_slope;  // 1/min κᵢ (Ep = 0)
    const bool steep = parameters_.n < 1.0 && parameters_.B > 0.0 && eps_p_n < steep_reach &&
                       hardening_limit(trial_equivalent, thermal) < std::pow(eps_p_n + steep_reach, parameters_.n);
    const return_map::FlowStressSolution solution =
        steep ? steep_return(trial, trial_equivalent, eps_p_n, thermal, rate_per_increment,
                             hardening_at_return, log_rate_at_return)
              : return_map::solve_flow_stress<return_map::Derivatives::for_corrections_only>(
                    constants_, trial, inverse_stress_scale_, flow, excess, guess);
    const double increment = solution.plastic_strain_increment;

    state.eps_p = eps_p_n + increment;
    state.sigma_y = solution.flow_stress;
    record_strain_rate(state, increment * inverse_time_step);
    state.power_anchor = power_anchor;
    state.log_anchor = log_anchor;
    const double damage_exponential = nearby_exponential(
        state.damage_anchor, returned_triaxiality(trial, solution.flow_stress, increment));
    state.D += increment / failure_strain_from_terms(damage_exponential, log_rate_at_return, homologous);
    if (heating_ > 0.0) {
      state.temperature += heating_ * solution.flow_stress * increment;
      // 1 − T*ᵐ as thermal_factor, T*ᵐ by the series from the last exact one
      // (T* itself for the common m = 1).
      const double heated = homologous_temperature(state.temperature);
      state.thermal_softening =
          !(heated > 0.0)          ? 1.0
          : parameters_.m == 1.0 ? 1.0 - heated
                                 : 1.0 - nearby_power(thermal_series_, parameters_.m, state.thermal_anchor, heated).value;
    }
    state.yield_stress = hardening_at_return * state.thermal_softening;  // (A + B ε̄pⁿ)(1 − T*ᵐ) at ε̄p,n+1
    if (state.D >= 1.0 || state.temperature >= parameters_.melting_temperature) {
      state.failed = true;
      state.stress.setZero();
    } else {
      state.stress = solution.stress;
    }
    return {true, solution.iterations};
  }

  // A + B ε̄pⁿ.
  double strain_hardening(double eps_p) const { return parameters_.A + parameters_.B * std::pow(eps_p, parameters_.n); }
  // T* = (T − Tr)/(Tm − Tr).
  double homologous_temperature(double temperature) const {
    return (temperature - parameters_.reference_temperature) * inverse_temperature_range_;
  }
  // 1 − T*ᵐ (T* ∈ [0, 1) while the point has not melted).
  double thermal_factor(double homologous) const {
    return homologous > 0.0 ? 1.0 - std::pow(homologous, parameters_.m) : 1.0;
  }
  // σ* = σm/σ̄ of a plane-stress state, σm = (σx + σy)/3 (σ33 = 0); 0 at zero stress.
  static double triaxiality(const StressVoigt& stress) {
    const double equivalent = std::sqrt(von_mises_squared(stress));
    return equivalent > 0.0 ? (stress.x() + stress.y()) / (3.0 * equivalent) : 0.0;
  }
  // σ* of the stress returned from `trial` with flow stress σs and increment
  // Δε̄p, without forming it: σ = L⁻¹σ* scales the trial's σx + σy (the
  // eigen-direction of κ₁) by σs/u₁, u₁ = σs + κ₁Δε̄p (eq. 2.32–2.33,
  // flow_stress_return.hpp), and σ̄ = σs·S with |S² − 1| ≤ 1e-12 (the return's
  // tolerance), so σ* = (σx* + σy*)/(3u₁) up to a factor S within 5e-13 of 1:
  // no square root, and the division runs beside the stress' own.
  double returned_triaxiality(const StressVoigt& trial, double flow_stress, double increment) const {
    return (trial.x() + trial.y()) / (3.0 * (flow_stress + constants_.kappa_1 * increment));
  }
  // εf of the 1985 paper at σ*, ε̇* and T* (ln ε̇* taken as 0 for ε̇* < 1).
  double failure_strain(double triaxiality, double rate, double homologous) const {
    return failure_strain_from_log_rate(triaxiality, rate > 1.0 ? std::log(rate) : 0.0, homologous);
  }
  // The same with ln ε̇* given (0 for ε̇* ≤ 1).
  double failure_strain_from_log_rate(double triaxiality, double log_rate, double homologous) const {
    return failure_strain_from_terms(std::exp(parameters_.D3 * triaxiality), log_rate, homologous);
  }

  const Parameters& parameters() const { return parameters_; }
  // Every constant that changes results (a checkpoint compares them, material.hpp).
  template <class F>
  void for_each_constant(F&& constant) const {
    const Parameters& p = parameters_;
    constant("A", p.A), constant("B", p.B), constant("n", p.n), constant("C", p.C);
    constant("reference strain rate", p.reference_strain_rate), constant("m", p.m);
    constant("reference temperature", p.reference_temperature), constant("melting temperature", p.melting_temperature);
    constant("initial temperature", p.initial_temperature), constant("Taylor-Quinney coefficient", p.taylor_quinney);
    constant("density (heating)", p.density), constant("specific heat", p.specific_heat);
    constant("D1", p.D1), constant("D2", p.D2), constant("D3", p.D3), constant("D4", p.D4), constant("D5", p.D5);
    // Listed last, so that a checkpoint of an earlier State (which lists no
    // such entry) is refused naming it, not misread field by field.
    constant("State layout", state_layout);
  }
  // The layout of State's fields (for_each_field): raised whenever they
  // change. 2: the series' anchors and the rates of the two steps before
  // the last (1 had neither).
  static constexpr double state_layout = 2.0;
  double youngs_modulus() const { return parameters_.E; }
  double poisson_ratio() const { return parameters_.nu; }
  double shear_modulus() const { return elasticity_.shear_modulus(); }
  // The linear law's constants this law reduces to with n = 1, C = 0 and no
  // thermal softening: σs0 = A, Ep = B.
  HardeningParameters hardening() const { return {parameters_.A, parameters_.B}; }
  // No threshold; the critical strain is εf in uniaxial tension (σ* = ⅓) at
  // ε̇* ≤ 1 and T = Tr; failure at D = 1.
  DamageParameters damage_parameters() const { return {0.0, failure_strain(1.0 / 3.0, 1.0, 0.0), 1.0}; }
  const PlaneStressElasticity& elasticity() const { return elasticity_; }
  Matrix3 elasticity_matrix() const { return elasticity_.matrix(); }

  double equivalent_stress(const State& state) const { return std::sqrt(von_mises_squared(state.stress)); }
  double equivalent_plastic_strain(const State& state) const { return state.eps_p; }
  double damage(const State& state) const { return state.D; }
  bool failed(const State& state) const { return state.failed; }
  double elastic_energy_density(const State& state) const {
    return elasticity_.complementary_energy_density(state.stress);
  }

 private:
  // The rate of the step's start. Where the last three steps all flowed, the
  // parabola through their rates, extrapolated one step: along a loading
  // that is smooth in time (an explicit run's steps resolve it) its error is
  // of third order in the step, small enough that one Halley correction
  // mostly meets the tolerance where the last rate needed two. Where the
  // parabola is not positive (a rate falling to 0), the last step's rate.
  // The return's safeguards hold either way: the start only has to lie in
  // the bracket, and one outside it is replaced (solve_flow_stress).
  static double start_rate(const State& state) {
    const double last = state.strain_rate;
    if (!(last > 0.0 && state.previous_strain_rate > 0.0 && state.before_previous_strain_rate > 0.0)) return last;
    const double extrapolated =
        3.0 * (last - state.previous_strain_rate) + state.before_previous_strain_rate;
    return extrapolated > 0.0 ? extrapolated : last;
  }
  static void record_strain_rate(State& state, double rate) {
    state.before_previous_strain_rate = state.previous_strain_rate;
    state.previous_strain_rate = state.strain_rate;
    state.strain_rate = rate;
  }

  // The same with exp(D3 σ*) given.
  double failure_strain_from_terms(double damage_exponential, double log_rate, double homologous) const {
    return (parameters_.D1 + parameters_.D2 * damage_exponential) * (1.0 + parameters_.D4 * log_rate) *
           (1.0 + parameters_.D5 * homologous);
  }

  // A function's value at x and 1/x (the derivatives' factor), the latter
  // within δ⁸ ≤ 4e-11 of itself: only the corrections use it.
  struct NearbyValue {
    double value;
    double inverse;
  };
  // |z| = |x − a|/(x + a) below which the series of 2 atanh z to z¹¹
  // replaces log() (nearby_log; x/a within [0.905, 1.105]): its first omitted
  // term, 2z¹³/13, is then below 1.9e-18 and each further one below z² = 2.5e-3
  // times the one before (absolute, in ln ε̇*; a four-hundredth of ln ε̇*'s last
  // bit where ε̇* ≥ e, and the rate factor 1 + C ln ε̇* sees C times it). Wide
  // enough for ε̇* of several steps along a smooth loading.
  static constexpr double log_series_reach = 5e-2;
  // |D3 Δσ*| below which exp(D3 σ*) follows from the anchor's by the series of
  // exp to the 7th power: the first omitted term, x⁸/8!, is then below 6.4e-19
  // (relative).
  static constexpr double exponential_reach = 2e-2;

  // The binomial series of (1 + δ)ⁿ to δ¹⁰: its coefficients C(n, k) and its
  // reach, the largest |δ| (at most 5e-2) with |C(n, 11)δ¹¹| ≤ 2⁻⁵⁴ and each
  // further term below half the one before (|(n − k)δ/(k + 1)| ≤ ½ for
  // k ≥ 11, which δ ≤ 6/max(|n − 11|, 12) ensures). 5e-2 keeps nearby_inverse
  // within δ⁸ < 4e-11.
  struct PowerSeries {
    static constexpr int terms = 11;
    explicit PowerSeries(double n) {
      double c = 1.0;
      for (int k = 0; k < terms; ++k) {
        coefficients[k] = c;
        c *= (n - k) / (k + 1);
      }
      reach = std::min(5e-2, 6.0 / std::max(std::abs(n - terms), 12.0));
      if (c != 0.0)
        reach = std::min(reach, std::pow(0.25 * std::numeric_limits<double>::epsilon() / std::abs(c), 1.0 / terms));
    }
    double coefficients[terms];
    double reach;
  };

  // 1/x from the anchor's reciprocal, 1/(a(1 + δ)) = (1/a)(1 − δ + δ² − … − δ⁷)
  // = (1/a)(1 − δ)(1 + δ²)(1 + δ⁴).
  static double nearby_inverse(const NearbyPoint& anchor, double delta) {
    const double delta_2 = delta * delta;
    return anchor.inverse * ((1.0 - delta) * (1.0 + delta_2)) * (1.0 + delta_2 * delta_2);
  }
  // x to the power `exponent` (x ≥ 0; series_of is its PowerSeries), from
  // the anchor's value by the binomial series (in Estrin's grouping) when x
  // is within its reach. Else std::pow gives the value at a new anchor, put
  // ahead of x by the reach: the arguments (ε̄p, T*) only grow, so x lies
  // within reach below it and the growth up to twice the reach follows by
  // the series.
  [[gnu::always_inline]] static NearbyValue nearby_power(const PowerSeries& series_of, double exponent,
                                                         NearbyPoint& anchor, double x) {
    double delta = x * anchor.inverse - 1.0;  // −1 while there is no anchor
    if (!(std::abs(delta) <= series_of.reach)) {
      if (!(x > 0.0)) return {std::pow(x, exponent), 1.0 / x};  // ε̄p = 0: no anchor there
      const double ahead = x * (1.0 + series_of.reach);
      anchor = {ahead, 1.0 / ahead, std::pow(ahead, exponent)};
      delta = x * anchor.inverse - 1.0;  // −reach/(1 + reach), within reach
    }
    const double* c = series_of.coefficients;
    const double delta_2 = delta * delta, delta_4 = delta_2 * delta_2;
    const double series = ((1.0 + c[1] * delta) + delta_2 * (c[2] + c[3] * delta)) +
                          delta_4 * (((c[4] + c[5] * delta) + delta_2 * (c[6] + c[7] * delta)) +
                                     delta_4 * ((c[8] + c[9] * delta) + delta_2 * c[10]));
    return {anchor.value * series, nearby_inverse(anchor, delta)};
  }
  // ln x and 1/x (exact), ln x from the anchor's as ln a + ln(x/a),
  //   ln(x/a) = 2 atanh z = 2z (1 + z²/3 + z⁴/5 + … + z¹⁰/11 + …),  z = (x − a)/(x + a),
  // to z¹¹ (Estrin's grouping in z²) when |z| ≤ log_series_reach, else by
  // std::log (and x becomes the anchor). In z the series runs in even powers
  // and falls by z² ≈ δ²/4 a term (δ = x/a − 1), so it reaches twice as far as
  // the series of ln(1 + δ) to δ¹¹ with half the terms. Its two divisions
  // depend on x alone: at the return's first iterate (the start) they run
  // beside the rest of the step; the later iterates use the start's Taylor
  // polynomials.
  [[gnu::always_inline]] static NearbyValue nearby_log(NearbyPoint& anchor, double x) {
    const double inverse = 1.0 / x;
    if (anchor.argument > 0.0) {
      const double z = (x - anchor.argument) / (x + anchor.argument);
      if (std::abs(z) <= log_series_reach) {
        const double z_2 = z * z, z_4 = z_2 * z_2;
        const double series = ((1.0 + z_2 * (1.0 / 3.0)) + z_4 * (0.2 + z_2 * (1.0 / 7.0))) +
                              z_4 * z_4 * (1.0 / 9.0 + z_2 * (1.0 / 11.0));
        return {anchor.value + 2.0 * z * series, inverse};
      }
    }
    anchor = {x, inverse, std::log(x)};
    return {anchor.value, inverse};
  }
  // A function's cubic Taylor polynomial about a point: f, f′, f″, f‴ there.
  struct Cubic {
    double value, slope, curvature, third;
    double at(double step) const {
      return value + step * (slope + step * (0.5 * curvature + step * (third * (1.0 / 6.0))));
    }
    double slope_at(double step) const { return slope + step * (curvature + step * (0.5 * third)); }
    double curvature_at(double step) const { return curvature + step * third; }
  };
  // The return's first iterate (set: evaluated, with ε̄p > 0 and Δε̄p > 0):
  // its Δε̄p, whether the rate term was active there, 1/Δε̄p, ln ε̇*, and the
  // Taylor polynomials of A + Bε̄pⁿ and of σs in Δε̄p.
  struct NearStart {
    bool set = false;
    bool rate_active = false;
    double increment = 0.0;
    double inverse_increment = 0.0;
    double log_rate = 0.0;
    Cubic hardening{0.0, 0.0, 0.0, 0.0};
    Cubic flow{0.0, 0.0, 0.0, 0.0};
  };
  // The reach of the cubic Taylor polynomials about the start, as a fraction
  // η of its Δε̄p. Their remainder is f⁗(ξ)d⁴/24 (d = ηΔε̄p). With
  // σs = θ·H·R, H = A + Bε̄pⁿ ≥ Bε̄pⁿ, R = 1 + C ln ε̇* ≥ 1, ε̄p ≥ Δε̄p,
  //   |H⁽ᵏ⁾|/H ≤ |n(n − 1)…(n − k + 1)|/Δε̄pᵏ,  |R⁽ʲ⁾|/R ≤ C (j − 1)!/Δε̄pʲ (j ≥ 1),
  // so by Leibniz's rule |σs⁗|/σs ≤ 24K/Δε̄p⁴ with
  //   24K = |n)₄| + 4C|n)₃| + 6C|n)₂| + 8C|n| + 6C,  (n)ₖ the falling factorial,
  // and the relative remainder is below Kη⁴/(1 − η)⁴ (ξ within ηΔε̄p of the
  // start); |H⁗|/H ≤ |n)₄|/Δε̄p⁴ ≤ 24K/Δε̄p⁴ bounds A + Bε̄pⁿ's remainder by the
  // same. The reach keeps Kη⁴ ≤ 2⁻⁵⁵, so both stay below 2⁻⁵⁴ (the series'
  // round-off), and is at most 1e-3 (ln(1 + η) to η⁵ then within 1.7e-19).
  static double taylor_reach(double n, double C) {
    const double n_2 = std::abs(n * (n - 1.0)), n_3 = n_2 * std::abs(n - 2.0), n_4 = n_3 * std::abs(n - 3.0);
    const double bound = (n_4 + 4.0 * C * n_3 + 6.0 * C * n_2 + 8.0 * C * std::abs(n) + 6.0 * C) / 24.0;
    const double largest = 1e-3;
    return bound > 0.0 ? std::min(largest, std::pow(0.125 * std::numeric_limits<double>::epsilon() / bound, 0.25))
                       : largest;
  }

  // exp(D3 σ*), from the anchor's by the series of exp(x), x = D3 (σ* − σ*ₐ),
  // to x⁷ (Estrin's grouping) when |x| ≤ exponential_reach, else by std::exp
  // (and σ* becomes the anchor).
  double nearby_exponential(ExponentialPoint& anchor, double triaxiality) const {
    const double x = parameters_.D3 * (triaxiality - anchor.triaxiality);
    if (std::abs(x) <= exponential_reach) {
      const double x_2 = x * x, x_4 = x_2 * x_2;
      const double series = ((1.0 + x) + x_2 * (0.5 + x * (1.0 / 6.0))) +
                            x_4 * ((1.0 / 24.0 + x * (1.0 / 120.0)) + x_2 * (1.0 / 720.0 + x * (1.0 / 5040.0)));
      return anchor.value * series;
    }
    anchor = {triaxiality, std::exp(parameters_.D3 * triaxiality)};
    return anchor.value;
  }

  // 2⁻⁶⁴ of the return's bound on Δε̄p: below it, the iteration in Δε̄p would
  // bisect from its start (at least min κᵢ/max κᵢ of the bound) down to the
  // larger of ε̄p,n and the root, some 64 halvings of the 100 corrections it may take.
  static constexpr double steep_fraction = 0x1p-64;

  // ε̄pⁿ at which (A + Bε̄pⁿ)θ = σ̄* (B > 0).
  double hardening_limit(double trial_equivalent, double thermal) const {
    return (trial_equivalent / thermal - parameters_.A) / parameters_.B;
  }

  // The return in v = ε̄pⁿ = (ε̄p,n + Δε̄p)ⁿ (the steep start, top of the file):
  // A + Bv is linear in v, Δε̄p = v^(1/n) − ε̄p,n has the slope
  // dΔε̄p/dv = ε̄p/(nv) and the curvature (1/n − 1)/v · dΔε̄p/dv (both 0 at
  // v = 0 for n < 1), and the rate factor 1 + C ln ε̇* (ε̇* ∝ Δε̄p) has the
  // slope C (ln Δε̄p)′ and the curvature C (ln Δε̄p)″, (ln Δε̄p)′ = Δε̄p′/Δε̄p,
  // (ln Δε̄p)″ = Δε̄p″/Δε̄p − (ln Δε̄p)′². The bracket is [ε̄p,nⁿ, hardening
  // limit] (g > 0 at Δε̄p = 0; at the limit σs ≥ σ̄* and uᵢ ≥ σs, so g ≤ 0),
  // started at the limit: without the rate term the root lies within κᵢΔε̄p/σ̄*
  // (< 2⁻⁶³ of the excess over σ̄*) of it, so the start meets the tolerance.
  // Sets the hardening A + Bv and ln ε̇* of the returned v, as the update's flow does.
  return_map::FlowStressSolution steep_return(const StressVoigt& trial, double trial_equivalent,
                                              double eps_p_n, double thermal, double rate_per_increment,
                                              double& hardening_at_return, double& log_rate_at_return) const {
    const Parameters& p = parameters_;
    const double inverse_n = 1.0 / p.n;
    const auto flow = [&](double v) {
      const double eps_p = std::pow(v, inverse_n);
      const double increment = std::max(eps_p - eps_p_n, 0.0);
      const double increment_slope = v > 0.0 ? inverse_n * eps_p / v : 0.0;
      const double increment_curvature = v > 0.0 ? (inverse_n - 1.0) * increment_slope / v : 0.0;
      const double hardening = p.A + p.B * v;
      const double rate = increment * rate_per_increment;
      const bool rate_active = rate > 1.0;  // ln ε̇* taken as 0 below ε̇* = 1
      const double log_rate = rate_active ? std::log(rate) : 0.0;
      const double rate_factor = 1.0 + p.C * log_rate;
      const double log_slope = rate_active ? increment_slope / increment : 0.0;
      const double log_curvature = rate_active ? increment_curvature / increment - log_slope * log_slope : 0.0;
      const double rate_slope = p.C * log_slope, rate_curvature = p.C * log_curvature;
      hardening_at_return = hardening;
      log_rate_at_return = log_rate;
      return return_map::FlowStressValue{increment,
                                         increment_slope,
                                         increment_curvature,
                                         hardening * rate_factor * thermal,
                                         (p.B * rate_factor + hardening * rate_slope) * thermal,
                                         (2.0 * p.B * rate_slope + hardening * rate_curvature) * thermal};
    };
    const double upper = hardening_limit(trial_equivalent, thermal);
    const double lower = std::pow(eps_p_n, p.n);
    return return_map::solve_flow_stress(constants_, trial, inverse_stress_scale_, flow, upper, lower, upper);
  }

  static void validate(const Parameters& p) {
    using sphshell::detail::invalid_parameter;
    detail::validate_elastic_constants(p.E, p.nu);
    sphshell::detail::require_positive("A", p.A);
    sphshell::detail::require_nonnegative("B", p.B);
    sphshell::detail::require_positive("n", p.n);
    sphshell::detail::require_nonnegative("C", p.C);
    sphshell::detail::require_positive("reference_strain_rate", p.reference_strain_rate);
    sphshell::detail::require_positive("m", p.m);
    sphshell::detail::require_finite("reference_temperature", p.reference_temperature);
    if (!(p.melting_temperature > p.reference_temperature) || !std::isfinite(p.melting_temperature))
      invalid_parameter("melting_temperature", p.melting_temperature,
                        "must be finite and > reference_temperature = " + number(p.reference_temperature));
    if (!(p.initial_temperature >= p.reference_temperature && p.initial_temperature < p.melting_temperature))
      invalid_parameter("initial_temperature", p.initial_temperature,
                        "must lie in [reference_temperature, melting_temperature) = [" +
                            number(p.reference_temperature) + ", " + number(p.melting_temperature) + ")");
    if (!(p.taylor_quinney >= 0.0 && p.taylor_quinney <= 1.0))
      invalid_parameter("taylor_quinney", p.taylor_quinney, "must lie in [0, 1] (0: no adiabatic heating)");
    if (p.taylor_quinney > 0.0) {
      sphshell::detail::require_finite("density", p.density);
      sphshell::detail::require_finite("specific_heat", p.specific_heat);
      const double heat_capacity = p.density * p.specific_heat;
      if (!(heat_capacity > 0.0) || !std::isfinite(heat_capacity))
        invalid_parameter("density*specific_heat", heat_capacity,
                          "must be finite and > 0 when taylor_quinney > 0 (density = " + number(p.density) +
                              ", specific_heat = " + number(p.specific_heat) + ")");
    }
    sphshell::detail::require_finite("D1", p.D1);
    sphshell::detail::require_finite("D2", p.D2);
    sphshell::detail::require_finite("D3", p.D3);
    sphshell::detail::require_nonnegative("D4", p.D4);
    sphshell::detail::require_nonnegative("D5", p.D5);
    // D1 + D2 exp(D3 σ*) is monotonic in σ*: positive at both ends of the
    // plane-stress range means positive on all of it.
    for (const double end : {-max_plane_stress_triaxiality, max_plane_stress_triaxiality}) {
      const double triaxiality_term = p.D1 + p.D2 * std::exp(p.D3 * end);
      if (!(triaxiality_term > 0.0) || !std::isfinite(triaxiality_term))
        invalid_parameter("D1 + D2*exp(D3*triaxiality)", triaxiality_term,
                          "must be finite and > 0 at triaxiality " + number(end) + " (D1 = " + number(p.D1) +
                              ", D2 = " + number(p.D2) + ", D3 = " + number(p.D3) +
                              "): the failure strain of plane stress, triaxiality in [-2/3, 2/3]");
    }
  }
  static std::string number(double value) {
    std::ostringstream text;
    text.precision(17);
    text << value;
    return text.str();
  }

  Parameters parameters_;
  PlaneStressElasticity elasticity_;
  return_map::ClosedFormConstants constants_;  // κᵢ of ΓΞ (Ep unused)
  double inverse_temperature_range_;          // 1/(Tm − Tr)
  double heating_;                             // β/(ρ cp), 0 without heating
  double inverse_reference_strain_rate_;       // 1/ε̇0
  // 1/A: the return's stress scale (flow_stress_return.hpp; any stress of the
  // return's size keeps its numbers far from over- and underflow, and the
  // residual test is scale-free). A constant, so that no division by the last
  // step's yield stress stands at the head of the next step's return.
  double inverse_stress_scale_;
  PowerSeries power_series_;                   // of ε̄pⁿ near an anchor
  PowerSeries thermal_series_;                 // of T*ᵐ near an anchor
  double taylor_reach_;                        // of the Taylor polynomials about the return's start
};

}  // namespace sphshell::material
