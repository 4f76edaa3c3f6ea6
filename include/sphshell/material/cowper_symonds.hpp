#pragma once
// Cowper–Symonds rate scaling of the plane-stress J2 law with linear isotropic
// hardening (Cowper & Symonds 1957, Brown Univ. Tech. Rep. 28; Jones,
// "Structural Impact", 2nd ed., 2012, eq. 8.3):
//   σy = σs(ε̄p) [1 + (ε̄̇p/D)^(1/q)],   σs(ε̄p) = σs0 + Ep ε̄p   (eq. 2.34–2.35).
// Choices, and why:
// - The rate is the plastic one of the step, ε̄̇p = Δε̄p/Δt, and it enters the
//   consistency condition (consistent, not lagged): with no plastic flow the
//   overstress vanishes, so the elastic test is J2's, against σs(ε̄p,n).
// - The rate factor is ≥ 1, so the rate-scaled Δε̄p lies below J2's, and J2's
//   lies below excess/min(κᵢ + Ep) (return_map.hpp's bracket). When
//   (Δε̄p/(DΔt))^(1/q) at that bound does not change 1 + x in double
//   precision, the rate factor is 1 at every admissible Δε̄p and J2's own
//   return (return_map::solve) is the answer: D → ∞ is J2Plasticity bit for bit.
// - Both tests above are made on r = Δε̄p,bound/(DΔt) against constants of the
//   law (r ≤ (2⁻⁵³)^q ⇔ x ≤ 2⁻⁵³, the largest x with 1 + x == 1), so a step
//   pays no root r^(1/q) unless that bound is the tighter bracket end.
// - An integer q (mild steel's 5, aluminium's 4) raises x to it by repeated
//   squaring instead of std::pow: the iterations then cost J2's plus a few
//   multiplications.
// - Otherwise the return iterates on x = (Δε̄p/(DΔt))^(1/q), Δε̄p = DΔt xᵠ
//   (flow_stress_return.hpp): in Δε̄p the rate factor rises with an infinite
//   slope at 0 (q > 1), in x it is linear, and a typical explicit step's root
//   lies at Δε̄p ~ 1e-15 where Newton in Δε̄p would bisect for dozens of steps.

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

namespace sphshell::material {

struct CowperSymonds {
  struct Parameters {
    double E;         // Pa
    double nu;
    double sigma_y0;  // quasi-static initial yield stress σs0, Pa
    double Ep;        // plastic modulus E·Et/(E − Et), eq. (2.35), Pa
    double D;         // Cowper–Symonds rate constant, 1/s
    double q;         // Cowper–Symonds exponent
  };
  struct State {
    StressVoigt stress;
    double eps_p;        // equivalent plastic strain ε̄p
    double sigma_y;      // quasi-static yield stress σs = σs0 + Ep ε̄p, accumulated as J2Plasticity's
    double flow_stress;  // σy of the last step: σs [1 + (ε̄̇p/D)^(1/q)]
    double strain_rate;  // ε̄̇p = Δε̄p/Δt of the last step, 1/s (0 if elastic)
    // The fields a checkpoint stores (material.hpp).
    template <class S, class F>
    static void for_each_field(S& self, F&& field) {
      field(self.stress, self.eps_p, self.sigma_y, self.flow_stress, self.strain_rate);
    }
  };
  struct UpdateResult {
    bool plastic;
    int iterations;
  };

  static constexpr bool has_plasticity = true;
  static constexpr bool has_damage = false;
  static constexpr bool rate_dependent = true;
  static constexpr const char* name = "Cowper-Symonds";

  explicit CowperSymonds(const Parameters& parameters)
      : parameters_((validate(parameters), parameters)),
        elasticity_(parameters.E, parameters.nu),
        constants_(elasticity_, parameters.Ep),
        inverse_exponent_(1.0 / parameters.q),
        inverse_D_(1.0 / parameters.D),
        integer_exponent_(parameters.q == std::floor(parameters.q) && parameters.q <= max_integer_exponent
                              ? static_cast<int>(parameters.q)
                              : 0),
        quasi_static_ratio_(std::pow(largest_negligible_factor, parameters.q)) {}

  State initial_state() const {
    return State{StressVoigt::Zero(), 0.0, parameters_.sigma_y0, parameters_.sigma_y0, 0.0};
  }

  // Quasi-static limit: Δt = +inf, J2Plasticity's update (material.hpp).
  UpdateResult update(State& state, const StrainVoigt& d_eps) const {
    return update(state, d_eps, UpdateContext{std::numeric_limits<double>::infinity()});
  }

  UpdateResult update(State& state, const StrainVoigt& d_eps, const UpdateContext& context) const {
    detail::require_finite_strain(d_eps);
    const StressVoigt trial = state.stress + elasticity_.stress_increment(d_eps);  // eq. (2.23)
    if (von_mises_squared(trial) <= state.sigma_y * state.sigma_y) {
      state.stress = trial;
      state.flow_stress = state.sigma_y;
      state.strain_rate = 0.0;
      return {false, 0};
    }
    detail::require_time_step(context.time_step);
    const double inverse_yield = 1.0 / state.sigma_y;  // the return's stress scale (flow_stress_return.hpp)
    const double trial_equivalent = std::sqrt(von_mises_squared(trial));
    const double sigma_y_n = state.sigma_y, plastic_modulus = parameters_.Ep, q = parameters_.q;
    const double rate_time = parameters_.D * context.time_step;  // DΔt: Δε̄p/(DΔt) = ε̄̇p/D
    // 1/Δt and 1/(DΔt) (0 in the quasi-static limit): the step's one division
    // for its rates, independent of the trial, so it runs beside the return.
    const double inverse_time_step = 1.0 / context.time_step;
    const double inverse_rate_time = inverse_time_step * inverse_D_;
    // J2's Δε̄p is at most excess/min(κᵢ + Ep) (return_map.hpp), and the
    // rate-scaled one lies below J2's; x of that bound, r^(1/q), bounds x.
    const double excess = trial_equivalent - sigma_y_n;
    const double bound_ratio = excess * constants_.inverse_min_slope * inverse_rate_time;
    if (bound_ratio <= quasi_static_ratio_) {
      // The rate factor is 1 in double at every admissible Δε̄p (always in the
      // quasi-static limit, Δt = +inf): J2's return, bit for bit.
      const return_map::Solution quasi_static =
          return_map::solve(elasticity_, constants_, trial, sigma_y_n, ReturnMapOptions{});
      state.stress = quasi_static.stress;
      state.eps_p += quasi_static.plastic_strain_increment;
      state.sigma_y += plastic_modulus * quasi_static.plastic_strain_increment;  // eq. (2.34)
      state.flow_stress = state.sigma_y;
      state.strain_rate = quasi_static.plastic_strain_increment / context.time_step;
      return {true, quasi_static.iterations};
    }
    const auto flow = [&](double x) {
      // Δε̄p = DΔt xᵠ, dΔε̄p/dx = q DΔt xᵠ⁻¹, d²Δε̄p/dx² = q(q − 1) DΔt xᵠ⁻²; at
      // x = 0 the slope is +inf (q < 1), DΔt (q = 1) or 0.
      const Powers p = powers(x);
      const double increment = rate_time * p.q;
      const double increment_slope = q * rate_time * p.q_minus_1;
      const double increment_curvature = q * (q - 1.0) * rate_time * p.q_minus_2;
      const double quasi_static_flow = sigma_y_n + plastic_modulus * increment;
      return return_map::FlowStressValue{
          increment,
          increment_slope,
          increment_curvature,
          quasi_static_flow * (1.0 + x),
          plastic_modulus * increment_slope * (1.0 + x) + quasi_static_flow,
          plastic_modulus * (increment_curvature * (1.0 + x) + 2.0 * increment_slope)};
    };
    // Bracket in x: 0 (g > 0: the trial lies outside σs,n) and the smaller of
    // bound_x and r = excess/σs,n; at x = r already σy ≥ σs,n(1 + x) = σ̄*
    // and uᵢ > σy, so g ≤ 0.
    const double relative_excess = excess * inverse_yield;
    const double excess_power = power(relative_excess);
    const bool bound_tighter = bound_ratio < excess_power;
    const double upper = bound_tighter ? std::pow(bound_ratio, inverse_exponent_) : relative_excess;
    // The start. Where the overstress carries the excess (the usual impact
    // regime: κΔε̄p ≪ σs,n x), the surface σ̄ = σy, to first order in κᵢΔε̄p/σy,
    // is σ̄* − κ̂Δε̄p = σy with κ̂ = (κ₁A + κ₂B)/(A + B) the trial's mean of the
    // κᵢ (the weights of eq. B.5), i.e. x = r − c xᵠ with c = (κ̂ + Ep(1 + x))DΔt/σs,n.
    // One step of that fixed point from x = r lands within ρ·c rᵠ of its root,
    // ρ = q c rᵠ⁻¹ the map's contraction; it is taken where ρ ≤ ¼. Otherwise
    // the iteration starts from the last step's x, σy/σs − 1 (in steady flow the root
    // hardly moves), or from the upper end; the safeguard keeps it inside the bracket.
    const double equibiaxial = 0.25 * (trial.x() + trial.y()) * (trial.x() + trial.y());
    const double difference = trial.x() - trial.y();
    const double deviatoric = 0.75 * difference * difference + 3.0 * trial.z() * trial.z();
    const double mean_stiffness = (constants_.kappa_1 * equibiaxial + constants_.kappa_2 * deviatoric) /
                                  (equibiaxial + deviatoric);
    const double overstress_drop =
        (mean_stiffness + plastic_modulus * (1.0 + relative_excess)) * rate_time * inverse_yield * excess_power;
    const double predicted = relative_excess - overstress_drop;
    const double last_x = state.flow_stress * inverse_yield - 1.0;
    const double start = !bound_tighter && q * overstress_drop <= 0.25 * relative_excess && predicted > 0.0
                             ? predicted
                             : (last_x > 0.0 && last_x < upper ? last_x : upper);
    const return_map::FlowStressSolution solution =
        return_map::solve_flow_stress(constants_, trial, inverse_yield, flow, start, 0.0, upper);
    const double increment = solution.plastic_strain_increment;
    state.stress = solution.stress;
    state.eps_p += increment;
    state.sigma_y += plastic_modulus * increment;  // eq. (2.34)
    state.flow_stress = solution.flow_stress;
    state.strain_rate = increment * inverse_time_step;
    return {true, solution.iterations};
  }

  const Parameters& parameters() const { return parameters_; }
  // The rate constants (a checkpoint compares them, material.hpp).
  template <class F>
  void for_each_constant(F&& constant) const {
    constant("Cowper-Symonds D", parameters_.D), constant("Cowper-Symonds q", parameters_.q);
  }
  double youngs_modulus() const { return parameters_.E; }
  double poisson_ratio() const { return parameters_.nu; }
  double shear_modulus() const { return elasticity_.shear_modulus(); }
  // The quasi-static hardening the rate factor scales.
  HardeningParameters hardening() const { return {parameters_.sigma_y0, parameters_.Ep}; }
  const PlaneStressElasticity& elasticity() const { return elasticity_; }
  Matrix3 elasticity_matrix() const { return elasticity_.matrix(); }

  double equivalent_stress(const State& state) const { return std::sqrt(von_mises_squared(state.stress)); }
  double equivalent_plastic_strain(const State& state) const { return state.eps_p; }
  double damage(const State&) const { return 0.0; }
  bool failed(const State&) const { return false; }
  double elastic_energy_density(const State& state) const {
    return elasticity_.complementary_energy_density(state.stress);
  }

 private:
  static void validate(const Parameters& parameters) {
    detail::validate_plastic_constants(parameters.E, parameters.nu, parameters.sigma_y0, parameters.Ep);
    sphshell::detail::require_positive("D", parameters.D);
    sphshell::detail::require_positive("q", parameters.q);
  }

  // xᵠ: by repeated squaring for an integer q, else std::pow.
  double power(double x) const {
    if (integer_exponent_ == 0) return std::pow(x, parameters_.q);
    return integer_power(x, integer_exponent_);
  }
  static double integer_power(double x, int exponent) {
    double result = 1.0, square = x;
    for (int e = exponent; e > 0; e >>= 1) {
      if (e & 1) result *= square;
      square *= square;
    }
    return result;
  }
  struct Powers {
    double q, q_minus_1, q_minus_2;  // xᵠ, xᵠ⁻¹, xᵠ⁻²
  };
  // xᵠ with the two powers below it: for an integer q ≥ 2 xᵠ⁻² by squaring
  // and two products, else std::pow and divisions by x (x > 0; at x = 0
  // std::pow's limits of xᵠ⁻¹ and xᵠ⁻²).
  Powers powers(double x) const {
    if (integer_exponent_ >= 2) {
      const double lowest = integer_power(x, integer_exponent_ - 2);
      return {lowest * (x * x), lowest * x, lowest};
    }
    const double q = parameters_.q;
    const double top = power(x);
    if (!(x > 0.0)) return {top, std::pow(x, q - 1.0), std::pow(x, q - 2.0)};
    const double inverse_x = 1.0 / x;
    return {top, top * inverse_x, top * inverse_x * inverse_x};
  }

  // The largest x with 1 + x == 1 in double (ties round to even): 2⁻⁵³.
  static constexpr double largest_negligible_factor = 0.5 * std::numeric_limits<double>::epsilon();
  // Integer exponents up to this are raised by squaring (at most 2·6 products).
  static constexpr double max_integer_exponent = 64.0;

  Parameters parameters_;
  PlaneStressElasticity elasticity_;
  return_map::ClosedFormConstants constants_;
  double inverse_exponent_;     // 1/q
  double inverse_D_;            // 1/D
  int integer_exponent_;        // q when it is an integer ≤ max_integer_exponent, else 0
  double quasi_static_ratio_;   // (2⁻⁵³)^q: r at or below it gives x ≤ 2⁻⁵³
};

}  // namespace sphshell::material
