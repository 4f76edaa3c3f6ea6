// The director hourglass of a quadrilateral cell (shell/cell_hourglass.hpp;
// docs/method.md §4, "The director hourglass"): its energy against an
// independent quadrature of the bilinear director field's bending, the patch
// test on a skewed quad, objectivity, its forces against the derivative of its
// energy. (The spurious mode it removes: test_validation_benchmarks.)
#include <sphshell/core/frame.hpp>
#include <sphshell/core/types.hpp>
#include <sphshell/shell/cell_hourglass.hpp>

#include <catch2/catch.hpp>

#include <Eigen/Dense>

#include <algorithm>
#include <array>
#include <cmath>
#include <random>
#include <utility>
#include <vector>

using namespace sphshell;

namespace {

constexpr double E = 210e9, nu = 0.3, thickness = 0.004;
const double bending_stiffness = E * thickness * thickness * thickness / (12.0 * (1.0 - nu * nu));

struct QuadCell {
  std::vector<Vector3> x, d;
  std::array<int, 4> corners{0, 1, 2, 3};
  double area;
};
// Flat cells in z = 0, normals +z; a parallelogram and a general quad.
QuadCell make_quad(const std::vector<Vector3>& x) {
  QuadCell q;
  q.x = x;
  q.d.assign(4, Vector3::UnitZ());
  q.area = 0.5 * (x[2] - x[0]).cross(x[3] - x[1]).norm();
  return q;
}
QuadCell parallelogram() {
  return make_quad({Vector3(0, 0, 0), Vector3(0.010, 0.002, 0), Vector3(0.013, 0.011, 0), Vector3(0.003, 0.009, 0)});
}
QuadCell skewed() {
  return make_quad({Vector3(0, 0, 0), Vector3(0.010, 0.001, 0), Vector3(0.013, 0.011, 0), Vector3(0.002, 0.008, 0)});
}
shell::CellHourglass tie(const QuadCell& q) {
  return shell::tie_cell_hourglass(q.corners.data(), q.x, q.d, tangent_frame(Vector3::UnitZ()), bending_stiffness, nu,
                                   q.area);
}

struct Forces {
  double energy = 0.0;
  std::vector<Vector3> force, director_force;
};
Forces hourglass_forces(const shell::CellHourglass& cell, const std::vector<Vector3>& x, const std::vector<Vector3>& d,
                        bool nonlinear) {
  Forces f;
  f.force.assign(4, Vector3::Zero());
  f.director_force.assign(4, Vector3::Zero());
  f.energy = shell::add_hourglass_forces(
      cell, [&](int k) -> const Vector3& { return x[std::size_t(k)]; },
      [&](int k) -> const Vector3& { return d[std::size_t(k)]; }, nonlinear, f.force.data(), f.director_force.data());
  return f;
}

// The bending energy of the bilinear director field's part that the cell
// centre does not see, integrated independently: the field interpolated from
// the corners, its gradient with the exact (here constant) Jacobian at 3 × 3
// Gauss points, minus the gradient at the centre; κ_αβ = sym(∂d_α/∂X_β) of a
// flat plate in the linear theory.
double bilinear_hourglass_energy(const QuadCell& q, const std::vector<Vector3>& d) {
  const std::array<double, 4> xi{-1, 1, 1, -1}, eta{-1, -1, 1, 1};
  const auto gradient_at = [&](double s, double t) {
    Eigen::Matrix2d dx = Eigen::Matrix2d::Zero(), dd = Eigen::Matrix2d::Zero();  // ∂(x, y)/∂(ξ, η), ∂(d_x, d_y)/∂(ξ, η)
    for (int k = 0; k < 4; ++k) {
      const double dn_ds = 0.25 * xi[k] * (1 + eta[k] * t), dn_dt = 0.25 * eta[k] * (1 + xi[k] * s);
      for (int a = 0; a < 2; ++a) {
        dx(a, 0) += dn_ds * q.x[k][a], dx(a, 1) += dn_dt * q.x[k][a];
        dd(a, 0) += dn_ds * d[k][a], dd(a, 1) += dn_dt * d[k][a];
      }
    }
    return std::make_pair(Eigen::Matrix2d(dd * dx.inverse()), dx.determinant());  // ∂d_α/∂X_β, det J
  };
  const Eigen::Matrix2d centre = gradient_at(0, 0).first;
  const double g = std::sqrt(0.6);
  const std::array<double, 3> point{-g, 0.0, g}, weight{5.0 / 9, 8.0 / 9, 5.0 / 9};
  double energy = 0.0;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) {
      const auto [gradient, jacobian] = gradient_at(point[i], point[j]);
      const Eigen::Matrix2d k = gradient - centre;
      const double k11 = k(0, 0), k22 = k(1, 1), k12 = 0.5 * (k(0, 1) + k(1, 0));
      const double density = 0.5 * bending_stiffness *
                             (k11 * k11 + k22 * k22 + 2 * nu * k11 * k22 + 2 * (1 - nu) * k12 * k12);
      energy += weight[i] * weight[j] * jacobian * density;
    }
  return energy;
}

}  // namespace

TEST_CASE("Director hourglass: the energy of the bilinear field's xi-eta part, integrated exactly",
          "[solver][hourglass]") {
  const QuadCell q = parallelogram();
  const shell::CellHourglass cell = tie(q);
  // Small tilts: a pure hourglass pattern, and a pattern with linear parts too
  // (which the centre sees, and this term must not).
  const std::vector<std::vector<Vector2>> tilts{
      {Vector2(1e-3, 0), Vector2(-1e-3, 0), Vector2(1e-3, 0), Vector2(-1e-3, 0)},
      {Vector2(0, 2e-3), Vector2(0, -2e-3), Vector2(0, 2e-3), Vector2(0, -2e-3)},
      {Vector2(3e-4, -1e-3), Vector2(-2e-3, 4e-4), Vector2(1.5e-3, 7e-4), Vector2(-5e-4, -2e-3)}};
  for (const std::vector<Vector2>& tilt : tilts) {
    std::vector<Vector3> d = q.d;
    for (int k = 0; k < 4; ++k) d[k] += Vector3(tilt[k].x(), tilt[k].y(), 0.0);
    const double exact = bilinear_hourglass_energy(q, d);
    REQUIRE(exact > 0.0);
    CHECK(hourglass_forces(cell, q.x, d, false).energy == Approx(exact).epsilon(1e-10));
    // The nonlinear form on unit directors: the same to second order in the tilt.
    for (Vector3& director : d) director.normalize();
    CHECK(hourglass_forces(cell, q.x, d, true).energy == Approx(exact).epsilon(1e-4));
  }
}

TEST_CASE("Director hourglass: a linear director field strains nothing, on a skewed quad too", "[solver][hourglass][patch]") {
  for (const QuadCell& q : {parallelogram(), skewed()}) {
    const shell::CellHourglass cell = tie(q);
    // d = N + G X: a uniform curvature, which the stress point integrates.
    Eigen::Matrix2d G;
    G << 0.3, -0.7, 0.2, 0.5;
    std::vector<Vector3> d = q.d;
    for (int k = 0; k < 4; ++k) {
      const Vector2 tilt = G * Vector2(q.x[k].x(), q.x[k].y());
      d[k] += Vector3(tilt.x(), tilt.y(), 0.0);
    }
    // A 1e-3 hourglass tilt would hold about ½ D (1e-3 / Δ)² A.
    const double scale = 0.5 * bending_stiffness * 1e-6 / q.area * q.area;
    CHECK(std::abs(hourglass_forces(cell, q.x, d, false).energy) < 1e-20 * scale);
    CHECK(std::abs(hourglass_forces(cell, q.x, d, true).energy) < 1e-20 * scale);
    // The same field plus an alternating tilt is not free.
    for (int k = 0; k < 4; ++k) d[k].x() += (k % 2 == 0 ? 1e-3 : -1e-3);
    CHECK(hourglass_forces(cell, q.x, d, false).energy > 1e-3 * scale);
  }
}

TEST_CASE("Director hourglass: a rigid rotation strains nothing, the forces are the energy gradient and balance",
          "[solver][hourglass][objectivity]") {
  std::mt19937 random(5);
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  for (const QuadCell& q : {parallelogram(), skewed()}) {
    const shell::CellHourglass cell = tie(q);
    const Eigen::AngleAxisd rotation(1.1, Vector3(0.3, -0.5, 0.8).normalized());
    std::vector<Vector3> x = q.x, d = q.d;
    for (int k = 0; k < 4; ++k) {
      x[k] = rotation * x[k] + Vector3(0.1, -0.2, 0.05);
      d[k] = rotation * d[k];
    }
    const double scale = 0.5 * bending_stiffness * 1e-6;
    CHECK(std::abs(hourglass_forces(cell, x, d, true).energy) < 1e-12 * scale);
    for (int k = 0; k < 4; ++k) {
      x[k] += 1e-4 * Vector3(uniform(random), uniform(random), uniform(random));
      d[k] = (d[k] + 0.05 * Vector3(uniform(random), uniform(random), uniform(random))).normalized();
    }
    for (bool nonlinear : {true, false}) {
      const Forces f = hourglass_forces(cell, x, d, nonlinear);
      REQUIRE(f.energy > 0.0);
      double force_scale = 0.0, director_scale = 0.0;
      Vector3 total = Vector3::Zero();
      for (int k = 0; k < 4; ++k) {
        force_scale = std::max(force_scale, f.force[k].norm());
        director_scale = std::max(director_scale, f.director_force[k].norm());
        total += f.force[k];
      }
      CHECK(total.norm() <= 1e-12 * force_scale);  // linear momentum (the linear form on a flat cell: no force at all)
      if (nonlinear) {  // angular momentum: Σ x × f + d × g = 0 for a rotation-invariant energy
        Vector3 moment = Vector3::Zero();
        for (int k = 0; k < 4; ++k) moment += x[k].cross(f.force[k]) + d[k].cross(f.director_force[k]);
        CHECK(moment.norm() < 1e-10 * (force_scale * 0.1 + director_scale));
      }
      const double h = 1e-7;
      for (int i = 0; i < 4; ++i)
        for (int k = 0; k < 3; ++k) {
          auto energy_at = [&](std::vector<Vector3>& v, double step) {
            const double kept = v[i][k];
            v[i][k] = kept + step;
            const double e = hourglass_forces(cell, x, d, nonlinear).energy;
            v[i][k] = kept;
            return e;
          };
          CHECK(f.force[i][k] == Approx((energy_at(x, h) - energy_at(x, -h)) / (2 * h)).margin(1e-6 * force_scale));
          CHECK(f.director_force[i][k] ==
                Approx((energy_at(d, h) - energy_at(d, -h)) / (2 * h)).margin(1e-6 * director_scale));
        }
    }
  }
}
