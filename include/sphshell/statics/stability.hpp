#pragma once
// The stability of a static state, for telling where a path turns unstable (a
// bifurcation, or a limit point of the load): the number of negative
// eigenvalues of the symmetrised tangent stiffness, read off the signs of its
// LDLᵀ pivots (Sylvester's law of inertia), and its eigenvalue nearest zero
// by inverse iteration on the same factorisation. The eigenvalue mixes N/m
// and N·m/rad: compare it along one path, not across models.

#include <sphshell/core/error.hpp>
#include <sphshell/statics/tangent.hpp>

#include <Eigen/SparseCholesky>

#include <cmath>
#include <vector>

namespace sphshell::statics {

struct Stability {
  int negative_eigenvalues = 0;
  double eigenvalue_nearest_zero = 0.0;
  // Its mode: |φ · f| / (‖φ‖ ‖f‖) with the load f (near 0 at a bifurcation,
  // not at a limit point of the load), and each particle's translation in it.
  double load_share = 0.0;
  std::vector<Vector3> mode;
  std::vector<Vector3> mode_rotation;  // each director's rotation vector in it (rad per unit of the mode)
};

namespace detail {
// Inverse iterations for the eigenvalue nearest zero: the error falls by
// |μ₁/μ₂| per iteration (μ the eigenvalues nearest zero).
inline constexpr int stability_inverse_iterations = 60;
}  // namespace detail

// The stability of the solver's current state (the configuration is left as it was).
template <class Solver>
Stability stability(TangentAssembly<Solver>& assembly) {
  const DegreesOfFreedom dofs = assembly.degrees_of_freedom();
  const SparseMatrix symmetric = symmetrised(assembly.tangent(dofs));
  Eigen::SimplicialLDLT<SparseMatrix> ldlt(symmetric);
  if (ldlt.info() != Eigen::Success)
    sphshell::detail::invalid_parameter("state (stability)", "a zero pivot",
                                        "the symmetrised tangent must have no exactly zero pivot");
  Stability result;
  for (Eigen::Index i = 0; i < ldlt.vectorD().size(); ++i)
    if (ldlt.vectorD()[i] < 0.0) ++result.negative_eigenvalues;
  Eigen::VectorXd x(symmetric.rows());
  for (Eigen::Index i = 0; i < x.size(); ++i)
    x[i] = std::sin(1.0 + detail::start_vector_increment * static_cast<double>(i));
  x.normalize();
  for (int iteration = 0; iteration < detail::stability_inverse_iterations; ++iteration)
    x = ldlt.solve(x).normalized();
  result.eigenvalue_nearest_zero = x.dot(symmetric * x);
  const Eigen::VectorXd f = assembly.external_load(dofs);
  result.load_share = f.norm() > 0.0 ? std::abs(x.dot(f)) / f.norm() : 0.0;
  assembly.split(dofs, x, result.mode, result.mode_rotation);
  return result;
}

}  // namespace sphshell::statics
