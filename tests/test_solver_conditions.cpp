// Kinematic conditions: symmetry planes reproduce the full model, fixed
// rotations stay fixed under large rotation, prescribed motions are imposed
// exactly, and energy stays balanced when a pre-crack is cut mid-run.
#include <sphshell/approx/all.hpp>
#include <sphshell/crack/all.hpp>
#include <sphshell/kernel/all.hpp>
#include <sphshell/material/all.hpp>
#include <sphshell/solver.hpp>
#include <sphshell/thickness/all.hpp>

#include <catch2/catch.hpp>

#include <cmath>

using namespace sphshell;

namespace {

using ElasticSolver = Solver<approx::MLS<kernel::CubicSpline>, thickness::Gauss<2>, material::Elastic>;


SolverOptions relaxation(double fundamental_frequency) {
  SolverOptions options;
  options.nonlinear = false;
  options.damping = 2 * fundamental_frequency;
  options.rotary_inertia_scale = 3.0;
  return options;
}

}  // namespace

TEST_CASE("A quarter plate with two symmetry planes matches the full plate", "[solver][conditions]") {
  const double L = 1.0, d = 0.02, E = 210e9, nu = 0.3, rho = 7850, q = 1e3;
  const double D = E * d * d * d / (12 * (1 - nu * nu));
  const double omega = 35.99 / (L * L) * std::sqrt(D / (rho * d));
  const double end = 6 * 2 * M_PI / omega;

  ElasticSolver full(ShellModel::rectangular_plate(L, L, 21, 21, d), {E, nu}, relaxation(omega));
  full.clamp(full.model().set("boundary"));
  full.add_uniform_pressure(full.model().all_particles(), q);
  full.run_until(end);
  const double full_centre = full.displacement(full.model().set("centre")[0]).z();

  // The quarter [0, L/2]²: clamped at x = 0 and y = 0, symmetric at x = L/2 and y = L/2.
  ElasticSolver quarter(ShellModel::rectangular_plate(L / 2, L / 2, 11, 11, d), {E, nu}, relaxation(omega));
  const ShellModel& model = quarter.model();
  quarter.clamp(model.set("x_min"));
  quarter.clamp(model.set("y_min"));
  quarter.symmetry_plane(model.set("x_max"), Vector3::UnitX());
  quarter.symmetry_plane(model.set("y_max"), Vector3::UnitY());
  quarter.add_uniform_pressure(model.all_particles(), q);
  quarter.run_until(end);
  const double quarter_centre = quarter.displacement(model.nearest_particle(Vector3(L / 2, L / 2, 0))).z();
  WARN("centre deflection: full plate " << full_centre << " m, quarter with symmetry " << quarter_centre << " m");
  CHECK(quarter_centre == Approx(full_centre).epsilon(0.02));
}

TEST_CASE("A symmetry plane keeps the director in the plane under large rotation", "[solver][conditions]") {
  // A strip bent by an end load into large rotation; the symmetry plane y = 0
  // forbids the director to tilt in y.
  SolverOptions options;
  options.nonlinear = true;
  options.damping = 200.0;
  ElasticSolver solver(ShellModel::rectangular_plate(0.5, 0.1, 21, 5, 0.02), {210e9, 0.0}, options);
  const ShellModel& model = solver.model();
  solver.clamp(model.set("x_min"));
  solver.symmetry_plane(model.set("y_min"), Vector3::UnitY());
  const ParticleSet& tip = model.set("x_max");
  solver.add_point_force(tip, Vector3(0, 0, -2.0 * 210e9 * 0.1 * 8e-6 / 12 / 0.25 / tip.size()));
  solver.run_until(2e-2);
  double largest_tilt = 0.0, largest_rotation = 0.0;
  for (int i : model.set("y_min")) {
    largest_tilt = std::max(largest_tilt, std::abs(solver.directors()[i].y()));
    largest_rotation = std::max(largest_rotation, solver.rotation(i).norm());
  }
  INFO("largest rotation on the plane " << largest_rotation << " rad");
  CHECK(largest_rotation > 0.5);
  CHECK(largest_tilt < 1e-12);
}

TEST_CASE("A prescribed displacement history is imposed exactly", "[solver][conditions]") {
  ElasticSolver solver(ShellModel::rectangular_plate(0.2, 0.1, 11, 6, 0.01), {210e9, 0.3});
  const double a = 50.0;  // m/s²
  solver.prescribe_displacement(solver.model().set("x_max"),
                                [a](const Vector3&, double t) { return Vector3(a * t * t, 0.0, 0.0); });
  solver.clamp(solver.model().set("x_min"));
  for (int k = 0; k < 40; ++k) solver.step();
  const double t = solver.time();
  for (int i : solver.model().set("x_max"))
    CHECK(solver.displacement(i).x() == Approx(a * t * t).epsilon(1e-9));
  CHECK_THROWS_WITH(solver.prescribe_velocity(solver.model().set("y_min"),
                                              [](const Vector3&, double) { return Vector3(NAN, 0, 0); }),
                    Catch::Contains("prescribed motion"));
  ElasticSolver fresh(ShellModel::rectangular_plate(0.2, 0.1, 11, 6, 0.01), {210e9, 0.3});
  CHECK_THROWS_WITH(fresh.prescribe_displacement(fresh.model().set("x_max"),
                                                 [](const Vector3&, double) { return Vector3(1e-3, 0, 0); }),
                    Catch::Contains("prescribed displacement at t = 0"));
}

TEST_CASE("Cutting a pre-crack mid-run keeps the energy balance", "[solver][fracture][energy]") {
  Solver<approx::MLS<kernel::CubicSpline>, thickness::Gauss<2>, material::Elastic, crack::LineSegments> solver(
      ShellModel::rectangular_plate(0.2, 0.1, 21, 11, 0.005), {210e9, 0.3});
  const ShellModel& model = solver.model();
  solver.clamp(model.set("x_min"));
  solver.add_uniform_pressure(model.all_particles(), 2e4, time_function::Ramp{1e-4});
  solver.run_until(2e-4);
  solver.add_precrack({Vector3(0.1025, -0.002, 0.0), Vector3(0.1025, 0.06, 0.0)});
  solver.run_until(4e-4);
  const EnergyReport energy = solver.energy();
  INFO("external " << energy.external_work << " J, balance " << energy.balance() << " J, released "
                   << energy.released_by_fracture << " J, dissipation " << energy.plastic_dissipation << " J");
  CHECK(std::abs(energy.balance()) < 2e-3 * energy.external_work);
  CHECK(energy.plastic_dissipation > -1e-6 * energy.external_work);
}
