#pragma once
// Solver<Approx, Rule, Material, Crack>: explicit dynamics of an SPH shell
// (design.md §2, the paper's Table 2 program flow).
//
// Each step: strains at the integration points from the current particle
// positions and directors → material update through the thickness rule →
// resultants → internal forces and moments on the particles → central
// difference update of velocities, positions and directors.
//
// Integration points are the stress points (membrane, bending and transverse
// shear) and, for stability, the particles themselves (design.md §2.3): the
// membrane and bending work is shared between the two sets, and the particles
// add a small, softened transverse-shear term. This removes the spurious
// zero-energy modes of stress-point-only quadrature without shear locking.

#include <sphshell/approx/approx.hpp>
#include <sphshell/approx/neighbour_search.hpp>
#include <sphshell/core/error.hpp>
#include <sphshell/core/frame.hpp>
#include <sphshell/core/types.hpp>
#include <sphshell/crack/crack.hpp>
#include <sphshell/crack/none.hpp>
#include <sphshell/io/csv_probe.hpp>
#include <sphshell/io/pvd_collection.hpp>
#include <sphshell/io/vtu_writer.hpp>
#include <sphshell/material/material.hpp>
#include <sphshell/shell/constraints.hpp>
#include <sphshell/shell/kinematics.hpp>
#include <sphshell/shell/loads.hpp>
#include <sphshell/shell/model.hpp>
#include <sphshell/thickness/section.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <filesystem>
#include <iostream>
#include <memory>
#include <sstream>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

namespace sphshell {

struct SolverOptions {
  double density = 7850.0;  // ρ, kg/m³
  // Geometrically nonlinear (Green strain, paper §3.2) or linear (§3.1) analysis.
  bool nonlinear = true;
  // The time step is safety_factor × the stable bound (see stable_time_step()).
  double safety_factor = 0.8;
  // A user time step (s); 0 selects safety_factor × the bound. A step above the
  // bound is refused.
  double time_step = 0.0;
  // Mass-proportional damping coefficient c (1/s): M a = f − c M v. For
  // quasi-static solutions by dynamic relaxation; 0 for dynamics.
  double damping = 0.0;
  // Support radius of the approximation in units of the particle spacing.
  double support_radius_factor = 2.0;
  // Rotary inertia ρ d³/12 A is multiplied by this (≥ 1), as explicit FE shell
  // codes do to lift the shear–rotation frequency limit on thin shells.
  double rotary_inertia_scale = 1.0;
  double shear_correction = 5.0 / 6.0;  // κs of the elastic transverse shear
  // Particle integration (design.md §2.3): share of the membrane and bending
  // work carried by the particles (the stress points carry the rest), and the
  // particles' transverse-shear weight (fraction of their area) with its
  // stiffness softened by d² / (d² + softening Δ²). Any share > 0 removes the
  // stress points' spurious zero-energy modes (a free 11 × 11 plate keeps its
  // six rigid modes and a physical seventh from 0.02 up; at 0 the seventh is
  // spurious, at a quarter of that frequency).
  // Fracture: only stress points can become crack points (a particle on a
  // crack would tie its faces together), so a particle whose integral points
  // all fail just drops out and leaves softer material, not a crack. With a
  // large share such points fail on both sides of a crack tip, and the tip's
  // neighbours beside it fail next instead of the one ahead: in the
  // detonation tube (examples/detonation_tube.cpp) the crack then branches at
  // once, while with 0.02 it runs axially first, as in the paper, whose
  // stress points alone integrate. For fracture runs where the crack path
  // matters, use a small share such as 0.02.
  double particle_integration_share = 0.5;
  double particle_shear_weight = 0.01;
  double particle_shear_softening = 0.01;
  // Print a progress line every this many steps (0: quiet).
  long progress_interval = 0;
  // A run stops with an error when |energy balance| exceeds this fraction of
  // the largest energy in play (after the first steps).
  double energy_tolerance = 0.5;
  // ParaView output: every output_interval seconds of simulated time, one .vtu
  // of the particles and one of the stress points, gathered in particles.pvd and
  // stress_points.pvd inside output_directory (created if missing). An empty
  // directory writes nothing.
  std::string output_directory;
  double output_interval = 0.0;
  // Probes (add_particle_probe, add_stress_point_probe) write a CSV row every
  // probe_interval seconds (0: every step).
  double probe_interval = 0.0;
};

struct EnergyReport {
  double kinetic = 0.0;
  double internal = 0.0;             // work done on the shell's material (elastic + dissipated)
  double elastic = 0.0;              // recoverable part of internal
  double plastic_dissipation = 0.0;  // internal − elastic
  double external_work = 0.0;        // loads and prescribed motions
  double damping_work = 0.0;         // removed by mass-proportional damping
  double released_by_fracture = 0.0; // elastic energy held by integration points when they were removed (part of plastic_dissipation)
  // kinetic + internal + damping − external, zero up to the time-discretization
  // error. The leapfrog velocities live at half steps, so the internal energy
  // enters at the half step too (the mean of its two neighbouring values).
  double balance() const { return balance_; }

  double balance_ = 0.0;
};

template <class Approx, class Rule, class Material, class Crack = crack::None>
class Solver {
  // Each family's check names the member a policy lacks; the message here says
  // which parameter it was.
  static_assert(approx::check_approximation<Approx>(),
                "Solver: the first parameter must be an approximation policy (approx::MLS<Kernel> or approx::NSPH<Kernel>)");
  static_assert(thickness::check_thickness_rule<Rule>(),
                "Solver: the second parameter must be a thickness rule (thickness::Gauss<N>, thickness::Simpson<N> or thickness::Global)");
  static_assert(material::check_material_law<Material>(),
                "Solver: the third parameter must be a material law (material::Elastic, J2Plasticity or LemaitreDamage)");
  static_assert(crack::check_crack_policy<Crack>(),
                "Solver: the fourth parameter must be a crack policy (crack::None or crack::LineSegments)");

 public:
  using Section = thickness::Section<Rule, Material>;
  using SectionState = typename Section::State;
  using MaterialParameters = typename Material::Parameters;

  Solver(ShellModel model, const MaterialParameters& parameters, SolverOptions options = {})
      : model_(std::move(model)),
        law_(parameters),
        options_(options) {
    validate_options();
    initialize_particles();
    initialize_integration_points();
    stable_time_step_ = compute_stable_time_step();
    if (options_.time_step > 0.0) {
      if (options_.time_step > stable_time_step_)
        detail::invalid_parameter("time_step", options_.time_step,
                                  "exceeds the stable bound " + to_string(stable_time_step_) + " s");
      time_step_ = options_.time_step;
    } else {
      time_step_ = options_.safety_factor * stable_time_step_;
    }
  }

  // Boundary conditions on particle sets.
  void clamp(const ParticleSet& set) {
    for (int i : checked(set)) {
      constraints_.fix_all_translations(i);
      constraints_.fix_all_rotations(i);
    }
  }
  // Translations fixed, rotations free ("soft" simple support).
  void simply_support(const ParticleSet& set) {
    for (int i : checked(set)) constraints_.fix_all_translations(i);
  }
  // Translations fixed and the director kept from tilting along the edge
  // ("hard" simple support of Mindlin plates): fixes rotation about n × t.
  void simply_support_hard(const ParticleSet& set, const Vector3& edge_tangent) {
    for (int i : checked(set)) {
      constraints_.fix_all_translations(i);
      constraints_.fix_rotation(i, model_.particle_normal[i].cross(edge_tangent));
    }
  }
  // Mirror symmetry about a plane (given by its normal) through the particles:
  // no translation across the plane and no rotation tilting the director out of it.
  void symmetry_plane(const ParticleSet& set, const Vector3& plane_normal) {
    for (int i : checked(set)) {
      constraints_.fix_translation(i, plane_normal);
      constraints_.fix_rotation(i, model_.particle_normal[i].cross(plane_normal));
    }
  }
  void fix_translation(const ParticleSet& set, const Vector3& direction) {
    for (int i : checked(set)) constraints_.fix_translation(i, direction);
  }
  void fix_rotation(const ParticleSet& set, const Vector3& axis) {
    for (int i : checked(set)) constraints_.fix_rotation(i, axis);
  }
  // Prescribed displacement u(X, t) (a Vector3 from the reference position and
  // time) imposed on all three translations of the set.
  template <class DisplacementFunction>
  void prescribe_displacement(const ParticleSet& set, DisplacementFunction displacement) {
    static_assert(std::is_invocable_r_v<Vector3, DisplacementFunction, const Vector3&, double>,
                  "prescribe_displacement: the function must be callable as Vector3 u(const Vector3& X, double t)");
    for (int i : checked(set)) {
      const Vector3 start = displacement(model_.particle_position[i], time_);
      if (steps_ == 0 && start.norm() > 0.0)
        detail::invalid_parameter("prescribed displacement at t = 0, particle " + std::to_string(i),
                                  start.transpose(), "must be zero: the run starts from the reference configuration");
    }
    add_motion(set, std::make_unique<detail::PrescribedDisplacement<DisplacementFunction>>(
                        std::move(displacement)));
  }
  // Prescribed velocity v(X, t) imposed on all three translations of the set.
  template <class VelocityFunction>
  void prescribe_velocity(const ParticleSet& set, VelocityFunction velocity) {
    static_assert(std::is_invocable_r_v<Vector3, VelocityFunction, const Vector3&, double>,
                  "prescribe_velocity: the function must be callable as Vector3 v(const Vector3& X, double t)");
    add_motion(set, std::make_unique<detail::PrescribedVelocity<VelocityFunction>>(
                        std::move(velocity)));
  }

  // Loads. Pressure p(X, t) in Pa (see loads.hpp for the sign convention).
  template <class PressureFunction>
  void add_pressure(const ParticleSet& set, PressureFunction pressure,
                    PressureDirection direction = PressureDirection::follower) {
    static_assert(std::is_invocable_r_v<double, PressureFunction, const Vector3&, double>,
                  "add_pressure: the pressure must be callable as double p(const Vector3& X, double t)");
    loads_.push_back(std::make_unique<detail::PressureLoad<PressureFunction>>(
        checked(set), std::move(pressure), direction));
  }
  template <class TimeFunction = time_function::Step>
  void add_uniform_pressure(const ParticleSet& set, double pressure, TimeFunction time = {},
                            PressureDirection direction = PressureDirection::follower) {
    detail::require_finite("pressure", pressure);
    add_pressure(
        set, [pressure, time](const Vector3&, double t) { return pressure * time(t); }, direction);
  }
  template <class TimeFunction = time_function::Step>
  void add_point_force(const ParticleSet& set, const Vector3& force, TimeFunction time = {}) {
    if (!force.allFinite()) detail::invalid_parameter("point force", force.transpose(), "must be finite");
    loads_.push_back(std::make_unique<detail::PointForceLoad<TimeFunction>>(checked(set), force,
                                                                              std::move(time)));
  }

  // CSV time history of one particle: t, displacement, velocity, rotation.
  void add_particle_probe(const std::string& csv_path, int particle) {
    checked({particle});
    create_parent_directory(csv_path);
    probes_.push_back({io::CsvProbe(csv_path, {"t [s]", "ux [m]", "uy [m]", "uz [m]", "vx [m/s]",
                                               "vy [m/s]", "vz [m/s]", "rx [rad]", "ry [rad]", "rz [rad]"}),
                       particle, false});
    write_probe(probes_.back());
  }
  // CSV time history of one stress point: t, then the equivalent stress,
  // equivalent plastic strain and damage at each thickness output point
  // (integral points in the rule's order, ζ ascending).
  void add_stress_point_probe(const std::string& csv_path, int stress_point) {
    if (stress_point < 0 || static_cast<std::size_t>(stress_point) >= model_.stress_point_count())
      detail::invalid_parameter("stress point index", stress_point, "out of range");
    std::vector<std::string> columns{"t [s]"};
    for (int k = 1; k <= output_points; ++k) columns.push_back("equivalent_stress_" + std::to_string(k) + " [Pa]");
    for (int k = 1; k <= output_points; ++k) columns.push_back("equivalent_plastic_strain_" + std::to_string(k));
    for (int k = 1; k <= output_points; ++k) columns.push_back("damage_" + std::to_string(k));
    create_parent_directory(csv_path);
    probes_.push_back({io::CsvProbe(csv_path, std::move(columns)), stress_point, true});
    write_probe(probes_.back());
  }

  // Writes one ParaView frame now (particles and stress points), whatever the
  // output interval; requires output_directory.
  void write_frame() {
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
    io::write_vtu_points(particle_file, position_, particle_fields());
    particle_collection_->add(time_, particle_file);
    io::write_vtu_points(stress_file, stress_point_positions(), stress_point_fields());
    stress_point_collection_->add(time_, stress_file);
    if constexpr (Crack::enabled) write_crack_frame(suffix.str());
  }

  // Current stress point positions, interpolated from the particles.
  std::vector<Vector3> stress_point_positions() const {
    std::vector<Vector3> positions(model_.stress_point_count(), Vector3::Zero());
    const approx::ShapeFunctions& shape = shape_[0];
    for (std::size_t row = 0; row < positions.size(); ++row)
      for (std::size_t s = shape.row_begin[row]; s < shape.row_begin[row] + shape.row_size[row]; ++s)
        positions[row] += shape.phi[s] * position_[shape.neighbour[s]];
    return positions;
  }

  // A pre-crack: a polyline on the shell (reference coordinates). Pairs across
  // it stop interacting at once. Stress points lying on it become its crack
  // points and leave the integration, so a pre-crack drawn along a row of
  // stress points is the crack that row's failure would form; a polyline
  // through a particle is an Error (the particle would tie the faces together).
  void add_precrack(const std::vector<Vector3>& polyline) {
    static_assert(Crack::enabled,
                  "add_precrack needs a crack policy such as crack::LineSegments; a Solver with "
                  "crack::None has no cracks");
    reject_particles_on(polyline);
    const std::vector<int> absorbed = crack_.add_precrack(polyline);
    // Stress points on the pre-crack are its crack points: they leave the
    // integration as damaged ones would, and particles left without any
    // stress point become fragments.
    std::vector<int> new_fragments;
    for (int p : absorbed) {
      if (active_[p]) deactivate(static_cast<std::size_t>(p));
      for (int corner : particles_of_stress_point_[p])
        if (!fragment_[corner] && all_damaged_around(corner)) {
          fragment_[corner] = 1;
          new_fragments.push_back(corner);
          if (point_count(1) > 0 && active_[point_offset_[1] + corner]) deactivate(point_offset_[1] + corner);
        }
    }
    precrack_stress_points_ += absorbed.size();
    rebuild_near_segments(crack_.segments(), new_fragments);
  }
  // Stress points removed because they lie on a pre-crack (not counted as damaged).
  std::size_t precrack_stress_point_count() const { return precrack_stress_points_; }
  // The crack topology (reference configuration); crack::None has none.
  const Crack& crack() const { return crack_; }
  // Stress points removed from the force integration (all integral points failed).
  std::size_t damaged_stress_point_count() const { return damaged_stress_points_; }
  bool is_fragment(int particle) const {
    check_particle(particle);
    return fragment_[particle] != 0;
  }
  std::size_t fragment_count() const {
    return static_cast<std::size_t>(std::count(fragment_.begin(), fragment_.end(), 1));
  }

  // One explicit step of size time_step().
  void step() {
    if (!forces_current_) compute_internal_forces();
    if (steps_ == 0 && frames_written_ == 0 && !options_.output_directory.empty() &&
        options_.output_interval > 0.0) {
      write_frame();  // the reference configuration at t = 0
      next_frame_time_ = options_.output_interval;
    }
    const double dt = steps_ == 0 ? 0.5 * time_step_ : time_step_;  // leapfrog start-up
    apply_external_loads(time_);
    advance_velocities(dt);
    advance_configuration();
    time_ += time_step_;
    ++steps_;
    forces_current_ = false;
    check_configuration();
    compute_internal_forces();
    if constexpr (Crack::enabled) update_cracks();
    check_energy_balance();
    if (options_.progress_interval > 0 && steps_ % options_.progress_interval == 0) print_progress();
    write_scheduled_output();
  }

  // Steps until time t_end, calling observer(*this) after every step.
  template <class Observer>
  void run_until(double t_end, Observer&& observer) {
    detail::require_finite("t_end", t_end);
    while (time_ < t_end - 0.5 * time_step_) {
      step();
      observer(*this);
    }
  }
  void run_until(double t_end) {
    run_until(t_end, [](const Solver&) {});
  }

  double time() const { return time_; }
  long steps() const { return steps_; }
  double time_step() const { return time_step_; }
  double stable_time_step() const { return stable_time_step_; }
  const ShellModel& model() const { return model_; }
  const Material& material() const { return law_; }
  const SolverOptions& options() const { return options_; }

  std::size_t particle_count() const { return position_.size(); }
  const std::vector<Vector3>& positions() const { return position_; }
  const std::vector<Vector3>& directors() const { return director_; }
  const std::vector<Vector3>& velocities() const { return velocity_; }
  const std::vector<Vector3>& angular_velocities() const { return angular_velocity_; }
  Vector3 displacement(int particle) const {
    check_particle(particle);
    return position_[particle] - model_.particle_position[particle];
  }
  // Rotation vector taking the reference director to the current one.
  Vector3 rotation(int particle) const {
    check_particle(particle);
    const Vector3& from = model_.particle_normal[particle];
    const Vector3& to = director_[particle];
    const Vector3 axis = from.cross(to);
    const double sine = axis.norm();
    if (sine < 1e-300) return Vector3::Zero();
    return axis / sine * std::atan2(sine, from.dot(to));
  }
  const std::vector<double>& masses() const { return mass_; }
  const std::vector<double>& rotary_inertias() const { return rotary_inertia_; }
  const std::vector<Vector3>& internal_forces() const { return internal_force_; }
  // ∂Π/∂d_j: the internal generalized force on each director.
  const std::vector<Vector3>& internal_director_forces() const { return internal_director_force_; }

  // Moves the particles and directors to a new configuration at once (a
  // kinematic jump, used e.g. to probe the discrete stiffness): the strain
  // change goes through the material law like a step's, and the internal
  // forces are recomputed. Velocities are kept.
  void set_configuration(std::vector<Vector3> positions, std::vector<Vector3> directors) {
    if (positions.size() != position_.size() || directors.size() != director_.size())
      detail::invalid_parameter("configuration size", positions.size(), "must equal the particle count");
    for (std::size_t i = 0; i < positions.size(); ++i) {
      if (!positions[i].allFinite())
        detail::invalid_parameter("position of particle " + std::to_string(i), positions[i].transpose(), "must be finite");
      const double length = directors[i].norm();
      if (!(length > 0.0) || !std::isfinite(length))
        detail::invalid_parameter("director length of particle " + std::to_string(i), length, "must be finite and non-zero");
      directors[i] /= length;
    }
    position_ = std::move(positions);
    director_ = std::move(directors);
    compute_internal_forces();
  }

  // Per stress point, per thickness output point k (integral point; one for Global).
  static constexpr int output_points = Section::output_points;
  std::size_t stress_point_count() const { return model_.stress_point_count(); }
  double equivalent_stress(int stress_point, int k) const {
    check_output_point(stress_point, k);
    return section_of(stress_point).equivalent_stress(state_[stress_point], k);
  }
  double equivalent_plastic_strain(int stress_point, int k) const {
    check_output_point(stress_point, k);
    return section_of(stress_point).equivalent_plastic_strain(state_[stress_point], k);
  }
  double damage(int stress_point, int k) const {
    check_output_point(stress_point, k);
    return section_of(stress_point).damage(state_[stress_point], k);
  }
  // Membrane forces (N/m) and moments (N·m/m) at a stress point, Voigt (xx, yy, xy)
  // in its reference tangent frame.
  const StressVoigt& membrane_force(int stress_point) const {
    check_output_point(stress_point, 0);
    return membrane_[stress_point];
  }
  const StressVoigt& bending_moment(int stress_point) const {
    check_output_point(stress_point, 0);
    return moment_[stress_point];
  }

  EnergyReport energy() const {
    EnergyReport report;
    report.kinetic = kinetic_energy_;
    report.internal = internal_energy_;
    double elastic = 0.0;
    for (std::size_t p = 0; p < state_.size(); ++p)
      if (active_[p]) elastic += stored_energy(p);
    report.elastic = elastic;
    report.plastic_dissipation = internal_energy_ - elastic;
    report.external_work = external_work_;
    report.damping_work = damping_work_;
    report.released_by_fracture = released_energy_;
    report.balance_ = kinetic_energy_ + 0.5 * (previous_internal_energy_ + internal_energy_) +
                      damping_work_ - external_work_;
    return report;
  }

 private:
  void validate_options() const {
    detail::require_positive("density", options_.density);
    detail::require_half_open_interval("safety_factor", options_.safety_factor, 0.0, 1.0);
    detail::require_nonnegative("time_step", options_.time_step);
    detail::require_nonnegative("damping", options_.damping);
    detail::require_positive("support_radius_factor", options_.support_radius_factor);
    if (!(options_.rotary_inertia_scale >= 1.0) || !std::isfinite(options_.rotary_inertia_scale))
      detail::invalid_parameter("rotary_inertia_scale", options_.rotary_inertia_scale, "must be finite and >= 1");
    detail::require_half_open_interval("shear_correction", options_.shear_correction, 0.0, 1.0);
    if (!(options_.particle_integration_share >= 0.0 && options_.particle_integration_share < 1.0))
      detail::invalid_parameter("particle_integration_share", options_.particle_integration_share,
                                "must lie in [0, 1)");
    detail::require_nonnegative("particle_shear_weight", options_.particle_shear_weight);
    detail::require_nonnegative("particle_shear_softening", options_.particle_shear_softening);
    detail::require_positive("energy_tolerance", options_.energy_tolerance);
    detail::require_nonnegative("output_interval", options_.output_interval);
    detail::require_nonnegative("probe_interval", options_.probe_interval);
  }

  void check_particle(int particle) const {
    if (particle < 0 || static_cast<std::size_t>(particle) >= position_.size())
      detail::invalid_parameter("particle index", particle, "out of range");
  }
  void check_output_point(int stress_point, int k) const {
    if (stress_point < 0 || static_cast<std::size_t>(stress_point) >= model_.stress_point_count())
      detail::invalid_parameter("stress point index", stress_point, "out of range");
    if (k < 0 || k >= output_points)
      detail::invalid_parameter("thickness output point", k, "out of range");
  }

  ParticleSet checked(const ParticleSet& set) const {
    if (set.empty()) detail::invalid_parameter("particle set size", 0, "must not be empty");
    for (int i : set)
      if (i < 0 || static_cast<std::size_t>(i) >= model_.particle_count())
        detail::invalid_parameter("particle index", i, "out of range");
    return set;
  }

  template <class Motion>
  void add_motion(const ParticleSet& set, std::unique_ptr<Motion> motion) {
    const ParticleSet particles = checked(set);
    for (int i : particles) {
      const Vector3 v = motion->velocity(i, model_.particle_position[i], time_, time_step_);
      if (!v.allFinite())
        detail::invalid_parameter("prescribed motion at particle " + std::to_string(i), v.transpose(),
                                  "must be finite");
    }
    const detail::PrescribedMotion* owned = constraints_.own(std::move(motion));
    for (int i : particles) {
      constraints_.fix_all_translations(i);
      constraints_.add_motion(i, owned);
    }
  }

  static void create_parent_directory(const std::string& path) {
    const std::filesystem::path parent = std::filesystem::path(path).parent_path();
    if (!parent.empty()) std::filesystem::create_directories(parent);
  }

  static std::string to_string(double value) {
    std::ostringstream out;
    out.precision(6);
    out << value;
    return out.str();
  }

  void initialize_particles() {
    const std::size_t n = model_.particle_count();
    position_ = model_.particle_position;
    director_ = model_.particle_normal;
    velocity_.assign(n, Vector3::Zero());
    angular_velocity_.assign(n, Vector3::Zero());
    mass_.resize(n);
    rotary_inertia_.resize(n);
    for (std::size_t i = 0; i < n; ++i) {
      const double d = model_.particle_thickness(i);
      mass_[i] = options_.density * d * model_.particle_area[i];
      rotary_inertia_[i] =
          options_.rotary_inertia_scale * options_.density * d * d * d / 12.0 * model_.particle_area[i];
    }
    internal_force_.assign(n, Vector3::Zero());
    internal_director_force_.assign(n, Vector3::Zero());
    external_force_.assign(n, Vector3::Zero());
  }

  // Shape functions at the stress points (group 0) and at the particles (group
  // 1), built once in the reference configuration (total Lagrangian).
  void initialize_integration_points() {
    const double spacing = model_.maximum_spacing();
    smoothing_length_ =
        options_.support_radius_factor * spacing / Approx::kernel_type::support_radius_factor;
    for (const Vector3& normal : model_.stress_point_normal) frames_[0].push_back(tangent_frame(normal));
    for (const Vector3& normal : model_.particle_normal) frames_[1].push_back(tangent_frame(normal));
    shape_[0] = Approx::build(model_.particle_position, model_.particle_area,
                              model_.stress_point_position, frames_[0], smoothing_length_);
    const bool particles_integrate =
        options_.particle_integration_share > 0.0 || options_.particle_shear_weight > 0.0;
    if (particles_integrate)
      shape_[1] = Approx::build(model_.particle_position, model_.particle_area,
                                model_.particle_position, frames_[1], smoothing_length_);

    // A row that fell back to the constant approximation has no gradient: the
    // support is too small for the spacing.
    for (int group = 0; group < 2; ++group)
      for (std::size_t row = 0; row < shape_[group].rows(); ++row)
        if (shape_[group].shepard[row])
          detail::invalid_parameter("support_radius_factor", options_.support_radius_factor,
                                    std::string("too few neighbours (fewer than 3) at ") +
                                        (group == 0 ? "stress point " : "particle ") + std::to_string(row));
    const std::size_t stress_points = model_.stress_point_count();
    const std::size_t particle_points = particles_integrate ? model_.particle_count() : 0;
    point_offset_ = {0, stress_points};
    const std::size_t total = stress_points + particle_points;
    const double shear_modulus = law_.youngs_modulus() / (2.0 * (1.0 + law_.poisson_ratio()));
    // One section per distinct thickness; each integration point refers to its own.
    section_index_.resize(total);
    auto section_for = [&](double d) {
      for (std::size_t k = 0; k < sections_.size(); ++k)
        if (sections_[k].thickness() == d) return static_cast<int>(k);
      sections_.emplace_back(law_, d);
      return static_cast<int>(sections_.size() - 1);
    };

    membrane_bending_weight_.resize(total);
    shear_weight_.resize(total);
    for (std::size_t p = 0; p < stress_points; ++p) {
      const double d = model_.stress_point_thickness(p);
      section_index_[p] = section_for(d);
      membrane_bending_weight_[p] =
          (1.0 - options_.particle_integration_share) * model_.stress_point_area[p];
      shear_weight_[p] = model_.stress_point_area[p] * options_.shear_correction * shear_modulus * d;
    }
    for (std::size_t i = 0; i < particle_points; ++i) {
      const double d = model_.particle_thickness(i);
      const double shear_stiffness = options_.shear_correction * shear_modulus * d;
      section_index_[stress_points + i] = section_for(d);
      const double local_spacing = std::sqrt(model_.particle_area[i]);
      const double softening =
          d * d / (d * d + options_.particle_shear_softening * local_spacing * local_spacing);
      membrane_bending_weight_[stress_points + i] =
          options_.particle_integration_share * model_.particle_area[i];
      shear_weight_[stress_points + i] =
          options_.particle_shear_weight * model_.particle_area[i] * shear_stiffness * softening;
    }
    reference_.resize(total);
    for (int group = 0; group < 2; ++group)
      for (std::size_t row = 0; row < point_count(group); ++row)
        reference_[point_offset_[group] + row] = gather(group, row, position_, director_);

    state_.assign(total, sections_.front().initial_state());
    membrane_strain_.assign(total, StrainVoigt::Zero());
    curvature_.assign(total, StrainVoigt::Zero());
    shear_.assign(total, Vector2::Zero());
    shear_force_.assign(total, Vector2::Zero());
    membrane_.assign(total, StressVoigt::Zero());
    moment_.assign(total, StressVoigt::Zero());
    work_increment_.assign(total, 0.0);
    active_.assign(total, 1);
    fragment_.assign(model_.particle_count(), 0);
    build_slot_transpose();
    if constexpr (Crack::enabled) initialize_cracks();
  }

  std::size_t point_count(int group) const { return shape_[group].rows(); }

  // Maps every particle to the shape-function slots that reference it, so the
  // force gather is a deterministic per-particle sum (no atomics, identical
  // results for any thread count).
  // Rows keep their capacity when cracks shrink them, so the slot arrays are
  // sized once; only the map is rebuilt.
  void build_slot_transpose() {
    slot_offset_ = {0, shape_[0].neighbour.size()};
    const std::size_t slots = shape_[0].neighbour.size() + shape_[1].neighbour.size();
    if (slot_force_.size() != slots) {
      slot_force_.assign(slots, Vector3::Zero());
      slot_director_force_.assign(slots, Vector3::Zero());
    }
    std::vector<std::size_t> count(model_.particle_count() + 1, 0);
    auto for_each_slot = [&](auto&& visit) {
      for (int group = 0; group < 2; ++group) {
        const approx::ShapeFunctions& shape = shape_[group];
        for (std::size_t row = 0; row < point_count(group); ++row)
          for (std::size_t s = shape.row_begin[row]; s < shape.row_begin[row] + shape.row_size[row]; ++s)
            visit(shape.neighbour[s], slot_offset_[group] + s);
      }
    };
    for_each_slot([&](int particle, std::size_t) { ++count[particle + 1]; });
    for (std::size_t i = 1; i < count.size(); ++i) count[i] += count[i - 1];
    particle_slot_begin_ = count;
    particle_slots_.resize(count.back());
    for_each_slot([&](int particle, std::size_t slot) { particle_slots_[count[particle]++] = slot; });
  }

  shell::SurfaceGradients gather(int group, std::size_t row, const std::vector<Vector3>& x,
                                 const std::vector<Vector3>& d) const {
    const approx::ShapeFunctions& shape = shape_[group];
    shell::SurfaceGradients g;
    const std::size_t end = shape.row_begin[row] + shape.row_size[row];
    for (std::size_t s = shape.row_begin[row]; s < end; ++s) {
      const int j = shape.neighbour[s];
      g.a1 += shape.dphi_d1[s] * x[j];
      g.a2 += shape.dphi_d2[s] * x[j];
      g.n += shape.phi[s] * d[j];
      g.n1 += shape.dphi_d1[s] * d[j];
      g.n2 += shape.dphi_d2[s] * d[j];
    }
    return g;
  }

  shell::Strains strains_of(const shell::SurfaceGradients& current, const shell::SurfaceGradients& reference) const {
    return options_.nonlinear ? shell::green_strains(current, reference)
                              : shell::linear_strains(current, reference);
  }

  // Strains → material update → resultants → forces on the slots of one point.
  void integrate_point(int group, std::size_t row) {
    const std::size_t p = point_offset_[group] + row;
    if (!active_[p]) return;
    const shell::SurfaceGradients current = gather(group, row, position_, director_);
    const shell::Strains strains = strains_of(current, reference_[p]);
    const StrainVoigt d_membrane = strains.membrane - membrane_strain_[p];
    const StrainVoigt d_curvature = strains.curvature - curvature_[p];
    const Vector2 d_shear = strains.shear - shear_[p];
    const thickness::Resultants resultants = section_of(p).update(state_[p], d_membrane, d_curvature);
    // The elastic transverse shear force (weighted: shear_weight_ holds κs G d A)
    // is updated incrementally like the other resultants, so a change of shape
    // functions (after a crack) leaves it continuous.
    const Vector2 shear_force = shear_force_[p] + shear_weight_[p] * d_shear;
    const double w = membrane_bending_weight_[p];
    // Trapezoidal work of the generalized stresses over the strain increment.
    work_increment_[p] = w * (0.5 * (membrane_[p] + resultants.membrane).dot(d_membrane) +
                              0.5 * (moment_[p] + resultants.moment).dot(d_curvature)) +
                         0.5 * (shear_force_[p] + shear_force).dot(d_shear);
    membrane_strain_[p] = strains.membrane;
    curvature_[p] = strains.curvature;
    shear_[p] = strains.shear;
    membrane_[p] = resultants.membrane;
    moment_[p] = resultants.moment;
    shear_force_[p] = shear_force;
    scatter_point(group, row, current);
  }

  // Forces of one point's stored resultants on the slots of its row (no material update).
  void scatter_point(int group, std::size_t row, const shell::SurfaceGradients& current) {
    const std::size_t p = point_offset_[group] + row;
    const double w = membrane_bending_weight_[p];
    const shell::WeightedStresses weighted{w * membrane_[p], w * moment_[p], shear_force_[p]};
    const shell::ConjugateForces f =
        shell::conjugate_forces(options_.nonlinear ? current : reference_[p], weighted);
    const approx::ShapeFunctions& shape = shape_[group];
    const std::size_t end = shape.row_begin[row] + shape.row_size[row];
    for (std::size_t s = shape.row_begin[row]; s < end; ++s) {
      const std::size_t slot = slot_offset_[group] + s;
      slot_force_[slot] = shape.dphi_d1[s] * f.a1 + shape.dphi_d2[s] * f.a2;
      slot_director_force_[slot] = shape.phi[s] * f.n + shape.dphi_d1[s] * f.n1 + shape.dphi_d2[s] * f.n2;
    }
  }

  // Deterministic per-particle sums of the slot forces.
  void gather_particle_forces() {
    const long particles = static_cast<long>(model_.particle_count());
#pragma omp parallel for schedule(static)
    for (long i = 0; i < particles; ++i) {
      Vector3 force = Vector3::Zero(), director_force = Vector3::Zero();
      for (std::size_t k = particle_slot_begin_[i]; k < particle_slot_begin_[i + 1]; ++k) {
        force += slot_force_[particle_slots_[k]];
        director_force += slot_director_force_[particle_slots_[k]];
      }
      internal_force_[i] = force;
      internal_director_force_[i] = director_force;
    }
  }

  // Elastic energy held by one integration point (membrane, bending, shear).
  double stored_energy(std::size_t p) const {
    const double shear = shear_weight_[p] > 0.0 ? 0.5 * shear_force_[p].squaredNorm() / shear_weight_[p] : 0.0;
    return membrane_bending_weight_[p] * section_of(p).elastic_energy(state_[p]) + shear;
  }

  void compute_internal_forces() {
    for (int group = 0; group < 2; ++group) {
      const long rows = static_cast<long>(point_count(group));
      // An exception must not escape an OpenMP region: keep the one of the
      // lowest point (deterministic) and rethrow it after the loop.
      long failed_row = rows;
      std::string failure;
#pragma omp parallel for schedule(static)
      for (long row = 0; row < rows; ++row) {
        try {
          integrate_point(group, static_cast<std::size_t>(row));
        } catch (const std::exception& error) {
#pragma omp critical(sphshell_failure)
          if (row < failed_row) {
            failed_row = row;
            failure = error.what();
          }
        }
      }
      // The points before the failure are already updated: the solver cannot
      // continue after this error.
      if (failed_row < rows)
        fail_unstable(std::string(group == 0 ? "stress point " : "particle ") + std::to_string(failed_row) +
                      ": " + failure);
    }
    gather_particle_forces();
    previous_internal_energy_ = internal_energy_;
    for (double work : work_increment_) internal_energy_ += work;
    std::fill(work_increment_.begin(), work_increment_.end(), 0.0);
    forces_current_ = true;
  }

  void apply_external_loads(double t) {
    std::fill(external_force_.begin(), external_force_.end(), Vector3::Zero());
    detail::LoadContext context{t, model_.particle_position, model_.particle_normal, director_,
                                model_.particle_area, external_force_};
    for (const auto& load : loads_) load->apply(context);
    for (std::size_t i = 0; i < external_force_.size(); ++i)
      if (!external_force_[i].allFinite())
        fail_unstable("non-finite external load at particle " + std::to_string(i) +
                      " (a pressure or force function returned NaN or infinity)");
  }

  // v^{n+½} = v^{n−½} + dt M⁻¹ (f_ext − f_int) with mass-proportional damping
  // taken at the mid-step velocity; then the kinematic conditions.
  void advance_velocities(double dt) {
    const std::size_t n = position_.size();
    const double c = options_.damping;
    const double keep = (1.0 - 0.5 * c * dt) / (1.0 + 0.5 * c * dt);
    const double gain = dt / (1.0 + 0.5 * c * dt);
    old_velocity_ = velocity_;
    old_angular_velocity_ = angular_velocity_;
    for (std::size_t i = 0; i < n; ++i) {
      const Vector3 force = external_force_[i] - internal_force_[i];
      velocity_[i] = keep * velocity_[i] + gain * force / mass_[i];
      // δΠ = g·δd with δd = δθ × d gives ∂Π/∂θ = d × g, so the moment is −d × g.
      const Vector3 moment = -director_[i].cross(internal_director_force_[i]);
      const Vector3 omega = keep * angular_velocity_[i] + gain * moment / rotary_inertia_[i];
      angular_velocity_[i] = omega - omega.dot(director_[i]) * director_[i];  // no drilling
    }
    // Velocity the unconstrained update produced, for the reaction work below.
    std::vector<Vector3>& free_velocity = scratch_;
    free_velocity = velocity_;
    for (std::size_t k = 0; k < constraints_.particles().size(); ++k) {
      const int i = constraints_.particles()[k];
      const detail::ParticleConstraint& constraint = constraints_.at(k);
      // The position update always spans time_step_ (also on the half-step
      // start-up of the velocities), so the imposed velocity does too.
      Vector3 prescribed = Vector3::Zero();
      for (const detail::PrescribedMotion* motion : constraint.motions)
        prescribed += motion->velocity(i, model_.particle_position[i], time_, time_step_);
      if (!prescribed.allFinite())
        fail_unstable("prescribed motion of particle " + std::to_string(i) + " is not finite");
      velocity_[i] = constraint.free_translation * velocity_[i] +
                     (Matrix3::Identity() - constraint.free_translation) * prescribed;
      // Project onto the free rotations and the plane normal to the director at
      // once: projecting one after the other would let the drilling removal
      // reintroduce a fixed component when the director is tilted.
      Matrix3 free = constraint.free_rotation;
      const Vector3 drilling = free * director_[i];
      if (drilling.squaredNorm() > 1e-24) free -= drilling * drilling.transpose() / drilling.squaredNorm();
      angular_velocity_[i] = free * angular_velocity_[i];
    }
    // Energy: the work of each force over the step is f · dt · (v^{n−½} + v^{n+½})/2.
    double external = 0.0, damping = 0.0, kinetic = 0.0;
    for (std::size_t i = 0; i < n; ++i) {
      const Vector3 average = 0.5 * (old_velocity_[i] + velocity_[i]);
      const Vector3 reaction = mass_[i] * (velocity_[i] - free_velocity[i]) / dt;
      external += dt * (external_force_[i] + reaction).dot(average);
      damping += dt * c * mass_[i] * average.squaredNorm() +
                 dt * c * rotary_inertia_[i] *
                     (0.5 * (old_angular_velocity_[i] + angular_velocity_[i])).squaredNorm();
      kinetic += 0.5 * mass_[i] * velocity_[i].squaredNorm() +
                 0.5 * rotary_inertia_[i] * angular_velocity_[i].squaredNorm();
    }
    external_work_ += external;
    damping_work_ += damping;
    kinetic_energy_ = kinetic;
  }

  // x^{n+1} = x^n + dt v^{n+½}; directors rotate by dt ω^{n+½} (Rodrigues).
  void advance_configuration() {
    const double dt = time_step_;
    const std::size_t n = position_.size();
    for (std::size_t i = 0; i < n; ++i) {
      position_[i] += dt * velocity_[i];
      const Vector3 rotation = dt * angular_velocity_[i];
      const double angle = rotation.norm();
      if (angle > 0.0) {
        const Vector3 axis = rotation / angle;
        const Vector3& d = director_[i];
        director_[i] = (d * std::cos(angle) + axis.cross(d) * std::sin(angle) +
                        axis * axis.dot(d) * (1.0 - std::cos(angle)))
                           .normalized();
      }
    }
  }

  // Stable step of the central difference scheme, dt ≤ 2/ω_max, with ω_max
  // bounded from the wave speeds over the smallest particle distance Δ:
  //   membrane  ω_m² = 9 c_m² / Δ²,   c_m² = E / (ρ (1 − ν²)),
  //   rotation  ω_r² = (12 κs G / (ρ d²) + 9 c_m² / Δ²) / s_I + 9 c_s² / Δ²,   c_s² = κs G / ρ,
  // where the rotational line is the director's oscillator (transverse shear
  // stiffness κs G d and bending stiffness E d³/(12(1−ν²)) over Δ², against the
  // rotary inertia ρ d³/12 scaled by s_I) plus the shear wave it couples to.
  // ω_max² = ω_m² + ω_r²: on curved shells the membrane and rotation modes
  // couple, and a run at 0.8 × the larger of the two alone went unstable on a
  // thin tube with the two equal. The factor 9 covers the highest mode of a
  // square grid with this approximation (8.0 measured for the membrane); the
  // tests check the bound against the exact spectrum of the assembled system.
  // With a varying thickness a particle's inertia follows its own thickness d_i
  // while its stiffness comes from the integration points that reach it, the
  // thickest of them D_i: with r = D_i / d_i the membrane and shear-wave terms
  // scale by r, the transverse-shear term by r and the bending term by r³,
  // particle by particle.
  double compute_stable_time_step() const {
    const double E = law_.youngs_modulus(), nu = law_.poisson_ratio();
    const double rho = options_.density;
    const double G = E / (2.0 * (1.0 + nu));
    const double spacing = std::min(model_.minimum_spacing(), nearest_particle_distance());
    const double membrane_speed_squared = E / (rho * (1.0 - nu * nu));
    const double shear_speed_squared = options_.shear_correction * G / rho;
    const double membrane = 9.0 * membrane_speed_squared / (spacing * spacing);
    const double shear_wave = 9.0 * shear_speed_squared / (spacing * spacing);
    const std::vector<double> stiffest = thickest_integration_point_reaching_each_particle();
    double omega_squared = 0.0;
    for (std::size_t i = 0; i < model_.particle_count(); ++i) {
      const double d = model_.particle_thickness(i);
      const double r = std::max(stiffest[i], d) / d;
      const double rotation =
          (12.0 * shear_speed_squared / (d * d) * r + membrane * r * r * r) / options_.rotary_inertia_scale +
          shear_wave * r;
      omega_squared = std::max(omega_squared, membrane * r + rotation);
    }
    return 2.0 / std::sqrt(omega_squared);
  }

  std::vector<double> thickest_integration_point_reaching_each_particle() const {
    std::vector<double> thickest(model_.particle_count(), 0.0);
    for (int group = 0; group < 2; ++group)
      for (std::size_t row = 0; row < point_count(group); ++row) {
        const double d = section_of(point_offset_[group] + row).thickness();
        const approx::ShapeFunctions& shape = shape_[group];
        const std::size_t end = shape.row_begin[row] + shape.row_size[row];
        for (std::size_t s = shape.row_begin[row]; s < end; ++s) {
          const auto j = static_cast<std::size_t>(shape.neighbour[s]);
          thickest[j] = std::max(thickest[j], d);
        }
      }
    return thickest;
  }

  void write_scheduled_output() {
    const double tolerance = 1e-9 * time_step_;
    if (!options_.output_directory.empty() && options_.output_interval > 0.0) {
      if (time_ >= next_frame_time_ - tolerance) {
        write_frame();
        next_frame_time_ += options_.output_interval * std::max(1.0, std::floor((time_ - next_frame_time_) / options_.output_interval + 1.0));
      }
    }
    if (!probes_.empty() && time_ >= next_probe_time_ - tolerance) {
      for (Probe& probe : probes_) write_probe(probe);
      next_probe_time_ = time_ + options_.probe_interval;
    }
  }

  struct Probe {
    io::CsvProbe file;
    int index;
    bool stress_point;
  };

  void write_probe(Probe& probe) {
    std::vector<double> row{time_};
    if (!probe.stress_point) {
      const Vector3 u = displacement(probe.index), v = velocity_[probe.index], r = rotation(probe.index);
      row.insert(row.end(), {u.x(), u.y(), u.z(), v.x(), v.y(), v.z(), r.x(), r.y(), r.z()});
    } else {
      for (int k = 0; k < output_points; ++k) row.push_back(equivalent_stress(probe.index, k));
      for (int k = 0; k < output_points; ++k) row.push_back(equivalent_plastic_strain(probe.index, k));
      for (int k = 0; k < output_points; ++k) row.push_back(damage(probe.index, k));
    }
    probe.file.write_row(row);
  }

  static io::PointField vector_field(const std::string& name, const std::vector<Vector3>& values) {
    io::PointField field{name, 3, {}};
    field.values.reserve(3 * values.size());
    for (const Vector3& v : values) field.values.insert(field.values.end(), {v.x(), v.y(), v.z()});
    return field;
  }

  std::vector<io::PointField> particle_fields() const {
    const std::size_t n = position_.size();
    std::vector<Vector3> displacement_values(n), rotation_values(n);
    for (std::size_t i = 0; i < n; ++i) {
      displacement_values[i] = displacement(static_cast<int>(i));
      rotation_values[i] = rotation(static_cast<int>(i));
    }
    std::vector<io::PointField> fields{vector_field("displacement", displacement_values),
                                       vector_field("velocity", velocity_),
                                       vector_field("rotation", rotation_values),
                                       vector_field("director", director_)};
    if constexpr (Crack::enabled) {
      io::PointField fragment{"fragment", 1, {}};
      for (unsigned char flag : fragment_) fragment.values.push_back(flag);
      fields.push_back(fragment);
    }
    return fields;
  }

  // The crack segments as a ParaView line set, in the current configuration:
  // a damaged stress point's crack point follows the interpolated motion of the
  // stress point, a pre-crack point the displacement of its nearest particle.
  void write_crack_frame(const std::string& suffix) {
    if (!crack_collection_)
      crack_collection_ = std::make_unique<io::PvdCollection>(options_.output_directory + "/cracks.pvd");
    const std::vector<Vector3>& reference = crack_.points();
    std::vector<Vector3> points(reference.size());
    std::vector<char> placed(reference.size(), 0);
    const std::vector<Vector3> stress_positions = stress_point_positions();
    for (std::size_t p = 0; p < model_.stress_point_count(); ++p) {
      const int k = crack_.crack_point_of_stress_point(static_cast<int>(p));
      if (k >= 0) {
        points[k] = stress_positions[p];
        placed[k] = 1;
      }
    }
    for (std::size_t k = 0; k < points.size(); ++k)
      if (!placed[k]) points[k] = reference[k] + displacement(model_.nearest_particle(reference[k]));
    std::vector<std::array<int, 2>> lines;
    io::CellField crack_id{"crack_id", 1, {}};
    for (const auto& segment : crack_.segments()) {
      lines.push_back({segment.start_point, segment.end_point});
      crack_id.values.push_back(segment.crack_id);
    }
    const std::string file = options_.output_directory + "/cracks_" + suffix + ".vtu";
    io::write_vtu_lines(file, points, lines, {}, {crack_id});
    crack_collection_->add(time_, file);
  }

  // Per stress point: one array per quantity with a component per thickness
  // output point (named ip1, ip2, … in ζ order).
  std::vector<io::PointField> stress_point_fields() const {
    const std::size_t m = model_.stress_point_count();
    std::vector<std::string> names;
    for (int k = 1; k <= output_points; ++k) names.push_back("ip" + std::to_string(k));
    io::PointField stress{"equivalent_stress", output_points, {}, names};
    io::PointField plastic{"equivalent_plastic_strain", output_points, {}, names};
    io::PointField damage_field{"damage", output_points, {}, names};
    io::PointField membrane{"membrane_force", 3, {}, {"Nxx", "Nyy", "Nxy"}};
    io::PointField moment{"bending_moment", 3, {}, {"Mxx", "Myy", "Mxy"}};
    for (std::size_t s = 0; s < m; ++s) {
      const int sp = static_cast<int>(s);
      for (int k = 0; k < output_points; ++k) {
        stress.values.push_back(equivalent_stress(sp, k));
        plastic.values.push_back(equivalent_plastic_strain(sp, k));
        damage_field.values.push_back(damage(sp, k));
      }
      for (int c = 0; c < 3; ++c) {
        membrane.values.push_back(membrane_[s][c]);
        moment.values.push_back(moment_[s][c]);
      }
    }
    std::vector<io::PointField> fields{stress, plastic};
    if constexpr (Material::has_damage) fields.push_back(damage_field);
    if constexpr (Crack::enabled) {
      io::PointField removed{"removed", 1, {}};
      for (std::size_t s = 0; s < m; ++s) removed.values.push_back(active_[s] ? 0.0 : 1.0);
      fields.push_back(removed);
    }
    fields.push_back(membrane);
    fields.push_back(moment);
    return fields;
  }

  const std::vector<Vector3>& evaluation_positions(int group) const {
    return group == 0 ? model_.stress_point_position : model_.particle_position;
  }

  void initialize_cracks() {
    const double support_radius = smoothing_length_ * Approx::kernel_type::support_radius_factor;
    crack_.initialize(model_.stress_point_position, model_.stress_point_normal, model_.maximum_spacing(),
                      support_radius);
    // The particles around each stress point: the corners of its cell, or, for
    // a model without cells, the particles within one spacing; and the inverse.
    particles_of_stress_point_.assign(model_.stress_point_count(), {});
    if (!model_.quads().empty()) {
      for (std::size_t q = 0; q < model_.quads().size(); ++q)
        particles_of_stress_point_[q].assign(model_.quads()[q].begin(), model_.quads()[q].end());
    } else {
      const double reach = model_.maximum_spacing();
      const approx::CellList cells(model_.particle_position, reach);
      for (std::size_t q = 0; q < model_.stress_point_count(); ++q)
        cells.for_each_within(model_.stress_point_position[q], reach, [&](int i, double) {
          particles_of_stress_point_[q].push_back(i);
        });
    }
    stress_points_of_particle_.assign(model_.particle_count(), {});
    for (std::size_t q = 0; q < particles_of_stress_point_.size(); ++q)
      for (int i : particles_of_stress_point_[q]) stress_points_of_particle_[i].push_back(static_cast<int>(q));
  }

  // Zeroes the forces a point left on the slots of its row.
  void clear_slots(int group, std::size_t row) {
    const approx::ShapeFunctions& shape = shape_[group];
    for (std::size_t s = shape.row_begin[row]; s < shape.row_begin[row + 1]; ++s) {
      slot_force_[slot_offset_[group] + s].setZero();
      slot_director_force_[slot_offset_[group] + s].setZero();
    }
  }

  // Removes an integration point from the force integration, keeping its
  // stored elastic energy in the books as released.
  void deactivate(std::size_t p) {
    released_energy_ += stored_energy(p);
    active_[p] = 0;
    const int group = p < point_offset_[1] ? 0 : 1;
    clear_slots(group, p - point_offset_[group]);
  }

  // Per step: stress points whose integral points have all failed leave the
  // integration and join the crack topology; their neighbourhoods get new,
  // visibility-filtered shape functions; particles with every stress point
  // damaged become fragments (design.md §2.6).
  void update_cracks() {
    std::vector<int> newly_damaged;
    bool removed_particle_point = false;
    for (std::size_t p = 0; p < model_.stress_point_count(); ++p)
      if (active_[p] && section_of(p).all_failed(state_[p])) newly_damaged.push_back(static_cast<int>(p));
    for (std::size_t i = 0; i < point_count(1); ++i) {
      const std::size_t p = point_offset_[1] + i;
      if (active_[p] && section_of(p).all_failed(state_[p])) {
        deactivate(p);
        removed_particle_point = true;
      }
    }
    if (newly_damaged.empty()) {
      if (removed_particle_point) gather_particle_forces();
      return;
    }
    for (int p : newly_damaged) deactivate(static_cast<std::size_t>(p));
    damaged_stress_points_ += newly_damaged.size();
    const auto segments = crack_.add_damaged_stress_points(newly_damaged);
    std::vector<int> new_fragments;
    for (int p : newly_damaged)
      for (int corner : particles_of_stress_point_[p])
        if (!fragment_[corner] && all_damaged_around(corner)) {
          fragment_[corner] = 1;
          new_fragments.push_back(corner);
          if (point_count(1) > 0 && active_[point_offset_[1] + corner]) deactivate(point_offset_[1] + corner);
        }
    rebuild_near_segments(segments, new_fragments);
  }

  // A particle on a crack line would see both faces and tie them together.
  void reject_particles_on(const std::vector<Vector3>& polyline) const {
    const double tolerance = Crack::on_precrack_in_spacings * crack_.spacing();
    for (std::size_t k = 0; k + 1 < polyline.size(); ++k)
      for (std::size_t i = 0; i < model_.particle_count(); ++i)
        if (Crack::distance_to_precrack_piece(model_.particle_position[i], polyline[k], polyline[k + 1]) <=
            tolerance) {
          std::ostringstream message;
          message << "sphshell: the pre-crack passes through particle " << i << " at ("
                  << model_.particle_position[i].transpose()
                  << "); a particle on a crack would tie its faces together: move the pre-crack off the particles "
                     "(along a row of stress points, or a fraction of the spacing aside)";
          throw Error(message.str());
        }
  }

  bool all_damaged_around(int particle) const {
    const std::vector<int>& around = stress_points_of_particle_[particle];
    return !around.empty() &&
           std::all_of(around.begin(), around.end(), [&](int q) { return !active_[q]; });
  }

  // Rebuilds the shape functions of every evaluation point within the support
  // of a new crack segment or of a new fragment, hiding the pairs the cracks
  // cut and the fragments. The strain bookkeeping restarts from the new
  // approximation so the change of functions itself creates no strain.
  template <class Segments>
  void rebuild_near_segments(const Segments& segments, const std::vector<int>& new_fragments = {}) {
    const double support_radius = smoothing_length_ * Approx::kernel_type::support_radius_factor;
    for (int group = 0; group < 2; ++group) {
      if (point_count(group) == 0) continue;
      const std::vector<Vector3>& eval = evaluation_positions(group);
      std::vector<std::size_t> rows = crack_.affected_points(eval, segments);
      for (int particle : new_fragments)
        for (std::size_t row = 0; row < eval.size(); ++row)
          if ((eval[row] - model_.particle_position[particle]).norm() < support_radius) rows.push_back(row);
      std::sort(rows.begin(), rows.end());
      rows.erase(std::unique(rows.begin(), rows.end()), rows.end());
      for (std::size_t row : rows) {
        const std::size_t p = point_offset_[group] + row;
        if (!active_[p]) continue;
        const Vector3& x = eval[row];
        const TangentFrame& frame = frames_[group][row];
        auto visible = [&](std::size_t, std::size_t j) {
          return !fragment_[j] && crack_.visible(x, model_.particle_position[j], frame);
        };
        try {
          Approx::rebuild_row(shape_[group], row, model_.particle_position, model_.particle_area, x,
                              frame, smoothing_length_, visible);
        } catch (const Error&) {
          deactivate(p);  // nothing visible is left: the point is cut loose
          continue;
        }
        if (shape_[group].shepard[row]) {
          deactivate(p);  // no gradient left: the point can carry no strain
          continue;
        }
        reference_[p] = gather(group, row, model_.particle_position, model_.particle_normal);
        const shell::SurfaceGradients current = gather(group, row, position_, director_);
        const shell::Strains strains = strains_of(current, reference_[p]);
        membrane_strain_[p] = strains.membrane;
        curvature_[p] = strains.curvature;
        shear_[p] = strains.shear;
        clear_slots(group, row);
        scatter_point(group, row, current);
      }
    }
    build_slot_transpose();
    gather_particle_forces();
  }

  // Smallest distance between two particles: on distorted grids (the corners
  // of a spherical cap) it is shorter than the square root of the cell area.
  double nearest_particle_distance() const {
    const double reach = 2.0 * model_.maximum_spacing();
    const approx::CellList cells(model_.particle_position, reach);
    double nearest = reach;
    for (std::size_t i = 0; i < model_.particle_count(); ++i)
      cells.for_each_within(model_.particle_position[i], reach, [&](int j, double distance_squared) {
        if (static_cast<std::size_t>(j) != i) nearest = std::min(nearest, std::sqrt(distance_squared));
      });
    return nearest;
  }

  void check_configuration() const {
    const std::size_t n = position_.size();
    for (std::size_t i = 0; i < n; ++i)
      if (!position_[i].allFinite() || !director_[i].allFinite() || !velocity_[i].allFinite() ||
          !angular_velocity_[i].allFinite())
        fail_unstable("non-finite state at particle " + std::to_string(i) + " (external force " +
                      to_string(external_force_[i].norm()) + " N, internal force " +
                      to_string(internal_force_[i].norm()) + " N)");
  }

  void check_energy_balance() const {
    if (steps_ % 16 != 0) return;  // the energy sums cost a pass over all states
    const EnergyReport e = energy();
    const double scale = std::max({std::abs(e.external_work), e.kinetic, std::abs(e.internal)});
    // Below the energy of a 1e-10 strain in the whole shell, the sums are
    // round-off (e.g. before a travelling load arrives) and carry no balance.
    double volume = 0.0;
    for (std::size_t i = 0; i < model_.particle_count(); ++i)
      volume += model_.particle_thickness(i) * model_.particle_area[i];
    const double round_off_energy = law_.youngs_modulus() * volume * 1e-20;
    if (steps_ > 20 && scale > round_off_energy && std::abs(e.balance()) > options_.energy_tolerance * scale) {
      std::ostringstream message;
      message << "energy balance lost (kinetic " << e.kinetic << " J, internal " << e.internal
              << " J, external work " << e.external_work << " J, balance " << e.balance()
              << " J); reduce the time step or check the loads";
      fail_unstable(message.str());
    }
  }

  [[noreturn]] void fail_unstable(const std::string& what) const {
    std::ostringstream message;
    message.precision(6);
    message << "sphshell: simulation unstable at step " << steps_ << ", t = " << time_ << " s: " << what;
    throw Error(message.str());
  }

  void print_progress() const {
    const EnergyReport e = energy();
    std::ostringstream line;
    line.precision(4);
    line << "step " << steps_ << "  t = " << time_ << " s  kinetic " << e.kinetic << " J  internal "
         << e.internal << " J  external " << e.external_work << " J  balance " << e.balance() << " J\n";
    std::cout << line.str() << std::flush;
  }

  ShellModel model_;
  Material law_;
  std::vector<Section> sections_;
  std::vector<int> section_index_;  // per integration point, into sections_
  const Section& section_of(std::size_t p) const { return sections_[static_cast<std::size_t>(section_index_[p])]; }
  SolverOptions options_;
  double smoothing_length_ = 0.0;
  double stable_time_step_ = 0.0;
  double time_step_ = 0.0;
  double time_ = 0.0;
  long steps_ = 0;
  bool forces_current_ = false;

  std::vector<Vector3> position_, director_, velocity_, angular_velocity_;
  std::vector<Vector3> old_velocity_, old_angular_velocity_, scratch_;
  std::vector<double> mass_, rotary_inertia_;
  std::vector<Vector3> internal_force_, internal_director_force_, external_force_;

  std::array<approx::ShapeFunctions, 2> shape_;
  std::array<std::vector<TangentFrame>, 2> frames_;  // evaluation frames, kept for rebuilds
  std::array<std::size_t, 2> point_offset_{};
  std::array<std::size_t, 2> slot_offset_{};
  // Integration weights: area share for membrane and bending; area × κs G d
  // (softened at particles) for transverse shear.
  std::vector<double> membrane_bending_weight_, shear_weight_;
  std::vector<shell::SurfaceGradients> reference_;
  std::vector<SectionState> state_;
  std::vector<StrainVoigt> membrane_strain_, curvature_;
  std::vector<Vector2> shear_, shear_force_;
  std::vector<StressVoigt> membrane_, moment_;
  std::vector<double> work_increment_;
  std::vector<unsigned char> active_;    // per integration point: still integrates forces
  std::vector<unsigned char> fragment_;  // per particle: every stress point around it damaged
  Crack crack_;
  std::vector<std::vector<int>> particles_of_stress_point_, stress_points_of_particle_;
  std::size_t damaged_stress_points_ = 0;
  std::size_t precrack_stress_points_ = 0;
  double released_energy_ = 0.0;
  std::vector<Vector3> slot_force_, slot_director_force_;
  std::vector<std::size_t> particle_slot_begin_, particle_slots_;

  std::vector<Probe> probes_;
  std::unique_ptr<io::PvdCollection> particle_collection_, stress_point_collection_, crack_collection_;
  long frames_written_ = 0;
  double next_frame_time_ = 0.0;
  double next_probe_time_ = 0.0;

  detail::Constraints constraints_;
  std::vector<std::unique_ptr<detail::Load>> loads_;
  double previous_internal_energy_ = 0.0, internal_energy_ = 0.0, external_work_ = 0.0, damping_work_ = 0.0, kinetic_energy_ = 0.0;
};

}  // namespace sphshell
