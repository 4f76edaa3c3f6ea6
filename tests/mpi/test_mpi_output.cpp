// Output of a distributed run (docs/distributed.md, "Output"): one .vtu piece
// per rank, a .pvtu per frame and one .pvd series, read back with VTK's own
// parallel reader (tests/mpi/check_pvtu.py, when a Python with VTK was found
// at configure time); probe CSVs written by the rank owning the particle or
// stress point, byte for byte the serial Solver's probe of the same one, also
// across a checkpoint and load_checkpoint.
#include <sphshell/approx/mls.hpp>
#include <sphshell/kernel/cubic_spline.hpp>
#include <sphshell/material/elastic.hpp>
#include <sphshell/mpi/distributed_solver.hpp>
#include <sphshell/solver.hpp>
#include <sphshell/thickness/gauss.hpp>

#include <catch2/catch.hpp>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

using namespace sphshell;

namespace {

using Approximation = approx::MLS<kernel::CubicSpline>;
using Serial = Solver<Approximation, thickness::Gauss<3>, material::Elastic>;
using Distributed = mpi::DistributedSolver<Approximation, thickness::Gauss<3>, material::Elastic>;

std::string file_text(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

// An empty directory "<stem><rank count>" with an empty "serial" inside,
// made by rank 0 before any rank goes on.
std::string fresh_directories(const mpi::Communicator& comm, const std::string& stem) {
  const std::string directory = stem + std::to_string(comm.size());
  if (comm.is_root()) {
    std::filesystem::remove_all(directory);
    std::filesystem::create_directories(directory + "/serial");
  }
  comm.barrier();
  return directory;
}

}  // namespace

TEST_CASE("Distributed frames and probes", "[mpi][output]") {
  const mpi::Communicator comm;
  namespace fs = std::filesystem;
  const std::string directory = fresh_directories(comm, "mpi_output_np");
  const ShellModel model = ShellModel::rectangular_plate(0.5, 0.5, 21, 21, 0.01);
  SolverOptions options;
  options.density = 7850.0;
  options.frame_precision = io::VtuPrecision::float64;
  const double end_time = 5e-5;
  // The probed particles: the first particle each rank owns (every one on
  // another rank for all but one rank), and a corner.
  std::vector<int> probed, probed_stress_points;
  {
    Distributed layout_only(comm, model, {210e9, 0.3}, options);
    probed = comm.all_gather(layout_only.layout().owned.front());
    // Likewise the first stress point each rank owns.
    const mpi::RankLayout& layout = layout_only.layout();
    int first_owned = -1;
    for (std::size_t k = 0; k < layout.computed[0].size() && first_owned < 0; ++k)
      if (layout.computed_is_owned[0][k]) first_owned = static_cast<int>(layout.computed[0][k]);
    probed_stress_points = comm.all_gather(first_owned);
  }
  probed.push_back(static_cast<int>(model.particle_count()) - 1);
  probed_stress_points.push_back(static_cast<int>(model.stress_point_count()) - 1);
  std::vector<Vector3> serial_positions, serial_stress_points;
  {
    Serial serial(model, {210e9, 0.3}, options);
    serial.clamp(model.set("boundary"));
    serial.add_uniform_pressure(model.all_particles(), 5e5);
    for (std::size_t k = 0; k < probed.size(); ++k)
      serial.add_particle_probe(directory + "/serial/probe_" + std::to_string(comm.rank()) + "_" + std::to_string(k) + ".csv",
                                probed[k]);
    for (std::size_t k = 0; k < probed_stress_points.size(); ++k)
      serial.add_stress_point_probe(directory + "/serial/stress_probe_" + std::to_string(comm.rank()) + "_" +
                                        std::to_string(k) + ".csv",
                                    probed_stress_points[k]);
    serial.run_until(end_time);
    serial_positions = serial.positions();
    serial_stress_points = serial.stress_point_positions();
  }
  SolverOptions distributed_options = options;
  distributed_options.output_directory = directory + "/frames";
  distributed_options.output_interval = 1e-5;
  {
    Distributed distributed(comm, model, {210e9, 0.3}, distributed_options);
    distributed.clamp("boundary");
    distributed.add_uniform_pressure(model.all_particles(), 5e5);
    for (std::size_t k = 0; k < probed.size(); ++k)
      distributed.add_particle_probe(directory + "/probe_" + std::to_string(k) + ".csv", probed[k]);
    for (std::size_t k = 0; k < probed_stress_points.size(); ++k)
      distributed.add_stress_point_probe(directory + "/stress_probe_" + std::to_string(k) + ".csv",
                                         probed_stress_points[k]);
    // The same file twice, or a stress point out of range, is an Error on every rank.
    CHECK_THROWS_WITH(distributed.add_particle_probe(directory + "/probe_0.csv", 3),
                      Catch::Contains("already the file of another probe"));
    CHECK_THROWS_WITH(distributed.add_stress_point_probe(directory + "/probe_0.csv", 3),
                      Catch::Contains("already the file of another probe"));
    CHECK_THROWS_WITH(distributed.add_stress_point_probe(directory + "/other.csv",
                                                         static_cast<int>(model.stress_point_count())),
                      Catch::Contains("stress point index"));
    // A probe on a file the run writes itself (a frame's piece, a .pvtu, a
    // collection, the lock file) is an Error on every rank.
    for (const std::string frame_like : {"particles_000001_r0.vtu", "stress_points_000002.pvtu", "particles.pvd",
                                         ".sphshell.lock"})
      CHECK_THROWS_WITH(distributed.add_particle_probe(distributed_options.output_directory + "/" + frame_like, 3),
                        Catch::Contains("output_directory") && Catch::Contains("give the probe a file of its own"));
    // The folder is this solver's while it lives: a second one there is an Error on every rank.
    CHECK_THROWS_WITH(Distributed(comm, model, {210e9, 0.3}, distributed_options),
                      Catch::Contains(distributed_options.output_directory) && Catch::Contains("in use"));
    {
      // A probe on any rank's checkpoint file (checkpoint_path + ".rank<r>") is an Error on every rank.
      SolverOptions checkpointed = options;
      checkpointed.checkpoint_path = directory + "/run.ckpt";
      checkpointed.checkpoint_every_steps = 10;
      Distributed other(comm, model, {210e9, 0.3}, checkpointed);
      const std::string last_rank = std::to_string(comm.size() - 1);
      CHECK_THROWS_WITH(other.add_particle_probe(checkpointed.checkpoint_path + ".rank" + last_rank, 3),
                        Catch::Contains("is rank " + last_rank + "'s checkpoint file"));
    }
    distributed.run_until(end_time);
    CHECK(distributed.positions() == serial_positions);
  }
  comm.barrier();
  for (std::size_t k = 0; k < probed.size(); ++k) {
    const std::string mine = file_text(directory + "/probe_" + std::to_string(k) + ".csv");
    const std::string serial = file_text(directory + "/serial/probe_" + std::to_string(comm.rank()) + "_" +
                                         std::to_string(k) + ".csv");
    INFO("probe " << k << " of particle " << probed[k]);
    CHECK(!serial.empty());
    CHECK(mine == serial);  // every rank reads the file the owner wrote
  }
  for (std::size_t k = 0; k < probed_stress_points.size(); ++k) {
    const std::string mine = file_text(directory + "/stress_probe_" + std::to_string(k) + ".csv");
    const std::string serial = file_text(directory + "/serial/stress_probe_" + std::to_string(comm.rank()) + "_" +
                                         std::to_string(k) + ".csv");
    INFO("probe " << k << " of stress point " << probed_stress_points[k]);
    CHECK(serial.find('\n') < serial.size() - 1);  // a header and rows
    CHECK(mine == serial);
  }
  // Frames at 0, 1e-5, ..., 5e-5 s: six, each with a particle and a
  // stress-point piece per rank.
  std::size_t particle_pieces = 0, stress_pieces = 0;
  for (const auto& entry : fs::directory_iterator(directory + "/frames")) {
    const std::string name = entry.path().filename().string();
    if (entry.path().extension() != ".vtu") continue;
    particle_pieces += name.rfind("particles_", 0) == 0 ? 1 : 0;
    stress_pieces += name.rfind("stress_points_", 0) == 0 ? 1 : 0;
  }
  CHECK(particle_pieces == 6 * static_cast<std::size_t>(comm.size()));
  CHECK(stress_pieces == 6 * static_cast<std::size_t>(comm.size()));
  // The last frame is drawn as the serial frame is, the shell as its cells:
  // over all pieces every stress point is one cell, and the particle pieces
  // hold the same cells plus a vertex for each particle no cell holds.
  auto cells_in = [&](const std::string& series) {
    std::size_t total = 0;
    for (int r = 0; r < comm.size(); ++r) {
      const std::string text =
          file_text(directory + "/frames/" + series + "_000005_r" + std::to_string(r) + ".vtu");
      const std::string key = "NumberOfCells=\"";
      const std::size_t at = text.find(key);
      REQUIRE(at != std::string::npos);
      total += std::stoul(text.substr(at + key.size()));
    }
    return total;
  };
  REQUIRE(!model.cells().empty());
  std::vector<char> in_a_cell(model.particle_count(), 0);
  for (const Cell& cell : model.cells())
    for (const int corner : cell) in_a_cell[static_cast<std::size_t>(corner)] = 1;
  const auto loose = static_cast<std::size_t>(std::count(in_a_cell.begin(), in_a_cell.end(), 0));
  CHECK(cells_in("stress_points") == model.stress_point_count());
  CHECK(cells_in("particles") == model.stress_point_count() + loose);
#ifdef SPHSHELL_VTK_PYTHON
  if (comm.is_root()) {
    {
      std::ofstream reference(directory + "/serial_positions.csv");
      char line[128];
      for (const Vector3& x : serial_positions) {
        std::snprintf(line, sizeof line, "%.17g,%.17g,%.17g\n", x.x(), x.y(), x.z());
        reference << line;
      }
      std::ofstream stress_reference(directory + "/serial_stress_points.csv");
      for (const Vector3& x : serial_stress_points) {
        std::snprintf(line, sizeof line, "%.17g,%.17g,%.17g\n", x.x(), x.y(), x.z());
        stress_reference << line;
      }
    }
    const std::string command = std::string(SPHSHELL_VTK_PYTHON) + " " + SPHSHELL_CHECK_PVTU + " " + directory +
                                "/frames " + std::to_string(comm.size()) + " 6 " + directory +
                                "/serial_positions.csv " + directory + "/serial_stress_points.csv";
    CHECK(std::system(command.c_str()) == 0);
  }
#else
  if (comm.is_root()) WARN("frames not read back: no Python with VTK was found at configure time (python3-vtk9)");
#endif
}

TEST_CASE("More ranks than particles is an Error on every rank", "[mpi][errors]") {
  const mpi::Communicator comm;
  // One triangle: three particles.
  const ShellModel triangle = ShellModel::from_cells(
      {Vector3(0, 0, 0), Vector3(0.01, 0, 0), Vector3(0, 0.01, 0)}, {Cell(0, 1, 2)}, 0.001);
  if (comm.size() <= 3) {
    WARN("needs 4 ranks or more (ctest mpi:test_mpi_output:np4)");
    return;
  }
  std::string message;
  try {
    Distributed solver(comm, triangle, {210e9, 0.3});
  } catch (const Error& error) {
    message = error.what();
  }
  CHECK(message == "sphshell: invalid parameter rank count = " + std::to_string(comm.size()) +
                       " (exceeds the particle count 3: every rank must own at least one particle)");
}

TEST_CASE("Distributed probes continue their files after load_checkpoint: the serial run's files byte for byte",
          "[mpi][output][checkpoint]") {
  const mpi::Communicator comm;
  namespace fs = std::filesystem;
  const std::string directory = fresh_directories(comm, "mpi_probe_restart_np");
  const ShellModel model = ShellModel::rectangular_plate(0.5, 0.5, 21, 21, 0.01);
  SolverOptions options;
  options.density = 7850.0;
  constexpr long checkpoint_step = 30, killed_at = 50, total_steps = 80;
  // The last rank's first particle and stress point: on 2 and 3 ranks
  // another rank's than the first's, whose file the checkpoint does not hold.
  int particle = -1, stress_point = -1;
  {
    Distributed layout_only(comm, model, {210e9, 0.3}, options);
    const mpi::RankLayout& layout = layout_only.layout();
    int first_owned = -1;
    for (std::size_t k = 0; k < layout.computed[0].size() && first_owned < 0; ++k)
      if (layout.computed_is_owned[0][k]) first_owned = static_cast<int>(layout.computed[0][k]);
    particle = comm.all_gather(layout.owned.front()).back();
    stress_point = comm.all_gather(first_owned).back();
  }
  CHECK(stress_point >= 0);
  // The reference: the serial run, uninterrupted (each rank its own files).
  const std::string serial_particle = directory + "/serial/particle_" + std::to_string(comm.rank()) + ".csv";
  const std::string serial_stress = directory + "/serial/stress_" + std::to_string(comm.rank()) + ".csv";
  {
    Serial serial(model, {210e9, 0.3}, options);
    serial.clamp(model.set("boundary"));
    serial.add_uniform_pressure(model.all_particles(), 5e5);
    serial.add_particle_probe(serial_particle, particle);
    serial.add_stress_point_probe(serial_stress, stress_point);
    for (long n = 0; n < total_steps; ++n) serial.step();
  }
  const std::string particle_csv = directory + "/particle.csv", stress_csv = directory + "/stress.csv";
  const std::string checkpoint = directory + "/run.ckpt";
  auto same_as_serial = [&](const char* run) {
    comm.barrier();  // the owners' rows are written before any rank reads them
    const std::string particle_rows = file_text(particle_csv), stress_rows = file_text(stress_csv);
    INFO(run << ": probes of particle " << particle << " and stress point " << stress_point);
    // A header, the row at t = 0 and one row a step: the rows before the checkpoint once.
    CHECK(std::count(particle_rows.begin(), particle_rows.end(), '\n') == 1 + 1 + total_steps);
    CHECK(particle_rows == file_text(serial_particle));
    CHECK(stress_rows == file_text(serial_stress));
  };
  {
    // Probes added before the checkpoint; the run goes on past it, then
    // reloads it: the files are cut back to the checkpoint's rows and go on.
    Distributed run(comm, model, {210e9, 0.3}, options);
    run.clamp("boundary");
    run.add_uniform_pressure(model.all_particles(), 5e5);
    run.add_particle_probe(particle_csv, particle);
    run.add_stress_point_probe(stress_csv, stress_point);
    for (long n = 0; n < checkpoint_step; ++n) run.step();
    run.save_checkpoint(checkpoint);
    for (long n = checkpoint_step; n < killed_at; ++n) run.step();
    run.load_checkpoint(checkpoint);
    CHECK(run.steps() == checkpoint_step);
    for (long n = checkpoint_step; n < total_steps; ++n) run.step();
  }
  same_as_serial("reloaded into the run that added the probes");
  {
    // A new solver that loads the checkpoint and then adds the same probes
    // continues the files from the checkpoint's rows too.
    Distributed restarted(comm, model, {210e9, 0.3}, options);
    restarted.clamp("boundary");
    restarted.add_uniform_pressure(model.all_particles(), 5e5);
    restarted.load_checkpoint(checkpoint);
    restarted.add_particle_probe(particle_csv, particle);
    restarted.add_stress_point_probe(stress_csv, stress_point);
    for (long n = checkpoint_step; n < total_steps; ++n) restarted.step();
  }
  same_as_serial("restarted by a new solver");
}
