#pragma once
// The bending energy of a quadrilateral cell's director hourglass
// (docs/method.md §4, "The director hourglass").
//
// Neither integration group sees a director field that alternates from
// particle to particle: the MLS gradient of (−1)^(i+j) vanishes at every cell
// centre (the field is odd about it in both directions) and at every interior
// particle (even about it), and the edge-tied shear (shell/cell_shear.hpp)
// takes the mean director of an edge, which cancels. Such a field is a
// rotation of the directors against the surface, a transverse shear the
// continuum resists with κs G d; the discrete model holds it only through the
// one-sided supports at its edges. Under compression a shell then buckles into
// it (the pull-out cylinder of Sze, Liu & Lo 2004 at a quarter of its limit
// load).
//
// The cure is the bending energy the bilinear interpolation of the corner
// directors carries and the one-point rule misses. With the cell mapped to
// (ξ, η) ∈ [−1, 1]² (corners k = 0…3 counter-clockwise at (∓1, ∓1), (±1, ∓1)…),
//   d(ξ, η) = … + ξη h,  h = ¼ Σ_k s_k d_k,  s = (+1, −1, +1, −1),
// whose ξη part adds η h to ∂d/∂ξ and ξ h to ∂d/∂η. Its curvature, in the
// covariant components κ_αβ = ½ (x_,α·d_,β + x_,β·d_,α), is
//   κ = η [[g_ξ, ½g_η], [½g_η, 0]] + ξ [[0, ½g_ξ], [½g_ξ, g_η]],
//   g_α = x_,α·h − (the same in the reference),
// with x_,α the cell's tangents at its centre. Both parts are odd in ξ or η,
// so the cell centre sees none of it, and exactly integrated over the cell
// (∫η² dA = ∫ξ² dA = A/3, ∫ξη dA = 0 for any quadrilateral) the elastic
// bending energy is
//   Π_h = ½ (A/3) (κ_a : D : κ_a + κ_b : D : κ_b) = ½ gᵀ S g,
// D the section's elastic bending stiffness E d³/(12(1 − ν²)) [1 ν 0; ν 1 0;
// 0 0 (1 − ν)/2] on (κ11, κ22, 2κ12) in the stress point's tangent frame.
// Every coefficient is the cell's own; there is nothing to tune. On a cell
// that is not a parallelogram a linear field has a ξη part too, so h is taken
// with Flanagan & Belytschko's (1981) hourglass weights,
//   h = Σ_k γ_k d_k,  γ_k = ¼ [s_k − (Σ_j s_j X_j)·∇N_k],
// ∇N_k the bilinear shape functions' reference gradients at the centre: h
// vanishes for every linear director field (a uniform curvature strains
// nothing, the patch test), and γ_k = s_k/4 on a parallelogram. For a smooth
// field g = O(Δ²) (h is a second difference), so the term vanishes with the
// spacing. The g_α are dot products of current vectors: rigid
// motions strain nothing, and the forces (its exact derivatives) conserve
// linear and angular momentum.

#include <sphshell/core/error.hpp>
#include <sphshell/core/frame.hpp>
#include <sphshell/core/types.hpp>

#include <Eigen/Dense>

#include <array>
#include <cmath>
#include <string>
#include <vector>

namespace sphshell::shell {

inline constexpr int hourglass_corners = 4;
// Corner signs of the ξη mode, and the corners' ξ and η over 4 (the centre
// tangents x_,ξ = Σ_k (ξ_k/4) x_k and x_,η = Σ_k (η_k/4) x_k).
inline constexpr std::array<double, hourglass_corners> hourglass_sign{1.0, -1.0, 1.0, -1.0};
inline constexpr std::array<double, hourglass_corners> corner_xi_quarter{-0.25, 0.25, 0.25, -0.25};
inline constexpr std::array<double, hourglass_corners> corner_eta_quarter{-0.25, -0.25, 0.25, 0.25};

// What is fixed about one cell's hourglass term (reference configuration).
struct CellHourglass {
  std::array<double, hourglass_corners> weight{};      // γ_k
  Eigen::Matrix2d stiffness = Eigen::Matrix2d::Zero();  // S (N/m: bending stiffness × area / length⁴)
  Vector2 reference = Vector2::Zero();                  // (X_,ξ·H, X_,η·H)
  // The reference tangents and hourglass director, which only the linear
  // form reads.
  Vector3 tangent_xi = Vector3::Zero(), tangent_eta = Vector3::Zero(), director = Vector3::Zero();
};

// The hourglass term of a quadrilateral cell with corners (counter-clockwise)
// at reference positions and normals, in the tangent frame of its stress
// point, for a section of elastic bending stiffness E d³/(12(1 − ν²)) and
// Poisson ratio ν, of area A.
inline CellHourglass tie_cell_hourglass(const int* corners, const std::vector<Vector3>& positions,
                                        const std::vector<Vector3>& normals, const TangentFrame& frame,
                                        double bending_stiffness, double poisson_ratio, double area) {
  CellHourglass cell;
  Vector3 hourglass_position = Vector3::Zero();  // Σ_k s_k X_k
  for (int k = 0; k < hourglass_corners; ++k) {
    const Vector3& x = positions[std::size_t(corners[k])];
    cell.tangent_xi += corner_xi_quarter[std::size_t(k)] * x;
    cell.tangent_eta += corner_eta_quarter[std::size_t(k)] * x;
    hourglass_position += hourglass_sign[std::size_t(k)] * x;
  }
  // J maps natural to the frame's coordinates; a covariant tensor K becomes
  // J⁻ᵀ K J⁻¹ in the frame.
  Eigen::Matrix2d jacobian;
  jacobian << frame.e1.dot(cell.tangent_xi), frame.e1.dot(cell.tangent_eta), frame.e2.dot(cell.tangent_xi),
      frame.e2.dot(cell.tangent_eta);
  const double determinant = jacobian.determinant();
  if (!(std::abs(determinant) > 0.0) || !std::isfinite(determinant))
    detail::invalid_parameter("cell at particle " + std::to_string(corners[0]) + " Jacobian determinant", determinant,
                              "must not vanish (a degenerate cell)");
  const Eigen::Matrix2d inverse = jacobian.inverse();
  const Vector2 hourglass_in_frame(frame.e1.dot(hourglass_position), frame.e2.dot(hourglass_position));
  for (int k = 0; k < hourglass_corners; ++k) {
    // ∇N_k at the centre: J⁻ᵀ (ξ_k, η_k) / 4.
    const Vector2 gradient =
        inverse.transpose() * Vector2(corner_xi_quarter[std::size_t(k)], corner_eta_quarter[std::size_t(k)]);
    cell.weight[std::size_t(k)] = 0.25 * (hourglass_sign[std::size_t(k)] - hourglass_in_frame.dot(gradient));
    cell.director += cell.weight[std::size_t(k)] * normals[std::size_t(corners[k])];
  }
  cell.reference = Vector2(cell.tangent_xi.dot(cell.director), cell.tangent_eta.dot(cell.director));
  Eigen::Matrix3d section;
  section << 1.0, poisson_ratio, 0.0, poisson_ratio, 1.0, 0.0, 0.0, 0.0, 0.5 * (1.0 - poisson_ratio);
  section *= bending_stiffness;
  // The curvature per unit g_ξ and g_η of each odd part, in Voigt form.
  const auto voigt = [&](const Eigen::Matrix2d& covariant) {
    const Eigen::Matrix2d k = inverse.transpose() * covariant * inverse;
    return Eigen::Vector3d(k(0, 0), k(1, 1), 2.0 * k(0, 1));
  };
  Eigen::Matrix<double, 3, 2> along_eta, along_xi;  // κ_a (the η part) and κ_b (the ξ part)
  Eigen::Matrix2d unit;
  unit << 1.0, 0.0, 0.0, 0.0;
  along_eta.col(0) = voigt(unit);
  unit << 0.0, 0.5, 0.5, 0.0;
  along_eta.col(1) = voigt(unit);
  along_xi.col(0) = voigt(unit);
  unit << 0.0, 0.0, 0.0, 1.0;
  along_xi.col(1) = voigt(unit);
  cell.stiffness =
      (area / 3.0) * (along_eta.transpose() * section * along_eta + along_xi.transpose() * section * along_xi);
  return cell;
}

// Adds the hourglass term's forces on the corners (force[k] += ∂Π/∂x and
// director_force[k] += ∂Π/∂d of corner k) from their positions x(k) and
// directors d(k); returns its energy. The linear form (nonlinear false) keeps
// the first-order part of g about the reference and the reference vectors in
// its derivatives.
template <class CornerPosition, class CornerDirector>
inline double add_hourglass_forces(const CellHourglass& cell, const CornerPosition& x, const CornerDirector& d,
                                   bool nonlinear, Vector3* force, Vector3* director_force) {
  Vector3 tangent_xi = Vector3::Zero(), tangent_eta = Vector3::Zero(), director = Vector3::Zero();
  for (int k = 0; k < hourglass_corners; ++k) {
    tangent_xi += corner_xi_quarter[std::size_t(k)] * x(k);
    tangent_eta += corner_eta_quarter[std::size_t(k)] * x(k);
    director += cell.weight[std::size_t(k)] * d(k);
  }
  Vector2 strain;
  if (nonlinear) {
    strain = Vector2(tangent_xi.dot(director), tangent_eta.dot(director)) - cell.reference;
  } else {
    strain = Vector2((tangent_xi - cell.tangent_xi).dot(cell.director) + cell.tangent_xi.dot(director - cell.director),
                     (tangent_eta - cell.tangent_eta).dot(cell.director) +
                         cell.tangent_eta.dot(director - cell.director));
  }
  const Vector2 conjugate = cell.stiffness * strain;  // ∂Π/∂g
  const Vector3& h = nonlinear ? director : cell.director;
  const Vector3 along_tangents = conjugate[0] * (nonlinear ? tangent_xi : cell.tangent_xi) +
                                 conjugate[1] * (nonlinear ? tangent_eta : cell.tangent_eta);
  for (int k = 0; k < hourglass_corners; ++k) {
    force[k] += (conjugate[0] * corner_xi_quarter[std::size_t(k)] + conjugate[1] * corner_eta_quarter[std::size_t(k)]) * h;
    director_force[k] += cell.weight[std::size_t(k)] * along_tangents;
  }
  return 0.5 * strain.dot(conjugate);
}

}  // namespace sphshell::shell
