#pragma once
// GMRES (Saad & Schultz, SIAM J. Sci. Stat. Comput. 7 (1986) 856–869) with
// right preconditioning, for the Newton steps of statics::PathFollower and
// Solver::solve_static: the current tangent is applied without being
// assembled (a central difference of the forces along a direction,
// difference_product of statics/coupling.hpp) and an
// older factorisation of it is the preconditioner, so a Newton iteration
// costs a few force evaluations and back substitutions instead of an
// assembly and a factorisation (docs/method.md, §11 "Path following").
//
// Right preconditioning (A M⁻¹ y = b, x = M⁻¹ y) keeps the residual GMRES
// minimises the true one, ‖b − A x‖, so the stopping test is on the
// quantity Newton needs.

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>
#include <vector>

namespace sphshell::statics {

// What one GMRES solve did.
struct KrylovSolve {
  int iterations = 0;           // products with the operator
  double relative_residual = 0; // ‖b − A x‖ / ‖b‖ as the Arnoldi process estimates it
  bool converged = false;       // relative_residual ≤ the tolerance asked
};

// Solves A x = b to ‖b − A x‖ ≤ tolerance ‖b‖ in at most max_iterations
// products (no restart: the caller falls back to a direct solve instead).
// apply(v) returns A v, precondition(v) returns M⁻¹ v. x is the best
// iterate found (zero when b is zero).
template <class Apply, class Precondition>
KrylovSolve gmres(Apply&& apply, Precondition&& precondition, const Eigen::VectorXd& b, double tolerance,
                  int max_iterations, Eigen::VectorXd& x) {
  KrylovSolve result;
  const Eigen::Index n = b.size();
  x = Eigen::VectorXd::Zero(n);
  const double beta = b.norm();
  if (!(beta > 0.0)) {
    result.converged = true;
    return result;
  }
  const int m = std::max(1, max_iterations);
  Eigen::MatrixXd basis(n, m + 1);                             // the Arnoldi vectors v_j
  Eigen::MatrixXd hessenberg = Eigen::MatrixXd::Zero(m + 1, m);  // reduced to upper triangular by the rotations
  Eigen::VectorXd cosines(m), sines(m), g = Eigen::VectorXd::Zero(m + 1);
  basis.col(0) = b / beta;
  g[0] = beta;
  int k = 0;
  double residual = beta;
  while (k < m) {
    Eigen::VectorXd w = apply(Eigen::VectorXd(precondition(Eigen::VectorXd(basis.col(k)))));
    // Modified Gram–Schmidt, twice where it lost most of w (a Krylov basis
    // nearly dependent on the earlier vectors).
    const double before = w.norm();
    for (int pass = 0; pass < 2; ++pass) {
      for (int j = 0; j <= k; ++j) {
        const double h = basis.col(j).dot(w);
        hessenberg(j, k) += h;
        w -= h * basis.col(j);
      }
      if (w.norm() > 0.5 * before) break;
    }
    const double next = w.norm();
    hessenberg(k + 1, k) = next;
    // The earlier rotations, then the one that zeroes H(k+1, k).
    for (int j = 0; j < k; ++j) {
      const double upper = cosines[j] * hessenberg(j, k) + sines[j] * hessenberg(j + 1, k);
      hessenberg(j + 1, k) = -sines[j] * hessenberg(j, k) + cosines[j] * hessenberg(j + 1, k);
      hessenberg(j, k) = upper;
    }
    const double radius = std::hypot(hessenberg(k, k), hessenberg(k + 1, k));
    cosines[k] = radius > 0.0 ? hessenberg(k, k) / radius : 1.0;
    sines[k] = radius > 0.0 ? hessenberg(k + 1, k) / radius : 0.0;
    hessenberg(k, k) = radius;
    hessenberg(k + 1, k) = 0.0;
    g[k + 1] = -sines[k] * g[k];
    g[k] = cosines[k] * g[k];
    ++k;
    residual = std::abs(g[k]);
    if (residual <= tolerance * beta || !(next > 0.0)) break;
    basis.col(k) = w / next;
  }
  // y from the triangular system, x = M⁻¹ V y.
  const Eigen::VectorXd y =
      hessenberg.topLeftCorner(k, k).triangularView<Eigen::Upper>().solve(g.head(k));
  x = precondition(Eigen::VectorXd(basis.leftCols(k) * y));
  result.iterations = k;
  result.relative_residual = residual / beta;
  result.converged = result.relative_residual <= tolerance;
  return result;
}

}  // namespace sphshell::statics
