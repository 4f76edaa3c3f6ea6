#pragma once
// Plane-stress von Mises plasticity with linear isotropic hardening (section 2.2
// of the paper): elastic predictor, yield check, Newton–Raphson return map.

#include <sphshell/core/error.hpp>
#include <sphshell/core/types.hpp>
#include <sphshell/material/elastic.hpp>
#include <sphshell/material/material.hpp>
#include <sphshell/material/return_map.hpp>

#include <cmath>

namespace sphshell::material {

namespace detail {
inline void validate_plastic_constants(double E, double nu, double sigma_y0, double Ep) {
  validate_elastic_constants(E, nu);
  sphshell::detail::require_positive("sigma_y0", sigma_y0);
  sphshell::detail::require_nonnegative("Ep", Ep);
}
}  // namespace detail

struct J2Plasticity {
  struct Parameters {
    double E;
    double nu;
    double sigma_y0;  // initial yield stress σs0
    double Ep;        // plastic modulus E·Et/(E − Et), eq. (2.35)
  };
  struct State {
    StressVoigt stress;
    double eps_p;    // equivalent plastic strain ε̄p
    double sigma_y;  // current yield stress σs = σs0 + Ep ε̄p
    // The fields a checkpoint stores (material.hpp).
    template <class S, class F>
    static void for_each_field(S& self, F&& field) {
      field(self.stress, self.eps_p, self.sigma_y);
    }
  };
  struct UpdateResult {
    bool plastic;
    int iterations;  // Newton corrections after the initial value (0 if elastic)
  };

  static constexpr bool has_plasticity = true;
  static constexpr bool has_damage = false;
  static constexpr const char* name = "J2 plasticity";

  explicit J2Plasticity(const Parameters& parameters)
      : parameters_((detail::validate_plastic_constants(parameters.E, parameters.nu,
                                                        parameters.sigma_y0, parameters.Ep),
                     parameters)),
        elasticity_(parameters.E, parameters.nu),
        return_map_constants_(elasticity_, parameters.Ep) {}

  State initial_state() const { return State{StressVoigt::Zero(), 0.0, parameters_.sigma_y0}; }

  UpdateResult update(State& state, const StrainVoigt& d_eps) const {
    return update(state, d_eps, ReturnMapOptions{});
  }

  UpdateResult update(State& state, const StrainVoigt& d_eps,
                      const ReturnMapOptions& options) const {
    detail::require_finite_strain(d_eps);
    const StressVoigt trial = state.stress + elasticity_.stress_increment(d_eps);  // eq. (2.23)
    // eq. (2.19)/(2.21) with the yield stress of step n.
    if (von_mises_squared(trial) <= state.sigma_y * state.sigma_y) {
      state.stress = trial;
      return {false, 0};
    }
    const return_map::Solution solution =
        return_map::solve(elasticity_, return_map_constants_, trial, state.sigma_y, options);
    state.stress = solution.stress;
    state.eps_p += solution.plastic_strain_increment;
    state.sigma_y += parameters_.Ep * solution.plastic_strain_increment;  // eq. (2.34)
    return {true, solution.iterations};
  }

  const Parameters& parameters() const { return parameters_; }
  double youngs_modulus() const { return parameters_.E; }
  double poisson_ratio() const { return parameters_.nu; }
  double shear_modulus() const { return elasticity_.shear_modulus(); }
  HardeningParameters hardening() const { return {parameters_.sigma_y0, parameters_.Ep}; }
  const PlaneStressElasticity& elasticity() const { return elasticity_; }
  Matrix3 elasticity_matrix() const { return elasticity_.matrix(); }

  double equivalent_stress(const State& state) const {
    return std::sqrt(von_mises_squared(state.stress));
  }
  double equivalent_plastic_strain(const State& state) const { return state.eps_p; }
  double damage(const State&) const { return 0.0; }
  bool failed(const State&) const { return false; }
  double elastic_energy_density(const State& state) const {
    return elasticity_.complementary_energy_density(state.stress);
  }

 private:
  Parameters parameters_;
  PlaneStressElasticity elasticity_;
  return_map::ClosedFormConstants return_map_constants_;
};

}  // namespace sphshell::material
