// Rigid bodies and the shell's contact with itself in a distributed run
// (contact/solver_contact.hpp) against the serial Solver: the same model run by sphshell::Solver in one process (on
// every rank, as the independent reference) and by the distributed Solver
// over the ranks. The particles' positions, directors and velocities, the
// bodies' state (position, velocities, contact force, moment, impulse,
// contact count) and the contact's energy terms must be bitwise the serial
// ones; the shell's energies within 1e-12 relative (exact sums over the
// ranks against the serial loop's, solver/energy_ledger.hpp). A body's probe
// and frames are written once, by rank 0, and are the serial run's bytes; a
// restart continues the probe's file.
// Refused input is the serial Error on every rank, with nothing written.
#include <sphshell/approx/mls.hpp>
#include <sphshell/contact/all.hpp>
#include <sphshell/kernel/cubic_spline.hpp>
#include <sphshell/material/elastic.hpp>
#include <sphshell/material/j2_plasticity.hpp>
#include <sphshell/mpi/distributed_solver.hpp>
#include <sphshell/solver.hpp>
#include <sphshell/thickness/gauss.hpp>

#include "mpi_test_support.hpp"

#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iterator>
#include <sstream>
#include <string>
#include <vector>

using namespace sphshell;

namespace {

using Approximation = approx::MLS<kernel::CubicSpline>;
template <class Material>
using Serial = Solver<Approximation, thickness::Gauss<3>, Material>;
template <class Material>
using Distributed = mpi::DistributedSolver<Approximation, thickness::Gauss<3>, Material>;

constexpr double pi = 3.14159265358979323846;
constexpr double steel_density = 7850.0, steel_E = 210e9, steel_nu = 0.3, steel_yield = 250e6, steel_Ep = 1e9;

// A 0.2 m square steel plate, 2 mm thick, clamped on its boundary.
constexpr double plate_side = 0.2, plate_thickness = 2e-3;
ShellModel plate(int n) { return ShellModel::rectangular_plate(plate_side, plate_side, n, n, plate_thickness); }
SolverOptions plate_options() {
  SolverOptions options;
  options.density = steel_density;
  return options;
}

// A free steel sphere of radius 30 mm (several particles touch it at once),
// its surface `gap` above the plate's upper face over the point (x, y), with
// gravity.
constexpr double sphere_radius = 0.03;
const double sphere_mass = steel_density * 4.0 / 3.0 * pi * sphere_radius * sphere_radius * sphere_radius;
using FreeSphere = contact::RigidBody<contact::Sphere, contact::Free>;
FreeSphere sphere_at(double x, double y, double gap, const Vector3& velocity) {
  contact::RigidKinematics start;
  start.position = Vector3(x, y, sphere_radius + 0.5 * plate_thickness + gap);
  start.velocity = velocity;
  const double inertia = 0.4 * sphere_mass * sphere_radius * sphere_radius;
  return FreeSphere(contact::Sphere(sphere_radius),
                    contact::Free({sphere_mass, Vector3::Constant(inertia), Vector3(0.0, 0.0, -9.81)}), start);
}

// A wall above the plate, facing down and slightly tilted, so that it first
// touches the plate at its corner (x, y) = (L, L), `gap` above the upper face
// there; it moves down, its speed ramped up to `speed` over `ramp_time`.
struct WallVelocity {
  double speed, ramp_time;
  Vector3 operator()(double t) const { return Vector3(0.0, 0.0, -speed * std::min(1.0, t / ramp_time)); }
};
auto pressing_wall(double gap, double speed, double ramp_time) {
  contact::RigidKinematics corner;
  corner.position = Vector3(plate_side, plate_side, 0.5 * plate_thickness + gap);
  const Vector3 downward_normal = -Vector3(3e-4, 1e-4, 1.0).normalized();
  return contact::RigidBody(contact::Plane(downward_normal), contact::prescribed(WallVelocity{speed, ramp_time}),
                            corner);
}

// Two n × n square plates of side `side` in the planes z = 0 and z = gap,
// directors +z, one model: the sets "upper", "lower" and "lower_edge".
ShellModel two_plates(int n, double side, double gap, double thickness) {
  std::vector<Vector3> positions, normals;
  std::vector<Quad> quads;
  const double spacing = side / (n - 1);
  for (int sheet = 0; sheet < 2; ++sheet) {
    const int base = sheet * n * n;
    for (int i = 0; i < n; ++i)
      for (int j = 0; j < n; ++j) {
        positions.emplace_back(i * spacing, j * spacing, sheet * gap);
        normals.push_back(Vector3::UnitZ());
      }
    for (int i = 0; i + 1 < n; ++i)
      for (int j = 0; j + 1 < n; ++j)
        quads.push_back({base + i * n + j, base + (i + 1) * n + j, base + (i + 1) * n + j + 1, base + i * n + j + 1});
  }
  ShellModel model = ShellModel::from_quads(positions, normals, quads, thickness);
  const double edge = 1e-3 * spacing;
  model.define_set("upper", [gap](const Vector3& X) { return X.z() > 0.5 * gap; });
  model.define_set("lower", [gap](const Vector3& X) { return X.z() < 0.5 * gap; });
  model.define_set("lower_edge", [=](const Vector3& X) {
    return X.z() < 0.5 * gap &&
           (X.x() < edge || X.y() < edge || X.x() > side - edge || X.y() > side - edge);
  });
  return model;
}

bool same_bits(double a, double b) { return std::memcmp(&a, &b, sizeof(double)) == 0; }
bool same_bits(const Vector3& a, const Vector3& b) {
  return same_bits(a.x(), b.x()) && same_bits(a.y(), b.y()) && same_bits(a.z(), b.z());
}
double relative(double a, double b) {
  const double scale = std::max(std::abs(a), std::abs(b));
  return scale == 0.0 ? 0.0 : std::abs(a - b) / scale;
}
std::string file_text(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

// Every body's state bitwise the serial one's.
template <class S, class D>
void check_bodies(const S& serial, const D& distributed, const std::string& when) {
  REQUIRE(distributed.rigid_body_count() == serial.rigid_body_count());
  for (contact::RigidBodyId id = 0; id < serial.rigid_body_count(); ++id) {
    const contact::RigidBodyState s = serial.rigid_body(id), d = distributed.rigid_body(id);
    INFO(when << ", body " << id << ": serial force " << s.contact_force.transpose() << ", distributed "
              << d.contact_force.transpose());
    CHECK(same_bits(d.kinematics.position, s.kinematics.position));
    CHECK(same_bits(d.kinematics.velocity, s.kinematics.velocity));
    CHECK(same_bits(d.kinematics.angular_velocity, s.kinematics.angular_velocity));
    CHECK(same_bits(d.kinematics.orientation.coeffs().x(), s.kinematics.orientation.coeffs().x()));
    CHECK(same_bits(d.kinematics.orientation.coeffs().w(), s.kinematics.orientation.coeffs().w()));
    CHECK(same_bits(d.contact_force, s.contact_force));
    CHECK(same_bits(d.contact_moment, s.contact_moment));
    CHECK(same_bits(d.contact_impulse, s.contact_impulse));
    CHECK(d.contacts == s.contacts);
    CHECK(same_bits(d.kinetic_energy, s.kinetic_energy));
  }
}

// What a compared run saw of the contact, for the checks that it was real.
struct ContactSeen {
  long steps_in_contact = 0;
  std::size_t most_contacts = 0;
  double largest_force = 0.0;
};

// Both solvers stepped together; the bodies compared after every step, the
// particles and the books at the end.
template <class Material>
ContactSeen compare_runs(const std::string& label, Serial<Material>& serial, Distributed<Material>& distributed,
                         long steps) {
  const mpi::Communicator& comm = distributed.communicator();
  REQUIRE(distributed.time_step() == serial.time_step());
  ContactSeen seen;
  for (long n = 0; n < steps; ++n) {
    serial.step();
    distributed.step();
    check_bodies(serial, distributed, label + " after step " + std::to_string(n + 1));
    for (contact::RigidBodyId id = 0; id < serial.rigid_body_count(); ++id) {
      const contact::RigidBodyState s = serial.rigid_body(id);
      seen.most_contacts = std::max(seen.most_contacts, s.contacts);
      seen.largest_force = std::max(seen.largest_force, s.contact_force.norm());
      if (s.contacts > 0 && id == 0) ++seen.steps_in_contact;
    }
  }
  INFO(label << " on " << comm.size() << " ranks, " << steps << " steps; rank " << comm.rank() << " owns "
             << distributed.layout().owned_count() << " particles");
  CHECK(mpi_test::differing_components(distributed.positions(), serial.positions()) == 0);
  CHECK(mpi_test::differing_components(distributed.directors(), serial.directors()) == 0);
  CHECK(mpi_test::differing_components(distributed.velocities(), serial.velocities()) == 0);
  CHECK(mpi_test::differing_components(distributed.angular_velocities(), serial.angular_velocities()) == 0);
  const EnergyReport e = distributed.energy(), s = serial.energy();
  // The bodies' and contact's terms are formed alike on every rank: bitwise.
  CHECK(same_bits(e.rigid_body_kinetic, s.rigid_body_kinetic));
  CHECK(same_bits(e.contact_energy, s.contact_energy));
  CHECK(same_bits(e.friction_dissipation, s.friction_dissipation));
  CHECK(same_bits(e.contact_work_on_shell, s.contact_work_on_shell));
  CHECK(same_bits(e.rigid_body_work, s.rigid_body_work));
  // The shell's books: exact sums over the ranks against the serial loop's.
  CHECK(relative(e.kinetic, s.kinetic) < 1e-12);
  CHECK(relative(e.internal, s.internal) < 1e-12);
  CHECK(relative(e.external_work, s.external_work) < 1e-12);
  const double scale = std::max({s.kinetic, std::abs(s.external_work), s.rigid_body_kinetic, s.rigid_body_work});
  CHECK(std::abs(e.balance() - s.balance()) < 1e-12 * scale);
  // The contact did work on the shell: a test of equal zeros proves nothing.
  CHECK(std::abs(s.contact_work_on_shell) > 1e-6 * scale);
  return seen;
}

}  // namespace

TEST_CASE("Distributed rigid body: a free sphere striking a clamped plate obliquely with friction, bitwise serial",
          "[mpi][contact]") {
  const mpi::Communicator comm;
  const ShellModel model = plate(21);
  const material::J2Plasticity::Parameters steel{steel_E, steel_nu, steel_yield, steel_Ep};
  contact::PenaltyOptions rough;
  rough.friction_coefficient = 0.3;
  // Over the middle of a cell of four particles (10 mm apart) next to the
  // plate's centre, so that it strikes several at once, which the
  // partition's cuts split; oblique, so that friction turns the sphere.
  const FreeSphere sphere = sphere_at(0.095, 0.105, 2e-5, Vector3(8.0, -5.0, -40.0));
  Serial<material::J2Plasticity> serial(model, steel, plate_options());
  serial.clamp("boundary");
  serial.add_rigid_body(sphere, rough);
  Distributed<material::J2Plasticity> distributed(comm, model, steel, plate_options());
  distributed.clamp("boundary");
  distributed.add_rigid_body(sphere, rough);
  const ContactSeen seen = compare_runs("sphere on a plate", serial, distributed, 250);
  // The sphere struck (several particles at once), slowed and turned.
  CHECK(seen.steps_in_contact > 10);
  CHECK(seen.most_contacts >= 4);
  const contact::RigidBodyState body = serial.rigid_body(0);
  CHECK(body.kinematics.velocity.z() > -39.8);
  CHECK(body.kinematics.angular_velocity.norm() > 1.0);
  CHECK(serial.energy().friction_dissipation > 0.0);
  if (comm.is_root())
    WARN("sphere on a plate on " << comm.size() << " ranks: bitwise over 250 steps, " << seen.steps_in_contact
                                 << " in contact, up to " << seen.most_contacts << " particles, sphere velocity "
                                 << body.kinematics.velocity.transpose() << " m/s");
}

TEST_CASE("Distributed rigid bodies: a plate pressed by a moving wall onto a fixed one, bitwise serial; probe and "
          "frames written once",
          "[mpi][contact]") {
  const mpi::Communicator comm;
  namespace fs = std::filesystem;
  const fs::path base = fs::temp_directory_path() / ("sphshell_mpi_contact_" + std::to_string(comm.size()));
  const fs::path serial_dir = base / ("serial_rank" + std::to_string(comm.rank()));
  const fs::path distributed_dir = base / "distributed";
  if (comm.is_root()) fs::remove_all(distributed_dir);
  fs::remove_all(serial_dir);
  fs::create_directories(serial_dir);
  comm.barrier();
  const ShellModel model = plate(13);
  const material::Elastic::Parameters steel{steel_E, steel_nu};
  const double time_step = 0.8 * Serial<material::Elastic>(model, steel, plate_options()).time_step();
  const long steps = 120;
  const auto options_in = [&](const fs::path& directory) {
    SolverOptions options = plate_options();
    options.output_directory = directory.string();
    options.output_interval = 40.5 * time_step;
    options.time_step = time_step;
    return options;
  };
  // The plate lies on a fixed wall (its lower face touching), with
  // friction; the tilted wall comes down on it at up to 5 m/s, first at a
  // corner, and presses it onto the fixed one.
  const auto set_up = [&](auto& solver, const fs::path& probe) {
    contact::PenaltyOptions rough;
    rough.friction_coefficient = 0.2;
    solver.add_rigid_body(pressing_wall(1e-6, 5.0, 30 * time_step), rough);
    solver.add_rigid_body(contact::fixed_wall(Vector3(0.0, 0.0, -0.5 * plate_thickness), Vector3::UnitZ()), rough);
    solver.add_rigid_body_probe(probe.string(), 0);
  };
  Serial<material::Elastic> serial(model, steel, options_in(serial_dir / "frames"));
  set_up(serial, serial_dir / "wall.csv");
  Distributed<material::Elastic> distributed(comm, model, steel, options_in(distributed_dir / "frames"));
  set_up(distributed, distributed_dir / "wall.csv");
  const ContactSeen seen = compare_runs("plate between walls", serial, distributed, steps);
  CHECK(seen.most_contacts > 20);
  CHECK(serial.rigid_body(1).contacts > 20);  // pressed onto the lower wall
  if (comm.is_root())
    WARN("plate between walls on " << comm.size() << " ranks: bitwise over " << steps << " steps, up to "
                                   << seen.most_contacts << " particles on a wall, " << serial.rigid_body(1).contacts
                                   << " on the lower one at the end");
  distributed.write_frame();
  serial.write_frame();
  comm.barrier();
  if (comm.is_root()) {
    // One probe, written by rank 0: the serial run's bytes (a header line,
    // the start and a row per step).
    const std::string probe = file_text(distributed_dir / "wall.csv");
    CHECK(probe == file_text(serial_dir / "wall.csv"));
    CHECK(std::count(probe.begin(), probe.end(), '\n') == steps + 2);
    // The bodies' frames (a plane drawn over the whole shell): the serial run's bytes.
    int frames = 0;
    for (const fs::directory_entry& entry : fs::directory_iterator(serial_dir / "frames")) {
      const std::string name = entry.path().filename().string();
      if (name.rfind("bodies_", 0) != 0) continue;
      ++frames;
      INFO(name);
      CHECK(file_text(distributed_dir / "frames" / name) == file_text(entry.path()));
    }
    CHECK(frames >= 4);
  }
  comm.barrier();
  fs::remove_all(serial_dir);
  comm.barrier();
  if (comm.is_root()) fs::remove_all(base);
}

TEST_CASE("Distributed rigid bodies: refused input is the serial Error on every rank, nothing written",
          "[mpi][contact][errors]") {
  const mpi::Communicator comm;
  namespace fs = std::filesystem;
  const ShellModel model = plate(11);
  const material::Elastic::Parameters steel{steel_E, steel_nu};
  const auto message_of = [](auto&& body) {
    try {
      body();
    } catch (const Error& error) {
      return std::string(error.what());
    }
    return std::string("(no Error)");
  };
  Serial<material::Elastic> serial(model, steel, plate_options());
  Distributed<material::Elastic> distributed(comm, model, steel, plate_options());
  // A sphere sunk into the plate (over several particles, on several ranks):
  // the particle of lowest global id is named, as serially.
  const FreeSphere sunk = sphere_at(0.5 * plate_side, 0.5 * plate_side, -0.012, Vector3::Zero());
  const std::string serial_sunk = message_of([&] { serial.add_rigid_body(sunk); });
  CHECK_THAT(serial_sunk, Catch::Contains("the body starts inside the shell"));
  CHECK(message_of([&] { distributed.add_rigid_body(sunk); }) == serial_sunk);
  CHECK(distributed.rigid_body_count() == 0);
  // Negative friction.
  contact::PenaltyOptions negative;
  negative.friction_coefficient = -0.1;
  const FreeSphere clear = sphere_at(0.5 * plate_side, 0.5 * plate_side, 1e-3, Vector3::Zero());
  const std::string serial_friction = message_of([&] { serial.add_rigid_body(clear, negative); });
  CHECK_THAT(serial_friction, Catch::Contains("friction_coefficient = -0.1"));
  CHECK(message_of([&] { distributed.add_rigid_body(clear, negative); }) == serial_friction);
  CHECK(distributed.rigid_body_count() == 0);
  // A probe of a body that is not there, and a probe file that cannot be
  // written (only rank 0 writes: its Error is every rank's).
  CHECK(message_of([&] { distributed.add_rigid_body_probe("unused.csv", 0); }) ==
        message_of([&] { serial.add_rigid_body_probe("unused.csv", 0); }));
  CHECK_FALSE(fs::exists("unused.csv"));
  distributed.add_rigid_body(clear);
  serial.add_rigid_body(clear);
  const fs::path not_a_folder = fs::temp_directory_path() / ("sphshell_mpi_probe_folder_np" + std::to_string(comm.size()));
  if (comm.is_root()) std::ofstream(not_a_folder.string()) << "a file";
  comm.barrier();
  const std::string bad_path = (not_a_folder / "probe.csv").string();
  const std::string serial_bad_path = message_of([&] { serial.add_rigid_body_probe(bad_path, 0); });
  CHECK_THAT(serial_bad_path, Catch::Contains(bad_path));
  CHECK(message_of([&] { distributed.add_rigid_body_probe(bad_path, 0); }) == serial_bad_path);
  comm.barrier();
  if (comm.is_root()) fs::remove(not_a_folder);
  // The shell contact enabled twice: the serial Error.
  serial.enable_shell_contact();
  distributed.enable_shell_contact();
  const std::string serial_twice = message_of([&] { serial.enable_shell_contact(); });
  CHECK_THAT(serial_twice, Catch::Contains("enable_shell_contact"));
  CHECK(message_of([&] { distributed.enable_shell_contact(); }) == serial_twice);
}

TEST_CASE("Distributed shell contact: a plate driven onto another, bitwise serial", "[mpi][contact][shell_contact]") {
  const mpi::Communicator comm;
  // 0.1 m square steel plates, 2 mm thick, 11 × 11 particles (10 mm apart),
  // 21 mm apart: beyond the 20 mm support radius, so they share no
  // approximation rows; only the contact joins them.
  const double side = 0.1, thickness = 2e-3, gap = 0.021;
  const ShellModel model = two_plates(11, side, gap, thickness);
  const material::Elastic::Parameters steel{steel_E, steel_nu};
  Serial<material::Elastic> serial(model, steel, plate_options());
  Distributed<material::Elastic> distributed(comm, model, steel, plate_options());
  // The upper plate is driven down rigidly: fast over 200 steps until its
  // lower face is 0.1 mm above the lower plate's upper face, then at 10 m/s
  // into it; the lower plate is clamped at its edges.
  const double dt = serial.time_step(), approach = gap - thickness - 1e-4, steps_to_close = 200;
  const double fast = approach / (steps_to_close * dt), switch_time = steps_to_close * dt, slow = 10.0;
  const auto driven = [=](const Vector3&, double t) { return Vector3(0.0, 0.0, t < switch_time ? -fast : -slow); };
  const auto set_up = [&](auto& solver) {
    solver.clamp("lower_edge");
    solver.prescribe_velocity("upper", driven);
    solver.enable_shell_contact();
  };
  set_up(serial);
  set_up(distributed);
  std::size_t most_contacts = 0;
  long steps_in_contact = 0;
  for (long n = 0; n < 400; ++n) {
    serial.step();
    distributed.step();
    const contact::ShellContactStatistics s = serial.shell_contact_statistics(),
                                          d = distributed.shell_contact_statistics();
    CHECK(d.contacts == s.contacts);
    CHECK(d.candidate_pairs == s.candidate_pairs);
    CHECK(same_bits(d.largest_penetration, s.largest_penetration));
    CHECK(same_bits(d.spring_energy, s.spring_energy));
    most_contacts = std::max(most_contacts, s.contacts);
    if (s.contacts > 0) ++steps_in_contact;
  }
  // The plates met over much of their area, for many steps.
  CHECK(most_contacts > 50);
  CHECK(steps_in_contact > 100);
  compare_runs("plate driven onto a plate", serial, distributed, 0);
  // The shell contact's loads on this rank's particles are the serial run's.
  std::size_t differing = 0;
  const contact::ParticleContactLoads& local = distributed.shell_contact_loads();
  const contact::ParticleContactLoads& whole = serial.shell_contact_loads();
  for (std::size_t i = 0; i < distributed.layout().owned_count(); ++i) {
    const auto g = static_cast<std::size_t>(distributed.global_id(i));
    if (!same_bits(local.force[i], whole.force[g]) || !same_bits(local.moment[i], whole.moment[g])) ++differing;
  }
  CHECK(differing == 0);
  if (comm.is_root())
    WARN("plate driven onto a plate on " << comm.size() << " ranks: bitwise over 400 steps, " << steps_in_contact
                                         << " with shell contact, up to " << most_contacts << " particles");
}

TEST_CASE("Distributed rigid body: a restart from a checkpoint taken in contact continues bitwise", "[mpi][contact][checkpoint]") {
  const mpi::Communicator comm;
  namespace fs = std::filesystem;
  const fs::path folder = fs::temp_directory_path() / ("sphshell_mpi_contact_checkpoint_np" + std::to_string(comm.size()));
  if (comm.is_root()) fs::create_directories(folder);
  comm.barrier();
  const std::string path = (folder / "in_contact").string();
  const ShellModel model = plate(15);
  const material::Elastic::Parameters steel{steel_E, steel_nu};
  contact::PenaltyOptions rough;
  rough.friction_coefficient = 0.3;
  // Struck obliquely: in contact from the first steps, the friction springs
  // (contact history, per rank) loaded when the checkpoint is taken.
  const FreeSphere sphere = sphere_at(0.1, 0.1, 0.0, Vector3(5.0, 0.0, -20.0));
  const auto set_up = [&](Distributed<material::Elastic>& solver) {
    solver.clamp("boundary");
    solver.add_rigid_body(sphere, rough);
  };
  // The sphere's probe, written by rank 0: the restarted run continues the file.
  const std::string probe = (folder / "sphere.csv").string();
  Distributed<material::Elastic> original(comm, model, steel, plate_options());
  set_up(original);
  original.add_rigid_body_probe(probe, 0);
  // Saved at the first step in contact (every rank holds the same body: the
  // loop ends alike on all of them).
  for (int n = 0; n < 200 && original.rigid_body(0).contacts == 0; ++n) original.step();
  CHECK(original.rigid_body(0).contacts > 0);
  original.step();
  // The friction springs hold a tangential force: the history the files carry.
  CHECK(std::abs(original.rigid_body(0).contact_force.x()) > 1e-3 * std::abs(original.rigid_body(0).contact_force.z()));
  original.save_checkpoint(path);
  for (int n = 0; n < 30; ++n) original.step();
  const std::string whole_probe = comm.is_root() ? file_text(probe) : std::string();
  Distributed<material::Elastic> restarted(comm, model, steel, plate_options());
  set_up(restarted);
  restarted.load_checkpoint(path);
  restarted.add_rigid_body_probe(probe, 0);
  for (int n = 0; n < 30; ++n) restarted.step();
  if (comm.is_root()) {
    // The uninterrupted run's bytes: its rows after the checkpoint cut off and written again.
    CHECK(std::count(whole_probe.begin(), whole_probe.end(), '\n') == 1 + 1 + original.steps());
    CHECK(file_text(probe) == whole_probe);
  }
  check_bodies(original, restarted, "30 steps after the restart");
  CHECK(mpi_test::differing_components(restarted.positions(), original.positions()) == 0);
  CHECK(mpi_test::differing_components(restarted.velocities(), original.velocities()) == 0);
  const EnergyReport a = original.energy(), b = restarted.energy();
  CHECK(same_bits(a.contact_work_on_shell, b.contact_work_on_shell));
  CHECK(same_bits(a.friction_dissipation, b.friction_dissipation));
  comm.barrier();
  if (comm.is_root()) fs::remove_all(folder);
}
