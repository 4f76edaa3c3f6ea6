#pragma once
// The tangent stiffness of a solver's model in the free degrees of freedom of
// static Conditions: per particle the free translations and the free
// rotations of the director (two axes normal to it; drilling is no degree of
// freedom). The stiffness is the Jacobian of the internal forces, assembled by
// central differences of the solver's own forces.
//
// The assembly perturbs many particles at once, colour by colour of the
// coupling graph of the solver's rows (statics/coupling.hpp, the one
// difference Jacobian Solver::solve_static uses too).

#include <sphshell/core/error.hpp>
#include <sphshell/core/frame.hpp>
#include <sphshell/core/types.hpp>
#include <sphshell/solver/integration_points.hpp>
#include <sphshell/statics/conditions.hpp>
#include <sphshell/statics/coupling.hpp>
#include <sphshell/statics/sparse_factorisation.hpp>
#include <sphshell/statics/statics.hpp>

#include <Eigen/Dense>
#include <Eigen/Sparse>
#include <Eigen/SparseCholesky>
#include <Eigen/SparseLU>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>
#include <memory>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

namespace sphshell::statics {

// The cost of a static analysis so far.
struct NewtonReport {
  int load_steps = 0;          // converged steps, halved ones included
  int iterations = 0;          // Newton updates in all
  long force_evaluations = 0;  // internal-force computations in all
  int factorisations = 0;      // tangents assembled and factorised for Newton steps
  long krylov_iterations = 0;  // tangent products of the GMRES Newton steps (NewtonOptions::krylov_iterations)
  // Shortened trials of the line search (NewtonOptions::line_search): force
  // evaluations at a fraction of a Newton update, the final one included.
  long line_search_trials = 0;
  // The relative residual ‖r‖ / ‖λ f_ext‖ where the last step's Newton
  // iteration started, at its predictor (load control: NewtonOptions::predictor;
  // displacement control and arc length: the last two converged states and load
  // factors extrapolated in the control), the last attempt when the step was
  // halved; 0 for a step that starts unloaded (λ = 0: nothing to measure against).
  double load_step_start_residual = 0.0;
};

// The finite-difference steps of the tangent.
struct TangentSteps {
  double translation = 1e-7;  // in units of the model's largest spacing
  double rotation = 1e-7;     // rad
  // Perturb one particle at a time (for checking the colouring; slow).
  bool one_particle_per_colour = false;
};

// How the tangent is factorised: symmetrised and LDLᵀ (the stiffness of an
// elastic law at equilibrium is symmetric; the finite differences leave it so
// to rounding), or as it is by LU (a nonlinear tangent off equilibrium).
enum class Factorisation { symmetric, general };

// The free degrees of freedom of the current configuration.
struct DegreesOfFreedom {
  std::vector<Vector3> direction;  // translation (m) or rotation axis (rad) per degree of freedom
  std::vector<char> is_rotation;
  std::vector<int> first;  // first degree of freedom of each particle; first[n] = count
  int count() const { return first.empty() ? 0 : first.back(); }
};

namespace detail {

// A direction whose component left after removing held ones is below this
// (of a unit vector) is held.
inline constexpr double held_direction_remainder = 1e-8;

// A pivot of the symmetrised tangent at the unloaded start below this
// fraction of its own diagonal entry is a rounding residue of zero. The
// comparison is per degree of freedom, not with the largest pivot: the rows
// mix N/m and N·m/rad, so a ratio to the largest pivot depends on the model's
// size and thickness. A pivot D_i of LDLᵀ is the diagonal entry K_ii less the
// part other degrees of freedom carry; D_i / K_ii ≥ λ_min of the diagonally
// scaled tangent, which for a supported thin plate is about (t/L)² (ℓ/L)²
// (1.6e-9 at L/t = 500 and 51 particles a side). Unloaded, the forces are
// zero, so the central differences' rounding is ε |K| per entry: a free
// motion leaves D_i / K_ii at rounding level, near ε times the number of
// entries of a row (1e-16 to 1e-13 on the free strips and the Scordelis–Lo
// roof left free to slide along its axis, against 4e-6 and more on the
// supported models of the tests).
inline constexpr double mechanism_pivot_ratio = 1e-12;

// Start vectors of inverse and subspace iterations have components
// sin(1 + g i): a part along every mode (no symmetry of a model is orthogonal
// to it), g the plastic number's reciprocal.
inline constexpr double start_vector_increment = 0.7548776662;

// Orthonormal basis of the part of span(ambient) orthogonal to `held`.
inline std::vector<Vector3> free_basis(const std::vector<Vector3>& ambient, const std::vector<Vector3>& held) {
  std::vector<Vector3> held_in_span;
  for (const Vector3& h : held) {
    Vector3 p = Vector3::Zero();
    for (const Vector3& a : ambient) p += h.dot(a) * a;
    for (const Vector3& q : held_in_span) p -= p.dot(q) * q;
    if (p.norm() > held_direction_remainder) held_in_span.push_back(p.normalized());
  }
  std::vector<Vector3> result;
  for (Vector3 v : ambient) {
    for (const Vector3& q : held_in_span) v -= v.dot(q) * q;
    for (const Vector3& q : result) v -= v.dot(q) * q;
    if (v.norm() > held_direction_remainder) result.push_back(v.normalized());
  }
  return result;
}

}  // namespace detail

// ½ (K + Kᵀ).
inline SparseMatrix symmetrised(const SparseMatrix& k) {
  const SparseMatrix transposed = k.transpose();
  return 0.5 * (k + transposed);
}

// LDLᵀ of a symmetric stiffness. With `check` set (the unloaded start of a
// solve, where a zero pivot can only be a mechanism) it is refused with an
// Error when a pivot is zero to rounding against its own diagonal entry (a
// free rigid-body motion or an unsupported part); otherwise only a failed
// factorisation is. `where` names the state.
enum class MechanismCheck { at_start, none };
inline void factorise_checked(Eigen::SimplicialLDLT<SparseMatrix>& ldlt, const SparseMatrix& symmetric,
                              const std::string& where, MechanismCheck check = MechanismCheck::at_start) {
  ldlt.compute(symmetric);
  if (ldlt.info() != Eigen::Success)
    sphshell::detail::invalid_parameter("conditions (tangent stiffness " + where + ")", "a failed LDLT",
                                        "the tangent has a zero pivot: the model has a mechanism; hold its free "
                                        "rigid-body motions");
  if (check == MechanismCheck::none) return;
  // D is in the fill-reducing order P K Pᵀ: the diagonal taken to the same order.
  const Eigen::VectorXd diagonal = ldlt.permutationP() * Eigen::VectorXd(symmetric.diagonal());
  const Eigen::VectorXd& pivots = ldlt.vectorD();
  Eigen::Index worst = -1;
  double worst_ratio = std::numeric_limits<double>::infinity();
  for (Eigen::Index i = 0; i < pivots.size(); ++i) {
    const double ratio = std::abs(diagonal[i]) > 0.0 ? std::abs(pivots[i]) / std::abs(diagonal[i]) : 0.0;
    if (!(ratio > detail::mechanism_pivot_ratio) && !(ratio >= worst_ratio)) worst = i, worst_ratio = ratio;
  }
  if (worst < 0) return;
  // The degree of freedom in the caller's numbering.
  const Eigen::Index dof = ldlt.permutationPinv().indices()[worst];
  std::ostringstream text;
  text << "a pivot of the tangent is zero to rounding (|pivot| / |diagonal| = " << worst_ratio
       << " <= " << detail::mechanism_pivot_ratio << " at degree of freedom " << dof
       << "): the model has a mechanism; hold its free rigid-body motions";
  sphshell::detail::invalid_parameter("conditions (tangent stiffness " + where + ")", pivots[worst], text.str());
}

// The assembly of the residual and the tangent of one solver under Conditions.
template <class Solver>
class TangentAssembly {
  static_assert(is_static_analysable_v<Solver>,
                "statics: the solver must be a serial sphshell::Solver (set_configuration and the internal forces); "
                "a distributed model relaxes with Solver::solve_static and StaticMass::particle_bound (the default), "
                "or solve it on one process and load its state");

 public:
  TangentAssembly(Solver& solver, Conditions conditions, TangentSteps steps = {})
      : solver_(solver), conditions_(std::move(conditions)), steps_(steps) {
    const std::size_t n = solver_.particle_count();
    if (conditions_.particle_count() != n || conditions_.held_translations.size() != n ||
        conditions_.held_rotation_axes.size() != n || conditions_.symmetry_normals.size() != n ||
        conditions_.rotations_held.size() != n || conditions_.moment.size() != n)
      sphshell::detail::invalid_parameter("Conditions particle count", conditions_.particle_count(),
                                          "must equal the solver's particle count " + std::to_string(n));
    sphshell::detail::require_positive("TangentSteps::translation", steps_.translation);
    sphshell::detail::require_positive("TangentSteps::rotation", steps_.rotation);
    translation_step_ = steps_.translation * solver_.model().maximum_spacing();
    colour_particles();
  }

  Solver& solver() { return solver_; }
  const Solver& solver() const { return solver_; }
  const Conditions& conditions() const { return conditions_; }
  std::size_t colour_count() const { return coupling_.colours.size(); }
  NewtonReport& report() { return report_; }
  const NewtonReport& report() const { return report_; }

  Vector3 displacement(int particle) const {
    return solver_.positions()[particle] - solver_.model().particle_position[particle];
  }

  DegreesOfFreedom degrees_of_freedom() const {
    const std::size_t n = solver_.particle_count();
    DegreesOfFreedom dofs;
    dofs.first.resize(n + 1);
    for (std::size_t i = 0; i < n; ++i) {
      dofs.first[i] = static_cast<int>(dofs.direction.size());
      for (const Vector3& t : detail::free_basis({Vector3::UnitX(), Vector3::UnitY(), Vector3::UnitZ()},
                                                 conditions_.held_translations[i])) {
        dofs.direction.push_back(t);
        dofs.is_rotation.push_back(0);
      }
      if (conditions_.rotations_held[i]) continue;
      const Vector3 d = solver_.directors()[i];
      const TangentFrame frame = tangent_frame(d);
      std::vector<Vector3> held = conditions_.held_rotation_axes[i];
      for (const Vector3& m : conditions_.symmetry_normals[i]) held.push_back(d.cross(m));
      for (const Vector3& a : detail::free_basis({frame.e1, frame.e2}, held)) {
        dofs.direction.push_back(a);
        dofs.is_rotation.push_back(1);
      }
    }
    dofs.first[n] = static_cast<int>(dofs.direction.size());
    return dofs;
  }

  // Residual λ f_ext − f_int in the degrees of freedom (f_int = ∂Π/∂q).
  Eigen::VectorXd residual(const DegreesOfFreedom& dofs, double lambda) const {
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

  // The external load at load factor 1 in the degrees of freedom.
  Eigen::VectorXd external_load(const DegreesOfFreedom& dofs) const {
    Eigen::VectorXd f(dofs.direction.size());
    for (std::size_t i = 0; i + 1 < dofs.first.size(); ++i)
      for (int k = dofs.first[i]; k < dofs.first[i + 1]; ++k)
        f[k] = dofs.direction[k].dot(dofs.is_rotation[k] ? conditions_.moment[i] : conditions_.force[i]);
    return f;
  }

  // ‖λ f_ext‖ in the degrees of freedom.
  double load_norm(const DegreesOfFreedom& dofs, double lambda) const {
    double sum = 0.0;
    for (std::size_t i = 0; i + 1 < dofs.first.size(); ++i)
      for (int k = dofs.first[i]; k < dofs.first[i + 1]; ++k) {
        const double f = dofs.direction[k].dot(dofs.is_rotation[k] ? conditions_.moment[i] : conditions_.force[i]);
        sum += f * f;
      }
    return std::abs(lambda) * std::sqrt(sum);
  }

  // The Jacobian of the residual's negative (the tangent stiffness) at the
  // current configuration, which it leaves as it found it.
  SparseMatrix tangent(const DegreesOfFreedom& dofs) {
    const std::vector<Vector3> x0 = solver_.positions(), d0 = solver_.directors();
    const SparseMatrix k = difference_tangent(
        coupling_, dofs.first, [&](int p, int local) { return step_of(dofs, dofs.first[p] + local); },
        [&](const std::vector<Perturbation>& perturbations) {
          std::vector<Vector3> x = x0, d = d0;
          for (const Perturbation& m : perturbations)
            move(dofs, dofs.first[m.particle] + m.local, m.amount, x[m.particle], d[m.particle]);
          solver_.set_configuration(std::move(x), std::move(d));
          ++report_.force_evaluations;
          return Eigen::VectorXd(-residual(dofs, 0.0));
        });
    solver_.set_configuration(x0, d0);
    ++report_.force_evaluations;
    return k;
  }

  // The tangent's solutions for the columns of `rhs`, from one factorisation;
  // `where` names the state in an Error.
  // `check`: whether a pivot zero to rounding is refused as a mechanism (at
  // the unloaded start of a solve only, see factorise_checked).
  // Factorisation::general goes through factorise (below), which keeps its
  // factorisation for solve_kept.
  Eigen::MatrixXd solve(const DegreesOfFreedom& dofs, const Eigen::MatrixXd& rhs, Factorisation factorisation,
                        const std::string& where, MechanismCheck check = MechanismCheck::none) {
    if (factorisation == Factorisation::symmetric) {
      Eigen::SimplicialLDLT<SparseMatrix> ldlt;
      factorise_checked(ldlt, symmetrised(tangent(dofs)), where, check);
      return ldlt.solve(rhs);
    }
    factorise(dofs, where);
    return solve_kept(rhs);
  }

  // Assembles the tangent in `dofs` and factorises it by LU, kept (with the
  // degrees of freedom it is written in) until the next factorise or discard.
  // The fill-reducing ordering and the symbolic analysis depend on the
  // pattern alone, so they are redone only when the pattern changes (the
  // numbers are the same as a fresh analysis: the row pivoting is numeric).
  void factorise(const DegreesOfFreedom& dofs, const std::string& where) {
    kept_.valid = false;
    if (!kept_.factorisation.factorise_general(tangent(dofs)))
      sphshell::detail::invalid_parameter("conditions (tangent stiffness " + where + ")",
                                          kept_.factorisation.failure(),
                                          "the LU factorisation met a zero pivot: a mechanism or a singular point "
                                          "of the path");
    kept_.dofs = dofs;
    kept_.valid = true;
    ++report_.factorisations;
  }

  // Whether a factorisation is kept, the degrees of freedom it is written
  // in, its solutions, and forgetting it.
  bool has_kept_factorisation() const { return kept_.valid; }
  const DegreesOfFreedom& kept_degrees_of_freedom() const { return kept_.dofs; }
  Eigen::MatrixXd solve_kept(const Eigen::MatrixXd& rhs) const { return kept_.factorisation.solve(rhs); }
  void discard_kept_factorisation() { kept_.valid = false; }

  // Moves the particles by an update in the degrees of freedom (translations
  // added, directors turned by the rotation vector of their degrees of freedom).
  void apply_update(const DegreesOfFreedom& dofs, const Eigen::VectorXd& update) {
    apply_update(dofs, solver_.positions(), solver_.directors(), update);
  }
  // The same from the configuration (x0, d0) instead of the current one.
  void apply_update(const DegreesOfFreedom& dofs, std::vector<Vector3> x0, std::vector<Vector3> d0,
                    const Eigen::VectorXd& update) {
    set_moved_configuration(dofs, std::move(x0), std::move(d0), update);
    ++report_.iterations;
  }
  // The configuration (x0, d0) moved by `update` as apply_update moves it,
  // counted as a force evaluation but not as a Newton update (a line
  // search's shortened trial).
  void set_moved_configuration(const DegreesOfFreedom& dofs, std::vector<Vector3> x0, std::vector<Vector3> d0,
                               const Eigen::VectorXd& update) {
    moved(dofs, update, x0, d0);
    set_configuration(std::move(x0), std::move(d0));
  }

  // The tangent stiffness at the configuration (x0, d0) applied to v, K v
  // with K = −∂r/∂q in `dofs`: difference_product (statics/coupling.hpp,
  // two force evaluations) with the steps of the assembled tangent, the
  // configuration moved by ±h v as apply_update moves it. The solver is left
  // in a moved configuration: the caller sets the one it wants afterwards.
  Eigen::VectorXd tangent_product(const DegreesOfFreedom& dofs, const std::vector<Vector3>& x0,
                                  const std::vector<Vector3>& d0, const Eigen::VectorXd& v) {
    return difference_product(
        v, [&](Eigen::Index k) { return step_of(dofs, static_cast<int>(k)); },
        [&](const Eigen::VectorXd& update) {
          set_moved_configuration(dofs, x0, d0, update);
          return Eigen::VectorXd(-residual(dofs, 0.0));
        });
  }

  // Each particle's translation and director rotation in a vector of the
  // degrees of freedom (a mode).
  void split(const DegreesOfFreedom& dofs, const Eigen::VectorXd& values, std::vector<Vector3>& translation,
             std::vector<Vector3>& rotation) const {
    translation.assign(dofs.first.size() - 1, Vector3::Zero());
    rotation.assign(dofs.first.size() - 1, Vector3::Zero());
    for (std::size_t i = 0; i + 1 < dofs.first.size(); ++i)
      for (int k = dofs.first[i]; k < dofs.first[i + 1]; ++k)
        (dofs.is_rotation[k] ? rotation[i] : translation[i]) += values[k] * dofs.direction[k];
  }

  // Sets a configuration, counted as one force evaluation.
  void set_configuration(std::vector<Vector3> x, std::vector<Vector3> d) {
    solver_.set_configuration(std::move(x), std::move(d));
    ++report_.force_evaluations;
  }
  // A configuration the solver held (its positions() and directors()), put
  // back bit for bit (Solver::restore_configuration).
  void restore_configuration(std::vector<Vector3> x, std::vector<Vector3> d) {
    solver_.restore_configuration(std::move(x), std::move(d));
    ++report_.force_evaluations;
  }

 private:
  double step_of(const DegreesOfFreedom& dofs, int k) const {
    return dofs.is_rotation[k] ? steps_.rotation : translation_step_;
  }

  // x and d moved by an update in the degrees of freedom (see apply_update).
  static void moved(const DegreesOfFreedom& dofs, const Eigen::VectorXd& update, std::vector<Vector3>& x,
                    std::vector<Vector3>& d) {
    const int n = static_cast<int>(x.size());
    for (int i = 0; i < n; ++i) {
      Vector3 rotation = Vector3::Zero();
      for (int k = dofs.first[i]; k < dofs.first[i + 1]; ++k) {
        if (dofs.is_rotation[k])
          rotation += update[k] * dofs.direction[k];
        else
          x[i] += update[k] * dofs.direction[k];
      }
      const double angle = rotation.norm();
      if (angle > 0.0) d[i] = Eigen::AngleAxisd(angle, rotation / angle) * d[i];
    }
  }

  // Moves particle i by degree of freedom k's amount `amount`.
  static void move(const DegreesOfFreedom& dofs, int k, double amount, Vector3& x, Vector3& d) {
    if (dofs.is_rotation[k])
      d = Eigen::AngleAxisd(amount, dofs.direction[k]) * d;
    else
      x += amount * dofs.direction[k];
  }

  // The coupling graph of the solver's own rows and its colours (every
  // point's support follows its own spacing, so a distance bound would have
  // to take the largest radius everywhere).
  void colour_particles() {
    using Approx = typename Solver::approximation_type;
    const ShellModel& model = solver_.model();
    const SolverOptions& options = solver_.options();
    const solver::IntegrationPoints<Approx> points(model, options.physics(), options.particle_integration(),
                                                   solver_.material().shear_modulus(),
                                                   solver_.material().poisson_ratio());
    coupling_ = coloured_coupling(points, model.particle_count(), steps_.one_particle_per_colour);
  }

  Solver& solver_;
  Conditions conditions_;
  TangentSteps steps_;
  double translation_step_ = 0.0;
  Coupling coupling_;
  NewtonReport report_;
  // The last LU factorisation of the tangent (see factorise).
  struct KeptFactorisation {
    SparseFactorisation<SparseMatrix> factorisation;
    DegreesOfFreedom dofs;
    bool valid = false;
  } kept_;
};

}  // namespace sphshell::statics
