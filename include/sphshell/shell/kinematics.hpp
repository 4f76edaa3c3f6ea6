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

// Generalized stresses at an integration point, already multiplied by its
// integration weights: N, M conjugate to e, κ; Q conjugate to γ.
struct WeightedStresses {
  StressVoigt membrane;
  StressVoigt moment;
  Vector2 shear;
};

// Forces conjugate to a1, a2, n, n1, n2: the virtual work is
// δW = δa1·F_a1 + δa2·F_a2 + δn·F_n + δn1·F_n1 + δn2·F_n2.
struct ConjugateForces {
  Vector3 a1, a2, n, n1, n2;
};

// ---------------------------------------------------------------------------
// The same quantities at L points side by side (structure of arrays, a lane a
// point), so that the loops over the lanes below run in the vector registers
// of whatever instruction set the library is built for. Each formula is
// written once, for lane l; the functions of one point further down are the
// case L = 1. A lane computes exactly what the point alone would, operation
// for operation in the same order (Eigen's 3-vector dot product adds its
// three products from the first: (x0 y0 + x1 y1) + x2 y2), so without
// contracted multiply-adds the results agree bit for bit.

// N components of a vector at L points: component i of lane l at c[i][l].
// Wider groups are aligned for whole vector registers.
template <int N, int L>
struct ComponentLanes {
  alignas(L > 1 ? 64 : 8) double c[N][L];

  template <class Vector>
  void set(int l, const Vector& v) {
    for (int i = 0; i < N; ++i) c[i][l] = v[i];
  }
  Eigen::Matrix<double, N, 1> at(int l) const {
    Eigen::Matrix<double, N, 1> v;
    for (int i = 0; i < N; ++i) v[i] = c[i][l];
    return v;
  }
};
template <int L>
using Vector3Lanes = ComponentLanes<3, L>;
template <int L>
using Vector2Lanes = ComponentLanes<2, L>;

// x·y at lane l, in Eigen's order.
template <int L>
inline double dot_at(const Vector3Lanes<L>& x, const Vector3Lanes<L>& y, int l) {
  return x.c[0][l] * y.c[0][l] + x.c[1][l] * y.c[1][l] + x.c[2][l] * y.c[2][l];
}

template <int L>
struct SurfaceGradientLanes {
  Vector3Lanes<L> a1, a2, n, n1, n2;

  void set(int l, const SurfaceGradients& g) {
    a1.set(l, g.a1);
    a2.set(l, g.a2);
    n.set(l, g.n);
    n1.set(l, g.n1);
    n2.set(l, g.n2);
  }
  SurfaceGradients at(int l) const { return SurfaceGradients{a1.at(l), a2.at(l), n.at(l), n1.at(l), n2.at(l)}; }
};

template <int L>
struct ReferenceProductLanes {
  alignas(L > 1 ? 64 : 8) double a1a1[L], a2a2[L], a1a2[L], a1n1[L], a2n2[L], a1n2[L], a2n1[L], a1n[L], a2n[L];

  void set(int l, const ReferenceProducts& r) {
    a1a1[l] = r.a1a1;
    a2a2[l] = r.a2a2;
    a1a2[l] = r.a1a2;
    a1n1[l] = r.a1n1;
    a2n2[l] = r.a2n2;
    a1n2[l] = r.a1n2;
    a2n1[l] = r.a2n1;
    a1n[l] = r.a1n;
    a2n[l] = r.a2n;
  }
};

// Strains, strain increments, or the resultants conjugate to them (a
// membrane and a bending part in Voigt order, a transverse shear).
template <int L>
struct StrainLanes {
  Vector3Lanes<L> membrane, curvature;
  Vector2Lanes<L> shear;

  void set(int l, const Strains& s) {
    membrane.set(l, s.membrane);
    curvature.set(l, s.curvature);
    shear.set(l, s.shear);
  }
  Strains at(int l) const { return Strains{membrane.at(l), curvature.at(l), shear.at(l)}; }
};

template <int L>
using WeightedStressLanes = StrainLanes<L>;

template <int L>
using ConjugateForceLanes = SurfaceGradientLanes<L>;

// Green strains (nonlinear analysis) at every lane, from the reference's products.
template <int L>
inline void green_strains(const SurfaceGradientLanes<L>& g, const ReferenceProductLanes<L>& r, StrainLanes<L>& out) {
  // Formed in a local, which the inputs cannot alias, so that the loop vectorises.
  StrainLanes<L> s;
  for (int l = 0; l < L; ++l) {
    s.membrane.c[0][l] = 0.5 * (dot_at(g.a1, g.a1, l) - r.a1a1[l]);
    s.membrane.c[1][l] = 0.5 * (dot_at(g.a2, g.a2, l) - r.a2a2[l]);
    s.membrane.c[2][l] = dot_at(g.a1, g.a2, l) - r.a1a2[l];
    s.curvature.c[0][l] = dot_at(g.a1, g.n1, l) - r.a1n1[l];
    s.curvature.c[1][l] = dot_at(g.a2, g.n2, l) - r.a2n2[l];
    s.curvature.c[2][l] = dot_at(g.a1, g.n2, l) + dot_at(g.a2, g.n1, l) - r.a1n2[l] - r.a2n1[l];
    s.shear.c[0][l] = dot_at(g.a1, g.n, l) - r.a1n[l];
    s.shear.c[1][l] = dot_at(g.a2, g.n, l) - r.a2n[l];
  }
  out = s;
}

// Small-strain, small-rotation strains at every lane: the first-order part
// of green_strains in the displacement (a − A) and the director change (n − N).
template <int L>
inline void linear_strains(const SurfaceGradientLanes<L>& g, const SurfaceGradientLanes<L>& r, StrainLanes<L>& out) {
  StrainLanes<L> s;  // as in green_strains
  for (int l = 0; l < L; ++l) {
    // The reference's vectors at lane l, u_α = a_α − A_α and the changes of n, n_α.
    double A1[3], A2[3], N[3], N1[3], N2[3], u1[3], u2[3], dn[3], dn1[3], dn2[3];
    for (int i = 0; i < 3; ++i) {
      A1[i] = r.a1.c[i][l];
      A2[i] = r.a2.c[i][l];
      N[i] = r.n.c[i][l];
      N1[i] = r.n1.c[i][l];
      N2[i] = r.n2.c[i][l];
      u1[i] = g.a1.c[i][l] - A1[i];
      u2[i] = g.a2.c[i][l] - A2[i];
      dn[i] = g.n.c[i][l] - N[i];
      dn1[i] = g.n1.c[i][l] - N1[i];
      dn2[i] = g.n2.c[i][l] - N2[i];
    }
    const auto dot = [](const double* x, const double* y) { return x[0] * y[0] + x[1] * y[1] + x[2] * y[2]; };
    s.membrane.c[0][l] = dot(A1, u1);
    s.membrane.c[1][l] = dot(A2, u2);
    s.membrane.c[2][l] = dot(A1, u2) + dot(A2, u1);
    s.curvature.c[0][l] = dot(A1, dn1) + dot(u1, N1);
    s.curvature.c[1][l] = dot(A2, dn2) + dot(u2, N2);
    s.curvature.c[2][l] = dot(A1, dn2) + dot(u1, N2) + dot(A2, dn1) + dot(u2, N1);
    s.shear.c[0][l] = dot(A1, dn) + dot(u1, N);
    s.shear.c[1][l] = dot(A2, dn) + dot(u2, N);
  }
  out = s;
}

// The conjugate forces at every lane; `b` holds the vectors the strain
// variations are taken at: the current ones in the nonlinear analysis, the
// reference ones in the linear analysis.
template <int L>
inline void conjugate_forces(const SurfaceGradientLanes<L>& b, const WeightedStressLanes<L>& w,
                             ConjugateForceLanes<L>& out) {
  ConjugateForceLanes<L> f;  // as in green_strains
  for (int l = 0; l < L; ++l) {
    const double N0 = w.membrane.c[0][l], N1 = w.membrane.c[1][l], N2 = w.membrane.c[2][l];
    const double M0 = w.curvature.c[0][l], M1 = w.curvature.c[1][l], M2 = w.curvature.c[2][l];
    const double Q0 = w.shear.c[0][l], Q1 = w.shear.c[1][l];
    for (int i = 0; i < 3; ++i) {
      const double a1 = b.a1.c[i][l], a2 = b.a2.c[i][l], n = b.n.c[i][l], n1 = b.n1.c[i][l], n2 = b.n2.c[i][l];
      f.a1.c[i][l] = N0 * a1 + N2 * a2 + M0 * n1 + M2 * n2 + Q0 * n;
      f.a2.c[i][l] = N1 * a2 + N2 * a1 + M1 * n2 + M2 * n1 + Q1 * n;
      f.n1.c[i][l] = M0 * a1 + M2 * a2;
      f.n2.c[i][l] = M1 * a2 + M2 * a1;
      f.n.c[i][l] = Q0 * a1 + Q1 * a2;
    }
  }
  out = f;
}

// ---------------------------------------------------------------------------
// One point: the lanes' formulas at L = 1.

// Green strains (nonlinear analysis), from the reference's products.
inline Strains green_strains(const SurfaceGradients& g, const ReferenceProducts& r) {
  SurfaceGradientLanes<1> g1;
  ReferenceProductLanes<1> r1;
  StrainLanes<1> s1;
  g1.set(0, g);
  r1.set(0, r);
  green_strains(g1, r1, s1);
  return s1.at(0);
}

// Green strains (nonlinear analysis).
inline Strains green_strains(const SurfaceGradients& g, const SurfaceGradients& reference) {
  return green_strains(g, reference_products(reference));
}

// Small-strain, small-rotation strains.
inline Strains linear_strains(const SurfaceGradients& g, const SurfaceGradients& r) {
  SurfaceGradientLanes<1> g1, r1;
  StrainLanes<1> s1;
  g1.set(0, g);
  r1.set(0, r);
  linear_strains(g1, r1, s1);
  return s1.at(0);
}

inline ConjugateForces conjugate_forces(const SurfaceGradients& b, const WeightedStresses& w) {
  SurfaceGradientLanes<1> b1;
  WeightedStressLanes<1> w1;
  ConjugateForceLanes<1> f1;
  b1.set(0, b);
  w1.set(0, Strains{w.membrane, w.moment, w.shear});
  conjugate_forces(b1, w1, f1);
  const SurfaceGradients f = f1.at(0);
  return ConjugateForces{f.a1, f.a2, f.n, f.n1, f.n2};
}

}  // namespace sphshell::shell
