#pragma once
// Minimal stand-ins for sphshell::material::{Elastic, J2Plasticity, LemaitreDamage}
// (written in parallel elsewhere) with the same member names, so the thickness rules
// can be built and tested before the merge. Deliberately small: plane-stress J2 with
// a scalar Newton return in the eigenbasis Γ and Ξ share (design §2.4), and a
// staggered Lemaitre damage on top of it. Not for production use.

#include <sphshell/core/error.hpp>
#include <sphshell/core/types.hpp>

#include <Eigen/Core>
#include <Eigen/LU>

#include <cmath>

namespace sphshell::test_support {

namespace stand_in_detail {

inline Eigen::Matrix3d plane_stress_elasticity(double E, double nu) {
  Eigen::Matrix3d gamma;
  gamma << 1.0, nu, 0.0, nu, 1.0, 0.0, 0.0, 0.0, 0.5 * (1.0 - nu);
  return E / (1.0 - nu * nu) * gamma;
}

// Ξ of σ̄² = σᵀΞσ (design §2.4).
inline Eigen::Matrix3d mises_matrix() {
  Eigen::Matrix3d xi;
  xi << 1.0, -0.5, 0.0, -0.5, 1.0, 0.0, 0.0, 0.0, 3.0;
  return xi;
}

inline double mises(const Eigen::Vector3d& stress) {
  return std::sqrt(stress.dot(mises_matrix() * stress));
}

inline void validate_elastic(double E, double nu) {
  sphshell::detail::require_positive("E", E);
  sphshell::detail::require_open_interval("nu", nu, -1.0, 0.5);
}

struct ReturnResult {
  Eigen::Vector3d stress;
  double d_eps_p;
  int iterations;
};

// Radial-return-like closest point for f = σᵀΞσ − σs² with σs = σs,n + Ep Δε̄p and the
// consistent flow Δεp = (Δε̄p/σs) Ξσ: σ = L⁻¹σ*, L = I + (Δε̄p/σs) ΓΞ, diagonal in the
// basis (1,1,0)/√2, (1,−1,0)/√2, (0,0,1) with ΓΞ eigenvalues E/(2(1−ν)), 3G, 3G.
inline ReturnResult plane_stress_return(const Eigen::Vector3d& trial, double sigma_y_n,
                                        double Ep, double E, double nu) {
  const double p_trial = (trial.x() + trial.y()) / std::sqrt(2.0);
  const double q_trial = (trial.x() - trial.y()) / std::sqrt(2.0);
  const double s_trial = trial.z();
  const double lambda_p = E / (2.0 * (1.0 - nu));
  const double lambda_q = 3.0 * E / (2.0 * (1.0 + nu));
  auto residual = [&](double d_eps_p, double& derivative) {
    const double sigma_y = sigma_y_n + Ep * d_eps_p;
    const double c = d_eps_p / sigma_y;
    const double dc = sigma_y_n / (sigma_y * sigma_y);
    const double fp = 1.0 / (1.0 + c * lambda_p);
    const double fq = 1.0 / (1.0 + c * lambda_q);
    const double a = 0.5 * p_trial * p_trial;
    const double b = 1.5 * q_trial * q_trial + 3.0 * s_trial * s_trial;
    derivative = (-2.0 * a * lambda_p * fp * fp * fp - 2.0 * b * lambda_q * fq * fq * fq) * dc -
                 2.0 * sigma_y * Ep;
    return a * fp * fp + b * fq * fq - sigma_y * sigma_y;
  };
  double lower = 0.0;
  double upper = -1.0;
  double d_eps_p = 0.0;
  int iterations = 0;
  for (; iterations < 200; ++iterations) {
    double derivative = 0.0;
    const double g = residual(d_eps_p, derivative);
    const double sigma_y = sigma_y_n + Ep * d_eps_p;
    if (std::abs(g) <= 1e-14 * sigma_y * sigma_y) break;
    if (g > 0.0) lower = d_eps_p; else upper = d_eps_p;
    double next = d_eps_p - g / derivative;
    const bool outside = !(next > lower) || (upper >= 0.0 && !(next < upper));
    if (outside) next = upper >= 0.0 ? 0.5 * (lower + upper) : 2.0 * lower + 1e-12;
    if (upper >= 0.0 && upper - lower <= 1e-16 * upper) break;
    d_eps_p = next;
  }
  const double sigma_y = sigma_y_n + Ep * d_eps_p;
  const double c = d_eps_p / sigma_y;
  const double p = p_trial / (1.0 + c * lambda_p);
  const double q = q_trial / (1.0 + c * lambda_q);
  const double s = s_trial / (1.0 + c * lambda_q);
  return {Eigen::Vector3d((p + q) / std::sqrt(2.0), (p - q) / std::sqrt(2.0), s), d_eps_p,
          iterations};
}

}  // namespace stand_in_detail

class Elastic {
 public:
  struct Parameters {
    double E, nu;
  };
  struct State {
    Eigen::Vector3d stress;
  };
  struct UpdateResult {
    bool plastic;
    int iterations;
  };
  static constexpr bool has_plasticity = false;
  static constexpr bool has_damage = false;
  static constexpr const char* name = "Elastic (stand-in)";

  explicit Elastic(const Parameters& parameters) : parameters_(parameters) {
    stand_in_detail::validate_elastic(parameters.E, parameters.nu);
    gamma_ = stand_in_detail::plane_stress_elasticity(parameters.E, parameters.nu);
    compliance_ = gamma_.inverse();
  }
  State initial_state() const { return {Eigen::Vector3d::Zero()}; }
  UpdateResult update(State& state, const StrainVoigt& d_eps) const {
    state.stress += gamma_ * d_eps;
    return {false, 0};
  }
  const Parameters& parameters() const { return parameters_; }
  double youngs_modulus() const { return parameters_.E; }
  double poisson_ratio() const { return parameters_.nu; }
  double equivalent_stress(const State& state) const { return stand_in_detail::mises(state.stress); }
  double equivalent_plastic_strain(const State&) const { return 0.0; }
  double damage(const State&) const { return 0.0; }
  bool failed(const State&) const { return false; }
  double elastic_energy_density(const State& state) const {
    return 0.5 * state.stress.dot(compliance_ * state.stress);
  }
  Eigen::Matrix3d elasticity_matrix() const { return gamma_; }

 private:
  Parameters parameters_;
  Eigen::Matrix3d gamma_;
  Eigen::Matrix3d compliance_;
};

class J2Plasticity {
 public:
  struct Parameters {
    double E, nu, sigma_y0, Ep;
  };
  struct State {
    Eigen::Vector3d stress;
    double eps_p, sigma_y;
  };
  struct UpdateResult {
    bool plastic;
    int iterations;
  };
  static constexpr bool has_plasticity = true;
  static constexpr bool has_damage = false;
  static constexpr const char* name = "J2Plasticity (stand-in)";

  explicit J2Plasticity(const Parameters& parameters) : parameters_(parameters) {
    stand_in_detail::validate_elastic(parameters.E, parameters.nu);
    sphshell::detail::require_positive("sigma_y0", parameters.sigma_y0);
    sphshell::detail::require_nonnegative("Ep", parameters.Ep);
    gamma_ = stand_in_detail::plane_stress_elasticity(parameters.E, parameters.nu);
    compliance_ = gamma_.inverse();
  }
  State initial_state() const { return {Eigen::Vector3d::Zero(), 0.0, parameters_.sigma_y0}; }
  UpdateResult update(State& state, const StrainVoigt& d_eps) const {
    const Eigen::Vector3d trial = state.stress + gamma_ * d_eps;
    if (stand_in_detail::mises(trial) <= state.sigma_y) {
      state.stress = trial;
      return {false, 0};
    }
    const auto result = stand_in_detail::plane_stress_return(trial, state.sigma_y, parameters_.Ep,
                                                             parameters_.E, parameters_.nu);
    state.stress = result.stress;
    state.eps_p += result.d_eps_p;
    state.sigma_y += parameters_.Ep * result.d_eps_p;
    return {true, result.iterations};
  }
  const Parameters& parameters() const { return parameters_; }
  double youngs_modulus() const { return parameters_.E; }
  double poisson_ratio() const { return parameters_.nu; }
  double equivalent_stress(const State& state) const { return stand_in_detail::mises(state.stress); }
  double equivalent_plastic_strain(const State& state) const { return state.eps_p; }
  double damage(const State&) const { return 0.0; }
  bool failed(const State&) const { return false; }
  double elastic_energy_density(const State& state) const {
    return 0.5 * state.stress.dot(compliance_ * state.stress);
  }
  Eigen::Matrix3d elasticity_matrix() const { return gamma_; }

 private:
  Parameters parameters_;
  Eigen::Matrix3d gamma_;
  Eigen::Matrix3d compliance_;
};

// Staggered: J2 return on the effective stress σ/(1 − D), then the Lemaitre damage
// increment (design §2.5) from the effective triaxiality.
class LemaitreDamage {
 public:
  struct Parameters {
    double E, nu, sigma_y0, Ep, eps_s, eps_c, Dc;
  };
  struct State {
    Eigen::Vector3d stress;
    double eps_p, sigma_y, D;
    bool failed;
  };
  struct UpdateResult {
    bool plastic;
    int iterations;
  };
  static constexpr bool has_plasticity = true;
  static constexpr bool has_damage = true;
  static constexpr const char* name = "LemaitreDamage (stand-in)";

  explicit LemaitreDamage(const Parameters& parameters) : parameters_(parameters) {
    stand_in_detail::validate_elastic(parameters.E, parameters.nu);
    sphshell::detail::require_positive("sigma_y0", parameters.sigma_y0);
    sphshell::detail::require_nonnegative("Ep", parameters.Ep);
    sphshell::detail::require_nonnegative("eps_s", parameters.eps_s);
    if (!(parameters.eps_c > parameters.eps_s))
      sphshell::detail::invalid_parameter("eps_c", parameters.eps_c, "must exceed eps_s");
    sphshell::detail::require_half_open_interval("Dc", parameters.Dc, 0.0, 1.0);
    gamma_ = stand_in_detail::plane_stress_elasticity(parameters.E, parameters.nu);
    compliance_ = gamma_.inverse();
  }
  State initial_state() const {
    return {Eigen::Vector3d::Zero(), 0.0, parameters_.sigma_y0, 0.0, false};
  }
  UpdateResult update(State& state, const StrainVoigt& d_eps) const {
    if (state.failed) return {false, 0};
    const Eigen::Vector3d trial = state.stress / (1.0 - state.D) + gamma_ * d_eps;
    if (stand_in_detail::mises(trial) <= state.sigma_y) {
      state.stress = (1.0 - state.D) * trial;
      return {false, 0};
    }
    const auto result = stand_in_detail::plane_stress_return(trial, state.sigma_y, parameters_.Ep,
                                                             parameters_.E, parameters_.nu);
    state.eps_p += result.d_eps_p;
    state.sigma_y += parameters_.Ep * result.d_eps_p;
    const double triaxiality =
        (result.stress.x() + result.stress.y()) / 3.0 / stand_in_detail::mises(result.stress);
    const double nu = parameters_.nu;
    const double factor =
        2.0 / 3.0 * (1.0 + nu) + 3.0 * (1.0 - 2.0 * nu) * triaxiality * triaxiality;
    if (factor * state.eps_p >= parameters_.eps_s)
      state.D += parameters_.Dc / (parameters_.eps_c - parameters_.eps_s) * factor * result.d_eps_p;
    if (state.D >= parameters_.Dc) {
      state.D = parameters_.Dc;
      state.failed = true;
      state.stress.setZero();
    } else {
      state.stress = (1.0 - state.D) * result.stress;
    }
    return {true, result.iterations};
  }
  const Parameters& parameters() const { return parameters_; }
  double youngs_modulus() const { return parameters_.E; }
  double poisson_ratio() const { return parameters_.nu; }
  double equivalent_stress(const State& state) const { return stand_in_detail::mises(state.stress); }
  double equivalent_plastic_strain(const State& state) const { return state.eps_p; }
  double damage(const State& state) const { return state.D; }
  bool failed(const State& state) const { return state.failed; }
  double elastic_energy_density(const State& state) const {
    if (state.failed) return 0.0;
    return 0.5 * state.stress.dot(compliance_ * state.stress) / (1.0 - state.D);
  }
  Eigen::Matrix3d elasticity_matrix() const { return gamma_; }

 private:
  Parameters parameters_;
  Eigen::Matrix3d gamma_;
  Eigen::Matrix3d compliance_;
};

}  // namespace sphshell::test_support
