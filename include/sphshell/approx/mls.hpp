#pragma once
// First-order moving least squares (basis 1, ξ1, ξ2) in the tangent plane of
// each evaluation point.
//
// Weights: w_j = V_j W(|x_j − x|, h) — the particle volume times the kernel.
// On uniform sheets this is the plain-kernel MLS up to a constant factor (which
// cancels); on graded or cut sheets it keeps a large particle from counting as
// much as a small one, and it makes the Shepard fallback and NSPH use the same
// Φ_j = V_j W_j / Σ V_k W_k.
//
// With the basis shifted to the evaluation point and scaled by h,
// p_j = (1, ξ_j1/h, ξ_j2/h), moment matrix M = Σ w_j p_j p_jᵀ and
// γ = M⁻¹ e₀, the shape functions are Φ_j = w_j γ·p_j. Their full derivative
// w.r.t. the evaluation point moving along e_α, with ∂p_j/∂x_α = −e_α/h and
// ∂M_α = Σ ∂w_jα p_j p_jᵀ − (e_α m₀ᵀ + m₀ e_αᵀ)/h (m₀ = M e₀), is
//   ∂Φ_j/∂x_α = w_j (∂γ_α·p_j − γ_α/h) + ∂w_jα γ·p_j,  ∂γ_α = −M⁻¹ ∂M_α γ,
// the derivative of the MLS approximant itself (not the "diffuse" derivative),
// so Σ Φ_j = 1, Σ ∇Φ_j = 0 and linear fields are reproduced with their exact
// gradient.

#include <sphshell/approx/approx.hpp>
#include <sphshell/approx/detail/row_builder.hpp>
#include <sphshell/kernel/kernel.hpp>

#include <cmath>
#include <vector>

namespace sphshell::approx {

template <class Kernel>
struct MLS {
  static_assert(kernel::check_kernel<Kernel>());
  using kernel_type = Kernel;

  template <class Visible = AlwaysVisible>
  static ShapeFunctions build(const std::vector<Vector3>& particles,
                              const std::vector<double>& particle_volumes,
                              const std::vector<Vector3>& eval_positions,
                              const std::vector<TangentFrame>& eval_frames, double h,
                              Visible visible = {}) {
    return detail::build_all<Kernel, MLS>(particles, particle_volumes, eval_positions,
                                          eval_frames, h, visible);
  }

  // One smoothing length per evaluation point (the solver's local support).
  template <class Visible = AlwaysVisible>
  static ShapeFunctions build(const std::vector<Vector3>& particles,
                              const std::vector<double>& particle_volumes,
                              const std::vector<Vector3>& eval_positions,
                              const std::vector<TangentFrame>& eval_frames, const std::vector<double>& h,
                              Visible visible = {}) {
    return detail::build_all<Kernel, MLS>(particles, particle_volumes, eval_positions,
                                          eval_frames, h, visible);
  }

  template <class Visible>
  static void rebuild_row(ShapeFunctions& sf, std::size_t row,
                          const std::vector<Vector3>& particles,
                          const std::vector<double>& particle_volumes,
                          const Vector3& eval_position, const TangentFrame& eval_frame, double h,
                          Visible visible) {
    detail::rebuild_one_row<Kernel, MLS>(sf, row, particles, particle_volumes, eval_position,
                                         eval_frame, h, visible);
  }

  // Moment matrices below this relative determinant (det M / Π M_kk, which is
  // 1 for a diagonal matrix and 0 for collinear neighbours) are treated as
  // singular: the row falls back to Shepard.
  static constexpr double singular_tolerance = 1e-10;

  static bool solve(const detail::RowWorkspace& ws, double h, double* phi, double* dphi_d1,
                    double* dphi_d2) {
    const double inverse_h = 1.0 / h;
    // The three matrices are symmetric: accumulate their six distinct entries
    // (1, a, b, a², ab, b² times each weight). Plain arrays measured ~12 %
    // faster here than Eigen 6-vectors.
    double m[6] = {0, 0, 0, 0, 0, 0};
    double d1[6] = {0, 0, 0, 0, 0, 0};
    double d2[6] = {0, 0, 0, 0, 0, 0};
    for (std::size_t k = 0; k < ws.count; ++k) {
      const double a = ws.xi1[k] * inverse_h;
      const double b = ws.xi2[k] * inverse_h;
      const double outer[6] = {1.0, a, b, a * a, a * b, b * b};
      const double w = ws.weight[k], w1 = ws.dweight_d1[k], w2 = ws.dweight_d2[k];
      for (int e = 0; e < 6; ++e) {
        m[e] += w * outer[e];
        d1[e] += w1 * outer[e];
        d2[e] += w2 * outer[e];
      }
    }
    const auto symmetric = [](const double* e) {
      Matrix3 matrix;
      matrix << e[0], e[1], e[2], e[1], e[3], e[4], e[2], e[4], e[5];
      return matrix;
    };
    const Matrix3 moment = symmetric(m);
    Matrix3 dmoment_1 = symmetric(d1);
    Matrix3 dmoment_2 = symmetric(d2);
    const Vector3 m0 = moment.col(0);
    dmoment_1.row(1) -= inverse_h * m0.transpose();
    dmoment_1.col(1) -= inverse_h * m0;
    dmoment_2.row(2) -= inverse_h * m0.transpose();
    dmoment_2.col(2) -= inverse_h * m0;

    const double diagonal = moment(0, 0) * moment(1, 1) * moment(2, 2);
    const double determinant = moment.determinant();
    if (!(diagonal > 0.0) || !(determinant > singular_tolerance * diagonal)) return false;
    const Matrix3 inverse = moment.inverse();
    const Vector3 gamma = inverse.col(0);
    const Vector3 dgamma_1 = -inverse * (dmoment_1 * gamma);
    const Vector3 dgamma_2 = -inverse * (dmoment_2 * gamma);
    const double gamma_1 = gamma(1) * inverse_h;
    const double gamma_2 = gamma(2) * inverse_h;
    for (std::size_t k = 0; k < ws.count; ++k) {
      const Vector3 p(1.0, ws.xi1[k] * inverse_h, ws.xi2[k] * inverse_h);
      const double w = ws.weight[k];
      const double gamma_p = gamma.dot(p);
      phi[k] = w * gamma_p;
      dphi_d1[k] = w * (dgamma_1.dot(p) - gamma_1) + ws.dweight_d1[k] * gamma_p;
      dphi_d2[k] = w * (dgamma_2.dot(p) - gamma_2) + ws.dweight_d2[k] * gamma_p;
    }
    return true;
  }
};

}  // namespace sphshell::approx
