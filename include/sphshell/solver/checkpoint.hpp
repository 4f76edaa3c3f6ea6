#pragma once
// Checkpoint files: the whole state of a Solver at a step boundary, so that a
// run restarted from it continues bit for bit as if it had not stopped
// (Solver::save_checkpoint, Solver::load_checkpoint, Solver::from_checkpoint).
//
// File layout (every number little endian, io/binary_stream.hpp):
//   header   "SPHSHCKP" (8 bytes), format version (u32),
//            the library version that wrote it (text),
//            the five policy types of the Solver (text each: approximation,
//            thickness rule, material law, crack policy, stepper; the
//            compiler's spelling of the C++ type),
//            payload size (u64), payload checksum (FNV-1a 64, u64),
//            header checksum (FNV-1a 64 of everything before it, u64);
//   payload  sections, each a four-letter tag, its size (u64) and its data:
//            IDNT what the run is (counts, model fingerprints, material
//                 constants, the options that change results, Δt),
//            BDID the rigid bodies: count, each one's shape, motion and mass,
//            TIME t0, step n, Δt, t, whether the forces are current, the step latch,
//            PART particle state, FORC particle forces,
//            PNTS the shape-function rows cracks rebuilt,
//            SECT every integration point's section state, strains,
//                 resultants and active flag,
//            FRAC crack topology, fragments, fracture counters,
//            ENRG energy ledger, BODY the rigid bodies' state and contact
//                 history, their energy terms, STEP the stepper's own state (if any),
//            OUTP output and probe schedules, frame series, probe files
//                 (particle, stress-point and rigid-body probes: a record's
//                 kind 0, 1, 2; a file without kind 2 loads, its body
//                 probes starting new files).
// Each part of the solver (include/sphshell/solver/) writes and reads its own
// section through save(Writer&) const / load(Reader&) members, so the parts
// keep owning their state.
//
// What a checkpoint holds is the state, not the set-up: boundary conditions,
// loads and prescribed motions are functions the program gives again (they
// depend on time only through t, which is restored). Pre-cracks are state
// (crack topology) and must not be added again.
//
// A file is written to "<path>.tmp", synced and renamed over path, so a kill
// while writing leaves the previous checkpoint whole.

#include <sphshell/core/error.hpp>
#include <sphshell/io/binary_stream.hpp>
#include <sphshell/io/output_file.hpp>
#include <sphshell/shell/model.hpp>
#include <sphshell/solver/options.hpp>

#if __has_include(<sphshell/version.hpp>)
#include <sphshell/version.hpp>
#endif
#if __has_include(<cxxabi.h>)
#include <cxxabi.h>
#define SPHSHELL_HAVE_CXXABI 1
#endif

#include <array>
#include <chrono>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <iterator>
#include <string>
#include <type_traits>
#include <typeinfo>
#include <utility>
#include <vector>

namespace sphshell::solver::checkpoint {

inline constexpr char magic[8] = {'S', 'P', 'H', 'S', 'H', 'C', 'K', 'P'};
// Raised whenever the layout or the meaning of any section changes; a file
// of another version is refused (no silent reinterpretation). Version 2: the
// identity lists transverse_shear and director_hourglass among the options
// that change results (version 1 did not, so a restart with either changed
// went on with other physics). Version 3: the rigid bodies (BDID, BODY);
// the rigid-body probe records (OUTP, kind 2) only extend it: a version-3
// file without them loads (its body probes start new files), and a library
// from before them refuses one with them ("a probe of unknown kind 2").
inline constexpr std::uint32_t format_version = 3;

inline std::string library_version() {
#ifdef SPHSHELL_VERSION_STRING
  return SPHSHELL_VERSION_STRING;
#else
  return "unknown (sphshell/version.hpp not generated)";
#endif
}

// The C++ type as the compiler spells it ("sphshell::thickness::Gauss<5>").
template <class T>
std::string type_name() {
  const char* mangled = typeid(T).name();
#ifdef SPHSHELL_HAVE_CXXABI
  int status = 0;
  char* demangled = abi::__cxa_demangle(mangled, nullptr, nullptr, &status);
  if (status == 0 && demangled) {
    std::string name(demangled);
    std::free(demangled);
    return name;
  }
#endif
  return mangled;
}

// A policy that stores its own state: save(Writer&) const (and load(Reader&)).
template <class Policy, class = void>
struct has_save_load : std::false_type {};
template <class Policy>
struct has_save_load<Policy, std::void_t<decltype(std::declval<const Policy&>().save(std::declval<io::BinaryWriter&>()))>>
    : std::true_type {};

// Whether a Solver of these policies can be checkpointed: its stepper is
// empty or stores itself, its section state lists its fields, and its crack
// policy (if enabled) stores itself. save_checkpoint says at compile time
// which is missing; periodic checkpoints of a solver that cannot are an Error
// when it is built, so a solver that never checkpoints needs none of it.
template <class Crack, class Stepper, class SectionState>
constexpr bool can_checkpoint() {
  return (std::is_empty_v<Stepper> || has_save_load<Stepper>::value) && io::is_serialisable<SectionState>() &&
         (!Crack::enabled || has_save_load<Crack>::value);
}

inline constexpr std::array<const char*, 5> policy_roles{"approximation", "thickness rule", "material law",
                                                          "crack policy", "stepper"};

template <class Approx, class Rule, class Material, class Crack, class Stepper>
std::array<std::string, 5> policy_names() {
  return {type_name<Approx>(), type_name<Rule>(), type_name<Material>(), type_name<Crack>(), type_name<Stepper>()};
}

// A value this solver has and the file must have too, by name.
struct NamedValue {
  std::string name;
  double value = 0.0;
  template <class S, class F>
  static void for_each_field(S& self, F&& field) {
    field(self.name, self.value);
  }
};
struct NamedCount {
  std::string name;
  std::uint64_t value = 0;
  template <class S, class F>
  static void for_each_field(S& self, F&& field) {
    field(self.name, self.value);
  }
};

inline std::string number_text(double value) { return io::detail::round_trip_decimal(value); }

// What a checkpoint must agree on with the solver that loads it.
struct Identity {
  std::vector<NamedCount> counts;            // particles, stress points, integration points, slots
  std::vector<NamedCount> model;             // FNV-1a of each model array
  std::vector<NamedValue> material;          // the law's constants
  std::vector<NamedValue> options;           // the options that change results, and Δt

  template <class S, class F>
  static void for_each_field(S& self, F&& field) {
    field(self.counts, self.model, self.material, self.options);
  }
};

template <class T>
std::uint64_t fingerprint(const std::vector<T>& values) {
  io::BinaryWriter bytes;
  bytes(values);
  return io::fnv1a(bytes.bytes());
}

// The model's arrays, one fingerprint each, so a mismatch names the array.
inline std::vector<NamedCount> model_fingerprints(const ShellModel& model) {
  std::vector<double> particle_thickness(model.particle_count()), stress_thickness(model.stress_point_count());
  for (std::size_t i = 0; i < particle_thickness.size(); ++i) particle_thickness[i] = model.particle_thickness(i);
  for (std::size_t p = 0; p < stress_thickness.size(); ++p) stress_thickness[p] = model.stress_point_thickness(p);
  std::vector<int> cells;
  for (const Cell& cell : model.cells()) {
    cells.push_back(static_cast<int>(cell.size()));
    cells.insert(cells.end(), cell.begin(), cell.end());
  }
  std::vector<double> cuts;  // each polyline's point count, then its coordinates
  for (const std::vector<Vector3>& polyline : model.cuts()) {
    cuts.push_back(static_cast<double>(polyline.size()));
    for (const Vector3& point : polyline) cuts.insert(cuts.end(), point.data(), point.data() + 3);
  }
  return {{"particle positions", fingerprint(model.particle_position)},
          {"particle normals", fingerprint(model.particle_normal)},
          {"particle areas", fingerprint(model.particle_area)},
          {"particle thicknesses", fingerprint(particle_thickness)},
          {"stress point positions", fingerprint(model.stress_point_position)},
          {"stress point normals", fingerprint(model.stress_point_normal)},
          {"stress point areas", fingerprint(model.stress_point_area)},
          {"stress point thicknesses", fingerprint(stress_thickness)},
          {"cells", fingerprint(cells)},
          {"cuts", fingerprint(cuts)}};
}

// The law's constants through the material contract's members.
// Whether a law lists further constants (material/material.hpp).
struct ConstantVisitor {
  void operator()(const char*, double) const {}
};
template <class Law, class = void>
struct has_for_each_constant : std::false_type {};
template <class Law>
struct has_for_each_constant<Law, std::void_t<decltype(std::declval<const Law&>().for_each_constant(
                                      ConstantVisitor{}))>> : std::true_type {};

template <class Material>
std::vector<NamedValue> material_constants(const Material& law) {
  std::vector<NamedValue> values{{"Young's modulus", law.youngs_modulus()}, {"Poisson's ratio", law.poisson_ratio()}};
  if constexpr (Material::has_plasticity) {
    const auto hardening = law.hardening();
    values.push_back({"initial yield stress", hardening.initial_yield_stress});
    values.push_back({"plastic modulus", hardening.plastic_modulus});
  }
  if constexpr (Material::has_damage) {
    const auto damage = law.damage_parameters();
    values.push_back({"damage threshold strain", damage.threshold_strain});
    values.push_back({"critical plastic strain", damage.critical_strain});
    values.push_back({"critical damage", damage.critical_damage});
  }
  if constexpr (has_for_each_constant<Material>::value)
    law.for_each_constant([&](const char* name, double value) { values.push_back({name, value}); });
  return values;
}

// Every option that changes the numbers a step produces (not the monitoring
// or output ones), and the time step they gave.
inline std::vector<NamedValue> result_options(const SolverOptions& options, double time_step) {
  return {{"density", options.density},
          {"nonlinear", options.nonlinear ? 1.0 : 0.0},
          {"support_radius_factor", options.support_radius_factor},
          {"rotary_inertia_scale", options.rotary_inertia_scale},
          {"shear_correction", options.shear_correction},
          {"transverse_shear (0: cell_edges, 1: shape_functions)",
           static_cast<double>(static_cast<int>(options.transverse_shear))},
          {"director_hourglass", options.director_hourglass ? 1.0 : 0.0},
          {"particle_integration_share", options.particle_integration_share},
          {"particle_shear_weight", options.particle_shear_weight},
          {"particle_shear_softening", options.particle_shear_softening},
          {"safety_factor", options.safety_factor},
          {"time_step (option)", options.time_step},
          {"damping", options.damping},
          {"time step in use", time_step}};
}

// The file's identity against this solver's: an Error naming the first
// thing that differs, with both values.
inline void check_identity(const Identity& file, const Identity& here, const std::string& path) {
  const std::string lead = "sphshell: checkpoint '" + path + "' is of another ";
  // A distributed run's identity starts with its rank count; a serial one's does not.
  auto rank_count = [](const Identity& id) -> long {
    return !id.counts.empty() && id.counts.front().name == "rank count" ? static_cast<long>(id.counts.front().value)
                                                                       : -1;
  };
  const long file_ranks = rank_count(file), here_ranks = rank_count(here);
  if (file_ranks >= 0 && here_ranks < 0)
    throw Error("sphshell: checkpoint '" + path + "' is one rank's file of a distributed checkpoint (written by a "
                "distributed solver on " + std::to_string(file_ranks) + " ranks); a serial Solver loads only a "
                "serial Solver's checkpoint: restart the run distributed on " + std::to_string(file_ranks) + " ranks");
  if (file_ranks < 0 && here_ranks >= 0)
    throw Error("sphshell: checkpoint '" + path + "' is a serial Solver's checkpoint; a distributed solver loads "
                "only the files of a distributed one (one per rank): restart the run with the serial Solver");
  auto compare_counts = [&](const std::vector<NamedCount>& a, const std::vector<NamedCount>& b, const char* kind,
                            bool show_values) {
    for (std::size_t k = 0; k < b.size(); ++k) {
      if (k >= a.size() || a[k].name != b[k].name)
        throw Error(lead + kind + ": it lists no '" + b[k].name + "' (written by another format)");
      if (a[k].value != b[k].value)
        throw Error(lead + kind + ": the " + b[k].name + " differ" +
                    (show_values ? " (checkpoint: " + std::to_string(a[k].value) + ", this solver: " +
                                       std::to_string(b[k].value) + ")"
                                 : std::string(" (the checkpoint was written for another model)")));
    }
  };
  auto compare_values = [&](const std::vector<NamedValue>& a, const std::vector<NamedValue>& b, const char* kind) {
    for (std::size_t k = 0; k < b.size(); ++k) {
      if (k >= a.size() || a[k].name != b[k].name)
        throw Error(lead + kind + ": it lists no '" + b[k].name + "' (written by another format)");
      if (std::memcmp(&a[k].value, &b[k].value, sizeof(double)) != 0)
        throw Error(lead + kind + ": " + b[k].name + " is " + number_text(a[k].value) + " there and " +
                    number_text(b[k].value) + " in this solver");
    }
  };
  compare_counts(file.counts, here.counts, "model size", true);
  compare_counts(file.model, here.model, "model", false);
  compare_values(file.material, here.material, "material");
  compare_values(file.options, here.options, "set of options");
}

// A TIME section's Δt must be the one its identity lists, which matched this
// solver's: the steps were taken with it. `in` fails naming both otherwise.
template <class Reader>
void check_time_step(Reader& in, double time_step, double identity_time_step) {
  if (std::memcmp(&time_step, &identity_time_step, sizeof time_step) != 0)
    in.fail("its time step " + number_text(time_step) + " s is not the " + number_text(identity_time_step) +
            " s its identity lists");
}

// A TIME section's time must be t0 + n dt bit for bit (the solvers keep time
// that way); `in` fails naming both otherwise.
template <class Reader>
void check_time_of_steps(Reader& in, double start_time, long steps, double time_step, double time) {
  const double expected = start_time + static_cast<double>(steps) * time_step;
  if (std::memcmp(&expected, &time, sizeof time) != 0)
    in.fail("its time " + number_text(time) + " s is not t0 + n dt = " + number_text(expected) + " s");
}

// The header, the payload and the checksums, written atomically.
inline void write_file(const std::string& path, const std::array<std::string, 5>& policies,
                       const io::BinaryWriter& payload) {
  io::BinaryWriter header;
  header.write_raw(magic, sizeof magic);
  header(format_version, library_version());
  for (const std::string& name : policies) header(name);
  header(static_cast<std::uint64_t>(payload.size()), io::fnv1a(payload.bytes()));
  header(io::fnv1a(header.bytes()));
  io::detail::ReplacingOutputFile file(path);
  file.stream().write(header.bytes().data(), static_cast<std::streamsize>(header.size()));
  file.check();
  file.stream().write(payload.bytes().data(), static_cast<std::streamsize>(payload.size()));
  file.finish();
  file.sync_to_disk();
  file.replace();
}

// The whole file, checked (magic, version, header checksum, policies, size,
// payload checksum); the reader stands at the payload's first section.
inline io::BinaryReader read_file(const std::string& path, const std::array<std::string, 5>& policies) {
  const std::string name = "checkpoint '" + path + "'";
  std::ifstream in(path, std::ios::binary);
  if (!in) {
    // The two kinds of run name their files differently: say so when the other kind's file is there.
    if (std::ifstream(path + ".rank0"))
      throw Error("sphshell: cannot open " + name + " for reading; '" + path + ".rank0' is there: '" + path +
                  "' names a distributed checkpoint (one file per rank), which a serial Solver does not load");
    static constexpr const char rank_suffix[] = ".rank";
    const std::size_t suffix = path.rfind(rank_suffix);
    if (suffix != std::string::npos && std::ifstream(path.substr(0, suffix)))
      throw Error("sphshell: cannot open " + name + " for reading; '" + path.substr(0, suffix) + "' is there: it "
                  "is a serial Solver's checkpoint, which a distributed solver does not load");
    throw Error("sphshell: cannot open " + name + " for reading");
  }
  // The magic first: a large file of another kind is named as such before it is read whole.
  std::string bytes(sizeof magic, '\0');
  in.read(bytes.data(), static_cast<std::streamsize>(sizeof magic));
  if (in.bad()) throw Error("sphshell: failed while reading " + name);
  if (in.gcount() != static_cast<std::streamsize>(sizeof magic) ||
      std::memcmp(bytes.data(), magic, sizeof magic) != 0)
    throw Error("sphshell: " + name + " is not a sphshell checkpoint (it does not start with \"SPHSHCKP\")");
  bytes.append(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  if (in.bad()) throw Error("sphshell: failed while reading " + name);
  io::BinaryReader reader(std::move(bytes), name + " (header)", sizeof magic);
  // A field that does not fit: the file ends in its header, or a damaged
  // length points past it.
  auto read_header = [&](auto&... fields) {
    try {
      reader(fields...);
    } catch (const Error&) {
      throw Error("sphshell: " + name + " is truncated or its header is damaged: the header does not fit in the " +
                  std::to_string(reader.position()) + " bytes read");
    }
  };
  std::uint32_t version = 0;
  std::string written_by;
  std::array<std::string, 5> file_policies;
  std::uint64_t payload_size = 0, payload_checksum = 0, header_checksum = 0;
  read_header(version);
  if (version != format_version)
    throw Error("sphshell: " + name + " has format version " + std::to_string(version) + "; this library (" +
                library_version() + ") reads version " + std::to_string(format_version));
  read_header(written_by);
  for (std::string& policy : file_policies) read_header(policy);
  read_header(payload_size, payload_checksum);
  const std::size_t header_end = reader.position();
  read_header(header_checksum);
  // Header checksum over everything before it, then the policies (a foreign
  // file is named as such before its size is judged), then the payload.
  const std::size_t payload_begin = reader.position();
  std::string file = reader.release_bytes();
  if (io::fnv1a(file.data(), header_end) != header_checksum)
    throw Error("sphshell: " + name + " is corrupted: its header checksum does not match");
  for (std::size_t k = 0; k < policies.size(); ++k)
    if (file_policies[k] != policies[k])
      throw Error("sphshell: " + name + " was written by a solver with another " + policy_roles[k] +
                  " (checkpoint: " + file_policies[k] + ", this solver: " + policies[k] +
                  "); restore it into a Solver of the same five policy types");
  const std::size_t present = file.size() - payload_begin;
  if (present < payload_size)
    throw Error("sphshell: " + name + " is truncated: " + std::to_string(present) + " of its " +
                std::to_string(payload_size) + " payload bytes are there");
  if (present > payload_size)
    throw Error("sphshell: " + name + " has " + std::to_string(present - payload_size) +
                " bytes after its payload (not a file this library wrote)");
  if (io::fnv1a(file.data() + payload_begin, static_cast<std::size_t>(payload_size)) != payload_checksum)
    throw Error("sphshell: " + name + " is corrupted: its payload checksum (FNV-1a) does not match (written by "
                "sphshell " + written_by + ")");
  return io::BinaryReader(std::move(file), name, payload_begin);
}

// One section of a checkpoint: its name, then what body() writes or reads.
template <class Writer, class Body>
void write_section(Writer& out, const char (&name)[5], Body&& body) {
  out.begin_section(name);
  body();
  out.end_section();
}
template <class Reader, class Body>
void read_section(Reader& in, const char (&name)[5], Body&& body) {
  in.open_section(name);
  body();
  in.close_section();
}

// When the run writes its periodic checkpoints (OutputOptions): every N steps
// and/or every T seconds of wall-clock time. The clock only schedules the
// writes; nothing of it reaches the state.
class Schedule {
 public:
  explicit Schedule(const OutputOptions& options)
      : path_(options.checkpoint_path),
        every_steps_(options.checkpoint_every_steps),
        every_seconds_(options.checkpoint_every_seconds) {}

  bool is_due(long step) const {
    if (path_.empty() || step == last_step_) return false;
    if (every_steps_ > 0 && step % every_steps_ == 0) return true;
    return every_seconds_ > 0.0 &&
           std::chrono::duration<double>(Clock::now() - last_write_).count() >= every_seconds_;
  }
  // A checkpoint was written (or loaded) at this step: the wall clock restarts.
  void written(long step) {
    last_step_ = step;
    last_write_ = Clock::now();
  }
  const std::string& path() const { return path_; }
  bool enabled() const { return !path_.empty() && (every_steps_ > 0 || every_seconds_ > 0.0); }
  // Whether the wall clock can make a checkpoint due (a distributed run then
  // lets one rank's clock decide for all).
  bool by_clock() const { return !path_.empty() && every_seconds_ > 0.0; }

 private:
  using Clock = std::chrono::steady_clock;
  std::string path_;
  long every_steps_;
  double every_seconds_;
  long last_step_ = -1;
  Clock::time_point last_write_ = Clock::now();
};

}  // namespace sphshell::solver::checkpoint
