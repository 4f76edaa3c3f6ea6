#pragma once
// The solver's output: ParaView frames (particles, stress points and, with a
// crack policy, crack segments, each series in a .pvd collection) on the
// output schedule, and CSV probes. Output is an observer: it reads the
// Solver's public accessors, so it holds no state of the run but its own
// schedule and files.
//
// A probe is a type whose column names and row values sit together:
//   std::vector<std::string> columns() const;
//   template <class Solver> std::vector<double> row(const Solver&) const;

#include <sphshell/core/error.hpp>
#include <sphshell/core/types.hpp>
#include <sphshell/io/csv_probe.hpp>
#include <sphshell/io/pvd_collection.hpp>
#include <sphshell/io/vtu_writer.hpp>
#include <sphshell/solver/options.hpp>
#include <sphshell/solver/section_states.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <filesystem>
#include <memory>
#include <sstream>
#include <string>
#include <utility>
#include <variant>
#include <vector>

namespace sphshell::solver {

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
// thickness output point (in the rule's order, ζ ascending).
template <int OutputPoints>
struct StressPointProbe {
  int stress_point;
  std::vector<std::string> columns() const {
    std::vector<std::string> names{"t [s]"};
    for (const IntegralPointQuantityInfo& info : integral_point_quantities)
      for (int k = 1; k <= OutputPoints; ++k) names.push_back(info.name + ("_" + std::to_string(k)) + info.unit);
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

// Holds the schedule and the open files; every member that reads the run takes
// the solver (any type with the Solver's public accessors).
template <int OutputPoints>
class SolverOutput {
 public:
  static constexpr int output_points = OutputPoints;
  using StressProbe = StressPointProbe<output_points>;

  explicit SolverOutput(const OutputOptions& options) : options_(options) {}

  template <class Probe, class Solver>
  void add_probe(const std::string& csv_path, Probe probe, const Solver& solver) {
    create_parent_directory(csv_path);
    probes_.push_back(OpenProbe{io::CsvProbe(csv_path, probe.columns()), std::move(probe)});
    write_probe(probes_.back(), solver);
  }

  // Before the first step: the reference configuration at t = 0.
  template <class Solver>
  void start(const Solver& solver) {
    if (frames_written_ == 0 && writes_frames()) {
      write_frame(solver);
      next_frame_time_ = options_.output_interval;
    }
  }

  // After a step: the frames and probe rows that are due.
  template <class Solver>
  void write_scheduled(const Solver& solver) {
    const double tolerance = schedule_tolerance * solver.time_step();
    const double time = solver.time();
    if (writes_frames() && time >= next_frame_time_ - tolerance) {
      write_frame(solver);
      next_frame_time_ += options_.output_interval *
                          std::max(1.0, std::floor((time - next_frame_time_) / options_.output_interval + 1.0));
    }
    if (!probes_.empty() && time >= next_probe_time_ - tolerance) {
      for (OpenProbe& probe : probes_) write_probe(probe, solver);
      next_probe_time_ = time + options_.probe_interval;
    }
  }

  // One frame now, whatever the schedule.
  template <class Solver>
  void write_frame(const Solver& solver) {
    if (options_.output_directory.empty())
      detail::invalid_parameter("output_directory", "(empty)", "set it to write ParaView frames");
    if (!particle_collection_) {
      std::filesystem::create_directories(options_.output_directory);
      particle_collection_ = std::make_unique<io::PvdCollection>(options_.output_directory + "/particles.pvd");
      stress_point_collection_ =
          std::make_unique<io::PvdCollection>(options_.output_directory + "/stress_points.pvd");
    }
    std::ostringstream suffix;
    suffix.width(6);
    suffix.fill('0');
    suffix << frames_written_++;
    const std::string particle_file = options_.output_directory + "/particles_" + suffix.str() + ".vtu";
    const std::string stress_file = options_.output_directory + "/stress_points_" + suffix.str() + ".vtu";
    io::write_vtu_points(particle_file, solver.positions(), particle_fields(solver));
    particle_collection_->add(solver.time(), particle_file);
    io::write_vtu_points(stress_file, solver.stress_point_positions(), stress_point_fields(solver));
    stress_point_collection_->add(solver.time(), stress_file);
    if constexpr (Solver::crack_type::enabled) write_crack_frame(solver, suffix.str());
  }

  static void create_parent_directory(const std::string& path) {
    const std::filesystem::path parent = std::filesystem::path(path).parent_path();
    if (!parent.empty()) std::filesystem::create_directories(parent);
  }

 private:
  // Frames and rows within this fraction of a step of their time are due.
  static constexpr double schedule_tolerance = 1e-9;

  // A CSV file and the probe that fills it.
  struct OpenProbe {
    io::CsvProbe file;
    std::variant<ParticleProbe, StressProbe> probe;
  };

  bool writes_frames() const { return !options_.output_directory.empty() && options_.output_interval > 0.0; }

  template <class Solver>
  static void write_probe(OpenProbe& open, const Solver& solver) {
    open.file.write_row(std::visit([&](const auto& probe) { return probe.row(solver); }, open.probe));
  }

  static io::PointField vector_field(const std::string& name, const std::vector<Vector3>& values) {
    io::PointField field{name, 3, {}};
    field.values.reserve(3 * values.size());
    for (const Vector3& v : values) field.values.insert(field.values.end(), {v.x(), v.y(), v.z()});
    return field;
  }

  template <class Solver>
  static std::vector<io::PointField> particle_fields(const Solver& solver) {
    const std::size_t n = solver.particle_count();
    std::vector<Vector3> displacement_values(n), rotation_values(n);
    for (std::size_t i = 0; i < n; ++i) {
      displacement_values[i] = solver.displacement(static_cast<int>(i));
      rotation_values[i] = solver.rotation(static_cast<int>(i));
    }
    std::vector<io::PointField> fields{vector_field("displacement", displacement_values),
                                       vector_field("velocity", solver.velocities()),
                                       vector_field("rotation", rotation_values),
                                       vector_field("director", solver.directors())};
    if constexpr (Solver::crack_type::enabled) {
      io::PointField fragment{"fragment", 1, {}};
      for (std::size_t i = 0; i < n; ++i) fragment.values.push_back(solver.is_fragment(static_cast<int>(i)) ? 1 : 0);
      fields.push_back(fragment);
    }
    return fields;
  }

  // Per stress point: one array per integral-point quantity with a component
  // per thickness output point (named ip1, ip2, … in ζ order), then the
  // removed flag (with cracks) and the resultants.
  template <class Solver>
  static std::vector<io::PointField> stress_point_fields(const Solver& solver) {
    const std::size_t m = solver.stress_point_count();
    std::vector<std::string> names;
    for (int k = 1; k <= output_points; ++k) names.push_back("ip" + std::to_string(k));
    std::vector<io::PointField> fields;
    for (const IntegralPointQuantityInfo& info : integral_point_quantities) {
      if (info.needs_damage_law && !Solver::material_type::has_damage) continue;
      io::PointField field{info.name, output_points, {}, names};
      field.values.reserve(m * output_points);
      for (std::size_t s = 0; s < m; ++s)
        for (int k = 0; k < output_points; ++k)
          field.values.push_back(solver.integral_point_quantity(info.quantity, static_cast<int>(s), k));
      fields.push_back(std::move(field));
    }
    if constexpr (Solver::crack_type::enabled) {
      io::PointField removed{"removed", 1, {}};
      for (std::size_t s = 0; s < m; ++s) removed.values.push_back(solver.is_removed(static_cast<int>(s)) ? 1.0 : 0.0);
      fields.push_back(removed);
    }
    io::PointField membrane{"membrane_force", 3, {}, {"Nxx", "Nyy", "Nxy"}};
    io::PointField moment{"bending_moment", 3, {}, {"Mxx", "Myy", "Mxy"}};
    for (std::size_t s = 0; s < m; ++s)
      for (int c = 0; c < 3; ++c) {
        membrane.values.push_back(solver.membrane_force(static_cast<int>(s))[c]);
        moment.values.push_back(solver.bending_moment(static_cast<int>(s))[c]);
      }
    fields.push_back(membrane);
    fields.push_back(moment);
    return fields;
  }

  // The crack segments as a ParaView line set, in the current configuration:
  // a damaged stress point's crack point follows the interpolated motion of the
  // stress point, a pre-crack point the displacement of its nearest particle.
  template <class Solver>
  void write_crack_frame(const Solver& solver, const std::string& suffix) {
    if (!crack_collection_)
      crack_collection_ = std::make_unique<io::PvdCollection>(options_.output_directory + "/cracks.pvd");
    const auto& crack = solver.crack();
    const std::vector<Vector3>& reference = crack.points();
    std::vector<Vector3> points(reference.size());
    std::vector<char> placed(reference.size(), 0);
    const std::vector<Vector3> stress_positions = solver.stress_point_positions();
    for (std::size_t p = 0; p < solver.stress_point_count(); ++p) {
      const int k = crack.crack_point_of_stress_point(static_cast<int>(p));
      if (k >= 0) {
        points[k] = stress_positions[p];
        placed[k] = 1;
      }
    }
    for (std::size_t k = 0; k < points.size(); ++k)
      if (!placed[k]) points[k] = reference[k] + solver.displacement(solver.model().nearest_particle(reference[k]));
    std::vector<std::array<int, 2>> lines;
    io::CellField crack_id{"crack_id", 1, {}};
    for (const auto& segment : crack.segments()) {
      lines.push_back({segment.start_point, segment.end_point});
      crack_id.values.push_back(segment.crack_id);
    }
    const std::string file = options_.output_directory + "/cracks_" + suffix + ".vtu";
    io::write_vtu_lines(file, points, lines, {}, {crack_id});
    crack_collection_->add(solver.time(), file);
  }

  OutputOptions options_;
  std::vector<OpenProbe> probes_;
  std::unique_ptr<io::PvdCollection> particle_collection_, stress_point_collection_, crack_collection_;
  long frames_written_ = 0;
  double next_frame_time_ = 0.0;
  double next_probe_time_ = 0.0;
};

}  // namespace sphshell::solver
