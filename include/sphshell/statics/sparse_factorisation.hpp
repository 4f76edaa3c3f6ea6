#pragma once
// The factorisation of a tangent stiffness that Newton's steps solve with:
// one part for the load-controlled static solve (statics/static_solve.hpp)
// and the path following's kept factorisation (statics/tangent.hpp).
//
//  - symmetric (the tangent of conservative loads on an elastic or
//    path-dependent law, symmetrised): Cholesky LLᵀ by CHOLMOD's supernodal
//    factorisation when the library was built with it (SPHSHELL_HAVE_CHOLMOD;
//    CMake option SPHSHELL_WITH_CHOLMOD, Debian libsuitesparse-dev) and the
//    tangent is positive definite, else Eigen's simplicial LDLᵀ (AMD
//    ordering), which also takes the indefinite tangents past a limit or
//    bifurcation point. Once a tangent has not been positive definite the
//    part goes to LDLᵀ at once, rather than pay a failed Cholesky per step.
//    On the 101 × 101 clamped plate (49,005 unknowns) the supernodal Cholesky
//    took 0.37 of the simplicial LDLᵀ's time and 0.80 of its factor entries
//    (docs/performance.md, "Static solutions").
//  - general (a tangent off equilibrium, or under follower loads): Eigen's
//    sparse LU (COLAMD ordering).
// factorise_tangent chooses between the two by the tangent's measured
// asymmetry (solve_static's Newton). The path following keeps the LU
// (factorise_general): on the pinched cylinder's octant (8,405 unknowns) its
// tangents turn indefinite within load steps, and the LU factorised and
// solved faster than the symmetric part's Cholesky or LDLᵀ
// (docs/performance-history.md).
// The fill-reducing ordering and the symbolic analysis depend on the pattern
// alone: they are redone only when the pattern changes, which gives the same
// numbers as a fresh factorisation (the pivoting is numeric).
//
// A class template (on the matrix type) so that it is compiled only in
// programs that factorise, as the rest of static_solve.hpp's sparse algebra.

#include <Eigen/Sparse>
#include <Eigen/SparseCholesky>
#include <Eigen/SparseLU>
#if defined(SPHSHELL_HAVE_CHOLMOD)
#include <Eigen/CholmodSupport>
#endif

#include <algorithm>
#include <limits>
#include <memory>
#include <string>
#include <vector>

namespace sphshell::statics {

// A tangent counts as symmetric when ‖K − Kᵀ‖_F is below this share of ‖K‖_F:
// the central differences leave an elastic tangent at equilibrium symmetric
// to their own error (3e-9 on the pinched cylinder's octant), while a tangent
// off equilibrium, of a path-dependent law or under follower loads differs
// from its transpose by far more. Newton on the symmetrised tangent of one
// that passes converges as on the tangent itself up to this share (one
// contraction by at most this factor per iteration, below the tolerances).
inline constexpr double symmetric_tangent_tolerance = 1e-4;

// Which factorisation holds the tangent.
enum class FactorisationMethod {
  none,                 // nothing factorised yet, or the last attempt failed
  cholmod_cholesky,     // CHOLMOD's supernodal LLᵀ (symmetric positive definite)
  simplicial_ldlt,      // Eigen's simplicial LDLᵀ (symmetric)
  lu                    // Eigen's sparse LU (general)
};

inline const char* to_string(FactorisationMethod method) {
  switch (method) {
    case FactorisationMethod::cholmod_cholesky: return "CHOLMOD supernodal Cholesky";
    case FactorisationMethod::simplicial_ldlt: return "simplicial LDLT";
    case FactorisationMethod::lu: return "sparse LU";
    case FactorisationMethod::none: break;
  }
  return "none";
}

// Whether this build factorises positive definite tangents by CHOLMOD.
inline constexpr bool cholmod_available =
#if defined(SPHSHELL_HAVE_CHOLMOD)
    true;
#else
    false;
#endif

template <class Matrix>
class SparseFactorisation {
 public:
  // Factorises a symmetric matrix (both triangles stored); false if it is
  // singular to the factorisation (a zero pivot).
  bool factorise_symmetric(const Matrix& symmetric) {
    method_ = FactorisationMethod::none;
    const bool same_pattern = remember_pattern(symmetric, Pattern::symmetric);
#if defined(SPHSHELL_HAVE_CHOLMOD)
    if (!indefinite_seen_) {
      if (!cholesky_) {
        cholesky_ = std::make_unique<Eigen::CholmodSupernodalLLT<Matrix>>();
        cholesky_->cholmod().print = 0;  // a tangent that is not positive definite is handled below, not printed
      }
      if (refactorise(*cholesky_, cholesky_analysed_, same_pattern, symmetric)) {
        method_ = FactorisationMethod::cholmod_cholesky;
        return true;
      }
      indefinite_seen_ = true;
    }
#endif
    if (!ldlt_) ldlt_ = std::make_unique<Eigen::SimplicialLDLT<Matrix, Eigen::Lower, Eigen::AMDOrdering<int>>>();
    if (!refactorise(*ldlt_, ldlt_analysed_, same_pattern, symmetric)) return false;
    method_ = FactorisationMethod::simplicial_ldlt;
    return true;
  }

  // Factorises a tangent: its symmetric part (factorise_symmetric) when it is
  // symmetric to symmetric_tangent_tolerance, else the tangent itself by LU;
  // false if the factorisation met a zero pivot.
  bool factorise_tangent(const Matrix& tangent) {
    const Matrix transpose = tangent.transpose();
    if ((tangent - transpose).norm() <= symmetric_tangent_tolerance * tangent.norm())
      return factorise_symmetric(Matrix(0.5 * (tangent + transpose)));
    return factorise_general(tangent);
  }

  // Factorises a general square matrix by LU; false if it met a zero pivot
  // (failure() says where).
  bool factorise_general(const Matrix& matrix) {
    method_ = FactorisationMethod::none;
    if (!lu_) lu_ = std::make_unique<Eigen::SparseLU<Matrix, Eigen::COLAMDOrdering<int>>>();
    if (!refactorise(*lu_, lu_analysed_, remember_pattern(matrix, Pattern::general), matrix)) return false;
    method_ = FactorisationMethod::lu;
    return true;
  }

  bool valid() const { return method_ != FactorisationMethod::none; }
  FactorisationMethod method() const { return method_; }
  Eigen::Index size() const { return size_; }
  // The LU's message after a failed factorise_general (empty otherwise).
  std::string failure() const { return lu_ && method_ == FactorisationMethod::none ? lu_->lastErrorMessage() : ""; }

  // The solutions for the columns of `rhs` (valid() required).
  Eigen::MatrixXd solve(const Eigen::MatrixXd& rhs) const {
    switch (method_) {
#if defined(SPHSHELL_HAVE_CHOLMOD)
      case FactorisationMethod::cholmod_cholesky: return cholesky_->solve(rhs);
#endif
      case FactorisationMethod::simplicial_ldlt: return ldlt_->solve(rhs);
      case FactorisationMethod::lu: return lu_->solve(rhs);
      default: break;
    }
    return Eigen::MatrixXd::Constant(rhs.rows(), rhs.cols(), std::numeric_limits<double>::quiet_NaN());
  }

 private:
  enum class Pattern { none, symmetric, general };
  // Factorises `matrix` by `factoriser`, analysing its pattern first unless
  // the factoriser has analysed this same pattern already; true on success.
  template <class Factoriser>
  static bool refactorise(Factoriser& factoriser, bool& analysed, bool same_pattern, const Matrix& matrix) {
    if (!same_pattern || !analysed) {
      factoriser.analyzePattern(matrix);
      analysed = true;
    }
    factoriser.factorize(matrix);
    return factoriser.info() == Eigen::Success;
  }
  // Records the pattern of `matrix`; true if it is the pattern (and kind)
  // analysed last.
  bool remember_pattern(const Matrix& matrix, Pattern kind) {
    size_ = matrix.rows();
    const bool same = pattern_ == kind && outer_.size() == static_cast<std::size_t>(matrix.outerSize() + 1) &&
                      inner_.size() == static_cast<std::size_t>(matrix.nonZeros()) &&
                      std::equal(outer_.begin(), outer_.end(), matrix.outerIndexPtr()) &&
                      std::equal(inner_.begin(), inner_.end(), matrix.innerIndexPtr());
    if (!same) {
      pattern_ = kind;
      outer_.assign(matrix.outerIndexPtr(), matrix.outerIndexPtr() + matrix.outerSize() + 1);
      inner_.assign(matrix.innerIndexPtr(), matrix.innerIndexPtr() + matrix.nonZeros());
      cholesky_analysed_ = ldlt_analysed_ = lu_analysed_ = false;
    }
    return same;
  }

  FactorisationMethod method_ = FactorisationMethod::none;
  Eigen::Index size_ = 0;
  Pattern pattern_ = Pattern::none;
  std::vector<typename Matrix::StorageIndex> outer_, inner_;
  bool cholesky_analysed_ = false, ldlt_analysed_ = false, lu_analysed_ = false;
  bool indefinite_seen_ = false;
#if defined(SPHSHELL_HAVE_CHOLMOD)
  std::unique_ptr<Eigen::CholmodSupernodalLLT<Matrix>> cholesky_;
#endif
  // Eigen's solvers can be neither copied nor moved: held by pointer.
  std::unique_ptr<Eigen::SimplicialLDLT<Matrix, Eigen::Lower, Eigen::AMDOrdering<int>>> ldlt_;
  std::unique_ptr<Eigen::SparseLU<Matrix, Eigen::COLAMDOrdering<int>>> lu_;
};

}  // namespace sphshell::statics
