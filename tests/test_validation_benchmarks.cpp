// The standard shell benchmarks, solved statically by Newton's
// method on the solver's own forces (sphshell/statics/path_following.hpp; the cases
// in tests/support/shell_benchmarks.hpp). The README's table and charts come
// from the shell_benchmarks example, which runs the same cases one refinement
// finer. Tolerances are the error measured at each case's finest resolution
// here plus a small margin (the README lists the measurements).
#include "support/shell_benchmarks.hpp"

#include <sphshell/material/elastic.hpp>
#include <sphshell/solver.hpp>
#include <sphshell/thickness/gauss.hpp>

#include <catch2/catch.hpp>

#include <cmath>
#include <cstdio>
#include <tuple>
#include <vector>
#include <algorithm>

using namespace sphshell;
using namespace sphshell::test_support;

namespace {

// Gauss<2> integrates the linear theory's stresses (linear through the
// thickness) exactly; the nonlinear strains are quadratic in ζ, so Gauss<3>.
using LinearSolver = Solver<approx::MLS<kernel::CubicSpline>, thickness::Gauss<2>, material::Elastic>;
using NonlinearSolver = Solver<approx::MLS<kernel::CubicSpline>, thickness::Gauss<3>, material::Elastic>;

double linear_benchmark(const StaticBenchmark& benchmark, statics::NewtonOptions newton = {}) {
  SolverOptions options;
  options.nonlinear = false;
  LinearSolver solver(benchmark.model, {benchmark.E, benchmark.nu}, options);
  statics::PathFollower<LinearSolver> statics(solver, benchmark.conditions, newton);
  statics.linear_solve(1.0);
  return reported_displacement(benchmark, solver);
}

double error_percent(double value, double reference) { return 100.0 * (value / reference - 1.0); }

// Runs a linear benchmark at each resolution, prints the errors, and returns
// the error at the last (finest) one.
template <class Build>
double linear_convergence(const char* name, Build&& build, std::initializer_list<int> resolutions) {
  double error = 0.0;
  for (int n : resolutions) {
    const StaticBenchmark benchmark = build(n);
    const double value = linear_benchmark(benchmark);
    error = error_percent(value, benchmark.reference);
    std::printf("%s, %d x %d particles: %.6g (reference %.6g, %+.2f %%)\n", name, n, n, value, benchmark.reference,
                error);
  }
  return error;
}

}  // namespace

TEST_CASE("Static shell: the coloured stiffness assembly equals one particle at a time", "[static][benchmarks]") {
  // A coarse pinched hemisphere (curved, symmetry planes, point loads): the
  // colouring perturbs many particles at once and credits each response to
  // the one in reach; it must give the same solution as perturbing each
  // particle alone.
  const StaticBenchmark benchmark = pinched_hemisphere(9, PointLoad::shape_functions);
  statics::NewtonOptions alone;
  alone.steps.one_particle_per_colour = true;
  const double coloured = linear_benchmark(benchmark);
  const double reference = linear_benchmark(benchmark, alone);
  CHECK(coloured == Approx(reference).epsilon(1e-6));
}

TEST_CASE("Static shell: the elastica by shooting matches the tabulated cantilever", "[static][benchmarks]") {
  // Sze, Liu & Lo (2004), §3.1, the cantilever under end shear (L = 10,
  // EI = 100, P_max = 4), their Table 1 at P = P_max: W = 6.698, −U = 3.286
  // (a converged S4R mesh). The elastica here is the exact beam answer.
  const TipDisplacement tip = elastica_tip(4.0, 100.0, 10.0);
  CHECK(tip.w == Approx(6.698).epsilon(5e-4));
  CHECK(tip.u == Approx(3.286).epsilon(2e-3));
  // Small loads: the linear tip deflection P L³ / (3 EI).
  const TipDisplacement small = elastica_tip(1e-4, 100.0, 10.0);
  CHECK(small.w == Approx(1e-4 * 1000.0 / 300.0).epsilon(1e-6));
}

namespace {

// The cantilever under end shear (21 x 3, P_max = 4 shared by the tip
// particles), its tip's w and −u as path readings, and load control's tip at
// P/P_max = 0.5 and 1.
struct EndShearPaths {
  CantileverStrip strip = cantilever_strip(10.0, 21, 3);
  statics::ControlDisplacement tip_w{{{strip.tip_mid, 1.0}}, Vector3::UnitZ()};
  statics::ControlDisplacement tip_u{{{strip.tip_mid, 1.0}}, -Vector3::UnitX()};
  std::vector<double> factors{0.5, 1.0};
  CantileverRun by_load = run_cantilever<NonlinearSolver>(EndLoad::shear, 21, 3, factors, 0.1);
  EndShearPaths() {
    const std::vector<double> share = edge_shares(3);
    for (int k = 0; k < 3; ++k) strip.conditions.add_force({strip.tip[k]}, Vector3(0.0, 0.0, 4.0 * share[k]));
  }
  // A path's tip {w, −u} read at each load factor against load control's: the
  // same equilibria of the same discrete model, to the Newton tolerance and
  // the path's quadratic interpolation. Returns the readings.
  std::vector<std::vector<double>> check(const char* method, const PathRun& path) const {
    REQUIRE(path.path.back().load_factor >= 1.0);
    std::vector<std::vector<double>> readings;
    for (std::size_t k = 0; k < factors.size(); ++k) {
      const std::vector<double> on_path = readings_at_load_factor(path.path, factors[k]);
      REQUIRE(on_path.size() == 2);
      std::printf("%s at P/Pmax = %.2f: w %.6f (load control %.6f), -u %.6f (%.6f)\n", method, factors[k], on_path[0],
                  by_load.points[k].w, on_path[1], by_load.points[k].u);
      CHECK(on_path[0] == Approx(by_load.points[k].w).epsilon(2e-3));
      CHECK(on_path[1] == Approx(by_load.points[k].u).epsilon(4e-3));
      readings.push_back(on_path);
    }
    return readings;
  }
};

}  // namespace

TEST_CASE("Static shell: displacement control follows the load-controlled path", "[static][benchmarks]") {
  // The cantilever under end shear solved twice: by load control to
  // P/P_max = 0.5 and 1, and by prescribing the tip's deflection in steps of
  // 0.5 (the load factor then an unknown); both stay near the elastica.
  const EndShearPaths cantilever;
  const PathRun path = follow_path<NonlinearSolver>(cantilever.strip.model, 1.2e6, 0.0, {}, cantilever.strip.conditions,
                                                    cantilever.tip_w, {cantilever.tip_w, cantilever.tip_u}, 0.5, 1.0,
                                                    40);
  for (std::size_t k = 1; k < path.path.size(); ++k)  // the tip's w is what was prescribed
    CHECK(path.path[k].values[0] == Approx(0.5 * double(k)).epsilon(1e-9));
  const std::vector<std::vector<double>> readings = cantilever.check("displacement control", path);
  for (std::size_t k = 0; k < readings.size(); ++k) {
    const TipDisplacement exact = elastica_tip(cantilever.factors[k] * 4.0, 100.0, 10.0);
    CHECK(readings[k][0] == Approx(exact.w).epsilon(5e-3));
  }
  // A path read beyond its last load factor gives nothing.
  CHECK(readings_at_load_factor(path.path, 10.0).empty());
  // Bad input: a non-positive displacement step.
  NonlinearSolver solver(cantilever.strip.model, {1.2e6, 0.0});
  statics::PathFollower<NonlinearSolver> statics(solver, cantilever.strip.conditions);
  CHECK_THROWS_WITH(statics.solve_to_displacement(cantilever.tip_w, 1.0, 0.0),
                    Catch::Contains("displacement step = 0") && Catch::Contains("> 0"));
}

TEST_CASE("Static shell: the arc length follows the load-controlled path", "[static][benchmarks]") {
  // The cantilever of the test above, followed by arc length (steps of 0.2
  // in the particles' root-mean-square motion, the load factor solved for).
  const EndShearPaths cantilever;
  const PathRun path = follow_arc_length<NonlinearSolver>(cantilever.strip.model, 1.2e6, 0.0, {},
                                                          cantilever.strip.conditions,
                                                          {cantilever.tip_w, cantilever.tip_u}, 0.2, 1.0, 60);
  REQUIRE(path.stopped.empty());
  for (std::size_t k = 1; k < path.path.size(); ++k) {  // forward along the path, never back
    CHECK(path.path[k].load_factor > path.path[k - 1].load_factor);
    CHECK(path.path[k].control > path.path[k - 1].control);
  }
  cantilever.check("arc length", path);
  NonlinearSolver solver(cantilever.strip.model, {1.2e6, 0.0});
  statics::PathFollower<NonlinearSolver> statics(solver, cantilever.strip.conditions);
  CHECK_THROWS_WITH(statics.arc_length_step(0.0), Catch::Contains("arc length = 0") && Catch::Contains("> 0"));
}

TEST_CASE("Static shell: the tangent's inertia finds the Euler load of a compressed strip", "[static][benchmarks]") {
  // The Sze cantilever strip (L = 10, EI = 100, ν = 0; 21 × 3) under an axial
  // dead load P at its free end stays straight; it loses stability at
  // Euler's P_cr = π² EI / (4 L²) (Mindlin's shear lowers it by P_cr / (κ G A),
  // 5·10⁻⁵ here). Below P_cr the tangent is positive definite; above it one
  // eigenvalue is negative, its mode the transverse bending one, orthogonal
  // to the load (a bifurcation, not a limit point of the load).
  CantileverStrip strip = cantilever_strip(10.0, 21, 3);
  const double euler = benchmark_pi * benchmark_pi * strip.EI / (4.0 * strip.L * strip.L);
  const std::vector<double> share = edge_shares(3);
  for (int k = 0; k < 3; ++k) strip.conditions.add_force({strip.tip[k]}, Vector3(-euler * share[k], 0.0, 0.0));
  NonlinearSolver solver(strip.model, {1.2e6, 0.0});
  statics::PathFollower<NonlinearSolver> statics(solver, strip.conditions);
  statics.solve_to(0.99, 0.5);
  const auto below = statics.stability();
  statics.solve_to(1.01, 0.5);
  const auto above = statics.stability();
  CHECK(std::abs(statics.displacement(strip.tip_mid).z()) < 1e-9);  // still straight
  CHECK(below.negative_eigenvalues == 0);
  CHECK(above.negative_eigenvalues == 1);
  CHECK(below.eigenvalue_nearest_zero > 0.0);
  CHECK(above.eigenvalue_nearest_zero < 0.0);
  // The eigenvalue falls linearly with the load: its zero is the discrete model's buckling load.
  const double critical = 0.99 + 0.02 * below.eigenvalue_nearest_zero /
                                     (below.eigenvalue_nearest_zero - above.eigenvalue_nearest_zero);
  std::printf("Euler strip (21 x 3): buckling at %.5f P_cr\n", critical);
  CHECK(critical == Approx(1.0).epsilon(5e-3));
  CHECK(above.load_share < 1e-8);
  // The mode bends the strip out of its plane: the tip moves most, along z.
  const Vector3 tip = above.mode[static_cast<std::size_t>(strip.tip_mid)];
  CHECK(std::abs(tip.z()) > 10.0 * std::abs(tip.x()));
  for (const Vector3& motion : above.mode) CHECK(motion.norm() <= std::abs(tip.z()) * (1.0 + 1e-6));
}

TEST_CASE("Benchmark: Scordelis-Lo roof (linear)", "[validation][benchmarks]") {
  // Reference 0.3024 (MacNeal & Harder 1985). Measured −0.52 % at 33 x 33
  // (+0.07 % at 17, −0.37 % at 25; −0.56 % at 41 in the example).
  const double error = linear_convergence("Scordelis-Lo roof", scordelis_lo_roof, {17, 25, 33});
  CHECK(std::abs(error) < 0.75);
}

TEST_CASE("Benchmark: pinched hemisphere with an 18 degree hole (linear)", "[validation][benchmarks]") {
  // Reference 0.094 (MacNeal & Harder 1985); point loads applied consistently
  // through the shape functions. Measured −1.24 % at 33 x 33 (−3.06 % at 25):
  // the cells near the hole are up to 3.2 : 1, their rows thin along the long
  // side (docs/method.md, "Support radius"; −0.34 / −1.87 % when every row took
  // the largest cell's spacing).
  const double error = linear_convergence(
      "Pinched hemisphere", [](int n) { return pinched_hemisphere(n, PointLoad::shape_functions); }, {25, 33});
  CHECK(std::abs(error) < 1.5);
}

TEST_CASE("Benchmark: pinched cylinder with rigid diaphragms (linear, a known miss)", "[validation][benchmarks]") {
  // Reference 1.8248e-5 (MacNeal & Harder 1985). Measured +4.22 % at 33 x 33
  // (+3.96 % at 25; +3.89 / +3.51 % at 41 / 49 in the example): above the
  // 2 % target, converging slowly from above (README, "Benchmarks").
  const double error = linear_convergence(
      "Pinched cylinder", [](int n) { return pinched_cylinder(n, PointLoad::shape_functions); }, {25, 33});
  CHECK(std::abs(error) < 4.5);
}

TEST_CASE("Benchmark: cantilever under end shear (Sze, Liu & Lo 2004, nonlinear)", "[validation][benchmarks]") {
  // The tip's w and −u against the elastica (exact for this ν = 0 strip) at
  // P/P_max = 0.1 … 1. Measured at 41 x 5: largest error +0.11 % (w) and
  // +0.14 % (u), at P_max; 21 x 3: +0.26 / +0.32 %.
  std::vector<double> factors;
  for (int k = 1; k <= 10; ++k) factors.push_back(0.1 * k);
  for (const auto& [nx, ny, tolerance] : {std::tuple{21, 3, 0.4}, std::tuple{41, 5, 0.2}}) {
    const CantileverRun run = run_cantilever<NonlinearSolver>(EndLoad::shear, nx, ny, factors, 0.1);
    double worst_w = 0.0, worst_u = 0.0;
    for (const CantileverPoint& point : run.points) {
      const TipDisplacement exact = elastica_tip(point.load_factor * run.full_load, run.EI, run.L);
      worst_w = std::max(worst_w, std::abs(error_percent(point.w, exact.w)));
      worst_u = std::max(worst_u, std::abs(error_percent(point.u, exact.u)));
    }
    const CantileverPoint& last = run.points.back();
    std::printf("Cantilever end shear, %d x %d: at P_max w = %.5g, -u = %.5g; largest error %.3f %% (w), %.3f %% (u); "
                "%d Newton iterations\n",
                nx, ny, last.w, last.u, worst_w, worst_u, run.report.iterations);
    CHECK(worst_w < tolerance);
    CHECK(worst_u < tolerance);
  }
}

TEST_CASE("Benchmark: cantilever rolled into a circle by an end moment (Sze, Liu & Lo 2004, nonlinear)",
          "[validation][benchmarks]") {
  // M = k · 2πEI/L bends the strip into an arc of radius EI/M; at k = 1 the
  // tip is back at the root. Measured at 49 x 5: half circle (k = 0.5) −u
  // +0.28 %, w −0.23 %; full circle: the tip 1.16 % of L from the closed form
  // (25 x 3: 4.7 %), converging at second order.
  std::vector<double> factors;
  for (int k = 1; k <= 20; ++k) factors.push_back(0.05 * k);
  for (const auto& [nx, ny, tolerance] : {std::tuple{25, 3, 5.0}, std::tuple{49, 5, 1.4}}) {
    const CantileverRun run = run_cantilever<NonlinearSolver>(EndLoad::moment, nx, ny, factors, 0.05);
    const CantileverPoint& half = run.points[9];
    const TipDisplacement half_exact = circle_tip(0.5 * run.full_load, run.EI, run.L);
    const CantileverPoint& full = run.points.back();
    const double miss = std::hypot(full.u - run.L, full.w) / run.L * 100.0;
    std::printf("Cantilever end moment, %d x %d: half circle -u %+.2f %%, w %+.2f %%; full circle: tip %.2f %% of L "
                "from the root; %d Newton iterations\n",
                nx, ny, error_percent(half.u, half_exact.u), error_percent(half.w, half_exact.w), miss,
                run.report.iterations);
    CHECK(miss < tolerance);
    if (nx == 49) {
      CHECK(std::abs(error_percent(half.u, half_exact.u)) < 0.5);
      CHECK(std::abs(error_percent(half.w, half_exact.w)) < 0.5);
    }
  }
}

TEST_CASE("Benchmark: slit annular plate under end shear (Sze, Liu & Lo 2004, nonlinear)", "[validation][benchmarks]") {
  // W_A (inner) and W_B (outer) of the loaded face against the paper's table
  // (§3.3) at P/P_max = 0.025, 0.1 … 1; the slit is a cut between duplicated
  // particles. Here 9 x 46 particles up to P_max / 2 (the whole path takes
  // ≈ 5 min): measured largest error −2.41 % (W_B at P_max / 2; −1.99 % when
  // every row took the largest cell's spacing, docs/method.md "Support
  // radius"); with that former spacing, to P_max it
  // grows to −3.16 % (W_A), and at 11 x 61 the error at P_max / 2 is −0.87 %
  // (README, shell_benchmarks).
  constexpr int radial = 9, circumferential = 46;
  const SlitPlateRun run = run_slit_annular_plate<NonlinearSolver>(radial, circumferential, 0.025, 0.5);
  const std::vector<TabulatedPoint> table = sze_slit_annular_plate_table();
  double worst = 0.0;
  for (std::size_t k = 0; k < run.points.size(); ++k) {
    worst = std::max({worst, std::abs(error_percent(run.points[k].first, table[k].first)),
                      std::abs(error_percent(run.points[k].second, table[k].second))});
  }
  const TabulatedPoint& last = run.points.back();
  const TabulatedPoint& reference = table[run.points.size() - 1];
  std::printf("Slit annular plate, %d x %d: at P/P_max = %.2f W_A = %.4g (%+.2f %%), W_B = %.4g (%+.2f %%); largest "
              "error over the table %.2f %%; %d Newton iterations\n",
              radial, circumferential, last.load_factor, last.first, error_percent(last.first, reference.first),
              last.second, error_percent(last.second, reference.second), worst, run.report.iterations);
  CHECK(worst < 2.6);
}

TEST_CASE("Benchmark: hemisphere with an 18 degree hole under alternating forces (Sze, Liu & Lo 2004, nonlinear)",
          "[validation][benchmarks]") {
  // §3.4: the pulled point's outward and the pushed point's inward radial
  // displacement against the paper's table. Here 29 x 29 particles up to
  // P/P_max = 0.1 (about 30 s on one thread; every further 0.05 costs about
  // as much again). Measured at 0.05 / 0.1: −1.71 / −1.90 % (pulled), −1.92 /
  // −2.29 % (pushed); at 0.05: 21 x 21 −6.04 / −5.81 %, 25 x 25 −3.08 /
  // −3.12 %, 33 x 33 −1.03 / −1.33 %. The lat-long cells near the hole are up
  // to 3.2 : 1 and their rows thin along the meridian (docs/method.md,
  // "Support radius"): with each cell's longest side for its spacing 21 x 21
  // was −1.66 / −1.40 %, and along the path it grew to −3.6 % at 0.45.
  constexpr int n = 29;
  const TabulatedRun run = run_sze_hemisphere<NonlinearSolver>(n, 0.0125, 0.1);
  const std::vector<TabulatedPoint> table = sze_hemisphere_table();
  REQUIRE(!run.points.empty());
  double worst = 0.0;
  for (std::size_t k = 0; k < run.points.size(); ++k) {
    const double pulled = error_percent(run.points[k].first, table[k].first);
    const double pushed = error_percent(run.points[k].second, table[k].second);
    std::printf("Hemisphere (Sze), %d x %d, P/P_max = %.2f: pulled %.4g (%+.2f %%), pushed %.4g (%+.2f %%)\n", n, n,
                run.points[k].load_factor, run.points[k].first, pulled, run.points[k].second, pushed);
    worst = std::max({worst, std::abs(pulled), std::abs(pushed)});
  }
  std::printf("Hemisphere (Sze): largest error %.2f %%; %d Newton iterations\n", worst, run.report.iterations);
  CHECK(worst < 2.6);
}

TEST_CASE("Benchmark: pinched cylinder with rigid diaphragms up to P/P_max = 0.1 (Sze, Liu & Lo 2004, nonlinear)",
          "[validation][benchmarks]") {
  // §3.6: −W_A (inward under the load) and U_B (radial at B, slightly
  // inward here) against the paper's table at P/P_max = 0.05, 0.075 and 0.1,
  // by load control in steps of 0.025, at 41 x 41, which the octant's
  // concentrated dent needs. Measured for −W_A: +0.25 / −0.27 / −1.25 %
  // (−3.0 / −13 / −20 % at 25², −0.56 / −2.65 / −4.99 % at 33²; at 41²
  // −1.82 % at 0.125 and −3.36 % at 0.15, where the paper's snap begins); for
  // U_B +0.43 / −0.41 / −1.88 %. Newton's steps by GMRES preconditioned by a
  // kept factorisation (most iterations need no new one; docs/method.md §11),
  // each load step from the last converged state (started from the linear
  // extrapolation of the last two, the steps need more fresh factorisations).
  constexpr int n = 41;
  const std::vector<double> factors{0.05, 0.075, 0.1};
  statics::NewtonOptions newton;
  newton.tolerance = 1e-5;
  newton.krylov_iterations = 40;
  newton.predictor = statics::LoadPredictor::last_state;
  const CylinderRun run = run_sze_cylinder<NonlinearSolver>(sze_pinched_cylinder(n, n), factors, 0.025, newton);
  const std::vector<TabulatedPoint> table = sze_pinched_cylinder_table();
  REQUIRE(run.points.size() == factors.size());
  double worst_w = 0.0, worst_u = 0.0;
  for (std::size_t k = 0; k < run.points.size(); ++k) {
    REQUIRE(table[k].load_factor == Approx(factors[k]));
    const double w = error_percent(-run.points[k].a, table[k].first), u = error_percent(run.points[k].b, table[k].second);
    std::printf("Pinched cylinder (Sze), %d x %d, P/P_max = %.3f: -W_A %.4g (%+.2f %%), U_B %.4g (%+.2f %%)\n", n, n,
                factors[k], -run.points[k].a, w, run.points[k].b, u);
    worst_w = std::max(worst_w, std::abs(w));
    worst_u = std::max(worst_u, std::abs(u));
  }
  std::printf("Pinched cylinder (Sze): largest error %.2f %% (-W_A), %.2f %% (U_B); %d Newton iterations, %d "
              "factorisations, %ld GMRES products\n",
              worst_w, worst_u, run.report.iterations, run.report.factorisations, run.report.krylov_iterations);
  CHECK(worst_w < 1.5);
  CHECK(worst_u < 2.0);
}

TEST_CASE("Static shell: the director hourglass removes the pull-out's spurious instability", "[static][benchmarks]") {
  // The pull-out octant at 13 x 9, −U_B prescribed in steps of 0.15, the
  // tangent's negative eigenvalues counted after every step. Without the
  // director hourglass (shell/cell_hourglass.hpp) the tangent turns
  // indefinite near P/P_max = 0.34 (measured: positive definite up to 0.30,
  // one negative eigenvalue where the control stalls at 0.343) on a mode of
  // alternating director rotations; with it, none up to P_max, past the
  // paper's snap at 0.5–0.525 (where the load passes a maximum: only there
  // may one appear).
  statics::NewtonOptions newton;
  newton.tolerance = 1e-5;
  newton.max_iterations = 12;
  const auto first_indefinite = [&](bool director_hourglass) {
    const SzeCylinder cylinder = sze_pullout_cylinder(13, 9, pullout_options(director_hourglass));
    NonlinearSolver solver(cylinder.model, {cylinder.E, cylinder.nu}, cylinder.options);
    statics::PathFollower<NonlinearSolver> statics(solver, cylinder.conditions, newton);
    const statics::ControlDisplacement u_b{cylinder.b, -Vector3::UnitY()};
    for (int k = 1; statics.load_factor() < 1.0 && k <= 60; ++k) {
      try {
        statics.solve_to_displacement(u_b, 0.15 * k, 0.15);
      } catch (const Error&) {
        return statics.load_factor();  // the control stalled
      }
      const double lambda = statics.load_factor();
      if (statics.stability().negative_eigenvalues > 0 && !(lambda > 0.5 && lambda < 0.6)) return lambda;
    }
    return statics.load_factor() >= 1.0 ? 2.0 : statics.load_factor();
  };
  const double without = first_indefinite(false), with = first_indefinite(true);
  std::printf("Pull-out 13 x 9: indefinite or stalled at P/P_max %.3f without the director hourglass, %s with it\n",
              without, with > 1.5 ? "never up to P_max" : std::to_string(with).c_str());
  CHECK(without < 0.4);
  CHECK(with == 2.0);
}

TEST_CASE("Benchmark: pull-out of an open-ended cylinder, the whole path (Sze, Liu & Lo 2004, nonlinear)",
          "[validation][benchmarks]") {
  // §3.5: W_A (outward under the load), −U_B and −U_C (inward, 90° round at
  // mid-length and at the free end) against the paper's table at every
  // tabulated P/P_max up to 1, through the snap between 0.5 and 0.525 (−U_B
  // jumps, −U_C turns back). The path is followed by prescribing −U_B in steps
  // of 0.1 (the load factor solved for), with the director hourglass (without
  // it the octant turns unstable at P/P_max ≈ 0.27 on a spurious mode; the
  // test below). The readings are where the path first reaches each load
  // factor, what load control would give.
  constexpr int circumferential = 22, axial = 15;
  const SzeCylinder cylinder = sze_pullout_cylinder(circumferential, axial);
  statics::NewtonOptions newton;
  newton.tolerance = 1e-5;  // the residual floors near 1e-6 of the load here
  newton.max_iterations = 12;
  const statics::ControlDisplacement w_a{cylinder.a, Vector3::UnitX()}, u_b{cylinder.b, -Vector3::UnitY()},
      u_c{cylinder.c, -Vector3::UnitY()};
  const PathRun run = follow_path<NonlinearSolver>(cylinder.model, cylinder.E, cylinder.nu, cylinder.options,
                                                   cylinder.conditions, u_b, {w_a, u_b, u_c}, 0.1, 1.0, 80, newton);
  INFO("stopped: " << run.stopped);
  REQUIRE(run.stopped.empty());
  // The paper's response jumps between 0.5 and 0.525, so the reading at
  // 0.525 depends on where exactly each model snaps; it is held apart.
  constexpr double at_the_snap = 0.525;
  double worst = 0.0, worst_elsewhere = 0.0;
  for (const TabulatedTriple& point : sze_pullout_table()) {
    const std::vector<double> at = readings_at_load_factor(run.path, point.load_factor);
    REQUIRE(at.size() == 3);
    const double a = error_percent(at[0], point.a), b = error_percent(at[1], point.b), c = error_percent(at[2], point.c);
    std::printf("Pull-out (Sze), %d x %d, P/P_max = %.3f: W_A %.4g (%+.2f %%), -U_B %.4g (%+.2f %%), -U_C %.4g "
                "(%+.2f %%)\n",
                circumferential, axial, point.load_factor, at[0], a, at[1], b, at[2], c);
    const double largest = std::max({std::abs(a), std::abs(b), std::abs(c)});
    worst = std::max(worst, largest);
    if (std::abs(point.load_factor - at_the_snap) > 1e-12) worst_elsewhere = std::max(worst_elsewhere, largest);
  }
  std::printf("Pull-out (Sze): largest error %.2f %% (%.2f %% away from P/P_max = 0.525); %d Newton iterations, %.1f s\n",
              worst, worst_elsewhere, run.report.iterations, run.seconds);
  CHECK(worst_elsewhere < 1.2);
  CHECK(worst < 2.2);
}

namespace {

// The hinged roof's path against the paper's table: each tabulated point's
// distance to the followed curve, the load factor measured in the table's
// limit load and the deflection in the roof's rise. Prints every point and
// returns the largest distance.
double hinged_roof_largest_distance(HingedRoofCase roof, const char* name, int n, double step) {
  statics::NewtonOptions newton;
  newton.tolerance = 1e-5;
  newton.max_iterations = 12;
  const PathRun run = follow_sze_hinged_roof<NonlinearSolver>(roof, n, step, newton);
  INFO("stopped: " << run.stopped);
  REQUIRE(run.stopped.empty());
  const std::vector<LoadDeflection> table = sze_hinged_roof_table(roof);
  const double load_scale = limit_load_factor(table), rise = sze_hinged_roof(roof, n).rise;
  double worst = 0.0;
  for (const LoadDeflection& point : table) {
    const double distance = 100.0 * distance_to_path(run.path, 0, point, load_scale, rise);
    std::printf("Hinged roof (Sze), %s, %d x %d: P/P_max %+.4f, -W_C %.3f: %.2f %% off the path\n", name, n, n,
                point.load_factor, point.deflection, distance);
    worst = std::max(worst, distance);
  }
  double first_maximum = 0.0;
  for (std::size_t k = 1; k < run.path.size() && run.path[k].load_factor >= first_maximum; ++k)
    first_maximum = run.path[k].load_factor;
  std::printf("Hinged roof (Sze), %s, %d x %d: largest distance %.2f %% (of the limit load %.4f and the rise %.2f); "
              "limit load %.4f (%+.2f %%); %zu steps, %d Newton iterations, %.1f s\n",
              name, n, n, worst, load_scale, rise, first_maximum, error_percent(first_maximum, load_scale),
              run.path.size() - 1, run.report.iterations, run.seconds);
  return worst;
}

}  // namespace

TEST_CASE("Benchmark: hinged cylindrical roof, t = 12.7, snap-through (Sze, Liu & Lo 2004, nonlinear)",
          "[validation][benchmarks]") {
  // §3.8: the centre's deflection −W_C prescribed in steps of 1 (the load
  // factor solved for) through the load's maximum and minimum to the
  // table's last point, P/P_max = 1.0835; every tabulated point within 2 %
  // of the followed curve (distances in the limit load and the rise).
  CHECK(hinged_roof_largest_distance(HingedRoofCase::thick, "t = 12.7", 13, 1.0) < 2.0);
}

TEST_CASE("Benchmark: hinged cylindrical roof, t = 6.35, snap-back (Sze, Liu & Lo 2004, nonlinear)",
          "[validation][benchmarks]") {
  // §3.8: by arc length (steps of at most 0.5 of the particles'
  // root-mean-square motion) through the snap-back, where the load factor
  // turns negative and the centre's deflection turns back, to the table's
  // last point, P/P_max = 1.0313.
  CHECK(hinged_roof_largest_distance(HingedRoofCase::thin, "t = 6.35", 17, 0.5) < 2.0);
}
