// The solver's seams: a user stepper as the fifth template parameter, the
// load context's mass and moment channels (gravity, applied moments) against
// closed forms, the parallel loop's deterministic error rule, and the grouped
// options.
#include <sphshell/approx/all.hpp>
#include <sphshell/crack/all.hpp>
#include <sphshell/kernel/all.hpp>
#include <sphshell/material/all.hpp>
#include <sphshell/shell/spherical_cap_ogrid.hpp>
#include <sphshell/solver.hpp>
#include <sphshell/thickness/all.hpp>

#include "support/relaxation.hpp"

#include <catch2/catch.hpp>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdint>
#include <cmath>
#include <memory>
#include <new>
#include <sstream>
#include <stdexcept>
#include <string>
#include <thread>
#include <utility>
#include <vector>

using namespace sphshell;

namespace {

// Counts the particles it updates and otherwise steps exactly as the central
// difference. The solver calls it on chunks of particles from several threads
// at once, so the counts are atomic (shared by copies of the stepper).
struct CountingStepper : stepper::CentralDifference {
  std::shared_ptr<std::atomic<long>> velocity_updates = std::make_shared<std::atomic<long>>(0);
  std::shared_ptr<std::atomic<long>> configuration_updates = std::make_shared<std::atomic<long>>(0);
  void advance_velocities(const stepper::StepContext& context, solver::ParticleState& state,
                          const solver::Inertia& inertia, const solver::ParticleForces& forces, std::size_t first,
                          std::size_t last) {
    *velocity_updates += static_cast<long>(last - first);
    CentralDifference::advance_velocities(context, state, inertia, forces, first, last);
  }
  void advance_configuration(const stepper::StepContext& context, solver::ParticleState& state, std::size_t first,
                             std::size_t last) {
    *configuration_updates += static_cast<long>(last - first);
    CentralDifference::advance_configuration(context, state, first, last);
  }
};

// Never moves anything: a solver that uses it must stay in the reference configuration.
struct FrozenStepper {
  double velocity_step(long, double time_step) const { return time_step; }
  void advance_velocities(const stepper::StepContext&, solver::ParticleState&, const solver::Inertia&,
                          const solver::ParticleForces&, std::size_t, std::size_t) {}
  void advance_configuration(const stepper::StepContext&, solver::ParticleState&, std::size_t, std::size_t) {}
};

struct NotAStepper {
  void advance_velocities() {}
};

static_assert(stepper::is_stepper_v<stepper::CentralDifference>);
static_assert(stepper::is_stepper_v<CountingStepper> && stepper::is_stepper_v<FrozenStepper>);
static_assert(!stepper::is_stepper_v<NotAStepper> && !stepper::is_stepper_v<int>);

template <class Stepper>
using PlateSolver = Solver<approx::MLS<kernel::CubicSpline>, thickness::Gauss<3>, material::Elastic, crack::None,
                           Stepper>;

template <class Stepper>
PlateSolver<Stepper> loaded_plate() {
  PlateSolver<Stepper> solver(ShellModel::rectangular_plate(0.2, 0.2, 9, 9, 0.01), {210e9, 0.3});
  solver.clamp(solver.model().set("boundary"));
  solver.add_uniform_pressure(solver.model().all_particles(), 1e6);
  return solver;
}

}  // namespace

TEST_CASE("A user stepper passed as the fifth parameter advances the solver", "[solver][stepper]") {
  auto counted = loaded_plate<CountingStepper>();
  auto reference = loaded_plate<stepper::CentralDifference>();
  const long steps = 37;
  for (long n = 0; n < steps; ++n) {
    counted.step();
    reference.step();
  }
  // Every particle once per step.
  const long particles = static_cast<long>(counted.particle_count());
  CHECK(*counted.integrator().velocity_updates == steps * particles);
  CHECK(*counted.integrator().configuration_updates == steps * particles);
  // The counting stepper steps as the default one: the same state, bit for bit.
  const int centre = counted.model().nearest_particle(Vector3(0.1, 0.1, 0.0));
  CHECK(counted.displacement(centre).z() != 0.0);
  for (std::size_t i = 0; i < counted.particle_count(); ++i) {
    CHECK(counted.positions()[i] == reference.positions()[i]);
    CHECK(counted.directors()[i] == reference.directors()[i]);
  }

  auto frozen = loaded_plate<FrozenStepper>();
  frozen.run_until(20 * frozen.time_step());
  for (std::size_t i = 0; i < frozen.particle_count(); ++i)
    CHECK(frozen.displacement(static_cast<int>(i)).norm() == 0.0);
}

TEST_CASE("Gravity acts on each particle's mass: a free plate falls as x = g t²/2", "[solver][loads]") {
  Solver<approx::MLS<kernel::CubicSpline>, thickness::Gauss<3>, material::Elastic> solver(
      ShellModel::rectangular_plate(0.2, 0.1, 9, 5, 0.01), {210e9, 0.3});
  const Vector3 g(0.0, 0.0, -9.81);
  solver.add_gravity(solver.model().all_particles(), g);
  solver.run_until(200 * solver.time_step());
  const double t = solver.time();
  // The central difference integrates a constant acceleration exactly, and a
  // rigid translation strains nothing.
  for (std::size_t i = 0; i < solver.particle_count(); ++i)
    CHECK(solver.displacement(static_cast<int>(i)).z() == Approx(0.5 * g.z() * t * t).epsilon(1e-12));
  const EnergyReport energy = solver.energy();
  double mass = 0.0;
  for (double m : solver.masses()) mass += m;
  // The ledger books the work up to the half step where the leapfrog's
  // velocities live: m |g|² (t − Δt/2)²/2, exactly for a constant force.
  const double half_step_back = t - 0.5 * solver.time_step();
  CHECK(energy.external_work == Approx(mass * 0.5 * g.squaredNorm() * half_step_back * half_step_back).epsilon(1e-9));
  CHECK(energy.kinetic == Approx(energy.external_work).epsilon(1e-9));
  CHECK(std::abs(energy.balance()) < 1e-9 * energy.external_work);
}

TEST_CASE("add_uniform_pressure gives the same bits as add_pressure with the same function on any thread count", "[solver][loads]") {
  // add_uniform_pressure evaluates its time function once per step and shares
  // its loop among the threads; add_pressure calls p(X, t) for every particle
  // on one thread. The forces, and so every position, must be the same bits.
  using PlateSolver = Solver<approx::MLS<kernel::CubicSpline>, thickness::Gauss<3>, material::Elastic>;
  const ShellModel plate = ShellModel::rectangular_plate(0.3, 0.2, 31, 21, 0.004);
  const time_function::Ramp ramp{2e-5, 1e-6};
  for (const PressureDirection direction : {PressureDirection::follower, PressureDirection::fixed}) {
    PlateSolver uniform(plate, {70e9, 0.3}), general(plate, {70e9, 0.3});
    for (PlateSolver* solver : {&uniform, &general}) solver->clamp(solver->model().set("boundary"));
    uniform.add_uniform_pressure(uniform.model().all_particles(), 4e5, ramp, direction);
    general.add_pressure(
        general.model().all_particles(), [ramp](const Vector3&, double t) { return 4e5 * ramp(t); }, direction);
    for (const int threads : {2, 1, 3}) {
#ifdef _OPENMP
      omp_set_num_threads(threads);
#endif
      for (int k = 0; k < 15; ++k) {
        uniform.step();
        general.step();
      }
    }
#ifdef _OPENMP
    omp_set_num_threads(1);
#endif
    std::size_t differing = 0;
    for (std::size_t i = 0; i < uniform.particle_count(); ++i)
      differing += uniform.positions()[i] == general.positions()[i] ? 0 : 1;
    CHECK(differing == 0);
    // The load has acted: the plate's centre moved against the normal.
    const int centre = 15 * 21 + 10;
    CHECK(uniform.displacement(centre).z() < -1e-9);
  }
}

TEST_CASE("The loads' single pass adds each load in turn on any thread count and reports the lowest bad particle", "[solver][loads]") {
  // ExternalLoads zeroes, adds every load and checks one range of particles
  // at a time. Against the sums written here, particle by particle in the
  // order the loads were added (the same additions, so the same bits): sets
  // unsorted and partial, a serial p(X, t) between parallel loads or none;
  // on 1, 2 and 3 threads, and each load applied to two ranges split at
  // chosen places (without threads too). User code (p(X, t), time
  // functions) runs on the calling thread only.
  constexpr std::size_t n = 3001;
  std::vector<Vector3> position(n), normal(n), director(n), force(n), moment(n);
  std::vector<double> area(n), mass(n);
  for (std::size_t i = 0; i < n; ++i) {
    const double x = 0.001 * static_cast<double>(i);
    position[i] = Vector3(x, std::sin(x), 0.0);
    normal[i] = Vector3(0.0, 0.0, 1.0);
    director[i] = Vector3(0.1 * std::sin(3 * x), 0.2 * std::cos(5 * x), 1.0).normalized();
    area[i] = 1e-4 * (1.0 + 0.3 * std::cos(7 * x));
    mass[i] = 0.02 * (1.0 + 0.2 * std::sin(11 * x));
  }
  std::vector<int> all(n), even_backwards, tail;
  for (std::size_t i = 0; i < n; ++i) all[i] = static_cast<int>(n - 1 - i);
  for (int i = static_cast<int>(n) - 1; i >= 0; i -= 2) even_backwards.push_back(i);
  for (int i = 2000; i < static_cast<int>(n); ++i) tail.push_back(i);
  const time_function::Ramp ramp{2e-5, 1e-6};
  const double t = 7.3e-6, pressure = 3.1e5;
  const Vector3 point_force(1.5, -2.25, 0.75), point_moment(0.0, 0.3, -0.1), gravity(0.0, 0.0, -9.81);
  const std::thread::id caller = std::this_thread::get_id();
  std::atomic<int> calls_elsewhere{0};
  const auto pressure_at = [caller, &calls_elsewhere](const Vector3& X, double time) {
    if (std::this_thread::get_id() != caller) ++calls_elsewhere;
    return 2e5 * (1.0 + X.x()) * time * 1e5;
  };
  const auto watched_ramp = [caller, &calls_elsewhere, ramp](double time) {
    if (std::this_thread::get_id() != caller) ++calls_elsewhere;
    return ramp(time);
  };
  const StepTime at{12, t};

  for (const bool with_serial : {false, true}) {
    const auto make_loads = [&] {
      std::vector<std::unique_ptr<detail::Load>> made;
      made.push_back(std::make_unique<detail::UniformPressureLoad<time_function::Ramp>>(all, pressure, ramp,
                                                                                         PressureDirection::follower));
      made.push_back(
          std::make_unique<detail::PointForceLoad<decltype(watched_ramp)>>(even_backwards, point_force, watched_ramp));
      if (with_serial)
        made.push_back(std::make_unique<detail::PressureLoad<decltype(pressure_at)>>(tail, pressure_at,
                                                                                     PressureDirection::fixed));
      made.push_back(std::make_unique<detail::GravityLoad<time_function::Ramp>>(tail, gravity, ramp));
      made.push_back(
          std::make_unique<detail::PointMomentLoad<time_function::Ramp>>(even_backwards, point_moment, ramp));
      return made;
    };
    ExternalLoads loads;
    for (auto& load : make_loads()) loads.add(std::move(load));

    // The expected sums, one particle at a time.
    const double f = ramp(t);
    std::vector<Vector3> expected_force(n, Vector3::Zero()), expected_moment(n, Vector3::Zero());
    for (std::size_t i = 0; i < n; ++i) {
      const bool even = i % 2 == 0, in_tail = i >= 2000;  // n − 1 = 3000: even_backwards holds the even indices
      expected_force[i] -= (pressure * f) * area[i] * director[i];
      if (even) expected_force[i] += f * point_force;
      if (with_serial && in_tail) expected_force[i] -= pressure_at(position[i], t) * area[i] * normal[i];
      if (in_tail) expected_force[i] += mass[i] * (f * gravity);
      if (even) expected_moment[i] += f * point_moment;
    }
    for (const int threads : {1, 2, 3}) {
#ifdef _OPENMP
      omp_set_num_threads(threads);
#endif
      std::fill(force.begin(), force.end(), Vector3::Constant(7.0));  // stale values must be zeroed
      std::fill(moment.begin(), moment.end(), Vector3::Constant(7.0));
      detail::LoadContext context{t, position, normal, director, area, mass, force, moment};
      loads.apply(at, context);
      std::size_t differing = 0;
      for (std::size_t i = 0; i < n; ++i)
        differing += force[i] == expected_force[i] && moment[i] == expected_moment[i] ? 0 : 1;
      INFO("threads " << threads << ", serial load " << with_serial);
      CHECK(differing == 0);
    }
#ifdef _OPENMP
    omp_set_num_threads(1);
#endif
    // Each load on [0, k) and then [k, n): the sets' ends, range ends on and
    // beside a member, and the empty ranges.
    const std::vector<std::unique_ptr<detail::Load>> parts = make_loads();
    for (const std::size_t k : {std::size_t{0}, std::size_t{1}, std::size_t{1000}, std::size_t{1001},
                                std::size_t{2000}, std::size_t{2001}, n - 1, n}) {
      std::fill(force.begin(), force.end(), Vector3::Zero());
      std::fill(moment.begin(), moment.end(), Vector3::Zero());
      detail::LoadContext context{t, position, normal, director, area, mass, force, moment};
      for (const auto& load : parts) {
        const double factor = load->factor(t);
        load->apply(context, factor, 0, k);
        load->apply(context, factor, k, n);
      }
      std::size_t differing = 0;
      for (std::size_t i = 0; i < n; ++i)
        differing += force[i] == expected_force[i] && moment[i] == expected_moment[i] ? 0 : 1;
      INFO("split at " << k << ", serial load " << with_serial);
      CHECK(differing == 0);
    }
  }
  CHECK(calls_elsewhere == 0);

  // A non-finite load stops the step, naming the lowest particle it reached.
  const auto nan_after = [](double time) { return time > 5e-6 ? std::nan("") : 1.0; };
  for (const int threads : {1, 2, 3}) {
#ifdef _OPENMP
    omp_set_num_threads(threads);
#endif
    ExternalLoads loads;
    loads.add(std::make_unique<detail::GravityLoad<time_function::Ramp>>(all, gravity, ramp));
    loads.add(std::make_unique<detail::PointForceLoad<decltype(nan_after)>>(std::vector<int>{2900, 1777, 601, 2400},
                                                                            point_force, nan_after));
    detail::LoadContext context{t, position, normal, director, area, mass, force, moment};
    INFO("threads " << threads);
    CHECK_THROWS_WITH(loads.apply(at, context),
                      Catch::Contains("step 12") && Catch::Contains("non-finite external load at particle 601 "));
  }
#ifdef _OPENMP
  omp_set_num_threads(1);
#endif
}

TEST_CASE("An end moment bends a cantilever strip uniformly: tip rotation ML/EI", "[solver][loads]") {
  // Linear, ν = 0 (the strip bends like a beam), static by dynamic relaxation.
  const double L = 0.5, width = 0.1, d = 0.02, E = 210e9, rho = 7850;
  const double EI = E * width * d * d * d / 12.0;
  const double omega = 3.516 * std::sqrt(EI / (rho * width * d)) / (L * L);
  SolverOptions options;
  options.nonlinear = false;
  options.density = rho;
  options.damping = 1.5 * omega;
  options.rotary_inertia_scale = 4.0;
  Solver<approx::MLS<kernel::CubicSpline>, thickness::Gauss<3>, material::Elastic> solver(
      ShellModel::rectangular_plate(L, width, 21, 5, d), {E, 0.0}, options);
  const ShellModel& model = solver.model();
  solver.clamp(model.set("x_min"));
  const ParticleSet& tip = model.set("x_max");
  // A moment about +y turns the x-directed strip's director from +z toward
  // +x, so the tip deflects downward (−z), w = −ML²/(2EI).
  const double M = 0.05 * EI / L;  // tip rotation 0.05 rad
  solver.add_point_moment(tip, Vector3(0.0, M / tip.size(), 0.0));
  double rotation = 0.0, deflection = 0.0;
  auto read_tip = [&] {
    rotation = 0.0;
    deflection = 0.0;
    for (int i : tip) {
      rotation += solver.rotation(i).y() / tip.size();
      deflection += solver.displacement(i).z() / tip.size();
    }
  };
  // The damping 1.5 ω takes every mode down by a factor 9e-3 per period of the
  // first: relaxed period by period until the tip rotation moves by less than
  // 1e-9 of itself over one (about 6 periods; 12 at most).
  const double period = 2 * M_PI / omega;
  test_support::relax_until_settled(solver, period, 12, 1e-9, [&] {
    read_tip();
    return rotation;
  });
  INFO("tip rotation " << rotation << " rad (ML/EI = " << M * L / EI << "), deflection " << deflection
                       << " m (-ML^2/2EI = " << -M * L * L / (2 * EI) << ")");
  CHECK(rotation == Approx(M * L / EI).epsilon(0.02));
  CHECK(deflection == Approx(-M * L * L / (2.0 * EI)).epsilon(0.02));
}

TEST_CASE("parallel::for_each rethrows the lowest failing index's error for any thread count", "[core][parallel]") {
  for (int threads : {1, 2, 4}) {
#ifdef _OPENMP
    omp_set_num_threads(threads);
#endif
    INFO(threads << " threads");
    std::vector<int> visited(1000, 0);
    std::string caught;
    std::size_t failing = 0;
    try {
      parallel::for_each(
          std::size_t{0}, visited.size(),
          [&](std::size_t i) {
            visited[i] = 1;
            if (i % 97 == 13) throw std::runtime_error("index " + std::to_string(i));
          },
          [&](std::size_t i, const std::exception_ptr& error) {
            failing = i;
            caught = parallel::what(error);
          });
    } catch (const std::runtime_error& error) {
      CHECK(std::string(error.what()) == "index 13");
    }
    CHECK(failing == 13);
    CHECK(caught == "index 13");
    // Every index still ran: a failure does not leave the region early.
    int count = 0;
    for (int v : visited) count += v;
    CHECK(count == 1000);
    // A noexcept body runs without the bookkeeping and visits every index once.
    std::vector<double> squares(1000);
    parallel::for_each(std::size_t{0}, squares.size(), [&](std::size_t i) noexcept { squares[i] = double(i) * i; });
    CHECK(squares[999] == 998001.0);
  }
#ifdef _OPENMP
  omp_set_num_threads(1);
#endif
}

TEST_CASE("parallel::for_each visits every index once, nested and repeated, with any spin time", "[core][parallel]") {
  const std::chrono::nanoseconds default_spin = parallel::spin_time();
  CHECK(default_spin == std::chrono::microseconds(50));
  for (std::chrono::nanoseconds spin : {std::chrono::nanoseconds(0), std::chrono::nanoseconds(20'000)}) {
    parallel::set_spin_time(spin);
    for (int threads : {1, 2, 3}) {
#ifdef _OPENMP
      omp_set_num_threads(threads);
#endif
      INFO(threads << " threads, spin " << spin.count() << " ns");
      // Many short loops in a row (the team is woken and parked over and
      // over), of sizes below, at and above a task's: each index once.
      bool all_once = true;
      for (int repeat = 0; repeat < 400; ++repeat) {
        const std::size_t n = 1 + static_cast<std::size_t>(repeat * 37 % 1500);
        std::vector<int> visits(n, 0);
        parallel::for_each(std::size_t{0}, n, [&](std::size_t i) noexcept { ++visits[i]; });
        for (int v : visits) all_once = all_once && v == 1;
      }
      CHECK(all_once);
      // A loop started inside a body runs serially on that thread, and an
      // index range that does not start at 0 is visited as given.
      std::vector<long> inner_sums(200, 0);
      parallel::for_each(100, 300, [&](int i) noexcept {
        long sum = 0;
        parallel::for_each(0, i, [&](int j) noexcept { sum += j; });
        inner_sums[static_cast<std::size_t>(i - 100)] = sum;
      });
      bool sums_right = true;
      for (int i = 100; i < 300; ++i) sums_right = sums_right && inner_sums[static_cast<std::size_t>(i - 100)] == long(i) * (i - 1) / 2;
      CHECK(sums_right);
    }
  }
  parallel::set_spin_time(default_spin);
  CHECK_THROWS_AS(parallel::set_spin_time(std::chrono::nanoseconds(-1)), Error);
  CHECK(parallel::spin_time() == default_spin);
#ifdef _OPENMP
  omp_set_num_threads(1);
#endif
}

TEST_CASE("parallel::for_each gives each thread one contiguous block, not indices in turn", "[core][parallel]") {
  // The cache affinity that makes two threads faster than one: the worker of a
  // two-thread team runs one contiguous range of a loop (its block, less what
  // the caller took from the block's back), whichever thread ran faster.
#ifndef _OPENMP
  // Not a pass: tests/CMakeLists.txt has ctest report this case as skipped.
  WARN("SKIPPED: built without OpenMP, the loops run on one thread and there is no worker to check");
#else
  omp_set_num_threads(2);
  constexpr std::size_t n = 20000;
  std::vector<std::thread::id> runner(n);
  std::vector<double> values(n, 1.0);
  int loops_with_worker = 0;
  bool contiguous = true;
  for (int repeat = 0; repeat < 200; ++repeat) {
    const std::thread::id caller = std::this_thread::get_id();
    parallel::for_each(std::size_t{0}, n, [&](std::size_t i) noexcept {
      double x = values[i];
      for (int k = 0; k < 20; ++k) x = std::sqrt(x + 1.0);
      values[i] = x;
      runner[i] = std::this_thread::get_id();
    });
    std::size_t first = n, last = 0, count = 0;
    for (std::size_t i = 0; i < n; ++i)
      if (runner[i] != caller) {
        first = std::min(first, i);
        last = i;
        ++count;
      }
    if (count == 0) continue;
    ++loops_with_worker;
    contiguous = contiguous && count == last - first + 1;
  }
  INFO("the worker joined " << loops_with_worker << " of 200 loops");
  CHECK(loops_with_worker > 0);
  CHECK(contiguous);
  omp_set_num_threads(1);
#endif
}

TEST_CASE("A plate's step is bitwise the same on 1, 2 and 3 threads", "[core][parallel]") {
  std::vector<std::vector<Vector3>> positions, directors;
  for (int threads : {1, 2, 3}) {
#ifdef _OPENMP
    omp_set_num_threads(threads);
#endif
    auto solver = loaded_plate<stepper::CentralDifference>();
    solver.run_until(60 * solver.time_step());
    positions.push_back(solver.positions());
    directors.push_back(solver.directors());
  }
#ifdef _OPENMP
  omp_set_num_threads(1);
#endif
  CHECK(positions[0][40].z() != 0.0);
  for (std::size_t run = 1; run < positions.size(); ++run) {
    CHECK(positions[run] == positions[0]);
    CHECK(directors[run] == directors[0]);
  }
}

namespace {
// Steps as the central difference, then makes four particles' positions NaN
// from step 3 on (a blow-up the solver must report); 301 and 310 share a chunk.
struct PoisonStepper : stepper::CentralDifference {
  static constexpr long first_poisoned_step = 3;
  void advance_configuration(const stepper::StepContext& context, solver::ParticleState& state, std::size_t first,
                             std::size_t last) {
    CentralDifference::advance_configuration(context, state, first, last);
    if (context.at.step < first_poisoned_step) return;
    for (const std::size_t i : {std::size_t{1200}, std::size_t{700}, std::size_t{310}, std::size_t{301}})
      if (first <= i && i < last) state.position[i].x() = std::nan("");
  }
};
}  // namespace

TEST_CASE("A step's particle pass reports failures as its parts one after the other would, on any thread count",
          "[solver][parallel][errors]") {
  // 41 × 31 = 1271 particles: five chunks of the pass, on 1, 2 and 3 threads.
  const ShellModel plate = ShellModel::rectangular_plate(0.4, 0.3, 41, 31, 0.004);
  REQUIRE(plate.particle_count() > 4 * solver::ParticleEnergyTerms::sum_chunk);
  using Plate = Solver<approx::MLS<kernel::CubicSpline>, thickness::Gauss<3>, material::Elastic>;
  using PoisonedPlate =
      Solver<approx::MLS<kernel::CubicSpline>, thickness::Gauss<3>, material::Elastic, crack::None, PoisonStepper>;
  const double nan = std::nan("");
  for (const int threads : {1, 2, 3}) {
#ifdef _OPENMP
    omp_set_num_threads(threads);
#endif
    INFO("threads " << threads);
    // Step 3 is the first whose loads (at the step's start, 3 Δt) and
    // prescribed velocities (at its middle, 3.5 Δt) are taken past 2.75 Δt.
    const auto failing_after = [](double time_step) { return 2.75 * time_step; };

    // A non-finite state: the lowest particle (not the last of its chunk), at the step's end.
    {
      PoisonedPlate solver(plate, {70e9, 0.3});
      solver.clamp(solver.model().set("boundary"));
      for (int n = 0; n < PoisonStepper::first_poisoned_step; ++n) solver.step();
      CHECK_THROWS_WITH(solver.step(), Catch::Contains("unstable at step 4,") &&
                                           Catch::Contains("non-finite state at particle 301 "));
    }
    // A prescribed motion that is not finite: the first condition in the
    // order they were added (1200, not the lowest particle), at the step's
    // start; it comes before the non-finite state it leaves.
    {
      PoisonedPlate solver(plate, {70e9, 0.3});
      const double after = failing_after(solver.time_step());
      solver.prescribe_velocity({1200, 700, 301}, [after, nan](const Vector3&, double t) {
        return t > after ? Vector3(nan, 0.0, 0.0) : Vector3::Zero();
      });
      for (int n = 0; n < 3; ++n) solver.step();
      CHECK_THROWS_WITH(solver.step(), Catch::Contains("unstable at step 3,") &&
                                           Catch::Contains("prescribed motion of particle 1200 is not finite"));
    }
    // A non-finite load: the lowest particle (640 and 650 share a chunk),
    // before the failing motion.
    {
      Plate solver(plate, {70e9, 0.3});
      const double after = failing_after(solver.time_step());
      solver.prescribe_velocity({1200, 700, 301}, [after, nan](const Vector3&, double t) {
        return t > after ? Vector3(nan, 0.0, 0.0) : Vector3::Zero();
      });
      solver.add_point_force({1250, 650, 640, 900}, Vector3(0.0, 0.0, 1.0),
                             [after, nan](double t) { return t > after ? nan : 1.0; });
      for (int n = 0; n < 3; ++n) solver.step();
      CHECK_THROWS_WITH(solver.step(), Catch::Contains("unstable at step 3,") &&
                                           Catch::Contains("non-finite external load at particle 640 "));
    }
  }
#ifdef _OPENMP
  omp_set_num_threads(1);
#endif
}

TEST_CASE("The energy books are the same on 1, 2 and 3 threads and add up every particle", "[core][parallel]") {
  // EnergyLedger::book_chunk adds the particles' terms in chunks of
  // ParticleEnergyTerms::sum_chunk on the threads; 31 × 21 particles make
  // three chunks, the last one short.
  const ShellModel plate = ShellModel::rectangular_plate(0.3, 0.2, 31, 21, 0.004);
  REQUIRE(plate.particle_count() > 2 * solver::ParticleEnergyTerms::sum_chunk);
  std::vector<EnergyReport> reports;
  for (const int threads : {1, 2, 3}) {
#ifdef _OPENMP
    omp_set_num_threads(threads);
#endif
    Solver<approx::MLS<kernel::CubicSpline>, thickness::Gauss<3>, material::Elastic> solver(plate, {70e9, 0.3});
    solver.clamp(solver.model().set("boundary"));
    solver.add_uniform_pressure(solver.model().all_particles(), 3e5);
    solver.run_until(30 * solver.time_step());
    reports.push_back(solver.energy());
    // The kinetic energy at the last half step, summed here particle by particle.
    double kinetic = 0.0;
    for (std::size_t i = 0; i < solver.particle_count(); ++i)
      kinetic += 0.5 * solver.masses()[i] * solver.velocities()[i].squaredNorm() +
                 0.5 * solver.rotary_inertias()[i] * solver.angular_velocities()[i].squaredNorm();
    CHECK(kinetic > 0.0);
    CHECK(std::abs(reports.back().kinetic - kinetic) <= 1e-13 * kinetic);
  }
#ifdef _OPENMP
  omp_set_num_threads(1);
#endif
  for (std::size_t run = 1; run < reports.size(); ++run) {
    CHECK(reports[run].kinetic == reports[0].kinetic);
    CHECK(reports[run].external_work == reports[0].external_work);
    CHECK(reports[run].damping_work == reports[0].damping_work);
    CHECK(reports[run].internal == reports[0].internal);
    CHECK(reports[run].elastic == reports[0].elastic);
  }
}

TEST_CASE("A sum over the points adds fixed chunks of rows in order, on any thread count, before and after a force pass",
          "[solver][parallel]") {
  // InternalForceAssembler::sum_over_points (the energy books) adds 64 rows
  // of one group at a time, each chunk in row order, the stress points'
  // chunks first, then the chunks' sums as detail::interleaved_sum does. The
  // same order written out here must give the same bits whether the chunks
  // follow the force pass's segments (after compute()) or are tasks of their own
  // (before it), on 1, 2 and 3 threads; and the force pass's own sum of its
  // points' work (internal_work()) likewise. The 111 × 87 plate's groups are no
  // multiple of 64 rows, and on two threads the force pass's runs would be
  // 149 rows long if they were not cut to whole chunks.
  const SolverOptions options;
  const ShellModel plate = ShellModel::rectangular_plate(0.55, 0.43, 111, 87, 0.004);
  const material::Elastic law({70e9, 0.3});
  using Approx = approx::MLS<kernel::CubicSpline>;
  const solver::IntegrationPoints<Approx> points(plate, options.physics(), options.particle_integration(),
                                                 law.shear_modulus());
  // The sum in that order, and a long double sum of the same values.
  constexpr std::size_t chunk_rows = 64;
  const auto chunked_sum = [&](const auto& value) {
    std::vector<double> chunk_sums;
    long double exact = 0.0L;
    for (const solver::PointGroup group : solver::point_groups)
      for (std::size_t first = 0; first < points.count(group); first += chunk_rows) {
        double sum = 0.0;
        for (std::size_t row = first; row < std::min(first + chunk_rows, points.count(group)); ++row) {
          sum += value(points.point(group, row));
          exact += value(points.point(group, row));
        }
        chunk_sums.push_back(sum);
      }
    double partial[8] = {};
    for (std::size_t c = 0; c < chunk_sums.size(); ++c) partial[c % 8] += chunk_sums[c];
    double total = 0.0;
    for (const double sum : partial) total += sum;
    return std::make_pair(total, static_cast<double>(exact));
  };
  REQUIRE(points.count(solver::PointGroup::stress_points) % chunk_rows != 0);
  REQUIRE(points.count(solver::PointGroup::particles) % chunk_rows != 0);
  const auto value = [](std::size_t p) { return 1.0 / (1.0 + 0.37 * static_cast<double>(p)); };
  const auto [expected, exact] = chunked_sum(value);
  CHECK(std::abs(expected - exact) <= 1e-14 * expected);
  std::vector<double> works;
  for (const int threads : {1, 2, 3}) {
#ifdef _OPENMP
    omp_set_num_threads(threads);
#endif
    INFO(threads << " threads");
    solver::ParticleState particles = solver::ParticleState::at_rest(plate.particle_position, plate.particle_normal);
    solver::ParticleForces forces(plate.particle_count());
    solver::SectionStates<thickness::Gauss<3>, material::Elastic> states(
        plate, law, points.count(solver::PointGroup::particles));
    solver::InternalForceAssembler assembler(true, points);
    CHECK(assembler.sum_over_points(points, value) == expected);
    assembler.compute(StepTime{}, particles, points, states, forces);
    CHECK(assembler.sum_over_points(points, value) == expected);
    CHECK(assembler.internal_work() == 0.0);  // at rest
    // Bent (the directors left as they were, so the shear strains too): the
    // pass's own sum of its points' work, formed inside the pass, in that
    // order too, and positive (from rest, the work is the energy taken up).
    for (Vector3& x : particles.position) x.z() += 0.02 * x.x() * x.x() + 0.01 * x.x() * x.y();
    assembler.compute(StepTime{1, 0.0}, particles, points, states, forces);
    const std::vector<double> work = assembler.work_increments();
    const auto [expected_work, exact_work] = chunked_sum([&](std::size_t p) { return work[p]; });
    CHECK(expected_work > 0.0);
    CHECK(std::abs(expected_work - exact_work) <= 1e-13 * expected_work);
    CHECK(assembler.internal_work() == expected_work);
    works.push_back(assembler.internal_work());
  }
#ifdef _OPENMP
  omp_set_num_threads(1);
#endif
  CHECK(works[1] == works[0]);
  CHECK(works[2] == works[0]);
}

TEST_CASE("The assembly schedule sums each particle once, after every point that refers to it",
          "[solver][parallel]") {
  // The interleaved pass (solver/assembly_schedule.hpp) may form a particle's
  // sum only once every point in its force entries has integrated in this
  // step: inside one segment, after the run that completes them, or in a band
  // that the last of the segments holding its points sums. A particle summed one run too early would take a point's forces
  // from the step before, an error too small for the mechanics tests to see.
  const SolverOptions options;
  const ShellModel plate = ShellModel::rectangular_plate(0.3, 0.2, 31, 21, 0.002);
  const ShellModel cap = spherical_cap_ogrid(2.54, 0.1860, 16, 0.0099);
  for (const ShellModel* model : {&plate, &cap}) {
    const solver::IntegrationPoints<approx::MLS<kernel::CubicSpline>> points(*model, options.physics(),
                                                                              options.particle_integration(), 80e9);
    for (std::size_t segments : {std::size_t{1}, std::size_t{2}, std::size_t{8}, std::size_t{32}}) {
      INFO(model->particle_count() << " particles, " << segments << " segments");
      solver::AssemblySchedule schedule;
      schedule.update(points, model->particle_count(), segments);
      REQUIRE(schedule.segments() == segments);
      // Every point in one run, each group's rows in order.
      std::vector<std::size_t> run_of(points.size(), points.size());
      std::size_t next_row[2] = {0, 0};
      bool rows_in_order = true;
      for (std::size_t s = 0; s < segments; ++s)
        for (std::size_t r = schedule.first_run(s); r < schedule.end_run(s); ++r) {
          const solver::AssemblySchedule::Run& run = schedule.run(r);
          const std::size_t g = solver::index_of(run.group);
          rows_in_order = rows_in_order && run.first_row == next_row[g] && run.end_row > run.first_row &&
                          run.first_row % solver::PointChunks::rows == 0;
          next_row[g] = run.end_row;
          for (std::size_t row = run.first_row; row < run.end_row; ++row) run_of[points.point(run.group, row)] = r;
        }
      CHECK(rows_in_order);
      CHECK(next_row[0] == points.count(solver::PointGroup::stress_points));
      CHECK(next_row[1] == points.count(solver::PointGroup::particles));
      // Each particle once; a particle summed in a segment only after all its points.
      std::vector<int> summed(model->particle_count(), 0);
      const std::vector<std::size_t>& begin = points.particle_slot_begin();
      bool after_its_points = true;
      std::size_t in_segments = 0;
      for (std::size_t s = 0; s < segments; ++s)
        for (std::size_t r = schedule.first_run(s); r < schedule.end_run(s); ++r)
          for (const std::uint32_t i : schedule.completed_by(r)) {
            ++summed[i];
            ++in_segments;
            for (std::size_t k = begin[i]; k < begin[i + 1]; ++k) {
              const std::size_t point_run = run_of[points.force_entries()[k].point];
              after_its_points = after_its_points && point_run >= schedule.first_run(s) && point_run <= r;
            }
          }
      // A band's particles: each segment that holds any of their points
      // reports once, after (or at) the last run there among those points.
      std::vector<std::size_t> segment_of_run(schedule.end_run(segments - 1));
      for (std::size_t s = 0; s < segments; ++s)
        for (std::size_t r = schedule.first_run(s); r < schedule.end_run(s); ++r) segment_of_run[r] = s;
      std::vector<std::vector<std::size_t>> report_run(schedule.band_count(),
                                                       std::vector<std::size_t>(segments, points.size()));
      bool one_report_per_segment = true;
      for (std::size_t s = 0; s < segments; ++s)
        for (std::size_t r = schedule.first_run(s); r < schedule.end_run(s); ++r)
          for (const std::uint32_t b : schedule.bands_after(r)) {
            one_report_per_segment = one_report_per_segment && report_run[b][s] == points.size();
            report_run[b][s] = r;
          }
      bool reports_after_points = true, parts_counted = true, bands_straddle = true;
      std::size_t in_bands = 0;
      for (std::size_t b = 0; b < schedule.band_count(); ++b) {
        std::vector<bool> holds(segments, false);
        for (const std::uint32_t i : schedule.band(b)) {
          ++summed[i];
          ++in_bands;
          std::vector<bool> own(segments, false);
          for (std::size_t k = begin[i]; k < begin[i + 1]; ++k) {
            const std::size_t point_run = run_of[points.force_entries()[k].point];
            const std::size_t s = segment_of_run[point_run];
            holds[s] = own[s] = true;
            reports_after_points = reports_after_points && report_run[b][s] != points.size() &&
                                   report_run[b][s] >= point_run;
          }
          bands_straddle = bands_straddle && std::count(own.begin(), own.end(), true) >= 2;
        }
        const auto reporting = std::count_if(report_run[b].begin(), report_run[b].end(),
                                             [&](std::size_t r) { return r != points.size(); });
        parts_counted = parts_counted && reporting == std::count(holds.begin(), holds.end(), true) &&
                        schedule.band_parts(b) == std::size_t(reporting) && reporting >= 2;
      }
      CHECK(in_bands == schedule.straddling().size());
      CHECK(one_report_per_segment);
      CHECK(reports_after_points);
      CHECK(parts_counted);
      CHECK(bands_straddle);
      CHECK(after_its_points);
      CHECK(std::all_of(summed.begin(), summed.end(), [](int n) { return n == 1; }));
      // With one segment no particle waits for the end; with two, most of a
      // grid's particles are summed inside theirs (a band of rows about the
      // cut straddles it).
      if (segments == 1) CHECK(schedule.straddling().empty());
      if (segments == 2 && model == &plate) CHECK(in_segments > model->particle_count() * 3 / 4);
    }
  }
}

TEST_CASE("Options are grouped by concern and still read as flat fields", "[solver][options]") {
  SolverOptions options;
  options.density = 2700.0;
  options.damping = 12.0;
  options.output_directory = "frames";
  CHECK(options.physics().density == 2700.0);
  CHECK(options.time().damping == 12.0);
  CHECK(options.output().output_directory == "frames");
  options.particle_integration().particle_integration_share = 0.02;
  CHECK(options.particle_integration_share == 0.02);
  options.monitoring().progress_interval = 5;
  CHECK(options.progress_interval == 5);
}

TEST_CASE("The progress line goes to the stream the user chose, with the end time, share done and ETA",
          "[solver][monitoring]") {
  std::ostringstream progress;
  SolverOptions options;
  options.progress_interval = 10;
  options.progress_stream = &progress;
  Solver<approx::MLS<kernel::CubicSpline>, thickness::Gauss<3>, material::Elastic> solver(
      ShellModel::rectangular_plate(0.2, 0.2, 9, 9, 0.01), {210e9, 0.3}, options);
  solver.clamp(solver.model().set("boundary"));
  solver.add_uniform_pressure(solver.model().all_particles(), 1e6);
  const double end = 40.25 * solver.time_step();
  solver.run_until(end);
  const std::string text = progress.str();
  INFO(text);
  // Steps 10, 20, 30 and 40: the run stops at 40 Δt, within half a step of its end.
  std::size_t lines = 0;
  for (char c : text) lines += c == '\n';
  CHECK(lines == 4);
  std::ostringstream end_text;
  end_text.precision(4);
  end_text << " of " << end << " s (";
  CHECK(text.find(end_text.str()) != std::string::npos);
  CHECK(text.find("step 20  t = ") != std::string::npos);
  // Step 20 of a run to 40.25 Δt: t = 20 Δt is 49.7 % of the way.
  CHECK(text.find("(49.7 %)") != std::string::npos);
  CHECK(text.find("steps/s") != std::string::npos);
  CHECK(text.find("ETA ") != std::string::npos);
  CHECK(text.find("balance") != std::string::npos);
  // A step outside run_until has no end time to report.
  std::ostringstream().swap(progress);
  for (int n = 0; n < 10; ++n) solver.step();
  CHECK(progress.str().find("step 50  t = ") == 0);
  CHECK(progress.str().find(" of ") == std::string::npos);
}

TEST_CASE("StepLatch: a step that fails (an Error or out of memory) closes it, later steps refuse", "[core]") {
  solver::StepLatch latch;
  long steps = 6;
  int runs = 0;
  latch.run(steps, [&] { ++runs; });
  CHECK(runs == 1);
  CHECK_FALSE(latch.closed());
  SECTION("out of memory becomes a named Error") {
    try {
      latch.run(steps, [&] { ++steps; throw std::bad_alloc(); });
      FAIL("no Error");
    } catch (const Error& error) {
      CHECK(std::string(error.what()) == "sphshell: out of memory (std::bad_alloc) in step 7");
    }
  }
  SECTION("an Error is rethrown as it is and kept with the step") {
    CHECK_THROWS_WITH(latch.run(steps, [] { throw Error("unstable"); }), "unstable");
    CHECK(latch.message() ==
          "sphshell: the solver stopped at step 6 and cannot go on from its half-updated state; the error was: unstable");
  }
  CHECK(latch.closed());
  const std::string kept = latch.message();
  CHECK_THROWS_WITH(latch.run(steps, [&] { ++runs; }), kept);
  CHECK_THROWS_WITH(latch.check(), kept);
  CHECK(runs == 1);
}
