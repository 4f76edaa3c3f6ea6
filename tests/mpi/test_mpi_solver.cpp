// The distributed step against the serial Solver (docs/distributed.md): the
// same model run by sphshell::Solver in one process (on every rank, as the
// independent reference) and by mpi::DistributedSolver over the ranks; the
// owned particles' positions, directors, velocities and angular velocities
// must be bitwise the serial ones, the energies within 1e-12 relative.
#include <sphshell/approx/mls.hpp>
#include <sphshell/kernel/cubic_spline.hpp>
#include <sphshell/material/elastic.hpp>
#include <sphshell/material/cowper_symonds.hpp>
#include <sphshell/material/j2_plasticity.hpp>
#include <sphshell/material/johnson_cook.hpp>
#include <sphshell/mpi/distributed_solver.hpp>
#include <sphshell/shell/spherical_cap_ogrid.hpp>
#include <sphshell/solver.hpp>
#include <sphshell/thickness/gauss.hpp>

#include "mpi_test_support.hpp"

#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <functional>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#ifdef _OPENMP
#include <omp.h>
#endif

using namespace sphshell;

namespace {

using Approximation = approx::MLS<kernel::CubicSpline>;
template <class Material>
using Serial = Solver<Approximation, thickness::Gauss<3>, Material>;
template <class Material>
using Distributed = mpi::DistributedSolver<Approximation, thickness::Gauss<3>, Material>;

// How many components of two fields differ in their bits.
double relative(double a, double b) {
  const double scale = std::max(std::abs(a), std::abs(b));
  return scale == 0.0 ? 0.0 : std::abs(a - b) / scale;
}

// One run's set-up, applied alike to either solver (global ids, set names).
template <class S>
using Setup = std::function<void(S&)>;

template <class Material>
void compare_runs(const std::string& label, const ShellModel& model, const typename Material::Parameters& parameters,
                  const SolverOptions& options, long steps, const Setup<Serial<Material>>& setup_serial,
                  const Setup<Distributed<Material>>& setup_distributed, double* plastic_strain = nullptr) {
  const mpi::Communicator comm;
  Serial<Material> serial(model, parameters, options);
  setup_serial(serial);
  Distributed<Material> distributed(comm, model, parameters, options);
  setup_distributed(distributed);
  CHECK(distributed.time_step() == serial.time_step());
  for (long n = 0; n < steps; ++n) {
    serial.step();
    distributed.step();
  }
  const std::size_t positions = mpi_test::differing_components(distributed.positions(), serial.positions());
  const std::size_t directors = mpi_test::differing_components(distributed.directors(), serial.directors());
  const std::size_t velocities = mpi_test::differing_components(distributed.velocities(), serial.velocities());
  const std::size_t angular = mpi_test::differing_components(distributed.angular_velocities(), serial.angular_velocities());
  const EnergyReport e = distributed.energy(), s = serial.energy();
  INFO(label << " on " << comm.size() << " ranks, " << steps << " steps; rank " << comm.rank() << " owns "
             << distributed.layout().owned_count() << " particles, " << distributed.layout().ghost_count()
             << " ghosts, " << distributed.layout().redundant_point_count() << " redundant points");
  CHECK(positions == 0);
  CHECK(directors == 0);
  CHECK(velocities == 0);
  CHECK(angular == 0);
  // The motion must be real: a test of equal zeros proves nothing.
  double largest_displacement = 0.0;
  for (std::size_t i = 0; i < model.particle_count(); ++i)
    largest_displacement = std::max(largest_displacement, serial.displacement(static_cast<int>(i)).norm());
  CHECK(largest_displacement > 1e-6);
  CHECK(s.kinetic > 0.0);
  CHECK(relative(e.kinetic, s.kinetic) < 1e-12);
  CHECK(relative(e.internal, s.internal) < 1e-12);
  CHECK(relative(e.elastic, s.elastic) < 1e-12);
  CHECK(relative(e.external_work, s.external_work) < 1e-12);
  CHECK(relative(e.damping_work, s.damping_work) < 1e-12);
  CHECK(std::abs(e.balance() - s.balance()) < 1e-12 * std::max(s.external_work, s.kinetic));
  if (comm.is_root())
    WARN(label << " on " << comm.size() << " ranks: bitwise equal over " << steps
               << " steps; energy differences (relative) kinetic " << relative(e.kinetic, s.kinetic) << ", internal "
               << relative(e.internal, s.internal) << ", external " << relative(e.external_work, s.external_work));
  if (plastic_strain) {
    double largest = 0.0;
    for (std::size_t p = 0; p < model.stress_point_count(); ++p)
      largest = std::max(largest, serial.equivalent_plastic_strain(static_cast<int>(p), 0));
    *plastic_strain = largest;
  }
}

// The paper's plate (L = 0.5 m, d = 0.01 m, steel), 21 × 21, clamped, under
// a step pressure.
ShellModel plate() { return ShellModel::rectangular_plate(0.5, 0.5, 21, 21, 0.01); }
constexpr double steel_E = 210e9, steel_nu = 0.3, steel_yield = 250e6, steel_Ep = 1e9;

// Both solvers take sets of ids or set names.
template <class Material>
void clamped_pressure(Serial<Material>& solver, double pressure) {
  solver.clamp("boundary");
  solver.add_uniform_pressure(solver.model().all_particles(), pressure);
}
template <class Material>
void clamped_pressure(Distributed<Material>& solver, double pressure) {
  solver.clamp("boundary");
  solver.add_uniform_pressure(solver.model().all_particles(), pressure);
}

}  // namespace

TEST_CASE("Distributed plate, elastic: bitwise the serial Solver", "[mpi][solver]") {
  SolverOptions options;
  options.density = 7850.0;
  compare_runs<material::Elastic>(
      "plate 21x21 elastic", plate(), {steel_E, steel_nu}, options, 300,
      [](Serial<material::Elastic>& s) { clamped_pressure(s, 5e5); },
      [](Distributed<material::Elastic>& s) { clamped_pressure(s, 5e5); });
}

TEST_CASE("Distributed plate, J2 plasticity: bitwise the serial Solver", "[mpi][solver]") {
  SolverOptions options;
  options.density = 7850.0;
  double plastic = 0.0;
  compare_runs<material::J2Plasticity>(
      "plate 21x21 J2", plate(), {steel_E, steel_nu, steel_yield, steel_Ep}, options, 300,
      [](Serial<material::J2Plasticity>& s) { clamped_pressure(s, 5e6); },
      [](Distributed<material::J2Plasticity>& s) { clamped_pressure(s, 5e6); }, &plastic);
  CHECK(plastic > 0.0);  // the plate yielded
}

TEST_CASE("Distributed plate, rate-dependent laws: bitwise the serial Solver", "[mpi][solver][rate]") {
  // The step's time step reaches the laws on every rank as it does serially:
  // Johnson-Cook with adiabatic heating, and Cowper-Symonds.
  SolverOptions options;
  options.density = 7850.0;
  material::JohnsonCook::Parameters johnson_cook{steel_E, steel_nu, steel_yield, 500e6, 0.3, 0.014, 1.0, 1.0,
                                                 293.0, 1793.0, 293.0};
  johnson_cook.taylor_quinney = 0.9;
  johnson_cook.density = 7850.0;
  johnson_cook.specific_heat = 477.0;
  johnson_cook.D1 = 10.0;  // no failure within the run
  double plastic = 0.0;
  compare_runs<material::JohnsonCook>(
      "plate 21x21 Johnson-Cook", plate(), johnson_cook, options, 300,
      [](Serial<material::JohnsonCook>& s) { clamped_pressure(s, 5e6); },
      [](Distributed<material::JohnsonCook>& s) { clamped_pressure(s, 5e6); }, &plastic);
  CHECK(plastic > 0.0);
  plastic = 0.0;
  compare_runs<material::CowperSymonds>(
      "plate 21x21 Cowper-Symonds", plate(), {steel_E, steel_nu, steel_yield, steel_Ep, 40.4, 5.0}, options, 300,
      [](Serial<material::CowperSymonds>& s) { clamped_pressure(s, 5e6); },
      [](Distributed<material::CowperSymonds>& s) { clamped_pressure(s, 5e6); }, &plastic);
  CHECK(plastic > 0.0);
}

TEST_CASE("Distributed conditions and loads of every kind, by set name: bitwise the serial Solver",
          "[mpi][solver]") {
  // The serial Solver takes the sets; the distributed one their names, for
  // every condition and load that has a set.
  const ShellModel model = plate();
  SolverOptions options;
  options.density = 7850.0;
  const auto ramp = [](const Vector3& X, double) { return 2e5 * (1.0 + X.x()); };
  compare_runs<material::Elastic>(
      "plate 21x21 every condition and load", model, {steel_E, steel_nu}, options, 200,
      [&](Serial<material::Elastic>& s) {
        s.symmetry_plane(model.set("x_min"), Vector3::UnitX());
        s.symmetry_plane(model.set("y_min"), Vector3::UnitY());
        s.simply_support_hard(model.set("x_max"), Vector3::UnitY());
        s.fix_translation(model.set("y_max"), Vector3::UnitZ());
        s.fix_rotation(model.set("y_max"), Vector3::UnitX());
        s.add_pressure(model.set("boundary"), ramp);
        s.add_uniform_pressure(model.all_particles(), 1e5);
        s.add_point_force(model.set("centre"), Vector3(0.0, 0.0, -2e3));
        s.add_point_moment(model.set("centre"), Vector3(50.0, 0.0, 0.0));
        s.add_gravity(model.set("boundary"), Vector3(0.0, 0.0, -9.81));
      },
      [&](Distributed<material::Elastic>& s) {
        s.symmetry_plane("x_min", Vector3::UnitX());
        s.symmetry_plane("y_min", Vector3::UnitY());
        s.simply_support_hard("x_max", Vector3::UnitY());
        s.fix_translation("y_max", Vector3::UnitZ());
        s.fix_rotation("y_max", Vector3::UnitX());
        s.add_pressure("boundary", ramp);
        s.add_uniform_pressure(model.all_particles(), 1e5);
        s.add_point_force("centre", Vector3(0.0, 0.0, -2e3));
        s.add_point_moment("centre", Vector3(50.0, 0.0, 0.0));
        s.add_gravity("boundary", Vector3(0.0, 0.0, -9.81));
      });
}

TEST_CASE("Distributed accessors refuse indices and fields out of range", "[mpi][solver][errors]") {
  const mpi::Communicator comm;
  SolverOptions options;
  options.density = 7850.0;
  const ShellModel model = plate();
  Distributed<material::Elastic> distributed(comm, model, {steel_E, steel_nu}, options);
  const int particles = static_cast<int>(model.particle_count());
  CHECK_FALSE(distributed.is_fragment(particles - 1));
  CHECK_THROWS_WITH(distributed.is_fragment(-1), Catch::Contains("particle index"));
  CHECK_THROWS_WITH(distributed.is_fragment(particles), Catch::Contains("particle index"));
  const std::size_t local = distributed.layout().local_count();
  CHECK(distributed.global_id(local - 1) >= 0);
  CHECK_THROWS_WITH(distributed.global_id(local), Catch::Contains("local particle index"));
  // Every rank is refused together (none is left waiting in the gather).
  CHECK_THROWS_WITH(distributed.gathered({}), Catch::Contains("local field size"));
  CHECK(distributed.gathered(std::vector<Vector3>(local, Vector3::UnitX())).size() == model.particle_count());
}

TEST_CASE("Distributed O-grid cap, J2 plasticity: bitwise the serial Solver", "[mpi][solver]") {
  // The paper's cap (Figs 6-7, aluminium, 600 psi inward) on a coarse O-grid.
  const double radius = 0.5657, half_angle = 26.67 * M_PI / 180.0, thickness = 0.010414;
  const ShellModel model = spherical_cap_ogrid(radius, half_angle, 8, thickness);
  SolverOptions options;
  options.density = 2618.0;
  const double E = 72.4e9, Et = 1.448e9;
  double plastic = 0.0;
  auto setup = [](auto& s) { clamped_pressure(s, 600.0 * 6894.757); };
  compare_runs<material::J2Plasticity>("O-grid cap J2", model, {E, 0.3, 165.5e6, E * Et / (E - Et)}, options, 300,
                                       setup, setup, &plastic);
  CHECK(plastic > 0.0);
}

TEST_CASE("Distributed O-grid cap with the director hourglass: bitwise the serial Solver", "[mpi][solver]") {
  // The hourglass term of each stress point's cell (shell/cell_hourglass.hpp)
  // is kept per row in a rank's subset, like the tied shear; the O-grid's
  // cells are not parallelograms, so its weights are not all ±1/4.
  const double radius = 0.5657, half_angle = 26.67 * M_PI / 180.0, thickness = 0.010414;
  const ShellModel model = spherical_cap_ogrid(radius, half_angle, 8, thickness);
  SolverOptions options;
  options.density = 2618.0;
  options.director_hourglass = true;
  auto setup = [](auto& s) { clamped_pressure(s, 600.0 * 6894.757); };
  compare_runs<material::Elastic>("O-grid cap, director hourglass", model, {72.4e9, 0.3}, options, 300, setup,
                                  setup);
}

TEST_CASE("Distributed plate, 2 OpenMP threads per rank: still bitwise", "[mpi][solver]") {
#ifdef _OPENMP
  const int threads = omp_get_max_threads();
  omp_set_num_threads(2);
#endif
  SolverOptions options;
  options.density = 7850.0;
  compare_runs<material::J2Plasticity>(
      "plate 21x21 J2, 2 threads per rank", plate(), {steel_E, steel_nu, steel_yield, steel_Ep}, options, 200,
      [](Serial<material::J2Plasticity>& s) {
#ifdef _OPENMP
        omp_set_num_threads(1);  // the reference runs on one thread
#endif
        clamped_pressure(s, 5e6);
      },
      [](Distributed<material::J2Plasticity>& s) { clamped_pressure(s, 5e6); });
#ifdef _OPENMP
  omp_set_num_threads(threads);
#endif
}

TEST_CASE("Distributed solver: an Error on one rank stops every rank with the serial message", "[mpi][solver]") {
  const mpi::Communicator comm;
  SolverOptions options;
  options.density = 7850.0;
  const ShellModel model = plate();
  // A pressure that turns NaN at the last particle (owned by the last rank)
  // from step 3 on.
  const Vector3 last = model.particle_position.back();
  auto pressure = [last](const Vector3& x, double t) {
    return (x - last).norm() < 1e-12 && t > 2.5e-7 * 2 ? std::nan("") : 1e5;
  };
  Serial<material::Elastic> serial(model, {steel_E, steel_nu}, options);
  serial.add_pressure(model.all_particles(), pressure);
  std::string serial_message;
  try {
    for (int n = 0; n < 20; ++n) serial.step();
  } catch (const Error& error) {
    serial_message = error.what();
  }
  REQUIRE(!serial_message.empty());
  Distributed<material::Elastic> distributed(comm, model, {steel_E, steel_nu}, options);
  distributed.add_pressure(model.all_particles(), pressure);
  std::string message;
  try {
    for (int n = 0; n < 20; ++n) distributed.step();
  } catch (const Error& error) {
    message = error.what();
  }
  CHECK(message == serial_message);
  // Every rank stopped; the next step refuses with the same latch.
  CHECK_THROWS_AS(distributed.step(), Error);

  // An unknown set name: the same Error on every rank.
  Distributed<material::Elastic> other(comm, model, {steel_E, steel_nu}, options);
  std::string unknown;
  try {
    other.clamp("no such set");
  } catch (const Error& error) {
    unknown = error.what();
  }
  CHECK(unknown.find("no such set") != std::string::npos);
  // A set member out of range: the Solver's message.
  std::string out_of_range;
  try {
    other.clamp(ParticleSet{0, static_cast<int>(model.particle_count())});
  } catch (const Error& error) {
    out_of_range = error.what();
  }
  CHECK(out_of_range.find("out of range") != std::string::npos);
}

TEST_CASE("Distributed checkpoint: a restart continues bitwise, files of another save or rank count are an Error",
          "[mpi][solver][checkpoint]") {
  const mpi::Communicator comm;
  using J2 = material::J2Plasticity;
  // A low yield stress, so that the plastic states the file must carry change within the run.
  const J2::Parameters steel{steel_E, steel_nu, 20e6, steel_Ep};
  SolverOptions options;
  options.density = 7850.0;
  const ShellModel model = plate();
  namespace fs = std::filesystem;
  const std::string folder =
      (fs::temp_directory_path() / ("sphshell_test_mpi_checkpoint_np" + std::to_string(comm.size()))).string();
  if (comm.is_root()) fs::create_directories(folder);
  comm.all_gather(0);  // the folder exists before any rank writes
  const std::string first = folder + "/at40", second = folder + "/at80";

  // The run that saves: 40 steps, save, 40 steps, save, 40 steps.
  Distributed<J2> original(comm, model, steel, options);
  clamped_pressure(original, 2e6);
  for (int n = 0; n < 40; ++n) original.step();
  original.save_checkpoint(first);
  for (int n = 0; n < 40; ++n) original.step();
  original.save_checkpoint(second);
  for (int n = 0; n < 40; ++n) original.step();
  const std::vector<Vector3> positions = original.positions(), velocities = original.velocities();
  const EnergyReport energy = original.energy();

  // A fresh solver from the first file continues bitwise (80 more steps).
  Distributed<J2> restarted(comm, model, steel, options);
  clamped_pressure(restarted, 2e6);
  restarted.load_checkpoint(first);
  CHECK(restarted.steps() == 40);
  for (int n = 0; n < 80; ++n) restarted.step();
  CHECK(restarted.steps() == original.steps());
  CHECK(mpi_test::differing_components(restarted.positions(), positions) == 0);
  CHECK(mpi_test::differing_components(restarted.velocities(), velocities) == 0);
  const EnergyReport again = restarted.energy();
  CHECK(again.kinetic == energy.kinetic);
  CHECK(again.internal == energy.internal);
  CHECK(again.external_work == energy.external_work);
  CHECK(energy.plastic_dissipation > 0.01 * energy.internal);  // the plastic states were restored too

  // A file that does not exist: an Error on every rank, the solver still usable.
  Distributed<J2> fresh(comm, model, steel, options);
  clamped_pressure(fresh, 2e6);
  CHECK_THROWS_WITH(fresh.load_checkpoint(folder + "/missing"), Catch::Contains("cannot open"));
  CHECK_NOTHROW(fresh.step());

  if (comm.size() > 1) {
    // The files of one rank count loaded on another (each rank alone here).
    const mpi::Communicator alone(MPI_COMM_SELF);
    Distributed<J2> single(alone, model, steel, options);
    CHECK_THROWS_WITH(single.load_checkpoint(first),
                      Catch::Contains("rank count differ (checkpoint: " + std::to_string(comm.size()) +
                                      ", this solver: 1)"));
    // Rank files of different saves: the last rank's file of the first save
    // replaced by its file of the second.
    comm.all_gather(0);
    if (comm.is_root())
      fs::copy_file(second + ".rank" + std::to_string(comm.size() - 1),
                    first + ".rank" + std::to_string(comm.size() - 1), fs::copy_options::overwrite_existing);
    comm.all_gather(0);
    Distributed<J2> mixed(comm, model, steel, options);
    clamped_pressure(mixed, 2e6);
    CHECK_THROWS_WITH(mixed.load_checkpoint(first), Catch::Contains("were written by different saves"));
    CHECK_THROWS_WITH(mixed.step(), Catch::Contains("loading a checkpoint failed part-way"));
  }
  comm.all_gather(0);
  if (comm.is_root()) fs::remove_all(folder);
}

TEST_CASE("Distributed progress line: rank 0 writes the Solver's lines with the reduced books", "[mpi][solver]") {
  const mpi::Communicator comm;
  std::ostringstream serial_lines, lines;
  SolverOptions options;
  options.density = 7850.0;
  options.progress_interval = 10;
  options.progress_stream = &serial_lines;
  Serial<material::Elastic> serial(plate(), {steel_E, steel_nu}, options);
  clamped_pressure(serial, 5e5);
  options.progress_stream = &lines;
  Distributed<material::Elastic> distributed(comm, plate(), {steel_E, steel_nu}, options);
  clamped_pressure(distributed, 5e5);
  const double end = 50.5 * serial.time_step();
  serial.run_until(end);
  distributed.run_until(end);
  // Each line without its wall-clock part (rate and ETA): step, time, share, books.
  auto without_clock = [](const std::string& text) {
    std::istringstream in(text);
    std::string line, kept;
    while (std::getline(in, line)) {
      const std::size_t clock = line.find(" %)");
      const std::size_t books = line.find("  kinetic");
      kept += line.substr(0, clock + 3) + line.substr(books) + "\n";
    }
    return kept;
  };
  const std::string written = lines.str();
  if (comm.is_root()) {
    REQUIRE(std::count(written.begin(), written.end(), '\n') == 5);
    CHECK(written.find("step 50  t = ") != std::string::npos);
    // The distributed books are the serial ones to within their rounding
    // (1e-12 relative, printed to 4 digits): the lines agree.
    CHECK(without_clock(written) == without_clock(serial_lines.str()));
  } else {
    CHECK(written.empty());
  }
}

TEST_CASE("Distributed prescribed motions added mid-run: the serial run, and the serial Error on a jump",
          "[mpi][solver]") {
  const mpi::Communicator comm;
  SolverOptions options;
  options.density = 7850.0;
  const ShellModel model = plate();
  Serial<material::Elastic> serial(model, {steel_E, steel_nu}, options);
  Distributed<material::Elastic> distributed(comm, model, {steel_E, steel_nu}, options);
  serial.clamp(model.set("x_min"));
  distributed.clamp("x_min");
  // At rest for 20 steps, then the far edge pulled from where it is (zero
  // displacement) and a transverse velocity on the middle row.
  for (int n = 0; n < 20; ++n) {
    serial.step();
    distributed.step();
  }
  const double t1 = serial.time();
  auto pull = [t1](const Vector3&, double t) { return Vector3(0.5 * (t - t1), 0.0, 0.0); };
  auto lift = [](const Vector3&, double) { return Vector3(0.0, 0.0, 0.3); };
  ParticleSet middle;
  for (std::size_t i = 0; i < model.particle_count(); ++i)
    if (std::abs(model.particle_position[i].y() - 0.25) < 1e-9 && model.particle_position[i].x() > 0.1 &&
        model.particle_position[i].x() < 0.4)
      middle.push_back(static_cast<int>(i));
  REQUIRE(!middle.empty());
  serial.prescribe_displacement(model.set("x_max"), pull);
  distributed.prescribe_displacement("x_max", pull);
  serial.prescribe_velocity(middle, lift);
  distributed.prescribe_velocity(middle, lift);
  for (int n = 0; n < 40; ++n) {
    serial.step();
    distributed.step();
  }
  CHECK(mpi_test::differing_components(distributed.positions(), serial.positions()) == 0);
  CHECK(mpi_test::differing_components(distributed.velocities(), serial.velocities()) == 0);
  CHECK(serial.displacement(model.set("x_max").front()).x() > 0.0);

  // A displacement that does not continue from the particles' own (the pulled
  // edge is not at 1 mm): the serial message on every rank, naming the first
  // particle of the set.
  auto jump = [](const Vector3&, double) { return Vector3(1e-3, 0.0, 0.0); };
  std::string serial_message, message;
  try {
    serial.prescribe_displacement(model.set("y_max"), jump);
  } catch (const Error& error) {
    serial_message = error.what();
  }
  try {
    distributed.prescribe_displacement("y_max", jump);
  } catch (const Error& error) {
    message = error.what();
  }
  REQUIRE(!serial_message.empty());
  CHECK(message == serial_message);
}

TEST_CASE("Distributed stress queries and run observer: the serial Solver's values", "[mpi][solver]") {
  const mpi::Communicator comm;
  SolverOptions options;
  options.density = 7850.0;
  const ShellModel model = plate();
  Serial<material::Elastic> serial(model, {steel_E, steel_nu}, options);
  Distributed<material::Elastic> distributed(comm, model, {steel_E, steel_nu}, options);
  clamped_pressure(serial, 5e5);
  clamped_pressure(distributed, 5e5);
  const double end = 30.0 * serial.time_step();  // 30 steps: the run stops within half a step of it
  long serial_calls = 0, calls = 0;
  serial.run_until(end, [&](const Serial<material::Elastic>&) { ++serial_calls; });
  distributed.run_until(end, [&](const Distributed<material::Elastic>& solver) {
    ++calls;
    CHECK(solver.steps() == calls);
  });
  CHECK(calls == 30);
  CHECK(calls == serial_calls);
  std::size_t differing = 0;
  double largest_moment = 0.0;
  for (std::size_t q = 0; q < model.stress_point_count(); ++q) {
    const int p = static_cast<int>(q);
    const StressVoigt n = distributed.membrane_force(p), m = distributed.bending_moment(p);
    for (int c = 0; c < 3; ++c) {
      differing += std::memcmp(&n[c], &serial.membrane_force(p)[c], sizeof(double)) != 0;
      differing += std::memcmp(&m[c], &serial.bending_moment(p)[c], sizeof(double)) != 0;
    }
    for (int k = 0; k < 3; ++k) {
      const double s = distributed.equivalent_stress(p, k), reference = serial.equivalent_stress(p, k);
      differing += std::memcmp(&s, &reference, sizeof(double)) != 0;
    }
    CHECK(distributed.is_removed(p) == serial.is_removed(p));
    largest_moment = std::max(largest_moment, m.norm());
  }
  CHECK(differing == 0);
  CHECK(largest_moment > 0.0);  // the plate bends: equal zeros would prove nothing
  CHECK_THROWS_WITH(distributed.membrane_force(static_cast<int>(model.stress_point_count())),
                    Catch::Contains("stress point index"));
  CHECK_THROWS_WITH(distributed.equivalent_stress(0, 3), Catch::Contains("thickness output point"));
}

TEST_CASE("Distributed static solution by dynamic relaxation: bitwise the serial Solver, Mindlin's deflection",
          "[mpi][solver][static]") {
  const mpi::Communicator comm;
  SolverOptions options;
  options.density = 7850.0;
  const ShellModel model = plate();
  const double q = 1e4, L = 0.5, d = 0.01;
  const double D = steel_E * d * d * d / (12.0 * (1.0 - steel_nu * steel_nu));
  const int centre = model.set("centre")[0];
  solver::StaticParameters parameters;
  parameters.progress_interval = 0;
  SECTION("elastic, one load step") {
    Serial<material::Elastic> serial(model, {steel_E, steel_nu}, options);
    Distributed<material::Elastic> distributed(comm, model, {steel_E, steel_nu}, options);
    clamped_pressure(serial, q);
    clamped_pressure(distributed, q);
    const solver::StaticResult s = serial.solve_static(parameters);
    long observed = 0;
    const solver::StaticResult r =
        distributed.solve_static(parameters, [&](const solver::StaticIteration&) { ++observed; });
    CHECK(r.iterations == s.iterations);
    CHECK(observed == r.iterations + 1);  // the start of the load step, then each relaxation step
    CHECK(std::memcmp(&r.residual, &s.residual, sizeof(double)) == 0);
    CHECK(mpi_test::differing_components(distributed.positions(), serial.positions()) == 0);
    CHECK(mpi_test::differing_components(distributed.directors(), serial.directors()) == 0);
    // Clamped square plate, L/d = 50 (Mindlin: w D/(q L^4) = 0.0012754), within the 21 x 21 discretisation error.
    const double coefficient = -serial.displacement(centre).z() * D / (q * L * L * L * L);
    CHECK(coefficient == Approx(0.0012754).epsilon(0.04));
    // At rest in equilibrium on every rank, the books restarted there.
    CHECK(distributed.energy().kinetic == 0.0);
    CHECK(relative(distributed.energy().elastic, serial.energy().elastic) < 1e-12);
  }
  SECTION("J2 plasticity, two load steps (a path)") {
    // Bitwise agreement along a plastic path, no figure: a coarser grid of the
    // same plate (the same stresses; fewer particles and relaxation steps).
    const ShellModel coarse = ShellModel::rectangular_plate(0.5, 0.5, 15, 15, 0.01);
    const material::J2Plasticity::Parameters law{steel_E, steel_nu, steel_yield, steel_Ep};
    Serial<material::J2Plasticity> serial(coarse, law, options);
    Distributed<material::J2Plasticity> distributed(comm, coarse, law, options);
    clamped_pressure(serial, 2.5e6);
    clamped_pressure(distributed, 2.5e6);
    parameters.load_factors = {0.5, 1.0};
    const solver::StaticResult s = serial.solve_static(parameters);
    const solver::StaticResult r = distributed.solve_static(parameters);
    CHECK(r.iterations == s.iterations);
    CHECK(mpi_test::differing_components(distributed.positions(), serial.positions()) == 0);
    CHECK(mpi_test::differing_components(distributed.directors(), serial.directors()) == 0);
    double largest = 0.0;
    for (std::size_t p = 0; p < coarse.stress_point_count(); ++p)
      largest = std::max(largest, serial.equivalent_plastic_strain(static_cast<int>(p), 0));
    CHECK(largest > 0.0);  // the path is plastic: an elastic answer would prove nothing
  }
}

TEST_CASE("Distributed static solution: Errors on every rank, the solver left as it was", "[mpi][solver][static]") {
  const mpi::Communicator comm;
  SolverOptions options;
  options.density = 7850.0;
  const ShellModel model = plate();
  auto message_of = [](auto&& body) {
    try {
      body();
    } catch (const Error& error) {
      return std::string(error.what());
    }
    return std::string();
  };
  Distributed<material::Elastic> distributed(comm, model, {steel_E, steel_nu}, options);
  distributed.add_uniform_pressure(model.all_particles(), 1e4);
  // No supports: the free rigid-body modes are found on the whole model.
  CHECK(message_of([&] { distributed.solve_static(); }).find("free rigid-body mode") != std::string::npos);
  distributed.clamp("boundary");
  solver::StaticParameters newton;
  newton.mass = solver::StaticMass::tangent;
  CHECK(message_of([&] { distributed.solve_static(newton); }).find("StaticMass::particle_bound") != std::string::npos);
  // A load function that throws on the last rank only ends the solve on every rank with its message.
  const int last = comm.size() - 1;
  Distributed<material::Elastic> throwing(comm, model, {steel_E, steel_nu}, options);
  throwing.clamp("boundary");
  throwing.add_pressure(model.all_particles(), [&](const Vector3&, double) -> double {
    if (comm.rank() == last) throw std::runtime_error("pressure table ends here");
    return 1e4;
  });
  CHECK(message_of([&] { throwing.solve_static(); }).find("pressure table ends here") != std::string::npos);
  // Left as it was: at rest in the reference configuration.
  double largest = 0.0;
  for (std::size_t i = 0; i < model.particle_count(); ++i)
    largest = std::max(largest, throwing.displacement(static_cast<int>(i)).norm());
  CHECK(largest == 0.0);
}
