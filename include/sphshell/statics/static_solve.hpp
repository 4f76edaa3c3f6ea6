#pragma once
// Solver::solve_static (the glue is solver/static_solution.hpp).
// Static solutions: the equilibrium f_int(x, d) = λ f_ext of the solver's
// model under its loads scaled by load factors λ₁ < λ₂ < … (docs/method.md,
// "Static solutions"). Two methods share the load stepping, the residual and
// its criterion:
//
//  - StaticMass::tangent: dynamic relaxation whose fictitious
//    mass is the tangent stiffness itself, i.e. Newton's method with a
//    backtracking line search. The tangent is the static family's one
//    difference Jacobian (statics/coupling.hpp): central differences of the
//    solver's own forces, two evaluations per colour of a distance-2
//    colouring of the particles' coupling graph and per degree of freedom
//    (three translations, two rotations normal to the director).
//    Known limit: on the cantilever strip (free edges) its Newton steps stall
//    even under small load steps; the clamped plates converge in 1–2 steps.
//    With StaticParameters::krylov_iterations the steps are solved by GMRES on
//    the current tangent (its products by difference_product of
//    statics/coupling.hpp, as in the path following), preconditioned by a
//    kept factorisation of an earlier one.
//  - StaticMass::particle_bound (the default): adaptive dynamic relaxation (Underwood 1983)
//    with a diagonal fictitious mass per degree of freedom from the
//    Gershgorin bound of the tangent's rows, m_a = (h²/4) Σ_b |K_ab| with the
//    pseudo step h = 1, and kinetic damping (velocities zeroed at each peak of
//    the kinetic energy) or Underwood's viscous damping c = 2 √(Δqᵀ K Δq /
//    Δqᵀ M Δq) from the current response.
//
// The residual r = λ f_ext − f_int is taken on the free degrees of freedom
// (the kinematic conditions remove the fixed ones); moments count as forces
// at the lever arm of the largest particle spacing ℓ. A load step has
// converged when ‖r‖ ≤ tolerance ‖λ f_ext‖.
//
// Every force evaluation of a load step starts from the material state of
// the last converged step. For path-dependent laws (J2 plasticity, damage) a
// load step is thus one increment of the law (backward Euler over the step)
// and the answer depends on the load stepping as a plastic path does; for
// all laws (the elastic one too updates its stress by increments) the forces
// of a configuration do not depend on the evaluations before it, so the
// order in which a share perturbs its particles leaves no trace.
//
// Numbering, the same in StaticIteration, StaticResult, the progress lines
// and every Error: load steps count from 1 (load step k has λ =
// load_factors[k − 1]); iteration k of a load step is the state after k
// iterations (Newton iterations or relaxation steps) of it, 0 its start.
//
// A load step that exhausts its budget stops with StaticNotConverged (an
// Error): the solver is left at the state of the lowest residual that load
// step reached, which the exception's result() describes.

#include <sphshell/core/error.hpp>
#include <sphshell/core/frame.hpp>
#include <sphshell/core/types.hpp>
#include <sphshell/shell/constraints.hpp>
#include <sphshell/shell/model.hpp>
#include <sphshell/solver/integration_points.hpp>
#include <sphshell/solver/particles.hpp>
#include <sphshell/solver/run_checks.hpp>
#include <sphshell/statics/coupling.hpp>
#include <sphshell/statics/krylov.hpp>
#include <sphshell/statics/sparse_factorisation.hpp>
#include <sphshell/statics/static_share.hpp>

#include <Eigen/Eigenvalues>
#include <Eigen/Sparse>
#include <Eigen/SparseCholesky>
#include <Eigen/SparseLU>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstddef>
#include <iostream>
#include <limits>
#include <memory>
#include <optional>
#include <ostream>
#include <sstream>
#include <string>
#include <vector>

namespace sphshell::statics {

// The fictitious mass of the relaxation.
enum class StaticMass {
  particle_bound,  // diagonal, from the Gershgorin bound of each degree of freedom's stiffness row
  tangent          // the assembled tangent stiffness: Newton steps with a line search (see the
                   // header comment: converges on the clamped plates, not yet on cantilevers)
};

// The damping of StaticMass::particle_bound (the tangent needs none).
enum class StaticDamping {
  viscous,  // Underwood's c = 2 ω₀, ω₀² the Rayleigh quotient of the current displacement increment
  kinetic   // undamped, velocities zeroed at each peak of the kinetic energy
};

struct StaticParameters {
  // λ of each load step, strictly increasing from above 0; the loads are the
  // solver's (add_pressure, add_point_force, ...) evaluated at load_time and
  // scaled by λ. The last step's equilibrium is the solver's state after the solve.
  std::vector<double> load_factors{1.0};
  // A load step has converged when ‖r‖ ≤ tolerance ‖λ f_ext‖; in (0, 1).
  double tolerance = 1e-6;
  StaticMass mass = StaticMass::particle_bound;
  StaticDamping damping = StaticDamping::viscous;
  // Budgets per load step: Newton iterations (StaticMass::tangent) and
  // relaxation steps (StaticMass::particle_bound). An exhausted budget is a
  // StaticNotConverged Error that leaves the solver at the step's best state.
  long max_newton_iterations = 40;
  // Newton's steps by GMRES (statics/krylov.hpp, as NewtonOptions::krylov_iterations
  // of the path following): K δ = r solved to ‖r − K δ‖ ≤ krylov_tolerance ‖r‖
  // with the current tangent K applied by central differences of the forces
  // (two evaluations a product) and the kept factorisation of an earlier
  // tangent, of this or an earlier load step, as the preconditioner; a solve
  // that needs more than krylov_iterations products assembles and factorises
  // a fresh tangent and solves with it. 0: off (a tangent assembled and
  // factorised at every Newton iteration).
  int krylov_iterations = 0;
  double krylov_tolerance = 1e-2;  // in (0, 1)
  // Unset: automatic_relaxation_steps(model, tolerance), which grows with the
  // model's stiffness spread (see there); a value given is used as it is.
  std::optional<long> max_relaxation_steps;
  // The time (s) at which the loads' time functions are evaluated; NaN: the
  // solver's current time (a Step load from t = 0 is on at t = 0; a Ramp is
  // not: give a load_time after its rise).
  double load_time = std::numeric_limits<double>::quiet_NaN();
  // Relative step of the finite-difference tangent: translations by this
  // times the largest spacing, rotations by this in radians.
  double perturbation = 1e-7;
  // Print a progress line every this many iterations (0: quiet) to
  // MonitoringOptions::progress_stream (std::clog when null).
  long progress_interval = 0;
};

// What the observer sees after every iteration (numbering: see the header comment).
struct StaticIteration {
  int load_step = 0;       // 1-based: load step k has λ = load_factors[k − 1]
  int load_steps = 0;      // how many there are
  double load_factor = 0.0;
  long iteration = 0;      // within the load step: the state after this many iterations (0: the step's start)
  double residual = 0.0;   // ‖r‖ / ‖λ f_ext‖
};

// The state the solve left the solver in: the last load step's equilibrium,
// or (in StaticNotConverged::result()) the best state of the load step that
// exhausted its budget.
struct StaticResult {
  long iterations = 0;         // over all load steps (Newton iterations or relaxation steps)
  long force_evaluations = 0;  // internal-force evaluations, the cost
  long factorisations = 0;     // tangents assembled and factorised (StaticMass::tangent)
  long krylov_iterations = 0;  // tangent products of the GMRES steps (StaticParameters::krylov_iterations)
  FactorisationMethod factorisation = FactorisationMethod::none;  // of the last factorised tangent
  double residual = 0.0;       // ‖r‖ / ‖λ f_ext‖ of the state held
  double load_factor = 0.0;    // λ of the load step of the state held
  int load_step = 0;           // 1-based number of that load step
  long iteration = 0;          // the iteration of that load step whose state is held (0: the step's start)
  bool converged = false;      // whether that state meets the tolerance
};

// A load step exhausted its budget. The message names the method, the budget,
// the load step (number and λ), the lowest residual reached and its iteration;
// the solver is left at that lowest-residual state (particles and directors,
// the material state and internal forces of it, at rest, energy books
// restarted there), and result() describes it.
class StaticNotConverged : public Error {
 public:
  StaticNotConverged(const std::string& message, const StaticResult& kept) : Error(message), kept_(kept) {}
  const StaticResult& result() const { return kept_; }

 private:
  StaticResult kept_;
};

// Checked before anything moves: an Error naming the parameter.
inline void validate(const StaticParameters& p) {
  if (p.load_factors.empty())
    sphshell::detail::invalid_parameter("StaticParameters::load_factors size", 0, "must list at least one load factor");
  double previous = 0.0;
  for (std::size_t k = 0; k < p.load_factors.size(); ++k) {
    const double lambda = p.load_factors[k];
    if (!std::isfinite(lambda) || !(lambda > previous))
      sphshell::detail::invalid_parameter("StaticParameters::load_factors[" + std::to_string(k) + "]", lambda,
                                "the load increment from the previous factor " + solver::number_text(previous) +
                                    " must be positive: load factors increase strictly from above 0");
    previous = lambda;
  }
  sphshell::detail::require_open_interval("StaticParameters::tolerance", p.tolerance, 0.0, 1.0);
  if (p.max_newton_iterations < 1)
    sphshell::detail::invalid_parameter("StaticParameters::max_newton_iterations", p.max_newton_iterations, "must be >= 1");
  if (p.max_relaxation_steps && *p.max_relaxation_steps < 1)
    sphshell::detail::invalid_parameter("StaticParameters::max_relaxation_steps", *p.max_relaxation_steps,
                              "must be >= 1 (or unset for the automatic budget)");
  if (p.krylov_iterations < 0)
    sphshell::detail::invalid_parameter("StaticParameters::krylov_iterations", p.krylov_iterations,
                                        "must be >= 0 (0: no GMRES)");
  sphshell::detail::require_open_interval("StaticParameters::krylov_tolerance", p.krylov_tolerance, 0.0, 1.0);
  sphshell::detail::require_open_interval("StaticParameters::perturbation", p.perturbation, 0.0, 1e-2);
  if (p.progress_interval < 0)
    sphshell::detail::invalid_parameter("StaticParameters::progress_interval", p.progress_interval, "must be >= 0");
  if (!std::isnan(p.load_time)) sphshell::detail::require_finite("StaticParameters::load_time", p.load_time);
}

// What the solve works on, handed by the Solver: its domain part (the
// process's share: owned particles, then ghosts; statics/static_share.hpp),
// the model, the share's particles and forces, the kinematic conditions, the
// integration points (whose rows give the coupling), and three actions:
// evaluate(λ) sets the external loads × λ and recomputes the internal forces
// of the current configuration, ghosts as they are (no exchange);
// save_material() / restore_material() keep and bring back the material
// state of the last converged load step (no-ops for a path-independent law).
template <class Domain, class Approx, class Evaluate, class SaveMaterial, class RestoreMaterial>
struct StaticSystem {
  Domain& domain;
  const ShellModel& model;
  solver::ParticleState& particles;
  const solver::ParticleForces& forces;
  const sphshell::detail::Constraints& constraints;
  const solver::IntegrationPoints<Approx>& points;
  Evaluate evaluate;
  SaveMaterial save_material;
  RestoreMaterial restore_material;
  std::ostream* progress_stream;
};

namespace detail {

// Degrees of freedom per particle: up to three translations, two rotations.
inline constexpr int max_translations = 3;
inline constexpr int max_rotations = 2;
inline constexpr int max_dofs = max_translations + max_rotations;
// An eigenvalue of a free-subspace projector above this marks a free direction (they are 0 or 1).
inline constexpr double free_eigenvalue = 0.5;
// A combination of rigid motions whose constrained part has a squared norm
// below this (per unit motion) is free: the model has a rigid-body mode.
inline constexpr double rigid_mode_tolerance = 1e-10;
// Line search: halve the Newton step at most this many times.
inline constexpr int max_step_halvings = 12;
// m_a = gershgorin_mass_factor × h² Σ_b |K_ab| (see the relaxation below).
inline constexpr double gershgorin_mass_factor = 0.5;
// Underwood's damping c = 2 ω₀ with the pseudo step h = 1 is stable for c h < 2.
inline constexpr double largest_damping = 2.0;

// The free directions of each particle: translation basis T (3 × nt) and
// rotation basis R (3 × nr, normal to the director).
struct Basis {
  std::vector<std::array<Vector3, max_translations>> translation;
  std::vector<std::array<Vector3, max_rotations>> rotation;
  std::vector<int> translations, rotations, offset;  // per particle; offset into the reduced vector
  int size = 0;
};

// The functions below that use Eigen's eigen solvers or sparse factorisations
// are templates so that they are compiled only in programs that call a static
// solve (as ordinary inline functions they added about 15 s to the compile
// time of every program that includes the library).
template <class Projector>
int free_directions(const Projector& projector, Vector3* out, int at_most) {
  Eigen::SelfAdjointEigenSolver<Matrix3> eigen(0.5 * (projector + projector.transpose()));
  int count = 0;
  for (int k = 2; k >= 0 && count < at_most; --k)
    if (eigen.eigenvalues()[k] > free_eigenvalue) out[count++] = eigen.eigenvectors().col(k).normalized();
  return count;
}

// The rotation projector of a constrained particle with the drilling part
// removed, as Constraints::impose applies it.
inline Matrix3 free_rotation_normal_to(const Matrix3& free_rotation, const Vector3& director) {
  Matrix3 free = free_rotation;
  const Vector3 drilling = free * director;
  if (drilling.squaredNorm() > sphshell::detail::Constraints::negligible_drilling_squared)
    free -= drilling * drilling.transpose() / drilling.squaredNorm();
  const Matrix3 normal = Matrix3::Identity() - director * director.transpose();
  return normal * free * normal;
}

template <class Particles>
Basis make_basis(const Particles& particles, const sphshell::detail::Constraints& constraints) {
  const std::size_t n = particles.size();
  Basis b;
  b.translation.resize(n);
  b.rotation.resize(n);
  b.translations.assign(n, max_translations);
  b.rotations.assign(n, max_rotations);
  b.offset.resize(n + 1);
  for (std::size_t i = 0; i < n; ++i) {
    b.translation[i] = {Vector3::UnitX(), Vector3::UnitY(), Vector3::UnitZ()};
    const TangentFrame frame = tangent_frame(particles.director[i]);
    b.rotation[i] = {frame.e1, frame.e2};
  }
  for (std::size_t k = 0; k < constraints.particles().size(); ++k) {
    const auto i = static_cast<std::size_t>(constraints.particles()[k]);
    const sphshell::detail::ParticleConstraint& c = constraints.at(k);
    b.translations[i] = free_directions(c.free_translation, b.translation[i].data(), max_translations);
    b.rotations[i] = free_directions(free_rotation_normal_to(c.free_rotation, particles.director[i]),
                                     b.rotation[i].data(), max_rotations);
  }
  int offset = 0;
  for (std::size_t i = 0; i < n; ++i) {
    b.offset[i] = offset;
    offset += b.translations[i] + b.rotations[i];
  }
  b.offset[n] = offset;
  b.size = offset;
  return b;
}

// Connected parts of the coupling graph.
inline std::vector<std::vector<int>> connected_parts(const std::vector<std::vector<int>>& coupled) {
  std::vector<int> part(coupled.size(), -1);
  std::vector<std::vector<int>> parts;
  for (std::size_t start = 0; start < coupled.size(); ++start) {
    if (part[start] >= 0) continue;
    parts.emplace_back();
    std::vector<int> stack{static_cast<int>(start)};
    part[start] = static_cast<int>(parts.size() - 1);
    while (!stack.empty()) {
      const int j = stack.back();
      stack.pop_back();
      parts.back().push_back(j);
      for (int i : coupled[static_cast<std::size_t>(j)])
        if (part[static_cast<std::size_t>(i)] < 0) {
          part[static_cast<std::size_t>(i)] = part[start];
          stack.push_back(i);
        }
    }
  }
  return parts;
}

// An Error when a rigid motion of a connected part (translation t, rotation ω
// about its centroid, scaled by its size) is left entirely free by the
// kinematic conditions: equilibrium would not be unique and the relaxation
// would drift for ever.
template <class Particles>
void check_rigid_body_modes(const std::vector<std::vector<int>>& parts, const Particles& particles,
                            const Basis& basis) {
  for (const std::vector<int>& part : parts) {
    Vector3 centre = Vector3::Zero();
    for (int i : part) centre += particles.position[static_cast<std::size_t>(i)];
    centre /= static_cast<double>(part.size());
    double size = 0.0;
    for (int i : part) size = std::max(size, (particles.position[static_cast<std::size_t>(i)] - centre).norm());
    if (!(size > 0.0)) size = 1.0;
    // Constrained part of each rigid mode (columns: t_x, t_y, t_z, ω_x, ω_y, ω_z with |ω| = 1/size).
    Eigen::Matrix<double, 6, 6> gram = Eigen::Matrix<double, 6, 6>::Zero();
    for (int i : part) {
      const auto k = static_cast<std::size_t>(i);
      const Vector3 arm = particles.position[k] - centre;
      const Vector3& d = particles.director[k];
      Eigen::Matrix<double, 6, 6> columns;  // [u; size · w] of each mode's constrained part
      for (int a = 0; a < 6; ++a) {
        Vector3 u = Vector3::Zero(), w = Vector3::Zero();
        if (a < 3) {
          u[a] = 1.0;
        } else {
          w[a - 3] = 1.0 / size;
          u = w.cross(arm);
        }
        // Director rotation normal to d: its drilling part does not move the director.
        const Vector3 w_normal = w - w.dot(d) * d;
        Vector3 fixed_u = u, fixed_w = w_normal;
        for (int t = 0; t < basis.translations[k]; ++t)
          fixed_u -= basis.translation[k][static_cast<std::size_t>(t)].dot(u) *
                     basis.translation[k][static_cast<std::size_t>(t)];
        for (int r = 0; r < basis.rotations[k]; ++r)
          fixed_w -= basis.rotation[k][static_cast<std::size_t>(r)].dot(w_normal) *
                     basis.rotation[k][static_cast<std::size_t>(r)];
        // Two segment writes, not a comma initializer: GCC 12 with AVX reads the
        // 3-vector as a 4-wide load there and warns (-Warray-bounds).
        columns.col(a).template head<3>() = fixed_u;
        columns.col(a).template tail<3>() = size * fixed_w;
      }
      gram += columns.transpose() * columns;
    }
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, 6, 6>> eigen(gram);
    if (eigen.eigenvalues()[0] <= rigid_mode_tolerance * static_cast<double>(part.size())) {
      const Eigen::Matrix<double, 6, 1> mode = eigen.eigenvectors().col(0);
      std::ostringstream message;
      message.precision(3);
      message << "sphshell: static solve impossible: the model has a free rigid-body mode (translation "
              << mode.head<3>().transpose() << ", rotation " << (mode.tail<3>() / size).transpose()
              << " rad/m about the centroid " << centre.transpose() << ") in its connected part of "
              << part.size() << " particles containing particle " << part.front()
              << "; the kinematic conditions leave it free, so there is no unique equilibrium: add supports "
                 "(clamp, simply_support, fix_translation, fix_rotation) that hold every part";
      throw Error(message.str());
    }
  }
}

// The automatic relaxation budget (see automatic_relaxation_steps).
inline constexpr double relaxation_steps_per_condition = 1.0;
inline constexpr long least_relaxation_steps = 200000;

}  // namespace detail

// The relaxation budget per load step when StaticParameters::max_relaxation_steps
// is unset. With the Gershgorin masses the stiffest mode of M⁻¹K has a
// frequency of about 1 per pseudo step, so reducing the residual by the factor
// tolerance takes O(√κ ln(1/tolerance)) steps, κ the ratio of the stiffest to
// the softest mode (Underwood 1983). On a shell of extent L, largest spacing s
// and least thickness d the softest mode bends over L (stiffness ∝ E d³/L⁴),
// the stiffest shears or stretches over one spacing (∝ E d/s²) or bends over
// it (∝ E d³/s⁴), so √κ ≈ L²/(s min(s, d)): the budget grows with the
// particles per side and with the slenderness. The factor 1 is about 12 times
// the steps the 21 × 21 clamped plate at L/d = 50 needed (docs/method.md,
// "Static solutions"); the floor is the budget the validation cases were run with.
inline long automatic_relaxation_steps(const ShellModel& model, double tolerance) {
  Vector3 lower = model.particle_position.front(), upper = lower;
  for (const Vector3& x : model.particle_position) lower = lower.cwiseMin(x), upper = upper.cwiseMax(x);
  const double extent = (upper - lower).norm(), spacing = model.maximum_spacing();
  const double root_condition = extent * extent / (spacing * std::min(spacing, model.minimum_thickness()));
  const double steps = detail::relaxation_steps_per_condition * root_condition * std::log(1.0 / tolerance);
  if (!(steps < static_cast<double>(std::numeric_limits<long>::max() / 2))) return std::numeric_limits<long>::max() / 2;
  return std::max(detail::least_relaxation_steps, static_cast<long>(std::ceil(steps)));
}

// The factorised tangent of a Newton step, K dq = r: the symmetric part
// (Cholesky or LDLᵀ, statics/sparse_factorisation.hpp) when the tangent is
// symmetric to finite-difference accuracy (conservative loads on an elastic
// or path-dependent law), else a sparse LU; an Error when the tangent is
// singular. Kept as the preconditioner of the GMRES steps
// (StaticParameters::krylov_iterations), and across the load steps of a solve
// so that the ordering and symbolic analysis of an unchanged pattern are
// reused. (A template for the reason given above free_directions.)
template <class SparseMatrix>
class NewtonFactorisation {
 public:
  void factorise(const SparseMatrix& K, int load_step, double lambda) {
    load_step_ = load_step;
    lambda_ = lambda;
    if (!factorisation_.factorise_tangent(K)) throw singular();
  }
  bool valid() const { return factorisation_.valid(); }
  Eigen::Index size() const { return factorisation_.size(); }
  FactorisationMethod method() const { return factorisation_.method(); }
  // K⁻¹ r, an Error when it is not finite.
  Eigen::VectorXd solve(const Eigen::VectorXd& r) const {
    Eigen::VectorXd dq = factorisation_.solve(r);
    if (!dq.allFinite()) throw singular();
    return dq;
  }

 private:
  Error singular() const {
    return Error("sphshell: static solve: the tangent stiffness is singular at load step " +
                 std::to_string(load_step_) + " (load factor " + solver::number_text(lambda_) +
                 "): the model has a mechanism, or it buckled; add supports or take smaller load steps");
  }
  int load_step_ = 0;
  double lambda_ = 0.0;
  SparseFactorisation<SparseMatrix> factorisation_;
};

// The solve itself (Solver::solve_static calls it).
template <class System, class Observer>
StaticResult solve_static(System& system, const StaticParameters& parameters, Observer&& observer) {
  using namespace detail;
  using SparseMatrix = Eigen::SparseMatrix<double>;
  validate(parameters);
  const ShellModel& model = system.model;
  auto& domain = system.domain;
  solver::ParticleState& particles = system.particles;
  const solver::ParticleForces& forces = system.forces;
  domain.collectively([&] {
    for (std::size_t k = 0; k < system.constraints.particles().size(); ++k)
      if (!system.constraints.at(k).motions.empty())
        sphshell::detail::invalid_parameter(
            "prescribed motion at particle " +
                std::to_string(domain.global_of(static_cast<std::size_t>(system.constraints.particles()[k]))),
            "(prescribe_displacement / prescribe_velocity)",
            "solve_static takes loads and fixed conditions, not prescribed motions");
  });
  // The share's particles: the owned ones first, then the ghosts, whose
  // residual rows are another process's (zero here).
  const std::size_t n = particles.size(), owned = domain.owned_count();
  domain.exchange({&particles.position, &particles.director});
  const double lever = model.maximum_spacing();  // ℓ: moments count as forces at this arm
  const double step_translation = parameters.perturbation * lever;
  const double step_rotation = parameters.perturbation;

  const Coupling coupling = coloured_coupling(system.points, n);
  // The free directions of the share's particles, the ghosts' from their owners (collective).
  auto free_basis = [&] {
    Basis b = make_basis(particles, system.constraints);
    share_basis(domain, b);
    return b;
  };
  if constexpr (std::decay_t<decltype(domain)>::is_distributed) {
    const auto whole = whole_model(domain, model.particle_count(), coupling.near, particles, free_basis());
    domain.collectively([&] { check_rigid_body_modes(connected_parts(whole.coupled), whole.particles, whole.basis); });
  } else {
    check_rigid_body_modes(connected_parts(coupling.near), particles, free_basis());
  }

  StaticResult result;
  Basis basis;
  Eigen::VectorXd r, external;
  // The reduced residual r and external load (both scaled) of the forces last evaluated.
  auto project = [&]() {
    r.setZero(basis.size);
    external.setZero(basis.size);
    for (std::size_t i = 0; i < owned; ++i) {
      const Vector3 f = forces.external[i] - forces.internal[i];
      const Vector3 m = forces.external_moment[i] - particles.director[i].cross(forces.internal_director[i]);
      const int o = basis.offset[i];
      for (int t = 0; t < basis.translations[i]; ++t) {
        r[o + t] = basis.translation[i][static_cast<std::size_t>(t)].dot(f);
        external[o + t] = basis.translation[i][static_cast<std::size_t>(t)].dot(forces.external[i]);
      }
      for (int q = 0; q < basis.rotations[i]; ++q) {
        r[o + basis.translations[i] + q] = basis.rotation[i][static_cast<std::size_t>(q)].dot(m) / lever;
        external[o + basis.translations[i] + q] =
            basis.rotation[i][static_cast<std::size_t>(q)].dot(forces.external_moment[i]) / lever;
      }
    }
  };
  auto residual = [&](double lambda) {
    system.restore_material();
    system.evaluate(lambda);
    ++result.force_evaluations;
    project();
  };
  // The same on every process together: a load function or a point that
  // throws on one stops all (collective).
  auto residual_everywhere = [&](double lambda) { domain.collectively([&] { residual(lambda); }); };
  auto norm = [&](const Eigen::VectorXd& v) { return global_norm(domain, v); };
  auto dot = [&](const Eigen::VectorXd& a, const Eigen::VectorXd& b) { return global_dot(domain, a, b); };
  // Moves the configuration by the reduced increment dq (rotations in rad; the
  // residual's rotation rows are moments / ℓ, so the rotation unknowns are ℓ θ).
  auto move = [&](const Eigen::VectorXd& dq) {
    for (std::size_t i = 0; i < n; ++i) {
      const int o = basis.offset[i];
      for (int t = 0; t < basis.translations[i]; ++t)
        particles.position[i] += dq[o + t] * basis.translation[i][static_cast<std::size_t>(t)];
      Vector3 theta = Vector3::Zero();
      for (int q = 0; q < basis.rotations[i]; ++q)
        theta += dq[o + basis.translations[i] + q] / lever * basis.rotation[i][static_cast<std::size_t>(q)];
      const double angle = theta.norm();
      if (angle > 0.0)
        particles.director[i] = (Eigen::AngleAxisd(angle, theta / angle) * particles.director[i]).normalized();
    }
    domain.exchange({&particles.position, &particles.director});
  };
  // The tangent K = −∂r/∂q (statics/coupling.hpp), the rows of the owned
  // particles (a process perturbs its ghosts as their owners do: the forces
  // of an owned particle are those of its coupled particles alone); the
  // configuration is restored, the forces are those of the last perturbed
  // one. Entries below `negligible` of their column's largest are left out.
  auto tangent = [&](double lambda, double negligible) {
    const std::vector<Vector3> x0 = particles.position, d0 = particles.director;
    const SparseMatrix K = difference_tangent(
        coupling, basis.offset,
        [&](int j, int local) {
          return local < basis.translations[static_cast<std::size_t>(j)] ? step_translation : step_rotation * lever;
        },
        [&](const std::vector<Perturbation>& perturbations) {
          particles.position = x0;
          particles.director = d0;
          for (const Perturbation& m : perturbations) {
            const auto j = static_cast<std::size_t>(m.particle);
            const int nt = basis.translations[j];
            if (m.local < nt)
              particles.position[j] += m.amount * basis.translation[j][static_cast<std::size_t>(m.local)];
            else
              particles.director[j] =
                  (Eigen::AngleAxisd(m.amount / lever, basis.rotation[j][static_cast<std::size_t>(m.local - nt)]) *
                   d0[j])
                      .normalized();
          }
          residual(lambda);
          return Eigen::VectorXd(-r);
        },
        negligible);
    particles.position = x0;
    particles.director = d0;
    return K;
  };

  // The Newton update K dq = r of StaticMass::tangent at the current state:
  // by GMRES on the current tangent, applied by difference_product
  // (statics/coupling.hpp, the path following's product too) with the
  // configuration moved by ±h v as `move` moves it, preconditioned by the
  // kept factorisation; without one that fits, or when GMRES needs more than
  // krylov_iterations products, by a fresh tangent's factorisation, which is
  // kept. The configuration is left as it was (its residual in r only when no
  // product was taken).
  NewtonFactorisation<SparseMatrix> kept;
  auto newton_update = [&](const Eigen::VectorXd& r0, double lambda, int load_step) {
    if (parameters.krylov_iterations > 0 && kept.valid() && kept.size() == basis.size) {
      const std::vector<Vector3> x0 = particles.position, d0 = particles.director;
      // Every unknown's difference step is the tangent's: the rotation
      // unknowns are ℓ θ, so their step ℓ × step_rotation is step_translation.
      auto product = [&](const Eigen::VectorXd& v) {
        return difference_product(
            v, [&](Eigen::Index) { return step_translation; },
            [&](const Eigen::VectorXd& update) {
              particles.position = x0;
              particles.director = d0;
              move(update);
              residual(lambda);
              return Eigen::VectorXd(-r);
            });
      };
      Eigen::VectorXd dq;
      const KrylovSolve krylov =
          gmres(product, [&](const Eigen::VectorXd& v) { return kept.solve(v); }, r0, parameters.krylov_tolerance,
                parameters.krylov_iterations, dq);
      result.krylov_iterations += krylov.iterations;
      particles.position = x0;
      particles.director = d0;
      domain.exchange({&particles.position, &particles.director});
      if (krylov.converged) return dq;
    }
    const SparseMatrix K = tangent(lambda, negligible_tangent_entry);
    kept.factorise(K, load_step, lambda);
    ++result.factorisations;
    result.factorisation = kept.method();
    return kept.solve(r0);
  };

  std::ostream& progress = system.progress_stream ? *system.progress_stream : std::clog;
  const auto wall_start = std::chrono::steady_clock::now();
  const int steps = static_cast<int>(parameters.load_factors.size());
  const long relaxation_budget = parameters.max_relaxation_steps
                                     ? *parameters.max_relaxation_steps
                                     : automatic_relaxation_steps(model, parameters.tolerance);
  auto stop_at_rest = [&] {
    for (std::size_t i = 0; i < n; ++i) {
      particles.velocity[i].setZero();
      particles.angular_velocity[i].setZero();
    }
  };
  system.save_material();
  for (int step = 0; step < steps; ++step) {
    const double lambda = parameters.load_factors[static_cast<std::size_t>(step)];
    const int load_step = step + 1;  // the numbering of every message
    basis = free_basis();
    residual_everywhere(lambda);
    const double load = norm(external);
    if (!(load > 0.0))
      sphshell::detail::invalid_parameter("StaticParameters::load_time",
                                std::isnan(parameters.load_time) ? std::string("(the solver's time)")
                                                                 : solver::number_text(parameters.load_time),
                                "the loads are zero on the free degrees of freedom at that time: a static solve "
                                "needs a load (add_pressure, add_point_force, ...) switched on at load_time");
    long iteration = 0;
    // The lowest-residual state of this load step: kept if the budget runs out.
    std::vector<Vector3> best_position = particles.position, best_director = particles.director;
    double best_relative = std::numeric_limits<double>::infinity();
    long best_iteration = 0;
    auto report = [&](double relative) {
      observer(StaticIteration{load_step, steps, lambda, iteration, relative});
      if (relative < best_relative) {
        best_relative = relative;
        best_iteration = iteration;
        best_position = particles.position;
        best_director = particles.director;
      }
      if (domain.is_root() && parameters.progress_interval > 0 && iteration % parameters.progress_interval == 0) {
        const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall_start).count();
        std::ostringstream line;
        line.precision(4);
        line << "static load step " << load_step << "/" << steps << "  lambda = " << lambda << "  iteration "
             << iteration << "  residual " << relative << " (tolerance " << parameters.tolerance << ")  "
             << result.force_evaluations << " force evaluations in " << seconds << " s\n";
        progress << line.str() << std::flush;
      }
    };
    // The budget ran out: back to the step's lowest-residual state, its
    // material state and internal forces recomputed, at rest; then the Error.
    auto fail_budget = [&](const char* method, const char* budget, long value, bool automatic, double last) {
      particles.position = best_position;
      particles.director = best_director;
      basis = free_basis();
      residual_everywhere(lambda);
      stop_at_rest();
      StaticResult kept = result;
      kept.residual = best_relative;
      kept.load_factor = lambda;
      kept.load_step = load_step;
      kept.iteration = best_iteration;
      kept.converged = false;
      std::ostringstream message;
      message.precision(6);
      message << "sphshell: static solve (" << method << ") did not converge within the budget StaticParameters::"
              << budget << " = " << value << (automatic ? " (automatic)" : "") << " at load step " << load_step
              << " of " << steps << " (load factor " << lambda << "): the lowest residual |r|/|lambda f_ext| = "
              << best_relative << " (tolerance " << parameters.tolerance << ") was reached at iteration "
              << best_iteration << " of the load step (" << last << " at iteration " << iteration
              << "); the solver is left at that lowest-residual state, at rest (StaticNotConverged::result() "
                 "describes it), not at the start of the solve; raise the budget or the tolerance, take smaller "
                 "load steps, or check the supports and loads";
      throw StaticNotConverged(message.str(), kept);
    };
    double relative = norm(r) / load;
    report(relative);
    if (parameters.mass == StaticMass::tangent) {
      while (!(relative <= parameters.tolerance)) {
        if (iteration >= parameters.max_newton_iterations)
          fail_budget("Newton, StaticMass::tangent", "max_newton_iterations", parameters.max_newton_iterations,
                      false, relative);
        const Eigen::VectorXd r0 = r;
        const Eigen::VectorXd dq = newton_update(r0, lambda, load_step);
        // Backtracking: the longest of 1, 1/2, 1/4, ... that lowers ‖r‖, else the best tried.
        const std::vector<Vector3> x0 = particles.position, d0 = particles.director;
        double best_norm = std::numeric_limits<double>::infinity(), best_scale = 1.0, scale = 1.0;
        bool lowered = false;
        for (int halving = 0; halving <= max_step_halvings && !lowered; ++halving, scale *= 0.5) {
          particles.position = x0;
          particles.director = d0;
          move(scale * dq);
          residual(lambda);
          const double tried = r.norm();
          if (tried < best_norm) best_norm = tried, best_scale = scale;
          lowered = tried < r0.norm();
        }
        if (!lowered) {
          particles.position = x0;
          particles.director = d0;
          move(best_scale * dq);
          residual(lambda);
        }
        ++iteration;
        ++result.iterations;
        // The rotation directions follow the turned directors.
        basis = free_basis();
        project();
        relative = norm(r) / load;
        report(relative);
      }
    } else {
      // Fictitious masses from the Gershgorin bound of each tangent row with the
      // pseudo step h = 1: m_a = (h²/2) Σ_b |K_ab|, twice the stability limit
      // h²/4 Σ|K| (Underwood 1983), since the bound of the step's start serves
      // the whole step while the stiffness changes along a nonlinear path.
      // Every entry and each row summed in the global order of the columns,
      // so that the masses do not depend on the share.
      SparseMatrix K;
      domain.collectively([&] { K = tangent(lambda, 0.0); });
      residual_everywhere(lambda);
      Eigen::VectorXd mass = Eigen::VectorXd::Ones(basis.size);  // a ghost's row is never used
      mass.head(basis.offset[owned]).setZero();
      for (std::size_t p : in_global_order(domain, n))
        for (int column = basis.offset[p]; column < basis.offset[p + 1]; ++column)
          for (SparseMatrix::InnerIterator it(K, column); it; ++it)
            mass[it.row()] += gershgorin_mass_factor * std::abs(it.value());
      domain.collectively([&] {
        for (std::size_t i = 0; i < owned; ++i)
          for (int row = basis.offset[i]; row < basis.offset[i + 1]; ++row)
            if (!(mass[row] > 0.0))
              throw Error("sphshell: static solve: free degree of freedom " + std::to_string(row - basis.offset[i]) +
                          " of particle " + std::to_string(domain.global_of(i)) +
                          " has no stiffness (a mechanism): add supports");
      });
      const Eigen::VectorXd r_start = r;
      Eigen::VectorXd velocity = Eigen::VectorXd::Zero(basis.size), moved = Eigen::VectorXd::Zero(basis.size);
      double kinetic_before = 0.0;
      while (!(relative <= parameters.tolerance)) {
        if (iteration >= relaxation_budget)
          fail_budget("dynamic relaxation, StaticMass::particle_bound", "max_relaxation_steps", relaxation_budget,
                      !parameters.max_relaxation_steps, relative);
        if (parameters.damping == StaticDamping::kinetic) {
          velocity += r.cwiseQuotient(mass);
        } else {
          // Underwood: ω₀² = Δqᵀ K Δq / Δqᵀ M Δq with K Δq ≈ −(r − r_start).
          const double stiffness = -dot(moved, r - r_start);
          const double inertia = dot(moved, mass.cwiseProduct(moved));
          const double omega_squared = inertia > 0.0 ? std::max(0.0, stiffness / inertia) : 0.0;
          const double c = std::min(largest_damping, 2.0 * std::sqrt(omega_squared));
          velocity = ((2.0 - c) * velocity + 2.0 * r.cwiseQuotient(mass)) / (2.0 + c);
        }
        move(velocity);
        moved += velocity;
        residual_everywhere(lambda);
        ++iteration;
        ++result.iterations;
        if (parameters.damping == StaticDamping::kinetic) {
          const double kinetic = 0.5 * dot(velocity, mass.cwiseProduct(velocity));
          if (kinetic < kinetic_before) {
            velocity.setZero();
            kinetic_before = 0.0;
          } else {
            kinetic_before = kinetic;
          }
        }
        relative = norm(r) / load;
        report(relative);
      }
    }
    // The converged state is the next step's start.
    system.save_material();
    result.residual = relative;
    result.load_factor = lambda;
    result.load_step = load_step;
    result.iteration = iteration;
    result.converged = true;
  }
  stop_at_rest();
  return result;
}

}  // namespace sphshell::statics
