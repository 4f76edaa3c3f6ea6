#pragma once
// The plane-stress J2 return of return_map.hpp for a flow stress that is a
// nonlinear function of the step's plastic strain increment — power-law
// hardening, a strain-rate factor in Δε̄p/Δt — as the rate-dependent laws
// (JohnsonCook, CowperSymonds) need it.
//
// The equations are those of return_map.hpp with σs,n + Ep Δε̄p replaced by a
// general σs(Δε̄p): σ = L⁻¹σ*, L = I + (Δε̄p/σs)ΓΞ (eq. 2.32–2.33) is diagonal
// in the shared eigenbasis of Γ and Ξ with entries uᵢ/σs, uᵢ = σs + κᵢΔε̄p, and
// the consistency condition (eq. 2.36, normalized by σs²) reads
//   S²(Δε̄p) − 1 = A/u₁² + B/u₂² − 1 = 0,   A = P*²/4,  B = ¾Q*² + 3s*².
// The rate term is inside σs, so the return is consistent (the flow stress is
// that of the rate the step itself produces), not lagged from the last step.
//
// Newton runs on φ = 1 − 1/S, as the J2 closed form does, in an iteration
// variable v of the flow stress' choosing: Δε̄p(v) may be a power of v when
// σs grows like a root of Δε̄p (Cowper–Symonds), where Newton in Δε̄p would
// start with an infinite slope. The flow stress gives, at v:
//   FlowStressValue{Δε̄p, dΔε̄p/dv, σs, dσs/dv}
// and dS²/dv = −2 Σᵢ (termᵢ/uᵢ) duᵢ/dv with duᵢ/dv = dσs/dv + κᵢ dΔε̄p/dv.
// The iteration is return_map's safeguarded Newton (bisection inside a bracket
// where g changes sign), with the same tolerance |S² − 1| ≤ 1e-12.

#include <sphshell/core/error.hpp>
#include <sphshell/core/types.hpp>
#include <sphshell/material/return_map.hpp>

#include <algorithm>
#include <cmath>

namespace sphshell::material::detail {

// The time step a rate-dependent law forms its strain rate with (UpdateContext).
inline void require_time_step(double time_step) {
  if (!(time_step > 0.0))
    sphshell::detail::invalid_parameter(
        "time_step", time_step,
        "must be > 0 (+inf: quasi-static) for a rate-dependent law; the solver passes its step through "
        "InternalForceAssembler::set_time_step");
}

}  // namespace sphshell::material::detail

namespace sphshell::material::return_map {

struct FlowStressValue {
  double increment;        // Δε̄p at the iteration variable v
  double increment_slope;  // dΔε̄p/dv
  double flow_stress;      // σs
  double flow_slope;       // dσs/dv
};

struct FlowStressSolution {
  StressVoigt stress;               // returned stress, on the surface σ̄ = σs
  double plastic_strain_increment;  // Δε̄p
  double flow_stress;               // σs at the returned Δε̄p
  int iterations;                   // corrections after the initial value
};

namespace detail {

// A kernel for solve_safeguarded (return_map.hpp) with the flow stress
// FlowStress: FlowStressValue operator()(double v) const.
template <class FlowStress>
class FlowStressKernel {
 public:
  FlowStressKernel(const ClosedFormConstants& constants, const StressVoigt& trial, const FlowStress& flow)
      : sum_(trial.x() + trial.y()),
        diff_(trial.x() - trial.y()),
        shear_(trial.z()),
        equibiaxial_part_(0.25 * sum_ * sum_),
        deviatoric_part_(0.75 * diff_ * diff_ + 3.0 * shear_ * shear_),
        kappa_1_(constants.kappa_1),
        kappa_2_(constants.kappa_2),
        flow_(flow) {}

  double trial_equivalent() const { return std::sqrt(equibiaxial_part_ + deviatoric_part_); }
  // Δε̄p of the return with a constant flow stress (no hardening, no rate):
  // eq. (B.8) with Ep = 0, an upper bound of the return with any σs(Δε̄p) ≥ σs(0).
  double perfectly_plastic_start(double excess) const {
    return excess * (equibiaxial_part_ + deviatoric_part_) /
           (kappa_1_ * equibiaxial_part_ + kappa_2_ * deviatoric_part_);
  }

  void evaluate(double v) {
    value_ = flow_(v);
    const double u1 = value_.flow_stress + kappa_1_ * value_.increment;
    const double u2 = value_.flow_stress + kappa_2_ * value_.increment;
    const double inverse_product = 1.0 / (u1 * u2);
    inverse_u1_ = u2 * inverse_product;
    inverse_u2_ = u1 * inverse_product;
    term_1_ = equibiaxial_part_ * inverse_u1_ * inverse_u1_;
    term_2_ = deviatoric_part_ * inverse_u2_ * inverse_u2_;
    ratio_squared_ = term_1_ + term_2_;
  }

  double relative_yield_residual() const { return ratio_squared_ - 1.0; }

  // −φ/φ' with φ = 1 − 1/S, φ' = ½S⁻³ dS²/dv. An infinite slope of σs (a root
  // law at Δε̄p = 0) gives a zero or NaN correction, which solve_safeguarded
  // replaces by bisection.
  double newton_correction() const {
    const double du1 = value_.flow_slope + kappa_1_ * value_.increment_slope;
    const double du2 = value_.flow_slope + kappa_2_ * value_.increment_slope;
    const double d_ratio_squared = -2.0 * (term_1_ * du1 * inverse_u1_ + term_2_ * du2 * inverse_u2_);
    const double ratio = std::sqrt(ratio_squared_);
    return -2.0 * ratio_squared_ * (ratio - 1.0) / d_ratio_squared;
  }

  // σ = L⁻¹σ*: each eigen-component scaled by σs/uᵢ.
  StressVoigt stress() const {
    const double returned_sum = sum_ * value_.flow_stress * inverse_u1_;
    const double deviatoric_factor = value_.flow_stress * inverse_u2_;
    const double returned_diff = diff_ * deviatoric_factor;
    return StressVoigt(0.5 * (returned_sum + returned_diff), 0.5 * (returned_sum - returned_diff),
                       shear_ * deviatoric_factor);
  }
  const FlowStressValue& value() const { return value_; }

 private:
  double sum_, diff_, shear_;
  double equibiaxial_part_, deviatoric_part_;
  double kappa_1_, kappa_2_;
  const FlowStress& flow_;
  FlowStressValue value_{0.0, 0.0, 0.0, 0.0};
  double inverse_u1_ = 0.0, inverse_u2_ = 0.0;
  double term_1_ = 0.0, term_2_ = 0.0, ratio_squared_ = 0.0;
};

}  // namespace detail

// The return of `trial` with the flow stress `flow`, by safeguarded Newton
// from v = start inside the bracket [lower, upper] of the iteration variable,
// where g(lower) > 0 ≥ g(upper) (the caller's bounds; see the laws).
template <class FlowStress>
FlowStressSolution solve_flow_stress(const ClosedFormConstants& constants, const StressVoigt& trial,
                                     const FlowStress& flow, double start, double lower, double upper) {
  detail::FlowStressKernel<FlowStress> kernel(constants, trial, flow);
  double v = start;
  kernel.evaluate(v);
  const int iterations = detail::solve_safeguarded(kernel, v, lower, upper);
  return FlowStressSolution{kernel.stress(), kernel.value().increment, kernel.value().flow_stress, iterations};
}

// The return for a flow stress whose iteration variable is Δε̄p itself and
// that does not fall below σs(0) as Δε̄p grows, given the excess σ̄* − σs(0) > 0
// of the trial stress over it. The bracket is [0, excess/min κᵢ] (uᵢ ≥ σs(0) +
// min κᵢ Δε̄p, so S ≤ 1 there). The start is `guess` when it lies inside (a
// law passes the last step's Δε̄p at the same rate: in steady flow the root
// hardly moves), else the perfectly plastic return (eq. B.8 with Ep = 0).
template <class FlowStress>
FlowStressSolution solve_flow_stress(const ClosedFormConstants& constants, const StressVoigt& trial,
                                     const FlowStress& flow, double excess, double guess = 0.0) {
  detail::FlowStressKernel<FlowStress> kernel(constants, trial, flow);
  const double upper = excess / std::min(constants.kappa_1, constants.kappa_2);
  double increment = guess > 0.0 && guess < upper ? guess : std::min(kernel.perfectly_plastic_start(excess), upper);
  kernel.evaluate(increment);
  const int iterations = detail::solve_safeguarded(kernel, increment, 0.0, upper);
  return FlowStressSolution{kernel.stress(), kernel.value().increment, kernel.value().flow_stress, iterations};
}

}  // namespace sphshell::material::return_map
