#pragma once
// Load paths shared by the material tests. They drive a law only through its
// public update(); the expected values are computed independently in the tests.

#include <sphshell/core/types.hpp>

#include <cmath>
#include <stdexcept>

namespace material_test {

// Steel of the paper's Table 3 (σs0 235 MPa); Ep chosen per test.
constexpr double youngs_modulus = 210e9;
constexpr double poisson_ratio = 0.3;
constexpr double yield_stress = 235e6;

// One step of a uniaxial stress path: applies the axial strain increment
// d_eps_x and finds the lateral increment that keeps σy = 0 (σxy stays 0 since
// γxy = 0) by the secant method on the law itself. Returns the lateral
// increment used; `state` ends in the accepted state.
template <class Law>
double uniaxial_step(const Law& law, typename Law::State& state, double d_eps_x,
                     typename Law::UpdateResult* result = nullptr) {
  const double tolerance = 1e-11 * yield_stress;
  const auto lateral_stress = [&](double d_eps_y, typename Law::State& trial) {
    trial = state;
    const auto r = law.update(trial, sphshell::StrainVoigt(d_eps_x, d_eps_y, 0.0));
    if (result) *result = r;
    return trial.stress.y();
  };
  typename Law::State trial = state;
  double x0 = -law.poisson_ratio() * d_eps_x;  // elastic guess
  double x1 = -0.5 * d_eps_x;                  // plastically incompressible guess
  double f0 = lateral_stress(x0, trial);
  if (std::abs(f0) <= tolerance) {
    state = trial;
    return x0;
  }
  double f1 = lateral_stress(x1, trial);
  for (int iteration = 0; iteration < 100; ++iteration) {
    if (std::abs(f1) <= tolerance) {
      state = trial;
      return x1;
    }
    if (f1 == f0) break;
    const double x2 = x1 - f1 * (x1 - x0) / (f1 - f0);
    x0 = x1;
    f0 = f1;
    x1 = x2;
    f1 = lateral_stress(x1, trial);
  }
  throw std::runtime_error("uniaxial_step: lateral strain secant did not converge");
}

}  // namespace material_test
