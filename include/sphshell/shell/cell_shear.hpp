#pragma once
// Transverse shear of a cell tied to its edges (an assumed natural strain, as
// in the MITC4 / MITC3 shell elements; docs/method.md §4, "Transverse shear
// tied to the cell edges").
//
// On each edge a → b of a stress point's cell the tangential shear strain is
//   e_ab = (x_b − x_a)·(d_a + d_b) / (2 ℓ_ab) − (the same in the reference),
// ℓ_ab the reference edge length: the component γ·t of γ_α = a_α·n − A_α·N
// (shell/kinematics.hpp) along the edge, with a_t the chord and n the mean of
// the two directors. Both are second-order accurate at the edge midpoint, so a
// smooth Kirchhoff motion (γ = 0) gives e = O(Δ²) on every edge, boundary
// edges included: the thin-plate constraint is met without locking. A rigid
// motion leaves every dot product unchanged, so it strains nothing.
//
// The cell's shear energy is integrated at its corners (the nodal rule of the
// bilinear field MITC4 interpolates): at corner k the two edges meeting there
// give the Cartesian shear γ_k = T_k⁻¹ (e_{k−1}, e_k), T_k the unit edge
// tangents in the stress point's tangent plane, and each corner carries
// κs G d A / m of the cell's area A (m = 3 or 4 corners):
//   Π_s = ½ Σ_k (κs G d A / m) |γ_k|² = ½ eᵀ C e,  C = Σ_k (κs G d A / m) P_kᵀ (T_k T_kᵀ)⁻¹ P_k.
// A uniform shear field is recovered exactly at every corner (the patch test),
// and every edge strain is penalised, so the checkerboard deflection that a
// one-point (cell-centre) shear cannot see has stiffness. Corner k couples
// only its two edges, k − 1 and k (mod m), so C is symmetric and cyclic
// tridiagonal: its diagonal and one coupling per corner hold all of it.

#include <sphshell/core/error.hpp>
#include <sphshell/core/frame.hpp>
#include <sphshell/core/types.hpp>

#include <Eigen/Dense>

#include <array>
#include <cmath>
#include <cstddef>
#include <string>
#include <vector>

namespace sphshell::shell {

inline constexpr int max_cell_corners = 4;
using CellEdgeVector = Eigen::Matrix<double, max_cell_corners, 1>;

// What is fixed about one cell's tied shear (reference configuration). Edge e
// runs from corner e to corner (e + 1) mod corners. CellShearTie is what both
// analyses read; CellShearEdges the reference edges, which only the linear
// form reads (a solver keeps them only for a linear analysis).
struct CellShearTie {
  int corners = 0;                                          // 3 or 4; 0: the cell is not tied
  std::array<int, max_cell_corners> particle{};             // corner particle indices
  std::array<double, max_cell_corners> inverse_length{};    // 1 / ℓ_ab
  std::array<double, max_cell_corners> reference_strain{};  // chord·normal_sum / (2ℓ)
  // C (N/m × m²: κs G d A per unit strain²): C_ee, and C_{k−1,k} = C_{k,k−1}
  // of the two edges that meet at corner k (k − 1 taken mod corners).
  std::array<double, max_cell_corners> diagonal{};
  std::array<double, max_cell_corners> coupling{};
};
struct CellShearEdges {
  CellShearEdges() {
    chord.fill(Vector3::Zero());  // Eigen vectors are not zeroed by {}
    normal_sum.fill(Vector3::Zero());
  }
  std::array<Vector3, max_cell_corners> chord;       // X_b − X_a
  std::array<Vector3, max_cell_corners> normal_sum;  // N_a + N_b
};
struct CellShearTying : CellShearTie, CellShearEdges {};

// Below this |sin| of the angle between a corner's two edges the cell is
// degenerate there (the corner cannot recover a Cartesian shear).
inline constexpr double degenerate_corner_sine = 1e-6;

// Ties the shear of a cell with the given corners (counter-clockwise), in the
// tangent frame of its stress point, with the shear stiffness per unit area
// κs G d (N/m) and the cell area A (m²).
inline CellShearTying tie_cell_shear(const int* corners, int corner_count, const std::vector<Vector3>& positions,
                                     const std::vector<Vector3>& normals, const TangentFrame& frame,
                                     double shear_stiffness, double area) {
  if (corner_count != 3 && corner_count != 4)
    detail::invalid_parameter("cell corner count", corner_count, "a tied shear needs 3 or 4 corners");
  CellShearTying tying;
  tying.corners = corner_count;
  std::array<Vector2, max_cell_corners> tangent;
  for (int e = 0; e < corner_count; ++e) {
    const int a = corners[e], b = corners[(e + 1) % corner_count];
    tying.particle[e] = a;
    tying.chord[e] = positions[b] - positions[a];
    tying.normal_sum[e] = normals[a] + normals[b];
    const double length = tying.chord[e].norm();
    tying.inverse_length[e] = 1.0 / length;
    tying.reference_strain[e] = tying.chord[e].dot(tying.normal_sum[e]) * 0.5 * tying.inverse_length[e];
    tangent[e] = Vector2(frame.e1.dot(tying.chord[e]), frame.e2.dot(tying.chord[e])).normalized();
  }
  const double corner_weight = shear_stiffness * area / corner_count;
  for (int k = 0; k < corner_count; ++k) {
    const int before = (k + corner_count - 1) % corner_count;
    const double cosine = tangent[before].dot(tangent[k]);
    const double sine_squared = 1.0 - cosine * cosine;
    if (!(sine_squared > degenerate_corner_sine * degenerate_corner_sine))
      detail::invalid_parameter("cell corner at particle " + std::to_string(corners[k]) + " edge angle sine",
                                std::sqrt(std::max(0.0, sine_squared)), "must not vanish (a degenerate cell)");
    // (T Tᵀ)⁻¹ for the unit tangents of the two edges: the inverse Gram matrix.
    const double scale = corner_weight / sine_squared;
    tying.diagonal[std::size_t(before)] += scale;
    tying.diagonal[std::size_t(k)] += scale;
    tying.coupling[std::size_t(k)] -= scale * cosine;
  }
  return tying;
}

// The energy ½ eᵀ C e of a tied cell and its forces on the corner particles:
// force[k] = ∂Π/∂x and director_force[k] = ∂Π/∂d of corner particle[k].
struct CellShearForces {
  CellShearForces() {
    force.fill(Vector3::Zero());
    director_force.fill(Vector3::Zero());
  }
  double energy = 0.0;
  std::array<Vector3, max_cell_corners> force;
  std::array<Vector3, max_cell_corners> director_force;
};

// The corner after corner k around a cell of `corners` corners: a compare,
// not (k + 1) % corners, whose integer division cost more than the rest of a
// cell's edge in the step's hot loop.
inline int next_corner(int k, int corners) { return k + 1 < corners ? k + 1 : 0; }
inline int previous_corner(int k, int corners) { return k > 0 ? k - 1 : corners - 1; }

// ∂Π/∂e = C e for a cell of a known corner count, each row's terms added in
// column order (the zeros of the edges that share no corner left out), the
// order of earlier versions' full-matrix product, so results match theirs.
// The entries past the corner count stay zero.
template <int Corners>
inline CellEdgeVector tied_edge_forces(const CellShearTie& t, const CellEdgeVector& strain) {
  CellEdgeVector edge_force = CellEdgeVector::Zero();
  for (int e = 0; e < Corners; ++e) {
    const int before = previous_corner(e, Corners), after = next_corner(e, Corners);
    double sum = 0.0;
    bool started = false;
    for (int k = 0; k < Corners; ++k) {
      if (k != e && k != before && k != after) continue;  // C_ek = 0
      const double c = k == e ? t.diagonal[std::size_t(e)]
                       : k == after ? t.coupling[std::size_t(after)]  // edges e and e + 1 meet at corner e + 1
                                    : t.coupling[std::size_t(e)];     // edges e − 1 and e at corner e
      sum = started ? sum + c * strain[k] : c * strain[k];
      started = true;
    }
    edge_force[e] = sum;
  }
  return edge_force;
}

// corner_shear_forces for a cell of a known corner count, so the edge loops
// unroll. The edges' chords and director sums are kept from the strains for
// the forces, and the forces are summed in locals and stored once (a store
// through the output pointers might alias the tying for all the compiler
// knows). The same operations in the same order as edge by edge.
template <int Corners, class CornerPosition, class CornerDirector>
inline double corner_shear_forces_of(const CellShearTie& t, const CellShearEdges* edges, const CornerPosition& x,
                                     const CornerDirector& d, bool nonlinear, Vector3* force, Vector3* director_force) {
  std::array<Vector3, Corners> chord, director_sum;
  CellEdgeVector strain = CellEdgeVector::Zero();
  for (int e = 0; e < Corners; ++e) {
    const int b = next_corner(e, Corners);
    chord[e] = x(b) - x(e);
    director_sum[e] = d(e) + d(b);
    const double value = nonlinear ? chord[e].dot(director_sum[e])
                                   : (chord[e] - edges->chord[e]).dot(edges->normal_sum[e]) +
                                         edges->chord[e].dot(director_sum[e] - edges->normal_sum[e]) +
                                         edges->chord[e].dot(edges->normal_sum[e]);
    strain[e] = value * 0.5 * t.inverse_length[e] - t.reference_strain[e];
  }
  const CellEdgeVector edge_force = tied_edge_forces<Corners>(t, strain);  // ∂Π/∂e
  std::array<Vector3, Corners> corner_force, corner_director_force;
  corner_force.fill(Vector3::Zero());
  corner_director_force.fill(Vector3::Zero());
  for (int e = 0; e < Corners; ++e) {
    const int b = next_corner(e, Corners);
    // ∂e/∂x_b = −∂e/∂x_a = (d_a + d_b)/(2ℓ), ∂e/∂d_a = ∂e/∂d_b = (x_b − x_a)/(2ℓ),
    // at the current vectors (nonlinear) or the reference ones (linear).
    const double factor = edge_force[e] * 0.5 * t.inverse_length[e];
    const Vector3 along_normal = factor * (nonlinear ? director_sum[e] : edges->normal_sum[e]);
    const Vector3 along_chord = factor * (nonlinear ? chord[e] : edges->chord[e]);
    corner_force[b] += along_normal;
    corner_force[e] -= along_normal;
    corner_director_force[e] += along_chord;
    corner_director_force[b] += along_chord;
  }
  for (int k = 0; k < Corners; ++k) {
    force[k] = corner_force[k];
    director_force[k] = corner_director_force[k];
  }
  return 0.5 * strain.dot(edge_force);
}

// The energy and the corner forces from the corners' positions x(k) and
// directors d(k), written into force and director_force (their first
// t.corners entries; nothing else is touched), of a tied cell (3 or 4
// corners). For the assembler, which keeps the forces per point and reads the
// corners from its packed kinematics.
// The reference edges are read only by the linear form (nonlinear false):
// edges may be null for the nonlinear one.
template <class CornerPosition, class CornerDirector>
inline double corner_shear_forces(const CellShearTie& t, const CellShearEdges* edges, const CornerPosition& x,
                                  const CornerDirector& d, bool nonlinear, Vector3* force, Vector3* director_force) {
  return t.corners == max_cell_corners
             ? corner_shear_forces_of<max_cell_corners>(t, edges, x, d, nonlinear, force, director_force)
             : corner_shear_forces_of<3>(t, edges, x, d, nonlinear, force, director_force);
}
template <class CornerPosition, class CornerDirector>
inline double corner_shear_forces(const CellShearTying& t, const CornerPosition& x, const CornerDirector& d,
                                  bool nonlinear, Vector3* force, Vector3* director_force) {
  return corner_shear_forces(t, &t, x, d, nonlinear, force, director_force);
}

inline CellShearForces cell_shear_forces(const CellShearTying& t, const std::vector<Vector3>& x,
                                         const std::vector<Vector3>& d, bool nonlinear) {
  CellShearForces out;
  if (t.corners == 0) return out;
  out.energy = corner_shear_forces(
      t, [&](int k) -> const Vector3& { return x[std::size_t(t.particle[std::size_t(k)])]; },
      [&](int k) -> const Vector3& { return d[std::size_t(t.particle[std::size_t(k)])]; }, nonlinear,
      out.force.data(), out.director_force.data());
  return out;
}

}  // namespace sphshell::shell
