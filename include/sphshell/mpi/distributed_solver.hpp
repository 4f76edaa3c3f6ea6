#pragma once
// mpi::DistributedSolver<Approx, Rule, Material, Crack, Stepper>: the
// Solver's step (solver.hpp) over the same parts, each rank on its share of
// the shell (docs/distributed.md).
//
// Set-up, on every rank from the same (replicated) model: the whole model's
// integration points and section states (as the Solver builds them), the
// stable step from them (so it is the serial value on every rank), the
// recursive-coordinate-bisection partition in the reference configuration,
// this rank's layout (owned particles, computed points, ghosts) and the halo
// plan. Then the rank keeps only its share: particles in the local numbering
// (owned first, then ghosts), the rows it computes (IntegrationPoints::subset,
// the edge-tied shear's corners renumbered) and their states.
//
// Ghost integration points are computed redundantly (mpi/layout.hpp says why):
// a rank computes every point whose row reaches a particle it owns, so every
// slot force on an owned particle is computed here and summed in the serial
// order; one halo exchange of positions and directors per step, nothing sent
// back. The owned particles' forces, and so positions, directors and
// velocities, are bitwise those of the serial Solver for any rank count and
// any thread count.
//
// The step is the Solver's script with two agreement points (the domain
// part, mpi/domain.hpp): the Solver's particle pass over the owned particles
// (solver/particle_pass.hpp: loads, velocities, conditions, books,
// configuration, finite-state check) ★ agreement (a load, a prescribed motion
// or a particle that is not finite, global ids; or any exception a user's
// function threw) → halo exchange → internal forces ★ agreement (the failing
// point's global index) → fracture → books → balance check (reduced books,
// decided alike on every rank). An exception on any rank therefore stops
// every rank with the same message.
//
// Particles, sets, loads and conditions are addressed by global ids or by the
// model's set names; a rank applies them to the members it owns. Cracks grow
// across rank boundaries with the whole crack set on every rank
// (mpi/distributed_fracture.hpp); frames are written in pieces and probes by
// the owning rank (mpi/distributed_output.hpp).

#include <sphshell/core/error.hpp>
#include <sphshell/core/parallel.hpp>
#include <sphshell/core/types.hpp>
#include <sphshell/crack/none.hpp>
#include <sphshell/material/material.hpp>
#include <sphshell/mpi/communicator.hpp>
#include <sphshell/mpi/distributed_fracture.hpp>
#include <sphshell/mpi/domain.hpp>
#include <sphshell/mpi/distributed_ledger.hpp>
#include <sphshell/mpi/distributed_output.hpp>
#include <sphshell/mpi/error_agreement.hpp>
#include <sphshell/mpi/exact_sum.hpp>
#include <sphshell/mpi/halo.hpp>
#include <sphshell/mpi/layout.hpp>
#include <sphshell/mpi/partition.hpp>
#include <sphshell/io/binary_stream.hpp>
#include <sphshell/solver.hpp>
#include <sphshell/solver/checkpoint.hpp>
#include <sphshell/solver/conditions_and_loads.hpp>
#include <sphshell/solver/particle_pass.hpp>

#include <array>
#include <chrono>
#include <cstring>
#include <ctime>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <memory>
#include <mutex>
#include <exception>
#include <optional>
#include <random>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

namespace sphshell::mpi {

template <class Approx, class Rule, class Material, class Crack = crack::None,
          class Stepper = stepper::CentralDifference>
class DistributedSolver
    : public solver::ConditionsAndLoads<DistributedSolver<Approx, Rule, Material, Crack, Stepper>> {
 public:
  using MaterialParameters = typename Material::Parameters;
  using Points = solver::IntegrationPoints<Approx>;
  using States = solver::SectionStates<Rule, Material>;
  // Whether save_checkpoint compiles for these policies (solver/checkpoint.hpp).
  static constexpr bool can_checkpoint = solver::checkpoint::can_checkpoint<
      Crack, Stepper, typename thickness::Section<Rule, Material>::State>();

  // Collective: every rank of comm passes the same model, parameters and
  // options. comm must outlive the solver.
  DistributedSolver(const Communicator& comm, ShellModel model, const MaterialParameters& parameters,
                    SolverOptions options = {}, const PartitionWeights& weights = {})
      : domain_(comm), model_(std::move(model)), law_(parameters), options_(std::move(options)) {
    domain_.collectively([&] { set_up(weights); });
    domain_.plan_halo();
    frames_ = DistributedFrames(domain_.communicator(), options_.output(), Crack::enabled);
  }

  // CSV history of one particle (global id; Solver::add_particle_probe's
  // columns and schedule), written by the rank that owns it. Collective.
  void add_particle_probe(const std::string& csv_path, int particle) {
    domain_.collectively([&] {
      solver::checked_set({particle}, model_.particle_count());
      require_new_probe_file(csv_path);
      DistributedProbe probe{DistributedProbe::Kind::particle, particle, csv_path, nullptr};
      if (owns(particle)) open_probe(probe, solver::ParticleProbe{particle}.columns());
      probes_.push_back(std::move(probe));
    });
  }
  // CSV history of one stress point (Solver::add_stress_point_probe's columns
  // and schedule: t, then the equivalent stress, equivalent plastic strain
  // and damage at each thickness output point), written by the rank that
  // owns the stress point. Collective.
  void add_stress_point_probe(const std::string& csv_path, int stress_point) {
    domain_.collectively([&] {
      if (stress_point < 0 || static_cast<std::size_t>(stress_point) >= model_.stress_point_count())
        sphshell::detail::invalid_parameter("stress point index", stress_point, "out of range");
      require_new_probe_file(csv_path);
      DistributedProbe probe{DistributedProbe::Kind::stress_point, stress_point, csv_path, nullptr};
      const std::vector<std::size_t>& rows = layout().computed[solver::index_of(solver::PointGroup::stress_points)];
      for (std::size_t k : owned_stress_rows())
        if (rows[k] == static_cast<std::size_t>(stress_point)) {
          probe.local_point = points_->point(solver::PointGroup::stress_points, k);
          open_probe(probe, stress_probe(stress_point).columns());
        }
      probes_.push_back(std::move(probe));
    });
  }
  // One ParaView frame now (particle and stress-point pieces per rank, their
  // .pvtu files, the crack frame, the .pvd series); needs output_directory.
  // Collective.
  void write_frame() {
    FramePiece piece;
    piece.time = time_;
    const bool deformed = options_.frame_coordinates == FrameCoordinates::deformed;
    for (std::size_t i = 0; i < layout().owned_count(); ++i) {
      piece.points.push_back(deformed ? particles_.position[i] : reference_position_[i]);
      piece.global_id.push_back(layout().owned[i]);
      piece.displacement.push_back(particles_.position[i] - reference_position_[i]);
      piece.velocity.push_back(particles_.velocity[i]);
      piece.director.push_back(particles_.director[i]);
      if constexpr (Crack::enabled) piece.fragment.push_back(fragment_flag(layout().owned[i]));
    }
    const io::VtuGrid stress_points = stress_point_piece();
    if constexpr (Crack::enabled) {
      const io::VtuGrid cracks = crack_frame();
      frames_.write(domain_.communicator(), piece, stress_points, &cracks, steps_);
    } else {
      frames_.write(domain_.communicator(), piece, stress_points, nullptr, steps_);
    }
  }

  // A pre-crack (Solver::add_precrack), on every rank alike (collective).
  void add_precrack(const std::vector<Vector3>& polyline) {
    static_assert(Crack::enabled, "add_precrack needs a crack policy: a solver with crack::None has no cracks; "
                                  "use crack::LineSegments as the fourth parameter");
    fracture_.add_precrack(polyline, fracture_parts());
  }
  // The crack topology, whole on every rank, and the fracture counters.
  const Crack& crack() const { return fracture_.crack(); }
  std::size_t damaged_stress_point_count() const { return fracture_.damaged_stress_point_count(); }
  std::size_t precrack_stress_point_count() const { return fracture_.precrack_stress_point_count(); }
  bool is_fragment(int particle) const {
    if (particle < 0 || static_cast<std::size_t>(particle) >= model_.particle_count())
      sphshell::detail::invalid_parameter("particle index", particle,
                                          "must lie in [0, " + std::to_string(model_.particle_count()) + ")");
    return fracture_.is_fragment(static_cast<std::size_t>(particle));
  }
  std::size_t fragment_count() const { return fracture_.fragment_count(); }

  // One step on every rank (collective). A step that stopped with an Error
  // leaves a half-updated state: later steps refuse with that error. With
  // periodic checkpoints (OutputOptions) every rank writes its file after
  // the steps that are due; by wall-clock time, rank 0's clock decides for all.
  void step() {
    latch_.run(steps_, [&] { advance(); });
    // Outside the latch: the state is whole, a failed write leaves the solver usable.
    if constexpr (can_checkpoint)
      if (checkpoint_due()) {
        save_checkpoint(checkpoints_.path());
        checkpoints_.written(steps_);
      }
  }
  // Checkpoints (collective). Each rank writes its own file, `path` + ".rank"
  // + its rank (the Solver's format, solver/checkpoint.hpp, replaced
  // atomically): its particles, forces, rows, section states and exact energy
  // books, the whole crack set, the step count, Δt, the step latch and the
  // frame and probe schedules, with a stamp of the save shared by all ranks.
  // A DistributedSolver of the same policies, model, material, options and
  // rank count that loads them continues bit for bit as the saving one would
  // have. An Error on every rank names a file of another rank count, rank,
  // model, material or options (nothing loaded: the solver stays usable), or
  // files of different saves, or a damaged file (the solver then refuses to
  // step). Conditions and loads stay as the loading solver has them; add
  // probes after loading: a probe on a file the checkpoint recorded continues
  // it from the checkpoint's rows (an Error if the file changed since).
  std::string checkpoint_file(const std::string& path) const { return domain_.checkpoint_file(path); }

  void save_checkpoint(const std::string& path) const {
    std::uint64_t stamp = 0;
    if (domain_.is_root())
      stamp = static_cast<std::uint64_t>(std::random_device{}()) << 32 ^
              static_cast<std::uint64_t>(std::chrono::steady_clock::now().time_since_epoch().count());
    stamp = domain_.communicator().all_gather(stamp).front();
    domain_.collectively([&] {
      using solver::checkpoint::write_section;
      io::BinaryWriter out;
      write_section(out, "IDNT", [&] { out(identity()); });
      write_section(out, "TIME", [&] {
        out(stamp, start_time_, static_cast<std::int64_t>(steps_), time_step_, time_, forces_current_, latch_.message());
      });
      write_section(out, "PART", [&] { particles_.save(out); });
      write_section(out, "FORC", [&] { forces_.save(out); });
      out.begin_section("PNTS");
      {
        // The local particles' reference positions and normals (a nonlinear
        // run's rows gather their reference gradients from them).
        std::vector<Vector3> reference_positions(layout().local_count()), reference_normals(layout().local_count());
        for (std::size_t k = 0; k < layout().local_count(); ++k) {
          const auto i = static_cast<std::size_t>(layout().global_of(k));
          reference_positions[k] = model_.particle_position[i];
          reference_normals[k] = model_.particle_normal[i];
        }
        points_->save(out, reference_positions, reference_normals);
      }
      if constexpr (Crack::enabled) all_points_->save(out, model_.particle_position, model_.particle_normal);
      out.end_section();
      write_section(out, "SECT", [&] { states_->save(out); });
      write_section(out, "FRAC", [&] { fracture_.save(out); });
      write_section(out, "ENRG", [&] { ledger_->save(out); });
      write_section(out, "STEP", [&] { if constexpr (!std::is_empty_v<Stepper>) stepper_.save(out); });
      out.begin_section("OUTP");
      frames_.save(out);
      out(next_probe_time_);
      // The owned probes' files, for probes added after a restart to continue them.
      std::uint64_t open_files = 0;
      for (const DistributedProbe& probe : probes_) open_files += probe.file ? 1 : 0;
      out(open_files);
      for (const DistributedProbe& probe : probes_)
        if (probe.file) {
          const io::CsvProbe::Resume written = probe.file->written();
          out(probe.path, static_cast<std::uint32_t>(probe.kind), static_cast<std::int64_t>(probe.index),
              written.bytes, written.hash);
        }
      out.end_section();
      solver::checkpoint::write_file(checkpoint_file(path), policies(), out);
    });
  }

  void load_checkpoint(const std::string& path) {
    const std::string file_path = checkpoint_file(path);
    // 1. Each rank's file and its identity; nothing changes yet.
    std::optional<io::BinaryReader> reader;
    domain_.collectively([&] {
      if (!probes_.empty())
        throw Error("sphshell: load_checkpoint: " + std::to_string(probes_.size()) +
                    " probe(s) were added before it; a distributed run adds its probes after loading a checkpoint");
      reader.emplace(solver::checkpoint::read_file(file_path, policies()));
      solver::checkpoint::Identity file;
      reader->open_section("IDNT");
      (*reader)(file);
      reader->close_section();
      solver::checkpoint::check_identity(file, identity(), file_path);
    });
    // 2. The state; a failure from here on leaves every rank stopped.
    std::uint64_t stamp = 0;
    try {
      domain_.collectively([&] { load_state(*reader, stamp); });
      const std::vector<std::uint64_t> stamps = domain_.communicator().all_gather(stamp);
      const std::vector<std::int64_t> steps = domain_.communicator().all_gather(static_cast<std::int64_t>(steps_));
      for (std::size_t r = 1; r < stamps.size(); ++r)
        if (stamps[r] != stamps[0])
          throw Error("sphshell: checkpoint files '" + path + ".rank0' (step " + std::to_string(steps[0]) + ") and '" +
                      path + ".rank" + std::to_string(r) + "' (step " + std::to_string(steps[r]) +
                      ") were written by different saves");
    } catch (const Error& error) {
      latch_.close(std::string("sphshell: loading a checkpoint failed part-way, so this solver's state is mixed and "
                               "it cannot step; the error was: ") +
                   error.what());
      throw;
    }
    checkpoints_.written(steps_);
  }

  // Whether a periodic checkpoint is due after this step, alike on every rank.
  bool checkpoint_due() const {
    const bool due = checkpoints_.is_due(steps_);
    return checkpoints_.by_clock() ? domain_.first_process_decides(due) : due;
  }

  // Steps until t_end, as Solver::run_until (collective).
  // observer(*this) is called after every step, on every rank (it may call
  // the collective queries).
  template <class Observer>
  void run_until(double t_end, Observer&& observer) {
    domain_.collectively([&] {
      solver::check_run_end(t_end, solver::RunPosition{time_, time_step_, steps_}, options_.max_steps_per_run);
    });
    progress_.start_run(now(), t_end);
    while (time_ < t_end - 0.5 * time_step_) {
      step();
      observer(*this);
    }
    if (frames_.writes_on_schedule() && frames_.last_frame_step() != steps_) write_frame();
    progress_.end_run();
  }
  void run_until(double t_end) { run_until(t_end, [](const DistributedSolver&) {}); }

  // Stress queries (Solver's), by global stress point, the same on every rank:
  // the owner's values are gathered (collective; for checks and small runs).
  double integral_point_quantity(solver::IntegralPointQuantity quantity, int stress_point, int k) const {
    domain_.collectively([&] {
      check_stress_point(stress_point);
      if (k < 0 || k >= output_points) sphshell::detail::invalid_parameter("thickness output point", k, "out of range");
    });
    return owner_values(stress_point, [&](std::size_t p) {
      return std::array<double, 3>{states_->quantity(quantity, p, k), 0.0, 0.0};
    })[0];
  }
  double equivalent_stress(int stress_point, int k) const {
    return integral_point_quantity(solver::IntegralPointQuantity::equivalent_stress, stress_point, k);
  }
  double equivalent_plastic_strain(int stress_point, int k) const {
    return integral_point_quantity(solver::IntegralPointQuantity::equivalent_plastic_strain, stress_point, k);
  }
  double damage(int stress_point, int k) const {
    return integral_point_quantity(solver::IntegralPointQuantity::damage, stress_point, k);
  }
  // Membrane forces (N/m) and moments (N·m/m), Voigt (xx, yy, xy) in the stress
  // point's reference tangent frame.
  StressVoigt membrane_force(int stress_point) const {
    domain_.collectively([&] { check_stress_point(stress_point); });
    const std::array<double, 3> n = owner_values(stress_point, [&](std::size_t p) {
      const StressVoigt& value = states_->membrane_force(p);
      return std::array<double, 3>{value[0], value[1], value[2]};
    });
    return StressVoigt(n[0], n[1], n[2]);
  }
  StressVoigt bending_moment(int stress_point) const {
    domain_.collectively([&] { check_stress_point(stress_point); });
    const std::array<double, 3> m = owner_values(stress_point, [&](std::size_t p) {
      const StressVoigt& value = states_->bending_moment(p);
      return std::array<double, 3>{value[0], value[1], value[2]};
    });
    return StressVoigt(m[0], m[1], m[2]);
  }
  // Whether a stress point has left the integration (damaged or on a pre-crack).
  bool is_removed(int stress_point) const {
    domain_.collectively([&] { check_stress_point(stress_point); });
    return owner_values(stress_point, [&](std::size_t p) {
             return std::array<double, 3>{states_->active(p) ? 0.0 : 1.0, 0.0, 0.0};
           })[0] != 0.0;
  }

  double time() const { return time_; }
  long steps() const { return steps_; }
  double time_step() const { return time_step_; }
  double stable_time_step() const { return stable_time_step_; }
  const ShellModel& model() const { return model_; }
  const SolverOptions& options() const { return options_; }
  const Communicator& communicator() const { return domain_.communicator(); }
  const RankLayout& layout() const { return domain_.layout(); }
  const HaloPlan& halo() const { return domain_.halo(); }
  const CommunicationCounters& counters() const { return domain_.counters(); }

  // This rank's particles in the local numbering (owned [0, owned), then ghosts).
  const solver::ParticleState& local_particles() const { return particles_; }
  const solver::ParticleForces& local_forces() const { return forces_; }
  int global_id(std::size_t local) const {
    if (local >= layout().local_count())
      sphshell::detail::invalid_parameter("local particle index", local,
                                          "must be below this rank's local_count() = " +
                                              std::to_string(layout().local_count()));
    return layout().global_of(local);
  }

  // The owned values of a per-particle field, in global order on every rank
  // (collective; O(N) bytes: for checks and small runs).
  std::vector<Vector3> gathered(const std::vector<Vector3>& local_field) const {
    // Checked on every rank together, so that a short field on one rank is
    // an Error on all of them, not a rank left waiting in the gather.
    domain_.collectively([&] {
      if (local_field.size() < layout().owned_count())
        sphshell::detail::invalid_parameter("local field size", local_field.size(),
                                            "must cover this rank's " + std::to_string(layout().owned_count()) +
                                                " owned particles (local numbering: owned, then ghosts)");
    });
    struct Entry {
      std::int64_t id;
      double value[3];
    };
    std::vector<Entry> mine(layout().owned_count());
    for (std::size_t i = 0; i < mine.size(); ++i)
      mine[i] = {layout().owned[i], {local_field[i].x(), local_field[i].y(), local_field[i].z()}};
    std::vector<Vector3> all(model_.particle_count(), Vector3::Zero());
    for (const Entry& entry : domain_.communicator().all_gather_v(mine))
      all[static_cast<std::size_t>(entry.id)] = Vector3(entry.value[0], entry.value[1], entry.value[2]);
    return all;
  }
  std::vector<Vector3> positions() const { return gathered(particles_.position); }
  std::vector<Vector3> directors() const { return gathered(particles_.director); }
  std::vector<Vector3> velocities() const { return gathered(particles_.velocity); }
  std::vector<Vector3> angular_velocities() const { return gathered(particles_.angular_velocity); }

  // The energy books over all ranks (collective).
  EnergyReport energy() {
    const Domain::Timer timer(domain_);
    ExactSum elastic;
    for (std::size_t p = 0; p < states_->size(); ++p)
      if (point_owned_[p] && states_->active(p))
        elastic.add(states_->stored_energy(p, points_->membrane_bending_weight(p), points_->shear_weight(p)));
    return ledger_->report(domain_.communicator(), elastic, fracture_.released_energy());
  }

 private:
  // Points with a failure during the configuration phase are keyed by phase,
  // then by global id, so a load failure wins over a later non-finite state
  // on another rank, as in the serial step.
  enum class Phase : long { loads = 0, motions = 1, configuration = 2 };

  void set_up(const PartitionWeights& weights) {
    detail::check_parts(domain_.size(), model_.particle_count());  // before rows that a tiny model cannot build
    validate(options_);
    using SectionState = typename thickness::Section<Rule, Material>::State;
    solver::check_memory<SectionState>(model_, options_);
    // The whole model's points and states, as the Solver builds them.
    const Points all_points(model_, options_.physics(), options_.particle_integration(), law_.shear_modulus(),
                           law_.poisson_ratio());
    const States all_states(model_, law_, all_points.count(solver::PointGroup::particles));
    stable_time_step_ = solver::stable_time_step(model_, law_, options_.physics(), all_points, all_states);
    if (options_.time_step > 0.0) {
      if (options_.time_step > stable_time_step_)
        sphshell::detail::invalid_parameter("time_step", options_.time_step,
                                            "exceeds the stable bound " + solver::number_text(stable_time_step_) + " s");
      time_step_ = options_.time_step;
    } else {
      time_step_ = options_.safety_factor * stable_time_step_;
    }
    solver::check_damping(options_.damping, time_step_);
    if (!can_checkpoint && checkpoints_.enabled())
      sphshell::detail::invalid_parameter(
          "checkpoint_path", options_.checkpoint_path,
          "periodic checkpoints need policies that can be checkpointed: a material State that lists its fields "
          "(for_each_field), a crack policy and a stepper with state that have save/load (see "
          "solver/checkpoint.hpp); set checkpoint_every_steps and checkpoint_every_seconds to 0");

    // The decomposition and this rank's share.
    const DecompositionInput input = decomposition_input(model_, all_points);
    partition_ = partition(input, domain_.size(), weights);
    domain_.set_layout(rank_layout(input, partition_, domain_.rank()));
    model_point_count_ = all_points.size();
    model_slot_count_ = all_points.slot_count();
    points_.emplace(local_points(all_points));
    std::vector<std::size_t> computed_points;
    for (solver::PointGroup group : solver::point_groups) {
      const std::size_t g = solver::index_of(group);
      for (std::size_t k = 0; k < layout().computed[g].size(); ++k) {
        computed_points.push_back(all_points.point(group, layout().computed[g][k]));
        point_owned_.push_back(layout().computed_is_owned[g][k]);
      }
    }
    global_point_ = computed_points;
    states_.emplace(all_states.subset(computed_points));

    // Particles in the local numbering.
    const std::size_t local = layout().local_count(), owned = layout().owned_count();
    const solver::Inertia all_inertia = solver::Inertia::lumped(model_, options_.density, options_.rotary_inertia_scale);
    for (std::size_t k = 0; k < local; ++k) {
      const auto i = static_cast<std::size_t>(layout().global_of(k));
      reference_position_.push_back(model_.particle_position[i]);
      reference_normal_.push_back(model_.particle_normal[i]);
      reference_area_.push_back(model_.particle_area[i]);
      inertia_.mass.push_back(all_inertia.mass[i]);
      inertia_.rotary_inertia.push_back(all_inertia.rotary_inertia[i]);
    }
    particles_ = solver::ParticleState::at_rest(reference_position_, reference_normal_);
    particles_.ranges = {0, owned, owned, local};
    constraints_.name_particles_by(std::vector<int>(layout().owned.begin(), layout().owned.end()));
    forces_ = solver::ParticleForces(local);
    assembler_.emplace(options_.nonlinear, *points_);
    fracture_.initialize(model_, all_points, layout());
    // Crack rebuilds run on the whole model's rows (fracture): kept only then.
    if constexpr (Crack::enabled) all_points_.emplace(all_points);
    ledger_.emplace(options_.monitoring(), law_.youngs_modulus(), solver::shell_volume(model_));
  }

  // A set of global ids: checked as the Solver checks it (range, each listed
  // once), then handed with its owned members in local indices to `apply`.
  // Collective: an Error on any rank stops all with the same message.
  template <class Apply>
  void on_set(const ParticleSelection& set, Apply&& apply) {
    domain_.collectively([&] {
      const ParticleSet global = solver::checked_set(set.members(model_), model_.particle_count());
      ParticleSet local;
      for (int i : global) {
        const int k = layout().local_of[static_cast<std::size_t>(i)];
        if (k >= 0 && static_cast<std::size_t>(k) < layout().owned_count()) local.push_back(k);
      }
      apply(global, local);
    });
  }

  // The conditions and loads (solver/conditions_and_loads.hpp): every rank
  // checks the whole set as the Solver does (the same Error everywhere), then
  // applies it to the members it owns.
  friend class solver::ConditionsAndLoads<DistributedSolver>;
  template <class Add>
  void add_conditions(const ParticleSelection& set, Add&& add) {
    on_set(set, [&](const ParticleSet& global, const ParticleSet& local) {
      add(checker_, global, model_.particle_position, model_.particle_normal);
      add(constraints_, local, reference_position_, reference_normal_);
    });
  }
  template <class Make>
  void add_load(const ParticleSelection& set, Make&& make) {
    on_set(set, [&](const ParticleSet&, const ParticleSet& local) { loads_.add(make(local)); });
  }
  // The Solver's check, by the owner of each particle; the failure first in
  // the set's order wins, as in the serial loop.
  template <class Displacement>
  void check_displacement_start(const ParticleSelection& set, const Displacement& displacement) {
    on_set(set, [&](const ParticleSet& global, const ParticleSet&) {
      std::optional<Failure> failure;
      for (std::size_t k = 0; k < global.size() && !failure; ++k) {
        const int i = global[k];
        if (!owns(i)) continue;
        const auto at = static_cast<std::size_t>(layout().local_of[static_cast<std::size_t>(i)]);
        try {
          solver::check_prescribed_displacement_start(i, displacement(model_.particle_position[i], time_),
                                                      particles_.position[at] - reference_position_[at], time_,
                                                      steps_, model_.minimum_spacing());
        } catch (...) {
          failure = domain_.failure_of_current_exception(static_cast<long>(k));
        }
      }
      agree(failure);
    });
  }

  // This rank's rows of the whole model's.
  Points local_points(const Points& all_points) const {
    return all_points.subset(layout().computed, layout().local_of, layout().local_count());
  }

  static std::array<std::string, 5> policies() {
    return solver::checkpoint::policy_names<Approx, Rule, Material, Crack, Stepper>();
  }
  // What a rank's checkpoint file must agree on with the solver loading it:
  // the Solver's identity (the whole model's counts) and the rank count and rank.
  solver::checkpoint::Identity identity() const {
    solver::checkpoint::Identity id;
    id.counts = {{"rank count", static_cast<std::uint64_t>(domain_.size())},
                 {"rank", static_cast<std::uint64_t>(domain_.rank())},
                 {"particle count", static_cast<std::uint64_t>(model_.particle_count())},
                 {"stress point count", static_cast<std::uint64_t>(model_.stress_point_count())},
                 {"integration point count", static_cast<std::uint64_t>(model_point_count_)},
                 {"shape-function slot count", static_cast<std::uint64_t>(model_slot_count_)}};
    id.model = solver::checkpoint::model_fingerprints(model_);
    id.material = solver::checkpoint::material_constants(law_);
    id.options = solver::checkpoint::result_options(options_, time_step_);
    return id;
  }

  // The sections after IDNT (load_checkpoint).
  void load_state(io::BinaryReader& in, std::uint64_t& stamp) {
    using solver::checkpoint::read_section;
    // Rows a crack rebuilt here since construction go back to the model's.
    bool rebuilt = points_->any_rebuilt();
    if constexpr (Crack::enabled) rebuilt = rebuilt || all_points_->any_rebuilt();
    if (rebuilt) {
      const Points fresh(model_, options_.physics(), options_.particle_integration(), law_.shear_modulus(),
                           law_.poisson_ratio());
      points_.emplace(local_points(fresh));
      if constexpr (Crack::enabled) all_points_.emplace(fresh);
    }
    assembler_.emplace(options_.nonlinear, *points_);
    std::int64_t steps = 0;
    // The identity matched this solver's time step; the steps must have been taken with it.
    const double identity_time_step = time_step_;
    read_section(in, "TIME", [&] {
      in(stamp, start_time_, steps, time_step_, time_, forces_current_, latch_.message());
    });
    steps_ = static_cast<long>(steps);
    solver::checkpoint::check_time_step(in, time_step_, identity_time_step);
    solver::checkpoint::check_time_of_steps(in, start_time_, steps_, time_step_, time_);
    read_section(in, "PART", [&] { particles_.load(in); });
    read_section(in, "FORC", [&] { forces_.load(in); });
    in.open_section("PNTS");
    points_->load(in, layout().local_count());
    if constexpr (Crack::enabled) all_points_->load(in, model_.particle_count());
    in.close_section();
    read_section(in, "SECT", [&] { states_->load(in); });
    read_section(in, "FRAC", [&] { fracture_.load(in); });
    read_section(in, "ENRG", [&] { ledger_->load(in); });
    read_section(in, "STEP", [&] { if constexpr (!std::is_empty_v<Stepper>) stepper_.load(in); });
    in.open_section("OUTP");
    frames_.load(in);
    in(next_probe_time_);
    std::uint64_t open_files = 0;
    in(open_files);
    restored_probes_.clear();
    for (std::uint64_t n = 0; n < open_files; ++n) {
      RestoredProbe record;
      std::uint32_t kind = 0;
      std::int64_t index = 0;
      in(record.path, kind, index, record.written.bytes, record.written.hash);
      if (kind > 1) in.fail("a probe of unknown kind " + std::to_string(kind));
      record.kind = static_cast<DistributedProbe::Kind>(kind);
      record.index = static_cast<int>(index);
      restored_probes_.push_back(std::move(record));
    }
    in.close_section();
    if (!in.at_end()) in.fail("there are bytes after its last section");
  }

  StepTime now() const { return {steps_, time_}; }
  using FractureParts = DistributedFractureParts<Approx, Rule, Material>;
  FractureParts fracture_parts() {
    return FractureParts{domain_.communicator(),      model_,     layout(), particles_, *all_points_, *points_,
                         *states_,   *assembler_, forces_, point_owned_};
  }

  void advance() {
    if (!forces_current_) compute_internal_forces();
    if (steps_ == 0 && frames_.writes_on_schedule() && frames_.last_frame_step() < 0) {
      write_frame();
      frames_.schedule_next(time_ + options_.output_interval);
    }
    const stepper::StepContext context{now(), time_step_, stepper_.velocity_step(steps_, time_step_),
                                       options_.damping};
    std::optional<Failure> failure;
    const bool loads_in_pass = loads_.applies_in_chunks();
    if (!loads_in_pass) apply_loads(context.at, failure);
    // The Solver's particle pass over the owned particles; the ghosts'
    // positions and directors come from the halo exchange, which packs them all.
    solver::ParticlePass<DistributedLedger, Stepper> pass{
        loads_,     load_context(context.at.time), constraints_, reference_position_, time_step_, *ledger_,
        stepper_,   particles_, inertia_, forces_, nullptr};
    const solver::ParticlePassFailures failed = pass.run(context, loads_in_pass);
    if (failed.load < layout().owned_count()) keep_first(failure, non_finite_load(context.at, failed.load));
    if (failed.condition_error) {
      const auto particle = static_cast<std::size_t>(constraints_.particles()[failed.condition]);
      try {
        std::rethrow_exception(failed.condition_error);
      } catch (...) {
        keep_first(failure, domain_.failure_of_current_exception(key(Phase::motions, layout().owned[particle])));
      }
    }
    ledger_->finish_step();
    ++steps_;
    time_ = start_time_ + static_cast<double>(steps_) * time_step_;  // t = t0 + n Δt, as the Solver
    forces_current_ = false;
    if (failed.state < layout().owned_count()) keep_first(failure, non_finite_state(failed.state));
    agree(failure);
    compute_internal_forces();
    if constexpr (Crack::enabled) fracture_.update(fracture_parts());
    if (solver::EnergyLedger::is_check_step(steps_)) {
      const EnergyReport report = energy();
      ledger_->check_balance(domain_.communicator(), now(), report, [&](std::size_t i) { return layout().global_of(i); });
    }
    // The Solver's progress line, from the reduced books, written by rank 0.
    if (progress_.is_due(steps_)) {
      const EnergyReport report = energy();
      if (domain_.is_root()) progress_.write(now(), report);
    }
    write_scheduled();
  }

  // The serial schedule (solver::SolverOutput::write_scheduled).
  void write_scheduled() {
    if (frames_.writes_on_schedule() && time_ >= frames_.next_frame_time() - 0.5 * time_step_) {
      if (frames_.last_frame_step() != steps_) write_frame();
      const double interval = options_.output_interval;
      const double passed = std::floor((time_ + 0.5 * time_step_ - frames_.next_frame_time()) / interval);
      frames_.schedule_next(frames_.next_frame_time() + interval * (std::max(0.0, passed) + 1.0));
    }
    if (!probes_.empty() && time_ >= next_probe_time_ - probe_schedule_tolerance * time_step_) {
      for (DistributedProbe& probe : probes_)
        if (probe.file) write_probe_row(probe);
      next_probe_time_ = time_ + options_.probe_interval;
    }
  }

  // What solver::ParticleProbe reads, for the particles owned here (global ids).
  struct OwnedView {
    const DistributedSolver& solver;
    struct Field {
      const std::vector<Vector3>& local;
      const std::vector<int>& local_of;
      const Vector3& operator[](int global) const { return local[static_cast<std::size_t>(local_of[global])]; }
    };
    double time() const { return solver.time_; }
    Field velocities() const { return {solver.particles_.velocity, solver.layout().local_of}; }
    Vector3 displacement(int global) const {
      const auto i = static_cast<std::size_t>(solver.layout().local_of[global]);
      return solver.particles_.position[i] - solver.reference_position_[i];
    }
    Vector3 rotation(int global) const {
      const auto i = static_cast<std::size_t>(solver.layout().local_of[global]);
      return solver::rotation_vector(solver.reference_normal_[i], solver.particles_.director[i]);
    }
  };
  // The current position of local stress-point row k, interpolated from the
  // particles (owned and ghosts: current after every step's exchange).
  Vector3 stress_point_position(std::size_t k) const {
    const approx::ShapeFunctions& shape = points_->shape(solver::PointGroup::stress_points);
    Vector3 position = Vector3::Zero();
    for (std::size_t s = shape.row_begin[k]; s < shape.row_begin[k] + shape.row_size[k]; ++s)
      position += shape.value[s].phi * particles_.position[static_cast<std::size_t>(shape.neighbour[s])];
    return position;
  }
  // Local stress-point rows owned here, in global order.
  std::vector<std::size_t> owned_stress_rows() const {
    const std::size_t g = solver::index_of(solver::PointGroup::stress_points);
    std::vector<std::size_t> rows;
    for (std::size_t k = 0; k < layout().computed[g].size(); ++k)
      if (layout().computed_is_owned[g][k]) rows.push_back(k);
    return rows;
  }

  // This rank's stress-point piece: a vertex cell at each active stress point
  // it owns, with the serial frame's stress-point cell arrays (integral-point
  // quantities per thickness output point, resultants, thickness, index).
  io::VtuGrid stress_point_piece() const {
    const std::size_t g = solver::index_of(solver::PointGroup::stress_points);
    const bool deformed = options_.frame_coordinates == FrameCoordinates::deformed;
    io::VtuGrid grid;
    grid.time = time_;
    std::vector<Vector3> displacement;
    std::vector<std::size_t> drawn;  // local points
    std::vector<int> index;          // global stress points
    for (std::size_t k : owned_stress_rows()) {
      const std::size_t p = points_->point(solver::PointGroup::stress_points, k);
      if (!states_->active(p)) continue;
      const auto q = layout().computed[g][k];
      const Vector3 current = stress_point_position(k), reference = model_.stress_point_position[q];
      grid.cells.add_vertex(static_cast<int>(grid.points.size()));
      grid.points.push_back(deformed ? current : reference);
      displacement.push_back(current - reference);
      drawn.push_back(p);
      index.push_back(static_cast<int>(q));
    }
    io::PointField displacement_field{"displacement", 3, {}};
    for (const Vector3& u : displacement) displacement_field.values.insert(displacement_field.values.end(), {u.x(), u.y(), u.z()});
    grid.point_fields = {displacement_field};
    const std::vector<std::string> names = solver::thickness_point_names<Rule>();
    for (const solver::IntegralPointQuantityInfo& info : solver::integral_point_quantities) {
      if (info.needs_damage_law && !Material::has_damage) continue;
      io::CellField field{info.name, output_points, {}, names};
      for (std::size_t p : drawn)
        for (int k = 0; k < output_points; ++k) field.values.push_back(states_->quantity(info.quantity, p, k));
      grid.cell_fields.push_back(std::move(field));
    }
    io::CellField membrane{"membrane_force", 3, {}, {"Nxx", "Nyy", "Nxy"}};
    io::CellField moment{"bending_moment", 3, {}, {"Mxx", "Myy", "Mxy"}};
    io::CellField thickness{"thickness", 1, {}};
    io::CellField stress_point{"stress_point", 1, {}, {}, io::FieldValues::integer};
    for (std::size_t n = 0; n < drawn.size(); ++n) {
      for (int c = 0; c < 3; ++c) {
        membrane.values.push_back(states_->membrane_force(drawn[n])[c]);
        moment.values.push_back(states_->bending_moment(drawn[n])[c]);
      }
      thickness.values.push_back(model_.stress_point_thickness(static_cast<std::size_t>(index[n])));
      stress_point.values.push_back(index[n]);
    }
    grid.cell_fields.push_back(std::move(membrane));
    grid.cell_fields.push_back(std::move(moment));
    grid.cell_fields.push_back(std::move(thickness));
    grid.cell_fields.push_back(std::move(stress_point));
    grid.note = std::string("sphshell frame piece (one rank's owned active stress points, a vertex cell each; "
                            "stress-point data as cell data), t = ") +
                io::detail::round_trip_decimal(time_) + " s; points: " + (deformed ? "deformed" : "reference") +
                " positions";
    return grid;
  }

  // The crack segments as lines, as the serial frame draws them: a damaged
  // stress point's crack point at the stress point's interpolated position, a
  // pre-crack point moved by its nearest particle's displacement; the owners
  // place the points and every rank gathers them (a crack has few points).
  // Collective; the grid is used on rank 0.
  io::VtuGrid crack_frame() const {
    const auto& crack = fracture_.crack();
    const std::vector<Vector3>& reference = crack.points();
    struct Placed {
      std::int64_t point;
      double position[3];
    };
    std::vector<Placed> mine;
    std::vector<char> from_stress_point(reference.size(), 0);
    for (std::size_t q = 0; q < model_.stress_point_count(); ++q) {
      const int k = crack.crack_point_of_stress_point(static_cast<int>(q));
      if (k >= 0) from_stress_point[static_cast<std::size_t>(k)] = 1;
    }
    const std::size_t g = solver::index_of(solver::PointGroup::stress_points);
    for (std::size_t k : owned_stress_rows()) {
      const int point = crack.crack_point_of_stress_point(static_cast<int>(layout().computed[g][k]));
      if (point < 0) continue;
      const Vector3 x = stress_point_position(k);
      mine.push_back({point, {x.x(), x.y(), x.z()}});
    }
    for (std::size_t k = 0; k < reference.size(); ++k) {
      if (from_stress_point[k]) continue;
      const int nearest = model_.nearest_particle(reference[k]);
      if (!owns(nearest)) continue;
      const auto i = static_cast<std::size_t>(layout().local_of[static_cast<std::size_t>(nearest)]);
      const Vector3 x = reference[k] + (particles_.position[i] - reference_position_[i]);
      mine.push_back({static_cast<std::int64_t>(k), {x.x(), x.y(), x.z()}});
    }
    std::vector<Vector3> current(reference.size(), Vector3::Zero());
    for (const Placed& placed : domain_.communicator().all_gather_v(mine))
      current[static_cast<std::size_t>(placed.point)] =
          Vector3(placed.position[0], placed.position[1], placed.position[2]);
    const bool deformed = options_.frame_coordinates == FrameCoordinates::deformed;
    io::VtuGrid grid;
    grid.time = time_;
    grid.points = deformed ? current : reference;
    io::PointField displacement{"displacement", 3, {}};
    for (std::size_t k = 0; k < reference.size(); ++k) {
      const Vector3 u = current[k] - reference[k];
      displacement.values.insert(displacement.values.end(), {u.x(), u.y(), u.z()});
    }
    io::CellField crack_id{"crack_id", 1, {}, {}, io::FieldValues::integer};
    for (const auto& segment : crack.segments()) {
      grid.cells.add_line(segment.start_point, segment.end_point);
      crack_id.values.push_back(segment.crack_id);
    }
    grid.point_fields = {displacement};
    grid.cell_fields = {crack_id};
    grid.note = "sphshell frame, t = " + io::detail::round_trip_decimal(time_) +
                " s: the crack segments as lines (crack_id per segment).";
    return grid;
  }

  // What solver::StressPointProbe reads, for a stress point owned here.
  struct StressPointView {
    const DistributedSolver& solver;
    std::size_t local_point;
    double time() const { return solver.time_; }
    double integral_point_quantity(solver::IntegralPointQuantity quantity, int, int k) const {
      return solver.states_->quantity(quantity, local_point, k);
    }
  };
  static constexpr int output_points = thickness::Section<Rule, Material>::output_points;
  static solver::StressPointProbe<output_points> stress_probe(int stress_point) {
    solver::StressPointProbe<output_points> probe(stress_point);
    probe.point_names = solver::thickness_point_names<Rule>();
    return probe;
  }
  void write_probe_row(DistributedProbe& probe) const {
    if (probe.kind == DistributedProbe::Kind::particle)
      probe.file->write_row(solver::ParticleProbe{probe.index}.row(OwnedView{*this}));
    else
      // A row needs no column names: no rule's names are built per row.
      probe.file->write_row(
          solver::StressPointProbe<output_points>(probe.index).row(StressPointView{*this, probe.local_point}));
  }
  // The owner's file of a new probe: the file a loaded checkpoint recorded
  // for the same probe continues from the checkpoint's rows; else a new
  // file starts with the row of now.
  void open_probe(DistributedProbe& probe, std::vector<std::string> columns) {
    for (auto record = restored_probes_.begin(); record != restored_probes_.end(); ++record)
      if (record->path == probe.path && record->kind == probe.kind && record->index == probe.index) {
        probe.file = std::make_unique<io::CsvProbe>(probe.path, std::move(columns), record->written);
        restored_probes_.erase(record);
        return;
      }
    probe.file = std::make_unique<io::CsvProbe>(probe.path, std::move(columns));
    write_probe_row(probe);
  }
  void require_new_probe_file(const std::string& csv_path) const {
    for (const DistributedProbe& probe : probes_)
      if (probe.path == csv_path)
        throw Error("sphshell: probe file '" + csv_path + "' is already the file of another probe; give each probe "
                    "a file of its own");
  }
  bool owns(int global) const { return domain_.owns(global); }
  void check_stress_point(int stress_point) const {
    if (stress_point < 0 || static_cast<std::size_t>(stress_point) >= model_.stress_point_count())
      sphshell::detail::invalid_parameter("stress point index", stress_point, "out of range");
  }
  // value(local point) of the rank that owns the stress point, on every rank.
  template <class Value>
  std::array<double, 3> owner_values(int stress_point, Value&& value) const {
    const std::size_t g = solver::index_of(solver::PointGroup::stress_points);
    std::vector<std::array<double, 3>> mine;
    for (std::size_t k : owned_stress_rows())
      if (layout().computed[g][k] == static_cast<std::size_t>(stress_point))
        mine.push_back(value(points_->point(solver::PointGroup::stress_points, k)));
    return domain_.communicator().all_gather_v(mine).front();
  }
  double fragment_flag(int global) const { return fracture_.is_fragment(static_cast<std::size_t>(global)) ? 1 : 0; }

  void agree(const std::optional<Failure>& failure) const { domain_.agree(failure); }
  long key(Phase phase, std::size_t global) const {
    return static_cast<long>(phase) * static_cast<long>(model_.particle_count() + 1) + static_cast<long>(global);
  }
  // The first failure of a step is the one the serial step would stop at.
  static void keep_first(std::optional<Failure>& kept, Failure candidate) {
    if (!kept || candidate.key < kept->key) kept = std::move(candidate);
  }

  sphshell::detail::LoadContext load_context(double time) {
    return {time,           reference_position_, reference_normal_, particles_.director,
            reference_area_, inertia_.mass,       forces_.external,  forces_.external_moment};
  }
  // The serial loads (a user's pressure function), before the particle pass.
  void apply_loads(const StepTime& at, std::optional<Failure>& failure) {
    sphshell::detail::LoadContext context = load_context(at.time);
    try {
      loads_.apply(at, context);
    } catch (...) {
      // A non-finite load: the serial message, with the lowest global id of
      // one here. Anything else (a load function that threw, of any type)
      // stops every rank with its own message.
      for (std::size_t i = 0; i < layout().owned_count(); ++i)
        if (!forces_.external[i].allFinite() || !forces_.external_moment[i].allFinite()) {
          keep_first(failure, non_finite_load(at, i));
          return;
        }
      keep_first(failure, domain_.failure_of_current_exception(key(Phase::loads, 0)));
    }
  }
  Failure non_finite_load(const StepTime& at, std::size_t i) const {
    const int id = layout().owned[i];
    return {key(Phase::loads, static_cast<std::size_t>(id)),
            unstable_text(at, "non-finite external load at particle " + std::to_string(id) +
                                  " (a pressure, force or moment function returned NaN or infinity)")};
  }
  // The Solver's message at the step's end time, with the global id.
  Failure non_finite_state(std::size_t i) const {
    const int id = layout().owned[i];
    return {key(Phase::configuration, static_cast<std::size_t>(id)),
            unstable_text(now(), "non-finite state at particle " + std::to_string(id) + " (external force " +
                                     solver::number_text(forces_.external[i].norm()) + " N, internal force " +
                                     solver::number_text(forces_.internal[i].norm()) + " N)")};
  }

  static std::string unstable_text(const StepTime& at, const std::string& what) {
    try {
      sphshell::detail::fail_unstable(at, what);
    } catch (const Error& error) {
      return error.what();
    }
    return what;
  }

  // Halo exchange, then the internal forces of every computed point; a
  // failing point stops every rank with its global index.
  void compute_internal_forces() {
    domain_.exchange({&particles_.position, &particles_.director});
    std::optional<Failure> failure;
    try {
      assembler_->compute(now(), particles_, *points_, *states_, forces_);
    } catch (const Error& error) {
      failure = Failure{static_cast<long>(global_point_[assembler_->failed_point()]), error.what()};
    } catch (...) {
      failure = domain_.failure_of_current_exception(0);
    }
    agree(failure);
    ledger_->book_internal_work(assembler_->work_increments(), point_owned_);
    forces_current_ = true;
  }

  Domain domain_;  // this rank's share, the halo and the agreement on failures
  ShellModel model_;
  Material law_;
  SolverOptions options_;
  Partition partition_;
  std::vector<Vector3> reference_position_, reference_normal_;
  std::vector<double> reference_area_;
  solver::ParticleState particles_;
  solver::Inertia inertia_;
  solver::ParticleForces forces_;
  std::optional<Points> all_points_;  // the whole model's rows, with cracks only
  std::optional<Points> points_;
  std::optional<States> states_;
  std::vector<std::size_t> global_point_;  // per local point: its index in the whole model's numbering
  std::vector<char> point_owned_;          // per local point: owned here (books its work)
  std::optional<solver::InternalForceAssembler> assembler_;
  std::optional<DistributedLedger> ledger_;
  DistributedFracture<Crack> fracture_;
  Stepper stepper_;
  sphshell::detail::Constraints constraints_;  // owned particles, local indices
  sphshell::detail::Constraints checker_;      // the whole sets, global ids: the Solver's checks and messages
  ExternalLoads loads_;
  DistributedFrames frames_;
  solver::ProgressReporter progress_{options_.monitoring()};
  solver::checkpoint::Schedule checkpoints_{options_.output()};
  std::vector<DistributedProbe> probes_;
  struct RestoredProbe {
    std::string path;
    DistributedProbe::Kind kind = DistributedProbe::Kind::particle;
    int index = 0;
    io::CsvProbe::Resume written;
  };
  std::vector<RestoredProbe> restored_probes_;  // recorded by a loaded checkpoint, not added again yet
  double next_probe_time_ = 0.0;
  // As the serial output's probe schedule (solver/output.hpp).
  static constexpr double probe_schedule_tolerance = 1e-9;
  std::size_t model_point_count_ = 0, model_slot_count_ = 0;  // the whole model's (checkpoint identity)
  double stable_time_step_ = 0.0;
  double time_step_ = 0.0;
  double start_time_ = 0.0;
  double time_ = 0.0;
  long steps_ = 0;
  bool forces_current_ = false;
  solver::StepLatch latch_;
};

}  // namespace sphshell::mpi
