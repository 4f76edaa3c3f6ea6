// The distributed solver's errors (docs/distributed.md, "Errors"): an
// exception a user function throws on one rank stops every rank with its
// message; periodic checkpoints are written by every rank and a restart from
// them continues bitwise; a checkpoint of the other kind of run or of another
// rank count, and a set name the model does not have, are each an Error
// naming it on every rank; a rigid body that starts inside the shell is
// refused alike (tests/mpi/test_mpi_contact.cpp runs bodies distributed).
#include <sphshell/approx/mls.hpp>
#include <sphshell/contact/sphere.hpp>
#include <sphshell/kernel/cubic_spline.hpp>
#include <sphshell/material/elastic.hpp>
#include <sphshell/mpi/distributed_solver.hpp>
#include <sphshell/solver.hpp>
#include <sphshell/thickness/gauss.hpp>

#include "mpi_test_support.hpp"

#include <catch2/catch.hpp>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <stdexcept>
#include <string>
#include <vector>

using namespace sphshell;

namespace {

using Approximation = approx::MLS<kernel::CubicSpline>;
using Serial = Solver<Approximation, thickness::Gauss<3>, material::Elastic>;
using Distributed = mpi::DistributedSolver<Approximation, thickness::Gauss<3>, material::Elastic>;

ShellModel plate() { return ShellModel::rectangular_plate(0.5, 0.5, 21, 21, 0.01); }
const material::Elastic::Parameters steel{210e9, 0.3};
constexpr double pressure_value = 1e5;  // Pa

SolverOptions steel_options() {
  SolverOptions options;
  options.density = 7850.0;
  return options;
}

// The rank a user function fails on: rank 1, or the only rank of a 1-rank run.
int failing_rank(const mpi::Communicator& comm) { return comm.size() > 1 ? 1 : 0; }

// What step() threw (empty: nothing), caught as the library's Error.
template <class Run>
std::string error_of(Run&& run) {
  try {
    run();
  } catch (const Error& error) {
    return error.what();
  }
  return {};
}

// A scratch folder per rank count, made before any rank writes to it.
std::string scratch_folder(const mpi::Communicator& comm, const std::string& name) {
  namespace fs = std::filesystem;
  const std::string folder =
      (fs::temp_directory_path() / ("sphshell_test_mpi_" + name + "_np" + std::to_string(comm.size()))).string();
  if (comm.is_root()) {
    fs::remove_all(folder);
    fs::create_directories(folder);
  }
  comm.all_gather(0);
  return folder;
}

}  // namespace

TEST_CASE("A user function that throws on one rank stops every rank with its message", "[mpi][solver][errors]") {
  const mpi::Communicator comm;
  const int thrower = failing_rank(comm);
  const std::string reason = "pressure table has no entry for this time";
  Distributed solver(comm, plate(), steel, steel_options());
  const double failing_time = 5.5 * solver.time_step();
  // Thrown from step 6 on, by one rank only (the others' calls return).
  solver.add_pressure(solver.model().all_particles(), [&](const Vector3&, double t) {
    if (t > failing_time && comm.rank() == thrower) throw Error(reason);
    return pressure_value;
  });
  std::string message = error_of([&] {
    for (int n = 0; n < 20; ++n) solver.step();
  });
  CHECK(message == reason);
  // Every rank stopped: a later step refuses with the same error.
  const std::string refused = error_of([&] { solver.step(); });
  CHECK(refused.find("the solver stopped at step") != std::string::npos);
  CHECK(refused.find(reason) != std::string::npos);

  // Any exception, not only the library's Error: every rank gets an Error
  // naming the rank and the exception's text.
  Distributed other(comm, plate(), steel, steel_options());
  other.add_pressure(other.model().all_particles(), [&](const Vector3&, double t) {
    if (t > failing_time && comm.rank() == thrower) throw std::runtime_error("lookup failed");
    return pressure_value;
  });
  message = error_of([&] {
    for (int n = 0; n < 20; ++n) other.step();
  });
  CHECK(message == "sphshell: exception on rank " + std::to_string(thrower) + ": lookup failed");
  CHECK_THROWS_WITH(other.step(), Catch::Contains("lookup failed"));

  // A prescribed motion whose function throws on one rank, the same way.
  Distributed moving(comm, plate(), steel, steel_options());
  moving.prescribe_velocity(moving.model().all_particles(), [&](const Vector3&, double t) {
    if (t > failing_time && comm.rank() == thrower) throw std::runtime_error("motion table ended");
    return Vector3(0.0, 0.0, 0.1);
  });
  message = error_of([&] {
    for (int n = 0; n < 20; ++n) moving.step();
  });
  CHECK(message == "sphshell: exception on rank " + std::to_string(thrower) + ": motion table ended");
  CHECK_THROWS_WITH(moving.step(), Catch::Contains("motion table ended"));
}

TEST_CASE("Periodic checkpoints of a distributed run: a run stopped mid-way restarts and continues bitwise",
          "[mpi][solver][checkpoint]") {
  const mpi::Communicator comm;
  const std::string folder = scratch_folder(comm, "periodic");
  const int thrower = failing_rank(comm);
  constexpr long total_steps = 60, every = 10;
  SolverOptions options = steel_options();
  auto pressure = [](const Vector3& x, double t) { return pressure_value * (1.0 + x.x()) * (1.0 + 1e4 * t); };

  const int centre = plate().set("centre").front();
  const int stress_point = static_cast<int>(plate().stress_point_count() / 2);
  {
  // The reference: no checkpoints, no interruption.
  Distributed reference(comm, plate(), steel, options);
  reference.clamp("boundary");
  reference.add_pressure(reference.model().all_particles(), pressure);
  reference.add_particle_probe(folder + "/reference_particle.csv", centre);
  reference.add_stress_point_probe(folder + "/reference_stress_point.csv", stress_point);
  for (long n = 0; n < total_steps; ++n) reference.step();

  // The same run with a checkpoint every 10 steps, stopped in step 36 by an
  // exception on one rank.
  options.checkpoint_path = folder + "/periodic";
  options.checkpoint_every_steps = every;
  Distributed stopped(comm, plate(), steel, options);
  stopped.clamp("boundary");
  const double failing_time = 35.5 * stopped.time_step();
  stopped.add_pressure(stopped.model().all_particles(), [&](const Vector3& x, double t) {
    if (t > failing_time && comm.rank() == thrower) throw std::runtime_error("killed mid-run");
    return pressure(x, t);
  });
  stopped.add_particle_probe(folder + "/particle.csv", centre);
  stopped.add_stress_point_probe(folder + "/stress_point.csv", stress_point);
  const std::string message = error_of([&] {
    for (long n = 0; n < total_steps; ++n) stopped.step();
  });
  CHECK(message.find("killed mid-run") != std::string::npos);
  CHECK(std::filesystem::exists(stopped.checkpoint_file(options.checkpoint_path)));

  // A new run loads the last periodic checkpoint (step 30) and goes on.
  Distributed restarted(comm, plate(), steel, options);
  restarted.clamp("boundary");
  restarted.add_pressure(restarted.model().all_particles(), pressure);
  restarted.load_checkpoint(options.checkpoint_path);
  // The probes' files continue from the checkpoint's rows.
  restarted.add_particle_probe(folder + "/particle.csv", centre);
  restarted.add_stress_point_probe(folder + "/stress_point.csv", stress_point);
  CHECK(restarted.steps() == 30);
  while (restarted.steps() < total_steps) restarted.step();
  CHECK(mpi_test::differing_components(restarted.positions(), reference.positions()) == 0);
  CHECK(mpi_test::differing_components(restarted.velocities(), reference.velocities()) == 0);
  CHECK(mpi_test::differing_components(restarted.directors(), reference.directors()) == 0);
  const EnergyReport a = restarted.energy(), b = reference.energy();
  CHECK(a.kinetic == b.kinetic);
  CHECK(a.external_work == b.external_work);
  CHECK(b.kinetic > 0.0);  // the plate moved: equal zeros would prove nothing
  }
  // The probe files (closed with their solvers) hold the uninterrupted run's rows.
  comm.all_gather(0);
  if (comm.is_root()) {
    auto text = [](const std::string& path) {
      std::ifstream in(path, std::ios::binary);
      return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
    };
    const std::string particle = text(folder + "/particle.csv"), point = text(folder + "/stress_point.csv");
    CHECK(std::count(particle.begin(), particle.end(), '\n') == total_steps + 2);  // header, t = 0, every step
    CHECK(particle == text(folder + "/reference_particle.csv"));
    CHECK(point == text(folder + "/reference_stress_point.csv"));
  }
  comm.all_gather(0);
  if (comm.is_root()) std::filesystem::remove_all(folder);
}

TEST_CASE("Checkpoints of the other kind of run or another rank count, unknown set names: an Error on every rank",
          "[mpi][solver][checkpoint][errors]") {
  const mpi::Communicator comm;
  const std::string folder = scratch_folder(comm, "mixed");
  const SolverOptions options = steel_options();

  // A serial Solver's checkpoint (written by rank 0) given to a distributed solver.
  if (comm.is_root()) {
    Serial serial(plate(), steel, options);
    serial.clamp("boundary");
    serial.step();
    serial.save_checkpoint(folder + "/serial");
  }
  comm.all_gather(0);
  Distributed distributed(comm, plate(), steel, options);
  CHECK_THROWS_WITH(distributed.load_checkpoint(folder + "/serial"),
                    Catch::Contains("'" + folder + "/serial' is there: it is a serial Solver's checkpoint"));
  CHECK_NOTHROW(distributed.step());  // nothing was loaded: the solver is usable

  // A distributed checkpoint given to a serial Solver: by its name, or one rank's file.
  distributed.save_checkpoint(folder + "/distributed");
  Serial serial(plate(), steel, options);
  CHECK_THROWS_WITH(serial.load_checkpoint(folder + "/distributed"),
                    Catch::Contains("names a distributed checkpoint"));
  CHECK_THROWS_WITH(serial.load_checkpoint(folder + "/distributed.rank0"),
                    Catch::Contains("is one rank's file of a distributed checkpoint (written by a distributed solver "
                                    "on " + std::to_string(comm.size()) + " ranks)"));

  // A checkpoint of one rank loaded on more: the rank count named on every rank.
  if (comm.size() > 1) {
    if (comm.is_root()) {
      const mpi::Communicator alone(MPI_COMM_SELF);
      Distributed single(alone, plate(), steel, options);
      single.step();
      single.save_checkpoint(folder + "/one_rank");
    }
    comm.all_gather(0);
    Distributed many(comm, plate(), steel, options);
    CHECK_THROWS_WITH(many.load_checkpoint(folder + "/one_rank"),
                      Catch::Contains("rank count differ (checkpoint: 1, this solver: " + std::to_string(comm.size()) +
                                      ")"));
  }

  // A set name the model does not have, in either solver.
  CHECK_THROWS_WITH(distributed.clamp("no such set"), Catch::Contains("no such set"));
  CHECK_THROWS_WITH(distributed.add_pressure("edge_typo", [](const Vector3&, double) { return 1.0; }),
                    Catch::Contains("edge_typo"));
  CHECK_THROWS_WITH(serial.fix_rotation("edge_typo", Vector3::UnitZ()), Catch::Contains("edge_typo"));
  // The serial Solver takes names too: the named set and its ids act alike.
  Serial by_name(plate(), steel, options), by_ids(plate(), steel, options);
  by_name.clamp("boundary");
  by_name.add_uniform_pressure(by_name.model().all_particles(), pressure_value);
  by_ids.clamp(by_ids.model().set("boundary"));
  by_ids.add_uniform_pressure(by_ids.model().all_particles(), pressure_value);
  for (int n = 0; n < 10; ++n) {
    by_name.step();
    by_ids.step();
  }
  CHECK(mpi_test::differing_components(by_name.positions(), by_ids.positions()) == 0);
  CHECK(by_name.displacement(by_name.model().nearest_particle(Vector3(0.25, 0.25, 0.0))).norm() > 0.0);
  comm.all_gather(0);
  if (comm.is_root()) std::filesystem::remove_all(folder);
}

TEST_CASE("A rigid body starting inside the shell in a distributed run: an Error on every rank, the run usable",
          "[mpi][solver][contact][errors]") {
  const mpi::Communicator comm;
  Distributed distributed(comm, plate(), steel, steel_options());
  distributed.clamp("boundary");
  contact::RigidKinematics sunk;
  sunk.position = Vector3(0.25, 0.25, 0.0);  // the plate's mid-surface through its centre
  const contact::RigidBody<contact::Sphere, contact::Fixed> sphere(contact::Sphere(0.05), contact::Fixed{}, sunk);
  CHECK_THROWS_WITH(distributed.add_rigid_body(sphere),
                    Catch::Contains("rigid body 0 initial gap at particle") &&
                        Catch::Contains("the body starts inside the shell"));
  CHECK(distributed.rigid_body_count() == 0);
  CHECK_NOTHROW(distributed.step());
  sunk.position.z() = 0.1;  // clear of the plate: taken
  CHECK_NOTHROW(distributed.add_rigid_body(
      contact::RigidBody<contact::Sphere, contact::Fixed>(contact::Sphere(0.05), contact::Fixed{}, sunk)));
  CHECK(distributed.rigid_body_count() == 1);
  CHECK_NOTHROW(distributed.step());
}
