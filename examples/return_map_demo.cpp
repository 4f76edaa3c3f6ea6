// One integral point through a uniaxial tension → unloading → compression →
// reloading loop, printed as a stress–strain table: a uniaxial test of the
// paper's plane-stress J2 return map (eq. 2.23-2.39).
// `return_map_demo --help` says what it prints.

#include <sphshell/material/all.hpp>

#include "example_arguments.hpp"

#include <cmath>
#include <cstdio>
#include <iostream>
#include <vector>

using namespace sphshell;
using namespace sphshell::material;

namespace {

// Lateral strain increment that keeps σy = 0 (secant on the law itself).
template <class Law>
typename Law::UpdateResult uniaxial_step(const Law& law, typename Law::State& state, double d_eps_x,
                                         double& d_eps_y) {
  typename Law::UpdateResult result{};
  const auto lateral_stress = [&](double lateral, typename Law::State& trial) {
    trial = state;
    result = law.update(trial, StrainVoigt(d_eps_x, lateral, 0.0));
    return trial.stress.y();
  };
  typename Law::State trial = state;
  double x0 = -law.poisson_ratio() * d_eps_x, x1 = -0.5 * d_eps_x;
  double f0 = lateral_stress(x0, trial);
  double f1 = lateral_stress(x1, trial);
  for (int iteration = 0; iteration < 50 && std::abs(f1) > 1e-6 && f1 != f0; ++iteration) {
    const double x2 = x1 - f1 * (x1 - x0) / (f1 - f0);
    x0 = x1;
    f0 = f1;
    x1 = x2;
    f1 = lateral_stress(x1, trial);
  }
  state = trial;
  d_eps_y = x1;
  return result;
}

}  // namespace

int main(int argc, char** argv) {
  example::CommandLine command_line(
      "return_map_demo",
      "One integral point of J2 plasticity (E 210 GPa, ν 0.3, σs0 235 MPa, tangent modulus 2.1 GPa) through "
      "a uniaxial loop: tension to 1 % strain, unloading to 0, compression to -1 %, reloading to 0.5 %, in "
      "steps of 0.025 %. σy = σxy = 0 is kept by solving for the lateral strain each step, so the table is "
      "a uniaxial test of the plane-stress return map.");
  command_line.note("Prints the table as CSV on standard output (redirect it to keep it; no files are "
                    "written): step, strains ε_x and ε_y, stresses σ_x and σ_y, equivalent stress, "
                    "equivalent plastic strain, current yield stress, whether the step was plastic and its "
                    "Newton iterations; then a closing line comparing σs0 + Ep ε̄p with the current yield "
                    "stress (linear hardening, eq. 2.35).");
  try {
    if (!command_line.parse(argc, argv)) return 0;
  } catch (const std::exception& error) {
    std::cerr << "return_map_demo: " << error.what() << '\n';
    return 1;
  }
  const double E = 210e9, nu = 0.3, sigma_y0 = 235e6;
  const double tangent_modulus = 2.1e9;
  const double Ep = E * tangent_modulus / (E - tangent_modulus);  // eq. (2.35)
  const J2Plasticity law({E, nu, sigma_y0, Ep});
  J2Plasticity::State state = law.initial_state();

  // Strain targets of the loop: tension to 1 %, back to 0, compression to −1 %, back to 0.5 %.
  const std::vector<double> targets = {0.01, 0.0, -0.01, 0.005};
  const double step = 2.5e-4;

  std::printf(
      "step,eps_x[-],eps_y[-],sigma_x[MPa],sigma_y[MPa],eq_stress[MPa],eps_p[-],"
      "yield_stress[MPa],plastic,newton_iterations\n");
  double eps_x = 0.0, eps_y = 0.0;
  int index = 0;
  std::printf("%d,%.6e,%.6e,%.3f,%.3e,%.3f,%.6e,%.3f,%d,%d\n", index, eps_x, eps_y, 0.0, 0.0, 0.0,
              0.0, state.sigma_y / 1e6, 0, 0);
  for (const double target : targets) {
    const int count = static_cast<int>(std::lround(std::abs(target - eps_x) / step));
    const double increment = (target - eps_x) / count;
    for (int k = 0; k < count; ++k) {
      double d_eps_y = 0.0;
      const auto result = uniaxial_step(law, state, increment, d_eps_y);
      eps_x += increment;
      eps_y += d_eps_y;
      std::printf("%d,%.6e,%.6e,%.3f,%.3e,%.3f,%.6e,%.3f,%d,%d\n", ++index, eps_x, eps_y,
                  state.stress.x() / 1e6, state.stress.y() / 1e6,
                  law.equivalent_stress(state) / 1e6, state.eps_p, state.sigma_y / 1e6,
                  result.plastic ? 1 : 0, result.iterations);
    }
  }
  // Closed-form check of the last plastic state: σx = σs0 + Ep ε̄p (linear hardening).
  std::printf("# final: sigma_y0 + Ep*eps_p = %.3f MPa, current yield stress = %.3f MPa\n",
              (sigma_y0 + Ep * state.eps_p) / 1e6, state.sigma_y / 1e6);
  return 0;
}
