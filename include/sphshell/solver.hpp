#pragma once
// Solver<Approx, Rule, Material, Crack, Stepper>: explicit dynamics of an SPH
// shell (docs/method.md; the paper's Table 2 program flow).
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

#include <sphshell/approx/approx.hpp>
#include <sphshell/approx/memory_estimate.hpp>
#include <sphshell/core/error.hpp>
#include <sphshell/core/parallel.hpp>
#include <sphshell/core/types.hpp>
#include <sphshell/crack/crack.hpp>
#include <sphshell/crack/none.hpp>
#include <sphshell/material/material.hpp>
#include <sphshell/shell/constraints.hpp>
#include <sphshell/shell/loads.hpp>
#include <sphshell/shell/model.hpp>
#include <sphshell/shell/particle_selection.hpp>
#include <sphshell/io/binary_stream.hpp>
#include <sphshell/solver/checkpoint.hpp>
#include <sphshell/solver/conditions_and_loads.hpp>
#include <sphshell/solver/energy_ledger.hpp>
#include <sphshell/solver/fracture.hpp>
#include <sphshell/solver/integration_points.hpp>
#include <sphshell/solver/internal_forces.hpp>
#include <sphshell/solver/options.hpp>
#include <sphshell/solver/output.hpp>
#include <sphshell/solver/particle_pass.hpp>
#include <sphshell/solver/particles.hpp>
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
#include <cstdint>
#include <cstring>
#include <limits>
#include <array>
#include <atomic>
#include <exception>
#include <memory>
#include <mutex>
#include <new>
#include <sstream>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

namespace sphshell {

template <class Approx, class Rule, class Material, class Crack = crack::None,
          class Stepper = stepper::CentralDifference>
class Solver : public solver::ConditionsAndLoads<Solver<Approx, Rule, Material, Crack, Stepper>> {
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

 public:
  using approximation_type = Approx;
  using rule_type = Rule;
  using material_type = Material;
  using crack_type = Crack;
  using stepper_type = Stepper;
  using Section = thickness::Section<Rule, Material>;
  using SectionState = typename Section::State;
  using MaterialParameters = typename Material::Parameters;
  // Per stress point, the thickness output points k (integral points; one for Global).
  static constexpr int output_points = Section::output_points;
  // Whether save_checkpoint compiles for these policies (solver/checkpoint.hpp).
  static constexpr bool can_checkpoint = solver::checkpoint::can_checkpoint<Crack, Stepper, SectionState>();

  Solver(ShellModel model, const MaterialParameters& parameters, SolverOptions options = {}) try
      : model_(std::move(model)),
        law_(parameters),
        options_((validate(options), solver::check_memory<SectionState>(model_, options), std::move(options))),
        particles_(solver::ParticleState::at_rest(model_.particle_position, model_.particle_normal)),
        inertia_(solver::Inertia::lumped(model_, options_.density, options_.rotary_inertia_scale)),
        forces_(model_.particle_count()),
        points_(model_, options_.physics(), options_.particle_integration(), law_.shear_modulus(),
                law_.poisson_ratio()),
        states_(model_, law_, points_.count(solver::PointGroup::particles)),
        assembler_(options_.nonlinear, points_),
        ledger_(options_.monitoring(), law_.youngs_modulus(), solver::shell_volume(model_)),
        progress_(options_.monitoring()),
        output_(options_.output(), options_.progress_stream),
        checkpoints_(options_.output()) {
    fracture_.initialize(model_, points_);
    stable_time_step_ = solver::stable_time_step(model_, law_, options_.physics(), points_, states_);
    if (options_.time_step > 0.0) {
      if (options_.time_step > stable_time_step_)
        detail::invalid_parameter("time_step", options_.time_step,
                                  "exceeds the stable bound " + solver::number_text(stable_time_step_) + " s");
      time_step_ = options_.time_step;
    } else {
      time_step_ = options_.safety_factor * stable_time_step_;
    }
    solver::check_damping(options_.damping, time_step_);
    if (!can_checkpoint && checkpoints_.enabled())
      detail::invalid_parameter("checkpoint_path", options_.checkpoint_path,
                                "periodic checkpoints need policies that can be checkpointed: a material State "
                                "that lists its fields (for_each_field), a crack policy and a stepper with state "
                                "that have save/load (see solver/checkpoint.hpp); set checkpoint_every_steps and "
                                "checkpoint_every_seconds to 0");
  } catch (const std::bad_alloc&) {
    // Members are gone here; the estimate check_memory made is kept for the message.
    throw Error("sphshell: out of memory building the solver (std::bad_alloc): " + solver::memory_estimate_text());
  }

  // CSV time history of one particle: t, displacement, velocity, rotation.
  void add_particle_probe(const std::string& csv_path, int particle) {
    checked({particle});
    output_.add_probe(csv_path, solver::ParticleProbe{particle}, *this);
  }
  // CSV time history of one stress point: t, then the equivalent stress,
  // equivalent plastic strain and damage at each thickness output point
  // (integral points in the rule's order, ζ ascending).
  void add_stress_point_probe(const std::string& csv_path, int stress_point) {
    if (stress_point < 0 || static_cast<std::size_t>(stress_point) >= model_.stress_point_count())
      detail::invalid_parameter("stress point index", stress_point, "out of range");
    output_.add_probe(csv_path, typename Output::StressProbe{stress_point}, *this);
  }
  // Writes one ParaView frame now (particles, stress points and cracks),
  // whatever the output interval; requires output_directory.
  void write_frame() { output_.write_frame(*this); }

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
  // The crack topology (reference configuration); crack::None has none.
  const Crack& crack() const { return fracture_.crack(); }
  // Stress points removed from the force integration (all integral points failed).
  std::size_t damaged_stress_point_count() const { return fracture_.damaged_stress_point_count(); }
  bool is_fragment(int particle) const {
    check_particle(particle);
    return fracture_.is_fragment(static_cast<std::size_t>(particle));
  }
  std::size_t fragment_count() const { return fracture_.fragment_count(); }
  // Whether a stress point has left the integration (damaged or on a pre-crack).
  bool is_removed(int stress_point) const {
    check_output_point(stress_point, 0);
    return !states_.active(static_cast<std::size_t>(stress_point));
  }

  // One explicit step of size time_step(). A step that stops with an Error
  // (an instability) leaves a half-updated state: every later step() refuses
  // with that error.
  void step() {
    latch_.run(steps_, [&] { advance(); });
    // Outside the latch: the state is whole, a failed write leaves the solver usable.
    if constexpr (can_checkpoint)
      if (checkpoints_.is_due(steps_)) {
        save_checkpoint(checkpoints_.path());
        checkpoints_.written(steps_);
      }
  }

  // Checkpoint and restart (solver/checkpoint.hpp has the file format). A
  // checkpoint holds the whole state between two steps: particles, every
  // integration point's material state, strains and resultants, cracks and
  // fragments with the shape functions they changed, the energy books, t0, the
  // step count and Δt, the step latch, and the output and probe schedules. A
  // solver of the same five policies, model, material and result-changing
  // options that loads it continues bit for bit as the saving one would have.
  // The file is replaced atomically (a kill while writing leaves the previous
  // one whole).
  void save_checkpoint(const std::string& path) const {
    using solver::checkpoint::write_section;
    io::BinaryWriter out;
    write_section(out, "IDNT", [&] { out(identity()); });
    write_section(out, "TIME", [&] {
      out(start_time_, static_cast<std::int64_t>(steps_), time_step_, time_, forces_current_, latch_.message());
    });
    write_section(out, "PART", [&] { particles_.save(out); });
    write_section(out, "FORC", [&] { forces_.save(out); });
    write_section(out, "PNTS", [&] { points_.save(out, model_.particle_position, model_.particle_normal); });
    write_section(out, "SECT", [&] { states_.save(out); });
    write_section(out, "FRAC", [&] { fracture_.save(out); });
    write_section(out, "ENRG", [&] { ledger_.save(out); });
    out.begin_section("STEP");
    if constexpr (!std::is_empty_v<Stepper>) {
      static_assert(solver::checkpoint::has_save_load<Stepper>::value,
                    "save_checkpoint: the stepper has members but no save/load; add `template <class Writer> void "
                    "save(Writer&) const` and `template <class Reader> void load(Reader&)` (stepper/stepper.hpp)");
      stepper_.save(out);
    }
    out.end_section();
    write_section(out, "OUTP", [&] { output_.save(out); });
    solver::checkpoint::write_file(path, policies(), out);
  }

  // Loads a checkpoint into this solver, which must have been built with the
  // same policies, model, material and result-changing options (an Error
  // names what differs, or what is wrong with the file: not a checkpoint,
  // another format version, truncated, corrupted). Conditions and loads stay
  // as this solver has them; pre-cracks come from the checkpoint (do not add
  // them again). Probes already added continue their files from the
  // checkpoint's rows; probes added later do too, when their file is one the
  // checkpoint recorded. An Error after the file was accepted leaves the
  // solver stopped (step() refuses).
  void load_checkpoint(const std::string& path) {
    using solver::checkpoint::read_section;
    io::BinaryReader in = solver::checkpoint::read_file(path, policies());
    solver::checkpoint::Identity file;
    read_section(in, "IDNT", [&] { in(file); });
    solver::checkpoint::check_identity(file, identity(), path);
    try {
      // Rows a crack rebuilt here since construction go back to the model's.
      if (points_.any_rebuilt())
        points_ = solver::IntegrationPoints<Approx>(model_, options_.physics(), options_.particle_integration(),
                                                    law_.shear_modulus(), law_.poisson_ratio());
      assembler_ = solver::InternalForceAssembler(options_.nonlinear, points_);
      std::int64_t steps = 0;
      // The identity matched this solver's time step; the steps must have been taken with it.
      const double identity_time_step = time_step_;
      read_section(in, "TIME", [&] { in(start_time_, steps, time_step_, time_, forces_current_, latch_.message()); });
      steps_ = static_cast<long>(steps);
      solver::checkpoint::check_time_step(in, time_step_, identity_time_step);
      solver::checkpoint::check_time_of_steps(in, start_time_, steps_, time_step_, time_);
      read_section(in, "PART", [&] { particles_.load(in); });
      read_section(in, "FORC", [&] { forces_.load(in); });
      read_section(in, "PNTS", [&] { points_.load(in, model_.particle_count()); });
      read_section(in, "SECT", [&] { states_.load(in); });
      read_section(in, "FRAC", [&] { fracture_.load(in); });
      read_section(in, "ENRG", [&] { ledger_.load(in); });
      read_section(in, "STEP", [&] { if constexpr (!std::is_empty_v<Stepper>) stepper_.load(in); });
      read_section(in, "OUTP", [&] { output_.load(in, *this); });
      if (!in.at_end()) in.fail("there are bytes after its last section");
    } catch (const Error& error) {
      latch_.close(std::string("sphshell: loading a checkpoint failed part-way, so this solver's state is mixed and "
                               "it cannot step; the error was: ") +
                   error.what());
      throw;
    } catch (const std::exception& error) {
      // Not the file's fault (memory ran out, say), but the state is as mixed.
      const std::string message = "sphshell: loading checkpoint '" + path + "' failed part-way: " + error.what();
      latch_.close(message + "; this solver's state is mixed and it cannot step");
      throw Error(message);
    }
    checkpoints_.written(steps_);
  }

  // A solver built from a checkpoint: the model, material and options as for
  // the run that wrote it, the state from the file. Then give the conditions,
  // loads and probes as for that run (not its pre-cracks: they are in the file).
  static Solver from_checkpoint(const std::string& path, ShellModel model, const MaterialParameters& parameters,
                                SolverOptions options = {}) {
    Solver solver(std::move(model), parameters, std::move(options));
    solver.load_checkpoint(path);
    return solver;
  }

 private:
  void advance() {
    if (!forces_current_) compute_internal_forces();
    if (steps_ == 0) output_.start(*this);
    const stepper::StepContext context{now(), time_step_, stepper_.velocity_step(steps_, time_step_),
                                       options_.damping};
    const std::size_t unstable = advance_particles(context);
    ++steps_;
    time_ = start_time_ + static_cast<double>(steps_) * time_step_;  // t = t0 + n Δt, never summed
    forces_current_ = false;
    if (unstable < particles_.size()) fail_non_finite_state(unstable);
    compute_internal_forces(Packing::done_by_particle_pass);
    if constexpr (Crack::enabled) fracture_.update(fracture_parts());
    if (solver::EnergyLedger::is_check_step(steps_)) ledger_.check_balance(now(), energy());
    if (progress_.is_due(steps_)) progress_.write(now(), energy());
    output_.write_scheduled(*this);
  }

 public:
  // Steps until time t_end (the step nearest it: the run stops within half a
  // step of t_end), calling observer(*this) after every step. With frames on
  // (OutputOptions), the last state is a frame, whether or not one was due.
  // The progress line (MonitoringOptions) then reports the share done and the time left.
  template <class Observer>
  void run_until(double t_end, Observer&& observer) {
    solver::check_run_end(t_end, solver::RunPosition{time_, time_step_, steps_}, options_.max_steps_per_run);
    progress_.start_run(now(), t_end);
    while (time_ < t_end - 0.5 * time_step_) {
      step();
      observer(*this);
    }
    output_.finish(*this);
    progress_.end_run();
  }
  void run_until(double t_end) { run_until(t_end, [](const Solver&) {}); }

  // Static equilibrium under the loads evaluated at parameters.load_time and
  // scaled by each load factor in turn (solver/static_solution.hpp; docs/method.md,
  // "Static solutions"). After it the solver holds the equilibrium at rest
  // (velocities zero, energy books restarted at it) and can step on from there.
  // observer(const solver::StaticIteration&) is called after every iteration.
  // An Error (no convergence within the budget, a free rigid-body mode, bad
  // parameters) leaves the solver as it was before the call.
  template <class Observer>
  solver::StaticResult solve_static(const solver::StaticParameters& parameters, Observer&& observer) {
    latch_.check();
    solver::validate(parameters);
    const double load_time = std::isnan(parameters.load_time) ? time_ : parameters.load_time;
    const solver::ParticleState start = particles_;
    const solver::SectionStates<Rule, Material> start_states = states_;
    solver::SectionStates<Rule, Material> converged = states_;
    auto evaluate = [&](double load_factor) {
      apply_loads({steps_, load_time});
      for (std::size_t i = 0; i < particles_.size(); ++i) {
        forces_.external[i] *= load_factor;
        forces_.external_moment[i] *= load_factor;
      }
      assembler_.compute(now(), particles_, points_, states_, forces_);
    };
    auto save = [&] {
      if constexpr (!solver::is_path_independent_v<Material>) converged = states_;
    };
    auto restore = [&] {
      if constexpr (!solver::is_path_independent_v<Material>) states_ = converged;
    };
    solver::StaticSystem<Approx, decltype(evaluate), decltype(save), decltype(restore)> system{
        model_, particles_, forces_, constraints_, points_, evaluate, save, restore,
        options_.progress_stream};
    try {
      const solver::StaticResult result = solver::solve_static(system, parameters, observer);
      forces_current_ = true;
      ledger_.restart_at_rest(energy().elastic);
      return result;
    } catch (...) {
      particles_ = start;
      states_ = start_states;
      compute_internal_forces();
      throw;
    }
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

  std::size_t particle_count() const { return particles_.size(); }
  const std::vector<Vector3>& positions() const { return particles_.position; }
  const std::vector<Vector3>& directors() const { return particles_.director; }
  const std::vector<Vector3>& velocities() const { return particles_.velocity; }
  const std::vector<Vector3>& angular_velocities() const { return particles_.angular_velocity; }
  Vector3 displacement(int particle) const {
    check_particle(particle);
    return particles_.position[particle] - model_.particle_position[particle];
  }
  // Rotation vector taking the reference director to the current one.
  Vector3 rotation(int particle) const {
    check_particle(particle);
    return solver::rotation_vector(model_.particle_normal[particle], particles_.director[particle]);
  }
  const std::vector<double>& masses() const { return inertia_.mass; }
  const std::vector<double>& rotary_inertias() const { return inertia_.rotary_inertia; }
  const std::vector<Vector3>& internal_forces() const { return forces_.internal; }
  // ∂Π/∂d_j: the internal generalized force on each director.
  const std::vector<Vector3>& internal_director_forces() const { return forces_.internal_director; }

  // Moves the particles and directors to a new configuration at once (a
  // kinematic jump, used e.g. to probe the discrete stiffness): the strain
  // change goes through the material law like a step's, and the internal
  // forces are recomputed. Velocities are kept.
  void set_configuration(std::vector<Vector3> positions, std::vector<Vector3> directors) {
    if (positions.size() != particles_.size() || directors.size() != particles_.size())
      detail::invalid_parameter("configuration size", positions.size(), "must equal the particle count");
    for (std::size_t i = 0; i < positions.size(); ++i) {
      if (!positions[i].allFinite())
        detail::invalid_parameter("position of particle " + std::to_string(i), positions[i].transpose(), "must be finite");
      const double length = directors[i].norm();
      if (!(length > 0.0) || !std::isfinite(length))
        detail::invalid_parameter("director length of particle " + std::to_string(i), length, "must be finite and non-zero");
      directors[i] /= length;
    }
    particles_.position = std::move(positions);
    particles_.director = std::move(directors);
    compute_internal_forces();
  }

  // Per stress point and thickness output point k (integral point; one for Global).
  std::size_t stress_point_count() const { return model_.stress_point_count(); }
  double integral_point_quantity(solver::IntegralPointQuantity quantity, int stress_point, int k) const {
    check_output_point(stress_point, k);
    return states_.quantity(quantity, static_cast<std::size_t>(stress_point), k);
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
  // Membrane forces (N/m) and moments (N·m/m) at a stress point, Voigt (xx, yy, xy)
  // in its reference tangent frame.
  const StressVoigt& membrane_force(int stress_point) const {
    check_output_point(stress_point, 0);
    return states_.membrane_force(static_cast<std::size_t>(stress_point));
  }
  const StressVoigt& bending_moment(int stress_point) const {
    check_output_point(stress_point, 0);
    return states_.bending_moment(static_cast<std::size_t>(stress_point));
  }
  // Current stress point positions, interpolated from the particles.
  std::vector<Vector3> stress_point_positions() const {
    std::vector<Vector3> positions(model_.stress_point_count(), Vector3::Zero());
    const approx::ShapeFunctions& shape = points_.shape(solver::PointGroup::stress_points);
    parallel::for_each(std::size_t{0}, positions.size(), [&](std::size_t row) noexcept {
      for (std::size_t s = shape.row_begin[row]; s < shape.row_begin[row] + shape.row_size[row]; ++s)
        positions[row] += shape.value[s].phi * particles_.position[shape.neighbour[s]];
    });
    return positions;
  }

  EnergyReport energy() const {
    // A point out of action holds 0, which adds nothing.
    const double stored = assembler_.sum_over_points(points_, [&](std::size_t p) {
      return states_.active(p) ? states_.stored_energy(p, points_.membrane_bending_weight(p), points_.shear_weight(p))
                               : 0.0;
    });
    return ledger_.report(stored, fracture_.released_energy());
  }

 private:
  using Output = solver::SolverOutput<output_points>;
  using Parts = solver::FractureParts<Approx, Rule, Material>;

  StepTime now() const { return {steps_, time_}; }

  static std::array<std::string, 5> policies() {
    return solver::checkpoint::policy_names<Approx, Rule, Material, Crack, Stepper>();
  }
  // What a checkpoint must agree on with the solver loading it.
  solver::checkpoint::Identity identity() const {
    solver::checkpoint::Identity id;
    id.counts = {{"particle count", static_cast<std::uint64_t>(model_.particle_count())},
                 {"stress point count", static_cast<std::uint64_t>(model_.stress_point_count())},
                 {"integration point count", static_cast<std::uint64_t>(points_.size())},
                 {"shape-function slot count", static_cast<std::uint64_t>(points_.slot_count())}};
    id.model = solver::checkpoint::model_fingerprints(model_);
    id.material = solver::checkpoint::material_constants(law_);
    id.options = solver::checkpoint::result_options(options_, time_step_);
    return id;
  }
  Parts fracture_parts() { return Parts{model_, particles_, points_, states_, assembler_, forces_}; }

  // A set's indices in range and each listed once (solver/run_checks.hpp).
  ParticleSet checked(const ParticleSelection& set) const {
    return solver::checked_set(set.members(model_), model_.particle_count());
  }
  void check_particle(int particle) const {
    if (particle < 0 || static_cast<std::size_t>(particle) >= particles_.size())
      detail::invalid_parameter("particle index", particle, "out of range");
  }
  void check_output_point(int stress_point, int k) const {
    if (stress_point < 0 || static_cast<std::size_t>(stress_point) >= model_.stress_point_count())
      detail::invalid_parameter("stress point index", stress_point, "out of range");
    if (k < 0 || k >= output_points) detail::invalid_parameter("thickness output point", k, "out of range");
  }
  // The conditions and loads (solver/conditions_and_loads.hpp) on the checked set.
  friend class solver::ConditionsAndLoads<Solver>;
  template <class Add>
  void add_conditions(const ParticleSelection& set, Add&& add) {
    add(constraints_, checked(set), model_.particle_position, model_.particle_normal);
  }
  template <class Make>
  void add_load(const ParticleSelection& set, Make&& make) {
    loads_.add(make(checked(set)));
  }
  template <class Displacement>
  void check_displacement_start(const ParticleSelection& set, const Displacement& displacement) const {
    for (int i : checked(set))
      solver::check_prescribed_displacement_start(i, displacement(model_.particle_position[i], time_),
                                                  particles_.position[i] - model_.particle_position[i], time_, steps_,
                                                  model_.minimum_spacing());
  }


  void apply_loads(const StepTime& at) {
    detail::LoadContext context = load_context_at(at.time);
    loads_.apply(at, context);
  }
  detail::LoadContext load_context_at(double time) {
    return {time,         model_.particle_position, model_.particle_normal,
            particles_.director, model_.particle_area,  inertia_.mass,
            forces_.external,    forces_.external_moment};
  }

  // Whether the particles' positions and directors were packed for the
  // gathers by the particle pass since they last moved (advance_particles).
  enum class Packing { needed, done_by_particle_pass };
  void compute_internal_forces(Packing packing = Packing::needed) {
    if (packing == Packing::done_by_particle_pass)
      assembler_.compute_packed(now(), points_, states_, forces_);
    else
      assembler_.compute(now(), particles_, points_, states_, forces_);
    ledger_.book_internal_work(assembler_.internal_work());
    forces_current_ = true;
  }

  // The particles' part of a step (solver/particle_pass.hpp); the lowest
  // particle with a non-finite state is returned (particle count if none)
  // for advance() to report at the step's end time.
  std::size_t advance_particles(const stepper::StepContext& context) {
    const bool loads_in_pass = loads_.applies_in_chunks();
    if (!loads_in_pass) apply_loads(context.at);
    solver::ParticlePass<solver::EnergyLedger, Stepper> pass{
        loads_,    load_context_at(context.at.time), constraints_, model_.particle_position, time_step_, ledger_,
        stepper_,  particles_, inertia_, forces_, &assembler_};
    const solver::ParticlePassFailures failed = pass.run(context, loads_in_pass);
    if (failed.load < particles_.size()) ExternalLoads::fail_non_finite(context.at, failed.load);
    if (failed.condition_error) std::rethrow_exception(failed.condition_error);
    ledger_.finish_step();  // a failed step's terms never reach the books
    return failed.state;
  }

  [[noreturn]] void fail_non_finite_state(std::size_t i) const {
    detail::fail_unstable(now(), "non-finite state at particle " + std::to_string(i) + " (external force " +
                                     solver::number_text(forces_.external[i].norm()) + " N, internal force " +
                                     solver::number_text(forces_.internal[i].norm()) + " N)");
  }

  ShellModel model_;
  Material law_;
  SolverOptions options_;
  solver::ParticleState particles_;
  solver::Inertia inertia_;
  solver::ParticleForces forces_;
  solver::IntegrationPoints<Approx> points_;
  solver::SectionStates<Rule, Material> states_;
  solver::InternalForceAssembler assembler_;
  solver::FractureManager<Crack> fracture_;
  solver::EnergyLedger ledger_;
  solver::ProgressReporter progress_;
  Output output_;
  solver::checkpoint::Schedule checkpoints_;
  Stepper stepper_;
  detail::Constraints constraints_;
  ExternalLoads loads_;
  double stable_time_step_ = 0.0;
  double time_step_ = 0.0;
  double start_time_ = 0.0;  // t0
  double time_ = 0.0;
  long steps_ = 0;
  bool forces_current_ = false;
  solver::StepLatch latch_;  // the error that stopped step(); later steps refuse with it
};

}  // namespace sphshell
