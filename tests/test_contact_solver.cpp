// Rigid bodies in the Solver (Solver::add_rigid_body): a free sphere striking
// an elastic clamped plate and rebounding, a sphere resting on a plate under
// gravity, momentum exchanged with a free plate, the run's time step, thread
// counts and refused input. The checks are conservation laws and statics,
// computed here from what the solver reports.
#include <sphshell/approx/all.hpp>
#include <sphshell/contact/all.hpp>
#include <sphshell/crack/all.hpp>
#include <sphshell/io/vtu_format.hpp>
#include <sphshell/kernel/all.hpp>
#include <sphshell/material/all.hpp>
#include <sphshell/solver.hpp>
#include <sphshell/thickness/all.hpp>

#include "support/mesh_files.hpp"
#include "support/vtu_reader.hpp"

#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <sstream>
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
  const test_support::ScratchDirectory directory("contact_probe");
  const contact::RigidBodyId wall = solver.add_rigid_body(contact::fixed_wall({0.0, 0.0, -0.01}, Vector3::UnitZ()));
  CHECK_THROWS_WITH(solver.add_rigid_body_probe((directory / "none.csv").string(), wall + 1),
                    Catch::Contains("rigid body id"));
  // A probe file whose folder is a file, and a file another probe has.
  std::ofstream((directory / "not_a_folder").string()) << "x";
  const std::string unwritable = (directory / "not_a_folder" / "wall.csv").string();
  CHECK_THROWS_WITH(solver.add_rigid_body_probe(unwritable, wall), Catch::Contains(unwritable));
  const std::string taken = (directory / "particle.csv").string();
  solver.add_particle_probe(taken, 0);
  CHECK_THROWS_WITH(solver.add_rigid_body_probe(taken, wall),
                    Catch::Contains(taken) && Catch::Contains("already the file of another probe"));
  const std::string probe = (directory / "wall.csv").string();
  solver.add_rigid_body_probe(probe, wall);
  for (int k = 0; k < 3; ++k) solver.step();
  std::ifstream in(probe);
  std::vector<std::string> lines;
  for (std::string line; std::getline(in, line);) lines.push_back(line);
  REQUIRE(lines.size() == 1 + 1 + 3);  // header, the start and three steps
  CHECK(lines.front() ==
        "t [s],x [m],y [m],z [m],vx at t-dt/2 [m/s],vy at t-dt/2 [m/s],vz at t-dt/2 [m/s],fx [N],fy [N],fz [N],"
        "impulse_x [N s],impulse_y [N s],impulse_z [N s],contacts");
  // The last row: the time of the third step and the wall where it was put, untouched.
  std::vector<double> row;
  std::istringstream fields(lines.back());
  for (std::string field; std::getline(fields, field, ',');) row.push_back(std::stod(field));
  REQUIRE(row.size() == 14);
  CHECK(row[0] == solver.time());
  CHECK(row[0] == 3.0 * solver.time_step());
  CHECK(row[1] == 0.0);
  CHECK(row[3] == -0.01);
  CHECK(row[13] == 0.0);
}

namespace {

// The struck clamped plate with friction (so the contact has a tangential history).
contact::PenaltyOptions rough_contact() {
  contact::PenaltyOptions options;
  options.friction_coefficient = 0.3;
  return options;
}

struct ImpactEnd {
  std::vector<Vector3> positions, velocities;
  contact::RigidBodyState sphere;
  EnergyReport energy;
};

ImpactEnd impact_end(const PlateSolver& solver) {
  return {solver.positions(), solver.velocities(), solver.rigid_body(0), solver.energy()};
}

// Bitwise equality of doubles (memcmp: −0 and +0 differ, as a restart must not change either).
bool same_bits(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; }
bool same_bits(const Vector3& a, const Vector3& b) {
  return same_bits(a.x(), b.x()) && same_bits(a.y(), b.y()) && same_bits(a.z(), b.z());
}

}  // namespace

TEST_CASE("a plate struck by a free sphere, checkpointed mid-impact and restarted, ends bit for bit as the whole run",
          "[contact][checkpoint]") {
  const test_support::ScratchDirectory directory("contact_checkpoint");
  const std::string path = (directory.path() / "impact.ckpt").string();
  const ShellModel plate = ShellModel::rectangular_plate(plate_side, plate_side, plate_particles, plate_particles,
                                                         plate_thickness);
  // The sphere strikes after 50 µs; the checkpoint is taken at the first step
  // after 150 µs that ends with the sphere touching the plate.
  constexpr double checkpoint_after = 1.5e-4, end_time = 6e-4;
  const Vector3 strike(0.3 * impact_speed, 0.0, -impact_speed);  // oblique, so friction acts
  PlateSolver whole(plate, steel, plate_options());
  whole.clamp(plate.set("boundary"));
  whole.add_rigid_body(sphere_above_plate(impact_gap, strike), rough_contact());
  whole.run_until(checkpoint_after);
  while (whole.rigid_body(0).contacts == 0 && whole.time() < end_time) whole.step();
  REQUIRE(whole.rigid_body(0).contacts > 0);
  REQUIRE(whole.time() < 0.5 * end_time);
  REQUIRE(whole.energy().friction_dissipation > 0.0);
  const double saved_time = whole.time();
  whole.save_checkpoint(path);
  whole.run_until(end_time);
  const ImpactEnd expected = impact_end(whole);

  PlateSolver restarted(plate, steel, plate_options());
  restarted.clamp(plate.set("boundary"));
  restarted.add_rigid_body(sphere_above_plate(impact_gap, strike), rough_contact());
  restarted.load_checkpoint(path);
  REQUIRE(restarted.time() == saved_time);
  restarted.run_until(end_time);
  const ImpactEnd got = impact_end(restarted);

  REQUIRE(got.positions.size() == expected.positions.size());
  std::size_t differing = 0;
  for (std::size_t i = 0; i < got.positions.size(); ++i)
    differing += same_bits(got.positions[i], expected.positions[i]) && same_bits(got.velocities[i], expected.velocities[i])
                     ? 0
                     : 1;
  CHECK(differing == 0);
  const contact::RigidKinematics& a = got.sphere.kinematics;
  const contact::RigidKinematics& b = expected.sphere.kinematics;
  CHECK(same_bits(a.position, b.position));
  CHECK(same_bits(a.velocity, b.velocity));
  CHECK(same_bits(a.angular_velocity, b.angular_velocity));
  CHECK(a.orientation.coeffs() == b.orientation.coeffs());
  CHECK(same_bits(got.sphere.contact_impulse, expected.sphere.contact_impulse));
  CHECK(same_bits(got.sphere.contact_force, expected.sphere.contact_force));
  CHECK(got.sphere.contacts == expected.sphere.contacts);
  // The sphere turned (friction's moment), so the orientation was a real test.
  CHECK(b.angular_velocity.norm() > 0.0);
  const EnergyReport& e = got.energy;
  const EnergyReport& f = expected.energy;
  CHECK(same_bits(e.kinetic, f.kinetic));
  CHECK(same_bits(e.elastic, f.elastic));
  CHECK(same_bits(e.external_work, f.external_work));
  CHECK(same_bits(e.rigid_body_kinetic, f.rigid_body_kinetic));
  CHECK(same_bits(e.contact_energy, f.contact_energy));
  CHECK(same_bits(e.friction_dissipation, f.friction_dissipation));
  CHECK(same_bits(e.contact_work_on_shell, f.contact_work_on_shell));
  CHECK(same_bits(e.rigid_body_work, f.rigid_body_work));
  CHECK(same_bits(e.balance(), f.balance()));
}

namespace {

std::string file_bytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}
void write_bytes(const std::string& path, const std::string& bytes) {
  std::ofstream(path, std::ios::binary | std::ios::trunc) << bytes;
}

}  // namespace

TEST_CASE("a body probe continues across a restart: its file is byte for byte the uninterrupted run's",
          "[contact][checkpoint][probe]") {
  const test_support::ScratchDirectory directory("contact_probe_restart");
  const ShellModel plate = ShellModel::rectangular_plate(plate_side, plate_side, plate_particles, plate_particles,
                                                         plate_thickness);
  const Vector3 strike(0.3 * impact_speed, 0.0, -impact_speed);
  const auto set_up = [&](PlateSolver& solver) {
    solver.clamp(plate.set("boundary"));
    solver.add_rigid_body(sphere_above_plate(impact_gap, strike), rough_contact());
  };
  const std::string reference_probe = (directory / "reference.csv").string();
  const std::string probe = (directory / "restarted.csv").string();
  const std::string checkpoint = (directory / "run.ckpt").string();
  // The sphere strikes after 50 µs; the checkpoint is taken at the first
  // step after 150 µs that ends in contact, and the first run goes on past
  // it (its rows after the checkpoint are cut off on restart).
  constexpr double checkpoint_after = 1.5e-4, killed_at = 2.2e-4, end_time = 3e-4;
  PlateSolver reference(plate, steel, plate_options());
  set_up(reference);
  reference.add_rigid_body_probe(reference_probe, 0);
  reference.run_until(end_time);
  {
    PlateSolver first(plate, steel, plate_options());
    set_up(first);
    first.add_rigid_body_probe(probe, 0);
    first.run_until(checkpoint_after);
    while (first.rigid_body(0).contacts == 0 && first.time() < killed_at) first.step();
    REQUIRE(first.rigid_body(0).contacts > 0);
    first.save_checkpoint(checkpoint);
    first.run_until(killed_at);
  }
  PlateSolver restarted(plate, steel, plate_options());
  set_up(restarted);
  restarted.load_checkpoint(checkpoint);
  restarted.add_rigid_body_probe(probe, 0);
  restarted.run_until(end_time);
  REQUIRE(restarted.steps() == reference.steps());
  const std::string expected = file_bytes(reference_probe);
  CHECK(std::count(expected.begin(), expected.end(), '\n') == 1 + 1 + reference.steps());  // header, start, steps
  CHECK(file_bytes(probe) == expected);
}

TEST_CASE("a body probe's file is not continued when it was rewritten or is another probe's",
          "[contact][checkpoint][probe][errors]") {
  const test_support::ScratchDirectory directory("contact_probe_refused");
  const ShellModel plate = ShellModel::rectangular_plate(plate_side, plate_side, plate_particles, plate_particles,
                                                         plate_thickness);
  const auto set_up = [&](PlateSolver& solver) {
    solver.add_rigid_body(sphere_above_plate(impact_gap, {0.0, 0.0, -impact_speed}));
    solver.add_rigid_body(contact::fixed_wall({0.0, 0.0, -0.01}, Vector3::UnitZ()));
  };
  const std::string probe = (directory / "sphere.csv").string();
  const std::string checkpoint = (directory / "run.ckpt").string();
  const std::string without_probe = (directory / "no_probe.ckpt").string();
  std::string at_checkpoint, killed;
  {
    PlateSolver run(plate, steel, plate_options());
    set_up(run);
    for (int n = 0; n < 5; ++n) run.step();
    run.save_checkpoint(without_probe);  // as a checkpoint from before body probes were recorded
    run.add_rigid_body_probe(probe, 0);
    for (int n = 0; n < 5; ++n) run.step();
    run.save_checkpoint(checkpoint);
    at_checkpoint = file_bytes(probe);
    for (int n = 0; n < 5; ++n) run.step();
    killed = file_bytes(probe);
  }
  REQUIRE(killed.size() > at_checkpoint.size());
  const auto loaded = [&](const std::string& path) {
    PlateSolver solver(plate, steel, plate_options());
    set_up(solver);
    solver.load_checkpoint(path);
    return solver;
  };
  // Another body's probe, or a particle's, on the recorded file.
  {
    PlateSolver solver = loaded(checkpoint);
    CHECK_THROWS_WITH(solver.add_rigid_body_probe(probe, 1),
                      Catch::Contains("'" + probe + "'") &&
                          Catch::Contains("rigid body probe of rigid body 0, not of rigid body 1"));
    CHECK_THROWS_WITH(solver.add_particle_probe(probe, 60),
                      Catch::Contains("rigid body probe of rigid body 0, not of particle 60"));
    CHECK(file_bytes(probe) == killed);  // refused before the file was touched
  }
  // A row edited since the checkpoint (one digit of the first row), and the file cut short.
  std::string edited = at_checkpoint;
  const std::size_t first_row = edited.find('\n') + 1;
  const std::size_t digit = edited.find_first_of("123456789", first_row);
  REQUIRE(digit < at_checkpoint.size());
  edited[digit] = edited[digit] == '9' ? '8' : static_cast<char>(edited[digit] + 1);
  write_bytes(probe, edited);
  CHECK_THROWS_WITH(loaded(checkpoint).add_rigid_body_probe(probe, 0),
                    Catch::Contains("CSV probe '" + probe + "'") && Catch::Contains("no longer holds the rows"));
  write_bytes(probe, at_checkpoint.substr(0, at_checkpoint.size() - 1));
  CHECK_THROWS_WITH(loaded(checkpoint).add_rigid_body_probe(probe, 0),
                    Catch::Contains("CSV probe '" + probe + "'") && Catch::Contains("fewer than the"));
  // Added before loading: the file starts anew, so its rows are gone.
  write_bytes(probe, killed);
  {
    PlateSolver solver(plate, steel, plate_options());
    set_up(solver);
    solver.add_rigid_body_probe(probe, 0);
    CHECK_THROWS_WITH(solver.load_checkpoint(checkpoint),
                      Catch::Contains("CSV probe '" + probe + "'") && Catch::Contains("add probes after restoring"));
  }
  // The file as the killed run left it: continued, its rows past the checkpoint cut off.
  write_bytes(probe, killed);
  {
    PlateSolver solver = loaded(checkpoint);
    solver.add_rigid_body_probe(probe, 0);
    CHECK(file_bytes(probe) == at_checkpoint);
  }
  // A checkpoint that records no body probe: the probe starts its file (header and the row of now).
  {
    PlateSolver solver = loaded(without_probe);
    solver.add_rigid_body_probe(probe, 0);
    const std::string restarted = file_bytes(probe);
    CHECK(std::count(restarted.begin(), restarted.end(), '\n') == 2);
    CHECK(restarted.rfind("t [s],", 0) == 0);
    CHECK(std::stod(restarted.substr(restarted.find('\n') + 1)) == solver.time());  // the row of the loaded time
    CHECK(solver.time() == 5.0 * solver.time_step());
  }
}

TEST_CASE("a checkpoint whose rigid bodies are not the solver's is refused, naming what differs",
          "[contact][checkpoint]") {
  const test_support::ScratchDirectory directory("contact_checkpoint_refused");
  const std::string path = (directory.path() / "impact.ckpt").string();
  const ShellModel plate = ShellModel::rectangular_plate(plate_side, plate_side, plate_particles, plate_particles,
                                                         plate_thickness);
  {
    PlateSolver saving(plate, steel, plate_options());
    saving.add_rigid_body(sphere_above_plate(impact_gap, {0.0, 0.0, -impact_speed}));
    saving.run_until(1e-4);
    saving.save_checkpoint(path);
  }
  auto refusal = [&](auto&& add_bodies) {
    PlateSolver loading(plate, steel, plate_options());
    add_bodies(loading);
    try {
      loading.load_checkpoint(path);
    } catch (const Error& error) {
      // Refused before anything was loaded: the solver still steps.
      loading.step();
      return std::string(error.what());
    }
    return std::string();
  };
  const std::string none = refusal([](PlateSolver&) {});
  CHECK_THAT(none, Catch::Contains(path) && Catch::Contains("1 rigid bodies and this solver 0"));
  const std::string wall = refusal([](PlateSolver& s) {
    s.add_rigid_body(contact::fixed_wall(Vector3(0.0, 0.0, -0.05), Vector3::UnitZ()));
  });
  CHECK_THAT(wall, Catch::Contains("free sphere") && Catch::Contains("fixed plane"));
  const std::string heavier = refusal([](PlateSolver& s) {
    contact::RigidKinematics start;
    start.position = sphere_above_plate(impact_gap, Vector3::Zero()).position();
    const double inertia = 0.4 * sphere_mass * sphere_radius * sphere_radius;
    s.add_rigid_body(FreeSphere(contact::Sphere(sphere_radius),
                                contact::Free({1.1 * sphere_mass, Vector3::Constant(inertia), Vector3::Zero()}), start));
  });
  CHECK_THAT(heavier, Catch::Contains("rigid body 0") && Catch::Contains("mass"));
  CHECK(refusal([](PlateSolver& s) { s.add_rigid_body(sphere_above_plate(impact_gap, Vector3::Zero())); }).empty());
}

namespace {

// A free 0.1 m square plate, 2 mm thick, lying on a fixed wall (its lower
// face touching it) under gravity: first a normal component g_n, ramped in
// over many contact periods so the plate settles on its contact springs
// without ringing, then a tangential component g_t along x, ramped in after
// it. Coulomb's law for the whole plate: it sticks while g_t < μ g_n (the
// wall then holds it with the tangential force M g_t) and slides otherwise,
// the wall's tangential force being μ times its normal force and the plate
// accelerating at g_t − μ g_n.
constexpr double friction_coefficient = 0.3;
constexpr double normal_gravity = 50.0;  // m/s²
constexpr double normal_ramp = 4e-4, tangential_start = 5e-4, tangential_ramp = 2e-4;
constexpr double measure_from = 1e-3, slide_end = 1.6e-3;

struct SlideRun {
  double mean_ratio = 0.0;          // |F_t| / |F_n| of the wall's reaction, averaged over the window
  double largest_ratio_error = 0.0;  // largest | |F_t|/|F_n| − mean | over the window's steps
  double mean_tangential = 0.0;     // wall's tangential reaction, averaged over the window (N)
  double acceleration = 0.0;        // plate's mean x acceleration over the window (m/s²)
  double largest_speed = 0.0;       // plate's largest mean x speed over the window (m/s)
  double plate_mass = 0.0;
};

SlideRun slide_on_wall(double tangential_gravity) {
  const double thickness = 2e-3;
  const ShellModel plate = ShellModel::rectangular_plate(0.1, 0.1, 9, 9, thickness);
  PlateSolver solver(plate, steel, plate_options());
  contact::PenaltyOptions contact;
  contact.friction_coefficient = friction_coefficient;
  const contact::RigidBodyId wall =
      solver.add_rigid_body(contact::fixed_wall(Vector3(0.0, 0.0, -0.5 * thickness), Vector3::UnitZ()), contact);
  solver.add_gravity(plate.all_particles(), Vector3(0.0, 0.0, -normal_gravity), time_function::Ramp{normal_ramp, 0.0});
  solver.add_gravity(plate.all_particles(), Vector3(tangential_gravity, 0.0, 0.0),
                     time_function::Ramp{tangential_ramp, tangential_start});
  SlideRun run;
  for (const double m : solver.masses()) run.plate_mass += m;
  auto mean_speed = [&](const PlateSolver& s) {
    double momentum = 0.0;
    const std::vector<Vector3> velocity = s.velocities();
    for (std::size_t i = 0; i < velocity.size(); ++i) momentum += s.masses()[i] * velocity[i].x();
    return momentum / run.plate_mass;
  };
  std::vector<double> ratios;
  double tangential_time = 0.0, window = 0.0, speed_at_start = 0.0, time_at_start = 0.0;
  solver.run_until(slide_end, [&](const PlateSolver& s) {
    if (s.time() < measure_from) return;
    const Vector3 force = s.rigid_body(wall).contact_force;
    const double speed = mean_speed(s);
    if (window == 0.0) {
      speed_at_start = speed;
      time_at_start = s.time();
    }
    ratios.push_back(std::hypot(force.x(), force.y()) / std::abs(force.z()));
    tangential_time += s.time_step() * force.x();
    window += s.time_step();
    run.largest_speed = std::max(run.largest_speed, std::abs(speed));
    run.acceleration = (speed - speed_at_start) / std::max(s.time() - time_at_start, s.time_step());
  });
  REQUIRE(!ratios.empty());
  for (const double r : ratios) run.mean_ratio += r / ratios.size();
  for (const double r : ratios) run.largest_ratio_error = std::max(run.largest_ratio_error, std::abs(r - run.mean_ratio));
  run.mean_tangential = tangential_time / window;
  return run;
}

}  // namespace

TEST_CASE("a plate sliding on a wall: the wall's tangential force is mu times its normal force", "[contact]") {
  // Pulled along at twice the sticking limit.
  const double pull = 2.0 * friction_coefficient * normal_gravity;
  const SlideRun slide = slide_on_wall(pull);
  INFO("mean |F_t|/|F_n| " << slide.mean_ratio << " (largest step deviation " << slide.largest_ratio_error
                           << "), plate acceleration " << slide.acceleration << " m/s²");
  CHECK(slide.mean_ratio == Approx(friction_coefficient).epsilon(0.01));
  CHECK(slide.largest_ratio_error < 0.02 * friction_coefficient);
  // Newton for the plate: g_t − μ g_n.
  CHECK(slide.acceleration == Approx(pull - friction_coefficient * normal_gravity).epsilon(0.03));
}

TEST_CASE("a plate pulled below mu g on a wall sticks: the wall holds it with M g_t", "[contact]") {
  const double pull = 0.5 * friction_coefficient * normal_gravity;
  const SlideRun stick = slide_on_wall(pull);
  INFO("mean tangential reaction " << stick.mean_tangential << " N, M g_t " << stick.plate_mass * pull
                                   << " N, largest speed " << stick.largest_speed << " m/s");
  CHECK(stick.mean_tangential == Approx(stick.plate_mass * pull).epsilon(0.01));
  // Were it sliding at μ g_n below the pull it would reach (g_t) × the window's
  // time; stuck, the plate only shakes on its tangential springs.
  CHECK(stick.largest_speed < 0.01 * pull * (slide_end - measure_from));
  CHECK(stick.mean_ratio < friction_coefficient);
}

TEST_CASE("frames draw the rigid bodies: bodies_N.vtu, part 1 of particles.pvd, the body where it is",
          "[contact]") {
  const test_support::ScratchDirectory directory("contact_frames");
  const ShellModel plate = ShellModel::rectangular_plate(plate_side, plate_side, plate_particles, plate_particles,
                                                         plate_thickness);
  SolverOptions options = plate_options();
  options.output_directory = directory.path().string();
  options.output_interval = 2e-4;
  options.frame_encoding = io::VtuEncoding::binary;
  options.frame_precision = io::VtuPrecision::float64;
  PlateSolver solver(plate, steel, options);
  solver.clamp(plate.set("boundary"));
  const contact::RigidBodyId sphere = solver.add_rigid_body(sphere_above_plate(impact_gap, {0.0, 0.0, -20.0}));
  const contact::RigidBodyId wall =
      solver.add_rigid_body(contact::fixed_wall(Vector3(0.0, 0.0, -0.05), Vector3::UnitZ()));
  solver.run_until(6e-4);
  const std::vector<test_support::PvdEntry> entries =
      test_support::read_pvd((directory.path() / "particles.pvd").string());
  std::vector<test_support::PvdEntry> shells, bodies;
  for (const auto& entry : entries) (entry.part == "1" ? bodies : shells).push_back(entry);
  REQUIRE(shells.size() == 4);  // t = 0, 2e-4, 4e-4, 6e-4
  REQUIRE(bodies.size() == shells.size());
  for (std::size_t k = 0; k < bodies.size(); ++k) {
    CHECK(bodies[k].time == shells[k].time);
    CHECK(bodies[k].file == "bodies_" + std::string(5, '0') + std::to_string(k) + ".vtu");
  }
  const test_support::Vtu last = test_support::read_vtu((directory.path() / bodies.back().file).string());
  const contact::SurfaceMesh sphere_mesh = contact::surface_mesh(contact::Sphere(sphere_radius));
  REQUIRE(last.cells() == sphere_mesh.triangles.size() + 2);
  REQUIRE(last.points() == sphere_mesh.vertices.size() + 4);
  const std::vector<double>& body = last.array("CellData", "body").values;
  CHECK(std::count(body.begin(), body.end(), 0.0) == static_cast<long>(sphere_mesh.triangles.size()));
  CHECK(std::count(body.begin(), body.end(), 1.0) == 2);
  // The sphere's vertices lie on the sphere where the run has it now, the wall's on the wall.
  const Vector3 centre = solver.rigid_body(sphere).kinematics.position;
  // It moved (struck the plate and rebounded) since the first frame.
  REQUIRE((centre - sphere_above_plate(impact_gap, Vector3::Zero()).position()).norm() > 5e-4);
  std::vector<double> points;
  for (const auto& array : last.arrays)
    if (array.section == "Points") points = array.values;
  REQUIRE(points.size() == 3 * last.points());
  for (std::size_t p = 0; p < last.points(); ++p) {
    const Vector3 x(points[3 * p], points[3 * p + 1], points[3 * p + 2]);
    if (p < sphere_mesh.vertices.size())
      REQUIRE((x - centre).norm() == Approx(sphere_radius).epsilon(1e-12));
    else
      REQUIRE(x.z() == Approx(solver.rigid_body(wall).kinematics.position.z()).epsilon(1e-12));
  }
}
