#pragma once
// Static equilibrium of any elastic shell model by Newton's method on a
// stiffness assembled from the solver's own internal forces (central
// differences), for the benchmark tests and the shell_benchmarks example. It
// generalises tests/support/static_plate.hpp from a flat grid's three bending
// dofs to every model: per particle the free translations and the free
// rotations of the director (two axes normal to it; drilling is no dof).
//
// - A linear solver (options.nonlinear = false) is solved by one Newton step:
//   the exact equilibrium its dynamic relaxation would reach.
// - A nonlinear solver is solved by load stepping, a full Newton iteration per
//   step (the tangent re-assembled at every iteration), and step halving when
//   an iteration diverges.
// - Or by displacement control (Batoz & Dhatt, IJNME 14 (1979) 1262–1267):
//   one displacement Σ w_j u_j · e is prescribed step by step and the load
//   factor is an unknown of each Newton iteration, so the path is followed
//   through limit points of the load (a snap-through), where load control
//   fails.
// - Or by arc length (Riks, IJSS 15 (1979) 529–551, in its hyperplane form):
//   each step moves the particles a given length along the path's direction
//   (the last step's motion), the load factor solved for with it, so the
//   path passes limit points of any single displacement too (a snap-back,
//   where displacement control stalls: the control cannot grow past them).
//
// The assembly perturbs many particles at once. A particle's motion changes
// the forces only within two support radii (the stress points that see it and
// the particles those points see), so particles more than four support radii
// apart in the reference configuration (the approximation is Lagrangian) share
// a colour and are perturbed together; each response is credited to the one
// perturbed particle within reach. The colours come from a greedy colouring.
//
// Conditions are kept here, not in the solver: held translation directions,
// held rotation axes, symmetry planes (no translation across the plane, the
// director kept in it), and dead forces and moments (a moment M does the work
// M · δθ for a director rotation δθ).

#include <sphshell/core/error.hpp>
#include <sphshell/core/frame.hpp>
#include <sphshell/core/types.hpp>
#include <sphshell/shell/cell.hpp>
#include <sphshell/solver/integration_points.hpp>
#include <sphshell/solver/static_solution.hpp>

#include <Eigen/Dense>
#include <Eigen/Sparse>
#include <Eigen/SparseCholesky>
#include <Eigen/SparseLU>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdio>
#include <functional>
#include <limits>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

namespace sphshell::test_support {

// Conditions and dead loads of a static problem, per particle.
struct StaticConditions {
  std::vector<std::vector<Vector3>> held_translations;  // directions with zero displacement
  std::vector<std::vector<Vector3>> held_rotation_axes;  // global axes with zero rotation
  std::vector<std::vector<Vector3>> symmetry_normals;    // planes the particle lies on
  std::vector<char> rotations_held;                      // both director rotations held
  std::vector<Vector3> force;   // N, at load factor 1
  std::vector<Vector3> moment;  // N·m, at load factor 1

  explicit StaticConditions(std::size_t particles)
      : held_translations(particles),
        held_rotation_axes(particles),
        symmetry_normals(particles),
        rotations_held(particles, 0),
        force(particles, Vector3::Zero()),
        moment(particles, Vector3::Zero()) {}

  void clamp(const ParticleSet& set) {
    for (int i : set) {
      held_translations[i] = {Vector3::UnitX(), Vector3::UnitY(), Vector3::UnitZ()};
      rotations_held[i] = 1;
    }
  }
  void hold_translation(const ParticleSet& set, const Vector3& direction) {
    for (int i : set) held_translations[i].push_back(direction.normalized());
  }
  void hold_rotation(const ParticleSet& set, const Vector3& axis) {
    for (int i : set) held_rotation_axes[i].push_back(axis.normalized());
  }
  void symmetry_plane(const ParticleSet& set, const Vector3& normal) {
    for (int i : set) {
      held_translations[i].push_back(normal.normalized());
      symmetry_normals[i].push_back(normal.normalized());
    }
  }
  void add_force(const ParticleSet& set, const Vector3& f) {
    for (int i : set) force[i] += f;
  }
  void add_moment(const ParticleSet& set, const Vector3& m) {
    for (int i : set) moment[i] += m;
  }
};

struct NewtonOptions {
  double tolerance = 1e-6;          // ‖residual‖ ≤ tolerance · ‖λ f_ext‖ (thin shells floor near 1e-7)
  int max_iterations = 25;          // per load step, before the step is halved
  int max_halvings = 12;            // per load step
  double translation_step = 1e-7;   // finite-difference step, in units of the model's spacing
  double rotation_step = 1e-7;      // rad
  // Perturb one particle at a time (for checking the colouring; slow).
  bool one_particle_per_colour = false;
  // Displacement control: at most this many attempted sub-steps (halved
  // increments and failed tries included) per solve_to_displacement call, so
  // a path creeping in tiny steps (where the control cannot pass) stops with
  // an error.
  int max_substeps = 64;
  // Print every displacement-control iteration (load factor, relative
  // residual, control gap) to standard error.
  bool trace = false;
};

// A displacement of the model, Σ w_j u_j · direction over particles j with
// weights w_j (a particle's own, or the approximation's value at a point).
struct ControlDisplacement {
  std::vector<std::pair<int, double>> weights;
  Vector3 direction;
};

// An arc-length step's control: Σ_j a_j · u_j − start, with a_j the motion of
// particle j over the path's last step divided by √N times its length ‖Δx‖
// (N particles: the control grows by the root-mean-square motion of the
// particles along that direction), start its value where the step begins.
struct PathDirection {
  std::vector<std::pair<int, Vector3>> motion;
  double start = 0.0;
};

struct NewtonReport {
  int load_steps = 0;         // converged steps, halved ones included
  int iterations = 0;         // Newton iterations (tangent assemblies) in all
  long force_evaluations = 0;  // internal-force computations in all
};

template <class Solver>
class StaticShell {
 public:
  StaticShell(Solver& solver, StaticConditions conditions, NewtonOptions options = {})
      : solver_(solver), conditions_(std::move(conditions)), options_(options) {
    const std::size_t n = solver_.particle_count();
    if (conditions_.force.size() != n) throw std::invalid_argument("StaticShell: conditions sized for another model");
    const double spacing = solver_.model().maximum_spacing();
    translation_step_ = options_.translation_step * spacing;
    colour_particles();
  }

  // Equilibrium at the load factor `lambda`, reached from the current state
  // in load steps of at most `step` (halved when an iteration diverges).
  void solve_to(double lambda, double step) {
    if (!(step > 0.0)) throw std::invalid_argument("StaticShell: the load step must be positive");
    double increment = std::min(step, lambda - lambda_);
    while (lambda_ < lambda - 1e-12 * std::abs(lambda)) {
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
      increment = std::min(step, 1.5 * taken);
    }
  }

  // Equilibrium with the control displacement at `target`, reached from the
  // current state in increments of at most `step` of it (halved when an
  // iteration diverges); the load factor is solved for with the displacement.
  void solve_to_displacement(const ControlDisplacement& control, double target, double step) {
    if (!(step > 0.0)) throw std::invalid_argument("StaticShell: the displacement step must be positive");
    double value = displacement_of(control);
    double increment = step;
    int substeps = 0;
    while (std::abs(target - value) > 1e-12 * std::max(std::abs(target), step)) {
      double next = value;
      const double taken = step_with_halving(
          increment, value,
          [&](double trial) {
            // Every attempt counts, the halved ones too.
            if (++substeps > options_.max_substeps)
              throw std::runtime_error("StaticShell: displacement control took more than " +
                                       std::to_string(options_.max_substeps) + " sub-steps toward " +
                                       std::to_string(target) + " (at " + std::to_string(value) + ", load factor " +
                                       std::to_string(lambda_) + ")");
            next = target > value ? std::min(target, value + trial) : std::max(target, value - trial);
            predict_displacement(next, value);
            return converge_displacement(control, next);
          },
          [&](double) {
            return "Newton did not converge at control displacement " + std::to_string(next) + " (load factor " +
                   std::to_string(lambda_) + ")";
          });
      value = next;
      increment = std::min(step, 1.5 * taken);
    }
  }

  // One arc-length step: the particles move a root-mean-square `length` (m)
  // along the path's direction, on the hyperplane normal to it, with the load factor solved
  // for. The direction is the motion of the last step (before any step: the
  // response K⁻¹f to the load, the way the load factor grows). Halved when
  // Newton fails (at most max_halvings times); returns the length taken.
  double arc_length_step(double length) {
    if (!(length > 0.0)) throw std::invalid_argument("StaticShell: the arc length must be positive");
    const std::vector<Vector3> x0 = solver_.positions();
    PathDirection direction;
    if (previous_.x.empty()) {
      const Dofs dofs = current_dofs();
      const Eigen::VectorXd response = solve_tangent(dofs, external_load(dofs), Factorisation::general).col(0);
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
    if (!(norm > 0.0)) throw std::runtime_error("StaticShell: the path has no direction (no load, or no last step)");
    // Lengths are root-mean-square motions of the particles (independent of their number).
    const double particles = std::sqrt(static_cast<double>(direction.motion.size()));
    for (auto& [particle, motion] : direction.motion) motion /= norm * particles;
    const double last_length = previous_.x.empty() ? 0.0 : norm / particles;
    // The control is 0 where the step begins (direction.start).
    direction.start = displacement_of(direction);
    return step_with_halving(
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
    for (const auto& [particle, weight] : control.weights) value += weight * displacement(particle).dot(control.direction);
    return value;
  }

  // One Newton step from the current configuration at load factor lambda (the
  // whole solution of a linear solver).
  // The stiffness is symmetrised and factorised by LDLᵀ (the linear
  // stiffness is symmetric; the finite differences leave it so to rounding).
  // This is K u = f at the reference state: the linear theory's answer. (The
  // solver's linear option keeps unit directors, so its forces are not exactly
  // linear in a finite rotation; the step is not iterated.)
  void linear_solve(double lambda) {
    lambda_ = lambda;
    newton_iteration(lambda, Factorisation::symmetric);
  }

  // The stability of the current state, for telling where a path turns
  // unstable (a bifurcation, or a limit point of the load): the number of
  // negative eigenvalues of the symmetrised tangent stiffness, read off the
  // signs of its LDLᵀ pivots (Sylvester's law of inertia), and its eigenvalue
  // nearest zero by inverse iteration on the same factorisation. The
  // eigenvalue mixes N/m and N·m/rad: compare it along one path, not across models.
  struct Stability {
    int negative_eigenvalues = 0;
    double eigenvalue_nearest_zero = 0.0;
    // Its mode: |φ · f| / (‖φ‖ ‖f‖) with the load f (near 0 at a bifurcation,
    // not at a limit point of the load), and each particle's translation in it.
    double load_share = 0.0;
    std::vector<Vector3> mode;
    std::vector<Vector3> mode_rotation;  // each director's rotation vector in it (rad per unit of the mode)
  };
  Stability stability() {
    constexpr int inverse_iterations = 60;
    const Dofs dofs = current_dofs();
    const Eigen::SparseMatrix<double> symmetric = symmetrised(tangent(dofs));
    Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> ldlt(symmetric);
    if (ldlt.info() != Eigen::Success) throw std::runtime_error("StaticShell: the tangent has a zero pivot");
    Stability result;
    for (Eigen::Index i = 0; i < ldlt.vectorD().size(); ++i)
      if (ldlt.vectorD()[i] < 0.0) ++result.negative_eigenvalues;
    // A start with a part along every mode (no symmetry of the model is orthogonal to it).
    Eigen::VectorXd x(symmetric.rows());
    for (Eigen::Index i = 0; i < x.size(); ++i) x[i] = std::sin(1.0 + 0.7548776662 * static_cast<double>(i));
    x.normalize();
    for (int iteration = 0; iteration < inverse_iterations; ++iteration) x = ldlt.solve(x).normalized();
    result.eigenvalue_nearest_zero = x.dot(symmetric * x);
    const Eigen::VectorXd f = external_load(dofs);
    result.load_share = f.norm() > 0.0 ? std::abs(x.dot(f)) / f.norm() : 0.0;
    result.mode.assign(dofs.first.size() - 1, Vector3::Zero());
    result.mode_rotation.assign(dofs.first.size() - 1, Vector3::Zero());
    for (std::size_t i = 0; i + 1 < dofs.first.size(); ++i)
      for (int k = dofs.first[i]; k < dofs.first[i + 1]; ++k)
        (dofs.is_rotation[k] ? result.mode_rotation[i] : result.mode[i]) += x[k] * dofs.direction[k];
    return result;
  }

  double load_factor() const { return lambda_; }
  const NewtonReport& report() const { return report_; }
  std::size_t colour_count() const { return colours_.size(); }
  Vector3 displacement(int particle) const {
    return solver_.positions()[particle] - solver_.model().particle_position[particle];
  }

 private:
  struct Dofs {
    std::vector<Vector3> direction;  // translation (m) or rotation axis (rad) per dof
    std::vector<char> is_rotation;
    std::vector<int> first;          // first dof of each particle; first[n] = count
  };

  // Orthonormal basis of the part of span(ambient) orthogonal to `held`.
  static std::vector<Vector3> free_basis(const std::vector<Vector3>& ambient, const std::vector<Vector3>& held) {
    // Remove the held directions (projected into the ambient span), then orthonormalise.
    std::vector<Vector3> held_in_span;
    for (const Vector3& h : held) {
      Vector3 p = Vector3::Zero();
      for (const Vector3& a : ambient) p += h.dot(a) * a;
      for (const Vector3& q : held_in_span) p -= p.dot(q) * q;
      if (p.norm() > 1e-8) held_in_span.push_back(p.normalized());
    }
    std::vector<Vector3> result;
    for (Vector3 v : ambient) {
      for (const Vector3& q : held_in_span) v -= v.dot(q) * q;
      for (const Vector3& q : result) v -= v.dot(q) * q;
      if (v.norm() > 1e-8) result.push_back(v.normalized());
    }
    return result;
  }

  Dofs current_dofs() const {
    const std::size_t n = solver_.particle_count();
    Dofs dofs;
    dofs.first.resize(n + 1);
    for (std::size_t i = 0; i < n; ++i) {
      dofs.first[i] = static_cast<int>(dofs.direction.size());
      for (const Vector3& t : free_basis({Vector3::UnitX(), Vector3::UnitY(), Vector3::UnitZ()},
                                         conditions_.held_translations[i])) {
        dofs.direction.push_back(t);
        dofs.is_rotation.push_back(0);
      }
      if (conditions_.rotations_held[i]) continue;
      const Vector3 d = solver_.directors()[i];
      const TangentFrame frame = tangent_frame(d);
      std::vector<Vector3> held = conditions_.held_rotation_axes[i];
      for (const Vector3& m : conditions_.symmetry_normals[i]) held.push_back(d.cross(m));
      for (const Vector3& a : free_basis({frame.e1, frame.e2}, held)) {
        dofs.direction.push_back(a);
        dofs.is_rotation.push_back(1);
      }
    }
    dofs.first[n] = static_cast<int>(dofs.direction.size());
    return dofs;
  }

  // Residual λ f_ext − f_int in the dofs (f_int = ∂Π/∂q).
  Eigen::VectorXd residual(const Dofs& dofs, double lambda) const {
    const std::size_t n = solver_.particle_count();
    Eigen::VectorXd r(dofs.direction.size());
    for (std::size_t i = 0; i < n; ++i) {
      const Vector3 moment = solver_.directors()[i].cross(solver_.internal_director_forces()[i]);
      for (int k = dofs.first[i]; k < dofs.first[i + 1]; ++k) {
        const Vector3& a = dofs.direction[k];
        r[k] = dofs.is_rotation[k] ? a.dot(lambda * conditions_.moment[i] - moment)
                                   : a.dot(lambda * conditions_.force[i] - solver_.internal_forces()[i]);
      }
    }
    return r;
  }

  double load_norm(const Dofs& dofs, double lambda) const {
    double sum = 0.0;
    for (std::size_t i = 0; i + 1 < dofs.first.size(); ++i)
      for (int k = dofs.first[i]; k < dofs.first[i + 1]; ++k) {
        const double f = dofs.direction[k].dot(dofs.is_rotation[k] ? conditions_.moment[i] : conditions_.force[i]);
        sum += f * f;
      }
    return std::abs(lambda) * std::sqrt(sum);
  }

  // Moves particle i by dof k's amount `amount`.
  static void move(const Dofs& dofs, int k, double amount, Vector3& x, Vector3& d) {
    if (dofs.is_rotation[k])
      d = Eigen::AngleAxisd(amount, dofs.direction[k]) * d;
    else
      x += amount * dofs.direction[k];
  }

  // The colours of the coupling graph of the solver's own rows (the library's
  // static_detail::coupling and distance-2 colouring, as solve_static uses):
  // each particle's near_ lists the particles whose forces its motion
  // changes, and no particle is near two of one colour. Every point's support
  // follows its own spacing, so a distance bound would have to take the
  // largest radius everywhere.
  void colour_particles() {
    using Approx = typename Solver::approximation_type;
    const ShellModel& model = solver_.model();
    const SolverOptions& options = solver_.options();
    const solver::IntegrationPoints<Approx> points(model, options.physics(), options.particle_integration(),
                                                   solver_.material().shear_modulus(),
                                                   solver_.material().poisson_ratio());
    near_ = solver::static_detail::coupling(points, model.particle_count());
    if (options_.one_particle_per_colour) {
      colours_.clear();
      for (int i = 0; i < static_cast<int>(near_.size()); ++i) colours_.push_back({i});
    } else {
      colours_ = solver::static_detail::colour(near_);
    }
  }

  // The Jacobian of the residual's negative (the tangent stiffness) in the dofs.
  Eigen::SparseMatrix<double> tangent(const Dofs& dofs) {
    const std::vector<Vector3> x0 = solver_.positions(), d0 = solver_.directors();
    const int n = static_cast<int>(x0.size());
    const int count = dofs.first[n];
    std::vector<Eigen::Triplet<double>> entries;
    std::vector<int> owner(n, -1);
    for (const std::vector<int>& members : colours_) {
      for (int p : members)
        for (int q : near_[p]) owner[q] = p;
      for (int local = 0; local < 5; ++local) {
        bool any = false;
        for (int p : members) any = any || dofs.first[p] + local < dofs.first[p + 1];
        if (!any) continue;
        std::vector<Eigen::VectorXd> forces;
        for (double sign : {1.0, -1.0}) {
          std::vector<Vector3> x = x0, d = d0;
          for (int p : members) {
            const int k = dofs.first[p] + local;
            if (k >= dofs.first[p + 1]) continue;
            move(dofs, k, sign * (dofs.is_rotation[k] ? options_.rotation_step : translation_step_), x[p], d[p]);
          }
          solver_.set_configuration(std::move(x), std::move(d));
          ++report_.force_evaluations;
          forces.push_back(-residual(dofs, 0.0));
        }
        for (int p : members) {
          const int column = dofs.first[p] + local;
          if (column >= dofs.first[p + 1]) continue;
          const double h = dofs.is_rotation[column] ? options_.rotation_step : translation_step_;
          for (int q : near_[p]) {
            if (owner[q] != p) continue;
            for (int row = dofs.first[q]; row < dofs.first[q + 1]; ++row) {
              const double value = (forces[0][row] - forces[1][row]) / (2.0 * h);
              if (value != 0.0) entries.emplace_back(row, column, value);
            }
          }
        }
      }
      for (int p : members)
        for (int q : near_[p]) owner[q] = -1;
    }
    solver_.set_configuration(x0, d0);
    ++report_.force_evaluations;
    Eigen::SparseMatrix<double> k(count, count);
    k.setFromTriplets(entries.begin(), entries.end());
    return k;
  }

  enum class Factorisation { symmetric, general };

  // ½ (K + Kᵀ): the finite differences leave the tangent symmetric only to rounding.
  static Eigen::SparseMatrix<double> symmetrised(const Eigen::SparseMatrix<double>& k) {
    const Eigen::SparseMatrix<double> transposed = k.transpose();
    return 0.5 * (k + transposed);
  }

  // The tangent's solutions for the columns of `rhs`, from one factorisation.
  // The stiffness is symmetrised and factorised by LDLᵀ (the linear
  // stiffness is symmetric; the finite differences leave it so to rounding),
  // or factorised as it is by LU (a nonlinear tangent).
  Eigen::MatrixXd solve_tangent(const Dofs& dofs, const Eigen::MatrixXd& rhs, Factorisation factorisation) {
    Eigen::SparseMatrix<double> k = tangent(dofs);
    k.makeCompressed();
    if (factorisation == Factorisation::symmetric) {
      Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> ldlt(symmetrised(k));
      if (ldlt.info() != Eigen::Success)
        throw std::runtime_error("StaticShell: the stiffness is singular (a free rigid-body mode?)");
      return ldlt.solve(rhs);
    }
    Eigen::SparseLU<Eigen::SparseMatrix<double>> lu;
    lu.compute(k);
    if (lu.info() != Eigen::Success)
      throw std::runtime_error("StaticShell: the tangent stiffness is singular (a free rigid-body mode?)");
    return lu.solve(rhs);
  }

  // Moves the particles by an update in the dofs (translations added,
  // directors turned by the rotation vector of their dofs).
  void apply_update(const Dofs& dofs, const Eigen::VectorXd& update) {
    std::vector<Vector3> x = solver_.positions(), d = solver_.directors();
    const int n = static_cast<int>(x.size());
    for (int i = 0; i < n; ++i) {
      Vector3 rotation = Vector3::Zero();
      for (int k2 = dofs.first[i]; k2 < dofs.first[i + 1]; ++k2) {
        if (dofs.is_rotation[k2])
          rotation += update[k2] * dofs.direction[k2];
        else
          x[i] += update[k2] * dofs.direction[k2];
      }
      const double angle = rotation.norm();
      if (angle > 0.0) d[i] = Eigen::AngleAxisd(angle, rotation / angle) * d[i];
    }
    solver_.set_configuration(std::move(x), std::move(d));
    ++report_.force_evaluations;
    ++report_.iterations;
  }

  // One Newton update; returns the relative residual before it.
  double newton_iteration(double lambda, Factorisation factorisation = Factorisation::general) {
    const Dofs dofs = current_dofs();
    const Eigen::VectorXd r = residual(dofs, lambda);
    const double reference = load_norm(dofs, lambda);
    apply_update(dofs, solve_tangent(dofs, r, factorisation).col(0));
    return reference > 0.0 ? r.norm() / reference : r.norm();
  }

  // The external load at load factor 1 in the dofs.
  Eigen::VectorXd external_load(const Dofs& dofs) const {
    Eigen::VectorXd f(dofs.direction.size());
    for (std::size_t i = 0; i + 1 < dofs.first.size(); ++i)
      for (int k = dofs.first[i]; k < dofs.first[i + 1]; ++k)
        f[k] = dofs.direction[k].dot(dofs.is_rotation[k] ? conditions_.moment[i] : conditions_.force[i]);
    return f;
  }

  // An arc-length control's gradient in the dofs.
  Eigen::VectorXd control_gradient(const Dofs& dofs, const PathDirection& control) const {
    Eigen::VectorXd g = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(dofs.direction.size()));
    for (const auto& [particle, motion] : control.motion)
      for (int k = dofs.first[particle]; k < dofs.first[particle + 1]; ++k)
        if (!dofs.is_rotation[k]) g[k] += motion.dot(dofs.direction[k]);
    return g;
  }

  // The control displacement's gradient in the dofs (it is linear in the translations).
  Eigen::VectorXd control_gradient(const Dofs& dofs, const ControlDisplacement& control) const {
    Eigen::VectorXd g = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(dofs.direction.size()));
    for (const auto& [particle, weight] : control.weights)
      for (int k = dofs.first[particle]; k < dofs.first[particle + 1]; ++k)
        if (!dofs.is_rotation[k]) g[k] += weight * control.direction.dot(dofs.direction[k]);
    return g;
  }

  // Newton's method on equilibrium and the prescribed control displacement,
  // the load factor lambda_ an unknown: with K δu_r = r and K δu_f = f_ext,
  // the update δu_r + δλ δu_f meets the displacement to first order (it is
  // linear in the translations, so exactly).
  template <class Control>
  bool converge_displacement(const Control& control, double target) {
    // A relative residual this much above the step's smallest so far means
    // the iteration left the path's basin (a wrong branch, a wild load
    // factor): halving the step is cheaper than iterating on.
    constexpr double divergence = 1e2;
    double smallest = std::numeric_limits<double>::infinity();
    for (int iteration = 0; iteration < options_.max_iterations; ++iteration) {
      const Dofs dofs = current_dofs();
      const Eigen::VectorXd f = external_load(dofs);
      const Eigen::VectorXd r = residual(dofs, lambda_);
      const double reference = std::abs(lambda_) * f.norm();
      const double gap = target - displacement_of(control);
      if (options_.trace)
        std::fprintf(stderr, "  iteration %d: load factor %.8g, residual %.3e (relative %.3e), gap %.3e\n", iteration,
                     lambda_, r.norm(), reference > 0.0 ? r.norm() / reference : 0.0, gap);
      if (!std::isfinite(r.norm())) return false;
      // At λ = 0 (the first iteration from the unloaded state) there is no
      // load to measure the residual against: iterate.
      if (reference > 0.0) {
        const double relative = r.norm() / reference;
        if (relative > divergence * smallest) return false;
        smallest = std::min(smallest, relative);
        if (relative <= options_.tolerance && std::abs(gap) <= options_.tolerance * std::abs(target)) return true;
      }
      Eigen::MatrixXd rhs(r.size(), 2);
      rhs.col(0) = r;
      rhs.col(1) = f;
      const Eigen::MatrixXd solution = solve_tangent(dofs, rhs, Factorisation::general);
      const Eigen::VectorXd g = control_gradient(dofs, control);
      const double along_load = g.dot(solution.col(1));
      if (!(std::abs(along_load) > 0.0)) return false;
      const double d_lambda = (gap - g.dot(solution.col(0))) / along_load;
      lambda_ += d_lambda;
      apply_update(dofs, solution.col(0) + d_lambda * solution.col(1));
    }
    return false;
  }

  // The start of a displacement step: the last two converged states (and
  // load factors) extrapolated linearly in the control displacement.
  void predict_displacement(double target, double value) {
    if (previous_.x.empty()) return;
    const double span = value - previous_.control;
    if (!(std::abs(span) > 0.0)) return;
    const double ratio = (target - value) / span;
    lambda_ += ratio * (lambda_ - previous_.lambda);
    extrapolate(ratio);
  }

  // The start of a load step: the last two converged states extrapolated
  // linearly in the load factor, else the current state.
  void predict(double target) {
    if (previous_.x.empty()) return;
    const double span = lambda_ - previous_.lambda;
    if (!(span > 0.0)) return;
    extrapolate((target - lambda_) / span);
  }

  // The current state moved on by `ratio` times the last step (translations,
  // and the director turned on by the last step's rotation, scaled).
  void extrapolate(double ratio) {
    std::vector<Vector3> x = solver_.positions(), d = solver_.directors();
    for (std::size_t i = 0; i < x.size(); ++i) {
      x[i] += ratio * (x[i] - previous_.x[i]);
      const Vector3 axis = previous_.d[i].cross(d[i]);
      const double angle = std::atan2(axis.norm(), previous_.d[i].dot(d[i]));
      if (axis.norm() > 1e-14) d[i] = Eigen::AngleAxisd(ratio * angle, axis.normalized()) * d[i];
    }
    solver_.set_configuration(std::move(x), std::move(d));
    ++report_.force_evaluations;
  }

  // The step-and-halve loop the controls share: attempt(increment) takes one
  // step of `increment` from the current state (predictor and Newton) and
  // returns whether it converged. After a failure the configuration and the
  // load factor are put back and the increment halved, at most max_halvings
  // times in a row (then an error with failure(increment)'s text). A converged
  // step leaves the state before it (control value `control_before`) as the
  // last one. Returns the increment that converged.
  template <class Attempt, class Failure>
  double step_with_halving(double increment, double control_before, Attempt&& attempt, Failure&& failure) {
    for (int halvings = 0;; ++halvings) {
      const std::vector<Vector3> x0 = solver_.positions(), d0 = solver_.directors();
      const double lambda0 = lambda_;
      if (attempt(increment)) {
        previous_ = {x0, d0, lambda0, control_before};
        ++report_.load_steps;
        return increment;
      }
      solver_.set_configuration(x0, d0);
      ++report_.force_evaluations;
      lambda_ = lambda0;
      if (halvings + 1 > options_.max_halvings) throw std::runtime_error("StaticShell: " + failure(increment));
      increment *= 0.5;
    }
  }

  bool converge(double lambda) {
    constexpr double divergence = 1e8;  // a relative residual that no iteration comes back from
    for (int iteration = 0; iteration < options_.max_iterations; ++iteration) {
      const Dofs dofs = current_dofs();
      const double reference = load_norm(dofs, lambda);
      const double relative = residual(dofs, lambda).norm() / reference;
      if (!std::isfinite(relative)) return false;
      if (relative <= options_.tolerance) return true;
      if (relative > divergence) return false;
      newton_iteration(lambda);
    }
    return false;
  }

  Solver& solver_;
  StaticConditions conditions_;
  NewtonOptions options_;
  double translation_step_ = 0.0;
  double lambda_ = 0.0;
  struct Converged {
    std::vector<Vector3> x, d;
    double lambda = 0.0;
    double control = 0.0;  // the control displacement (displacement control)
  } previous_;  // the converged state before the current one
  std::vector<std::vector<int>> colours_;
  std::vector<std::vector<int>> near_;  // per particle: the particles it is coupled to (itself included)
  NewtonReport report_;
};

}  // namespace sphshell::test_support
