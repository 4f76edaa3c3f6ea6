#pragma once
// Plane-stress von Mises plasticity with linear isotropic hardening (section 2.2
// of the paper): elastic predictor, yield check, Newton–Raphson return map.

#include <sphshell/core/error.hpp>
#include <sphshell/core/types.hpp>
#include <sphshell/material/elastic.hpp>
#include <sphshell/material/lanes.hpp>
#include <sphshell/material/material.hpp>
#include <sphshell/material/return_map.hpp>

#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>

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

  // N states in structure-of-arrays form, for update_lanes (lanes.hpp).
  template <int N>
  struct Lanes {
    VoigtLanes<N> stress;
    alignas(64) std::array<double, std::size_t(N)> eps_p{};
    alignas(64) std::array<double, std::size_t(N)> sigma_y{};

    State state(int k) const {
      return State{stress.at(k), eps_p[std::size_t(k)], sigma_y[std::size_t(k)]};
    }
    void set_state(int k, const State& s) {
      stress.set(k, s.stress);
      eps_p[std::size_t(k)] = s.eps_p;
      sigma_y[std::size_t(k)] = s.sigma_y;
    }
  };

  // update() of every lane at once: the elastic predictor and the yield check
  // for all lanes, then — only if some lane yields — the closed-form return
  // (return_map::closed_form_lane) for all lanes, the elastic ones masked. A
  // lane that leaves the closed form's fast path is solved by update() on its
  // own. Returns the number of lanes that yielded.
  template <int N>
  int update_lanes(Lanes<N>& lanes, const VoigtLanes<N>& d_eps) const {
    constexpr std::size_t n = std::size_t(N);
    // The loops below hold no branch and no floating-point operation that only
    // some lanes execute (under the default -ftrapping-math a compiler may not
    // run such an operation for every lane), only selections between values
    // computed for all lanes; flags are doubles (lanes.hpp, any_lane).
    // A non-finite increment is refused before anything changes, with update()'s
    // message: x − x is NaN for ±inf and NaN, +0 otherwise.
    alignas(64) std::array<double, n> non_finite;
    for (std::size_t k = 0; k < n; ++k)
      non_finite[k] = (d_eps.xx[k] - d_eps.xx[k]) + (d_eps.yy[k] - d_eps.yy[k]) + (d_eps.xy[k] - d_eps.xy[k]);
    if (detail::any_lane(non_finite))
      for (int k = 0; k < N; ++k) detail::require_finite_strain(d_eps.at(k));
    const double biaxial = elasticity_.biaxial_modulus(), nu = elasticity_.poisson_ratio(),
                 shear_modulus = elasticity_.shear_modulus();
    // eq. (2.23) and the yield check (2.19)/(2.21), as in update().
    alignas(64) std::array<double, n> trial_xx, trial_yy, trial_xy, yields;
    for (std::size_t k = 0; k < n; ++k) {
      const double x = lanes.stress.xx[k] + biaxial * (d_eps.xx[k] + nu * d_eps.yy[k]);
      const double y = lanes.stress.yy[k] + biaxial * (nu * d_eps.xx[k] + d_eps.yy[k]);
      const double xy = lanes.stress.xy[k] + shear_modulus * d_eps.xy[k];
      trial_xx[k] = x;
      trial_yy[k] = y;
      trial_xy[k] = xy;
      yields[k] = x * x + y * y - x * y + 3.0 * xy * xy <= lanes.sigma_y[k] * lanes.sigma_y[k] ? 0.0 : 1.0;
    }
    if (!detail::any_lane(yields)) {
      lanes.stress.xx = trial_xx;
      lanes.stress.yy = trial_yy;
      lanes.stress.xy = trial_xy;
      return 0;
    }
    // The closed form's invariants of every trial stress (return_map.hpp).
    alignas(64) std::array<double, n> equibiaxial, deviatoric, trial_equivalent;
    for (std::size_t k = 0; k < n; ++k) {
      const double sum = trial_xx[k] + trial_yy[k], diff = trial_xx[k] - trial_yy[k];
      equibiaxial[k] = 0.25 * sum * sum;
      deviatoric[k] = 0.75 * diff * diff + 3.0 * trial_xy[k] * trial_xy[k];
      trial_equivalent[k] = equibiaxial[k] + deviatoric[k];
    }
    detail::sqrt_lanes(trial_equivalent);
    // The return of every lane (the elastic ones too), kept in arrays so that
    // no part of it is computed for some lanes only.
    alignas(64) std::array<double, n> returned_xx, returned_yy, returned_xy, returned_eps_p, returned_sigma_y, fast;
    const double plastic_modulus = parameters_.Ep;
    for (std::size_t k = 0; k < n; ++k) {
      const double x = trial_xx[k], y = trial_yy[k], xy = trial_xy[k];
      const return_map::detail::LaneReturn returned =
          return_map::detail::closed_form_lane(return_map_constants_, x + y, x - y, xy, equibiaxial[k],
                                               deviatoric[k], trial_equivalent[k], lanes.sigma_y[k]);
      returned_xx[k] = returned.xx;
      returned_yy[k] = returned.yy;
      returned_xy[k] = returned.xy;
      returned_eps_p[k] = lanes.eps_p[k] + returned.increment;
      returned_sigma_y[k] = lanes.sigma_y[k] + plastic_modulus * returned.increment;  // eq. (2.34)
      fast[k] = returned.fast ? 1.0 : 0.0;
    }
    // Lanes that yield off the fast path are solved by update() first, on
    // copies: if one of them throws, every lane is still as it was (the
    // guarantee lanes.hpp states), and otherwise their results are written
    // after the others'.
    alignas(64) std::array<double, n> alone;
    for (std::size_t k = 0; k < n; ++k) alone[k] = yields[k] - yields[k] * fast[k];
    const bool some_alone = detail::any_lane(alone);
    std::array<State, n> solved_alone;
    if (some_alone)
      for (int k = 0; k < N; ++k) {
        if (alone[std::size_t(k)] == 0.0) continue;
        solved_alone[std::size_t(k)] = lanes.state(k);
        update(solved_alone[std::size_t(k)], d_eps.at(k));
      }
    // Each lane's new state: the trial (elastic), the return (yielding, on the
    // fast path), or the old state (yielding, off it: replaced below).
    for (std::size_t k = 0; k < n; ++k) {
      // 0/1 flags; detail::blend selects without a branch.
      const double returned_here = yields[k] * fast[k], left = alone[k];
      using detail::blend;
      lanes.stress.xx[k] = blend(returned_here, returned_xx[k], blend(left, lanes.stress.xx[k], trial_xx[k]));
      lanes.stress.yy[k] = blend(returned_here, returned_yy[k], blend(left, lanes.stress.yy[k], trial_yy[k]));
      lanes.stress.xy[k] = blend(returned_here, returned_xy[k], blend(left, lanes.stress.xy[k], trial_xy[k]));
      lanes.eps_p[k] = blend(returned_here, returned_eps_p[k], lanes.eps_p[k]);
      lanes.sigma_y[k] = blend(returned_here, returned_sigma_y[k], lanes.sigma_y[k]);
    }
    if (some_alone)
      for (int k = 0; k < N; ++k)
        if (alone[std::size_t(k)] != 0.0) lanes.set_state(k, solved_alone[std::size_t(k)]);
    int yielding = 0;
    for (std::size_t k = 0; k < n; ++k) yielding += yields[k] != 0.0;
    return yielding;
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
