#pragma once
// Solver<Approx, Rule, Material, Crack, Stepper, Domain>: explicit dynamics
// of an SPH shell (docs/method.md; the paper's Table 2 program flow), on one
// process (domain::Serial, the default) or on the ranks of a communicator
// (mpi::Domain, docs/distributed.md): the serial run is the one-process case
// of the same code.
//
// Each step: loads → velocities (the stepper) → kinematic conditions → energy
// books → positions and directors (the stepper) → strains at the integration
// points from the new configuration → material update through the thickness →
// resultants → internal forces and moments on the particles → cracks → checks
// and output. The solver owns the parts that do each of these
// (include/sphshell/solver/) and hands them their state as plain structures;
// step() is the script of calls.
//
// Integration points are the stress points (membrane, bending and transverse
// shear) and, for stability, the particles themselves (docs/method.md,
// "Quadrature and the particle share"): the membrane and bending work is
// shared between the two sets, and the particles add a small, softened
// transverse-shear term. This removes the spurious zero-energy modes of
// stress-point-only quadrature without shear locking.
//
// The domain part (domain/domain.hpp) says which share of the shell this
// process steps. Set-up, from the same (replicated) model on every process:
// the whole model's integration points and section states, the stable step
// from them (so it is the serial value everywhere), the share (all of it
// serially; a recursive-coordinate-bisection partition over MPI), then only
// the share's particles (owned first, then ghosts), rows and states are kept.
// A distributed run computes its ghost rows redundantly (mpi/layout.hpp) so
// that every force on an owned particle is summed in the serial order: the
// owned particles' motion is bitwise the serial one for any process count.
// The step has two agreement points (the particle pass; the internal forces):
// a failure on any process stops every process with the message the serial
// step would stop with.

#include <sphshell/approx/approx.hpp>
#include <sphshell/approx/memory_estimate.hpp>
#include <sphshell/contact/body_set.hpp>
#include <sphshell/contact/solver_contact.hpp>
#include <sphshell/core/error.hpp>
#include <sphshell/core/parallel.hpp>
#include <sphshell/core/types.hpp>
#include <sphshell/crack/crack.hpp>
#include <sphshell/crack/none.hpp>
#include <sphshell/domain/serial.hpp>
#include <sphshell/material/material.hpp>
#include <sphshell/shell/constraints.hpp>
#include <sphshell/shell/loads.hpp>
#include <sphshell/shell/model.hpp>
#include <sphshell/shell/particle_selection.hpp>
#include <sphshell/io/binary_stream.hpp>
#include <sphshell/solver/checkpoint.hpp>
#include <sphshell/solver/checkpoint_io.hpp>
#include <sphshell/solver/conditions_and_loads.hpp>
#include <sphshell/solver/energy_ledger.hpp>
#include <sphshell/solver/fracture.hpp>
#include <sphshell/solver/integration_points.hpp>
#include <sphshell/solver/internal_forces.hpp>
#include <sphshell/solver/options.hpp>
#include <sphshell/solver/output.hpp>
#include <sphshell/solver/particle_pass.hpp>
#include <sphshell/solver/particle_share.hpp>
#include <sphshell/solver/particles.hpp>
#include <sphshell/solver/point_share.hpp>
#include <sphshell/solver/progress.hpp>
#include <sphshell/solver/run_checks.hpp>
#include <sphshell/solver/section_states.hpp>
#include <sphshell/solver/stable_time_step.hpp>
#include <sphshell/solver/static_solution.hpp>
#include <sphshell/solver/step_latch.hpp>
#include <sphshell/stepper/central_difference.hpp>
#include <sphshell/stepper/stepper.hpp>
#include <sphshell/thickness/section.hpp>

#include <cmath>
#include <cstddef>
#include <exception>
#include <new>
#include <optional>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

namespace sphshell {
template <class Approx, class Rule, class Material, class Crack = crack::None,
          class Stepper = stepper::CentralDifference, class Domain = domain::Serial>
class Solver : public solver::ConditionsAndLoads<Solver<Approx, Rule, Material, Crack, Stepper, Domain>>,
               public solver::PointShare<Approx, Rule, Material, Domain>,
               public solver::CheckpointIO<Solver<Approx, Rule, Material, Crack, Stepper, Domain>>,
               public contact::SolverContact<Solver<Approx, Rule, Material, Crack, Stepper, Domain>> {
  using Share = solver::PointShare<Approx, Rule, Material, Domain>;
  using Share::domain_, Share::particles_, Share::inertia_, Share::forces_, Share::reference_position_,
      Share::reference_normal_, Share::points_, Share::all_points_, Share::states_, Share::point_owned_,
      Share::global_point_, Share::model_point_count_, Share::model_slot_count_;
  using typename Share::Phase;
  using Conditions = solver::ConditionsAndLoads<Solver>;
  using Conditions::constraints_, Conditions::loads_;
  using Share::keep_first, Share::non_finite_load, Share::stop_if_alone, Share::load_context_at, Share::key;

  // Each family's check names the member a policy lacks; the message here says
  // which parameter it was.
  static_assert(approx::check_approximation<Approx>(),
                "Solver: the first parameter must be an approximation policy; use approx::MLS<Kernel> or "
                "approx::NSPH<Kernel>");
  static_assert(thickness::check_thickness_rule<Rule>(),
                "Solver: the second parameter must be a thickness rule; use thickness::Gauss<N>, "
                "thickness::Simpson<N> or thickness::Global");
  static_assert(material::check_material_law<Material>(),
                "Solver: the third parameter must be a material law; use material::Elastic, J2Plasticity or "
                "LemaitreDamage");
  static_assert(crack::check_crack_policy<Crack>(),
                "Solver: the fourth parameter must be a crack policy; use crack::None or crack::LineSegments");
  static_assert(stepper::check_stepper<Stepper>(),
                "Solver: the fifth parameter must be a stepper; use stepper::CentralDifference or a type "
                "meeting stepper/stepper.hpp");
  static_assert(domain::check_domain<Domain>(),
                "Solver: the sixth parameter must be a domain part; use domain::Serial or mpi::Domain");
  static constexpr bool distributed = Domain::is_distributed;

 public:
  using approximation_type = Approx;
  using rule_type = Rule;
  using material_type = Material;
  using crack_type = Crack;
  using stepper_type = Stepper;
  using domain_type = Domain;
  using Section = thickness::Section<Rule, Material>;
  using SectionState = typename Section::State;
  using MaterialParameters = typename Material::Parameters;
  using typename Share::Points;
  using typename Share::States;
  using Share::output_points;
  // Whether save_checkpoint compiles for these policies (solver/checkpoint.hpp).
  static constexpr bool can_checkpoint = solver::checkpoint::can_checkpoint<Crack, Stepper, SectionState>();

  // One process.
  template <class D = Domain, std::enable_if_t<!D::is_distributed, int> = 0>
  Solver(ShellModel model, const MaterialParameters& parameters, SolverOptions options = {})
      : solver::CheckpointIO<Solver>(options.output()),
        model_(std::move(model)),
        law_(parameters),
        options_(std::move(options)) {
    set_up({});
  }
  // Collective: every process of the domain passes the same model, parameters
  // and options; `where` (an mpi::Communicator) must outlive the solver.
  template <class Where, class D = Domain, std::enable_if_t<D::is_distributed, int> = 0>
  Solver(const Where& where, ShellModel model, const MaterialParameters& parameters, SolverOptions options = {},
         const typename D::Weights& weights = {})
      : Share(where),
        solver::CheckpointIO<Solver>(options.output()),
        model_(std::move(model)),
        law_(parameters),
        options_(std::move(options)) {
    set_up(weights);
  }

  // CSV time history of one particle: t, displacement, velocity, rotation;
  // written by the process that owns it. Collective.
  void add_particle_probe(const std::string& csv_path, int particle) {
    domain_.collectively([&] {
      solver::checked_set({particle}, model_.particle_count());
      output_->add_probe(csv_path, solver::ParticleProbe{particle}, *this);
    });
  }
  // CSV time history of one stress point: t, then the equivalent stress,
  // equivalent plastic strain and damage at each thickness output point
  // (integral points in the rule's order, ζ ascending). Collective.
  void add_stress_point_probe(const std::string& csv_path, int stress_point) {
    domain_.collectively([&] {
      this->check_stress_point(stress_point);
      output_->add_probe(csv_path, typename Output::StressProbe{stress_point}, *this);
    });
  }
  // Writes one ParaView frame now (particles, stress points and cracks),
  // whatever the output interval; requires output_directory. Collective.
  void write_frame() { output_->write_frame(*this); }

  // A pre-crack: a polyline on the shell (reference coordinates). Pairs across
  // it stop interacting at once. Stress points lying on it become its crack
  // points and leave the integration, so a pre-crack drawn along a row of
  // stress points is the crack that row's failure would form; a polyline
  // through a particle is an Error (the particle would tie the faces together).
  void add_precrack(const std::vector<Vector3>& polyline) {
    static_assert(Crack::enabled, "add_precrack needs a crack policy: a Solver with crack::None has no cracks; "
                                  "use crack::LineSegments as the fourth parameter");
    fracture_.add_precrack(polyline, fracture_parts());
  }
  // Stress points removed because they lie on a pre-crack (not counted as damaged).
  std::size_t precrack_stress_point_count() const { return fracture_.precrack_stress_point_count(); }
  // The crack topology (reference configuration), whole on every process; crack::None has none.
  const Crack& crack() const { return fracture_.crack(); }
  // Stress points removed from the force integration (all integral points failed).
  std::size_t damaged_stress_point_count() const { return fracture_.damaged_stress_point_count(); }
  bool is_fragment(int particle) const {
    this->check_particle(particle);
    return fracture_.is_fragment(static_cast<std::size_t>(particle));
  }
  std::size_t fragment_count() const { return fracture_.fragment_count(); }

  // One explicit step of size time_step() (collective). A step that stops
  // with an Error (an instability) leaves a half-updated state: every later
  // step() refuses with that error. Periodic checkpoints (OutputOptions) are
  // written after the steps that are due; by wall-clock time, process 0's
  // clock decides for all.
  void step() {
    latch_.run(steps_, [&] { advance(); });
    // Outside the latch: the state is whole, a failed write leaves the solver usable.
    if constexpr (can_checkpoint) this->save_if_due();
  }

  // A serial solver built from a checkpoint: the model, material and options
  // as for the run that wrote it, the state from the file. Then give the
  // conditions, loads and probes as for that run (not its pre-cracks: they
  // are in the file).
  template <class D = Domain, std::enable_if_t<!D::is_distributed, int> = 0>
  static Solver from_checkpoint(const std::string& path, ShellModel model, const MaterialParameters& parameters,
                                SolverOptions options = {}) {
    Solver solver(std::move(model), parameters, std::move(options));
    solver.load_checkpoint(path);
    return solver;
  }

  // Steps until time t_end (the step nearest it: the run stops within half a
  // step of t_end), calling observer(*this) after every step, on every
  // process (it may call the collective queries). With frames on
  // (OutputOptions), the last state is a frame, whether or not one was due.
  // The progress line (MonitoringOptions) then reports the share done and the time left.
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
    output_->finish(*this);
    progress_.end_run();
  }
  void run_until(double t_end) { run_until(t_end, [](const Solver&) {}); }

  // Static equilibrium under the loads evaluated at parameters.load_time and
  // scaled by each load factor in turn (statics/static_solve.hpp; docs/method.md,
  // "Static solutions"). After it the solver holds the equilibrium at rest
  // (velocities zero, energy books restarted at it) and can step on from there.
  // observer(const solver::StaticIteration&) is called after every iteration.
  // A load step that exhausts its budget throws solver::StaticNotConverged
  // (an Error) and leaves the solver at that step's lowest-residual state, at
  // rest with its forces and energy books restarted there (the exception's
  // result() describes it); any other Error (a free rigid-body mode, bad
  // parameters, a singular tangent) leaves the solver as it was before the
  // call. A distributed run relaxes (StaticMass::particle_bound), to the
  // bit as one process does; StaticMass::tangent is one process's only.
  template <class Observer>
  solver::StaticResult solve_static(const solver::StaticParameters& parameters, Observer&& observer) {
    latch_.check();
    return solver::StaticSolution<Solver>::solve(*this, parameters, observer);
  }
  solver::StaticResult solve_static(const solver::StaticParameters& parameters = {}) {
    return solve_static(parameters, [](const solver::StaticIteration&) {});
  }

  double time() const { return time_; }
  long steps() const { return steps_; }
  double time_step() const { return time_step_; }
  double stable_time_step() const { return stable_time_step_; }
  const ShellModel& model() const { return model_; }
  const Material& material() const { return law_; }
  const SolverOptions& options() const { return options_; }
  // The time integrator (the fifth template parameter).
  const Stepper& integrator() const { return stepper_; }
  // Moves the particles and directors to a new configuration at once (a
  // kinematic jump, used e.g. to probe the discrete stiffness): the strain
  // change goes through the material law like a step's, and the internal
  // forces are recomputed. Velocities are kept. One process only. The
  // directors are normalised.
  void set_configuration(std::vector<Vector3> positions, std::vector<Vector3> directors) {
    move_to_configuration(std::move(positions), std::move(directors), DirectorLength::normalise);
  }
  // The same for a configuration this solver held before (its positions()
  // and directors()), put back bit for bit: normalising a unit director again
  // may move it by a rounding unit. The directors must be of unit length to
  // round-off (within 1e-12).
  void restore_configuration(std::vector<Vector3> positions, std::vector<Vector3> directors) {
    move_to_configuration(std::move(positions), std::move(directors), DirectorLength::keep);
  }

 private:
  enum class DirectorLength { normalise, keep };
  void move_to_configuration(std::vector<Vector3> positions, std::vector<Vector3> directors, DirectorLength rule) {
    static_assert(!distributed, "set_configuration: a distributed run sets no configuration");
    constexpr double unit_length_tolerance = 1e-12;
    if (positions.size() != particles_.size() || directors.size() != particles_.size())
      detail::invalid_parameter("configuration size", positions.size(), "must equal the particle count");
    for (std::size_t i = 0; i < positions.size(); ++i) {
      if (!positions[i].allFinite())
        detail::invalid_parameter("position of particle " + std::to_string(i), positions[i].transpose(), "must be finite");
      const double length = directors[i].norm();
      if (!(length > 0.0) || !std::isfinite(length))
        detail::invalid_parameter("director length of particle " + std::to_string(i), length, "must be finite and non-zero");
      if (rule == DirectorLength::normalise)
        directors[i] /= length;
      else if (!(std::abs(length - 1.0) <= unit_length_tolerance))
        detail::invalid_parameter("director length of particle " + std::to_string(i) + " (restore_configuration)",
                                  length, "must be 1 to within 1e-12: restore a configuration the solver held");
    }
    particles_.position = std::move(positions);
    particles_.director = std::move(directors);
    compute_internal_forces();
  }

 public:
  // The energy books over all processes (collective).
  EnergyReport energy() const {
    if constexpr (distributed) {
      const typename Domain::Timer timer(domain_);
      typename Domain::EnergySum elastic;
      for (std::size_t p = 0; p < states_->size(); ++p)
        if (point_owned_[p] && states_->active(p))
          elastic.add(states_->stored_energy(p, points_->membrane_bending_weight(p), points_->shear_weight(p)));
      EnergyReport report = ledger_->report(domain_, elastic, fracture_.released_energy());
      if (bodies_.active()) report.add_rigid_bodies(bodies_.energy());  // the same on every process
      return report;
    } else {
      // A point out of action holds 0, which adds nothing.
      const double stored = assembler_->sum_over_points(*points_, [&](std::size_t p) {
        return states_->active(p)
                   ? states_->stored_energy(p, points_->membrane_bending_weight(p), points_->shear_weight(p))
                   : 0.0;
      });
      EnergyReport report = ledger_->report(domain_, stored, fracture_.released_energy());
      if (bodies_.active()) report.add_rigid_bodies(bodies_.energy());
      return report;
    }
  }

 private:
  using Ledger = solver::EnergyBooks<Domain>;
  using Fracture = solver::FractureManager<Crack, Domain>;
  using Output = solver::SolverOutput<output_points>;
  friend Output;
  friend class solver::CheckpointIO<Solver>;
  friend class solver::FramePiece<Solver>;
  friend class solver::StaticSolution<Solver>;
  friend class contact::SolverContact<Solver>;
  StepTime now() const { return {steps_, time_}; }
  contact::ContactParticles contact_particles() {
    return {particles_.position, particles_.director, particles_.velocity, particles_.angular_velocity,
            inertia_.mass,       this->contact_thicknesses()};
  }

  void set_up(const typename Domain::Weights& weights) try {
    domain_.collectively([&] {
      domain_.check_share(model_);
      validate(options_);
      solver::check_memory<SectionState>(model_, options_);
      // The whole model's points and states; the stable step from them.
      Points all_points(model_, options_.physics(), options_.particle_integration(), law_.shear_modulus(),
                        law_.poisson_ratio());
      States all_states(model_, law_, all_points.count(solver::PointGroup::particles));
      stable_time_step_ = solver::stable_time_step(model_, law_, options_.physics(), all_points, all_states);
      if (options_.time_step > 0.0) {
        if (options_.time_step > stable_time_step_)
          detail::invalid_parameter("time_step", options_.time_step,
                                    "exceeds the stable bound " + solver::number_text(stable_time_step_) + " s");
        time_step_ = options_.time_step;
      } else {
        time_step_ = options_.safety_factor * stable_time_step_;
      }
      solver::check_damping(options_.damping, time_step_);
      if (!can_checkpoint && this->periodic_checkpoints())
        detail::invalid_parameter("checkpoint_path", options_.checkpoint_path,
                                  "periodic checkpoints need policies that can be checkpointed: a material State "
                                  "that lists its fields (for_each_field), a crack policy and a stepper with state "
                                  "that have save/load (see solver/checkpoint.hpp); set checkpoint_every_steps and "
                                  "checkpoint_every_seconds to 0");
      // The share, and this process's part of everything.
      domain_.decompose(model_, all_points, weights);
      fracture_.initialize(model_, all_points, domain_);
      this->share_points(model_, std::move(all_points), std::move(all_states), Crack::enabled);
      this->share_particles(model_, options_);
      if constexpr (distributed)
        constraints_.name_particles_by(std::vector<int>(domain_.layout().owned.begin(), domain_.layout().owned.end()));
      assembler_.emplace(options_.nonlinear, *points_);
      ledger_.emplace(options_.monitoring(), law_.youngs_modulus(), solver::shell_volume(model_));
    });
    if constexpr (distributed) domain_.plan_halo();
    output_.emplace(domain_, options_.output(), options_.progress_stream);
  } catch (const std::bad_alloc&) {
    throw Error("sphshell: out of memory building the solver (std::bad_alloc): " + solver::memory_estimate_text());
  }

  solver::FractureParts<Approx, Rule, Material, Domain> fracture_parts() {
    return {domain_,     model_, particles_, all_points_ ? *all_points_ : *points_, *points_, *states_,
            *assembler_, forces_, point_owned_};
  }


  // The conditions and loads (solver/conditions_and_loads.hpp): every process
  // checks the whole set (the same Error everywhere), then applies it to the
  // members it owns.
  friend class solver::ConditionsAndLoads<Solver>;
  void apply_loads_now(const StepTime& at) {
    detail::LoadContext context = load_context_at(at.time);
    loads_.apply(at, context);
  }
  // The loads that cannot be applied in chunks (a user's pressure function), before the particle pass.
  void apply_loads(const StepTime& at, std::optional<domain::Failure>& failure) {
    try {
      apply_loads_now(at);
    } catch (...) {
      // A non-finite load: the serial message, with the lowest global id of
      // one here. Anything else (a load function that threw, of any type)
      // stops every process with its own message.
      for (std::size_t i = 0; i < domain_.owned_count(); ++i)
        if (!forces_.external[i].allFinite() || !forces_.external_moment[i].allFinite()) {
          keep_first(failure, non_finite_load(at, i));
          return;
        }
      keep_first(failure, domain_.failure_of_current_exception(key(Phase::loads, 0)));
    }
  }
  // Whether the particles' positions and directors were packed for the
  // gathers by the particle pass since they last moved (one process only: a
  // distributed run's ghosts come from the halo exchange, which packs them all).
  enum class Packing { needed, done_by_particle_pass };
  // Halo exchange, then the internal forces of every computed point; a
  // failing point stops every process with its global index.
  void compute_internal_forces(Packing packing = Packing::needed) {
    domain_.exchange({&particles_.position, &particles_.director});
    // The strain increments of this pass span one step (rate-dependent laws).
    assembler_->set_time_step(time_step_);
    std::optional<domain::Failure> failure;
    try {
      if (packing == Packing::done_by_particle_pass)
        assembler_->compute_packed(now(), *points_, *states_, forces_);
      else
        assembler_->compute(now(), particles_, *points_, *states_, forces_);
    } catch (...) {
      // Keyed by the failing point's global index: the serial pass stops at the lowest.
      long point = 0;
      if constexpr (distributed) point = static_cast<long>(global_point_[assembler_->failed_point()]);
      failure = domain_.failure_of_current_exception(point);
    }
    domain_.agree(failure);
    ledger_->book_internal_work(*assembler_, point_owned_);
    forces_current_ = true;
  }

  void advance() {
    if (!forces_current_) compute_internal_forces();
    if (steps_ == 0) output_->start(*this);
    const stepper::StepContext context{now(), time_step_, stepper_.velocity_step(steps_, time_step_),
                                       options_.damping};
    std::optional<domain::Failure> failure;
    const bool loads_in_pass = loads_.applies_in_chunks();
    if (!loads_in_pass) apply_loads(context.at, failure);
    stop_if_alone(failure);
    // The particle pass over the owned particles (solver/particle_pass.hpp).
    if (bodies_.active()) this->prepare_contact_step(ledger_->chunk_count(particles_));
    solver::ParticlePass<Ledger, Stepper> pass{
        loads_,   load_context_at(context.at.time), constraints_, reference_position_, time_step_, *ledger_,
        stepper_, particles_, inertia_, forces_, distributed ? nullptr : &*assembler_,
        bodies_.active() ? &bodies_ : nullptr};
    const solver::ParticlePassFailures failed = pass.run(context, loads_in_pass);
    if (failed.load < domain_.owned_count()) keep_first(failure, non_finite_load(context.at, failed.load));
    if (failed.condition_error) {
      const auto particle = static_cast<std::size_t>(constraints_.particles()[failed.condition]);
      try {
        std::rethrow_exception(failed.condition_error);
      } catch (...) {
        keep_first(failure,
                   domain_.failure_of_current_exception(key(Phase::motions, std::size_t(domain_.global_of(particle)))));
      }
    }
    stop_if_alone(failure);
    ledger_->finish_step();  // a failed step's terms never reach the books
    if (bodies_.active()) this->finish_contact_step(context.at, context.velocity_step);
    ++steps_;
    time_ = start_time_ + static_cast<double>(steps_) * time_step_;  // t = t0 + n Δt, never summed
    forces_current_ = false;
    if (failed.state < domain_.owned_count()) keep_first(failure, this->non_finite_state(now(), failed.state));
    domain_.agree(failure);
    compute_internal_forces(distributed ? Packing::needed : Packing::done_by_particle_pass);
    if constexpr (Crack::enabled) fracture_.update(fracture_parts());
    if (solver::EnergyLedger::is_check_step(steps_)) ledger_->check_balance(domain_, now(), energy());
    // The progress line, from the reduced books, written by process 0.
    if (progress_.is_due(steps_)) {
      const EnergyReport report = energy();
      if (domain_.is_root()) progress_.write(now(), report);
    }
    output_->write_scheduled(*this);
  }

  ShellModel model_;
  Material law_;
  SolverOptions options_;
  std::optional<solver::InternalForceAssembler> assembler_;
  std::optional<Ledger> ledger_;
  Fracture fracture_;
  Stepper stepper_;
  std::optional<Output> output_;
  solver::ProgressReporter progress_{options_.monitoring()};
  double stable_time_step_ = 0.0;
  double time_step_ = 0.0;
  double start_time_ = 0.0;  // t0
  double time_ = 0.0;
  long steps_ = 0;
  bool forces_current_ = false;
  contact::RigidBodySet bodies_;
  solver::StepLatch latch_;  // the error that stopped step(); later steps refuse with it
};

}  // namespace sphshell
