// Rigid bodies in the Solver (Solver::add_rigid_body): a free sphere striking
// an elastic clamped plate and rebounding, a sphere resting on a plate under
// gravity, momentum exchanged with a free plate, the run's time step, thread
// counts and refused input. The checks are conservation laws and statics,
// computed here from what the solver reports.
#include <sphshell/sphshell.hpp>

#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <fstream>
#include <string>
#include <vector>
#ifdef _OPENMP
#include <omp.h>
#endif

using namespace sphshell;

namespace {

constexpr double pi = 3.14159265358979323846;

using PlateSolver = Solver<approx::MLS<kernel::CubicSpline>, thickness::Gauss<3>, material::Elastic>;
using FreeSphere = contact::RigidBody<contact::Sphere, contact::Free>;

// A 0.2 m square steel plate, 2 mm thick, 15 × 15 particles.
constexpr double plate_side = 0.2;
constexpr int plate_particles = 15;
constexpr double plate_thickness = 2e-3;
constexpr double steel_density = 7850.0;
const material::Elastic::Parameters steel{210e9, 0.3};

// A steel sphere of radius 10 mm.
constexpr double sphere_radius = 0.01;
const double sphere_mass = steel_density * 4.0 / 3.0 * pi * sphere_radius * sphere_radius * sphere_radius;

SolverOptions plate_options(double damping = 0.0) {
  SolverOptions options;
  options.density = steel_density;
  options.damping = damping;
  return options;
}

Vector3 plate_centre() { return {0.5 * plate_side, 0.5 * plate_side, 0.0}; }

// A free sphere above the plate centre: its surface `gap` above the plate's upper face.
FreeSphere sphere_above_plate(double gap, const Vector3& velocity, const Vector3& gravity = Vector3::Zero()) {
  contact::RigidKinematics start;
  start.position = plate_centre() + Vector3(0.0, 0.0, sphere_radius + 0.5 * plate_thickness + gap);
  start.velocity = velocity;
  const double inertia = 0.4 * sphere_mass * sphere_radius * sphere_radius;
  return FreeSphere(contact::Sphere(sphere_radius),
                    contact::Free({sphere_mass, Vector3::Constant(inertia), gravity}), start);
}

// The total energy of shell, bodies and contact springs.
double system_energy(const EnergyReport& e) {
  return e.kinetic + e.elastic + e.rigid_body_kinetic + e.contact_energy;
}

// What a struck-plate run gives.
struct ImpactRun {
  double impulse_from_forces = 0.0;  // Σ over the steps of the reported contact force × the velocity update's span
  Vector3 velocity_change = Vector3::Zero();
  double largest_energy_error = 0.0;  // |E(t) − E0| / E0 over the run
  double largest_balance = 0.0;       // |balance| / E0
  std::size_t steps_in_contact = 0;
  double time_step = 0.0, time_step_without_body = 0.0;
  std::vector<Vector3> positions;
};

constexpr double impact_speed = 1.0;   // m/s
constexpr double impact_gap = 5e-5;    // m, so the sphere strikes after 50 µs
constexpr double impact_duration = 1.5e-3;

ImpactRun strike_clamped_plate(double stiffness_scale = contact::default_penalty_stiffness_scale) {
  const ShellModel plate = ShellModel::rectangular_plate(plate_side, plate_side, plate_particles, plate_particles,
                                                         plate_thickness);
  PlateSolver solver(plate, steel, plate_options());
  solver.clamp(plate.set("boundary"));
  ImpactRun run;
  run.time_step_without_body = solver.time_step();
  contact::PenaltyOptions contact;
  contact.stiffness_scale = stiffness_scale;
  const contact::RigidBodyId sphere =
      solver.add_rigid_body(sphere_above_plate(impact_gap, {0.0, 0.0, -impact_speed}), contact);
  run.time_step = solver.time_step();
  const double initial_energy = 0.5 * sphere_mass * impact_speed * impact_speed;
  const Vector3 initial_velocity = solver.rigid_body(sphere).kinematics.velocity;
  solver.run_until(impact_duration, [&](const PlateSolver& s) {
    const contact::RigidBodyState body = s.rigid_body(sphere);
    // The step just taken was step n = steps − 1; the first update spans Δt/2.
    const double span = s.steps() == 1 ? 0.5 * s.time_step() : s.time_step();
    run.impulse_from_forces += span * body.contact_force.z();
    if (body.contacts > 0) ++run.steps_in_contact;
    const EnergyReport e = s.energy();
    run.largest_energy_error =
        std::max(run.largest_energy_error, std::abs(system_energy(e) - initial_energy) / initial_energy);
    run.largest_balance = std::max(run.largest_balance, std::abs(e.balance()) / initial_energy);
  });
  run.velocity_change = solver.rigid_body(sphere).kinematics.velocity - initial_velocity;
  run.positions = solver.positions();
  run.positions.push_back(solver.rigid_body(sphere).kinematics.position);
  return run;
}

}  // namespace

TEST_CASE("a free sphere striking a clamped elastic plate: impulse equals momentum change, energy conserved",
          "[contact][validation]") {
  const ImpactRun run = strike_clamped_plate();
  INFO("steps in contact " << run.steps_in_contact << ", velocity change " << run.velocity_change.transpose());
  // The sphere struck, and left the plate moving up.
  REQUIRE(run.steps_in_contact > 10);
  CHECK(run.velocity_change.z() > impact_speed);
  // ∫ F dt from the contact forces the solver reported equals m Δv to 0.5 %.
  const double momentum_change = sphere_mass * run.velocity_change.z();
  CHECK(std::abs(run.impulse_from_forces - momentum_change) <= 5e-3 * std::abs(momentum_change));
  // Shell, sphere and contact springs hold the sphere's initial kinetic energy to 1 %.
  INFO("largest energy error " << run.largest_energy_error << ", largest balance " << run.largest_balance);
  CHECK(run.largest_energy_error < 0.01);
  CHECK(run.largest_balance < 0.01);
}

TEST_CASE("contact keeps the run's time step", "[contact]") {
  const ImpactRun run = strike_clamped_plate();
  // The penalty stiffness follows from the step (k = s m / Δt²): the step is not cut at all.
  CHECK(run.time_step == run.time_step_without_body);
  CHECK(run.time_step >= 0.9 * run.time_step_without_body);
  // At the largest scale the rule allows beside the shell's own stiffness
  // (s = 1.44, contact/penalty.hpp) the run at that step stays stable: the
  // energy stays within a few per cent (an unstable run grows without bound).
  const ImpactRun stiff = strike_clamped_plate(1.4);
  INFO("largest energy error at s = 1.4: " << stiff.largest_energy_error);
  CHECK(stiff.largest_energy_error < 0.05);
}

TEST_CASE("a sphere resting on a plate under gravity: the contact force is its weight",
          "[contact][validation]") {
  const ShellModel plate = ShellModel::rectangular_plate(plate_side, plate_side, plate_particles, plate_particles,
                                                         plate_thickness);
  // Mass-proportional damping near twice the plate's fundamental angular
  // frequency (clamped square plate: ω = 35.99 √(D / ρh) / a²), so it settles.
  const double bending_stiffness = 210e9 * std::pow(plate_thickness, 3) / (12.0 * (1.0 - 0.3 * 0.3));
  const double fundamental =
      35.99 * std::sqrt(bending_stiffness / (steel_density * plate_thickness)) / (plate_side * plate_side);
  PlateSolver solver(plate, steel, plate_options(2.0 * fundamental));
  solver.clamp(plate.set("boundary"));
  const Vector3 gravity(0.0, 0.0, -9.81);
  const contact::RigidBodyId sphere = solver.add_rigid_body(sphere_above_plate(0.0, Vector3::Zero(), gravity));
  const double settle = 8e-3, average_over = 2e-3;
  double force_time = 0.0, time = 0.0;
  solver.run_until(settle + average_over, [&](const PlateSolver& s) {
    if (s.time() <= settle) return;
    force_time += s.time_step() * s.rigid_body(sphere).contact_force.z();
    time += s.time_step();
  });
  const double weight = sphere_mass * 9.81;
  const double mean_force = force_time / time;
  INFO("mean contact force " << mean_force << " N, weight " << weight << " N");
  CHECK(std::abs(mean_force - weight) <= 5e-3 * weight);
  // At rest: the last force too, and the sphere's speed is negligible.
  CHECK(std::abs(solver.rigid_body(sphere).contact_force.z() - weight) <= 5e-3 * weight);
  CHECK(solver.rigid_body(sphere).kinematics.velocity.norm() < 1e-4);
  // The plate carries the sphere: its centre is pressed down.
  CHECK(solver.displacement(plate.set("centre")[0]).z() < 0.0);
}

TEST_CASE("a sphere striking a free plate: shell and sphere exchange momentum exactly", "[contact]") {
  const ShellModel plate = ShellModel::rectangular_plate(plate_side, plate_side, plate_particles, plate_particles,
                                                         plate_thickness);
  PlateSolver solver(plate, steel, plate_options());
  const contact::RigidBodyId sphere =
      solver.add_rigid_body(sphere_above_plate(impact_gap, {0.0, 0.0, -impact_speed}));
  solver.run_until(5e-4);
  REQUIRE(solver.rigid_body(sphere).contact_impulse.norm() > 0.0);
  // Σ m_i v_i of the shell plus m v of the sphere: what the sphere brought in.
  const std::vector<Vector3> velocity = solver.velocities();
  Vector3 momentum = sphere_mass * solver.rigid_body(sphere).kinematics.velocity;
  for (std::size_t i = 0; i < velocity.size(); ++i) momentum += solver.masses()[i] * velocity[i];
  const double brought = sphere_mass * impact_speed;
  INFO("momentum " << momentum.transpose() << ", impulse " << solver.rigid_body(sphere).contact_impulse.transpose());
  CHECK(std::abs(momentum.z() + brought) <= 1e-9 * brought);
  CHECK(std::abs(momentum.x()) <= 1e-9 * brought);
  CHECK(std::abs(momentum.y()) <= 1e-9 * brought);
  // The impulse the sphere received is a sizeable part of its momentum.
  CHECK(solver.rigid_body(sphere).contact_impulse.z() > 0.1 * brought);
}

#ifdef _OPENMP
TEST_CASE("a struck plate gives the same bits on 1 and 2 threads", "[contact]") {
  omp_set_num_threads(1);
  const ImpactRun one = strike_clamped_plate();
  omp_set_num_threads(2);
  const ImpactRun two = strike_clamped_plate();
  omp_set_num_threads(1);
  REQUIRE(one.positions.size() == two.positions.size());
  std::size_t differing = 0;
  for (std::size_t i = 0; i < one.positions.size(); ++i) differing += one.positions[i] != two.positions[i] ? 1 : 0;
  CHECK(differing == 0);
}
#endif

TEST_CASE("rigid bodies: refused input and the probe", "[contact]") {
  const ShellModel plate = ShellModel::rectangular_plate(plate_side, plate_side, plate_particles, plate_particles,
                                                         plate_thickness);
  PlateSolver solver(plate, steel, plate_options());
  // A body deeper in the shell than half its thickness.
  CHECK_THROWS_WITH(solver.add_rigid_body(sphere_above_plate(-plate_thickness, Vector3::Zero())),
                    Catch::Contains("initial gap") && Catch::Contains("inside the shell"));
  contact::PenaltyOptions negative_friction;
  negative_friction.friction_coefficient = -0.1;
  CHECK_THROWS_WITH(solver.add_rigid_body(sphere_above_plate(0.01, Vector3::Zero()), negative_friction),
                    Catch::Contains("friction_coefficient"));
  CHECK(solver.rigid_body_count() == 0);
  CHECK_THROWS_WITH(solver.rigid_body(0), Catch::Contains("rigid body id"));
  // A wall below the plate, and a probe of it.
  const contact::RigidBodyId wall = solver.add_rigid_body(contact::fixed_wall({0.0, 0.0, -0.01}, Vector3::UnitZ()));
  const std::string probe = "test_contact_solver_wall.csv";
  solver.add_rigid_body_probe(probe, wall);
  for (int k = 0; k < 3; ++k) solver.step();
  std::ifstream in(probe);
  std::string line;
  int lines = 0;
  while (std::getline(in, line)) ++lines;
  CHECK(lines == 2 + 1 + 3);  // comment, header, the start and three steps
  CHECK_THROWS_WITH(solver.save_checkpoint("test_contact_solver.ckpt"), Catch::Contains("rigid bodies"));
}
