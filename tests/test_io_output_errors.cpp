// Output paths and files that go wrong: every one is a
// sphshell::Error naming the path and the system's reason; the three ParaView
// collections agree however a run is killed; a reused output directory holds
// only the new run's frames. Uses the Solver's public API only.
#include <sphshell/approx/all.hpp>
#include <sphshell/crack/all.hpp>
#include <sphshell/io/pvd_collection.hpp>
#include <sphshell/io/vtu_writer.hpp>
#include <sphshell/kernel/all.hpp>
#include <sphshell/material/all.hpp>
#include <sphshell/solver.hpp>
#include <sphshell/thickness/all.hpp>

#include "support/mesh_files.hpp"
#include "support/vtu_reader.hpp"

#include <catch2/catch.hpp>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <random>
#include <set>
#include <string>
#include <thread>
#include <vector>

#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

using namespace sphshell;
namespace fs = std::filesystem;
using test_support::ScratchDirectory;

namespace {

using PlateSolver = Solver<approx::MLS<kernel::CubicSpline>, thickness::Gauss<3>, material::Elastic>;
using CrackSolver =
    Solver<approx::MLS<kernel::CubicSpline>, thickness::Gauss<3>, material::LemaitreDamage, crack::LineSegments>;
const material::LemaitreDamage::Parameters steel{210e9, 0.3, 235e6, 0.0, 0.02, 0.37, 0.24};

ShellModel small_plate() { return ShellModel::rectangular_plate(0.1, 0.1, 5, 5, 0.01); }

// A short loaded run with frames into `directory`.
void run_with_frames(const std::string& directory, double end_time = 2e-5) {
  SolverOptions options;
  options.output_directory = directory;
  options.output_interval = 5e-6;
  PlateSolver solver(small_plate(), {210e9, 0.3}, options);
  solver.clamp(solver.model().set("boundary"));
  solver.add_uniform_pressure(solver.model().all_particles(), 1e5);
  solver.run_until(end_time);
}

// A strip with a pre-crack, pulled, a frame every `interval` (every step when
// below the step), run to `end_time`: all three series have data.
void run_strip(const std::string& directory, double interval, double end_time) {
  SolverOptions options;
  options.output_directory = directory;
  options.output_interval = interval;
  CrackSolver solver(ShellModel::rectangular_plate(0.2, 0.1, 21, 11, 0.005), steel, options);
  solver.add_precrack({Vector3(0.105, -0.002, 0.0), Vector3(0.105, 0.102, 0.0)});
  solver.clamp(solver.model().set("x_min"));
  solver.prescribe_velocity(solver.model().set("x_max"), [](const Vector3&, double) { return Vector3(2.0, 0.0, 0.0); });
  solver.run_until(end_time);
}

void touch(const fs::path& path) { test_support::write_text(path, "not a folder\n"); }

}  // namespace

TEST_CASE("An output directory that cannot be one is an Error naming it and the reason", "[io][output][errors]") {
  ScratchDirectory scratch("output_directory_errors");
  const std::string file = (scratch / "a_file").string();
  touch(file);
  for (const std::string& directory : {file, file + "/frames", std::string("/proc/sphshell_no_such_folder/frames")}) {
    INFO("output_directory " << directory);
    try {
      run_with_frames(directory);
      FAIL("no error for output_directory " << directory);
    } catch (const Error& error) {
      const std::string message = error.what();
      CHECK_THAT(message, Catch::Contains(directory));
      // Either "is not a folder" or the system's reason in parentheses.
      CHECK((message.find("not a folder") != std::string::npos || message.find(" (") != std::string::npos));
    } catch (const std::exception& other) {
      FAIL("output_directory " << directory << " threw a non-sphshell exception: " << other.what());
    }
  }
}

TEST_CASE("A probe file under a file is an Error naming it and the reason", "[io][output][errors]") {
  ScratchDirectory scratch("probe_path_errors");
  const std::string file = (scratch / "a_file").string();
  touch(file);
  PlateSolver solver(small_plate(), {210e9, 0.3});
  const std::string probe = file + "/centre.csv";
  try {
    solver.add_particle_probe(probe, 0);
    FAIL("no error for probe " << probe);
  } catch (const Error& error) {
    CHECK_THAT(std::string(error.what()),
               Catch::Contains(probe) && (Catch::Contains("not a folder") || Catch::Contains("Not a directory")));
  } catch (const std::exception& other) {
    FAIL("probe " << probe << " threw a non-sphshell exception: " << other.what());
  }
}

TEST_CASE("Two probes on one CSV file are refused, however the path is spelled", "[io][output][errors]") {
  ScratchDirectory scratch("probe_twice");
  PlateSolver solver(small_plate(), {210e9, 0.3});
  const std::string path = (scratch / "probe.csv").string();
  solver.add_particle_probe(path, 0);
  CHECK_THROWS_WITH(solver.add_particle_probe(path, 1), Catch::Contains(path) && Catch::Contains("another probe"));
  CHECK_THROWS_WITH(solver.add_stress_point_probe((scratch / "." / "probe.csv").string(), 0),
                    Catch::Contains("another probe"));
  solver.add_particle_probe((scratch / "other.csv").string(), 1);  // a file of its own is fine
  solver.run_until(2e-6);
  // The first probe kept all its rows: header, t = 0 and one per step.
  const std::string text = test_support::read_file(path);
  CHECK(static_cast<long>(std::count(text.begin(), text.end(), '\n')) == solver.steps() + 2);
}

TEST_CASE("Output options that would be ignored are Errors", "[io][output][errors]") {
  SolverOptions quiet;
  quiet.progress_interval = -5;
  CHECK_THROWS_WITH(PlateSolver(small_plate(), {210e9, 0.3}, quiet),
                    Catch::Contains("progress_interval") && Catch::Contains("-5"));
  SolverOptions nowhere;
  nowhere.output_interval = 1e-5;
  CHECK_THROWS_WITH(PlateSolver(small_plate(), {210e9, 0.3}, nowhere),
                    Catch::Contains("output_interval") && Catch::Contains("output_directory"));
}

TEST_CASE("A full disk names the file and the system's reason", "[io][output][errors]") {
  if (!fs::exists("/dev/full")) {
    WARN("no /dev/full on this system: skipped");
    return;
  }
  SECTION("a CSV probe") {
    PlateSolver solver(small_plate(), {210e9, 0.3});
    CHECK_THROWS_WITH(solver.add_particle_probe("/dev/full", 0),
                      Catch::Contains("/dev/full") && Catch::Contains("No space left on device"));
  }
  SECTION("a VTU frame, whose temporary is on the full device") {
    ScratchDirectory scratch("disk_full");
    const std::string frame = (scratch / "frame.vtu").string();
    fs::create_symlink("/dev/full", frame + ".tmp");
    std::vector<Vector3> points(20000, Vector3(1, 2, 3));
    CHECK_THROWS_WITH(io::write_vtu_points(frame, points, {}),
                      Catch::Contains(frame) && Catch::Contains("No space left on device"));
    CHECK_FALSE(fs::exists(frame));
  }
}

TEST_CASE("run_until ends with a frame of its last state, written once", "[io][output]") {
  ScratchDirectory scratch("last_frame");
  for (const double end_time : {3.5e-5, 4e-5}) {
    INFO("run_until(" << end_time << ") with frames every 1e-5 s");
    const std::string directory = (scratch / ("end_" + std::to_string(end_time))).string();
    SolverOptions options;
    options.output_directory = directory;
    options.output_interval = 1e-5;
    PlateSolver solver(small_plate(), {210e9, 0.3}, options);
    solver.clamp(solver.model().set("boundary"));
    solver.add_uniform_pressure(solver.model().all_particles(), 1e5);
    solver.run_until(end_time);
    const auto frames = test_support::read_pvd(directory + "/particles.pvd");
    REQUIRE(!frames.empty());
    // The run stops within half a step of end_time, and its last state is the last frame.
    CHECK(std::abs(solver.time() - end_time) <= 0.5 * solver.time_step() * (1 + 1e-9));
    CHECK(frames.back().time == solver.time());
    // t = 0, 1e-5, 2e-5, 3e-5, then the end (3.5e-5), or 4e-5 once only.
    CHECK(frames.size() == 5);
    std::set<double> times;
    for (const auto& frame : frames) times.insert(frame.time);
    CHECK(times.size() == frames.size());
    for (std::size_t k = 1; k + 1 < frames.size(); ++k)
      CHECK(std::abs(frames[k].time - 1e-5 * static_cast<double>(k)) <= 0.5 * solver.time_step() * (1 + 1e-9));
  }
}

TEST_CASE("A reused output directory holds only the new run's frames, and no temporaries",
          "[io][output]") {
  ScratchDirectory scratch("reused_directory");
  const std::string directory = (scratch / "frames").string();
  run_with_frames(directory, 5e-5);  // 11 frames
  // Leftovers of a killed run: temporaries of a frame and of a collection.
  touch(directory + "/particles_000099.vtu.tmp");
  touch(directory + "/stress_points.pvd.tmp");
  touch(directory + "/notes.txt");  // not the solver's: kept
  run_with_frames(directory, 1e-5);  // t = 0, 5e-6, 1e-5: 3 frames
  std::set<std::string> files;
  for (const auto& entry : fs::directory_iterator(directory)) files.insert(entry.path().filename().string());
  const std::set<std::string> expected{"particles.pvd",        "stress_points.pvd",    "notes.txt",
                                       "particles_000000.vtu", "particles_000001.vtu", "particles_000002.vtu",
                                       "stress_points_000000.vtu", "stress_points_000001.vtu",
                                       "stress_points_000002.vtu"};
  CHECK(files == expected);
  CHECK(test_support::read_pvd(directory + "/particles.pvd").size() == 3);
}

// The child of the kill test: writes a frame every step until killed.
TEST_CASE("kill child: a run writing frames until it is killed", "[.kill_child]") {
  const char* directory = std::getenv("SPHSHELL_KILL_TEST_DIRECTORY");
  if (directory == nullptr) return;
  run_strip(directory, 1e-12, 1.0);
}

TEST_CASE("Killed at any moment, the three collections list the same complete frames", "[io][output][kill]") {
  ScratchDirectory scratch("kill_safety");
  const std::string directory = (scratch / "frames").string();
  const std::string self = fs::read_symlink("/proc/self/exe").string();
  std::mt19937 random(20261201);
  std::uniform_int_distribution<int> delay_ms(20, 400);
  // SPHSHELL_KILL_TRIALS overrides the count, for a longer measurement.
  const char* trials_override = std::getenv("SPHSHELL_KILL_TRIALS");
  const int trials = trials_override ? std::atoi(trials_override) : 24;
  int killed_with_temporaries = 0, disagreeing = 0, incomplete = 0, mixed = 0, unlisted = 0;
  for (int trial = 0; trial < trials; ++trial) {
    const pid_t child = fork();
    REQUIRE(child >= 0);
    if (child == 0) {
      setenv("SPHSHELL_KILL_TEST_DIRECTORY", directory.c_str(), 1);
      execl(self.c_str(), self.c_str(), "kill child: a run writing frames until it is killed", nullptr);
      _exit(127);
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(delay_ms(random)));
    kill(child, SIGKILL);
    int status = 0;
    waitpid(child, &status, 0);
    REQUIRE(WIFSIGNALED(status));
    if (!fs::exists(directory + "/particles.pvd")) continue;  // killed before its first frame
    std::set<std::string> files;
    for (const auto& entry : fs::directory_iterator(directory)) files.insert(entry.path().filename().string());
    killed_with_temporaries += std::any_of(files.begin(), files.end(), [](const std::string& name) {
      return name.size() > 4 && name.compare(name.size() - 4, 4, ".tmp") == 0;
    });
    std::vector<std::vector<test_support::PvdEntry>> series;
    for (const char* name : {"particles", "stress_points", "cracks"}) {
      const std::string pvd = directory + "/" + name + ".pvd";
      series.push_back(fs::exists(pvd) ? test_support::read_pvd(pvd) : std::vector<test_support::PvdEntry>{});
    }
    bool same = series[0].size() == series[1].size() && series[0].size() == series[2].size();
    for (std::size_t k = 0; same && k < series[0].size(); ++k)
      same = series[0][k].time == series[1][k].time && series[0][k].time == series[2][k].time &&
             series[0][k].file.substr(series[0][k].file.size() - 10) ==
                 series[1][k].file.substr(series[1][k].file.size() - 10);
    disagreeing += !same;
    // Every listed frame is complete, and the listing is one run's: frames
    // 0, 1, 2, ... at increasing times. (Unlisted files of an earlier run may
    // remain when the kill came while they were being removed; the next run
    // removes them, checked below.)
    std::set<std::string> listed;
    for (const auto& entries : series)
      for (std::size_t k = 0; k < entries.size(); ++k) {
        listed.insert(entries[k].file);
        char number[32];
        std::snprintf(number, sizeof number, "_%06zu.vtu", k);
        const bool in_order = entries[k].file.find(number) != std::string::npos &&
                              (k == 0 || entries[k].time > entries[k - 1].time);
        mixed += !in_order;
        try {
          test_support::read_vtu(directory + "/" + entries[k].file);
        } catch (const std::exception&) {
          ++incomplete;
        }
      }
    for (const std::string& name : files)
      unlisted += name.size() > 4 && name.compare(name.size() - 4, 4, ".vtu") == 0 && !listed.count(name);
  }
  INFO(trials << " kills: " << disagreeing << " with disagreeing collections, " << incomplete
              << " listed frames incomplete, " << mixed << " listed out of order or from an earlier run, "
              << killed_with_temporaries << " left temporaries, " << unlisted << " unlisted frame files");
  CHECK(disagreeing == 0);
  CHECK(incomplete == 0);
  CHECK(mixed == 0);
  // A normal run into the same directory: no temporaries, nothing of the killed runs.
  run_strip(directory, 1e-5, 2e-5);
  std::size_t vtu_files = 0;
  for (const auto& entry : fs::directory_iterator(directory)) {
    const std::string name = entry.path().filename().string();
    CHECK(name.find(".tmp") == std::string::npos);
    vtu_files += name.size() > 4 && name.compare(name.size() - 4, 4, ".vtu") == 0;
  }
  const auto particles = test_support::read_pvd(directory + "/particles.pvd");
  CHECK(vtu_files == 3 * particles.size());
  CHECK(test_support::read_pvd(directory + "/cracks.pvd").size() == particles.size());
  WARN(trials << " kills: " << disagreeing << " with disagreeing collections, " << killed_with_temporaries
              << " left temporaries, " << unlisted << " unlisted frame files (all removed by the next run)");
}
