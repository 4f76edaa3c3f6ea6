#pragma once
// Linear isotropic plane-stress elasticity: the Elastic law, and the
// PlaneStressElasticity helper every law shares (Γ of eq. 2.24, its inverse,
// and the von Mises matrix Ξ of eq. 2.20).

#include <sphshell/core/error.hpp>
#include <sphshell/core/types.hpp>
#include <sphshell/material/lanes.hpp>

#include <array>
#include <cmath>
#include <cstddef>
#include <sstream>

namespace sphshell::material {

enum class ReturnMapForm { closed_form, generic };

// How the Newton–Raphson return map picks its first Δε̄p.
enum class InitialGuess {
  appendix_b,  // (σ̄* − σs,n)/(σ̂ + Ep), eq. (2.39)/(B.8) with the consistent K = ΓΞ/σ̄*
  zero,        // Δε̄p⁰ = 0, the naive start
  radial_return  // (σ̄* − σs,n)/(3G + Ep), exact for a purely deviatoric trial stress
};

// The function whose root Newton seeks (return_map.hpp explains the choice).
enum class NewtonFunction {
  normalized,  // φ = 1 − σs/σ̄, the unsquared yield function (2.19) over σ̄
  squared      // g = σᵀΞσ − σs², eq. (2.36), with Appendix A's derivative
};

// Aggregate order: {form, initial_guess, fixed_iterations, newton_function}.
struct ReturnMapOptions {
  ReturnMapForm form = ReturnMapForm::closed_form;
  InitialGuess initial_guess = InitialGuess::appendix_b;
  // 0: iterate to convergence (safeguarded). > 0: exactly that many plain
  // Newton steps, no convergence test and no safeguard — the baseline of codes
  // that run a fixed number of iterations.
  int fixed_iterations = 0;
  NewtonFunction newton_function = NewtonFunction::normalized;
};

namespace detail {

// Kept out of line so the finiteness check costs the hot path one branch.
[[noreturn]] [[gnu::noinline, gnu::cold]] inline void throw_non_finite_strain(
    const StrainVoigt& d_eps) {
  std::ostringstream message;
  message.precision(17);
  message << "sphshell: non-finite strain increment d_eps = (" << d_eps.x() << ", " << d_eps.y()
          << ", " << d_eps.z() << ")";
  throw Error(message.str());
}

inline void require_finite_strain(const StrainVoigt& d_eps) {
  // x − x is NaN for ±inf and NaN, 0 otherwise: one test for all three components.
  const double probe = (d_eps.x() - d_eps.x()) + (d_eps.y() - d_eps.y()) + (d_eps.z() - d_eps.z());
  if (probe != 0.0) throw_non_finite_strain(d_eps);
}

}  // namespace detail

// σ̄² = σᵀΞσ with Ξ = [[1, −½, 0], [−½, 1, 0], [0, 0, 3]] (eq. 2.20).
inline double von_mises_squared(const StressVoigt& stress) {
  return stress.x() * stress.x() + stress.y() * stress.y() - stress.x() * stress.y() +
         3.0 * stress.z() * stress.z();
}

inline Matrix3 von_mises_matrix() {
  Matrix3 xi;
  xi << 1.0, -0.5, 0.0, -0.5, 1.0, 0.0, 0.0, 0.0, 3.0;
  return xi;
}

// Plane-stress Γ (eq. 2.24) with the constants the return maps need.
class PlaneStressElasticity {
 public:
  PlaneStressElasticity(double youngs_modulus, double poisson_ratio)
      : E_(youngs_modulus),
        nu_(poisson_ratio),
        shear_modulus_(youngs_modulus / (2.0 * (1.0 + poisson_ratio))),
        biaxial_modulus_(youngs_modulus / (1.0 - poisson_ratio * poisson_ratio)),
        equibiaxial_stiffness_(0.5 * youngs_modulus / (1.0 - poisson_ratio)) {}

  double youngs_modulus() const { return E_; }
  double poisson_ratio() const { return nu_; }
  double shear_modulus() const { return shear_modulus_; }
  // E/(1 − ν²), the factor of Γ's normal block.
  double biaxial_modulus() const { return biaxial_modulus_; }

  // Eigenvalues of ΓΞ along (1,1,0)/√2 and along (1,−1,0)/√2, (0,0,1): the
  // stiffness the return map sees against the volumetric-like and deviatoric
  // parts of a plane stress.
  double equibiaxial_stiffness() const { return equibiaxial_stiffness_; }
  double deviatoric_stiffness() const { return 3.0 * shear_modulus_; }

  // Γ Δε, Δε with engineering shear (eq. 2.23).
  StressVoigt stress_increment(const StrainVoigt& d_eps) const {
    return StressVoigt(biaxial_modulus_ * (d_eps.x() + nu_ * d_eps.y()),
                       biaxial_modulus_ * (nu_ * d_eps.x() + d_eps.y()),
                       shear_modulus_ * d_eps.z());
  }

  Matrix3 matrix() const {
    Matrix3 gamma;
    gamma << 1.0, nu_, 0.0, nu_, 1.0, 0.0, 0.0, 0.0, 0.5 * (1.0 - nu_);
    return biaxial_modulus_ * gamma;
  }

  // ½ σᵀΓ⁻¹σ, Γ⁻¹ = [[1, −ν, 0], [−ν, 1, 0], [0, 0, 2(1+ν)]]/E.
  double complementary_energy_density(const StressVoigt& stress) const {
    return 0.5 *
           (stress.x() * stress.x() + stress.y() * stress.y() -
            2.0 * nu_ * stress.x() * stress.y() + 2.0 * (1.0 + nu_) * stress.z() * stress.z()) /
           E_;
  }

 private:
  double E_;
  double nu_;
  double shear_modulus_;
  double biaxial_modulus_;
  double equibiaxial_stiffness_;
};

namespace detail {
inline void validate_elastic_constants(double E, double nu) {
  sphshell::detail::require_positive("E", E);
  sphshell::detail::require_open_interval("nu", nu, -1.0, 0.5);
}
}  // namespace detail

struct Elastic {
  struct Parameters {
    double E;
    double nu;
  };
  struct State {
    StressVoigt stress;
    // The fields a checkpoint stores (material.hpp).
    template <class S, class F>
    static void for_each_field(S& self, F&& field) {
      field(self.stress);
    }
  };
  struct UpdateResult {
    bool plastic;
    int iterations;
  };

  static constexpr bool has_plasticity = false;
  static constexpr bool has_damage = false;
  static constexpr const char* name = "elastic";

  explicit Elastic(const Parameters& parameters)
      : parameters_((detail::validate_elastic_constants(parameters.E, parameters.nu), parameters)),
        elasticity_(parameters.E, parameters.nu) {}

  State initial_state() const { return State{StressVoigt::Zero()}; }

  UpdateResult update(State& state, const StrainVoigt& d_eps) const {
    detail::require_finite_strain(d_eps);
    state.stress += elasticity_.stress_increment(d_eps);
    return {false, 0};
  }
  // Same signature as the plastic laws so generic code can pass options to any law.
  UpdateResult update(State& state, const StrainVoigt& d_eps, const ReturnMapOptions&) const {
    return update(state, d_eps);
  }

  // N states in structure-of-arrays form, for update_lanes (lanes.hpp).
  template <int N>
  struct Lanes {
    VoigtLanes<N> stress;
    State state(int k) const { return State{stress.at(k)}; }
    void set_state(int k, const State& s) { stress.set(k, s.stress); }
  };
  // update() of every lane at once; never yields, returns 0.
  template <int N>
  int update_lanes(Lanes<N>& lanes, const VoigtLanes<N>& d_eps) const {
    alignas(64) std::array<double, std::size_t(N)> non_finite;  // NaN where an increment is not finite
    for (std::size_t k = 0; k < std::size_t(N); ++k)
      non_finite[k] = (d_eps.xx[k] - d_eps.xx[k]) + (d_eps.yy[k] - d_eps.yy[k]) + (d_eps.xy[k] - d_eps.xy[k]);
    if (detail::any_lane(non_finite))
      for (int k = 0; k < N; ++k) detail::require_finite_strain(d_eps.at(k));
    const double biaxial = elasticity_.biaxial_modulus(), nu = elasticity_.poisson_ratio(),
                 shear_modulus = elasticity_.shear_modulus();
    for (std::size_t k = 0; k < std::size_t(N); ++k) {  // eq. (2.23), as in update()
      lanes.stress.xx[k] += biaxial * (d_eps.xx[k] + nu * d_eps.yy[k]);
      lanes.stress.yy[k] += biaxial * (nu * d_eps.xx[k] + d_eps.yy[k]);
      lanes.stress.xy[k] += shear_modulus * d_eps.xy[k];
    }
    return 0;
  }

  const Parameters& parameters() const { return parameters_; }
  double youngs_modulus() const { return parameters_.E; }
  double poisson_ratio() const { return parameters_.nu; }
  double shear_modulus() const { return elasticity_.shear_modulus(); }
  const PlaneStressElasticity& elasticity() const { return elasticity_; }
  Matrix3 elasticity_matrix() const { return elasticity_.matrix(); }

  double equivalent_stress(const State& state) const {
    return std::sqrt(von_mises_squared(state.stress));
  }
  double equivalent_plastic_strain(const State&) const { return 0.0; }
  double damage(const State&) const { return 0.0; }
  bool failed(const State&) const { return false; }
  double elastic_energy_density(const State& state) const {
    return elasticity_.complementary_energy_density(state.stress);
  }

 private:
  Parameters parameters_;
  PlaneStressElasticity elasticity_;
};

}  // namespace sphshell::material
