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
// The iteration runs on h = −p₁p₂(S² − 1) (FlowStressKernel below), a
// polynomial in the uᵢ, by Halley's method, in an iteration variable v of the
// flow stress' choosing: Δε̄p(v) may be a power of v when σs grows like a root
// of Δε̄p (Cowper–Symonds; Johnson–Cook from ε̄p ≈ 0 with a small n, in
// v = ε̄pⁿ), where an iteration in Δε̄p would start with an infinite slope. The flow stress gives, at v,
//   FlowStressValue{Δε̄p, dΔε̄p/dv, d²Δε̄p/dv², σs, dσs/dv, d²σs/dv²},
// and duᵢ/dv = dσs/dv + κᵢ dΔε̄p/dv (likewise the second derivatives). A rate
// term curves σs strongly (C ln ε̇* has d²/dΔε̄p² = −C/Δε̄p²): Newton's
// quadratic convergence then needed three corrections from the last step's
// Δε̄p where Halley's cubic one needs two. The iteration is return_map's
// safeguard (bisection inside a bracket where g changes sign) with the same
// tolerance |S² − 1| ≤ 1e-12.

#include <sphshell/core/error.hpp>
#include <sphshell/core/types.hpp>
#include <sphshell/material/return_map.hpp>

#include <algorithm>
#include <cmath>
#include <limits>

namespace sphshell::material::detail {

[[noreturn]] [[gnu::noinline, gnu::cold]] inline void throw_bad_time_step(double time_step) {
  sphshell::detail::invalid_parameter(
      "time_step", time_step,
      "must be > 0 (+inf: quasi-static) for a rate-dependent law; the solver passes its step through "
      "InternalForceAssembler::set_time_step");
}

// The time step a rate-dependent law forms its strain rate with (UpdateContext).
inline void require_time_step(double time_step) {
  if (!(time_step > 0.0)) throw_bad_time_step(time_step);
}

}  // namespace sphshell::material::detail

namespace sphshell::material::return_map {

// The flow stress and Δε̄p at the iteration variable v, with their first and
// second derivatives in v.
struct FlowStressValue {
  double increment;            // Δε̄p
  double increment_slope;      // dΔε̄p/dv
  double increment_curvature;  // d²Δε̄p/dv²
  double flow_stress;          // σs
  double flow_slope;           // dσs/dv
  double flow_curvature;       // d²σs/dv²
};

struct FlowStressSolution {
  StressVoigt stress;               // returned stress, on the surface σ̄ = σs
  double plastic_strain_increment;  // Δε̄p
  double flow_stress;               // σs at the returned Δε̄p
  int iterations;                   // corrections after the initial value
};

// When the return forms h′ and h″ (FlowStressKernel): with h at every
// iterate, or only where a correction follows. The latter saves them at the
// iterate that meets the tolerance (most often the first after the start),
// and the flow stress' slopes with them, inlined, where those cost much
// (Johnson–Cook's series); where they are a few products (Cowper–Symonds)
// forming them beside h keeps them off the path that follows the
// convergence test.
enum class Derivatives { with_each_value, for_corrections_only };

namespace detail {

// The consistency condition of the top of the file without divisions or
// roots. With every stress scaled by a stress of the return's size, 1/s (the
// law's last yield stress: a = As², b = Bs², ũᵢ = uᵢs), and pᵢ = ũᵢ²,
//   h(v) = p₁p₂ − a p₂ − b p₁ = (p₁ − a)(p₂ − b) − ab = −p₁p₂ (S² − 1),
// so h has the root of S² − 1, the opposite sign (h < 0 while the trial is
// not yet returned), and the test |S² − 1| ≤ tol reads |h| ≤ tol·p₁p₂. h is a
// polynomial in the ũᵢ, so h′ and h″ follow from ũᵢ′ and ũᵢ″ alone:
//   h′ = p₁′(p₂ − b) + p₂′(p₁ − a),  h″ = p₁″(p₂ − b) + 2p₁′p₂′ + p₂″(p₁ − a),
//   pᵢ′ = 2ũᵢũᵢ′,  pᵢ″ = 2(ũᵢ′² + ũᵢũᵢ″).
// Halley's correction −2hh′/(2h′² − hh″) converges cubically, so the
// curvature of a rate term (ln ε̇*, a root of ε̇) costs no extra corrections;
// it takes one division and no square root.
// Its members are forced inline into the law's update (as closed_form_lane
// is): called, the kernel lives in memory and each evaluation waits on its
// stores and loads.
template <class FlowStress, Derivatives derivatives = Derivatives::with_each_value>
class FlowStressKernel {
 public:
  [[gnu::always_inline]] FlowStressKernel(const ClosedFormConstants& constants, const StressVoigt& trial, double inverse_scale,
                   const FlowStress& flow)
      : sum_(trial.x() + trial.y()),
        diff_(trial.x() - trial.y()),
        shear_(trial.z()),
        inverse_scale_(inverse_scale),
        equibiaxial_part_(0.25 * sum_ * sum_ * inverse_scale * inverse_scale),
        deviatoric_part_((0.75 * diff_ * diff_ + 3.0 * shear_ * shear_) * inverse_scale * inverse_scale),
        kappa_1_(constants.kappa_1 * inverse_scale),
        kappa_2_(constants.kappa_2 * inverse_scale),
        flow_(flow) {}

  // Δε̄p of the return with a constant flow stress (no hardening, no rate):
  // eq. (B.8) with Ep = 0, an upper bound of the return with any σs(Δε̄p) ≥ σs(0).
  // excess·(A + B)/(κ₁A + κ₂B) = excess·s(a + b)/(κ₁s·a + κ₂s·b).
  double perfectly_plastic_start(double excess) const {
    return excess * inverse_scale_ * (equibiaxial_part_ + deviatoric_part_) /
           (kappa_1_ * equibiaxial_part_ + kappa_2_ * deviatoric_part_);
  }

  // h and the residual's scale at v; h′ and h″ with them or in correction()
  // (Derivatives).
  [[gnu::always_inline]] void evaluate(double v) {
    value_ = flow_(v);
    const double f = value_.flow_stress * inverse_scale_;
    u1_ = f + kappa_1_ * value_.increment;
    u2_ = f + kappa_2_ * value_.increment;
    const double p1 = u1_ * u1_, p2 = u2_ * u2_;
    rest_1_ = p1 - equibiaxial_part_;
    rest_2_ = p2 - deviatoric_part_;
    scale_ = p1 * p2;
    h_ = rest_1_ * rest_2_ - equibiaxial_part_ * deviatoric_part_;
    if constexpr (derivatives == Derivatives::with_each_value) slopes(dh_, ddh_);
  }

  bool converged() const { return std::abs(h_) <= relative_tolerance * scale_; }
  // h < 0: v lies below the root (S > 1).
  bool below_root() const { return h_ < 0.0; }
  // |S² − 1| = |h|/(p₁p₂) as the pair (|h|, p₁p₂), to compare without dividing.
  double residual_numerator() const { return std::abs(h_); }
  double residual_scale() const { return scale_; }
  // S² − 1 (only for the error message).
  double relative_yield_residual() const { return -h_ / scale_; }

  // Halley's correction at the last evaluated v; where hh″ ≥ h′² (far from
  // the root, where Halley would more than double Newton's step or reverse
  // it) Newton's, −h/h′.
  [[gnu::always_inline]] double correction() const {
    double dh = dh_, ddh = ddh_;
    if constexpr (derivatives == Derivatives::for_corrections_only) slopes(dh, ddh);
    const double slope_squared = dh * dh;
    const double curvature_term = h_ * ddh;
    const double denominator = curvature_term < slope_squared ? 2.0 * slope_squared - curvature_term
                                                              : 2.0 * slope_squared;
    return -2.0 * h_ * dh / denominator;
  }

  // σ = L⁻¹σ*: each eigen-component scaled by σs/uᵢ (= f/ũᵢ).
  [[gnu::always_inline]] StressVoigt stress() const {
    const double f = value_.flow_stress * inverse_scale_;
    const double inverse_product = f / (u1_ * u2_);
    const double returned_sum = sum_ * u2_ * inverse_product;
    const double deviatoric_factor = u1_ * inverse_product;
    const double returned_diff = diff_ * deviatoric_factor;
    return StressVoigt(0.5 * (returned_sum + returned_diff), 0.5 * (returned_sum - returned_diff),
                       shear_ * deviatoric_factor);
  }
  const FlowStressValue& value() const { return value_; }

 private:
  // h′ and h″ at the last evaluated v (the top of the class).
  [[gnu::always_inline]] void slopes(double& dh, double& ddh) const {
    const double df = value_.flow_slope * inverse_scale_, ddf = value_.flow_curvature * inverse_scale_;
    const double du1 = df + kappa_1_ * value_.increment_slope, du2 = df + kappa_2_ * value_.increment_slope;
    const double ddu1 = ddf + kappa_1_ * value_.increment_curvature,
                 ddu2 = ddf + kappa_2_ * value_.increment_curvature;
    const double dp1 = 2.0 * u1_ * du1, dp2 = 2.0 * u2_ * du2;
    const double ddp1 = 2.0 * (du1 * du1 + u1_ * ddu1), ddp2 = 2.0 * (du2 * du2 + u2_ * ddu2);
    dh = dp1 * rest_2_ + dp2 * rest_1_;
    ddh = ddp1 * rest_2_ + 2.0 * dp1 * dp2 + ddp2 * rest_1_;
  }

  double sum_, diff_, shear_;
  double inverse_scale_;                     // s
  double equibiaxial_part_, deviatoric_part_;  // a, b
  double kappa_1_, kappa_2_;                 // κᵢs
  const FlowStress& flow_;
  FlowStressValue value_{0.0, 0.0, 0.0, 0.0, 0.0, 0.0};
  double u1_ = 0.0, u2_ = 0.0;
  double rest_1_ = 0.0, rest_2_ = 0.0;  // p₁ − a, p₂ − b
  double scale_ = 0.0, h_ = 0.0;
  double dh_ = 0.0, ddh_ = 0.0;  // with_each_value only
};

// return_map.hpp's safeguard around Halley's correction: g(lower) > 0 ≥
// g(upper) (h < 0 at lower); a correction that leaves the bracket, or any
// after one that failed to halve |S² − 1|, is replaced by bisection; the
// same tolerance, the same stop when the bracket collapses to round-off and
// the same limit of max_iterations. The kernel arrives evaluated at v.
template <class Kernel>
[[gnu::always_inline]] inline int solve_bracketed(Kernel& kernel, double& v, double lower, double upper) {
  int iterations = 0;
  bool distrust = false;
  while (!kernel.converged()) {
    if (kernel.below_root())
      lower = v;
    else
      upper = v;
    if (upper - lower <= 4.0 * std::numeric_limits<double>::epsilon() * upper) break;
    if (iterations == max_iterations) throw_not_converged(v, kernel.relative_yield_residual());
    const double next = v + kernel.correction();
    v = !distrust && next > lower && next < upper ? next : 0.5 * (lower + upper);
    const double previous_numerator = kernel.residual_numerator(), previous_scale = kernel.residual_scale();
    kernel.evaluate(v);
    distrust = kernel.residual_numerator() * previous_scale > 0.5 * previous_numerator * kernel.residual_scale();
    ++iterations;
  }
  return iterations;
}

}  // namespace detail

// The return of `trial` with the flow stress `flow` (its stresses scaled by
// inverse_scale, 1/s: the reciprocal of a stress of the return's size), by safeguarded Halley iteration from v = start inside
// the bracket [lower, upper] of the iteration variable, where g(lower) > 0 ≥
// g(upper) (the caller's bounds; see the laws).
template <Derivatives derivatives = Derivatives::with_each_value, class FlowStress>
[[gnu::always_inline]] inline FlowStressSolution solve_flow_stress(const ClosedFormConstants& constants, const StressVoigt& trial,
                                     double inverse_scale, const FlowStress& flow, double start, double lower,
                                     double upper) {
  detail::FlowStressKernel<FlowStress, derivatives> kernel(constants, trial, inverse_scale, flow);
  double v = start;
  kernel.evaluate(v);
  const int iterations = detail::solve_bracketed(kernel, v, lower, upper);
  return FlowStressSolution{kernel.stress(), kernel.value().increment, kernel.value().flow_stress, iterations};
}

// The return for a flow stress whose iteration variable is Δε̄p itself and
// that does not fall below σs(0) as Δε̄p grows, given the excess σ̄* − σs(0) > 0
// of the trial stress over it. The bracket is [0, excess/min κᵢ] (uᵢ ≥ σs(0) +
// min κᵢ Δε̄p, so S ≤ 1 there). The start is `guess` when it lies inside (a
// law passes the last step's Δε̄p at the same rate: in steady flow the root
// hardly moves), else the perfectly plastic return (eq. B.8 with Ep = 0).
template <Derivatives derivatives = Derivatives::with_each_value, class FlowStress>
[[gnu::always_inline]] inline FlowStressSolution solve_flow_stress(const ClosedFormConstants& constants, const StressVoigt& trial,
                                     double inverse_scale, const FlowStress& flow, double excess,
                                     double guess = 0.0) {
  detail::FlowStressKernel<FlowStress, derivatives> kernel(constants, trial, inverse_scale, flow);
  const double upper = excess / std::min(constants.kappa_1, constants.kappa_2);
  double increment = guess > 0.0 && guess < upper ? guess : std::min(kernel.perfectly_plastic_start(excess), upper);
  kernel.evaluate(increment);
  const int iterations = detail::solve_bracketed(kernel, increment, 0.0, upper);
  return FlowStressSolution{kernel.stress(), kernel.value().increment, kernel.value().flow_stress, iterations};
}

}  // namespace sphshell::material::return_map
