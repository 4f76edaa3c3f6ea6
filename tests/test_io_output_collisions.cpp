// Outputs that cannot collide: a solver holds its output directory by a lock
// file (a second live solver there is refused, a crashed one's lock is taken
// over), probe, frame, collection and checkpoint paths that coincide are
// refused before the first step, and a restart keeps and names stray files
// in the output folder instead of failing part-way. Public API only.
#include <sphshell/approx/all.hpp>
#include <sphshell/crack/all.hpp>
#include <sphshell/kernel/all.hpp>
#include <sphshell/material/all.hpp>
#include <sphshell/solver.hpp>
#include <sphshell/thickness/all.hpp>

#include "support/mesh_files.hpp"

#include <catch2/catch.hpp>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include <sys/wait.h>
#include <unistd.h>

using namespace sphshell;
namespace fs = std::filesystem;
using test_support::ScratchDirectory;

namespace {

using PlateSolver = Solver<approx::MLS<kernel::CubicSpline>, thickness::Gauss<3>, material::Elastic>;
const material::Elastic::Parameters steel{210e9, 0.3};
const char lock_name[] = ".sphshell.lock";

ShellModel small_plate() { return ShellModel::rectangular_plate(0.1, 0.1, 5, 5, 0.01); }

SolverOptions with_frames(const fs::path& directory) {
  SolverOptions options;
  options.output_directory = directory.string();
  options.output_interval = 5e-6;
  return options;
}

std::string read_text(const fs::path& path) {
  std::ifstream in(path);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

std::string this_host() {
  char name[256] = {};
  ::gethostname(name, sizeof name - 1);
  return name;
}

// The message of the Error `make` throws ("" if none).
template <class Make>
std::string error_of(Make&& make) {
  try {
    make();
  } catch (const Error& error) {
    return error.what();
  }
  return "";
}

}  // namespace

TEST_CASE("A second live solver on one output directory is refused, naming it and the holder", "[io][output]") {
  ScratchDirectory scratch("collisions_lock");
  const fs::path frames = scratch / "frames";
  PlateSolver first(small_plate(), steel, with_frames(frames));
  const std::string message = error_of([&] { PlateSolver second(small_plate(), steel, with_frames(frames)); });
  CHECK_THAT(message, Catch::Contains(frames.string()));
  CHECK_THAT(message, Catch::Contains("pid " + std::to_string(::getpid())));
  // Another spelling of the same folder is the same folder.
  const std::string other = error_of([&] {
    PlateSolver second(small_plate(), steel, with_frames(frames / "." / ".." / "frames"));
  });
  CHECK_THAT(other, Catch::Contains("pid " + std::to_string(::getpid())));
}

TEST_CASE("The output directory's lock holds the pid and host and goes with the solver", "[io][output]") {
  ScratchDirectory scratch("collisions_release");
  const fs::path frames = scratch / "frames";
  {
    PlateSolver first(small_plate(), steel, with_frames(frames));
    REQUIRE(fs::exists(frames / lock_name));
    const std::string lock = read_text(frames / lock_name);
    CHECK_THAT(lock, Catch::Contains(std::to_string(::getpid())));
    CHECK_THAT(lock, Catch::Contains(this_host()));
  }
  CHECK_FALSE(fs::exists(frames / lock_name));
  PlateSolver second(small_plate(), steel, with_frames(frames));  // the folder is free again
  CHECK(fs::exists(frames / lock_name));
}

TEST_CASE("A crashed run's lock (its pid gone on this host) is taken over", "[io][output]") {
  ScratchDirectory scratch("collisions_stale");
  const fs::path frames = scratch / "frames";
  fs::create_directories(frames);
  // A pid that was alive and is no longer: a child that exited and was reaped.
  const pid_t child = ::fork();
  REQUIRE(child >= 0);
  if (child == 0) ::_exit(0);
  int status = 0;
  REQUIRE(::waitpid(child, &status, 0) == child);
  {
    std::ofstream(frames / lock_name) << "pid " << child << " host " << this_host() << "\n";
  }
  PlateSolver solver(small_plate(), steel, with_frames(frames));
  CHECK_THAT(read_text(frames / lock_name), Catch::Contains("pid " + std::to_string(::getpid())));
}

TEST_CASE("A probe on a frame's or a collection's path is refused before the first step", "[io][output]") {
  ScratchDirectory scratch("collisions_probe_frame");
  const fs::path frames = scratch / "frames";
  PlateSolver solver(small_plate(), steel, with_frames(frames));
  for (const char* name :
       {"particles_000000.vtu", "stress_points_000003.vtu", "particles.pvd", "bodies_000002.vtu"}) {
    const std::string message = error_of([&] { solver.add_particle_probe((frames / name).string(), 0); });
    CHECK_THAT(message, Catch::Contains(name));
    CHECK_THAT(message, Catch::Contains("frame"));
    CHECK_THAT(message, Catch::Contains("probe"));
  }
}

TEST_CASE("A probe on the checkpoint's path, and a checkpoint on a frame's, are refused", "[io][output]") {
  ScratchDirectory scratch("collisions_checkpoint");
  const fs::path frames = scratch / "frames";
  SolverOptions options = with_frames(frames);
  options.checkpoint_path = (scratch / "run.ckpt").string();
  options.checkpoint_every_steps = 10;
  {
    PlateSolver solver(small_plate(), steel, options);
    const std::string message = error_of([&] { solver.add_particle_probe(options.checkpoint_path, 0); });
    CHECK_THAT(message, Catch::Contains(options.checkpoint_path));
    CHECK_THAT(message, Catch::Contains("checkpoint"));
    CHECK_THAT(message, Catch::Contains("probe"));
  }
  options.checkpoint_path = (frames / "stress_points.pvd").string();
  const std::string message = error_of([&] { PlateSolver solver(small_plate(), steel, options); });
  CHECK_THAT(message, Catch::Contains("checkpoint_path"));
  CHECK_THAT(message, Catch::Contains("frame"));
  options.checkpoint_path = (frames / lock_name).string();
  CHECK_THAT(error_of([&] { PlateSolver solver(small_plate(), steel, options); }), Catch::Contains("lock"));
}

TEST_CASE("A restart keeps and names stray files named like frames in the output folder", "[io][output]") {
  ScratchDirectory scratch("collisions_stray");
  const fs::path frames = scratch / "frames";
  const std::string checkpoint = (scratch / "run.ckpt").string();
  {
    PlateSolver first(small_plate(), steel, with_frames(frames));
    first.clamp(first.model().set("boundary"));
    first.add_uniform_pressure(first.model().all_particles(), 1e5);
    first.run_until(1e-5);
    first.save_checkpoint(checkpoint);
  }
  // A number no frame has (past any long), a folder named like a later frame, a name like a frame's.
  const std::string huge = "particles_99999999999999999999999999.vtu";
  std::ofstream(frames / huge) << "not a frame\n";
  fs::create_directories(frames / "stress_points_000099.vtu" / "inside");
  std::ofstream(frames / "particles_junk.vtu") << "not a frame either\n";
  std::ostringstream notes;
  SolverOptions options = with_frames(frames);
  options.progress_stream = &notes;
  PlateSolver restarted(small_plate(), steel, options);
  restarted.clamp(restarted.model().set("boundary"));
  restarted.add_uniform_pressure(restarted.model().all_particles(), 1e5);
  REQUIRE_NOTHROW(restarted.load_checkpoint(checkpoint));
  REQUIRE_NOTHROW(restarted.run_until(2e-5));
  CHECK(fs::exists(frames / huge));
  CHECK(fs::is_directory(frames / "stress_points_000099.vtu"));
  CHECK(fs::exists(frames / "particles_junk.vtu"));
  CHECK_THAT(notes.str(), Catch::Contains(huge));
  CHECK_THAT(notes.str(), Catch::Contains("stress_points_000099.vtu"));
}

TEST_CASE("An earlier run's body frames are removed when a new run starts in the folder", "[io][output]") {
  ScratchDirectory scratch("collisions_stale_bodies");
  const fs::path frames = scratch / "frames";
  fs::create_directories(frames);
  // What a run with rigid bodies left: body surfaces of frames this run may never write.
  for (const char* name : {"bodies_000000.vtu", "bodies_000041.vtu", "bodies_000003.vtu.tmp"})
    std::ofstream(frames / name) << "an earlier run's bodies\n";
  std::ofstream(frames / "bodies_notes.txt") << "not a frame\n";
  PlateSolver solver(small_plate(), steel, with_frames(frames));
  solver.clamp(solver.model().set("boundary"));
  solver.run_until(5e-6);
  CHECK_FALSE(fs::exists(frames / "bodies_000041.vtu"));
  CHECK_FALSE(fs::exists(frames / "bodies_000003.vtu.tmp"));
  // This run has no bodies, so it wrote none in frame 0's place either.
  CHECK_FALSE(fs::exists(frames / "bodies_000000.vtu"));
  CHECK(fs::exists(frames / "bodies_notes.txt"));
}
