#pragma once
// The solver's CSV probes (solver/output.hpp): what a probe is, and the
// probe files of a run with their schedule, their identity (a probe file is
// one file, by its absolute normalized path) and their continuation after a
// checkpoint. A probe's file is written by the process that owns what it
// probes (a rigid body's by the first process: every process holds every
// body); every process registers every probe.
//
// A probe is a type whose column names and row values sit together:
//   std::vector<std::string> columns() const;
//   template <class Solver> std::vector<double> row(const Solver&) const;

#include <sphshell/core/error.hpp>
#include <sphshell/core/types.hpp>
#include <sphshell/io/csv_probe.hpp>
#include <sphshell/io/output_directory.hpp>
#include <sphshell/solver/section_states.hpp>

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <iterator>
#include <optional>
#include <string>
#include <utility>
#include <variant>
#include <vector>

namespace sphshell::solver {

// The thickness output points of a rule named by where they sit: their height
// ζ along the director as a fraction of the wall thickness d, the first
// (ζ < 0, the side the director points away from) "bottom", the last "top",
// ζ = 0 "mid"; e.g. Gauss<3>: "bottom zeta=-0.387d", "mid zeta=0",
// "top zeta=+0.387d". A resultant rule (Global) has one, "whole section".
template <class Rule>
std::vector<std::string> thickness_point_names() {
  if constexpr (Rule::num_points == 0) {
    return {"whole section"};
  } else {
    std::vector<std::string> names;
    const int count = Rule::num_points;
    for (int k = 0; k < count; ++k) {
      // Reference points lie on [-1, 1]: ζ/d is half of one.
      const double fraction = 0.5 * Rule::reference_points[std::size_t(k)];
      char height[32];
      if (fraction == 0.0)
        std::snprintf(height, sizeof height, "zeta=0");
      else
        std::snprintf(height, sizeof height, "zeta=%+.3gd", fraction);
      std::string name;
      if (fraction == 0.0)
        name = "mid ";
      else if (k == 0)
        name = "bottom ";
      else if (k == count - 1)
        name = "top ";
      names.push_back(name + height);
    }
    return names;
  }
}

// One particle's history: t, displacement, velocity, rotation vector.
struct ParticleProbe {
  int particle;
  std::vector<std::string> columns() const {
    return {"t [s]", "ux [m]", "uy [m]", "uz [m]", "vx [m/s]", "vy [m/s]", "vz [m/s]", "rx [rad]", "ry [rad]", "rz [rad]"};
  }
  template <class Solver>
  std::vector<double> row(const Solver& solver) const {
    const Vector3 u = solver.displacement(particle), v = solver.velocities()[particle], r = solver.rotation(particle);
    return {solver.time(), u.x(), u.y(), u.z(), v.x(), v.y(), v.z(), r.x(), r.y(), r.z()};
  }
};

// One stress point's history: t, then each integral-point quantity at each
// thickness output point (in the rule's order, ζ ascending), the column named
// by the point's number and position, e.g. "equivalent_stress_1 (bottom
// zeta=-0.453d) [Pa]".
template <int OutputPoints>
struct StressPointProbe {
  explicit StressPointProbe(int point) : stress_point(point) {}
  int stress_point;
  std::vector<std::string> point_names;  // thickness_point_names of the rule (set when it is added)
  std::vector<std::string> columns() const {
    std::vector<std::string> names{"t [s]"};
    for (const IntegralPointQuantityInfo& info : integral_point_quantities)
      for (int k = 1; k <= OutputPoints; ++k)
        names.push_back(info.name + ("_" + std::to_string(k)) + " (" + point_names.at(std::size_t(k - 1)) + ")" +
                        info.unit);
    return names;
  }
  template <class Solver>
  std::vector<double> row(const Solver& solver) const {
    std::vector<double> values{solver.time()};
    for (const IntegralPointQuantityInfo& info : integral_point_quantities)
      for (int k = 0; k < OutputPoints; ++k) values.push_back(solver.integral_point_quantity(info.quantity, stress_point, k));
    return values;
  }
};

// One rigid body's history (Solver::add_rigid_body_probe): t, the body's
// centre at t, its velocity at t − Δt/2 (the central difference's half step,
// contact/rigid_body.hpp), the contact force it received in the last step and
// the impulse received so far, and the particles in contact in the last step.
struct RigidBodyProbe {
  std::size_t body;
  std::vector<std::string> columns() const {
    return {"t [s]",
            "x [m]",
            "y [m]",
            "z [m]",
            "vx at t-dt/2 [m/s]",
            "vy at t-dt/2 [m/s]",
            "vz at t-dt/2 [m/s]",
            "fx [N]",
            "fy [N]",
            "fz [N]",
            "impulse_x [N s]",
            "impulse_y [N s]",
            "impulse_z [N s]",
            "contacts"};
  }
  template <class Solver>
  std::vector<double> row(const Solver& solver) const {
    const auto state = solver.rigid_body(body);
    const Vector3 &x = state.kinematics.position, &v = state.kinematics.velocity, &f = state.contact_force,
                  &impulse = state.contact_impulse;
    return {solver.time(), x.x(), x.y(), x.z(),       v.x(),       v.y(),       v.z(),
            f.x(),         f.y(), f.z(), impulse.x(), impulse.y(), impulse.z(), static_cast<double>(state.contacts)};
  }
};

// The probe files of a run. Rows are read through a view of what this
// process owns: make_view(local_point) gives an object with the Solver
// members the probes read (time, velocities, displacement, rotation,
// integral_point_quantity of the probed stress point's local point,
// rigid_body).
template <int OutputPoints>
class ProbeFiles {
 public:
  using StressProbe = StressPointProbe<OutputPoints>;
  using Probe = std::variant<ParticleProbe, StressProbe, RigidBodyProbe>;

  // A probe file as a checkpoint records it: kind 0 a particle probe, 1 a
  // stress-point probe, 2 a rigid-body probe (the variant's index), of
  // particle, stress point or body `index`.
  struct Record {
    std::string key;
    std::uint32_t kind = 0;
    std::int64_t index = 0;
    io::CsvProbe::Resume written;
    template <class S, class F>
    static void for_each_field(S& self, F&& field) {
      field(self.key, self.kind, self.index, self.written.bytes, self.written.hash);
    }
  };

  // An Error when `key` (io::identity_of(path)) is the file of a probe already added.
  void refuse_taken(const std::string& key, const std::string& path) const {
    for (const OpenProbe& open : probes_)
      if (open.key == key)
        throw Error("sphshell: probe file '" + path + "' is already the file of another probe (added as '" +
                    open.path + "'); give each probe a file of its own");
  }

  // Registers a probe; `local_point` is set on the process that owns what it
  // probes (a particle probe's is unused), which writes the file: it
  // continues the file a loaded checkpoint recorded (no header, no row now:
  // the file has both), or starts it with a header and the row of now.
  template <class MakeView>
  void add(const std::string& path, const std::string& key, Probe probe, std::optional<std::size_t> local_point,
           const MakeView& make_view) {
    OpenProbe open{path, key, std::move(probe), std::nullopt, local_point.value_or(0)};
    if (!local_point) return probes_.push_back(std::move(open));
    create_parent_directory(path);
    for (auto record = restored_.begin(); record != restored_.end(); ++record)
      if (record->key == key) {
        check_same_probe(*record, open.probe, path);
        open.file.emplace(path, columns_of(open.probe), record->written);
        restored_.erase(record);
        return probes_.push_back(std::move(open));
      }
    open.file.emplace(path, columns_of(open.probe));
    write_row(open, make_view);
    probes_.push_back(std::move(open));
  }

  // After a step: a row of every probe this process writes, when due (within
  // schedule_tolerance of a step of its time).
  template <class MakeView>
  void write_scheduled(double time, double time_step, double interval, const MakeView& make_view) {
    if (probes_.empty() || !(time >= next_time_ - schedule_tolerance * time_step)) return;
    for (OpenProbe& open : probes_)
      if (open.file) write_row(open, make_view);
    next_time_ = time + interval;
  }

  double next_time() const { return next_time_; }

  // Checkpoints: each file this process writes (path, what it probes, its
  // length and content hash).
  template <class Writer>
  void save(Writer& out) const {
    std::vector<Record> records;
    for (const OpenProbe& open : probes_) {
      if (!open.file) continue;
      Record record;
      record.key = open.key;
      record.kind = static_cast<std::uint32_t>(open.probe.index());
      record.index = probed_index(open.probe);
      record.written = open.file->written();
      records.push_back(record);
    }
    out(records);
  }
  template <class Reader>
  static std::vector<Record> read(Reader& in) {
    std::vector<Record> records;
    in(records);
    for (const Record& record : records)
      if (record.kind >= std::variant_size_v<Probe>) in.fail("a probe of unknown kind " + std::to_string(record.kind));
    return records;
  }
  // Probes already added continue their files (or restart them, if the
  // checkpoint has none of theirs); the others continue when added.
  template <class MakeView>
  void restore(std::vector<Record> records, double next_time, const MakeView& make_view) {
    next_time_ = next_time;
    restored_ = std::move(records);
    for (OpenProbe& open : probes_) {
      if (!open.file) continue;  // another process's
      auto record =
          std::find_if(restored_.begin(), restored_.end(), [&](const Record& r) { return r.key == open.key; });
      if (record == restored_.end()) {
        open.file.emplace(open.path, columns_of(open.probe));  // a probe new to the run: starts now
        write_row(open, make_view);
        continue;
      }
      check_same_probe(*record, open.probe, open.path);
      open.file.emplace(open.path, columns_of(open.probe), record->written);
      restored_.erase(record);
    }
  }

 private:
  // Probe rows within this fraction of a step of their time are due.
  static constexpr double schedule_tolerance = 1e-9;

  // A probe: its CSV file as added and its identity (to keep two probes off
  // one file), what it probes, and, on the process that owns that, the open
  // file (and a stress point's local point).
  struct OpenProbe {
    std::string path, key;
    Probe probe;
    std::optional<io::CsvProbe> file;
    std::size_t local_point;
  };

  static void create_parent_directory(const std::string& path) {
    const std::filesystem::path parent = std::filesystem::path(path).parent_path();
    if (!parent.empty()) io::make_directory(parent.string(), "probe file '" + path + "': ", "its folder");
  }
  static std::vector<std::string> columns_of(const Probe& probe) {
    return std::visit([](const auto& p) { return p.columns(); }, probe);
  }
  static std::int64_t probed_index(const Probe& probe) {
    if (const auto* particle = std::get_if<ParticleProbe>(&probe)) return particle->particle;
    if (const auto* body = std::get_if<RigidBodyProbe>(&probe)) return static_cast<std::int64_t>(body->body);
    return std::get<StressProbe>(probe).stress_point;
  }
  static void check_same_probe(const Record& record, const Probe& probe, const std::string& path) {
    static const char* const kinds[] = {"particle", "stress point", "rigid body"};
    static_assert(std::size(kinds) == std::variant_size_v<Probe>, "check_same_probe: name every kind of probe");
    if (record.kind != probe.index() || record.index != probed_index(probe))
      throw Error("sphshell: probe file '" + path + "' is, in the checkpoint, the file of the " + kinds[record.kind] +
                  " probe of " + kinds[record.kind] + " " + std::to_string(record.index) + ", not of " +
                  kinds[probe.index()] + " " + std::to_string(probed_index(probe)) +
                  ": give this probe another file, or probe what the run probed");
  }
  template <class MakeView>
  static void write_row(OpenProbe& open, const MakeView& make_view) {
    const auto view = make_view(open.local_point);
    open.file->write_row(std::visit([&](const auto& probe) { return probe.row(view); }, open.probe));
  }

  std::vector<OpenProbe> probes_;
  std::vector<Record> restored_;  // probe files of a loaded checkpoint, not yet added again
  double next_time_ = 0.0;
};

}  // namespace sphshell::solver
