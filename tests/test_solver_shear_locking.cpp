// Thin-plate shear locking and the edge-tied transverse shear
// (shell/cell_shear.hpp; docs/method.md §4, "Transverse shear tied to the cell
// edges"): the tied cell's energy against closed forms, its forces against the
// derivative of its energy, and the clamped plate at L/d = 500 against
// Kirchhoff's value, solved statically (tests/support/static_plate.hpp; the
// same equilibrium the dynamic relaxation of test_solver_plate reaches).
#include "support/static_plate.hpp"

#include <sphshell/approx/mls.hpp>
#include <sphshell/kernel/cubic_spline.hpp>
#include <sphshell/material/elastic.hpp>
#include <sphshell/shell/cell_shear.hpp>
#include <sphshell/solver.hpp>
#include <sphshell/thickness/gauss.hpp>

#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

using namespace sphshell;

namespace {

using PlateSolver = Solver<approx::MLS<kernel::CubicSpline>, thickness::Gauss<2>, material::Elastic>;

// Kirchhoff's clamped square plate under uniform pressure: w_c = 0.00126532 q L⁴/D
// (Timoshenko & Woinowsky-Krieger, Theory of Plates and Shells, Table 35: 0.00126).
constexpr double kirchhoff_clamped = 0.00126532;

// w_centre D / (q L⁴) of the clamped L = 1 m plate with n × n particles, linear.
double clamped_coefficient(int n, double slenderness, SolverOptions options = {}) {
  const double L = 1.0, d = L / slenderness, E = 210e9, nu = 0.3, q = 1e3;
  const double D = E * d * d * d / (12 * (1 - nu * nu));
  options.nonlinear = false;
  PlateSolver solver(ShellModel::rectangular_plate(L, L, n, n, d), {E, nu}, options);
  const Eigen::VectorXd w =
      test_support::clamped_plate_deflection(solver, {n, n}, solver.model().set("boundary"), q, 1e-7);
  return -w[solver.model().set("centre")[0]] * D / (q * L * L * L * L);
}

// One cell: a skewed quad or a triangle in the plane z = 0, normals +z.
struct OneCell {
  std::vector<Vector3> x, d;
  std::vector<int> corners;
  double area;
};
OneCell skewed_quad() {
  OneCell c;
  c.x = {Vector3(0, 0, 0), Vector3(0.010, 0.001, 0), Vector3(0.013, 0.011, 0), Vector3(0.002, 0.008, 0)};
  c.corners = {0, 1, 2, 3};
  // The quad's area from its diagonals.
  c.area = 0.5 * (c.x[2] - c.x[0]).cross(c.x[3] - c.x[1]).norm();
  c.d.assign(4, Vector3::UnitZ());
  return c;
}
OneCell triangle() {
  OneCell c;
  c.x = {Vector3(0, 0, 0), Vector3(0.010, 0.002, 0), Vector3(0.003, 0.009, 0)};
  c.corners = {0, 1, 2};
  c.area = 0.5 * (c.x[1] - c.x[0]).cross(c.x[2] - c.x[0]).norm();
  c.d.assign(3, Vector3::UnitZ());
  return c;
}
shell::CellShearTying tie(const OneCell& c, double stiffness) {
  return shell::tie_cell_shear(c.corners.data(), static_cast<int>(c.corners.size()), c.x, c.d,
                               tangent_frame(Vector3::UnitZ()), stiffness, c.area);
}

}  // namespace

TEST_CASE("Tied shear: a uniform shear field gives the exact energy on skewed quads and triangles",
          "[solver][shear][patch]") {
  const double stiffness = 5.0 / 6.0 * 80e9 * 0.002;  // κs G d, N/m
  const Vector2 gamma(2e-4, -3e-4);
  for (const OneCell& cell : {skewed_quad(), triangle()}) {
    const shell::CellShearTying tying = tie(cell, stiffness);
    const double exact = 0.5 * stiffness * cell.area * gamma.squaredNorm();
    // Linear: γ from tilted directors, then from a tilted mid-surface (w = γ·X
    // with the directors kept, γ_α = ∂w/∂X_α): both give γ·t on every edge.
    std::vector<Vector3> d = cell.d, x = cell.x;
    for (Vector3& director : d) director += Vector3(gamma.x(), gamma.y(), 0.0);
    CHECK(shell::cell_shear_forces(tying, cell.x, d, false).energy == Approx(exact).epsilon(1e-12));
    for (Vector3& position : x) position.z() += gamma.x() * position.x() + gamma.y() * position.y();
    CHECK(shell::cell_shear_forces(tying, x, cell.d, false).energy == Approx(exact).epsilon(1e-12));
    // Nonlinear: unit directors tilted by a finite angle; γ = (d_x, d_y) on a flat cell.
    const Vector3 tilted = Vector3(0.3, -0.2, 1.0).normalized();
    std::vector<Vector3> unit(cell.d.size(), tilted);
    const double exact_nonlinear = 0.5 * stiffness * cell.area * (tilted.x() * tilted.x() + tilted.y() * tilted.y());
    CHECK(shell::cell_shear_forces(tying, cell.x, unit, true).energy == Approx(exact_nonlinear).epsilon(1e-12));
  }
}

TEST_CASE("Tied shear: a finite rigid rotation strains nothing, and the forces are the energy's gradient",
          "[solver][shear][objectivity]") {
  const double stiffness = 5.0 / 6.0 * 80e9 * 0.002;
  std::mt19937 random(11);
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  for (const OneCell& cell : {skewed_quad(), triangle()}) {
    const shell::CellShearTying tying = tie(cell, stiffness);
    const Eigen::AngleAxisd rotation(1.1, Vector3(0.3, -0.5, 0.8).normalized());
    std::vector<Vector3> x = cell.x, d = cell.d;
    for (std::size_t i = 0; i < x.size(); ++i) {
      x[i] = rotation * x[i] + Vector3(0.1, -0.2, 0.05);
      d[i] = rotation * d[i];
    }
    // A 1e-3 shear would hold ½ κs G d A 1e-6; the rotation leaves round-off.
    const double scale = 0.5 * stiffness * cell.area * 1e-6;
    CHECK(std::abs(shell::cell_shear_forces(tying, x, d, true).energy) < 1e-12 * scale);
    // A random configuration: the forces against central differences of the energy.
    for (std::size_t i = 0; i < x.size(); ++i) {
      x[i] += 1e-4 * Vector3(uniform(random), uniform(random), uniform(random));
      d[i] = (d[i] + 0.05 * Vector3(uniform(random), uniform(random), uniform(random))).normalized();
    }
    for (bool nonlinear : {true, false}) {
      const shell::CellShearForces f = shell::cell_shear_forces(tying, x, d, nonlinear);
      double force_scale = 0.0, director_scale = 0.0;
      for (std::size_t i = 0; i < x.size(); ++i) {
        force_scale = std::max(force_scale, f.force[i].norm());
        director_scale = std::max(director_scale, f.director_force[i].norm());
      }
      const double h = 1e-7;
      for (std::size_t i = 0; i < x.size(); ++i)
        for (int k = 0; k < 3; ++k) {
          auto energy_at = [&](std::vector<Vector3>& v, double step) {
            const double kept = v[i][k];
            v[i][k] = kept + step;
            const double e = shell::cell_shear_forces(tying, x, d, nonlinear).energy;
            v[i][k] = kept;
            return e;
          };
          const double force = (energy_at(x, h) - energy_at(x, -h)) / (2 * h);
          const double director_force = (energy_at(d, h) - energy_at(d, -h)) / (2 * h);
          CHECK(f.force[i][k] == Approx(force).margin(1e-6 * force_scale));
          CHECK(f.director_force[i][k] == Approx(director_force).margin(1e-6 * director_scale));
        }
    }
  }
}

// Measured before the cell-edge shear: with the shear from the shape functions and the
// particles' shear term (the former default), the clamped plate at L/d = 500
// was −8.6 / −5.5 / −2.4 % from Kirchhoff at 21 / 31 / 51 particles a side.
TEST_CASE("Clamped plate, L/d = 500: no shear locking, within 3 % of Kirchhoff at 21 x 21 and 1 % at 51 x 51",
          "[solver][plate][shear]") {
  const double coarse = clamped_coefficient(21, 500.0);
  const double fine = clamped_coefficient(51, 500.0);
  WARN("clamped L/d=500: w D/(q L^4) = " << coarse << " at 21x21 (" << 100 * (coarse / kirchhoff_clamped - 1)
                                         << " %), " << fine << " at 51x51 (" << 100 * (fine / kirchhoff_clamped - 1)
                                         << " %)");
  CHECK(coarse == Approx(kirchhoff_clamped).epsilon(0.03));
  CHECK(fine == Approx(kirchhoff_clamped).epsilon(0.01));
}

TEST_CASE("The shape-function shear with the particles' shear term locks the same plate",
          "[solver][plate][shear]") {
  SolverOptions options;
  options.transverse_shear = TransverseShear::shape_functions;
  options.particle_shear_weight = 0.01;
  const double locked = clamped_coefficient(21, 500.0, options);
  WARN("clamped L/d=500, shape-function shear + particle shear 0.01: w D/(q L^4) = "
       << locked << " at 21x21 (" << 100 * (locked / kirchhoff_clamped - 1) << " %)");
  CHECK(locked < 0.95 * kirchhoff_clamped);
}

// The convergence table of the README and docs/method.md §4: w_c D/(q L⁴) at
// 21, 31 and 51 particles a side for L/d = 10, 50, 100 (against Mindlin, the
// values of test_solver_plate) and 500 (against Kirchhoff), with the edge-tied
// shear and with the former shape-function shear (particle shear weight 0.01).
// Every tied entry is within 3 / 1.5 / 1 % of its reference at 21 / 31 / 51.
TEST_CASE("Clamped plate convergence table, tied and shape-function shear", "[solver][plate][shear][validation]") {
  struct Row { double slenderness, reference; };
  SolverOptions former;
  former.transverse_shear = TransverseShear::shape_functions;
  former.particle_shear_weight = 0.01;
  for (const Row row : {Row{10, 0.0015046}, Row{50, 0.0012754}, Row{100, 0.0012679}, Row{500, kirchhoff_clamped}}) {
    for (const auto& [n, tolerance] : {std::pair<int, double>{21, 0.03}, {31, 0.015}, {51, 0.01}}) {
      const double tied = clamped_coefficient(n, row.slenderness);
      const double shape = clamped_coefficient(n, row.slenderness, former);
      WARN("L/d = " << row.slenderness << ", " << n << "x" << n << ": tied " << tied << " ("
                    << 100 * (tied / row.reference - 1) << " %), shape functions " << shape << " ("
                    << 100 * (shape / row.reference - 1) << " %), reference " << row.reference);
      CHECK(tied == Approx(row.reference).epsilon(tolerance));
    }
  }
}
