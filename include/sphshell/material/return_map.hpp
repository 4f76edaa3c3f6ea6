#pragma once
// Plane-stress J2 return map (eq. 2.31–2.39, Appendices A–B), shared by
// J2Plasticity and LemaitreDamage (which returns its effective stress).
//
// Given a trial stress σ* outside the yield surface, find Δε̄p ≥ 0 with
//   σ = L⁻¹σ*,  L = I + cΓΞ,  c = Δε̄p/σs,  σs = σs,n + Ep Δε̄p   (eq. 2.32–2.34)
//   g(Δε̄p) = σᵀΞσ − σs² = 0                                        (eq. 2.36)
// c uses the consistent scaling Δεp = (Δε̄p/σs)Ξσ rather than the paper's
// printed 3Δε̄p/σs: with the factor 3 a uniaxial return produces three times the
// von Mises equivalent plastic strain, so hardening would be applied to the
// wrong strain (docs/method.md, "The consistent scaling"). Appendix A's derivative and
// Appendix B's K are rederived for the same scaling.
//
// Two implementations of the same equations:
// - closed form: Γ and Ξ share the eigenvectors (1,1,0)/√2, (1,−1,0)/√2,
//   (0,0,1); ΓΞ has eigenvalues κ₁ = E/(2(1−ν)), κ₂ = κ₃ = 3G there, so L is
//   diagonal with entries 1 + cκᵢ. Writing P = σx+σy, Q = σx−σy, s = σxy,
//   σᵀΞσ = P²/4 + ¾Q² + 3s², and because 1 + cκᵢ = uᵢ/σs with
//   uᵢ = σs,n + (κᵢ + Ep)Δε̄p (linear in Δε̄p), each component of σ is its trial
//   value times σs/uᵢ. g and its derivative are then a handful of flops.
// - generic: the literal 3×3 L, its inverse and the matrix products, as in the
//   paper; kept as the reference and the benchmark baseline.
//
// The function Newton iterates on (NewtonFunction): by default the unsquared
// yield function (2.19) normalized by σ̄, φ = 1 − σs/σ̄(Δε̄p), which has the
// same root and sign as g. Appendix B's initial value is exactly the first
// Newton step of φ from Δε̄p = 0, and φ is nearly linear in Δε̄p (exactly linear
// for a purely deviatoric trial stress), so one correction usually meets the
// tolerance; the squared g of eq. (2.36) curves more and typically needs one
// more correction for the same 1e-12 (see bench_return_map). Either way the
// stopping test is on g: |g| ≤ 1e-12 σs².

#include <sphshell/core/error.hpp>
#include <sphshell/core/types.hpp>
#include <sphshell/material/elastic.hpp>

#include <Eigen/LU>

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

namespace sphshell::material::return_map {

// |g| ≤ relative_tolerance·σs² ends the iteration: σ̄ then matches σs to ~5e-13.
inline constexpr double relative_tolerance = 1e-12;
// Bisection alone needs ~60 halvings to reach round-off; far more than the
// Newton iteration ever uses. Exceeding it throws.
inline constexpr int max_iterations = 100;

struct Solution {
  StressVoigt stress;               // returned stress, on the yield surface
  double plastic_strain_increment;  // Δε̄p
  int iterations;  // Newton (or safeguard) corrections applied after the initial value
};

// What the closed form needs from E, ν and Ep, computed once per law so the
// hot path has no divisions for it.
struct ClosedFormConstants {
  ClosedFormConstants(const PlaneStressElasticity& elasticity, double plastic_modulus)
      : kappa_1(elasticity.equibiaxial_stiffness()),
        kappa_2(elasticity.deviatoric_stiffness()),
        slope_1(kappa_1 + plastic_modulus),
        slope_2(kappa_2 + plastic_modulus),
        plastic_modulus(plastic_modulus),
        inverse_max_slope(1.0 / std::max(slope_1, slope_2)),
        inverse_min_slope(1.0 / std::min(slope_1, slope_2)),
        inverse_slope_2(1.0 / slope_2),
        slope_difference(slope_2 - slope_1) {}
  double kappa_1, kappa_2;  // eigenvalues of ΓΞ: E/(2(1−ν)) and 3G
  double slope_1, slope_2;  // κᵢ + Ep
  double plastic_modulus;
  double inverse_max_slope, inverse_min_slope, inverse_slope_2;
  double slope_difference;  // slope₂ − slope₁ = κ₂ − κ₁
};

namespace detail {

// A negative count of fixed Newton steps would silently mean "iterate to
// convergence" (0); it is refused instead.
inline void require_valid(const ReturnMapOptions& options) {
  if (options.fixed_iterations < 0)
    sphshell::detail::invalid_parameter("fixed_iterations", options.fixed_iterations,
                                        "must be >= 0 (0: Newton to convergence)");
}

[[noreturn]] [[gnu::noinline, gnu::cold]] inline void throw_not_converged(
    double increment, double relative_residual) {
  std::ostringstream message;
  message.precision(17);
  message << "sphshell: plane-stress return map did not converge in " << max_iterations
          << " iterations (delta eps_p = " << increment
          << ", |g|/sigma_s^2 = " << std::abs(relative_residual) << ")";
  throw Error(message.str());
}

// Reached only from the plastic branch: a NaN state fails the elastic test and lands here.
[[noreturn]] [[gnu::noinline, gnu::cold]] inline void throw_non_finite_trial(
    const StressVoigt& trial, double yield_stress) {
  std::ostringstream message;
  message.precision(17);
  message << "sphshell: non-finite material state in the return map (trial stress = (" << trial.x()
          << ", " << trial.y() << ", " << trial.z() << "), yield stress = " << yield_stress << ")";
  throw Error(message.str());
}

// A kernel evaluates the return at a trial Δε̄p and caches what the next calls need:
//   void evaluate(double increment);
//   double relative_yield_residual() const;  g/σs² = (σ̄/σs)² − 1 at the last evaluation
//   double newton_correction() const;        −f/f' for the selected Newton function f
//   StressVoigt stress() const;              the returned stress there
// The test |g| ≤ tol·σs² is applied as |g/σs²| ≤ tol.

// Safeguarded Newton–Raphson on the decreasing g, with g(lower) > 0 > g(upper)
// (upper may be +inf: then the bracket grows by doubling). A Newton step that
// leaves the bracket, or any step after one that failed to halve |g|, is
// replaced by bisection (or doubling), so convergence never hinges on the
// initial value. The kernel arrives evaluated at `increment` and is left
// evaluated at the returned Δε̄p. Returns the number of corrections applied.
// `iterations` and `distrust_newton` let a caller that has already applied
// corrections itself (the closed form's fast path) continue exactly where it stopped.
template <class Kernel>
inline int solve_safeguarded(Kernel& kernel, double& increment, double lower, double upper,
                             int iterations = 0, bool distrust_newton = false) {
  while (!(std::abs(kernel.relative_yield_residual()) <= relative_tolerance)) {
    if (kernel.relative_yield_residual() > 0.0)
      lower = increment;
    else
      upper = increment;
    // Bracket collapsed to round-off: no representable Δε̄p does better.
    if (upper < std::numeric_limits<double>::infinity() &&
        upper - lower <= 4.0 * std::numeric_limits<double>::epsilon() * upper)
      break;
    if (iterations == max_iterations)
      throw_not_converged(increment, kernel.relative_yield_residual());
    const double newton = increment + kernel.newton_correction();
    if (!distrust_newton && newton > lower && newton < upper) {
      increment = newton;
    } else if (upper < std::numeric_limits<double>::infinity()) {
      increment = 0.5 * (lower + upper);
    } else {
      increment = lower > 0.0 ? 2.0 * lower : 2.0 * increment + 1e-12;
    }
    const double previous = std::abs(kernel.relative_yield_residual());
    kernel.evaluate(increment);
    distrust_newton = std::abs(kernel.relative_yield_residual()) > 0.5 * previous;
    ++iterations;
  }
  return iterations;
}

// Plain Newton, a fixed number of steps, no test: the "fixed iterations" baseline.
// The kernel arrives evaluated at `increment`.
template <class Kernel>
inline void solve_fixed(Kernel& kernel, double& increment, int steps) {
  for (int step = 0; step < steps; ++step) {
    increment += kernel.newton_correction();
    kernel.evaluate(increment);
  }
}

// The closed form in the shared eigenbasis of Γ and Ξ (see the top of the file).
class ClosedFormKernel {
 public:
  ClosedFormKernel(const ClosedFormConstants& constants, const StressVoigt& trial,
                   double yield_stress, NewtonFunction function)
      : sum_(trial.x() + trial.y()),
        diff_(trial.x() - trial.y()),
        shear_(trial.z()),
        equibiaxial_part_(0.25 * sum_ * sum_),
        deviatoric_part_(0.75 * diff_ * diff_ + 3.0 * shear_ * shear_),
        constants_(constants),
        slope_1_(constants.slope_1),
        slope_2_(constants.slope_2),
        yield_stress_(yield_stress),
        plastic_modulus_(constants.plastic_modulus),
        function_(function) {}

  double trial_equivalent() const { return std::sqrt(equibiaxial_part_ + deviatoric_part_); }

  // eq. (B.8), Δε̄p⁰ = (σ̄* − σs,n)/(σ̂ + Ep), with σ̂ = σ*ᵀKᵀΞσ*/σ̄* and
  // K = ΓΞ/σ̄* (B.3, B.5): σ̂ is the stiffness-weighted mean (κ₁A + κ₂B)/(A + B),
  // so Δε̄p⁰ = excess·(A + B)/(κ₁A + κ₂B + Ep(A + B)) = numerator/denominator.
  double appendix_b_numerator(double excess) const {
    return excess * (equibiaxial_part_ + deviatoric_part_);
  }
  double appendix_b_denominator() const {
    return constants_.kappa_1 * equibiaxial_part_ + constants_.kappa_2 * deviatoric_part_ +
           plastic_modulus_ * (equibiaxial_part_ + deviatoric_part_);
  }
  double radial_return_start(double excess) const { return excess * constants_.inverse_slope_2; }
  // Since min uᵢ ≤ σs σ̄*/σ̄ ≤ max uᵢ, the root lies in [excess/max slope, excess/min slope].
  double lower_bound(double excess) const { return excess * constants_.inverse_max_slope; }
  double upper_bound(double excess) const { return excess * constants_.inverse_min_slope; }

  void evaluate(double increment) {
    sigma_s_ = yield_stress_ + plastic_modulus_ * increment;
    const double u1 = yield_stress_ + slope_1_ * increment;
    const double u2 = yield_stress_ + slope_2_ * increment;
    const double inverse_product = 1.0 / (u1 * u2);  // one division for both 1/uᵢ
    inverse_u1_ = u2 * inverse_product;
    inverse_u2_ = u1 * inverse_product;
    term_1_ = equibiaxial_part_ * inverse_u1_ * inverse_u1_;
    term_2_ = deviatoric_part_ * inverse_u2_ * inverse_u2_;
    ratio_squared_ = term_1_ + term_2_;  // S² = (σ̄/σs)² = A/u₁² + B/u₂²
  }

  // evaluate(numerator/denominator) without waiting for that division: with
  // nᵢ = σs,n·denominator + slopeᵢ·numerator, 1/uᵢ = denominator/nᵢ, and one
  // division 1/(n₁n₂) serves both. Used for the Appendix-B start, whose
  // fraction form is known.
  void evaluate_fraction(double numerator, double denominator, double increment) {
    sigma_s_ = yield_stress_ + plastic_modulus_ * increment;
    const double n1 = yield_stress_ * denominator + slope_1_ * numerator;
    const double n2 = yield_stress_ * denominator + slope_2_ * numerator;
    const double inverse_product = denominator / (n1 * n2);
    inverse_u1_ = n2 * inverse_product;
    inverse_u2_ = n1 * inverse_product;
    term_1_ = equibiaxial_part_ * inverse_u1_ * inverse_u1_;
    term_2_ = deviatoric_part_ * inverse_u2_ * inverse_u2_;
    ratio_squared_ = term_1_ + term_2_;
  }

  // The state evaluate(increment) leaves, from reciprocals 1/uᵢ obtained elsewhere.
  void assume_evaluated(double increment, double inverse_u1, double inverse_u2) {
    sigma_s_ = yield_stress_ + plastic_modulus_ * increment;
    inverse_u1_ = inverse_u1;
    inverse_u2_ = inverse_u2;
    term_1_ = equibiaxial_part_ * inverse_u1_ * inverse_u1_;
    term_2_ = deviatoric_part_ * inverse_u2_ * inverse_u2_;
    ratio_squared_ = term_1_ + term_2_;
  }

  double relative_yield_residual() const { return ratio_squared_ - 1.0; }

  double newton_correction() const {
    const double d_ratio_squared =
        -2.0 * (term_1_ * slope_1_ * inverse_u1_ + term_2_ * slope_2_ * inverse_u2_);
    if (function_ == NewtonFunction::squared) {
      // Appendix A in this basis: g = σs²(S² − 1), g' = 2σsEp(S² − 1) + σs² dS².
      const double g = ratio_squared_ - 1.0;
      return -sigma_s_ * g / (2.0 * plastic_modulus_ * g + sigma_s_ * d_ratio_squared);
    }
    // φ = 1 − 1/S, φ' = ½S⁻³ dS², so −φ/φ' = −2S²(S − 1)/dS²; the reciprocal
    // does not wait for the square root.
    const double inverse_slope = -2.0 / d_ratio_squared;
    const double ratio = std::sqrt(ratio_squared_);
    return inverse_slope * ratio_squared_ * (ratio - 1.0);
  }

  // σ = L⁻¹σ*: each eigen-component scaled by 1/(1 + cκᵢ) = σs/uᵢ.
  StressVoigt stress() const {
    const double returned_sum = sum_ * sigma_s_ * inverse_u1_;
    const double deviatoric_factor = sigma_s_ * inverse_u2_;
    const double returned_diff = diff_ * deviatoric_factor;
    return StressVoigt(0.5 * (returned_sum + returned_diff), 0.5 * (returned_sum - returned_diff),
                       shear_ * deviatoric_factor);
  }

 private:
  double sum_, diff_, shear_;  // P*, Q*, s*
  double equibiaxial_part_;    // A: σ̄*² along (1,1,0)
  double deviatoric_part_;     // B: σ̄*² along (1,−1,0) and (0,0,1)
  const ClosedFormConstants& constants_;
  double slope_1_, slope_2_;  // duᵢ/dΔε̄p = κᵢ + Ep
  double yield_stress_, plastic_modulus_;
  NewtonFunction function_;
  double sigma_s_ = 0.0, inverse_u1_ = 0.0, inverse_u2_ = 0.0;
  double term_1_ = 0.0, term_2_ = 0.0, ratio_squared_ = 0.0;
};

// The literal matrix form: L = I + cΓΞ, σ = L⁻¹σ*, and Appendix A's derivative
// dσ/dΔε̄p = −L⁻¹ΓΞσ · dc/dΔε̄p with dc/dΔε̄p = σs,n/σs².
class GenericKernel {
 public:
  GenericKernel(const PlaneStressElasticity& elasticity, const StressVoigt& trial,
                double yield_stress, double plastic_modulus, NewtonFunction function)
      : xi_(von_mises_matrix()),
        gamma_xi_(elasticity.matrix() * xi_),
        trial_(trial),
        yield_stress_(yield_stress),
        plastic_modulus_(plastic_modulus),
        function_(function) {}

  double trial_equivalent() const { return std::sqrt(trial_.dot(xi_ * trial_)); }
  double sigma_hat() const {
    const double equivalent = trial_equivalent();
    const Matrix3 k = gamma_xi_ / equivalent;                        // eq. (B.3)
    return trial_.dot(k.transpose() * (xi_ * trial_)) / equivalent;  // eq. (B.5)
  }

  void evaluate(double increment) {
    sigma_s_ = yield_stress_ + plastic_modulus_ * increment;
    const Matrix3 l = Matrix3::Identity() + (increment / sigma_s_) * gamma_xi_;
    inverse_l_ = l.inverse();
    stress_ = inverse_l_ * trial_;
  }

  double scale() const { return sigma_s_ * sigma_s_; }
  double relative_yield_residual() const {
    return (stress_.dot(xi_ * stress_) - scale()) / scale();
  }

  double newton_correction() const {
    const double dc = yield_stress_ / scale();
    const StressVoigt d_stress = -dc * (inverse_l_ * (gamma_xi_ * stress_));
    const StressVoigt xi_stress = xi_ * stress_;
    const double equivalent_squared = stress_.dot(xi_stress);
    const double d_equivalent_squared = 2.0 * xi_stress.dot(d_stress);
    if (function_ == NewtonFunction::squared) {
      const double g = equivalent_squared - scale();
      return -g / (d_equivalent_squared - 2.0 * sigma_s_ * plastic_modulus_);
    }
    // φ = 1 − σs/σ̄: φ' = −Ep/σ̄ + σs σ̄'/σ̄², σ̄' = (σ̄²)'/(2σ̄).
    const double equivalent = std::sqrt(equivalent_squared);
    const double phi = 1.0 - sigma_s_ / equivalent;
    const double d_phi = -plastic_modulus_ / equivalent +
                         sigma_s_ * d_equivalent_squared / (2.0 * equivalent_squared * equivalent);
    return -phi / d_phi;
  }

  StressVoigt stress() const { return stress_; }

 private:
  Matrix3 xi_, gamma_xi_;
  StressVoigt trial_;
  double yield_stress_, plastic_modulus_;
  NewtonFunction function_;
  double sigma_s_ = 0.0;
  Matrix3 inverse_l_ = Matrix3::Identity();
  StressVoigt stress_ = StressVoigt::Zero();
};

}  // namespace detail

namespace detail {

// Every option combination, through the kernel: the reference path of the closed form.
inline Solution closed_form_general(const ClosedFormConstants& constants, const StressVoigt& trial,
                                   double yield_stress, const ReturnMapOptions& options) {
  detail::ClosedFormKernel kernel(constants, trial, yield_stress, options.newton_function);
  const double excess = kernel.trial_equivalent() - yield_stress;
  // A trial stress on or inside the surface (callers check first; this catches round-off) needs no
  // return.
  if (!(excess > 0.0)) {
    if (!std::isfinite(excess)) detail::throw_non_finite_trial(trial, yield_stress);
    return Solution{trial, 0.0, 0};
  }
  double increment = 0.0;
  switch (options.initial_guess) {
    case InitialGuess::appendix_b: {
      const double numerator = kernel.appendix_b_numerator(excess);
      const double denominator = kernel.appendix_b_denominator();
      increment = numerator / denominator;
      kernel.evaluate_fraction(numerator, denominator, increment);
      break;
    }
    case InitialGuess::zero:
      increment = 0.0;
      kernel.evaluate(increment);
      break;
    case InitialGuess::radial_return:
      increment = kernel.radial_return_start(excess);
      kernel.evaluate(increment);
      break;
  }
  int iterations = options.fixed_iterations;
  if (options.fixed_iterations > 0) {
    detail::solve_fixed(kernel, increment, options.fixed_iterations);
  } else {
    // The analytic bracket, widened to contain the start.
    iterations = detail::solve_safeguarded(kernel, increment,
                                           std::min(kernel.lower_bound(excess), increment),
                                           std::max(kernel.upper_bound(excess), increment));
  }
  return Solution{kernel.stress(), increment, iterations};
}

// The fast path's way out when anything is unusual: the same solve from scratch.
[[gnu::noinline, gnu::cold]] inline Solution closed_form_fallback(
    const ClosedFormConstants& constants, const StressVoigt& trial, double yield_stress) {
  return closed_form_general(constants, trial, yield_stress, ReturnMapOptions{});
}

// The fast path's continuation when one correction did not reach the tolerance:
// the safeguarded iteration picks up with the same bracket, count and trust flag.
[[gnu::noinline, gnu::cold]] inline Solution closed_form_continue(
    const ClosedFormConstants& constants, const StressVoigt& trial, double yield_stress,
    double increment, double inverse_u1, double inverse_u2, double lower, double upper,
    bool distrust_newton) {
  ClosedFormKernel kernel(constants, trial, yield_stress, NewtonFunction::normalized);
  kernel.assume_evaluated(increment, inverse_u1, inverse_u2);
  const int iterations =
      solve_safeguarded(kernel, increment, lower, upper, /*iterations=*/1, distrust_newton);
  return Solution{kernel.stress(), increment, iterations};
}

// Above this |ε₀| the series for the first correction is not used (the general path takes over).
inline constexpr double series_limit = 1.0 / 4096.0;
// Above this |slopeᵢ·correction/uᵢ| the reciprocals at the corrected Δε̄p come from a division.
inline constexpr double reciprocal_series_limit = 1.0 / 8192.0;

// The default options (Appendix-B start, φ, converged, safeguarded), with the
// same equations as closed_form_general reorganized so that the dependency chain
// from the trial stress to the returned stress holds one square root and two
// divisions side by side instead of two square roots and three divisions in a row:
// - uᵢ(Δε̄p⁰) = σs,n + slopeᵢΔε̄p⁰ at the start Δε̄p⁰ = excess·σ̄*²/D (eq. B.8,
//   D = slope₁A + slope₂B) is written as a multiply-add in σ̄*, with 1/D taken
//   while the square root runs.
// - At the start, ε₀ = S² − 1 = (Au₂² + Bu₁² − M)/M with M = (u₁u₂)², and
//   dS²/dΔε̄p = −2Y/(u₁u₂)³ with Y = A·slope₁u₂³ + B·slope₂u₁³. The φ-Newton
//   correction −2S²(S − 1)/dS² = q(ε)·(u₁u₂)³/(2Y), q(ε) = 2(1 + ε)(√(1 + ε) − 1)
//   = ε(1 + ¾ε − ⅛ε² + …), is taken from the series (|ε| ≤ 2⁻¹²), so no second
//   square root; its one division runs alongside 1/M.
// - 1/uᵢ at the corrected Δε̄p¹ follow from 1/uᵢ(Δε̄p⁰) by a series in
//   xᵢ = slopeᵢ·correction/uᵢ(Δε̄p⁰) (a division when |xᵢ| > 2⁻¹³); the convergence
//   test is the kernel's, |S² − 1| ≤ tol at Δε̄p¹, and the returned stress is
//   σs/uᵢ times the trial components, as in ClosedFormKernel::stress().
// The safeguards are those of solve_safeguarded: the analytic bracket, updated
// by the sign of g at the start, the collapse test, and the Newton step only
// accepted strictly inside it. Anything else — a start already within the
// tolerance, |ε₀| above the series limit, a step outside the bracket, a
// non-finite or out-of-range intermediate — leaves for closed_form_general,
// which then runs the very same iteration from scratch; a correction that misses
// the tolerance continues in solve_safeguarded with the same bracket and counters.
inline Solution closed_form_default(const ClosedFormConstants& constants, const StressVoigt& trial,
                                   double yield_stress) {
  const double sum = trial.x() + trial.y();
  const double diff = trial.x() - trial.y();
  const double shear = trial.z();
  const double equibiaxial = 0.25 * sum * sum;                          // A
  const double deviatoric = 0.75 * diff * diff + 3.0 * shear * shear;  // B
  const double trial_squared = equibiaxial + deviatoric;               // σ̄*²
  const double trial_equivalent = std::sqrt(trial_squared);
  const double excess = trial_equivalent - yield_stress;
  if (!(excess > 0.0)) {
    if (!std::isfinite(excess)) throw_non_finite_trial(trial, yield_stress);
    return Solution{trial, 0.0, 0};
  }
  const double slope_1 = constants.slope_1, slope_2 = constants.slope_2;
  // Off the square root's path: 1/D and the coefficients of uᵢ(Δε̄p⁰) as functions of σ̄*.
  const double inverse_denominator = 1.0 / (slope_1 * equibiaxial + slope_2 * deviatoric);
  const double scaled_trial_squared = trial_squared * inverse_denominator;
  const double start = excess * scaled_trial_squared;  // eq. (B.8), Δε̄p⁰
  // uᵢ(Δε̄p⁰) = σs,n + slopeᵢΔε̄p⁰ = σs,n(1 − slopeᵢσ̄*²/D) + (slopeᵢσ̄*²/D)·σ̄*, with
  // 1 − slope₁σ̄*²/D = (slope₂ − slope₁)B/D and 1 − slope₂σ̄*²/D = −(slope₂ − slope₁)A/D.
  const double difference_scaled = constants.slope_difference * inverse_denominator * yield_stress;
  const double u1 = difference_scaled * deviatoric + (slope_1 * scaled_trial_squared) * trial_equivalent;
  const double u2 = (slope_2 * scaled_trial_squared) * trial_equivalent - difference_scaled * equibiaxial;
  const double product = u1 * u2;
  const double u1_squared = u1 * u1, u2_squared = u2 * u2;
  const double m = product * product;
  const double inverse_m = 1.0 / m;
  // 1/(−dS²/dΔε̄p) = (u₁u₂)³/(2Y), Y = A·slope₁u₂³ + B·slope₂u₁³.
  const double twice_y = ((2.0 * slope_1 * equibiaxial) * u2) * u2_squared +
                         ((2.0 * slope_2 * deviatoric) * u1) * u1_squared;
  // ε₀·M = A u₂² + B u₁² − (u₁u₂)², subtracted before the division completes.
  const double residual_0_numerator =
      equibiaxial * u2_squared + deviatoric * u1_squared - m;
  const double residual_0 = residual_0_numerator * inverse_m;  // ε₀ = S² − 1 at Δε̄p⁰
  if (!(std::abs(residual_0) > relative_tolerance && std::abs(residual_0) <= series_limit))
    return closed_form_fallback(constants, trial, yield_stress);
  // Bracket of solve_safeguarded's first pass.
  double lower = std::min(excess * constants.inverse_max_slope, start);
  double upper = std::max(excess * constants.inverse_min_slope, start);
  if (residual_0 > 0.0)
    lower = start;
  else
    upper = start;
  // −2S²(S − 1)/dS² = q(ε)/ε · ε₀M·u₁u₂/(2Y) with q(ε)/ε = 1 + ¾ε − ⅛ε² + 3/64 ε³ − …;
  // the dropped terms are < 7e-13 of the correction for |ε| ≤ 2⁻¹², which moves the new
  // residual by < 4e-16. With ε = ε₀M/M the truncated series is (M² + ¾ε₀M·M − ⅛(ε₀M)²)/M²,
  // so the correction takes one division, by 2Y·M², which runs alongside that of M.
  const double series_numerator =
      (m * m + (0.75 * residual_0_numerator) * m) -
      0.125 * residual_0_numerator * residual_0_numerator;
  const double correction = ((residual_0_numerator * product) * series_numerator) /
                            (twice_y * (m * m));
  const double increment = start + correction;
  if (!(upper - lower > 4.0 * std::numeric_limits<double>::epsilon() * upper && increment > lower &&
        increment < upper))
    return closed_form_fallback(constants, trial, yield_stress);
  // Evaluation at Δε̄p¹ (ClosedFormKernel::evaluate). 1/uᵢ(Δε̄p¹) follows from
  // 1/uᵢ(Δε̄p⁰) = u_j·u₁u₂/M without a division: with xᵢ = slopeᵢ·correction/uᵢ(Δε̄p⁰),
  // 1/uᵢ(Δε̄p¹) = 1/uᵢ(Δε̄p⁰)·(1 − xᵢ)(1 + xᵢ²)·(1 − xᵢ⁴/(1 + xᵢ)), and for |xᵢ| ≤ 2⁻¹³
  // the last factor is 1 to below 3e-16 (larger xᵢ: a division). |xᵢ| ≲ |ε₀|/2.
  const double sigma_s = yield_stress + constants.plastic_modulus * increment;
  const double inverse_u1_start = (u2 * product) * inverse_m;
  const double inverse_u2_start = (u1 * product) * inverse_m;
  const double x1 = (slope_1 * inverse_u1_start) * correction;
  const double x2 = (slope_2 * inverse_u2_start) * correction;
  // 1/uᵢ(Δε̄p¹) = reciprocal_i·factor_i.
  double reciprocal_1 = inverse_u1_start, reciprocal_2 = inverse_u2_start;
  double factor_1, factor_2;
  if (std::abs(x1) <= reciprocal_series_limit && std::abs(x2) <= reciprocal_series_limit) {
    factor_1 = (1.0 - x1) * (1.0 + x1 * x1);
    factor_2 = (1.0 - x2) * (1.0 + x2 * x2);
  } else {
    const double u1_new = yield_stress + slope_1 * increment;
    const double u2_new = yield_stress + slope_2 * increment;
    const double inverse_product = 1.0 / (u1_new * u2_new);
    reciprocal_1 = u2_new * inverse_product;
    reciprocal_2 = u1_new * inverse_product;
    factor_1 = factor_2 = 1.0;
  }
  const double inverse_u1 = reciprocal_1 * factor_1, inverse_u2 = reciprocal_2 * factor_2;
  const double residual_1 =
      (equibiaxial * inverse_u1 * inverse_u1 + deviatoric * inverse_u2 * inverse_u2) - 1.0;
  if (!(std::abs(residual_1) <= relative_tolerance))
    return closed_form_continue(constants, trial, yield_stress, increment, inverse_u1,
                                inverse_u2, lower, upper,
                                std::abs(residual_1) > 0.5 * std::abs(residual_0));
  // σ = L⁻¹σ*: each eigen-component scaled by σs/uᵢ (the factors applied last).
  const double half_sigma_s = 0.5 * sigma_s;
  const double returned_half_sum = ((sum * half_sigma_s) * reciprocal_1) * factor_1;
  const double deviatoric_scale = sigma_s * reciprocal_2;
  const double returned_half_diff = ((0.5 * diff) * deviatoric_scale) * factor_2;
  return Solution{StressVoigt(returned_half_sum + returned_half_diff,
                              returned_half_sum - returned_half_diff,
                              (shear * deviatoric_scale) * factor_2),
                  increment, 1};
}

// One lane of the batched return (lanes.hpp): closed_form_default's fast path,
// operation for operation and in the same order, without its branches, for a
// trial stress given by P* = σx+σy, Q* = σx−σy, s* = σxy, A, B and σ̄* = √(A+B)
// (the caller takes the square roots of all lanes at once). `fast` is false
// where closed_form_default would leave its fast path (trial on or inside the
// surface, |ε₀| outside the series range, a step outside the bracket, the
// reciprocals needing a division, or a residual above the tolerance); the
// caller then solves that lane with closed_form, which takes the very same
// route. Where `fast` is true, stress and increment are closed_form_default's.
struct LaneReturn {
  double xx, yy, xy;
  double increment;
  bool fast;
};

// Forced inline: called out of line (as GCC did inside the section loop) the
// lane loop around it stays scalar, a call per lane.
[[gnu::always_inline]] inline LaneReturn closed_form_lane(const ClosedFormConstants& constants, double sum, double diff, double shear,
                                   double equibiaxial, double deviatoric, double trial_equivalent,
                                   double yield_stress) {
  const double trial_squared = equibiaxial + deviatoric;
  const double excess = trial_equivalent - yield_stress;
  const double slope_1 = constants.slope_1, slope_2 = constants.slope_2;
  const double inverse_denominator = 1.0 / (slope_1 * equibiaxial + slope_2 * deviatoric);
  const double scaled_trial_squared = trial_squared * inverse_denominator;
  const double start = excess * scaled_trial_squared;
  const double difference_scaled = constants.slope_difference * inverse_denominator * yield_stress;
  const double u1 = difference_scaled * deviatoric + (slope_1 * scaled_trial_squared) * trial_equivalent;
  const double u2 = (slope_2 * scaled_trial_squared) * trial_equivalent - difference_scaled * equibiaxial;
  const double product = u1 * u2;
  const double u1_squared = u1 * u1, u2_squared = u2 * u2;
  const double m = product * product;
  const double inverse_m = 1.0 / m;
  const double twice_y = ((2.0 * slope_1 * equibiaxial) * u2) * u2_squared +
                         ((2.0 * slope_2 * deviatoric) * u1) * u1_squared;
  const double residual_0_numerator = equibiaxial * u2_squared + deviatoric * u1_squared - m;
  const double residual_0 = residual_0_numerator * inverse_m;
  const double lower_0 = std::min(excess * constants.inverse_max_slope, start);
  const double upper_0 = std::max(excess * constants.inverse_min_slope, start);
  const double lower = residual_0 > 0.0 ? start : lower_0;
  const double upper = residual_0 > 0.0 ? upper_0 : start;
  const double series_numerator =
      (m * m + (0.75 * residual_0_numerator) * m) - 0.125 * residual_0_numerator * residual_0_numerator;
  const double correction = ((residual_0_numerator * product) * series_numerator) / (twice_y * (m * m));
  const double increment = start + correction;
  const double sigma_s = yield_stress + constants.plastic_modulus * increment;
  const double inverse_u1_start = (u2 * product) * inverse_m;
  const double inverse_u2_start = (u1 * product) * inverse_m;
  const double x1 = (slope_1 * inverse_u1_start) * correction;
  const double x2 = (slope_2 * inverse_u2_start) * correction;
  const double factor_1 = (1.0 - x1) * (1.0 + x1 * x1);
  const double factor_2 = (1.0 - x2) * (1.0 + x2 * x2);
  const double inverse_u1 = inverse_u1_start * factor_1, inverse_u2 = inverse_u2_start * factor_2;
  const double residual_1 = (equibiaxial * inverse_u1 * inverse_u1 + deviatoric * inverse_u2 * inverse_u2) - 1.0;
  const double half_sigma_s = 0.5 * sigma_s;
  const double returned_half_sum = ((sum * half_sigma_s) * inverse_u1_start) * factor_1;
  const double deviatoric_scale = sigma_s * inverse_u2_start;
  const double returned_half_diff = ((0.5 * diff) * deviatoric_scale) * factor_2;
  // The fast path's tests, as closed_form_default applies them (NaN fails
  // each); `&`, not `&&`: all are evaluated, so the lane loop has no branch.
  const bool fast = (excess > 0.0) & (std::abs(residual_0) > relative_tolerance) &
                    (std::abs(residual_0) <= series_limit) &
                    (upper - lower > 4.0 * std::numeric_limits<double>::epsilon() * upper) & (increment > lower) &
                    (increment < upper) & (std::abs(x1) <= reciprocal_series_limit) &
                    (std::abs(x2) <= reciprocal_series_limit) & (std::abs(residual_1) <= relative_tolerance);
  return LaneReturn{returned_half_sum + returned_half_diff, returned_half_sum - returned_half_diff,
                    (shear * deviatoric_scale) * factor_2, increment, fast};
}

}  // namespace detail

inline Solution closed_form(const ClosedFormConstants& constants, const StressVoigt& trial,
                            double yield_stress, const ReturnMapOptions& options = {}) {
  detail::require_valid(options);
  if (options.initial_guess == InitialGuess::appendix_b && options.fixed_iterations <= 0 &&
      options.newton_function == NewtonFunction::normalized)
    return detail::closed_form_default(constants, trial, yield_stress);
  return detail::closed_form_general(constants, trial, yield_stress, options);
}

inline Solution closed_form(const PlaneStressElasticity& elasticity, const StressVoigt& trial,
                            double yield_stress, double plastic_modulus,
                            const ReturnMapOptions& options = {}) {
  return closed_form(ClosedFormConstants(elasticity, plastic_modulus), trial, yield_stress,
                     options);
}

inline Solution generic(const PlaneStressElasticity& elasticity, const StressVoigt& trial,
                        double yield_stress, double plastic_modulus,
                        const ReturnMapOptions& options = {}) {
  detail::require_valid(options);
  detail::GenericKernel kernel(elasticity, trial, yield_stress, plastic_modulus,
                               options.newton_function);
  const double excess = kernel.trial_equivalent() - yield_stress;
  if (!(excess > 0.0)) {
    if (!std::isfinite(excess)) detail::throw_non_finite_trial(trial, yield_stress);
    return Solution{trial, 0.0, 0};
  }
  double increment = 0.0;
  switch (options.initial_guess) {
    case InitialGuess::appendix_b:
      increment = excess / (kernel.sigma_hat() + plastic_modulus);  // eq. (B.8)
      break;
    case InitialGuess::zero:
      increment = 0.0;
      break;
    case InitialGuess::radial_return:
      increment = excess / (3.0 * elasticity.shear_modulus() + plastic_modulus);
      break;
  }
  kernel.evaluate(increment);
  int iterations = options.fixed_iterations;
  if (options.fixed_iterations > 0) {
    detail::solve_fixed(kernel, increment, options.fixed_iterations);
  } else {
    // No eigen-structure used here: g(0) > 0 is known, the upper end is found by expansion.
    iterations =
        detail::solve_safeguarded(kernel, increment, 0.0, std::numeric_limits<double>::infinity());
  }
  return Solution{kernel.stress(), increment, iterations};
}

// Dispatch on options.form; the laws pass their precomputed constants.
inline Solution solve(const PlaneStressElasticity& elasticity, const ClosedFormConstants& constants,
                      const StressVoigt& trial, double yield_stress,
                      const ReturnMapOptions& options) {
  if (options.form == ReturnMapForm::generic)
    return generic(elasticity, trial, yield_stress, constants.plastic_modulus, options);
  return closed_form(constants, trial, yield_stress, options);
}

inline Solution solve(const PlaneStressElasticity& elasticity, const StressVoigt& trial,
                      double yield_stress, double plastic_modulus,
                      const ReturnMapOptions& options) {
  return solve(elasticity, ClosedFormConstants(elasticity, plastic_modulus), trial, yield_stress,
               options);
}

}  // namespace sphshell::material::return_map
