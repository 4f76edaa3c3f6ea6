// Shell-level checks against closed forms and published references:
// geometric nonlinearity (the elastica), the spherical-cap benchmark, energy
// conservation, and the solver's errors on bad input and instability.
#include <sphshell/approx/all.hpp>
#include <sphshell/crack/all.hpp>
#include <sphshell/kernel/all.hpp>
#include <sphshell/material/all.hpp>
#include <sphshell/shell/spherical_cap_ogrid.hpp>
#include <sphshell/solver.hpp>
#include <sphshell/thickness/all.hpp>

#include "support/relaxation.hpp"

#include <catch2/catch.hpp>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>

using namespace sphshell;

namespace {

using ElasticSolver = Solver<approx::MLS<kernel::CubicSpline>, thickness::Gauss<3>, material::Elastic>;


// Cantilever strip (ν = 0, so the strip bends like a beam) under a fixed
// vertical end load P = α EI/L², solved by dynamic relaxation; returns the tip
// deflection over L. The damping 1.5 ω takes every mode down by e^(−0.75 ω t),
// a factor 9e-3 per period of the first: the relaxation runs period by period
// and stops once the deflection moves by less than 1e-9 of itself over one
// (about 6 periods; 12 at most), where it agrees with the value after 12
// periods to ~1e-10.
double cantilever_tip_deflection(double load_factor, bool nonlinear) {
  const double L = 0.5, width = 0.1, d = 0.02, E = 210e9, rho = 7850;
  const double EI = E * width * d * d * d / 12.0;
  const double omega = 3.516 * std::sqrt(EI / (rho * width * d)) / (L * L);
  SolverOptions options;
  options.nonlinear = nonlinear;
  options.density = rho;
  options.damping = 1.5 * omega;
  options.rotary_inertia_scale = 4.0;
  ElasticSolver solver(ShellModel::rectangular_plate(L, width, 21, 5, d), {E, 0.0}, options);
  const ShellModel& model = solver.model();
  solver.clamp(model.set("x_min"));
  const ParticleSet& tip = model.set("x_max");
  const double load = load_factor * EI / (L * L);
  solver.add_point_force(tip, Vector3(0, 0, -load / tip.size()));
  auto tip_deflection = [&] {
    double deflection = 0.0;
    for (int i : tip) deflection += -solver.displacement(i).z() / tip.size();
    return deflection / L;
  };
  const double period = 2 * M_PI / omega;
  return test_support::relax_until_settled(solver, period, 12, 1e-9, tip_deflection).value;
}

}  // namespace

TEST_CASE("Large deflection of a cantilever follows the elastica", "[solver][nonlinear][validation]") {
  // Elastica tip deflections (Bisshopp & Drucker 1945; Mattiasson 1981):
  // PL²/EI = 1 → w/L = 0.30172, PL²/EI = 2 → 0.49346; the linear value is α/3.
  const double linear = cantilever_tip_deflection(1.0, false);
  const double nonlinear_1 = cantilever_tip_deflection(1.0, true);
  const double nonlinear_2 = cantilever_tip_deflection(2.0, true);
  WARN("cantilever tip w/L: linear " << linear << " (1/3), elastica alpha=1 " << nonlinear_1
                                     << " (0.30172), alpha=2 " << nonlinear_2 << " (0.49346)");
  CHECK(linear == Approx(1.0 / 3.0).epsilon(0.03));
  CHECK(nonlinear_1 == Approx(0.30172).epsilon(0.03));
  CHECK(nonlinear_2 == Approx(0.49346).epsilon(0.03));
}

TEST_CASE("Clamped spherical cap under step pressure: apex response of the classic benchmark",
          "[solver][shell][validation]") {
  // Paper Fig. 7: the apex moves inward to u/d ≈ 0.15 in the
  // first swing (≈ 0.2 ms) and reaches u/d ≈ 0.2–0.25 within 1 ms.
  const double thickness = 0.010414;
  SolverOptions options;
  options.density = 2618.0;
  Solver<approx::MLS<kernel::CubicSpline>, thickness::Gauss<5>, material::Elastic> solver(
      ShellModel::spherical_cap(0.5657, 26.67 * M_PI / 180, 17, thickness), {72.4e9, 0.3}, options);
  const ShellModel& model = solver.model();
  solver.clamp(model.set("boundary"));
  solver.add_uniform_pressure(model.all_particles(), 600 * 6894.757);
  const int apex = model.set("apex")[0];
  double first_peak = 0.0, overall_peak = 0.0;
  solver.run_until(1e-3, [&](const auto& s) {
    const double u = -s.displacement(apex).dot(model.particle_normal[apex]) / thickness;
    if (s.time() < 0.3e-3) first_peak = std::max(first_peak, u);
    overall_peak = std::max(overall_peak, u);
  });
  WARN("cap apex u/d: first swing peak " << first_peak << ", peak within 1 ms " << overall_peak);
  CHECK(first_peak > 0.12);
  CHECK(first_peak < 0.18);
  CHECK(overall_peak > 0.18);
  CHECK(overall_peak < 0.28);
  const EnergyReport energy = solver.energy();
  CHECK(std::abs(energy.balance()) < 1e-3 * energy.external_work);
}

TEST_CASE("Undamped elastic vibration conserves energy", "[solver][energy]") {
  SolverOptions options;
  ElasticSolver solver(ShellModel::rectangular_plate(0.3, 0.3, 13, 13, 0.01), {210e9, 0.3}, options);
  solver.clamp(solver.model().set("boundary"));
  solver.add_uniform_pressure(solver.model().all_particles(), 2e5, time_function::Ramp{2e-4});
  solver.run_until(2e-3);
  const EnergyReport energy = solver.energy();
  INFO("kinetic " << energy.kinetic << " internal " << energy.internal << " external " << energy.external_work);
  CHECK(energy.external_work > 0.0);
  CHECK(std::abs(energy.balance()) < 2e-3 * energy.external_work);
  CHECK(std::abs(energy.plastic_dissipation) < 1e-6 * energy.internal);
}

TEST_CASE("Solver input errors name the parameter", "[solver][errors]") {
  const ShellModel plate = ShellModel::rectangular_plate(0.1, 0.1, 5, 5, 0.01);
  SolverOptions options;
  options.time_step = 1.0;
  CHECK_THROWS_WITH(ElasticSolver(plate, {210e9, 0.3}, options), Catch::Contains("time_step"));
  options = {};
  options.density = -1.0;
  CHECK_THROWS_WITH(ElasticSolver(plate, {210e9, 0.3}, options), Catch::Contains("density"));
  options = {};
  options.safety_factor = 1.5;
  CHECK_THROWS_WITH(ElasticSolver(plate, {210e9, 0.3}, options), Catch::Contains("safety_factor"));
  CHECK_THROWS_WITH(ElasticSolver(plate, {-1.0, 0.3}), Catch::Contains("E"));
  CHECK_THROWS_WITH(ShellModel::rectangular_plate(0.1, 0.1, 5, 5, 0.0), Catch::Contains("thickness"));
  ElasticSolver solver(plate, {210e9, 0.3});
  CHECK_THROWS_WITH(solver.clamp({99}), Catch::Contains("particle index"));
  CHECK_THROWS_WITH(solver.model().set("no such edge"), Catch::Contains("no such edge"));
  CHECK_THROWS_WITH(solver.add_uniform_pressure({0}, std::numeric_limits<double>::quiet_NaN()),
                    Catch::Contains("pressure"));
}

TEST_CASE("A run that goes non-finite stops with the step, time and particle", "[solver][errors]") {
  ElasticSolver solver(ShellModel::rectangular_plate(0.1, 0.1, 5, 5, 0.01), {210e9, 0.3});
  solver.add_pressure({12}, [](const Vector3&, double t) {
    return t > 5e-6 ? std::numeric_limits<double>::quiet_NaN() : 1e3;
  });
  try {
    solver.run_until(1e-4);
    FAIL("the run should have stopped");
  } catch (const Error& error) {
    const std::string message = error.what();
    CHECK_THAT(message, Catch::Contains("unstable at step") && Catch::Contains("t = ") &&
                            Catch::Contains("particle 12"));
  }
}

TEST_CASE("ParaView frames, collections and probes are written", "[solver][output]") {
  const std::string directory = (std::filesystem::temp_directory_path() / "sphshell_output_test").string();
  std::filesystem::remove_all(directory);
  SolverOptions options;
  options.output_directory = directory;
  options.output_interval = 1e-5;
  ElasticSolver solver(ShellModel::rectangular_plate(0.1, 0.1, 5, 5, 0.01), {210e9, 0.3}, options);
  solver.clamp(solver.model().set("boundary"));
  solver.add_uniform_pressure(solver.model().all_particles(), 1e5);
  solver.add_particle_probe(directory + "/centre.csv", solver.model().set("centre")[0]);
  solver.add_stress_point_probe(directory + "/sp0.csv", 0);
  solver.run_until(5e-5);
  std::ifstream collection(directory + "/particles.pvd");
  std::stringstream text;
  text << collection.rdbuf();
  const std::string pvd = text.str();
  std::size_t frames = 0;
  for (std::size_t at = pvd.find("<DataSet"); at != std::string::npos; at = pvd.find("<DataSet", at + 1)) ++frames;
  CHECK(frames >= 5);  // t = 0 and every 1e-5 s up to 5e-5 s
  CHECK(std::filesystem::exists(directory + "/particles_000000.vtu"));
  CHECK(std::filesystem::exists(directory + "/stress_points_000000.vtu"));
  std::ifstream stress_collection(directory + "/stress_points.pvd");
  CHECK(stress_collection.good());
  std::ifstream probe(directory + "/centre.csv");
  std::string line;
  std::size_t rows = 0;
  while (std::getline(probe, line)) ++rows;
  CHECK(rows == static_cast<std::size_t>(solver.steps()) + 2);  // header, t = 0, every step
  std::filesystem::remove_all(directory);
}
