// The local support radius (shell/local_spacing.hpp; docs/method.md,
// "Support radius"): on graded plates every row follows its own spacing, the
// shape functions stay first-order consistent at every point, and a graded
// clamped plate's static centre deflection is close to Mindlin's.
#include "support/static_plate.hpp"

#include <sphshell/approx/mls.hpp>
#include <sphshell/approx/nsph.hpp>
#include <sphshell/kernel/cubic_spline.hpp>
#include <sphshell/kernel/quintic_spline.hpp>
#include <sphshell/material/elastic.hpp>
#include <sphshell/solver.hpp>
#include <sphshell/thickness/gauss.hpp>

#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <vector>

using namespace sphshell;
using solver::PointGroup;

namespace {

constexpr double pi = 3.14159265358979323846;

// Node coordinates on [0, L]: spacing growing geometrically by `ratio` from
// the first cell to the last.
std::vector<double> geometric_nodes(int cells, double L, double ratio) {
  const double growth = std::pow(ratio, 1.0 / (cells - 1));
  std::vector<double> x{0.0};
  double step = 1.0;
  for (int k = 0; k < cells; ++k, step *= growth) x.push_back(x.back() + step);
  for (double& v : x) v *= L / x.back();
  return x;
}

// Node coordinates on [0, L] graded from the ends to the middle:
// x(u) = L (u − c sin 2πu / 2π) with c = (ratio − 1)/(ratio + 1), so the
// spacing x'(u) = L (1 − c cos 2πu) is `ratio` times the edges' at the centre
// (coarse there for ratio > 1, fine for ratio < 1), and the centre u = ½ is a
// node for an even cell count.
std::vector<double> centre_coarse_nodes(int cells, double L, double ratio) {
  const double c = (ratio - 1.0) / (ratio + 1.0);
  std::vector<double> x;
  for (int k = 0; k <= cells; ++k) {
    const double u = double(k) / cells;
    x.push_back(L * (u - c * std::sin(2 * pi * u) / (2 * pi)));
  }
  return x;
}

// A flat from_quads plate on the tensor grid xs × ys (index j * nx + i).
ShellModel grid_plate(const std::vector<double>& xs, const std::vector<double>& ys, double thickness) {
  const int nx = static_cast<int>(xs.size()), ny = static_cast<int>(ys.size());
  std::vector<Vector3> positions, normals;
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i) {
      positions.emplace_back(xs[i], ys[j], 0.0);
      normals.push_back(Vector3::UnitZ());
    }
  std::vector<Quad> quads;
  for (int j = 0; j + 1 < ny; ++j)
    for (int i = 0; i + 1 < nx; ++i) quads.push_back({j * nx + i, j * nx + i + 1, (j + 1) * nx + i + 1, (j + 1) * nx + i});
  return ShellModel::from_quads(positions, normals, quads, thickness);
}

// Σ Φ_j = 1, Σ Φ_j ξ_j = 0 (linear fields reproduced), Σ ∇Φ_j = 0 and
// Σ ∇_β Φ_j ξ_jα = δ_αβ (their gradients exact) at every row of both groups;
// `linear_values` is false for NSPH, whose Φ reproduces constants only.
template <class Approximation>
void check_first_order(const ShellModel& model, bool linear_values) {
  const SolverOptions options;
  const solver::IntegrationPoints<Approximation> points(model, options.physics(), options.particle_integration(), 80e9);
  double smallest = 1e300, largest = 0.0;
  for (PointGroup group : solver::point_groups) {
    const approx::ShapeFunctions& sf = points.shape(group);
    const std::vector<Vector3>& eval = points.positions(model, group);
    REQUIRE(points.count(group) == eval.size());
    for (std::size_t row = 0; row < points.count(group); ++row) {
      smallest = std::min(smallest, points.support_radius(group, row));
      largest = std::max(largest, points.support_radius(group, row));
      REQUIRE(sf.shepard[row] == 0);
      const TangentFrame& frame = points.frame(group, row);
      const Vector3 e1 = frame.e1.normalized(), e2 = frame.e2.normalized();
      double sum = 0.0, d1 = 0.0, d2 = 0.0;
      Vector2 first = Vector2::Zero();
      Matrix2 gradient = Matrix2::Zero();  // (α, β): Σ ∂_β Φ_j ξ_jα
      double scale = 0.0;
      for (std::size_t s = sf.row_begin[row]; s < sf.row_begin[row] + sf.row_size[row]; ++s) {
        const Vector3 d = model.particle_position[static_cast<std::size_t>(sf.neighbour[s])] - eval[row];
        const Vector2 xi(d.dot(e1), d.dot(e2));
        sum += sf.value[s].phi;
        d1 += sf.value[s].dphi_d1;
        d2 += sf.value[s].dphi_d2;
        first += sf.value[s].phi * xi;
        gradient.col(0) += sf.value[s].dphi_d1 * xi;
        gradient.col(1) += sf.value[s].dphi_d2 * xi;
        scale = std::max(scale, xi.norm());
      }
      const double h = points.smoothing_length(group, row);
      INFO(solver::name_of(group) << " " << row << " at " << eval[row].transpose() << ", support "
                                  << points.support_radius(group, row) << " m, " << sf.row_size[row] << " neighbours");
      CHECK(sum == Approx(1.0).epsilon(1e-10));
      if (linear_values) CHECK(first.norm() < 1e-10 * scale);
      CHECK(std::abs(d1) * h < 1e-9);
      CHECK(std::abs(d2) * h < 1e-9);
      CHECK((gradient - Matrix2::Identity()).cwiseAbs().maxCoeff() < 1e-9);
    }
  }
  // The rows do follow their own spacing: 1:4 in each direction.
  WARN("support radii from " << smallest << " to " << largest << " m");
  CHECK(largest / smallest > 3.0);
}

constexpr double E = 210e9, nu = 0.3, q = 1e3, L = 1.0;
using PlateSolver = Solver<approx::MLS<kernel::CubicSpline>, thickness::Gauss<2>, material::Elastic>;

// w_centre D / (q L⁴) of the clamped plate on the tensor grid xs × xs, linear
// and solved statically.
double clamped_coefficient(const std::vector<double>& xs, double slenderness) {
  const double d = L / slenderness;
  const double D = E * d * d * d / (12 * (1 - nu * nu));
  const int n = static_cast<int>(xs.size());
  ShellModel model = grid_plate(xs, xs, d);
  const double tolerance = 1e-9 * L;
  const ParticleSet edge = model.define_set("edge", [&](const Vector3& x) {
    return x.x() < tolerance || x.y() < tolerance || x.x() > L - tolerance || x.y() > L - tolerance;
  });
  SolverOptions options;
  options.nonlinear = false;
  PlateSolver solver(model, {E, nu}, options);
  const Eigen::VectorXd w = test_support::clamped_plate_deflection(
      solver, {n, n, 0, test_support::PerturbationGroups::coupling_colours}, edge, q, 1e-7);
  const int centre = (n / 2) * n + n / 2;
  REQUIRE((solver.model().particle_position[centre] - Vector3(0.5 * L, 0.5 * L, 0)).norm() < 1e-12);
  return -w[centre] * D / (q * L * L * L * L);
}

}  // namespace

TEST_CASE("Graded plate, spacing 1:4 across: MLS rows reproduce linear fields and their gradients at every point",
          "[approx][local_support]") {
  const std::vector<double> xs = geometric_nodes(24, 0.2, 4.0);
  const std::vector<double> ys = geometric_nodes(18, 0.15, 4.0);
  const ShellModel model = grid_plate(xs, ys, 0.002);
  check_first_order<approx::MLS<kernel::CubicSpline>>(model, true);
  check_first_order<approx::MLS<kernel::QuinticSpline>>(model, true);
  // NSPH: constants and exact gradients of linear fields.
  check_first_order<approx::NSPH<kernel::CubicSpline>>(model, false);
}

TEST_CASE("Graded plate: each row's support is support_radius_factor times its own spacing", "[approx][local_support]") {
  const std::vector<double> xs = geometric_nodes(20, 0.2, 4.0);
  const ShellModel model = grid_plate(xs, xs, 0.002);
  SolverOptions options;
  options.support_radius_factor = 2.5;
  const solver::IntegrationPoints<approx::MLS<kernel::CubicSpline>> points(model, options.physics(),
                                                                            options.particle_integration(), 80e9);
  // Stress points: √ of their own quad's area, or half its diagonal (the
  // distance to its corners) where that is larger (quads longer than 3.73:1,
  // at the corners where a fine x meets a coarse y), computed from the grid.
  const int n = static_cast<int>(xs.size());
  int long_quads = 0;
  for (int cj = 0; cj + 1 < n; ++cj)
    for (int ci = 0; ci + 1 < n; ++ci) {
      const double a = xs[ci + 1] - xs[ci], b = xs[cj + 1] - xs[cj];
      const double spacing = std::max(std::sqrt(a * b), std::hypot(a, b) / 2.0);
      if (std::hypot(a, b) / 2.0 > std::sqrt(a * b)) ++long_quads;
      CHECK(points.support_radius(PointGroup::stress_points, std::size_t(cj * (n - 1) + ci)) ==
            Approx(2.5 * spacing).epsilon(1e-12));
    }
  CHECK(long_quads > 0);  // both terms are exercised
  // Particles: the largest over their quads of √A and of the distance to the
  // farthest corner over √2, computed here from the grid.
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      double spacing = 0.0;
      for (int cj : {j - 1, j})
        for (int ci : {i - 1, i}) {
          if (ci < 0 || cj < 0 || ci + 1 >= n || cj + 1 >= n) continue;
          const double a = xs[ci + 1] - xs[ci], b = xs[cj + 1] - xs[cj];
          spacing = std::max({spacing, std::sqrt(a * b), std::hypot(a, b) / std::sqrt(2.0)});
        }
      CHECK(points.support_radius(PointGroup::particles, std::size_t(j * n + i)) == Approx(2.5 * spacing).epsilon(1e-12));
    }
  // The fine corner's rows are no larger than a uniform plate's, the largest
  // rows stay those of a uniform plate too (the support scales with the spacing).
  int largest = 0;
  for (int size : points.shape(PointGroup::stress_points).row_size) largest = std::max(largest, size);
  CHECK(largest <= 40);
}

// Graded clamped plates at 41 × 41 particles, L/d = 50, against Mindlin
// (test_solver_plate's value): spacing 1:2 and 1:4 from the centre (fine) to
// the clamped edges, and 1:2 from the edges (fine) to the centre. The uniform
// plate at 41 × 41 is +0.77 %; with one global support radius (the largest
// spacing) the 1:2 fine-centre plate was +1.5 % and the 1:2 coarse-centre
// plate +67 % at 21 × 21. Stronger coarse-centre grading is a known miss
// (README, Known limits): 1:3 +28 %, 1:4 +76 % at 21 × 21, +91 % at 41 × 41.
// (No ": " late in the name: Catch 2.13's console reporter indents wrapped
// lines to it and, past the line's width, wraps forever.)
TEST_CASE("Graded clamped plates at 41 x 41 (1:2 and 1:4 fine centre, 1:2 coarse centre), static centre "
          "deflection within 2 % of Mindlin",
          "[solver][plate][local_support][validation]") {
  constexpr int cells = 40;
  constexpr double mindlin = 0.0012754;
  for (const double ratio : {0.5, 0.25, 2.0}) {
    const std::vector<double> xs = centre_coarse_nodes(cells, L, ratio);
    // The grading: the centre cell's width over the edge cell's.
    REQUIRE((xs[cells / 2 + 1] - xs[cells / 2]) / (xs[1] - xs[0]) == Approx(ratio).epsilon(0.05));
    const double value = clamped_coefficient(xs, 50.0);
    WARN("graded clamped plate 1:" << ratio << " (edge : centre), 41x41, L/d = 50: w D/(q L^4) = " << value << " ("
                                   << 100 * (value / mindlin - 1) << " % from Mindlin " << mindlin << ")");
    CHECK(value == Approx(mindlin).epsilon(0.02));
  }
}
