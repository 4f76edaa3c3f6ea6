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
// wrong strain (design.md, scaling note). Appendix A's derivative and
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
  StressVoigt stress;  // returned stress, on the yield surface
  double plastic_strain_increment;  // Δε̄p
  int iterations;  // Newton (or safeguard) corrections applied after the initial value
};

struct Evaluation {
  double residual;        // the Newton function (φ or g) at Δε̄p
  double derivative;      // its derivative
  double yield_residual;  // g(Δε̄p) = σᵀΞσ − σs², tested for convergence
  double scale;           // σs(Δε̄p)², the tolerance's reference
};

namespace detail {

[[noreturn]] [[gnu::noinline, gnu::cold]] inline void throw_not_converged(double increment,
                                                                          double residual,
                                                                          double scale) {
  std::ostringstream message;
  message.precision(17);
  message << "sphshell: plane-stress return map did not converge in " << max_iterations
          << " iterations (delta eps_p = " << increment << ", |g|/sigma_s^2 = "
          << std::abs(residual) / scale << ")";
  throw Error(message.str());
}

// Safeguarded Newton–Raphson on a decreasing g with g(lower) > 0 > g(upper)
// (upper may be +inf: then the bracket is expanded by doubling). A Newton step
// that leaves the bracket, or a step after one that failed to halve |g|, is
// replaced by bisection (or doubling), so convergence never depends on the
// quality of the initial value. Returns the number of corrections applied.
template <class Residual>
inline int solve_safeguarded(const Residual& residual, double& increment, double lower,
                             double upper) {
  Evaluation value = residual(increment);
  bool distrust_newton = false;
  int iterations = 0;
  while (!(std::abs(value.yield_residual) <= relative_tolerance * value.scale)) {
    if (value.residual > 0.0)
      lower = increment;
    else
      upper = increment;
    // Bracket collapsed to round-off: no representable Δε̄p does better.
    if (upper < std::numeric_limits<double>::infinity() &&
        upper - lower <= 4.0 * std::numeric_limits<double>::epsilon() * upper)
      break;
    if (iterations == max_iterations)
      throw_not_converged(increment, value.yield_residual, value.scale);
    const double newton = increment - value.residual / value.derivative;
    if (!distrust_newton && newton > lower && newton < upper) {
      increment = newton;
    } else if (upper < std::numeric_limits<double>::infinity()) {
      increment = 0.5 * (lower + upper);
    } else {
      increment = lower > 0.0 ? 2.0 * lower : 2.0 * increment + 1e-12;
    }
    const double previous = std::abs(value.residual);
    value = residual(increment);
    distrust_newton = std::abs(value.residual) > 0.5 * previous;
    ++iterations;
  }
  return iterations;
}

// Plain Newton, a fixed number of steps, no test: the "fixed iterations" baseline.
template <class Residual>
inline void solve_fixed(const Residual& residual, double& increment, int steps) {
  for (int step = 0; step < steps; ++step) {
    const Evaluation value = residual(increment);
    increment -= value.residual / value.derivative;
  }
}

}  // namespace detail

// Closed form in the shared eigenbasis of Γ and Ξ.
inline Solution closed_form(const PlaneStressElasticity& elasticity, const StressVoigt& trial,
                            double yield_stress, double plastic_modulus,
                            const ReturnMapOptions& options = {}) {
  const double sum = trial.x() + trial.y();   // P*
  const double diff = trial.x() - trial.y();  // Q*
  const double shear = trial.z();             // s*
  // σ̄*² = A + B, A along (1,1,0), B along (1,−1,0) and (0,0,1).
  const double equibiaxial_part = 0.25 * sum * sum;
  const double deviatoric_part = 0.75 * diff * diff + 3.0 * shear * shear;
  const double kappa_1 = elasticity.equibiaxial_stiffness();
  const double kappa_2 = elasticity.deviatoric_stiffness();
  const double slope_1 = kappa_1 + plastic_modulus;  // duᵢ/dΔε̄p
  const double slope_2 = kappa_2 + plastic_modulus;

  const auto residual = [&](double increment) {
    const double sigma_s = yield_stress + plastic_modulus * increment;
    const double inverse_u1 = 1.0 / (yield_stress + slope_1 * increment);
    const double inverse_u2 = 1.0 / (yield_stress + slope_2 * increment);
    const double term_1 = equibiaxial_part * inverse_u1 * inverse_u1;
    const double term_2 = deviatoric_part * inverse_u2 * inverse_u2;
    // σᵀΞσ = σs²·S², S = σ̄/σs, S² = A/u₁² + B/u₂².
    const double ratio_squared = term_1 + term_2;
    const double d_ratio_squared =
        -2.0 * (term_1 * slope_1 * inverse_u1 + term_2 * slope_2 * inverse_u2);
    const double scale = sigma_s * sigma_s;
    const double yield_residual = scale * (ratio_squared - 1.0);
    if (options.newton_function == NewtonFunction::squared) {
      // Appendix A in this basis: dg/dΔε̄p = 2σsEp(S² − 1) + σs² dS²/dΔε̄p.
      return Evaluation{yield_residual,
                        2.0 * sigma_s * plastic_modulus * (ratio_squared - 1.0) +
                            scale * d_ratio_squared,
                        yield_residual, scale};
    }
    // φ = 1 − 1/S, dφ/dΔε̄p = ½ S⁻³ dS²/dΔε̄p.
    const double inverse_ratio = 1.0 / std::sqrt(ratio_squared);
    return Evaluation{1.0 - inverse_ratio, 0.5 * inverse_ratio / ratio_squared * d_ratio_squared,
                      yield_residual, scale};
  };

  const double trial_equivalent = std::sqrt(equibiaxial_part + deviatoric_part);
  const double excess = trial_equivalent - yield_stress;
  double increment = 0.0;
  switch (options.initial_guess) {
    case InitialGuess::appendix_b: {
      // σ̂ = σ*ᵀKᵀΞσ*/σ̄* with K = ΓΞ/σ̄* is the stiffness-weighted mean of κ₁, κ₂ (eq. B.5).
      const double sigma_hat = (kappa_1 * equibiaxial_part + kappa_2 * deviatoric_part) /
                               (equibiaxial_part + deviatoric_part);
      increment = excess / (sigma_hat + plastic_modulus);  // eq. (B.8)
      break;
    }
    case InitialGuess::zero:
      increment = 0.0;
      break;
    case InitialGuess::radial_return:
      increment = excess / slope_2;
      break;
  }

  int iterations = options.fixed_iterations;
  if (options.fixed_iterations > 0) {
    detail::solve_fixed(residual, increment, options.fixed_iterations);
  } else {
    // Since min uᵢ ≤ σs·σ̄*/σ̄ ≤ max uᵢ, the root lies in
    // [excess/max slope, excess/min slope]; widened to contain the start.
    const double lower = std::min(excess / std::max(slope_1, slope_2), increment);
    const double upper = std::max(excess / std::min(slope_1, slope_2), increment);
    iterations = detail::solve_safeguarded(residual, increment, lower, upper);
  }

  const double sigma_s = yield_stress + plastic_modulus * increment;
  const double returned_sum = sum * sigma_s / (yield_stress + slope_1 * increment);
  const double deviatoric_factor = sigma_s / (yield_stress + slope_2 * increment);
  const double returned_diff = diff * deviatoric_factor;
  return Solution{StressVoigt(0.5 * (returned_sum + returned_diff),
                              0.5 * (returned_sum - returned_diff), shear * deviatoric_factor),
                  increment, iterations};
}

// The literal matrix form: L = I + cΓΞ, σ = L⁻¹σ*, and Appendix A's derivative
// dσ/dΔε̄p = −L⁻¹ΓΞσ · dc/dΔε̄p with dc/dΔε̄p = σs,n/σs².
inline Solution generic(const PlaneStressElasticity& elasticity, const StressVoigt& trial,
                        double yield_stress, double plastic_modulus,
                        const ReturnMapOptions& options = {}) {
  const Matrix3 xi = von_mises_matrix();
  const Matrix3 gamma_xi = elasticity.matrix() * xi;

  const auto returned_stress = [&](double increment, Matrix3& inverse_l) {
    const double sigma_s = yield_stress + plastic_modulus * increment;
    const Matrix3 l = Matrix3::Identity() + (increment / sigma_s) * gamma_xi;
    inverse_l = l.inverse();
    return StressVoigt(inverse_l * trial);
  };
  const auto residual = [&](double increment) {
    Matrix3 inverse_l;
    const StressVoigt stress = returned_stress(increment, inverse_l);
    const double sigma_s = yield_stress + plastic_modulus * increment;
    const double dc = yield_stress / (sigma_s * sigma_s);
    const StressVoigt d_stress = -dc * (inverse_l * (gamma_xi * stress));
    const StressVoigt xi_stress = xi * stress;
    const double equivalent_squared = stress.dot(xi_stress);
    const double yield_residual = equivalent_squared - sigma_s * sigma_s;
    const double d_equivalent_squared = 2.0 * xi_stress.dot(d_stress);
    if (options.newton_function == NewtonFunction::squared) {
      return Evaluation{yield_residual, d_equivalent_squared - 2.0 * sigma_s * plastic_modulus,
                        yield_residual, sigma_s * sigma_s};
    }
    // φ = 1 − σs/σ̄: dφ = −Ep/σ̄ + σs dσ̄/σ̄², dσ̄ = d(σ̄²)/(2σ̄).
    const double equivalent = std::sqrt(equivalent_squared);
    return Evaluation{1.0 - sigma_s / equivalent,
                      -plastic_modulus / equivalent +
                          sigma_s * d_equivalent_squared / (2.0 * equivalent_squared * equivalent),
                      yield_residual, sigma_s * sigma_s};
  };

  const double trial_equivalent = std::sqrt(trial.dot(xi * trial));
  const double excess = trial_equivalent - yield_stress;
  double increment = 0.0;
  switch (options.initial_guess) {
    case InitialGuess::appendix_b: {
      const Matrix3 k = gamma_xi / trial_equivalent;                               // eq. (B.3)
      const double sigma_hat = trial.dot(k.transpose() * (xi * trial)) / trial_equivalent;  // (B.5)
      increment = excess / (sigma_hat + plastic_modulus);                         // (B.8)
      break;
    }
    case InitialGuess::zero:
      increment = 0.0;
      break;
    case InitialGuess::radial_return:
      increment = excess / (3.0 * elasticity.shear_modulus() + plastic_modulus);
      break;
  }

  int iterations = options.fixed_iterations;
  if (options.fixed_iterations > 0) {
    detail::solve_fixed(residual, increment, options.fixed_iterations);
  } else {
    // No eigen-structure used here: g(0) > 0 is known, the upper end is found by expansion.
    iterations = detail::solve_safeguarded(residual, increment, 0.0,
                                           std::numeric_limits<double>::infinity());
  }
  Matrix3 inverse_l;
  const StressVoigt stress = returned_stress(increment, inverse_l);
  return Solution{stress, increment, iterations};
}

inline Solution solve(const PlaneStressElasticity& elasticity, const StressVoigt& trial,
                      double yield_stress, double plastic_modulus,
                      const ReturnMapOptions& options) {
  if (options.form == ReturnMapForm::generic)
    return generic(elasticity, trial, yield_stress, plastic_modulus, options);
  return closed_form(elasticity, trial, yield_stress, plastic_modulus, options);
}

}  // namespace sphshell::material::return_map
