// Cost of contact, one thread:
//  - perforation_contact_cost: the plate of examples/sphere_perforation.cpp
//    (51 × 51 particles, 0.71 mm, Johnson–Cook 4340 steel with failure,
//    crack::LineSegments) struck by its 12.7 mm, 8.3 g free sphere at
//    200 m/s, against the same plate without the sphere, both advanced in
//    alternating chunks of steps over the first 60 µs of the impact (the
//    sphere in contact throughout, the plate yielding under it), and against
//    the plate with the same sphere at rest 20 mm above it. Counters:
//    `contact_ratio` is the time per step with the untouching sphere over the
//    time without it: what the contact costs each step over the whole plate
//    (every particle checked against the body, the terms gathered and summed,
//    the body moved, the books); the few particles that touch add a term
//    each. `struck_ratio` is the struck plate's time over the free plate's:
//    that cost plus the plasticity the impact causes (Johnson–Cook return
//    maps under the sphere), an upper bound on what contact adds.
//  - shell_contact_search: the shell's contact with itself on two plates of
//    n × n particles 2 mm apart in spacing, 1.9 mm apart in height (2 mm
//    thick: every particle touches), ShellContact::compute alone (cell list
//    rebuilt, pairs found and weighed, forces): ns per particle at 2 × 71²,
//    2 × 224² and 2 × 708² (about 10⁴, 10⁵ and 10⁶ particles). The counter
//    `pairs_per_particle` is the search's candidate pairs per particle.
// Run single-threaded (OMP_NUM_THREADS=1) for per-step figures.
#include <sphshell/approx/all.hpp>
#include <sphshell/contact/all.hpp>
#include <sphshell/crack/all.hpp>
#include <sphshell/kernel/all.hpp>
#include <sphshell/material/all.hpp>
#include <sphshell/solver.hpp>
#include <sphshell/thickness/all.hpp>

#include <benchmark/benchmark.h>

#include <chrono>
#include <memory>
#include <vector>

using namespace sphshell;

namespace {

using PlateSolver =
    Solver<approx::MLS<kernel::CubicSpline>, thickness::Gauss<5>, material::JohnsonCook, crack::LineSegments>;
using Ball = contact::RigidBody<contact::Sphere, contact::Free>;

// The example's plate and sphere (examples/sphere_perforation.cpp, where the
// constants' sources are given).
constexpr int plate_particles_per_edge = 51;
constexpr double plate_side = 0.1, plate_thickness = 0.71e-3, clamped_radius = 0.05;
constexpr double sphere_radius = 6.35e-3, sphere_mass = 8.3e-3, impact_speed = 200.0;
constexpr double start_gap_per_thickness = 0.05;
constexpr double timed_duration = 6e-5;  // s of the impact timed
constexpr int steps_per_chunk = 10;

material::JohnsonCook::Parameters steel_4340() {
  material::JohnsonCook::Parameters p{};
  p.E = 200e9;
  p.nu = 0.29;
  p.A = 792e6;
  p.B = 510e6;
  p.n = 0.26;
  p.C = 0.014;
  p.reference_strain_rate = 1.0;
  p.m = 1.03;
  p.reference_temperature = 293.0;
  p.melting_temperature = 1793.0;
  p.initial_temperature = 293.0;
  p.taylor_quinney = 0.9;
  p.density = 7830.0;
  p.specific_heat = 477.0;
  p.D1 = -0.80;
  p.D2 = 2.10;
  p.D3 = -0.5;
  p.D4 = 0.002;
  p.D5 = 0.61;
  return p;
}

enum class Sphere { none, striking, apart };
constexpr double apart_height = 0.02;  // m above the plate's face: never touches

std::unique_ptr<PlateSolver> clamped_plate(Sphere sphere) {
  const material::JohnsonCook::Parameters steel = steel_4340();
  SolverOptions options;
  options.density = steel.density;
  options.nonlinear = true;
  options.progress_interval = 0;
  ShellModel model = ShellModel::rectangular_plate(plate_side, plate_side, plate_particles_per_edge,
                                                   plate_particles_per_edge, plate_thickness);
  const Vector3 centre(0.5 * plate_side, 0.5 * plate_side, 0.0);
  model.define_set("clamped", [&](const Vector3& x) { return (x - centre).norm() >= clamped_radius - 1e-9; });
  auto solver = std::make_unique<PlateSolver>(model, steel, options);
  solver->clamp(solver->model().set("clamped"));
  if (sphere != Sphere::none) {
    contact::RigidKinematics start;
    const double gap = sphere == Sphere::striking ? plate_thickness * start_gap_per_thickness : apart_height;
    start.position = centre + Vector3(0.0, 0.0, sphere_radius + 0.5 * plate_thickness + gap);
    start.velocity = Vector3(0.0, 0.0, sphere == Sphere::striking ? -impact_speed : 0.0);
    const double inertia = 0.4 * sphere_mass * sphere_radius * sphere_radius;
    solver->add_rigid_body(Ball(contact::Sphere(sphere_radius),
                                contact::Free({sphere_mass, Vector3::Constant(inertia), Vector3::Zero()}), start));
  }
  return solver;
}

double seconds_for_steps(PlateSolver& solver, int steps) {
  const auto start = std::chrono::steady_clock::now();
  for (int k = 0; k < steps; ++k) solver.step();
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

void perforation_contact_cost(benchmark::State& state) {
  for (auto _ : state) {
    const auto struck_solver = clamped_plate(Sphere::striking);
    const auto apart_solver = clamped_plate(Sphere::apart);
    const auto free_solver = clamped_plate(Sphere::none);
    PlateSolver& struck = *struck_solver;
    PlateSolver& apart = *apart_solver;
    PlateSolver& free_plate = *free_solver;
    double struck_seconds = 0.0, apart_seconds = 0.0, free_seconds = 0.0;
    long steps = 0;
    while (struck.time() < timed_duration) {
      struck_seconds += seconds_for_steps(struck, steps_per_chunk);
      apart_seconds += seconds_for_steps(apart, steps_per_chunk);
      free_seconds += seconds_for_steps(free_plate, steps_per_chunk);
      steps += steps_per_chunk;
    }
    const double per_particle_step = 1e9 / double(steps) / double(struck.particle_count());
    state.SetIterationTime(apart_seconds / double(steps));
    state.counters["contact_ratio"] = apart_seconds / free_seconds;
    state.counters["struck_ratio"] = struck_seconds / free_seconds;
    state.counters["free_ns_per_particle_step"] = free_seconds * per_particle_step;
    state.counters["apart_ns_per_particle_step"] = apart_seconds * per_particle_step;
    state.counters["struck_ns_per_particle_step"] = struck_seconds * per_particle_step;
    state.counters["sphere_speed"] = -struck.rigid_body(contact::RigidBodyId{0}).kinematics.velocity.z();
    state.counters["steps"] = double(steps);
  }
}
BENCHMARK(perforation_contact_cost)->UseManualTime()->Unit(benchmark::kMillisecond)->Iterations(1)->Repetitions(3);

// Two n × n plates (spacing 2 mm, 2 mm thick) 1.9 mm apart, directors +z.
ShellModel touching_plates(int n) {
  constexpr double spacing = 2e-3, gap = 1.9e-3, thickness = 2e-3;
  std::vector<Vector3> positions, normals;
  std::vector<Quad> quads;
  for (int plate = 0; plate < 2; ++plate) {
    const int base = plate * n * n;
    for (int i = 0; i < n; ++i)
      for (int j = 0; j < n; ++j) {
        positions.emplace_back(i * spacing, j * spacing, plate * gap);
        normals.push_back(Vector3::UnitZ());
      }
    for (int i = 0; i + 1 < n; ++i)
      for (int j = 0; j + 1 < n; ++j)
        quads.push_back({base + i * n + j, base + (i + 1) * n + j, base + (i + 1) * n + j + 1, base + i * n + j + 1});
  }
  return ShellModel::from_quads(positions, normals, quads, thickness);
}

// One size's contact: the model, the particles at rest in it, the contact.
struct TouchingPlates {
  static constexpr double steel_density = 7850.0, time_step = 1e-7;
  ShellModel model;
  std::vector<Vector3> velocity, angular_velocity;
  std::vector<double> mass, thickness;
  contact::ShellContact contact;
  contact::ParticleContactLoads loads;

  explicit TouchingPlates(int n)
      : model(touching_plates(n)),
        velocity(model.particle_count(), Vector3::Zero()),
        angular_velocity(model.particle_count(), Vector3::Zero()),
        thickness(model.particle_thicknesses()),
        contact(model, {}) {
    for (std::size_t i = 0; i < model.particle_count(); ++i)
      mass.push_back(steel_density * model.particle_area[i] * thickness[i]);
    // Untimed first two calls: they size the pair stores (this step's and the
    // last step's, which swap at every call) and the loads, first touching
    // their pages, which a run's later steps reuse.
    compute();
    compute();
  }
  std::size_t size() const { return model.particle_count(); }
  void compute() {
    const contact::ContactParticles particles{model.particle_position, model.particle_normal, velocity,
                                              angular_velocity, mass, thickness};
    contact.compute(particles, time_step, loads);
    benchmark::DoNotOptimize(loads.force.data());
  }
};

void shell_contact_search(benchmark::State& state) {
  TouchingPlates plates(int(state.range(0)));
  for (auto _ : state) plates.compute();
  state.counters["ns_per_particle"] = benchmark::Counter(
      double(plates.size()) * 1e-9, benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kInvert);
  state.counters["particles"] = double(plates.size());
  state.counters["pairs_per_particle"] =
      double(plates.contact.statistics().candidate_pairs) / double(plates.size());
}
BENCHMARK(shell_contact_search)->Arg(71)->Arg(224)->Arg(708)->Unit(benchmark::kMillisecond);

// The growth of the cost per particle from 2 × 71² to 2 × 708² particles,
// both sizes advanced in alternating rounds (100 evaluations of the small,
// one of the large: about the same time each) so that a change of machine
// load hits both alike. `growth` is the large size's time per particle over
// the small size's.
void shell_contact_scaling(benchmark::State& state) {
  constexpr int rounds = 20, small_per_round = 100;
  TouchingPlates small(71), large(708);
  for (auto _ : state) {
    double small_seconds = 0.0, large_seconds = 0.0;
    for (int round = 0; round < rounds; ++round) {
      auto start = std::chrono::steady_clock::now();
      for (int k = 0; k < small_per_round; ++k) small.compute();
      small_seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      start = std::chrono::steady_clock::now();
      large.compute();
      large_seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    }
    const double small_per_particle = small_seconds / (rounds * small_per_round) / double(small.size());
    const double large_per_particle = large_seconds / rounds / double(large.size());
    state.SetIterationTime(large_seconds / rounds);
    state.counters["growth"] = large_per_particle / small_per_particle;
    state.counters["small_ns_per_particle"] = 1e9 * small_per_particle;
    state.counters["large_ns_per_particle"] = 1e9 * large_per_particle;
  }
}
BENCHMARK(shell_contact_scaling)->UseManualTime()->Unit(benchmark::kMillisecond)->Iterations(1)->Repetitions(3);

}  // namespace

BENCHMARK_MAIN();
