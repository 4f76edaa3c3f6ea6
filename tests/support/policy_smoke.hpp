#pragma once
// Builds and runs a small solver for one policy combination: a 7 × 7 clamped
// plate under pressure for a few steps, checking the state stays finite and moves.

#include <sphshell/sphshell.hpp>

#include <catch2/catch.hpp>

#include <string>

namespace sphshell::test_support {

template <class Material>
typename Material::Parameters steel_parameters() {
  if constexpr (std::is_same_v<Material, material::Elastic>) return {210e9, 0.3};
  else if constexpr (std::is_same_v<Material, material::J2Plasticity>) return {210e9, 0.3, 235e6, 1e9};
  else return {210e9, 0.3, 235e6, 1e9, 0.02, 0.37, 0.24};
}

template <class Approx, class Rule, class Material>
void run_policy_smoke_test(const std::string& label) {
  INFO(label);
  SolverOptions options;
  options.nonlinear = true;
  Solver<Approx, Rule, Material> solver(ShellModel::rectangular_plate(0.06, 0.06, 7, 7, 0.01),
                                        steel_parameters<Material>(), options);
  solver.clamp(solver.model().set("x_min"));
  const ParticleSet all = solver.model().all_particles();
  // Large enough to yield near the clamped edge within the few steps.
  solver.add_uniform_pressure(all, 5e7);
  for (int step = 0; step < 10; ++step) solver.step();
  double largest = 0.0;
  bool finite = true;
  for (std::size_t i = 0; i < solver.particle_count(); ++i) {
    finite = finite && solver.positions()[i].allFinite();
    largest = std::max(largest, solver.displacement(static_cast<int>(i)).norm());
  }
  CHECK(finite);
  CHECK(largest > 0.0);
  CHECK(std::isfinite(solver.energy().balance()));
}

}  // namespace sphshell::test_support
