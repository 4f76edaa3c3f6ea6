// Checkpoint and restart (solver/checkpoint.hpp): a run stopped at step k,
// restored into a new Solver from its checkpoint and continued is bit for bit
// the run that never stopped — J2 plasticity through Gauss<5>, and a fracture
// run whose cracks grow on both sides of the checkpoint — with its probe files
// and ParaView frames byte for byte those of the uninterrupted run; and a
// truncated, corrupted or foreign file is refused with an Error naming the file
// and the problem. The reference is always a second, uninterrupted run of the
// same program, never a stored output.
#include <sphshell/approx/all.hpp>
#include <sphshell/crack/all.hpp>
#include <sphshell/io/directory_lock.hpp>
#include <sphshell/kernel/all.hpp>
#include <sphshell/material/all.hpp>
#include <sphshell/solver.hpp>
#include <sphshell/thickness/all.hpp>

#include "support/mesh_files.hpp"

#include <catch2/catch.hpp>

#include <algorithm>
#include <array>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <initializer_list>
#include <iterator>
#include <map>
#include <memory>
#include <random>
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

using J2Solver = Solver<approx::MLS<kernel::CubicSpline>, thickness::Gauss<5>, material::J2Plasticity>;
using CrackSolver =
    Solver<approx::MLS<kernel::CubicSpline>, thickness::Gauss<3>, material::LemaitreDamage, crack::LineSegments>;
// Mild steel with linear hardening (E, ν, σs0, Ep).
const material::J2Plasticity::Parameters mild_steel{210e9, 0.3, 235e6, 1e9};
// The paper's Table 3 steel (tests/test_solver_fracture.cpp).
const material::LemaitreDamage::Parameters table_3_steel{210e9, 0.3, 235e6, 0.0, 0.02, 0.37, 0.24};

bool same_bits(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; }
bool same_bits(const Vector3& a, const Vector3& b) {
  return same_bits(a.x(), b.x()) && same_bits(a.y(), b.y()) && same_bits(a.z(), b.z());
}

std::string file_bytes(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

// Every particle's position, velocity, director and angular velocity, every
// stress point's state through the thickness and resultants, and the energy
// books, compared bit for bit; the first difference is reported.
template <class S>
void require_bitwise_equal(const S& restarted, const S& reference) {
  REQUIRE(restarted.steps() == reference.steps());
  REQUIRE(same_bits(restarted.time(), reference.time()));
  for (std::size_t i = 0; i < reference.particle_count(); ++i) {
    INFO("particle " << i);
    REQUIRE(same_bits(restarted.positions()[i], reference.positions()[i]));
    REQUIRE(same_bits(restarted.velocities()[i], reference.velocities()[i]));
    REQUIRE(same_bits(restarted.directors()[i], reference.directors()[i]));
    REQUIRE(same_bits(restarted.angular_velocities()[i], reference.angular_velocities()[i]));
    REQUIRE(same_bits(restarted.internal_forces()[i], reference.internal_forces()[i]));
  }
  for (std::size_t p = 0; p < reference.stress_point_count(); ++p) {
    INFO("stress point " << p);
    const int s = static_cast<int>(p);
    REQUIRE(restarted.is_removed(s) == reference.is_removed(s));
    for (int k = 0; k < S::output_points; ++k) {
      REQUIRE(same_bits(restarted.equivalent_stress(s, k), reference.equivalent_stress(s, k)));
      REQUIRE(same_bits(restarted.equivalent_plastic_strain(s, k), reference.equivalent_plastic_strain(s, k)));
      REQUIRE(same_bits(restarted.damage(s, k), reference.damage(s, k)));
    }
    for (int c = 0; c < 3; ++c) {
      REQUIRE(same_bits(restarted.membrane_force(s)[c], reference.membrane_force(s)[c]));
      REQUIRE(same_bits(restarted.bending_moment(s)[c], reference.bending_moment(s)[c]));
    }
  }
  const EnergyReport a = restarted.energy(), b = reference.energy();
  CHECK(same_bits(a.kinetic, b.kinetic));
  CHECK(same_bits(a.internal, b.internal));
  CHECK(same_bits(a.elastic, b.elastic));
  CHECK(same_bits(a.external_work, b.external_work));
  CHECK(same_bits(a.damping_work, b.damping_work));
  CHECK(same_bits(a.released_by_fracture, b.released_by_fracture));
  CHECK(same_bits(a.balance(), b.balance()));
}

// Every file of two output folders, byte for byte; returns the file count.
// The output files, not the live solvers' lock files (which name the process, not the run).
std::size_t require_same_files(const fs::path& restarted_dir, const fs::path& reference_dir) {
  std::map<std::string, std::string> reference_files, restarted_files;
  for (const auto& entry : fs::directory_iterator(reference_dir))
    if (entry.path().filename() != io::DirectoryLock::file_name)
      reference_files[entry.path().filename().string()] = file_bytes(entry.path());
  for (const auto& entry : fs::directory_iterator(restarted_dir))
    if (entry.path().filename() != io::DirectoryLock::file_name)
      restarted_files[entry.path().filename().string()] = file_bytes(entry.path());
  for (const auto& [name, bytes] : reference_files) {
    INFO("file " << name);
    REQUIRE(restarted_files.count(name) == 1);
    CHECK(restarted_files[name] == bytes);
  }
  CHECK(restarted_files.size() == reference_files.size());
  return reference_files.size();
}

// ---------------------------------------------------------------- J2 -----

ShellModel j2_plate() { return ShellModel::rectangular_plate(0.2, 0.2, 11, 11, 0.004); }
constexpr double j2_pressure = 8e6;  // ramped over 0.1 ms: the clamped edges yield from step ≈ 150 on

SolverOptions j2_options(const fs::path& frames) {
  SolverOptions options;
  options.output_directory = frames.string();
  options.output_interval = 1e-5;
  return options;
}

void set_up_j2(J2Solver& solver) {
  solver.clamp(solver.model().set("boundary"));
  solver.add_uniform_pressure(solver.model().all_particles(), j2_pressure, time_function::Ramp{1e-4});
}

double largest_plastic_strain(const J2Solver& solver) {
  double largest = 0.0;
  for (std::size_t p = 0; p < solver.stress_point_count(); ++p)
    for (int k = 0; k < J2Solver::output_points; ++k)
      largest = std::max(largest, solver.equivalent_plastic_strain(static_cast<int>(p), k));
  return largest;
}

void steps(J2Solver& solver, long count) {
  for (long n = 0; n < count; ++n) solver.step();
}

}  // namespace

TEST_CASE("A J2 run restarted from its checkpoint is bitwise the uninterrupted run", "[checkpoint][solver]") {
  ScratchDirectory scratch("checkpoint_j2");
  constexpr long checkpoint_step = 180, total_steps = 420, killed_at = 260;
  const fs::path reference_dir = scratch / "reference", restarted_dir = scratch / "restarted";

  // The uninterrupted run, with a particle probe and a stress-point probe.
  J2Solver reference(j2_plate(), mild_steel, j2_options(reference_dir));
  set_up_j2(reference);
  reference.add_particle_probe((reference_dir / "centre.csv").string(), 60);
  reference.add_stress_point_probe((reference_dir / "edge.csv").string(), 5);
  steps(reference, checkpoint_step);
  const double plastic_at_checkpoint = largest_plastic_strain(reference);
  steps(reference, total_steps - checkpoint_step);
  reference.run_until(reference.time());  // writes the final frame, as a run's end does
  REQUIRE(plastic_at_checkpoint > 0.0);
  REQUIRE(largest_plastic_strain(reference) > plastic_at_checkpoint);  // plastic flow on both sides

  // The same program, checkpointed at step k and "killed" later, at step
  // killed_at: its files then hold rows and frames past the checkpoint.
  const std::string checkpoint = (scratch / "run.ckpt").string();
  {
    J2Solver first(j2_plate(), mild_steel, j2_options(restarted_dir));
    set_up_j2(first);
    first.add_particle_probe((restarted_dir / "centre.csv").string(), 60);
    first.add_stress_point_probe((restarted_dir / "edge.csv").string(), 5);
    steps(first, checkpoint_step);
    first.save_checkpoint(checkpoint);
    steps(first, killed_at - checkpoint_step);
  }
  // A new solver from the file, set up as the program does after a restart.
  J2Solver restarted = J2Solver::from_checkpoint(checkpoint, j2_plate(), mild_steel, j2_options(restarted_dir));
  CHECK(restarted.steps() == checkpoint_step);
  set_up_j2(restarted);
  restarted.add_particle_probe((restarted_dir / "centre.csv").string(), 60);
  restarted.add_stress_point_probe((restarted_dir / "edge.csv").string(), 5);
  steps(restarted, total_steps - checkpoint_step);
  restarted.run_until(restarted.time());

  require_bitwise_equal(restarted, reference);
  // Probe files continue without duplicated or missing rows, and the frames
  // (the .vtu files and the three collections) are byte for byte the same.
  // Two probes, two collections, and frames at t = 0, every 10 µs to 0.238 ms and the end: 25 of each.
  CHECK(require_same_files(restarted_dir, reference_dir) == 2 + 2 + 2 * 25);
  CHECK(fs::exists(reference_dir / "particles_000024.vtu"));
  const std::string centre = file_bytes(reference_dir / "centre.csv");
  CHECK(std::count(centre.begin(), centre.end(), '\n') == 1 + 1 + total_steps);  // header, t = 0, every step
}

TEST_CASE("Reloading an earlier checkpoint into the same solver branches from it", "[checkpoint][solver]") {
  ScratchDirectory scratch("checkpoint_reload");
  const std::string checkpoint = (scratch / "k.ckpt").string();
  J2Solver solver(j2_plate(), mild_steel);
  set_up_j2(solver);
  steps(solver, 150);
  solver.save_checkpoint(checkpoint);
  steps(solver, 100);
  const std::vector<Vector3> at_250 = solver.positions();
  solver.load_checkpoint(checkpoint);
  CHECK(solver.steps() == 150);
  steps(solver, 100);
  for (std::size_t i = 0; i < at_250.size(); ++i) REQUIRE(same_bits(solver.positions()[i], at_250[i]));
}

// ----------------------------------------------------------- fracture -----

namespace {

// The coarse paper plate of tests/test_solver_fracture.cpp: 21 × 21,
// clamped, 12 MPa, tearing from the clamped mid-edges after ≈ 1.1 ms.
ShellModel tearing_plate() { return ShellModel::rectangular_plate(0.5, 0.5, 21, 21, 0.01); }
void set_up_tearing(CrackSolver& solver) {
  solver.clamp(solver.model().set("boundary"));
  solver.add_uniform_pressure(solver.model().all_particles(), 12e6);
}

}  // namespace

TEST_CASE("A fracture run restarted while its cracks grow is bitwise the uninterrupted run",
          "[checkpoint][fracture][solver]") {
  ScratchDirectory scratch("checkpoint_fracture");
  constexpr double end_time = 1.3e-3;
  // The uninterrupted run, with the crack segment count after every step.
  CrackSolver reference(tearing_plate(), table_3_steel);
  set_up_tearing(reference);
  std::vector<std::size_t> segments_after{0};
  reference.run_until(end_time, [&](const CrackSolver& s) { segments_after.push_back(s.crack().segments().size()); });
  const long total = reference.steps();
  // The checkpoint: the first step with cracks of at least 4 segments, so the
  // restored run must carry crack topology, fragments and rebuilt shape
  // functions, and grow the cracks further.
  long k = 0;
  while (k < total && segments_after[std::size_t(k)] < 4) ++k;
  INFO("checkpoint at step " << k << " of " << total << ", " << segments_after[std::size_t(k)] << " segments then, "
                             << segments_after.back() << " at the end");
  REQUIRE(k < total);
  REQUIRE(segments_after.back() > segments_after[std::size_t(k)] + 2);

  const std::string checkpoint = (scratch / "tearing.ckpt").string();
  {
    CrackSolver first(tearing_plate(), table_3_steel);
    set_up_tearing(first);
    for (long n = 0; n < k; ++n) first.step();
    first.save_checkpoint(checkpoint);
  }
  CrackSolver restarted = CrackSolver::from_checkpoint(checkpoint, tearing_plate(), table_3_steel);
  set_up_tearing(restarted);
  REQUIRE(restarted.crack().segments().size() == segments_after[std::size_t(k)]);
  restarted.run_until(end_time);

  require_bitwise_equal(restarted, reference);
  CHECK(restarted.crack().segments() == reference.crack().segments());
  CHECK(restarted.crack().points().size() == reference.crack().points().size());
  for (std::size_t q = 0; q < reference.crack().points().size(); ++q)
    CHECK(same_bits(restarted.crack().points()[q], reference.crack().points()[q]));
  CHECK(restarted.damaged_stress_point_count() == reference.damaged_stress_point_count());
  CHECK(restarted.fragment_count() == reference.fragment_count());
  for (std::size_t i = 0; i < reference.particle_count(); ++i)
    REQUIRE(restarted.is_fragment(static_cast<int>(i)) == reference.is_fragment(static_cast<int>(i)));
}

TEST_CASE("A pre-crack is part of the checkpoint", "[checkpoint][fracture][solver]") {
  ScratchDirectory scratch("checkpoint_precrack");
  auto build = [](const fs::path& frames) {
    SolverOptions options;
    options.output_directory = frames.string();
    options.output_interval = 1e-5;  // every ≈ 10 steps
    CrackSolver solver(ShellModel::rectangular_plate(0.2, 0.1, 21, 11, 0.005), table_3_steel, options);
    solver.clamp(solver.model().set("x_min"));
    solver.prescribe_velocity(solver.model().set("x_max"), [](const Vector3&, double) { return Vector3(2.0, 0.0, 0.0); });
    return solver;
  };
  // The reference writes its frames (with the crack series) and a probe into
  // one folder; the checkpointed run into another, and goes on past the
  // checkpoint before the restart.
  const fs::path reference_dir = scratch / "reference", restarted_dir = scratch / "restarted";
  CrackSolver reference = build(reference_dir);
  reference.add_precrack({Vector3(0.105, -0.002, 0.0), Vector3(0.105, 0.102, 0.0)});
  reference.add_stress_point_probe((reference_dir / "tip.csv").string(), 42);
  for (int n = 0; n < 120; ++n) reference.step();
  reference.run_until(reference.time());
  const std::string checkpoint = (scratch / "strip.ckpt").string();
  {
    CrackSolver first = build(restarted_dir);
    first.add_precrack({Vector3(0.105, -0.002, 0.0), Vector3(0.105, 0.102, 0.0)});
    first.add_stress_point_probe((restarted_dir / "tip.csv").string(), 42);
    for (int n = 0; n < 60; ++n) first.step();
    first.save_checkpoint(checkpoint);
    for (int n = 0; n < 30; ++n) first.step();
  }
  CrackSolver restarted = build(restarted_dir);  // no add_precrack: the checkpoint has it
  restarted.load_checkpoint(checkpoint);
  restarted.add_stress_point_probe((restarted_dir / "tip.csv").string(), 42);
  CHECK(restarted.precrack_stress_point_count() == reference.precrack_stress_point_count());
  for (int n = 0; n < 60; ++n) restarted.step();
  restarted.run_until(restarted.time());
  require_bitwise_equal(restarted, reference);
  CHECK(restarted.crack().segments() == reference.crack().segments());
  // tip.csv, three collections and 7 frames of each series (t = 0 and every 10 µs);
  // the killed run had gone on 30 steps (and frames) past the checkpoint.
  CHECK(require_same_files(restarted_dir, reference_dir) == 1 + 3 + 3 * 7);
}

TEST_CASE("Resultant sections (Global) and NSPH restart bitwise too", "[checkpoint][solver]") {
  using GlobalSolver = Solver<approx::NSPH<kernel::WendlandC2>, thickness::Global, material::LemaitreDamage>;
  ScratchDirectory scratch("checkpoint_global");
  auto build = [] {
    GlobalSolver solver(j2_plate(), table_3_steel);
    solver.clamp(solver.model().set("boundary"));
    solver.add_uniform_pressure(solver.model().all_particles(), j2_pressure, time_function::Ramp{1e-4});
    return solver;
  };
  GlobalSolver reference = build();
  for (int n = 0; n < 300; ++n) reference.step();
  const std::string checkpoint = (scratch / "global.ckpt").string();
  GlobalSolver first = build();
  for (int n = 0; n < 200; ++n) first.step();
  first.save_checkpoint(checkpoint);
  REQUIRE(first.equivalent_plastic_strain(5, 0) > 0.0);  // the resultant state carries plastic flow
  GlobalSolver restarted = build();
  restarted.load_checkpoint(checkpoint);
  for (int n = 0; n < 100; ++n) restarted.step();
  require_bitwise_equal(restarted, reference);
}

// --------------------------------------------------- files refused -----

namespace {

// A J2 checkpoint at step 40, to damage in various ways.
std::string j2_checkpoint(const ScratchDirectory& scratch) {
  const std::string path = (scratch / "j2.ckpt").string();
  J2Solver solver(j2_plate(), mild_steel);
  set_up_j2(solver);
  steps(solver, 40);
  solver.save_checkpoint(path);
  return path;
}

// A checkpoint's bytes after a change inside the payload, with both checksums
// computed again as the writer computes them, so that only the meaning of
// the change is left for the reader to find (header: magic, version, library
// version, five policy names, payload size and checksum, header checksum).
std::string resealed(std::string bytes) {
  io::BinaryReader header(bytes, "test", sizeof solver::checkpoint::magic);
  std::uint32_t version = 0;
  std::string written_by;
  std::array<std::string, 5> policies;
  std::uint64_t payload_size = 0, payload_checksum = 0;
  header(version, written_by);
  for (std::string& policy : policies) header(policy);
  header(payload_size);
  const std::size_t payload_checksum_at = header.position();
  header(payload_checksum);
  const std::size_t header_checksum_at = header.position();
  const std::size_t payload_begin = header_checksum_at + sizeof(std::uint64_t);
  REQUIRE(payload_begin + payload_size == bytes.size());
  // The file's numbers are little endian, as this machine's.
  const std::uint64_t payload_sum = io::fnv1a(bytes.data() + payload_begin, bytes.size() - payload_begin);
  std::memcpy(&bytes[payload_checksum_at], &payload_sum, sizeof payload_sum);
  const std::uint64_t header_sum = io::fnv1a(bytes.data(), header_checksum_at);
  std::memcpy(&bytes[header_checksum_at], &header_sum, sizeof header_sum);
  return bytes;
}

// Loading `path` into `solver` throws an Error naming the file and every problem.
void check_load_refused(J2Solver& solver, const std::string& path, std::initializer_list<std::string> problems) {
  try {
    solver.load_checkpoint(path);
    FAIL("loading " << path << " was accepted");
  } catch (const Error& error) {
    const std::string message = error.what();
    INFO(message);
    CHECK(message.find(path) != std::string::npos);
    for (const std::string& problem : problems) CHECK(message.find(problem) != std::string::npos);
  }
}

void require_refused(const std::string& path, const std::string& problem) {
  J2Solver solver(j2_plate(), mild_steel);
  check_load_refused(solver, path, {problem});
  // A refused file changes nothing: the solver still starts from rest.
  CHECK(solver.steps() == 0);
  solver.step();
}

}  // namespace

TEST_CASE("A truncated, corrupted or foreign checkpoint is refused naming the file and the problem",
          "[checkpoint][errors]") {
  ScratchDirectory scratch("checkpoint_refused");
  const std::string good = j2_checkpoint(scratch);
  const std::string bytes = file_bytes(good);
  REQUIRE(bytes.size() > 1000);

  SECTION("truncated") {
    const std::string path = (scratch / "truncated.ckpt").string();
    test_support::write_text(path, bytes.substr(0, bytes.size() / 2));
    require_refused(path, "is truncated: ");
    test_support::write_text(path, bytes.substr(0, 20));
    require_refused(path, "is truncated or its header is damaged");
  }
  SECTION("a byte flipped in the middle") {
    const std::string path = (scratch / "corrupted.ckpt").string();
    std::string damaged = bytes;
    damaged[damaged.size() / 2] = static_cast<char>(damaged[damaged.size() / 2] ^ 0x10);
    test_support::write_text(path, damaged);
    require_refused(path, "is corrupted: its payload checksum");
  }
  SECTION("a byte flipped in the header") {
    const std::string path = (scratch / "header.ckpt").string();
    std::string damaged = bytes;
    damaged[30] = static_cast<char>(damaged[30] ^ 0x01);  // inside the library version or the first policy name
    test_support::write_text(path, damaged);
    require_refused(path, "header");
  }
  SECTION("not a checkpoint") {
    const std::string path = (scratch / "text.ckpt").string();
    test_support::write_text(path, "t [s],ux [m]\n0,0\n");
    require_refused(path, "is not a sphshell checkpoint");
    require_refused((scratch / "missing.ckpt").string(), "cannot open");
  }
  SECTION("another format version") {
    const std::string path = (scratch / "version.ckpt").string();
    std::string other = bytes;
    other[8] = static_cast<char>(other[8] + 1);
    test_support::write_text(path, other);
    require_refused(path, "has format version " + std::to_string(solver::checkpoint::format_version + 1) + "; this library");
  }
  SECTION("a time step other than the one its identity lists (checksums resealed)") {
    REQUIRE(resealed(bytes) == bytes);  // resealing an unchanged file changes nothing
    // TIME: its tag, its size, then t0, the step count and Δt.
    const std::size_t time_step_at = bytes.find("TIME") + 4 + 3 * sizeof(std::uint64_t);
    J2Solver solver(j2_plate(), mild_steel);
    double time_step = 0.0;
    std::memcpy(&time_step, &bytes[time_step_at], sizeof time_step);
    REQUIRE(time_step == solver.time_step());
    time_step = std::nextafter(time_step, 1.0);
    std::string changed = bytes;
    std::memcpy(&changed[time_step_at], &time_step, sizeof time_step);
    const std::string path = (scratch / "time_step.ckpt").string();
    test_support::write_text(path, resealed(changed));
    check_load_refused(solver, path, {"its time step ", " s its identity lists"});
    // Refused after its state began to load: the solver is stopped.
    CHECK_THROWS_AS(solver.step(), Error);
  }
  SECTION("another policy combination") {
    CrackSolver solver(tearing_plate(), table_3_steel);
    const std::string path = (scratch / "lemaitre.ckpt").string();
    solver.save_checkpoint(path);
    require_refused(path, "another thickness rule (checkpoint: sphshell::thickness::Gauss<3>, this solver: "
                          "sphshell::thickness::Gauss<5>)");
  }
  SECTION("another model") {
    J2Solver other(ShellModel::rectangular_plate(0.2, 0.2, 13, 13, 0.004), mild_steel);
    const std::string path = (scratch / "model.ckpt").string();
    other.save_checkpoint(path);
    require_refused(path, "another model size: the particle count differ (checkpoint: 169, this solver: 121)");
    J2Solver thicker(ShellModel::rectangular_plate(0.2, 0.2, 11, 11, 0.005), mild_steel);
    thicker.save_checkpoint(path);
    require_refused(path, "another model: the particle thicknesses differ");
  }
  SECTION("another material or options that change results") {
    const std::string path = (scratch / "options.ckpt").string();
    J2Solver softer(j2_plate(), {210e9, 0.3, 200e6, 1e9});
    softer.save_checkpoint(path);
    require_refused(path, "another material: initial yield stress is 2e+08 there and 2.35e+08 in this solver");
    SolverOptions options;
    options.density = 7800.0;
    J2Solver lighter(j2_plate(), mild_steel, options);
    lighter.save_checkpoint(path);
    require_refused(path, "another set of options: density is 7800 there and 7850 in this solver");
    // The two options of the shell's transverse shear change every step's
    // forces too, though no array of the state depends on them.
    SolverOptions hourglass;
    hourglass.director_hourglass = true;
    J2Solver with_hourglass(j2_plate(), mild_steel, hourglass);
    with_hourglass.save_checkpoint(path);
    require_refused(path, "another set of options: director_hourglass is 1 there and 0 in this solver");
    SolverOptions gradients;
    gradients.transverse_shear = TransverseShear::shape_functions;
    J2Solver with_gradients(j2_plate(), mild_steel, gradients);
    with_gradients.save_checkpoint(path);
    require_refused(path,
                    "another set of options: transverse_shear (0: cell_edges, 1: shape_functions) is 1 there and 0 in "
                    "this solver");
  }
}

TEST_CASE("A probe file rewritten since the checkpoint is refused, not silently continued", "[checkpoint][errors]") {
  ScratchDirectory scratch("checkpoint_probe_rewritten");
  const std::string checkpoint = (scratch / "run.ckpt").string(), csv = (scratch / "w.csv").string();
  {
    J2Solver solver(j2_plate(), mild_steel);
    set_up_j2(solver);
    solver.add_particle_probe(csv, 60);
    steps(solver, 30);
    solver.save_checkpoint(checkpoint);
  }
  // Adding the probe before loading rewrites the file: its rows are gone.
  J2Solver solver(j2_plate(), mild_steel);
  set_up_j2(solver);
  solver.add_particle_probe(csv, 60);
  CHECK_THROWS_WITH(solver.load_checkpoint(checkpoint),
                    Catch::Contains("CSV probe '" + csv + "'") && Catch::Contains("add probes after restoring"));
  // A probe of something else on a recorded file is an Error too.
  J2Solver other = J2Solver::from_checkpoint(checkpoint, j2_plate(), mild_steel);
  CHECK_THROWS_WITH(other.add_particle_probe(csv, 61), Catch::Contains("particle probe of particle 60, not of particle 61"));
}

TEST_CASE("Periodic checkpoints: every N steps, atomically replaced", "[checkpoint][solver]") {
  ScratchDirectory scratch("checkpoint_periodic");
  SolverOptions options;
  options.checkpoint_path = (scratch / "periodic.ckpt").string();
  options.checkpoint_every_steps = 25;
  J2Solver solver(j2_plate(), mild_steel, options);
  set_up_j2(solver);
  steps(solver, 60);
  // The latest is that of step 50; no temporary is left behind.
  J2Solver restored = J2Solver::from_checkpoint(options.checkpoint_path, j2_plate(), mild_steel, options);
  CHECK(restored.steps() == 50);
  CHECK_FALSE(fs::exists(options.checkpoint_path + ".tmp"));
  // A write killed half-way leaves only a partial temporary: the checkpoint itself is whole.
  test_support::write_text(options.checkpoint_path + ".tmp", file_bytes(options.checkpoint_path).substr(0, 100));
  J2Solver again = J2Solver::from_checkpoint(options.checkpoint_path, j2_plate(), mild_steel, options);
  CHECK(again.steps() == 50);

  SolverOptions missing;
  missing.checkpoint_every_seconds = 60.0;
  CHECK_THROWS_WITH(J2Solver(j2_plate(), mild_steel, missing), Catch::Contains("checkpoint_path"));
  SolverOptions negative;
  negative.checkpoint_path = options.checkpoint_path;
  negative.checkpoint_every_steps = -1;
  CHECK_THROWS_WITH(J2Solver(j2_plate(), mild_steel, negative), Catch::Contains("checkpoint_every_steps"));
}

TEST_CASE("Periodic checkpoints by wall-clock time", "[checkpoint][solver]") {
  ScratchDirectory scratch("checkpoint_wall_clock");
  SolverOptions options;
  options.checkpoint_path = (scratch / "timed.ckpt").string();
  options.checkpoint_every_seconds = 1e-9;  // due after every step
  J2Solver solver(j2_plate(), mild_steel, options);
  set_up_j2(solver);
  steps(solver, 3);
  CHECK(J2Solver::from_checkpoint(options.checkpoint_path, j2_plate(), mild_steel).steps() == 3);
  // An hour apart: none in a few steps.
  options.checkpoint_path = (scratch / "hourly.ckpt").string();
  options.checkpoint_every_seconds = 3600.0;
  J2Solver hourly(j2_plate(), mild_steel, options);
  steps(hourly, 3);
  CHECK_FALSE(fs::exists(options.checkpoint_path));
}

// The child of the kill test: saves a checkpoint after every step until killed.
TEST_CASE("kill child: checkpoints after every step until killed", "[.kill_child]") {
  const char* path = std::getenv("SPHSHELL_CHECKPOINT_KILL_PATH");
  if (path == nullptr) return;
  SolverOptions options;
  options.checkpoint_path = path;
  options.checkpoint_every_steps = 1;
  J2Solver solver(j2_plate(), mild_steel, options);
  solver.clamp(solver.model().set("boundary"));
  solver.add_uniform_pressure(solver.model().all_particles(), 1e5);  // elastic: runs as long as it is let
  for (;;) solver.step();
}

TEST_CASE("Killed while writing checkpoints, the last one is whole", "[checkpoint][kill]") {
  ScratchDirectory scratch("checkpoint_kill");
  const std::string path = (scratch / "killed.ckpt").string();
  const std::string self = fs::read_symlink("/proc/self/exe").string();
  std::mt19937 random(20261202);
  std::uniform_int_distribution<int> delay_ms(30, 300);
  int loaded = 0, with_temporary = 0;
  for (int trial = 0; trial < 12; ++trial) {
    fs::remove(path);
    const pid_t child = fork();
    REQUIRE(child >= 0);
    if (child == 0) {
      setenv("SPHSHELL_CHECKPOINT_KILL_PATH", path.c_str(), 1);
      execl(self.c_str(), self.c_str(), "kill child: checkpoints after every step until killed", nullptr);
      _exit(127);
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(delay_ms(random)));
    kill(child, SIGKILL);
    int status = 0;
    waitpid(child, &status, 0);
    REQUIRE(WIFSIGNALED(status));
    with_temporary += fs::exists(path + ".tmp");
    if (!fs::exists(path)) continue;  // killed before its first checkpoint
    J2Solver restored(j2_plate(), mild_steel);
    REQUIRE_NOTHROW(restored.load_checkpoint(path));
    CHECK(restored.steps() > 0);
    ++loaded;
  }
  WARN("checkpoint kill test: " << loaded << " of 12 kills left a checkpoint, all loaded; " << with_temporary
                                << " left a partial temporary");
  CHECK(loaded > 0);
}

namespace {
// A stepper with a member and no save/load: such a solver steps as before,
// but cannot be checkpointed.
struct CountingStepper : stepper::CentralDifference {
  std::shared_ptr<std::atomic<long>> velocity_updates = std::make_shared<std::atomic<long>>(0);
  void advance_velocities(const stepper::StepContext& context, solver::ParticleState& state,
                          const solver::Inertia& inertia, const solver::ParticleForces& forces, std::size_t first,
                          std::size_t last) {
    *velocity_updates += static_cast<long>(last - first);
    CentralDifference::advance_velocities(context, state, inertia, forces, first, last);
  }
};
}  // namespace

TEST_CASE("Periodic checkpoints of a solver that cannot be checkpointed are refused when it is built",
          "[checkpoint][errors]") {
  using CountingSolver =
      Solver<approx::MLS<kernel::CubicSpline>, thickness::Gauss<3>, material::Elastic, crack::None, CountingStepper>;
  static_assert(!CountingSolver::can_checkpoint && J2Solver::can_checkpoint && CrackSolver::can_checkpoint);
  ScratchDirectory scratch("checkpoint_not_possible");
  SolverOptions options;
  options.checkpoint_path = (scratch / "never.ckpt").string();
  options.checkpoint_every_steps = 10;
  CHECK_THROWS_WITH(CountingSolver(j2_plate(), {210e9, 0.3}, options),
                    Catch::Contains("checkpoint_path") && Catch::Contains("periodic checkpoints need policies"));
  CountingSolver solver(j2_plate(), {210e9, 0.3});
  solver.step();
  CHECK(*solver.integrator().velocity_updates == static_cast<long>(solver.particle_count()));
}
