// Triangle meshes read from a file behave like the quad grids: the patch
// test, the free plate's six rigid-body modes and no other zero-energy mode,
// and the clamped plate's static deflection against the quad plate's at the
// same node spacing (and the Mindlin value of docs/method.md's plate tests).
#include "support/mesh_files.hpp"
#include "support/relaxation.hpp"
#include "support/stiffness.hpp"

#include <sphshell/approx/mls.hpp>
#include <sphshell/io/gmsh_reader.hpp>
#include <sphshell/kernel/cubic_spline.hpp>
#include <sphshell/material/elastic.hpp>
#include <sphshell/solver.hpp>
#include <sphshell/thickness/gauss.hpp>

#include <catch2/catch.hpp>

#include <Eigen/Eigenvalues>

#include <cmath>
#include <random>
#include <string>

using namespace sphshell;

namespace {

using ElasticSolver = Solver<approx::MLS<kernel::CubicSpline>, thickness::Gauss<2>, material::Elastic>;
const material::Elastic::Parameters steel{210e9, 0.3};

enum class Diagonals { uniform, alternating };

// An nx × ny node grid on [0, Lx] × [0, Ly], each cell cut into two
// triangles (all along the same diagonal, or alternating like a union flag),
// interior nodes optionally moved at random by up to `jitter` spacings;
// written as a Gmsh file with the groups "boundary" (the four edges) and
// "centre" (the node nearest the middle), and read back.
ShellModel triangle_plate(double lx, double ly, int nx, int ny, double d, Diagonals diagonals,
                          double jitter = 0.0) {
  test_support::GmshMesh mesh;
  std::mt19937 random(42);
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  const double hx = lx / (nx - 1), hy = ly / (ny - 1);
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i) {
      Vector3 x(i * hx, j * hy, 0.0);
      if (i > 0 && j > 0 && i < nx - 1 && j < ny - 1) x += jitter * Vector3(hx * uniform(random), hy * uniform(random), 0.0);
      mesh.nodes.push_back(x);
    }
  for (int j = 0; j + 1 < ny; ++j)
    for (int i = 0; i + 1 < nx; ++i) {
      const int a = j * nx + i, b = a + 1, c = a + nx + 1, e = a + nx;
      if (diagonals == Diagonals::uniform || (i + j) % 2 == 0) {
        mesh.cells.push_back(Cell(a, b, c));
        mesh.cells.push_back(Cell(a, c, e));
      } else {
        mesh.cells.push_back(Cell(a, b, e));
        mesh.cells.push_back(Cell(b, c, e));
      }
    }
  test_support::GmshEntity boundary{1, {}, {}, {"boundary"}};
  auto node = [&](int i, int j) { return j * nx + i; };
  for (int i = 0; i + 1 < nx; ++i) {
    boundary.node_elements.push_back({node(i, 0), node(i + 1, 0)});
    boundary.node_elements.push_back({node(i, ny - 1), node(i + 1, ny - 1)});
  }
  for (int j = 0; j + 1 < ny; ++j) {
    boundary.node_elements.push_back({node(0, j), node(0, j + 1)});
    boundary.node_elements.push_back({node(nx - 1, j), node(nx - 1, j + 1)});
  }
  mesh.entities.push_back({0, {{node(nx / 2, ny / 2)}}, {}, {"centre"}});
  mesh.entities.push_back(boundary);
  test_support::GmshEntity surface{2, {}, {}, {}};
  for (std::size_t c = 0; c < mesh.cells.size(); ++c) surface.cells.push_back(static_cast<int>(c));
  mesh.entities.push_back(surface);
  const test_support::ScratchDirectory directory("triangles");
  const auto path = directory / "plate.msh";
  test_support::write_text(path, test_support::gmsh_text(mesh, false));
  return io::read_gmsh(path.string(), d);
}

// Eigenvalues of K φ = ω² M φ of the free plate, in ascending order ((rad/s)²).
Eigen::VectorXd free_spectrum(const ShellModel& model) {
  SolverOptions options;
  options.nonlinear = false;
  ElasticSolver solver(model, steel, options);
  const test_support::DiscreteSystem system = test_support::assemble(solver, 1e-6);
  const Eigen::VectorXd inverse_sqrt_mass = system.mass.cwiseSqrt().cwiseInverse();
  const Eigen::MatrixXd scaled = inverse_sqrt_mass.asDiagonal() * system.stiffness * inverse_sqrt_mass.asDiagonal();
  return Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(scaled).eigenvalues();
}

// The clamped square plate of tests/test_solver_plate.cpp: L = 1 m, q = 1 kPa,
// linear, dynamic relaxation with damping 2ω₁ over at most 6 periods of the
// fundamental mode. Returns w_centre D / (q L⁴) and its relative change over
// the last period.
std::pair<double, double> clamped_coefficient(const ShellModel& model, double d) {
  const double L = 1.0, E = steel.E, nu = steel.nu, rho = 7850.0, q = 1e3;
  const double D = E * d * d * d / (12 * (1 - nu * nu));
  const double omega = 35.99 / (L * L) * std::sqrt(D / (rho * d));
  const double slenderness = L / d;
  SolverOptions options;
  options.nonlinear = false;
  options.density = rho;
  options.damping = 2 * omega;
  options.rotary_inertia_scale = std::max(3.0, 3.0 * (slenderness / 50.0) * (slenderness / 50.0));
  ElasticSolver solver(model, steel, options);
  solver.clamp(model.set("boundary"));
  solver.add_uniform_pressure(model.all_particles(), q, time_function::Step{}, PressureDirection::fixed);
  const int centre = model.set("centre")[0];
  const double period = 2 * M_PI / omega;
  auto coefficient = [&] { return -solver.displacement(centre).z() * D / (q * L * L * L * L); };
  // Period by period, up to 6; stopped early once the coefficient moves by
  // less than 1e-8 of itself over one (after 5 periods at 31 x 31, L/d = 50,
  // where it then agrees with the value after 6 to ~1e-11).
  const test_support::Settled settled = test_support::relax_until_settled(solver, period, 6, 1e-8, coefficient);
  return {settled.value, settled.last_change};
}

// The clamped plate at n × n particles and L/d = slenderness, as quads and as
// triangles (uniform diagonals): both relaxations settled, and the triangles'
// centre deflection within 1 % of the quads'. `mindlin` is printed beside them.
void check_triangles_against_quads(int n, double slenderness, double mindlin) {
  const double d = 1.0 / slenderness;
  const auto quad = clamped_coefficient(ShellModel::rectangular_plate(1.0, 1.0, n, n, d), d);
  const auto triangles = clamped_coefficient(triangle_plate(1.0, 1.0, n, n, d, Diagonals::uniform), d);
  WARN("clamped " << n << "x" << n << " L/d=" << slenderness << ": quads w D/(q L^4) = " << quad.first << " ("
                  << 100 * (quad.first / mindlin - 1) << " % vs Mindlin), triangles " << triangles.first << " ("
                  << 100 * (triangles.first / mindlin - 1) << " % vs Mindlin, "
                  << 100 * (triangles.first / quad.first - 1) << " % vs quads)");
  CHECK(quad.second < 1e-4);
  CHECK(triangles.second < 1e-4);
  CHECK(triangles.first == Approx(quad.first).epsilon(0.01));
}

}  // namespace

TEST_CASE("Triangle plate: a linear displacement field gives uniform exact strains and no interior force",
          "[io][mesh][triangles][patch test]") {
  const double lx = 0.7, ly = 0.6, d = 0.01, spacing = 0.05;
  const Eigen::Matrix3d gradient = (Eigen::Matrix3d() << 1e-4, 2e-4, 0, -0.5e-4, 3e-4, 0, 0, 0, 0).finished();
  const Eigen::Matrix3d gamma =
      steel.E / (1 - steel.nu * steel.nu) *
      (Eigen::Matrix3d() << 1, steel.nu, 0, steel.nu, 1, 0, 0, 0, (1 - steel.nu) / 2).finished();
  // Regular triangles, and triangles of a grid whose interior nodes moved by up to 30 % of a spacing.
  for (const double jitter : {0.0, 0.3}) {
    for (const bool nonlinear : {false, true}) {
      SolverOptions options;
      options.nonlinear = nonlinear;
      ElasticSolver solver(triangle_plate(lx, ly, 15, 13, d, Diagonals::uniform, jitter), steel, options);
      REQUIRE(solver.model().quads().empty());
      std::vector<Vector3> x = solver.positions();
      for (Vector3& xi : x) xi += gradient * xi;
      solver.set_configuration(x, solver.directors());
      const Eigen::Matrix2d grad = gradient.topLeftCorner<2, 2>();
      Eigen::Matrix2d strain = 0.5 * (grad + grad.transpose());
      if (nonlinear) strain += 0.5 * grad.transpose() * grad;
      const StressVoigt expected = d * gamma * StrainVoigt(strain(0, 0), strain(1, 1), 2 * strain(0, 1));
      INFO("jitter " << jitter << ", nonlinear " << nonlinear);
      double worst_membrane = 0.0, worst_moment = 0.0;
      for (std::size_t s = 0; s < solver.stress_point_count(); ++s) {
        worst_membrane = std::max(worst_membrane, (solver.membrane_force(static_cast<int>(s)) - expected).norm());
        worst_moment = std::max(worst_moment, solver.bending_moment(static_cast<int>(s)).norm());
      }
      CHECK(worst_membrane < 1e-9 * expected.norm());
      CHECK(worst_moment < 1e-9 * expected.norm() * d);
      if (jitter > 0.0) continue;
      // On the regular triangulation the stress points sit centrally
      // symmetric about every node, so a uniform stress leaves no force on a
      // particle whose support does not reach the edge (as on the quad grid).
      // On the jittered grid the quadrature loses that symmetry: not checked.
      double largest_interior = 0.0, largest = 0.0;
      for (std::size_t i = 0; i < solver.particle_count(); ++i) {
        const double f = solver.internal_forces()[i].norm();
        largest = std::max(largest, f);
        const Vector3& xi = solver.model().particle_position[i];
        if (xi.x() > 4.5 * spacing && xi.x() < lx - 4.5 * spacing && xi.y() > 4.5 * spacing &&
            xi.y() < ly - 4.5 * spacing)
          largest_interior = std::max(largest_interior, f);
      }
      CHECK(largest > 0.0);
      CHECK(largest_interior < 1e-9 * largest);
    }
  }
}

// The free plate's first elastic frequency, ω = 13.468 √(D/(ρd)) / L² for
// ν = 0.3 (Leissa, Vibration of Plates, NASA SP-160, 1969), as
// tests/test_solver_mechanics.cpp checks it for quads.
double leissa_first_frequency(double L, double d) {
  const double rho = 7850.0;
  return 13.468 * std::sqrt(steel.E * d * d * d / (12 * (1 - steel.nu * steel.nu)) / (rho * d)) / (L * L);
}

TEST_CASE("A free triangle plate has exactly six zero-energy modes", "[io][mesh][triangles][stability]") {
  for (const Diagonals diagonals : {Diagonals::uniform, Diagonals::alternating}) {
    const Eigen::VectorXd eigenvalues = free_spectrum(triangle_plate(0.5, 0.5, 11, 11, 0.01, diagonals));
    const double largest = eigenvalues.maxCoeff();
    int zero_modes = 0;
    for (int k = 0; k < eigenvalues.size(); ++k) zero_modes += std::abs(eigenvalues[k]) < 1e-9 * largest;
    INFO((diagonals == Diagonals::uniform ? "uniform" : "alternating")
         << " diagonals: 6th eigenvalue / largest = " << eigenvalues[5] / largest
         << ", 7th = " << eigenvalues[6] / largest);
    CHECK(zero_modes == 6);
    CHECK(eigenvalues[6] > 1e-8 * largest);
    if (diagonals == Diagonals::uniform) {
      // and the seventh is the first elastic mode, neither spurious nor stiffened.
      INFO("seventh frequency " << std::sqrt(eigenvalues[6]) << " rad/s, Leissa " << leissa_first_frequency(0.5, 0.01));
      CHECK(std::sqrt(eigenvalues[6]) == Approx(leissa_first_frequency(0.5, 0.01)).epsilon(0.05));
    }
  }
}

// With the diagonals alternating (a union-flag pattern) the stress points sit
// at (1/3, 1/3) and (2/3, 2/3) of the cells in a checkerboard. With the
// shape-function shear the free plate's first elastic mode came out stiff:
// 1070 rad/s against Leissa's 843 (+26.9 %) at 11 × 11, L/d = 50 (transverse
// shear over-constrained). With the shear tied to the cell edges
// (docs/method.md §4) it is 826 rad/s (−2.0 %); uniform diagonals give 834
// (−1.0 %) and quads 827 (−1.9 %).
TEST_CASE("Free triangle plate, alternating diagonals: first elastic frequency within 5 % of Leissa's",
          "[io][mesh][triangles][stability]") {
  const Eigen::VectorXd eigenvalues = free_spectrum(triangle_plate(0.5, 0.5, 11, 11, 0.01, Diagonals::alternating));
  WARN("alternating diagonals: seventh frequency " << std::sqrt(eigenvalues[6]) << " rad/s, Leissa "
                                                   << leissa_first_frequency(0.5, 0.01));
  CHECK(std::sqrt(eigenvalues[6]) == Approx(leissa_first_frequency(0.5, 0.01)).epsilon(0.05));
}

// Known miss, kept at the full criterion: the triangles lock in transverse
// shear. The shear is tied to the cell edges (docs/method.md §4), and a
// triangle mesh has about three edges per node against the quad grid's two,
// as many shear constraints as bending unknowns (w and two rotations); the
// plate is too stiff, the more so the thinner it is. Measured at 21 × 21
// (w D/(q L⁴), triangles vs quads, static solutions equal to this relaxation's):
// L/d = 10: −0.42 %, L/d = 50: −1.96 %, L/d = 100: −6.1 % (with the former
// shape-function shear: −0.55, −5.75, −12.6 %); at L/d = 50 the gap closes with
// refinement (−0.50 % at 31 × 31, −0.22 % at 41 × 41). Tagged [!shouldfail] so
// the suite reports the day a triangle shear that does not lock fixes it.
TEST_CASE("Clamped triangle plate, L/d = 50: centre deflection within 1 % of the quad plate's",
          "[io][mesh][triangles][plate][validation][!shouldfail]") {
  check_triangles_against_quads(21, 50, 0.0012754);
}

// The same plate one refinement up: the triangles' shear constraint relaxes
// with the spacing and the two meshes agree within 1 % (measured −0.50 %).
TEST_CASE("Clamped triangle plate, L/d = 50, 31 x 31: centre deflection within 1 % of the quad plate's",
          "[io][mesh][triangles][plate][validation]") {
  check_triangles_against_quads(31, 50, 0.0012754);
}

// Where shear does not constrain much, the triangles bend like the quads.
TEST_CASE("Clamped thick triangle plate, L/d = 10: centre deflection within 1 % of the quad plate's",
          "[io][mesh][triangles][plate][validation]") {
  check_triangles_against_quads(21, 10, 0.0015046);
}
