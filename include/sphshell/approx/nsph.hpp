#pragma once
// Normalized SPH: Shepard-normalized kernel values with a Randles–Libersky
// corrected gradient.
//
// Φ_j = w_j / S with w_j = V_j W(|x_j − x|, h), S = Σ w_k. The gradient starts
// from the gradient of Φ_j itself, g_j = (∇w_j − Φ_j ∇S) / S — the kernel
// gradient minus Φ_j times the normalized-kernel mean ΣV_k∇W_k — so Σ g_j = 0
// (Randles–Libersky's ∇u ≈ Σ V_j (u_j − u_i) ∇W_j with u_i replaced by the
// Shepard value, which works at stress points where no u_i exists). The
// correction C = Σ_j g_j ξ_jᵀ (2×2, tangent plane) then gives ∇Φ_j = C⁻¹ g_j,
// so Σ ∇Φ_j u_j = b for every u = a + b·ξ and Σ ∇Φ_j = 0 exactly.
// Φ itself reproduces constants only (that is NSPH); use MLS for linear Φ.

#include <sphshell/approx/approx.hpp>
#include <sphshell/approx/detail/row_builder.hpp>
#include <sphshell/kernel/kernel.hpp>

#include <cmath>
#include <vector>

namespace sphshell::approx {

template <class Kernel>
struct NSPH {
  static_assert(kernel::check_kernel<Kernel>());
  using kernel_type = Kernel;

  template <class Visible = AlwaysVisible>
  static ShapeFunctions build(const std::vector<Vector3>& particles,
                              const std::vector<double>& particle_volumes,
                              const std::vector<Vector3>& eval_positions,
                              const std::vector<TangentFrame>& eval_frames, double h,
                              Visible visible = {}) {
    return detail::build_all<Kernel, NSPH>(particles, particle_volumes, eval_positions,
                                           eval_frames, h, visible);
  }

  // One smoothing length per evaluation point (the solver's local support).
  template <class Visible = AlwaysVisible>
  static ShapeFunctions build(const std::vector<Vector3>& particles,
                              const std::vector<double>& particle_volumes,
                              const std::vector<Vector3>& eval_positions,
                              const std::vector<TangentFrame>& eval_frames, const std::vector<double>& h,
                              Visible visible = {}) {
    return detail::build_all<Kernel, NSPH>(particles, particle_volumes, eval_positions,
                                           eval_frames, h, visible);
  }

  template <class Visible>
  static void rebuild_row(ShapeFunctions& sf, std::size_t row,
                          const std::vector<Vector3>& particles,
                          const std::vector<double>& particle_volumes,
                          const Vector3& eval_position, const TangentFrame& eval_frame, double h,
                          Visible visible) {
    detail::rebuild_one_row<Kernel, NSPH>(sf, row, particles, particle_volumes, eval_position,
                                          eval_frame, h, visible);
  }

  // C ≈ I for a well-spread neighbourhood; |det C| below this fraction of its
  // largest squared entry (collinear neighbours) means singular.
  static constexpr double singular_tolerance = 1e-10;

  static bool solve(const detail::RowWorkspace& ws, double /*h*/, double* phi, double* dphi_d1,
                    double* dphi_d2) {
    double sum = 0.0, dsum_1 = 0.0, dsum_2 = 0.0;
    for (std::size_t k = 0; k < ws.count; ++k) {
      sum += ws.weight[k];
      dsum_1 += ws.dweight_d1[k];
      dsum_2 += ws.dweight_d2[k];
    }
    const double inverse_sum = 1.0 / sum;
    Matrix2 correction = Matrix2::Zero();
    for (std::size_t k = 0; k < ws.count; ++k) {
      const double shape = ws.weight[k] * inverse_sum;
      const double g1 = (ws.dweight_d1[k] - shape * dsum_1) * inverse_sum;
      const double g2 = (ws.dweight_d2[k] - shape * dsum_2) * inverse_sum;
      phi[k] = shape;
      dphi_d1[k] = g1;
      dphi_d2[k] = g2;
      correction(0, 0) += g1 * ws.xi1[k];
      correction(0, 1) += g1 * ws.xi2[k];
      correction(1, 0) += g2 * ws.xi1[k];
      correction(1, 1) += g2 * ws.xi2[k];
    }
    const double scale = correction.cwiseAbs().maxCoeff();
    const double determinant = correction.determinant();
    if (!(std::abs(determinant) > singular_tolerance * scale * scale)) return false;
    const Matrix2 inverse = correction.inverse();
    for (std::size_t k = 0; k < ws.count; ++k) {
      const double g1 = dphi_d1[k];
      const double g2 = dphi_d2[k];
      dphi_d1[k] = inverse(0, 0) * g1 + inverse(0, 1) * g2;
      dphi_d2[k] = inverse(1, 0) * g1 + inverse(1, 1) * g2;
    }
    return true;
  }
};

}  // namespace sphshell::approx
