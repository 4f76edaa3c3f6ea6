#pragma once
// Checkpoint and restart of a Solver (solver.hpp; the file format is
// solver/checkpoint.hpp's), a base part that owns the periodic schedule
// (OutputOptions: every so many steps or seconds) and the checkpoint API. It
// reads and writes the solver's state as the solver's friend.

#include <sphshell/core/error.hpp>
#include <sphshell/io/binary_stream.hpp>
#include <sphshell/solver/checkpoint.hpp>
#include <sphshell/solver/options.hpp>

#include <array>
#include <cstdint>
#include <exception>
#include <optional>
#include <string>
#include <type_traits>

namespace sphshell::solver {

template <class Solver>
class CheckpointIO {
 public:
  // Checkpoint and restart (solver/checkpoint.hpp has the file format). A
  // checkpoint holds the whole state between two steps: particles, every
  // integration point's material state, strains and resultants, cracks and
  // fragments with the shape functions they changed, the energy books, t0, the
  // step count and Δt, the step latch, and the output and probe schedules. A
  // solver of the same policies, model, material, result-changing options
  // (and process count) that loads it continues bit for bit as the saving one
  // would have. Each process writes its own file, checkpoint_file(path)
  // (`path` itself serially); a distributed save stamps its files alike, so
  // that files of different saves are not loaded together. The file is
  // replaced atomically (a kill while writing leaves the previous one whole).
  std::string checkpoint_file(const std::string& path) const { return self().domain_.checkpoint_file(path); }
  void save_checkpoint(const std::string& path) const {
    const Solver& s = self();
    constexpr bool distributed = Solver::domain_type::is_distributed;
    constexpr bool with_cracks = Solver::crack_type::enabled;
    using Stepper = typename Solver::stepper_type;
    const std::uint64_t stamp = s.domain_.save_stamp();
    s.domain_.collectively([&] {
      using checkpoint::write_section;
      io::BinaryWriter out;
      write_section(out, "IDNT", [&] { out(identity()); });
      write_section(out, "BDID", [&] { s.bodies_.save_descriptions(out); });
      write_section(out, "TIME", [&] {
        if constexpr (distributed) out(stamp);
        out(s.start_time_, static_cast<std::int64_t>(s.steps_), s.time_step_, s.time_, s.forces_current_, s.latch_.message());
      });
      write_section(out, "PART", [&] { s.particles_.save(out); });
      write_section(out, "FORC", [&] { s.forces_.save(out); });
      write_section(out, "PNTS", [&] {
        // The local particles' reference positions and normals (a nonlinear
        // run's rows gather their reference gradients from them).
        s.points_->save(out, s.reference_position_, s.reference_normal_);
        if constexpr (distributed && with_cracks)
          s.all_points_->save(out, s.model_.particle_position, s.model_.particle_normal);
      });
      write_section(out, "SECT", [&] { s.states_->save(out); });
      write_section(out, "FRAC", [&] { s.fracture_.save(out); });
      write_section(out, "ENRG", [&] { s.ledger_->save(out); });
      write_section(out, "BODY", [&] { s.bodies_.save(out); });
      out.begin_section("STEP");
      if constexpr (!std::is_empty_v<Stepper>) {
        static_assert(checkpoint::has_save_load<Stepper>::value,
                      "save_checkpoint: the stepper has members but no save/load; add `template <class Writer> void "
                      "save(Writer&) const` and `template <class Reader> void load(Reader&)` (stepper/stepper.hpp)");
        s.stepper_.save(out);
      }
      out.end_section();
      write_section(out, "OUTP", [&] { s.output_->save(out); });
      checkpoint::write_file(checkpoint_file(path), policies(), out);
    });
  }

  // Loads a checkpoint into this solver, which must have been built with the
  // same policies, model, material, result-changing options and process
  // count (an Error names what differs, or what is wrong with the file: not a
  // checkpoint, another format version, truncated, corrupted, another save's
  // file; nothing is loaded then, but for a damaged file). Conditions and loads stay
  // as this solver has them; pre-cracks come from the checkpoint (do not add
  // them again). Probes already added continue their files from the
  // checkpoint's rows; probes added later do too, when their file is one the
  // checkpoint recorded. Rigid bodies are added again, as the saving run had
  // them, before loading (the checkpoint holds their state, not their shape
  // or motion; an Error names a body count, kind or mass that differs); their
  // probes continue as the others do. An Error after the file was accepted
  // leaves the solver stopped (step() refuses).
  void load_checkpoint(const std::string& path) {
    Solver& s = self();
    const std::string file_path = checkpoint_file(path);
    std::optional<io::BinaryReader> reader;
    s.domain_.collectively([&] {
      reader.emplace(checkpoint::read_file(file_path, policies()));
      checkpoint::Identity file;
      checkpoint::read_section(*reader, "IDNT", [&] { (*reader)(file); });
      checkpoint::check_identity(file, identity(), file_path);
      // The rigid bodies, added again by the program, must be the checkpoint's.
      checkpoint::read_section(*reader, "BDID", [&] { s.bodies_.check_descriptions(*reader, file_path); });
    });
    try {
      std::uint64_t stamp = 0;
      s.domain_.collectively([&] { load_state(*reader, stamp); });
      s.domain_.check_same_save(path, stamp, s.steps_);
    } catch (const Error& error) {
      s.latch_.close(std::string("sphshell: loading a checkpoint failed part-way, so this solver's state is mixed and "
                               "it cannot step; the error was: ") +
                   error.what());
      throw;
    } catch (const std::exception& error) {
      // Not the file's fault (memory ran out, say), but the state is as mixed.
      const std::string message = "sphshell: loading checkpoint '" + path + "' failed part-way: " + error.what();
      s.latch_.close(message + "; this solver's state is mixed and it cannot step");
      throw Error(message);
    }
    schedule_.written(s.steps_);
  }

 protected:
  explicit CheckpointIO(const OutputOptions& options) : schedule_(options) {}

  bool periodic_checkpoints() const { return schedule_.enabled(); }
  // After a step: the periodic checkpoint, when due (alike on every process;
  // by wall-clock time, process 0's clock decides for all).
  void save_if_due() {
    const Solver& s = self();
    const bool due = schedule_.is_due(s.steps_);
    if (schedule_.by_clock() ? s.domain_.first_process_decides(due) : due) {
      save_checkpoint(schedule_.path());
      schedule_.written(s.steps_);
    }
  }

 private:
  const Solver& self() const { return static_cast<const Solver&>(*this); }
  Solver& self() { return static_cast<Solver&>(*this); }

  static std::array<std::string, 5> policies() {
    return checkpoint::policy_names<typename Solver::approximation_type, typename Solver::rule_type,
                                    typename Solver::material_type, typename Solver::crack_type,
                                    typename Solver::stepper_type>();
  }
  // What a checkpoint must agree on with the solver loading it (the whole
  // model's counts; distributed, the process count and rank too).
  checkpoint::Identity identity() const {
    const Solver& s = self();
    checkpoint::Identity id;
    s.domain_.add_identity(id.counts);
    id.counts.push_back({"particle count", static_cast<std::uint64_t>(s.model_.particle_count())});
    id.counts.push_back({"stress point count", static_cast<std::uint64_t>(s.model_.stress_point_count())});
    id.counts.push_back({"integration point count", static_cast<std::uint64_t>(s.model_point_count_)});
    id.counts.push_back({"shape-function slot count", static_cast<std::uint64_t>(s.model_slot_count_)});
    id.model = checkpoint::model_fingerprints(s.model_);
    id.material = checkpoint::material_constants(s.law_);
    id.options = checkpoint::result_options(s.options_, s.time_step_);
    return id;
  }
  // The sections after IDNT (load_checkpoint).
  void load_state(io::BinaryReader& in, std::uint64_t& stamp) {
    Solver& s = self();
    constexpr bool distributed = Solver::domain_type::is_distributed;
    constexpr bool with_cracks = Solver::crack_type::enabled;
    using Stepper = typename Solver::stepper_type;
    using checkpoint::read_section;
    // Rows a crack rebuilt here since construction go back to the model's.
    if (s.any_rebuilt())
      s.reset_rows(typename Solver::Points(s.model_, s.options_.physics(), s.options_.particle_integration(),
                                           s.law_.shear_modulus(), s.law_.poisson_ratio()));
    s.assembler_.emplace(s.options_.nonlinear, *s.points_);
    std::int64_t steps = 0;
    // The identity matched this solver's time step; the steps must have been taken with it.
    const double identity_time_step = s.time_step_;
    read_section(in, "TIME", [&] {
      if constexpr (distributed) in(stamp);
      in(s.start_time_, steps, s.time_step_, s.time_, s.forces_current_, s.latch_.message());
    });
    s.steps_ = static_cast<long>(steps);
    checkpoint::check_time_step(in, s.time_step_, identity_time_step);
    checkpoint::check_time_of_steps(in, s.start_time_, s.steps_, s.time_step_, s.time_);
    read_section(in, "PART", [&] { s.particles_.load(in); });
    read_section(in, "FORC", [&] { s.forces_.load(in); });
    read_section(in, "PNTS", [&] {
      s.points_->load(in, s.domain_.local_count());
      if constexpr (distributed && with_cracks) s.all_points_->load(in, s.model_.particle_count());
    });
    read_section(in, "SECT", [&] { s.states_->load(in); });
    read_section(in, "FRAC", [&] { s.fracture_.load(in); });
    read_section(in, "ENRG", [&] { s.ledger_->load(in); });
    read_section(in, "BODY", [&] { s.bodies_.load(in); });
    read_section(in, "STEP", [&] { if constexpr (!std::is_empty_v<Stepper>) s.stepper_.load(in); });
    read_section(in, "OUTP", [&] { s.output_->load(in, s); });
    if (!in.at_end()) in.fail("there are bytes after its last section");
  }


  checkpoint::Schedule schedule_;
};

}  // namespace sphshell::solver
