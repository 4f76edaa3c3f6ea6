#pragma once
// Equilibrium paths of an elastic shell model by Newton's method on the
// assembled tangent (statics/tangent.hpp), the load factor λ scaling the dead
// loads of the Conditions:
//
// - linear_solve: one Newton step from the reference state, K u = λ f, the
//   linear theory's answer (the whole solution of a linear solver).
// - solve_to (load control): load steps, a Newton iteration per step, a step
//   halved when its iteration diverges; the steps grow by a fixed factor after
//   a step taken whole, or (given a StepAdaptation) follow the Newton
//   updates the last step took. The tangent is assembled and
//   factorised afresh at each iteration until the residual is small; from
//   there one factorisation serves while the residual keeps falling fast
//   (NewtonOptions::tangent_reuse_contraction; the factorisation dominates
//   the cost of an iteration on the validation shells).
// - solve_to_displacement (displacement control, Batoz & Dhatt, IJNME 14
//   (1979) 1262–1267): one displacement Σ w_j u_j · e is prescribed step by
//   step and λ is an unknown of each Newton iteration, so the path is followed
//   through limit points of the load (a snap-through).
// - arc_length_step (Riks, IJSS 15 (1979) 529–551, in its hyperplane form):
//   each step moves the particles a given length along the path's direction
//   (the last step's motion), λ solved for with it, so the path passes limit
//   points of any single displacement too (a snap-back).
//
// Failures: bad input (a non-positive step or arc length, a control that is
// held, a mechanism at the start) is an Error before anything moves; a step
// that still fails to converge after its halvings is an Error naming the step
// (its number, counted from 1, and its target), the lowest relative residual
// of its last attempt and the iteration that reached it (the state after that
// many Newton updates, 0 the attempt's start), and the solver is left at the
// last converged state.
//
// A Newton update that overshoots may be shortened by a line search
// (NewtonOptions::line_search) to where the potential energy along it stops
// falling.
//
// An observer (PathFollower::observe) receives a PathPoint after each
// converged step: its number, the load factor, the control, the residual
// reached, the iterations taken and, when asked, the stability with the
// limit and bifurcation points flagged (the first point against the state
// the observation started from). PathCsv (statics/path_csv.hpp) writes the
// points as CSV, PathFrames (statics/path_frames.hpp) as ParaView frames.
// adapted_arc_length chooses the next arc length, and a StepAdaptation the
// next load or displacement step, from the iterations the last step took.

#include <sphshell/core/error.hpp>
#include <sphshell/statics/conditions.hpp>
#include <sphshell/statics/krylov.hpp>
#include <sphshell/statics/stability.hpp>
#include <sphshell/statics/tangent.hpp>

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <limits>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

namespace sphshell::statics {

// Where load control's Newton iteration starts a load step.
enum class LoadPredictor {
  extrapolated,  // the last two converged states extrapolated linearly in the load factor
  last_state     // the last converged state (where a strongly nonlinear path makes the extrapolation overshoot)
};

// How a Newton update is taken (NewtonOptions::line_search).
enum class LineSearch {
  none,   // whole
  energy  // shortened to where the potential energy along it stops falling, when the whole update overshoots
};

struct NewtonOptions {
  double tolerance = 1e-6;  // ‖residual‖ ≤ tolerance · ‖λ f_ext‖, in (0, 1) (thin shells floor near 1e-7)
  int max_iterations = 25;  // per load step, before the step is halved
  int max_halvings = 12;    // per load step
  TangentSteps steps;       // the tangent's finite-difference steps
  // Modified Newton near the solution: once the relative residual is below
  // detail::largest_reused_residual, the factorised tangent of an earlier
  // iteration of the same step serves the next one as long as the relative
  // residual fell at least by this factor over the last iteration; a slower
  // fall assembles and factorises a fresh tangent. The convergence test is
  // the same either way. In [0, 1); 0: a fresh tangent at every iteration
  // (Newton's method itself).
  double tangent_reuse_contraction = 0.3;
  // Load control's Newton steps by GMRES (statics/krylov.hpp): K δ = r
  // solved to ‖r − K δ‖ ≤ krylov_tolerance ‖r‖ with the current tangent K
  // applied by differences of the forces (two evaluations a product) and the
  // kept factorisation of an earlier tangent, from this or an earlier step,
  // as the preconditioner; a solve that needs more than krylov_iterations
  // products assembles and factorises a fresh tangent and solves with it.
  // 0: off (the kept factorisation used as it is, tangent_reuse_contraction).
  int krylov_iterations = 0;
  double krylov_tolerance = 1e-2;  // in (0, 1)
  LoadPredictor predictor = LoadPredictor::extrapolated;
  // Displacement control: at most this many attempted sub-steps (halved
  // increments and failed tries included) per solve_to_displacement call, so
  // a path creeping in tiny steps (where the control cannot pass) stops with
  // an Error.
  int max_substeps = 64;
  // The line search of every Newton update, all three controls (Matthies &
  // Strang, IJNME 14 (1979) 1613–1626): along the update, configuration
  // q(α) = q₀ + α δ at the update's load factor λ₁ (load control: the
  // step's; displacement and arc-length control: λ₀ + δλ, the load factor
  // taken whole), the slope of the potential energy is −s(α) with the slack
  // s(α) = δ · r(q(α), λ₁) (forces times translations, moments times
  // rotations: work). Newton's update has K δ = r(q₀, λ₁) (under the
  // controls too: K δu_r = r, K δu_f = f, δ = δu_r + δλ δu_f), so s(0) =
  // δᵀKδ, > 0 where the tangent is positive along δ. The whole update is
  // taken unless it overshoots the energy's minimum along it, s(1) <
  // −line_search_tolerance · s(0); then α is the zero of s found by
  // regula falsi (the Illinois variant) between 0 and 1, to |s(α)| ≤
  // line_search_tolerance · s(0) or max_line_search_trials trials (the last
  // one kept). Taken whole (no search): s(0) ≤ 0 (no descent of the energy
  // along δ, e.g. past a critical point), and relative residuals below
  // detail::smallest_searched_residual (Newton converges quadratically
  // there, and the residual nears the noise of the difference tangent). An
  // update taken whole costs no force evaluation more (its forces are those
  // the next iteration needs); each trial of a search costs one
  // (NewtonReport::line_search_trials). The displacement control's gap
  // after a shortened update is (1 − α) times the one before; the next
  // iteration closes it.
  LineSearch line_search = LineSearch::none;
  double line_search_tolerance = 0.5;  // in (0, 1)
  int max_line_search_trials = 8;      // >= 1
  // Print every iteration (load factor, relative residual, for
  // displacement control the control gap; whether the tangent was fresh) to
  // standard error.
  bool trace = false;
};

// The control of a path's step.
enum class PathControl {
  load,          // solve_to: the load factor prescribed
  displacement,  // solve_to_displacement: a ControlDisplacement prescribed
  arc_length     // arc_length_step
};

// A change of the number of negative eigenvalues of the tangent between two
// converged points: the path crossed a critical point between them, told apart
// by the mode of the eigenvalue nearest zero at the later point
// (Stability::load_share, |φ·f|/(‖φ‖‖f‖)): at a limit point of the load the
// critical mode does work on the load (φ·f ≠ 0), at a bifurcation it does not
// (φ·f = 0; Riks, IJSS 15 (1979) 529–551, §3). A share below
// detail::bifurcation_load_share is a bifurcation.
enum class PathEvent { none, limit_point, bifurcation };

// Whether the observer's points carry the stability (each costs an assembly
// and an LDLᵀ factorisation of the tangent, and the inverse iteration of
// statics::stability).
enum class PathStability { skip, compute };

// A converged point of the path, as the observer receives it.
struct PathPoint {
  int step = 0;             // this follower's converged steps, counted from 1
  double load_factor = 0.0;
  PathControl control = PathControl::load;
  // m: the control displacement (PathControl::displacement), or the arc
  // length travelled, the sum of this follower's arc-length steps (their
  // root-mean-square motions; PathControl::arc_length); NaN under load control.
  double control_value = std::numeric_limits<double>::quiet_NaN();
  double relative_residual = 0.0;  // ‖r‖ / ‖λ f_ext‖ at the point
  int iterations = 0;              // Newton updates of the step's converged attempt
  // With PathStability::compute (else -1 and NaN): statics::stability at the point.
  int negative_eigenvalues = -1;
  double eigenvalue_nearest_zero = std::numeric_limits<double>::quiet_NaN();
  double load_share = std::numeric_limits<double>::quiet_NaN();
  // Against the observed point before (none at the first one computed).
  PathEvent event = PathEvent::none;
};

// The bounds of the automatic load or displacement step
// (PathFollower::solve_to and solve_to_displacement with a StepAdaptation,
// adapted_step): in the load factor's unit (1) for load control, in metres
// of the control displacement for displacement control.
struct StepAdaptation {
  double min_step = 0.0;      // finite and > 0
  double max_step = 0.0;      // finite and >= min_step
  int target_iterations = 4;  // Newton updates a step should take, >= 1
};

// The bounds of the automatic arc length (adapted_arc_length).
struct ArcLengthAdaptation {
  double min_length = 0.0;     // m, finite and > 0
  double max_length = 0.0;     // m, finite and >= min_length
  int target_iterations = 4;   // Newton updates a step should take, >= 1
};

namespace detail {

// The rule both adaptations share: ℓ · √(target / max(1, used)) within
// [smallest, largest]; `names` gives the parameters' names for the Error.
struct AdaptationNames {
  const char* smallest;
  const char* largest;
  const char* target;
  const char* increment;
};
inline void check_adaptation(double smallest, double largest, int target, const AdaptationNames& names) {
  sphshell::detail::require_positive(names.smallest, smallest);
  if (!(std::isfinite(largest) && largest >= smallest))
    sphshell::detail::invalid_parameter(names.largest, largest,
                                        std::string("must be finite and >= ") + names.smallest + " = " +
                                            std::to_string(smallest));
  if (target < 1) sphshell::detail::invalid_parameter(names.target, target, "must be >= 1");
}
inline double adapted_increment(double increment, int iterations_used, double smallest, double largest, int target,
                                const AdaptationNames& names) {
  check_adaptation(smallest, largest, target, names);
  sphshell::detail::require_positive(names.increment, increment);
  if (iterations_used < 0)
    sphshell::detail::invalid_parameter("iterations used", iterations_used, "must be >= 0");
  const double used = std::max(1, iterations_used);
  return std::clamp(increment * std::sqrt(target / used), smallest, largest);
}
inline constexpr AdaptationNames arc_length_names{"ArcLengthAdaptation::min_length", "ArcLengthAdaptation::max_length",
                                                  "ArcLengthAdaptation::target_iterations", "arc length"};
inline constexpr AdaptationNames step_names{"StepAdaptation::min_step", "StepAdaptation::max_step",
                                            "StepAdaptation::target_iterations", "step"};

}  // namespace detail

// The next arc length from the last one, `length`, and the Newton updates
// its step took, `iterations_used` (Crisfield, Comput. Struct. 13 (1981)
// 55–62): ℓ_next = ℓ · √(target / used), used counted as at least 1, then
// bounded to [min_length, max_length]. Bad bounds are an Error naming them.
inline double adapted_arc_length(double length, int iterations_used, const ArcLengthAdaptation& rule) {
  return detail::adapted_increment(length, iterations_used, rule.min_length, rule.max_length, rule.target_iterations,
                                   detail::arc_length_names);
}

// The next load or displacement step from the last one, `step`, and the
// Newton updates it took: the rule of adapted_arc_length, step · √(target /
// used) within [min_step, max_step]. Bad bounds are an Error naming them.
inline double adapted_step(double step, int iterations_used, const StepAdaptation& rule) {
  return detail::adapted_increment(step, iterations_used, rule.min_step, rule.max_step, rule.target_iterations,
                                   detail::step_names);
}

namespace detail {

// A critical point whose mode's load share (Stability::load_share) is below
// this is a bifurcation, else a limit point (PathEvent).
inline constexpr double bifurcation_load_share = 1e-3;

// A relative residual this much above a displacement-control step's smallest
// so far means the iteration left the path's basin (a wrong branch, a wild
// load factor): halving the step is cheaper than iterating on.
inline constexpr double control_divergence = 1e2;
// A relative residual of load control that no iteration comes back from.
inline constexpr double load_divergence = 1e8;
// A target within this fraction of its scale counts as reached.
inline constexpr double target_reached = 1e-12;
// The growth of a step after one taken whole.
inline constexpr double step_growth = 1.5;
// A kept factorisation serves only below this relative residual: further
// from the solution the full Newton steps of the Sze cylinders overshoot
// (relative residuals 1 → 8 → 1 → 5 in a step's first iterations), and a
// tangent of an earlier iterate would compound that; the first iteration of
// a step (residual of the predictor near 1 or above) always takes a fresh one.
inline constexpr double largest_reused_residual = 1e-2;
// A rotation angle below this (rad) has no axis to extrapolate along.
inline constexpr double smallest_extrapolated_rotation = 1e-14;
// Below this relative residual a Newton update is taken whole (NewtonOptions::line_search).
inline constexpr double smallest_searched_residual = 1e-4;

inline void check(const NewtonOptions& options) {
  sphshell::detail::require_open_interval("NewtonOptions::tolerance", options.tolerance, 0.0, 1.0);
  if (options.max_iterations < 1)
    sphshell::detail::invalid_parameter("NewtonOptions::max_iterations", options.max_iterations, "must be >= 1");
  if (options.max_halvings < 0)
    sphshell::detail::invalid_parameter("NewtonOptions::max_halvings", options.max_halvings, "must be >= 0");
  if (options.max_substeps < 1)
    sphshell::detail::invalid_parameter("NewtonOptions::max_substeps", options.max_substeps, "must be >= 1");
  if (options.krylov_iterations < 0)
    sphshell::detail::invalid_parameter("NewtonOptions::krylov_iterations", options.krylov_iterations,
                                        "must be >= 0 (0: no GMRES)");
  sphshell::detail::require_open_interval("NewtonOptions::krylov_tolerance", options.krylov_tolerance, 0.0, 1.0);
  if (options.line_search != LineSearch::none && options.line_search != LineSearch::energy)
    sphshell::detail::invalid_parameter("NewtonOptions::line_search", static_cast<int>(options.line_search),
                                        "must be none or energy");
  sphshell::detail::require_open_interval("NewtonOptions::line_search_tolerance", options.line_search_tolerance, 0.0,
                                          1.0);
  if (options.max_line_search_trials < 1)
    sphshell::detail::invalid_parameter("NewtonOptions::max_line_search_trials", options.max_line_search_trials,
                                        "must be >= 1");
  if (!(options.tangent_reuse_contraction >= 0.0 && options.tangent_reuse_contraction < 1.0))
    sphshell::detail::invalid_parameter("NewtonOptions::tangent_reuse_contraction", options.tangent_reuse_contraction,
                                        "must lie in [0, 1) (0: a fresh tangent at every iteration)");
}

}  // namespace detail

template <class Solver>
class PathFollower {
 public:
  PathFollower(Solver& solver, Conditions conditions, NewtonOptions options = {})
      : assembly_(solver, std::move(conditions), (detail::check(options), options.steps)), options_(options) {}

  // Equilibrium at the load factor `lambda`, reached from the current state
  // in load steps of at most `step` (halved when an iteration diverges; after
  // a step taken whole the next is detail::step_growth times longer, up to
  // `step`).
  void solve_to(double lambda, double step) { solve_to(lambda, step, nullptr); }

  // The same with the automatic step: `first_step` first, then each next step
  // adapted_step(last step, its Newton updates, adaptation), within
  // [min_step, max_step] (a step that fails is still halved, below min_step
  // if need be; the last step ends at `lambda`). `first_step` must lie
  // within the bounds.
  void solve_to(double lambda, double first_step, const StepAdaptation& adaptation) {
    check_first_step("load step", first_step, adaptation);
    solve_to(lambda, first_step, &adaptation);
  }

  // Equilibrium with the control displacement at `target`, reached from the
  // current state in increments of at most `step` of it (halved when an
  // iteration diverges); the load factor is solved for with the displacement.
  void solve_to_displacement(const ControlDisplacement& control, double target, double step) {
    solve_to_displacement(control, target, step, nullptr);
  }

  // The same with the automatic step, as solve_to with a StepAdaptation
  // (its bounds in metres of the control displacement).
  void solve_to_displacement(const ControlDisplacement& control, double target, double first_step,
                             const StepAdaptation& adaptation) {
    check_first_step("displacement step", first_step, adaptation);
    solve_to_displacement(control, target, first_step, &adaptation);
  }

 private:
  void check_first_step(const char* name, double first_step, const StepAdaptation& adaptation) const {
    detail::check_adaptation(adaptation.min_step, adaptation.max_step, adaptation.target_iterations,
                             detail::step_names);
    if (!(first_step >= adaptation.min_step && first_step <= adaptation.max_step))
      sphshell::detail::invalid_parameter(std::string("first ") + name, first_step,
                                          "must lie within [StepAdaptation::min_step, StepAdaptation::max_step] = [" +
                                              std::to_string(adaptation.min_step) + ", " +
                                              std::to_string(adaptation.max_step) + "]");
  }

  // The next increment after one of `taken` that converged: with
  // `adaptation` by adapted_step from the Newton updates it took, else grown
  // by detail::step_growth up to `step`.
  double next_increment(double taken, double step, const StepAdaptation* adaptation) const {
    if (adaptation) return adapted_step(taken, last_converged_.iterations, *adaptation);
    return std::min(step, detail::step_growth * taken);
  }

  void solve_to(double lambda, double step, const StepAdaptation* adaptation) {
    sphshell::detail::require_positive("load step", step);
    sphshell::detail::require_finite("load factor", lambda);
    check_start();
    note_start_stability();
    double increment = std::min(step, lambda - lambda_);
    while (lambda_ < lambda - detail::target_reached * std::abs(lambda)) {
      double target = lambda;
      const double taken = step_with_halving(
          increment, 0.0,
          [&](double trial) {
            target = std::min(lambda, lambda_ + trial);
            predict(target);
            if (!converge(target)) return false;
            lambda_ = target;
            return true;
          },
          [&](double) { return "Newton did not converge at load factor " + std::to_string(target); });
      converged_step(PathControl::load, std::numeric_limits<double>::quiet_NaN());
      increment = next_increment(taken, step, adaptation);
    }
  }

  void solve_to_displacement(const ControlDisplacement& control, double target, double step,
                             const StepAdaptation* adaptation) {
    sphshell::detail::require_positive("displacement step", step);
    sphshell::detail::require_finite("target displacement", target);
    check_control(control);
    check_start();
    note_start_stability();
    double value = displacement_of(control);
    double increment = step;
    int substeps = 0;
    while (std::abs(target - value) > detail::target_reached * std::max(std::abs(target), step)) {
      double next = value;
      const double taken = step_with_halving(
          increment, value,
          [&](double trial) {
            // Every attempt counts, the halved ones too.
            if (++substeps > options_.max_substeps)
              throw Error("sphshell: displacement control took more than NewtonOptions::max_substeps = " +
                          std::to_string(options_.max_substeps) + " sub-steps toward " + std::to_string(target) +
                          " (at " + std::to_string(value) + ", load factor " + std::to_string(lambda_) +
                          "); the solver is at the last converged state");
            next = target > value ? std::min(target, value + trial) : std::max(target, value - trial);
            predict_displacement(next, value);
            return converge_displacement(control, next);
          },
          [&](double) {
            return "Newton did not converge at control displacement " + std::to_string(next) + " (load factor " +
                   std::to_string(lambda_) + ")";
          });
      value = next;
      converged_step(PathControl::displacement, displacement_of(control));
      increment = next_increment(taken, step, adaptation);
    }
  }

 public:

  // One arc-length step: the particles move a root-mean-square `length` (m)
  // along the path's direction, on the hyperplane normal to it, with the load
  // factor solved for. The direction is the motion of the last step (before
  // any step: the response K⁻¹f to the load, the way the load factor grows).
  // Halved when Newton fails (at most max_halvings times); returns the length taken.
  double arc_length_step(double length) {
    sphshell::detail::require_positive("arc length", length);
    check_start();
    note_start_stability();
    Solver& solver = assembly_.solver();
    const std::vector<Vector3> x0 = solver.positions();
    PathDirection direction;
    if (previous_.x.empty()) {
      const DegreesOfFreedom dofs = assembly_.degrees_of_freedom();
      const Eigen::VectorXd response =
          assembly_.solve(dofs, assembly_.external_load(dofs), Factorisation::general, "at the path's start").col(0);
      for (int i = 0; i + 1 < static_cast<int>(dofs.first.size()); ++i) {
        Vector3 motion = Vector3::Zero();
        for (int k = dofs.first[i]; k < dofs.first[i + 1]; ++k)
          if (!dofs.is_rotation[k]) motion += response[k] * dofs.direction[k];
        direction.motion.push_back({i, motion});
      }
    } else {
      for (int i = 0; i < static_cast<int>(x0.size()); ++i) direction.motion.push_back({i, x0[i] - previous_.x[i]});
    }
    double norm = 0.0;
    for (const auto& [particle, motion] : direction.motion) norm += motion.squaredNorm();
    norm = std::sqrt(norm);
    if (!(norm > 0.0))
      sphshell::detail::invalid_parameter("Conditions force and moment (arc length)", norm,
                                          "the path has no direction: the load must move the particles");
    // Lengths are root-mean-square motions of the particles (independent of their number).
    const double particles = std::sqrt(static_cast<double>(direction.motion.size()));
    for (auto& [particle, motion] : direction.motion) motion /= norm * particles;
    const double last_length = previous_.x.empty() ? 0.0 : norm / particles;
    // The control is 0 where the step begins (direction.start).
    direction.start = displacement_of(direction);
    const double taken = step_with_halving(
        length, 0.0,
        [&](double trial) {
          if (last_length > 0.0) {
            previous_.control = -last_length;  // the last step, measured along its own direction
            predict_displacement(trial, 0.0);
          }
          return converge_displacement(direction, trial);
        },
        [&](double trial) {
          return "Newton did not converge on an arc-length step of " + std::to_string(trial) + " (load factor " +
                 std::to_string(lambda_) + ")";
        });
    last_arc_length_ = taken;
    arc_length_travelled_ += taken;
    converged_step(PathControl::arc_length, arc_length_travelled_);
    return taken;
  }

  // The arc length for the next step by adapted_arc_length from the last
  // arc-length step's length and its Newton updates (an Error before any).
  double next_arc_length(const ArcLengthAdaptation& rule) const {
    if (!(last_arc_length_ > 0.0))
      sphshell::detail::invalid_parameter("arc length of the last step", last_arc_length_,
                                          "next_arc_length needs an arc-length step before it");
    return adapted_arc_length(last_arc_length_, last_converged_.iterations, rule);
  }

  // Hands every converged step's PathPoint to `observer` (an empty function:
  // none), with the stability when asked. With the stability, the state the
  // next step starts from (the first after this call) is factorised too, so
  // that a critical point between it and the first observed point is flagged
  // on that point like any other (the count of negative eigenvalues compared
  // with the start's). The observer is called
  // at the converged state, which it must leave as it is; what it throws
  // reaches the caller with the solver at that state.
  void observe(std::function<void(const PathPoint&)> observer, PathStability stability = PathStability::skip) {
    observer_ = std::move(observer);
    observed_stability_ = stability;
    previous_negative_eigenvalues_ = -1;
  }

  // The last converged step's number (counted from 1; 0 before any), its
  // relative residual and Newton updates.
  int steps_taken() const { return steps_; }
  double last_relative_residual() const { return last_converged_.relative; }
  int last_iterations() const { return last_converged_.iterations; }

  // One Newton step from the current configuration at load factor lambda on
  // the symmetrised tangent (LDLᵀ): K u = λ f at the reference state, the
  // linear theory's answer. (The solver's linear option keeps unit directors,
  // so its forces are not exactly linear in a finite rotation; the step is
  // not iterated.)
  void linear_solve(double lambda) {
    sphshell::detail::require_finite("load factor", lambda);
    const DegreesOfFreedom dofs = assembly_.degrees_of_freedom();
    const Eigen::VectorXd r = assembly_.residual(dofs, lambda);
    // From the unloaded start a zero pivot is a mechanism; elsewhere it may be a point of the path.
    const MechanismCheck check = at_start() ? MechanismCheck::at_start : MechanismCheck::none;
    const Eigen::VectorXd update =
        assembly_.solve(dofs, r, Factorisation::symmetric, "of the linear solve", check).col(0);
    lambda_ = lambda;
    assembly_.apply_update(dofs, update);
  }

  // The control of an arc-length step in the current configuration.
  double displacement_of(const PathDirection& control) const {
    double value = 0.0;
    for (const auto& [particle, motion] : control.motion) value += displacement(particle).dot(motion);
    return value - control.start;
  }

  // The control displacement in the current configuration.
  double displacement_of(const ControlDisplacement& control) const {
    double value = 0.0;
    for (const auto& [particle, weight] : control.weights)
      value += weight * displacement(particle).dot(control.direction);
    return value;
  }

  // The stability of the current state (statics/stability.hpp).
  Stability stability() { return statics::stability(assembly_); }

  double load_factor() const { return lambda_; }
  const NewtonReport& report() const { return assembly_.report(); }
  std::size_t colour_count() const { return assembly_.colour_count(); }
  Vector3 displacement(int particle) const { return assembly_.displacement(particle); }
  TangentAssembly<Solver>& assembly() { return assembly_; }

 private:
  // The count of negative eigenvalues where the observed path starts (the
  // first step after observe() with PathStability::compute), for the first
  // point's event. It is taken after check_start, so a mechanism at the
  // unloaded start is that Error, not a zero pivot here.
  void note_start_stability() {
    if (!observer_ || observed_stability_ != PathStability::compute || previous_negative_eigenvalues_ >= 0) return;
    previous_negative_eigenvalues_ = stability().negative_eigenvalues;
  }

  // A step converged: counted, and its point handed to the observer.
  void converged_step(PathControl control, double control_value) {
    ++steps_;
    if (!observer_) return;
    PathPoint point;
    point.step = steps_;
    point.load_factor = lambda_;
    point.control = control;
    point.control_value = control_value;
    point.relative_residual = last_converged_.relative;
    point.iterations = last_converged_.iterations;
    if (observed_stability_ == PathStability::compute) {
      const Stability state = stability();
      point.negative_eigenvalues = state.negative_eigenvalues;
      point.eigenvalue_nearest_zero = state.eigenvalue_nearest_zero;
      point.load_share = state.load_share;
      if (previous_negative_eigenvalues_ >= 0 && state.negative_eigenvalues != previous_negative_eigenvalues_)
        point.event = state.load_share < detail::bifurcation_load_share ? PathEvent::bifurcation
                                                                         : PathEvent::limit_point;
      previous_negative_eigenvalues_ = state.negative_eigenvalues;
    }
    observer_(point);
  }

  // At the unloaded start a mechanism (a free rigid-body motion) makes every
  // method fail; it is named before anything moves.
  bool at_start() const { return previous_.x.empty() && lambda_ == 0.0; }
  void check_start() {
    if (!at_start() || start_checked_) return;
    const DegreesOfFreedom dofs = assembly_.degrees_of_freedom();
    Eigen::SimplicialLDLT<SparseMatrix> ldlt;
    factorise_checked(ldlt, symmetrised(assembly_.tangent(dofs)), "at the start");
    start_checked_ = true;
  }

  // A control some particle of which can move along its direction.
  void check_control(const ControlDisplacement& control) const {
    const int n = static_cast<int>(assembly_.solver().particle_count());
    if (control.weights.empty())
      sphshell::detail::invalid_parameter("ControlDisplacement::weights", "empty", "must name at least one particle");
    if (!control.direction.allFinite() || !(control.direction.norm() > 0.0))
      sphshell::detail::invalid_parameter("ControlDisplacement::direction", control.direction.transpose(),
                                          "must be finite and non-zero");
    for (const auto& [particle, weight] : control.weights)
      if (particle < 0 || particle >= n)
        sphshell::detail::invalid_parameter("ControlDisplacement particle", particle,
                                            "must lie in [0, " + std::to_string(n) + ")");
    const DegreesOfFreedom dofs = assembly_.degrees_of_freedom();
    const Eigen::VectorXd g = control_gradient(dofs, control);
    double scale = 0.0;
    for (const auto& [particle, weight] : control.weights) scale += std::abs(weight);
    if (!(g.norm() > held_remainder() * scale * control.direction.norm()))
      sphshell::detail::invalid_parameter("ControlDisplacement particle", control.weights.front().first,
                                          "held along the control direction: a control must be free to move");
  }
  static constexpr double held_remainder() { return statics::detail::held_direction_remainder; }

  // An arc-length control's gradient in the degrees of freedom.
  Eigen::VectorXd control_gradient(const DegreesOfFreedom& dofs, const PathDirection& control) const {
    Eigen::VectorXd g = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(dofs.direction.size()));
    for (const auto& [particle, motion] : control.motion)
      for (int k = dofs.first[particle]; k < dofs.first[particle + 1]; ++k)
        if (!dofs.is_rotation[k]) g[k] += motion.dot(dofs.direction[k]);
    return g;
  }

  // The control displacement's gradient (it is linear in the translations).
  Eigen::VectorXd control_gradient(const DegreesOfFreedom& dofs, const ControlDisplacement& control) const {
    Eigen::VectorXd g = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(dofs.direction.size()));
    for (const auto& [particle, weight] : control.weights)
      for (int k = dofs.first[particle]; k < dofs.first[particle + 1]; ++k)
        if (!dofs.is_rotation[k]) g[k] += weight * control.direction.dot(dofs.direction[k]);
    return g;
  }

  // Newton's method on equilibrium and the prescribed control, λ an
  // unknown: with K δu_r = r and K δu_f = f_ext, the update δu_r + δλ δu_f
  // meets the control to first order (it is linear in the translations, so
  // exactly).
  template <class Control>
  bool converge_displacement(const Control& control, double target) {
    double smallest = std::numeric_limits<double>::infinity();
    last_relative_ = std::numeric_limits<double>::infinity();
    lowest_ = {};
    assembly_.discard_kept_factorisation();  // a step starts on a fresh tangent
    for (int iteration = 0; iteration < options_.max_iterations; ++iteration) {
      const DegreesOfFreedom dofs = assembly_.degrees_of_freedom();
      const Eigen::VectorXd f = assembly_.external_load(dofs);
      const Eigen::VectorXd r = assembly_.residual(dofs, lambda_);
      const double reference = std::abs(lambda_) * f.norm();
      const double gap = target - displacement_of(control);
      if (options_.trace)
        std::fprintf(stderr, "  iteration %d: load factor %.8g, residual %.3e (relative %.3e), gap %.3e\n", iteration,
                     lambda_, r.norm(), reference > 0.0 ? r.norm() / reference : 0.0, gap);
      if (iteration == 0) assembly_.report().load_step_start_residual = reference > 0.0 ? r.norm() / reference : 0.0;
      if (!std::isfinite(r.norm())) return false;
      // At λ = 0 (the first iteration from the unloaded state) there is no
      // load to measure the residual against: iterate.
      if (reference > 0.0) {
        const double relative = r.norm() / reference;
        note_residual(iteration, relative);
        if (relative > detail::control_divergence * smallest) return false;
        smallest = std::min(smallest, relative);
        if (relative <= options_.tolerance && std::abs(gap) <= options_.tolerance * std::abs(target)) {
          last_converged_ = {relative, iteration};
          return true;
        }
      }
      // The kept factorisation's degrees of freedom (they follow the
      // directors, so they may lag the current ones by its age).
      const DegreesOfFreedom& basis = tangent_for(dofs, reference > 0.0 ? r.norm() / reference : 0.0);
      Eigen::MatrixXd rhs(r.size(), 2);
      rhs.col(0) = &basis == &dofs ? r : assembly_.residual(basis, lambda_);
      rhs.col(1) = &basis == &dofs ? f : assembly_.external_load(basis);
      const Eigen::MatrixXd solution = assembly_.solve_kept(rhs);
      const Eigen::VectorXd g = control_gradient(basis, control);
      const double along_load = g.dot(solution.col(1));
      if (!(std::abs(along_load) > 0.0)) return false;
      const double d_lambda = (gap - g.dot(solution.col(0))) / along_load;
      lambda_ += d_lambda;
      // The slack's start: the residual where the update starts, at the update's load factor.
      take_update(basis, solution.col(0) + d_lambda * solution.col(1), lambda_, dofs, r + d_lambda * f,
                  reference > 0.0 ? r.norm() / reference : 0.0);
    }
    return false;
  }

  // Takes a Newton update from the current state: the configuration moved by
  // α `update` (in `basis`), α by the line search (NewtonOptions::line_search)
  // at the load factor `lambda`; `residual` is r(q₀, lambda) in `dofs`, the
  // current state's degrees of freedom, `relative` the current relative
  // residual (0: none to measure, no search).
  void take_update(const DegreesOfFreedom& basis, const Eigen::VectorXd& update, double lambda,
                   const DegreesOfFreedom& dofs, const Eigen::VectorXd& residual, double relative) {
    // Copies: the trials replace the solver's configuration.
    const std::vector<Vector3> x0 = assembly_.solver().positions(), d0 = assembly_.solver().directors();
    take_update(basis, x0, d0, update, lambda, dofs, residual, relative);
  }
  // The same from the configuration (x0, d0).
  void take_update(const DegreesOfFreedom& basis, const std::vector<Vector3>& x0, const std::vector<Vector3>& d0,
                   const Eigen::VectorXd& update, double lambda, const DegreesOfFreedom& dofs,
                   const Eigen::VectorXd& residual, double relative) {
    const bool search = options_.line_search == LineSearch::energy &&
                        relative > detail::smallest_searched_residual && std::isfinite(relative);
    std::vector<Vector3> translation, rotation;  // of the whole update, per particle
    double slack0 = 0.0;
    if (search) {
      assembly_.split(basis, update, translation, rotation);
      slack0 = slack(dofs, residual, translation, rotation);
    }
    assembly_.apply_update(basis, x0, d0, update);
    if (!search || !(slack0 > 0.0)) return;
    const double accepted = options_.line_search_tolerance * slack0;
    auto slack_here = [&] {
      const DegreesOfFreedom here = assembly_.degrees_of_freedom();
      return slack(here, assembly_.residual(here, lambda), translation, rotation);
    };
    const double slack1 = slack_here();
    if (slack1 >= -accepted) return;  // no overshoot (a NaN slack fails the test: searched)
    // Regula falsi on s(α) between (low, s_low) with s > 0 and (high, s_high) with s < 0.
    double low = 0.0, s_low = slack0, high = 1.0, s_high = std::isfinite(slack1) ? slack1 : -slack0;
    // Illinois: an end kept by two trials in a row has its slack halved (1: high kept, -1: low kept).
    int kept_side = 0;
    double alpha = 1.0, s_alpha = slack1;
    for (int trial = 0; trial < options_.max_line_search_trials; ++trial) {
      alpha = (low * s_high - high * s_low) / (s_high - s_low);
      assembly_.set_moved_configuration(basis, x0, d0, alpha * update);
      ++assembly_.report().line_search_trials;
      s_alpha = slack_here();
      if (!std::isfinite(s_alpha)) s_alpha = -slack0;  // treated as past the minimum
      if (std::abs(s_alpha) <= accepted) break;
      if (s_alpha > 0.0) {
        low = alpha, s_low = s_alpha;
        if (kept_side == 1) s_high *= 0.5;
        kept_side = 1;
      } else {
        high = alpha, s_high = s_alpha;
        if (kept_side == -1) s_low *= 0.5;
        kept_side = -1;
      }
    }
    if (options_.trace)
      std::fprintf(stderr, "  (line search: %.6g of the update, slack %.3e -> %.3e, whole %.3e)\n", alpha, slack0,
                   s_alpha, slack1);
  }

  // The slack δ · r of the update (translation, rotation per particle) with
  // the residual `residual` in `dofs`: work, the translations against the
  // forces and the rotations against the moments.
  double slack(const DegreesOfFreedom& dofs, const Eigen::VectorXd& residual, const std::vector<Vector3>& translation,
               const std::vector<Vector3>& rotation) const {
    std::vector<Vector3> force, moment;
    assembly_.split(dofs, residual, force, moment);
    double sum = 0.0;
    for (std::size_t i = 0; i < force.size(); ++i) sum += force[i].dot(translation[i]) + moment[i].dot(rotation[i]);
    return sum;
  }

  // Modified Newton (NewtonOptions::tangent_reuse_contraction): keeps the
  // factorisation of an earlier iteration of the step while the relative
  // residual is small and falls fast enough, else factorises the tangent in
  // `dofs`. `relative` is the
  // current relative residual (0 when there is no load to measure it
  // against: a fresh tangent). Returns the degrees of freedom of the
  // factorisation to use: `dofs` itself when it is fresh.
  const DegreesOfFreedom& tangent_for(const DegreesOfFreedom& dofs, double relative) {
    const double contraction = options_.tangent_reuse_contraction;
    const bool keep = contraction > 0.0 && relative > 0.0 && relative <= detail::largest_reused_residual &&
                      assembly_.has_kept_factorisation() &&
                      assembly_.kept_degrees_of_freedom().count() == dofs.count() &&
                      !(relative > contraction * last_relative_);
    last_relative_ = relative;
    if (keep) return assembly_.kept_degrees_of_freedom();
    if (options_.trace) std::fprintf(stderr, "  (a fresh tangent)\n");
    assembly_.factorise(dofs, "on the path");
    return dofs;
  }

  // The lowest relative residual of the current attempt and its iteration
  // (the state after that many updates, 0 the attempt's start), for the
  // Error when a step fails.
  void note_residual(int iteration, double relative) {
    if (relative < lowest_.relative) lowest_ = {relative, iteration};
  }

  // Load control's Newton iteration at λ.
  bool converge(double lambda) {
    last_relative_ = std::numeric_limits<double>::infinity();
    lowest_ = {};
    // A step starts on a fresh tangent, or with GMRES on the kept one as the preconditioner.
    if (options_.krylov_iterations == 0) assembly_.discard_kept_factorisation();
    for (int iteration = 0; iteration < options_.max_iterations; ++iteration) {
      const DegreesOfFreedom dofs = assembly_.degrees_of_freedom();
      const Eigen::VectorXd r = assembly_.residual(dofs, lambda);
      const double reference = assembly_.load_norm(dofs, lambda);
      const double relative = r.norm() / reference;
      if (iteration == 0) assembly_.report().load_step_start_residual = relative;
      if (!std::isfinite(relative)) return false;
      note_residual(iteration, relative);
      if (relative <= options_.tolerance) {
        last_converged_ = {relative, iteration};
        return true;
      }
      if (options_.trace)
        std::fprintf(stderr, "  iteration %d: load factor %.8g, relative residual %.3e\n", iteration, lambda, relative);
      if (relative > detail::load_divergence) return false;
      if (options_.krylov_iterations > 0) {
        krylov_update(dofs, r, lambda, relative);
        continue;
      }
      const DegreesOfFreedom& basis = tangent_for(dofs, relative);
      const Eigen::VectorXd rhs = &basis == &dofs ? r : assembly_.residual(basis, lambda);
      take_update(basis, assembly_.solve_kept(rhs).col(0), lambda, dofs, r, relative);
    }
    return false;
  }

  // One Newton update K δ = r by GMRES on the current tangent, the kept
  // factorisation its preconditioner (NewtonOptions::krylov_iterations);
  // without one, or when GMRES needs more products than allowed, a fresh
  // tangent is factorised at the current state and solved with directly.
  // The update is taken by take_update (at load factor `lambda`, `relative` the current relative residual).
  void krylov_update(const DegreesOfFreedom& dofs, const Eigen::VectorXd& r, double lambda, double relative) {
    Solver& solver = assembly_.solver();
    const std::vector<Vector3> x0 = solver.positions(), d0 = solver.directors();
    if (assembly_.has_kept_factorisation() && assembly_.kept_degrees_of_freedom().count() == dofs.count()) {
      Eigen::VectorXd update;
      const KrylovSolve krylov = gmres(
          [&](const Eigen::VectorXd& v) { return assembly_.tangent_product(dofs, x0, d0, v); },
          [&](const Eigen::VectorXd& v) { return Eigen::VectorXd(assembly_.solve_kept(v).col(0)); }, r,
          options_.krylov_tolerance, options_.krylov_iterations, update);
      assembly_.report().krylov_iterations += krylov.iterations;
      if (options_.trace)
        std::fprintf(stderr, "  (GMRES: %d products, relative residual %.3e)\n", krylov.iterations,
                     krylov.relative_residual);
      if (krylov.converged) {
        take_update(dofs, x0, d0, update, lambda, dofs, r, relative);
        return;
      }
      assembly_.set_configuration(x0, d0);
    }
    if (options_.trace) std::fprintf(stderr, "  (a fresh tangent)\n");
    assembly_.factorise(dofs, "on the path");
    take_update(dofs, x0, d0, assembly_.solve_kept(r).col(0), lambda, dofs, r, relative);
  }

  // The start of a displacement step: the last two converged states (and
  // load factors) extrapolated linearly in the control.
  void predict_displacement(double target, double value) {
    if (previous_.x.empty()) return;
    const double span = value - previous_.control;
    if (!(std::abs(span) > 0.0)) return;
    const double ratio = (target - value) / span;
    lambda_ += ratio * (lambda_ - previous_.lambda);
    extrapolate(ratio);
  }

  // The start of a load step: the last two converged states extrapolated
  // linearly in the load factor, else (or with LoadPredictor::last_state)
  // the current state.
  void predict(double target) {
    if (previous_.x.empty() || options_.predictor == LoadPredictor::last_state) return;
    const double span = lambda_ - previous_.lambda;
    if (!(span > 0.0)) return;
    extrapolate((target - lambda_) / span);
  }

  // The current state moved on by `ratio` times the last step (translations,
  // and the director turned on by the last step's rotation, scaled).
  void extrapolate(double ratio) {
    const Solver& solver = assembly_.solver();
    std::vector<Vector3> x = solver.positions(), d = solver.directors();
    for (std::size_t i = 0; i < x.size(); ++i) {
      x[i] += ratio * (x[i] - previous_.x[i]);
      const Vector3 axis = previous_.d[i].cross(d[i]);
      const double angle = std::atan2(axis.norm(), previous_.d[i].dot(d[i]));
      if (axis.norm() > detail::smallest_extrapolated_rotation)
        d[i] = Eigen::AngleAxisd(ratio * angle, axis.normalized()) * d[i];
    }
    assembly_.set_configuration(std::move(x), std::move(d));
  }

  // The step-and-halve loop the controls share: attempt(increment) takes one
  // step of `increment` from the current state (predictor and Newton) and
  // returns whether it converged. After a failure the configuration and the
  // load factor are put back and the increment halved, at most max_halvings
  // times in a row (then an Error with failure(increment)'s text). A converged
  // step leaves the state before it (control value `control_before`) as the
  // last one. Returns the increment that converged.
  template <class Attempt, class Failure>
  double step_with_halving(double increment, double control_before, Attempt&& attempt, Failure&& failure) {
    const Solver& solver = assembly_.solver();
    for (int halvings = 0;; ++halvings) {
      const std::vector<Vector3> x0 = solver.positions(), d0 = solver.directors();
      const double lambda0 = lambda_;
      bool converged = false;
      try {
        converged = attempt(increment);
      } catch (...) {
        assembly_.restore_configuration(x0, d0);
        lambda_ = lambda0;
        throw;
      }
      if (converged) {
        previous_ = {x0, d0, lambda0, control_before};
        ++assembly_.report().load_steps;
        return increment;
      }
      assembly_.restore_configuration(x0, d0);
      lambda_ = lambda0;
      // The halved step starts on a fresh tangent.
      assembly_.discard_kept_factorisation();
      if (halvings + 1 > options_.max_halvings) {
        std::ostringstream text;
        text.precision(4);
        text << "sphshell: " << failure(increment) << " at load step " << assembly_.report().load_steps + 1
             << " (counted from 1) after NewtonOptions::max_halvings = " << options_.max_halvings
             << " halvings: its last attempt's lowest relative residual |r|/|lambda f_ext| ";
        if (lowest_.iteration >= 0)
          text << "= " << lowest_.relative << " was reached at iteration " << lowest_.iteration;
        else
          text << "was never measured (no load)";
        text << " (tolerance " << options_.tolerance << ", NewtonOptions::max_iterations = " << options_.max_iterations
             << "); the solver is at the last converged state, load factor " << lambda_;
        throw Error(text.str());
      }
      increment *= 0.5;
    }
  }

  TangentAssembly<Solver> assembly_;
  NewtonOptions options_;
  double lambda_ = 0.0;
  bool start_checked_ = false;
  // The relative residual of the iteration before (tangent_for).
  double last_relative_ = std::numeric_limits<double>::infinity();
  struct Lowest {
    double relative = std::numeric_limits<double>::infinity();
    int iteration = -1;
  } lowest_;  // of the current attempt (note_residual)
  struct Converged {
    std::vector<Vector3> x, d;
    double lambda = 0.0;
    double control = 0.0;  // the control displacement (displacement control)
  } previous_;  // the converged state before the current one
  struct LastConverged {
    double relative = std::numeric_limits<double>::quiet_NaN();
    int iterations = 0;
  } last_converged_;  // the last converged attempt's relative residual and Newton updates
  int steps_ = 0;     // converged steps
  double last_arc_length_ = 0.0, arc_length_travelled_ = 0.0;
  std::function<void(const PathPoint&)> observer_;
  PathStability observed_stability_ = PathStability::skip;
  int previous_negative_eigenvalues_ = -1;  // at the last observed point with the stability
};

}  // namespace sphshell::statics
