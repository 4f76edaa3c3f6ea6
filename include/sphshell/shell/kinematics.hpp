#pragma once
// Mindlin–Reissner shell kinematics at one integration point (stress point or
// particle), total Lagrangian (docs/method.md §3; the paper's eq. 2.1–2.5).
//
// A fibre at height ζ along the director sits at x(ζ) = x_m + ζ n. With the
// in-plane base vectors a_α = ∂x_m/∂X_α (X_α the reference tangent coordinates
// of the integration point) and n_α = ∂n/∂X_α, the Green strain, truncated
// linearly in ζ, is E(ζ) = e + ζ κ with
//   e_αβ = ½ (a_α·a_β − A_α·A_β),   κ_αβ = ½ (a_α·n_β + a_β·n_α) − (same in the reference),
// and the transverse shear is γ_α = a_α·n − A_α·N (eq. 2.2–2.4 in the
// reference frame). Dot products are invariant under rigid rotations, so any
// rigid motion creates no strain. The linear analysis (paper §3.1) keeps the
// first-order part of the same expressions around the reference configuration.
// Internal forces are the exact variations of these strains, so the discrete
// system is conservative for elastic materials and momentum conserving
// (Σ ∇Φ_j = 0).

#include <sphshell/core/types.hpp>

namespace sphshell::shell {

// Interpolated mid-surface quantities at an integration point.
struct SurfaceGradients {
  Vector3 a1 = Vector3::Zero();  // ∂x/∂X1
  Vector3 a2 = Vector3::Zero();  // ∂x/∂X2
  Vector3 n = Vector3::Zero();   // Σ Φ_j d_j
  Vector3 n1 = Vector3::Zero();  // ∂n/∂X1
  Vector3 n2 = Vector3::Zero();  // ∂n/∂X2
};

struct Strains {
  StrainVoigt membrane;   // (e11, e22, 2 e12)
  StrainVoigt curvature;  // (κ11, κ22, 2 κ12)
  Vector2 shear;          // (γ1, γ2)
};

// The reference configuration's dot products in the Green strains: fixed for
// a point (total Lagrangian), so a solver computes them once per point.
struct ReferenceProducts {
  double a1a1 = 0.0, a2a2 = 0.0, a1a2 = 0.0;              // A_α·A_β
  double a1n1 = 0.0, a2n2 = 0.0, a1n2 = 0.0, a2n1 = 0.0;  // A_α·N_β
  double a1n = 0.0, a2n = 0.0;                            // A_α·N
};

inline ReferenceProducts reference_products(const SurfaceGradients& r) {
  return ReferenceProducts{r.a1.dot(r.a1), r.a2.dot(r.a2), r.a1.dot(r.a2), r.a1.dot(r.n1), r.a2.dot(r.n2),
                           r.a1.dot(r.n2), r.a2.dot(r.n1), r.a1.dot(r.n),  r.a2.dot(r.n)};
}

// Green strains (nonlinear analysis), from the reference's products.
inline Strains green_strains(const SurfaceGradients& g, const ReferenceProducts& r) {
  Strains s;
  s.membrane = StrainVoigt(0.5 * (g.a1.dot(g.a1) - r.a1a1), 0.5 * (g.a2.dot(g.a2) - r.a2a2), g.a1.dot(g.a2) - r.a1a2);
  s.curvature = StrainVoigt(g.a1.dot(g.n1) - r.a1n1, g.a2.dot(g.n2) - r.a2n2,
                            g.a1.dot(g.n2) + g.a2.dot(g.n1) - r.a1n2 - r.a2n1);
  s.shear = Vector2(g.a1.dot(g.n) - r.a1n, g.a2.dot(g.n) - r.a2n);
  return s;
}

// Green strains (nonlinear analysis).
inline Strains green_strains(const SurfaceGradients& g, const SurfaceGradients& reference) {
  return green_strains(g, reference_products(reference));
}

// Small-strain, small-rotation strains: the first-order part of green_strains
// in the displacement (a − A) and the director change (n − N).
inline Strains linear_strains(const SurfaceGradients& g, const SurfaceGradients& r) {
  const Vector3 u1 = g.a1 - r.a1, u2 = g.a2 - r.a2;
  const Vector3 dn = g.n - r.n, dn1 = g.n1 - r.n1, dn2 = g.n2 - r.n2;
  Strains s;
  s.membrane = StrainVoigt(r.a1.dot(u1), r.a2.dot(u2), r.a1.dot(u2) + r.a2.dot(u1));
  s.curvature = StrainVoigt(r.a1.dot(dn1) + u1.dot(r.n1), r.a2.dot(dn2) + u2.dot(r.n2),
                            r.a1.dot(dn2) + u1.dot(r.n2) + r.a2.dot(dn1) + u2.dot(r.n1));
  s.shear = Vector2(r.a1.dot(dn) + u1.dot(r.n), r.a2.dot(dn) + u2.dot(r.n));
  return s;
}

// Generalized stresses at an integration point, already multiplied by its
// integration weights: N, M conjugate to e, κ; Q conjugate to γ.
struct WeightedStresses {
  StressVoigt membrane;
  StressVoigt moment;
  Vector2 shear;
};

// Forces conjugate to a1, a2, n, n1, n2: the virtual work is
// δW = δa1·F_a1 + δa2·F_a2 + δn·F_n + δn1·F_n1 + δn2·F_n2. `b` holds the
// vectors the strain variations are taken at: the current ones in the nonlinear
// analysis, the reference ones in the linear analysis.
struct ConjugateForces {
  Vector3 a1, a2, n, n1, n2;
};

inline ConjugateForces conjugate_forces(const SurfaceGradients& b, const WeightedStresses& w) {
  const StressVoigt& N = w.membrane;
  const StressVoigt& M = w.moment;
  ConjugateForces f;
  f.a1 = N[0] * b.a1 + N[2] * b.a2 + M[0] * b.n1 + M[2] * b.n2 + w.shear[0] * b.n;
  f.a2 = N[1] * b.a2 + N[2] * b.a1 + M[1] * b.n2 + M[2] * b.n1 + w.shear[1] * b.n;
  f.n1 = M[0] * b.a1 + M[2] * b.a2;
  f.n2 = M[1] * b.a2 + M[2] * b.a1;
  f.n = w.shear[0] * b.a1 + w.shear[1] * b.a2;
  return f;
}

}  // namespace sphshell::shell
