#pragma once
// Linear buckling analysis: the load factors λ at which the tangent of the
// linear prebuckling state turns singular, (K₀ + λ K_σ) φ = 0, with K₀ the
// tangent stiffness at the reference state and K_σ the geometric stiffness of
// the reference load (the Conditions' forces and moments at λ = 1).
//
// K_σ is the derivative of the tangent along the linear prebuckling path
// u(λ) = λ K₀⁻¹ f, taken by the central difference
//   K_σ = (K(λ₀ u₁) − K(−λ₀ u₁)) / (2 λ₀),  u₁ = K₀⁻¹ f,
// whose error is O(λ₀²) (the even terms of the tangent along the path
// cancel), so the probe factor λ₀ may be small without the differencing
// losing the stress's effect. The solver must be geometrically nonlinear:
// the linear theory's forces have no geometric stiffness.
//
// The eigenproblem is solved as −K_σ φ = μ K₀ φ, μ = 1/λ (K₀ positive
// definite once the conditions remove every rigid motion), by subspace
// iteration on K₀⁻¹(−K_σ) with one sparse LDLᵀ of K₀ and a Rayleigh–Ritz step
// in a block of vectors (Bathe, Finite Element Procedures, §11.6); it finds
// the μ of largest magnitude, i.e. the buckling factors nearest zero, and
// returns the lowest positive ones (negative ones buckle under the reversed
// load).

#include <sphshell/core/error.hpp>
#include <sphshell/statics/conditions.hpp>
#include <sphshell/statics/tangent.hpp>

#include <Eigen/Dense>
#include <Eigen/Eigenvalues>
#include <Eigen/SparseCholesky>

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

namespace sphshell::statics {

struct BucklingOptions {
  int modes = 1;                    // how many buckling factors (lowest positive first), >= 1
  double probe_load_factor = 1e-3;  // λ₀ of the prebuckling states ±λ₀ u₁, in (0, 1]
  double tolerance = 1e-10;         // relative change of every wanted μ between iterations, in (0, 1)
  int max_iterations = 300;         // subspace iterations, >= 1
  TangentSteps steps;               // the tangent's finite-difference steps
};

struct BucklingMode {
  double load_factor = 0.0;           // λ: the buckling load is λ times the reference load
  std::vector<Vector3> translation;   // per particle, scaled to a largest translation of 1
  std::vector<Vector3> rotation;      // per particle: the director's rotation vector (rad per unit of the mode)
};

struct BucklingResult {
  std::vector<BucklingMode> modes;  // lowest positive load factor first
  int iterations = 0;               // subspace iterations
  long force_evaluations = 0;       // the cost: three tangent assemblies and the prebuckling solve
};

namespace detail {

// The subspace's size: the wanted modes and a margin, so the convergence
// rate of mode i is |μ_{p+1} / μ_i| with p well above the wanted count.
inline int subspace_size(int modes, int dofs) { return std::min(dofs, std::max(2 * modes, modes + 8)); }

// K_σ below this fraction of K₀ (Frobenius norms) has no stress in it.
inline constexpr double least_geometric_stiffness = 1e-12;

// A block of vectors stored row by row, so that the p values of one degree of
// freedom lie together: the sparse products and triangular solves below take
// each stored entry once for the whole block (Eigen's take the matrix once per
// column of a column-major block).
using RowBlock = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;

// y = m x for a block x.
inline RowBlock block_product(const SparseMatrix& m, const RowBlock& x) {
  const Eigen::Index p = x.cols();
  RowBlock y = RowBlock::Zero(m.rows(), p);
  for (Eigen::Index j = 0; j < m.outerSize(); ++j) {
    const double* xj = x.data() + j * p;
    for (SparseMatrix::InnerIterator it(m, j); it; ++it) {
      double* yi = y.data() + it.index() * p;
      const double v = it.value();
      for (Eigen::Index c = 0; c < p; ++c) yi[c] += v * xj[c];
    }
  }
  return y;
}

// K⁻¹ b for a block b with the LDLᵀ of K (P K Pᵀ = L D Lᵀ, L unit lower
// triangular with its diagonal not stored): one pass over L forward, one
// backward.
template <class Ldlt>
RowBlock block_solve(const Ldlt& ldlt, const RowBlock& b) {
  const SparseMatrix& l = ldlt.matrixL().nestedExpression();
  const Eigen::VectorXd& d = ldlt.vectorD();
  RowBlock x = ldlt.permutationP() * b;
  const Eigen::Index p = x.cols();
  for (Eigen::Index j = 0; j < l.outerSize(); ++j) {
    const double* xj = x.data() + j * p;
    for (SparseMatrix::InnerIterator it(l, j); it; ++it) {
      double* xi = x.data() + it.index() * p;
      const double v = it.value();
      for (Eigen::Index c = 0; c < p; ++c) xi[c] -= v * xj[c];
    }
  }
  for (Eigen::Index j = 0; j < x.rows(); ++j) x.row(j) /= d[j];
  for (Eigen::Index j = l.outerSize() - 1; j >= 0; --j) {
    double* xj = x.data() + j * p;
    for (SparseMatrix::InnerIterator it(l, j); it; ++it) {
      const double* xi = x.data() + it.index() * p;
      const double v = it.value();
      for (Eigen::Index c = 0; c < p; ++c) xj[c] -= v * xi[c];
    }
  }
  return ldlt.permutationPinv() * x;
}

inline void check(const BucklingOptions& options) {
  if (options.modes < 1) sphshell::detail::invalid_parameter("BucklingOptions::modes", options.modes, "must be >= 1");
  sphshell::detail::require_half_open_interval("BucklingOptions::probe_load_factor", options.probe_load_factor, 0.0,
                                               1.0);
  sphshell::detail::require_open_interval("BucklingOptions::tolerance", options.tolerance, 0.0, 1.0);
  if (options.max_iterations < 1)
    sphshell::detail::invalid_parameter("BucklingOptions::max_iterations", options.max_iterations, "must be >= 1");
}

}  // namespace detail

// The lowest buckling factors and modes of the reference load `conditions`
// from the solver's current (unloaded) configuration, which is left as it was.
template <class Solver>
BucklingResult linear_buckling(Solver& solver, const Conditions& conditions, const BucklingOptions& options = {}) {
  detail::check(options);
  TangentAssembly<Solver> assembly(solver, conditions, options.steps);
  const DegreesOfFreedom dofs = assembly.degrees_of_freedom();
  const Eigen::VectorXd f = assembly.external_load(dofs);
  if (!(f.norm() > 0.0))
    sphshell::detail::invalid_parameter("Conditions force and moment (buckling reference load)", f.norm(),
                                        "the reference load must be non-zero on a free degree of freedom");
  const std::vector<Vector3> x_reference = solver.positions(), d_reference = solver.directors();
  BucklingResult result;
  try {
    const SparseMatrix k0 = symmetrised(assembly.tangent(dofs));
    Eigen::SimplicialLDLT<SparseMatrix> ldlt;
    factorise_checked(ldlt, k0, "at the buckling reference state");
    const Eigen::VectorXd u1 = ldlt.solve(f);
    SparseMatrix shifted[2];
    for (int side = 0; side < 2; ++side) {
      const double factor = side == 0 ? options.probe_load_factor : -options.probe_load_factor;
      assembly.apply_update(dofs, factor * u1);
      shifted[side] = assembly.tangent(dofs);
      assembly.set_configuration(x_reference, d_reference);
    }
    // A = −K_σ, symmetrised.
    const SparseMatrix a = symmetrised(SparseMatrix(shifted[1] - shifted[0])) / (2.0 * options.probe_load_factor);
    if (!(a.norm() > detail::least_geometric_stiffness * k0.norm()))
      sphshell::detail::invalid_parameter("solver (linear buckling)", "no geometric stiffness",
                                          "the solver must be geometrically nonlinear (SolverOptions::nonlinear)");
    const int n = dofs.count();
    const int p = detail::subspace_size(options.modes, n);
    detail::RowBlock x(n, p);
    for (int j = 0; j < p; ++j)
      for (int i = 0; i < n; ++i) x(i, j) = std::sin(1.0 + detail::start_vector_increment * (i + 1.0) * (j + 1.0));
    Eigen::VectorXd previous = Eigen::VectorXd::Constant(p, std::numeric_limits<double>::quiet_NaN());
    Eigen::VectorXd mu;
    detail::RowBlock vectors;
    // A x, carried from one iteration to the next: the Ritz vectors are
    // combinations of the block y, so A times them is the same combination of A y.
    detail::RowBlock ax = detail::block_product(a, x);
    bool converged = false;
    for (int iteration = 1; iteration <= options.max_iterations && !converged; ++iteration) {
      // y = K₀⁻¹ A x, so K₀ y = A x: the reduced K₀ is yᵀ A x.
      const detail::RowBlock y = detail::block_solve(ldlt, ax);
      const detail::RowBlock ay = detail::block_product(a, y);
      const Eigen::MatrixXd reduced_a = y.transpose() * ay, reduced_b = y.transpose() * ax;
      Eigen::GeneralizedSelfAdjointEigenSolver<Eigen::MatrixXd> ritz(0.5 * (reduced_a + reduced_a.transpose()),
                                                                    0.5 * (reduced_b + reduced_b.transpose()));
      if (ritz.info() != Eigen::Success)
        sphshell::detail::invalid_parameter("BucklingOptions (subspace)", p,
                                            "the Rayleigh-Ritz step failed: the block lost rank; ask for fewer modes");
      // Largest μ first: the lowest positive buckling factors.
      mu = ritz.eigenvalues().reverse();
      const Eigen::MatrixXd ritz_vectors = ritz.eigenvectors().rowwise().reverse();
      vectors = y * ritz_vectors;
      ax = ay * ritz_vectors;
      for (int j = 0; j < p; ++j) {
        const double scale = 1.0 / vectors.col(j).norm();
        ax.col(j) *= scale;
      }
      result.iterations = iteration;
      converged = true;
      for (int j = 0; j < options.modes; ++j)
        converged = converged && std::abs(mu[j] - previous[j]) <= options.tolerance * std::abs(mu[j]);
      previous = mu;
    }
    if (!converged)
      sphshell::detail::invalid_parameter("BucklingOptions::max_iterations", options.max_iterations,
                                          "the subspace iteration did not reach BucklingOptions::tolerance; raise it");
    for (int j = 0; j < options.modes; ++j) {
      if (!(mu[j] > 0.0)) break;  // the rest buckle under the reversed load only
      BucklingMode mode;
      mode.load_factor = 1.0 / mu[j];
      assembly.split(dofs, vectors.col(j), mode.translation, mode.rotation);
      double largest = 0.0;
      for (const Vector3& t : mode.translation) largest = std::max(largest, t.cwiseAbs().maxCoeff());
      if (largest > 0.0) {
        for (Vector3& t : mode.translation) t /= largest;
        for (Vector3& r : mode.rotation) r /= largest;
      }
      result.modes.push_back(std::move(mode));
    }
    if (result.modes.empty())
      sphshell::detail::invalid_parameter("Conditions force and moment (buckling reference load)", mu[0],
                                          "no positive buckling factor: the load buckles nothing (reverse it?)");
  } catch (...) {
    solver.set_configuration(x_reference, d_reference);
    throw;
  }
  result.force_evaluations = assembly.report().force_evaluations;
  return result;
}

}  // namespace sphshell::statics
