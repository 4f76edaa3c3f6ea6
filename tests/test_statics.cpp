// The public static analysis (sphshell/statics): bad input named before
// anything moves, and the linear buckling analysis against closed forms.
#include <sphshell/approx/mls.hpp>
#include <sphshell/kernel/cubic_spline.hpp>
#include <sphshell/material/elastic.hpp>
#include <sphshell/solver.hpp>
#include <sphshell/statics/all.hpp>
#include <sphshell/thickness/gauss.hpp>

#include "support/vtu_reader.hpp"

#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <limits>
#include <string>
#include <utility>
#include <vector>

using namespace sphshell;

namespace {

using NonlinearSolver = Solver<approx::MLS<kernel::CubicSpline>, thickness::Gauss<3>, material::Elastic>;

constexpr double pi = 3.14159265358979323846;

// Trapezoidal shares of an edge load on n particles along the edge.
std::vector<double> edge_shares(int n) {
  std::vector<double> share(n, 1.0 / (n - 1));
  share.front() = share.back() = 0.5 / (n - 1);
  return share;
}

// The cantilever strip of Sze, Liu & Lo (2004): L = 10, b = 1, t = 0.1,
// E = 1.2e6, ν = 0, clamped at x = 0, nx × ny particles.
struct Strip {
  static constexpr double L = 10.0, b = 1.0, t = 0.1, E = 1.2e6;
  ShellModel model;
  statics::Conditions conditions;
  Strip(int nx, int ny) : model(ShellModel::rectangular_plate(L, b, nx, ny, t)), conditions(model.particle_count()) {
    conditions.clamp(model.set("x_min"));
  }
  double EI() const { return E * b * t * t * t / 12.0; }
  // An axial dead load −P along x shared by the tip particles.
  void compress_tip(double P) {
    const ParticleSet tip = model.set("x_max");
    const std::vector<double> share = edge_shares(static_cast<int>(tip.size()));
    for (std::size_t k = 0; k < tip.size(); ++k) conditions.add_force({tip[k]}, Vector3(-P * share[k], 0.0, 0.0));
  }
};

bool same_configuration(const NonlinearSolver& solver, const std::vector<Vector3>& x, const std::vector<Vector3>& d) {
  return solver.positions() == x && solver.directors() == d;
}

}  // namespace

TEST_CASE("Statics: bad input is an Error naming it, and the solver is left as it was", "[statics]") {
  Strip strip(11, 3);
  strip.compress_tip(1.0);
  strip.conditions.add_force(strip.model.set("x_max"), Vector3(0.0, 0.0, 0.1));
  NonlinearSolver solver(strip.model, {Strip::E, 0.0});
  const std::vector<Vector3> x0 = solver.positions(), d0 = solver.directors();
  statics::PathFollower<NonlinearSolver> path(solver, strip.conditions);

  SECTION("a control particle that is held") {
    const int root = strip.model.set("x_min").front();
    CHECK_THROWS_WITH(path.solve_to_displacement({{{root, 1.0}}, Vector3::UnitZ()}, 0.1, 0.05),
                      Catch::Contains("ControlDisplacement particle = " + std::to_string(root)) &&
                          Catch::Contains("held along the control direction"));
    CHECK_THROWS_WITH(path.solve_to_displacement({{{-1, 1.0}}, Vector3::UnitZ()}, 0.1, 0.05),
                      Catch::Contains("ControlDisplacement particle = -1"));
    CHECK_THROWS_WITH(path.solve_to_displacement({{{root + 1, 1.0}}, Vector3::UnitZ()}, 0.1, 0.0),
                      Catch::Contains("displacement step = 0"));
  }
  SECTION("an arc length <= 0") {
    CHECK_THROWS_WITH(path.arc_length_step(0.0), Catch::Contains("arc length = 0") && Catch::Contains("> 0"));
    CHECK_THROWS_WITH(path.arc_length_step(-0.5), Catch::Contains("arc length = -0.5"));
    CHECK_THROWS_WITH(path.solve_to(1.0, 0.0), Catch::Contains("load step = 0"));
  }
  SECTION("a tangent reuse contraction outside [0, 1)") {
    for (const double contraction : {-0.1, 1.0}) {
      statics::NewtonOptions options;
      options.tangent_reuse_contraction = contraction;
      CHECK_THROWS_WITH(statics::PathFollower<NonlinearSolver>(solver, strip.conditions, options),
                        Catch::Contains("NewtonOptions::tangent_reuse_contraction") && Catch::Contains("[0, 1)"));
    }
  }
  SECTION("GMRES options outside their ranges") {
    statics::NewtonOptions options;
    options.krylov_iterations = -1;
    CHECK_THROWS_WITH(statics::PathFollower<NonlinearSolver>(solver, strip.conditions, options),
                      Catch::Contains("NewtonOptions::krylov_iterations = -1") && Catch::Contains(">= 0"));
    for (const double tolerance : {0.0, 1.0, -0.5, std::numeric_limits<double>::quiet_NaN()}) {
      options.krylov_iterations = 10;
      options.krylov_tolerance = tolerance;
      CHECK_THROWS_WITH(statics::PathFollower<NonlinearSolver>(solver, strip.conditions, options),
                        Catch::Contains("NewtonOptions::krylov_tolerance = ") && Catch::Contains("(0, 1)"));
    }
  }
  SECTION("a buckling reference load of zero") {
    Strip unloaded(11, 3);
    CHECK_THROWS_WITH(statics::linear_buckling(solver, unloaded.conditions),
                      Catch::Contains("buckling reference load") && Catch::Contains("non-zero"));
  }
  SECTION("a mechanism: the tangent singular at the start") {
    statics::Conditions free(strip.model.particle_count());  // no support: six rigid motions
    free.add_force(strip.model.set("x_max"), Vector3(0.0, 0.0, 0.1));
    statics::PathFollower<NonlinearSolver> loose(solver, free);
    CHECK_THROWS_WITH(loose.solve_to(1.0, 0.5), Catch::Contains("mechanism"));
    CHECK_THROWS_WITH(loose.arc_length_step(0.1), Catch::Contains("mechanism"));
    CHECK_THROWS_WITH(loose.linear_solve(1.0), Catch::Contains("mechanism"));
    CHECK_THROWS_WITH(statics::linear_buckling(solver, free), Catch::Contains("mechanism"));
    // Too few holds: only the root's x held, the strip free to move across and turn.
    statics::Conditions pinned(strip.model.particle_count());
    pinned.hold_translation(strip.model.set("x_min"), Vector3::UnitX());
    pinned.add_force(strip.model.set("x_max"), Vector3(0.0, 0.0, 0.1));
    statics::PathFollower<NonlinearSolver> rolling(solver, pinned);
    CHECK_THROWS_WITH(rolling.solve_to(1.0, 0.5), Catch::Contains("mechanism"));
  }
  CHECK(same_configuration(solver, x0, d0));
  CHECK(path.load_factor() == 0.0);
  // Unharmed: the same follower still solves.
  path.solve_to(0.5, 0.5);
  CHECK(path.load_factor() == 0.5);
}

TEST_CASE("Statics: a step that cannot converge is an Error naming its number, the residual reached and the "
          "iteration, and the solver stays at the last converged state",
          "[statics]") {
  // The strip bent by a tip force to about a third of its length: one small
  // load step converges within the budget of four iterations; the next one,
  // to the whole load without halvings, needs more than four (full Newton
  // takes 15 for two steps of half the load to 1e-8).
  Strip strip(11, 3);
  strip.conditions.add_force(strip.model.set("x_max"), Vector3(0.0, 0.0, 1.0 / 3.0));
  NonlinearSolver solver(strip.model, {Strip::E, 0.0});
  statics::NewtonOptions options;
  options.max_iterations = 4;
  options.max_halvings = 0;
  statics::PathFollower<NonlinearSolver> path(solver, strip.conditions, options);
  path.solve_to(0.02, 0.02);
  REQUIRE(path.report().load_steps == 1);
  const std::vector<Vector3> x1 = solver.positions(), d1 = solver.directors();
  std::string message;
  try {
    path.solve_to(1.0, 1.0);
  } catch (const Error& e) {
    message = e.what();
  }
  std::printf("A step that cannot converge: %s\n", message.c_str());
  CHECK_THAT(message, Catch::Contains("at load factor 1") && Catch::Contains("at load step 2 (counted from 1)") &&
                          Catch::Contains("NewtonOptions::max_halvings = 0") &&
                          Catch::Contains("lowest relative residual |r|/|lambda f_ext| = ") &&
                          Catch::Contains("was reached at iteration ") &&
                          Catch::Contains("NewtonOptions::max_iterations = 4") &&
                          Catch::Contains("last converged state, load factor 0.02"));
  // The residual named lies above the tolerance, at an iteration of the budget.
  const std::size_t at = message.find("= ", message.find("lowest relative residual"));
  REQUIRE(at != std::string::npos);
  CHECK(std::stod(message.substr(at + 2)) > options.tolerance);
  const std::size_t iteration = message.find("at iteration ");
  REQUIRE(iteration != std::string::npos);
  const int reached = std::stoi(message.substr(iteration + 13));
  CHECK(reached >= 0);
  CHECK(reached < options.max_iterations);
  CHECK(same_configuration(solver, x1, d1));
  CHECK(path.load_factor() == 0.02);
  CHECK(path.report().load_steps == 1);
}

TEST_CASE("Statics: linear buckling of an Euler strip", "[validation][statics]") {
  // The cantilever strip under an axial tip load: P_cr = π² EI / (4 L²)
  // (Mindlin's shear lowers it by P_cr / (κ G A), 5·10⁻⁵ here). The
  // reference load is P_cr itself, so the lowest factor is 1.
  Strip strip(21, 3);
  const double euler = pi * pi * strip.EI() / (4.0 * Strip::L * Strip::L);
  strip.compress_tip(euler);
  NonlinearSolver solver(strip.model, {Strip::E, 0.0});
  const std::vector<Vector3> x0 = solver.positions(), d0 = solver.directors();
  statics::BucklingOptions options;
  options.modes = 2;
  const statics::BucklingResult result = statics::linear_buckling(solver, strip.conditions, options);
  REQUIRE(result.modes.size() == 2);
  const double first = result.modes[0].load_factor, second = result.modes[1].load_factor;
  std::printf("Euler strip (21 x 3), linear buckling: P1 = %.6f P_cr (%+.3f %%), P2 = %.5f P_cr (Euler: 9); %d "
              "subspace iterations, %ld force evaluations\n",
              first, 100.0 * (first - 1.0), second, result.iterations, result.force_evaluations);
  CHECK(first == Approx(1.0).epsilon(5e-3));
  CHECK(second == Approx(9.0).epsilon(3e-2));
  // The first mode bends the strip out of its plane, the tip moving most.
  const int tip = 20 + 21;  // the tip particle on the centre line
  const Vector3 motion = result.modes[0].translation[static_cast<std::size_t>(tip)];
  CHECK(std::abs(motion.z()) == Approx(1.0));
  CHECK(std::abs(motion.x()) < 1e-6);
  CHECK(same_configuration(solver, x0, d0));

  // The modes as frames, read back by the tests' own VTU reader: one file
  // per mode over the strip's cells, listed by mode number, the load factors
  // in the table to the last digit.
  const std::string folder = "statics_buckling_modes";
  std::filesystem::remove_all(folder);
  io::VtuFormat exact;
  exact.precision = io::VtuPrecision::float64;
  statics::write_buckling_modes(folder, strip.model, x0, result, exact);
  const std::vector<test_support::PvdEntry> listed = test_support::read_pvd(folder + "/buckling_modes.pvd");
  REQUIRE(listed.size() == 2);
  for (std::size_t k = 0; k < listed.size(); ++k) {
    CHECK(listed[k].time == static_cast<double>(k + 1));
    const test_support::Vtu vtu = test_support::read_vtu(folder + "/" + listed[k].file);
    CHECK(vtu.points() == strip.model.particle_count());
    CHECK(vtu.cells() == strip.model.cells().size());
    const std::vector<double>& written = vtu.array("PointData", "mode_translation").values;
    REQUIRE(written.size() == 3 * strip.model.particle_count());
    std::size_t differing = 0;
    for (std::size_t i = 0; i < strip.model.particle_count(); ++i)
      for (int c = 0; c < 3; ++c) differing += written[3 * i + c] != result.modes[k].translation[i][c];
    CHECK(differing == 0);
  }
  std::ifstream table(folder + "/buckling_modes.csv");
  std::string header, row1;
  std::getline(table, header);
  std::getline(table, row1);
  CHECK(header == "mode,load_factor,file");
  CHECK(std::stod(row1.substr(2)) == first);
  CHECK_THROWS_WITH(statics::write_buckling_modes(folder, strip.model, x0, statics::BucklingResult{}),
                    Catch::Contains("BucklingResult::modes"));
}

TEST_CASE("Statics: linear buckling of a simply supported square plate under uniaxial compression",
          "[validation][statics]") {
  // a = b = 1, t = 0.01, E = 1e9, ν = 0.3, simply supported on all edges
  // (w = 0; the twist along each edge held, the Kirchhoff plate's hard
  // support), compressed along x by a uniform edge stress σ. Kirchhoff plate
  // theory: σ_cr = k π² D / (b² t), k = 4 for a square (one half-wave each
  // way; Timoshenko & Gere, Theory of Elastic Stability, §9.2). The
  // reference stress is σ_cr, so the lowest factor is 1.
  const double a = 1.0, t = 0.01, E = 1e9, nu = 0.3;
  const double D = E * t * t * t / (12.0 * (1.0 - nu * nu));
  const double critical = 4.0 * pi * pi * D / (a * a * t);
  double error = 0.0;
  for (int n : {11, 15, 19}) {
    const ShellModel model = ShellModel::rectangular_plate(a, a, n, n, t);
    statics::Conditions conditions(model.particle_count());
    conditions.hold_translation(model.set("boundary"), Vector3::UnitZ());
    for (const char* edge : {"x_min", "x_max"}) conditions.hold_rotation(model.set(edge), Vector3::UnitX());
    for (const char* edge : {"y_min", "y_max"}) conditions.hold_rotation(model.set(edge), Vector3::UnitY());
    const ParticleSet loaded_edge = model.set("x_max"), held_edge = model.set("x_min");
    conditions.hold_translation(held_edge, Vector3::UnitX());
    conditions.hold_translation({held_edge[held_edge.size() / 2]}, Vector3::UnitY());
    const std::vector<double> share = edge_shares(n);
    for (int k = 0; k < n; ++k) conditions.add_force({loaded_edge[k]}, Vector3(-critical * t * a * share[k], 0.0, 0.0));
    NonlinearSolver solver(model, {E, nu});
    const statics::BucklingResult result = statics::linear_buckling(solver, conditions);
    REQUIRE(result.modes.size() == 1);
    error = result.modes[0].load_factor - 1.0;
    std::printf("Square plate %d x %d, linear buckling: sigma1 = %.6f sigma_cr (%+.3f %%); %d subspace iterations, "
                "%ld force evaluations\n",
                n, n, result.modes[0].load_factor, 100.0 * error, result.iterations, result.force_evaluations);
  }
  CHECK(std::abs(error) < 1e-2);
}

TEST_CASE("Statics: linear buckling of an axially compressed cylinder against the classical value",
          "[validation][statics]") {
  // R = 1, R/t = 50, L = R, E = 1e9, ν = 0.3; both ends held radially and
  // circumferentially (w = v = 0), rotations free (simply supported), the
  // bottom end held axially, the top end carrying a uniform axial load. The
  // classical value σ_cl = E t / (R √(3(1 − ν²))) (Timoshenko & Gere, §11.4)
  // assumes a membrane prebuckling state and a cylinder long against the
  // buckle's half-wave 1.73 √(R t) = 0.24 R (Batdorf's Z = L²√(1 − ν²)/(R t)
  // = 48 here); the linear prebuckling state holds the ends' Poisson
  // expansion back, a bending boundary layer of length ~√(R t) that barely
  // moves the lowest factor. The lowest modes lie on Koiter's circle (many
  // wave numbers at one load): the analysis finds a checkerboard mode, and
  // its factor approaches 1 from above as the spacing shrinks (measured:
  // +5.2 % at 48 × 13 particles, +1.27 % at 72 × 19).
  const double R = 1.0, t = R / 50.0, L = R, E = 1e9, nu = 0.3;
  const ShellModel model = ShellModel::cylindrical_panel(R, L, 2.0 * pi, 72, 19, t);
  statics::Conditions conditions(model.particle_count());
  for (int axis = 0; axis < 3; ++axis)
    conditions.hold_translation(model.set("z_min"), Vector3::Unit(axis));
  const ParticleSet top = model.set("z_max");
  const double classical = E * t / (R * std::sqrt(3.0 * (1.0 - nu * nu)));
  for (int i : top) {
    const Vector3 x = model.particle_position[std::size_t(i)];
    conditions.hold_translation({i}, Vector3(x.x(), x.y(), 0.0));
    conditions.hold_translation({i}, Vector3(-x.y(), x.x(), 0.0));
    conditions.add_force({i}, Vector3(0.0, 0.0, -classical * 2.0 * pi * R * t / static_cast<double>(top.size())));
  }
  NonlinearSolver solver(model, {E, nu});
  statics::BucklingOptions options;
  options.tolerance = 1e-6;  // the cluster on Koiter's circle converges slowly; 1e-6 of λ is far below the error
  options.max_iterations = 1000;
  const statics::BucklingResult result = statics::linear_buckling(solver, conditions, options);
  REQUIRE(result.modes.size() == 1);
  const double factor = result.modes[0].load_factor;
  std::printf("Compressed cylinder R/t = 50, 72 x 19, linear buckling: sigma1 = %.5f sigma_cl (%+.2f %%); %d subspace "
              "iterations, %ld force evaluations\n",
              factor, 100.0 * (factor - 1.0), result.iterations, result.force_evaluations);
  CHECK(factor > 1.0);
  CHECK(factor < 1.02);
  // A shell mode, not an end or rigid motion: the largest radial motion is
  // away from both ends.
  double largest = 0.0, z_of_largest = 0.0;
  for (std::size_t i = 0; i < model.particle_count(); ++i) {
    const Vector3 x = model.particle_position[i], u = result.modes[0].translation[i];
    const double radial = std::abs(u.x() * x.x() + u.y() * x.y()) / R;
    if (radial > largest) largest = radial, z_of_largest = x.z();
  }
  CHECK(z_of_largest > 0.1 * L);
  CHECK(z_of_largest < 0.9 * L);
}

namespace {

using LinearPlateSolver = Solver<approx::MLS<kernel::CubicSpline>, thickness::Gauss<2>, material::Elastic>;

// Kirchhoff's clamped square plate under uniform pressure: w_c = 0.00126532 q L⁴/D
// (Timoshenko & Woinowsky-Krieger, Theory of Plates and Shells, Table 35);
// at L/d = 500 the transverse shear adds 10⁻⁴ of it.
constexpr double kirchhoff_clamped = 0.00126532;

// The thin clamped plate: L = 1 m, L/d = 500, E = 210 GPa, ν = 0.3, linear,
// q = 1 kPa, n × n particles; Newton (StaticMass::tangent) at `tolerance`.
struct ThinPlateSolve {
  double coefficient = 0.0;  // w_c D / (q L⁴)
  std::vector<double> residuals;
  solver::StaticResult result;
};
ThinPlateSolve thin_plate_newton(int n, double tolerance) {
  const double d = 1.0 / 500.0, q = 1e3, E = 210e9, nu = 0.3;
  SolverOptions options;
  options.nonlinear = false;
  LinearPlateSolver solver(ShellModel::rectangular_plate(1.0, 1.0, n, n, d), {E, nu}, options);
  solver.clamp(solver.model().set("boundary"));
  solver.add_uniform_pressure(solver.model().all_particles(), q, time_function::Step{}, PressureDirection::fixed);
  solver::StaticParameters parameters;
  parameters.mass = solver::StaticMass::tangent;
  parameters.tolerance = tolerance;
  // Newton's steps by GMRES on the kept factorisation (one factorisation in
  // all), each to 1e-6 of its residual, so the iterates follow full Newton's.
  parameters.krylov_iterations = 40;
  parameters.krylov_tolerance = 1e-6;
  ThinPlateSolve solve;
  solve.result = solver.solve_static(parameters, [&](const solver::StaticIteration& it) {
    solve.residuals.push_back(it.residual);
  });
  const double D = E * d * d * d / (12.0 * (1.0 - nu * nu));
  solve.coefficient = -solver.displacement(solver.model().set("centre")[0]).z() * D / q;
  return solve;
}

// The first iteration whose residual is at most `level` (-1: none).
int first_below(const std::vector<double>& residuals, double level) {
  for (std::size_t k = 0; k < residuals.size(); ++k)
    if (residuals[k] <= level) return static_cast<int>(k);
  return -1;
}

}  // namespace

TEST_CASE("Statics: Newton on the thin clamped plate (L/d = 500) reaches 1e-8 at 51 x 51 and 1e-10 at 31 x 31",
          "[validation][statics]") {
  // The line search damps the first steps (the linear option keeps unit
  // directors, so the thin plate's stiff transverse shear is not linear in
  // a finite rotation); then the iteration converges. At 51 x 51 the
  // residual stays near 2.4e-10 however long Newton goes on (a tangent
  // error would shrink it by a constant factor per iteration): the rounding
  // of forces that are differences of terms (L/d)^2 larger than themselves
  // (the shear strain w' - theta), about 5 eps (L/d)^2 of them whatever the
  // load or the difference step (docs/validation.md, "Newton on a thin
  // plate"), so 51 x 51 is asked 1e-8 and 31 x 31, whose floor is lower, 1e-10.
  const ThinPlateSolve fine = thin_plate_newton(51, 1e-8);
  std::printf("Thin clamped plate 51 x 51, L/d = 500: w D/(qL^4) = %.8f (%+.3f %% from Kirchhoff); residual %.3e "
              "after %ld Newton iterations, %ld factorisations, %ld force evaluations\n",
              fine.coefficient, 100.0 * (fine.coefficient / kirchhoff_clamped - 1.0), fine.result.residual,
              fine.result.iterations, fine.result.factorisations, fine.result.force_evaluations);
  CHECK(fine.result.converged);
  CHECK(fine.result.factorisations < fine.result.iterations);
  CHECK(fine.result.residual <= 1e-8);
  CHECK(fine.result.iterations <= 11);
  CHECK(fine.coefficient == Approx(kirchhoff_clamped).epsilon(0.01));
  const ThinPlateSolve coarse = thin_plate_newton(31, 1e-10);
  std::printf("Thin clamped plate 31 x 31, L/d = 500: w D/(qL^4) = %.8f (%+.3f %%); residual %.3e after %ld Newton "
              "iterations (1e-8 after %d)\n",
              coarse.coefficient, 100.0 * (coarse.coefficient / kirchhoff_clamped - 1.0), coarse.result.residual,
              coarse.result.iterations, first_below(coarse.residuals, 1e-8));
  CHECK(coarse.result.converged);
  CHECK(coarse.result.residual <= 1e-10);
  CHECK(coarse.result.iterations <= 8);
  CHECK(coarse.coefficient == Approx(kirchhoff_clamped).epsilon(0.02));
}

TEST_CASE("Statics: the kept factorisation (modified Newton) reaches the equilibrium full Newton reaches",
          "[statics]") {
  // The strip bent by a tip force to a deflection of about a third of its
  // length, in two load steps: with a fresh tangent at every iteration and
  // with one kept while the residual falls by 0.9 per iteration (which keeps
  // it as long as possible), and by GMRES on the kept factorisation
  // (NewtonOptions::krylov_iterations). All stop below the relative residual
  // 1e-8, so their tip deflections agree to about that.
  auto tip_deflection = [](statics::NewtonOptions options, statics::NewtonReport& report) {
    Strip strip(11, 3);
    strip.conditions.add_force(strip.model.set("x_max"), Vector3(0.0, 0.0, 1.0 / 3.0));
    NonlinearSolver solver(strip.model, {Strip::E, 0.0});
    options.tolerance = 1e-8;
    statics::PathFollower<NonlinearSolver> path(solver, strip.conditions, options);
    path.solve_to(1.0, 0.5);
    report = path.report();
    return path.displacement(strip.model.set("x_max")[1]).z();
  };
  statics::NewtonReport newton_report, modified_report, krylov_report;
  statics::NewtonOptions full, kept, krylov_steps;
  full.tangent_reuse_contraction = 0.0;
  kept.tangent_reuse_contraction = 0.9;
  krylov_steps.krylov_iterations = 20;
  const double newton = tip_deflection(full, newton_report);
  const double modified = tip_deflection(kept, modified_report);
  const double krylov = tip_deflection(krylov_steps, krylov_report);
  std::printf("Strip tip deflection: full Newton %.10f (%d iterations, %d factorisations), kept factorisation %.10f "
              "(%d iterations, %d factorisations), GMRES %.10f (%d iterations, %d factorisations, %ld products)\n",
              newton, newton_report.iterations, newton_report.factorisations, modified, modified_report.iterations,
              modified_report.factorisations, krylov, krylov_report.iterations, krylov_report.factorisations,
              krylov_report.krylov_iterations);
  CHECK(newton > 0.2 * Strip::L);
  CHECK(modified == Approx(newton).epsilon(1e-6));
  CHECK(krylov == Approx(newton).epsilon(1e-6));
  // Full Newton factorises at every iteration; GMRES keeps a factorisation
  // as its preconditioner across iterations and the two load steps.
  CHECK(newton_report.factorisations == newton_report.iterations);
  CHECK(krylov_report.krylov_iterations > 0);
  CHECK(krylov_report.factorisations < newton_report.factorisations);
}

TEST_CASE("Statics: a load step starts where NewtonOptions::predictor says", "[statics]") {
  // The strip under a tip force in load steps 0 → 0.5 → 0.75 → 1. At the
  // third step the test computes the two possible starts itself: the state
  // converged at 0.75 (LoadPredictor::last_state), and that state moved on by
  // the whole last step (LoadPredictor::extrapolated: equal steps, so the
  // translations advance by x(0.75) − x(0.5) and each director turns once more
  // by the rotation that took it from d(0.5) to d(0.75)); their relative
  // residuals at λ = 1 must be what the third step started from.
  struct Starts {
    double last_state, extrapolated, reported;
    double tip_last_state, tip_extrapolated, tip_converged;  // tip deflections (m)
  };
  auto third_step = [](statics::LoadPredictor predictor, double tip_force) {
    Strip strip(11, 3);
    strip.conditions.add_force(strip.model.set("x_max"), Vector3(0.0, 0.0, tip_force));
    NonlinearSolver solver(strip.model, {Strip::E, 0.0});
    statics::NewtonOptions options;
    options.tolerance = 1e-8;
    options.predictor = predictor;
    statics::PathFollower<NonlinearSolver> path(solver, strip.conditions, options);
    path.solve_to(0.5, 0.5);
    const std::vector<Vector3> x_half = solver.positions(), d_half = solver.directors();
    path.solve_to(0.75, 0.25);
    const std::vector<Vector3> x = solver.positions(), d = solver.directors();
    statics::TangentAssembly<NonlinearSolver>& assembly = path.assembly();
    auto relative_residual_at_one = [&](std::vector<Vector3> xs, std::vector<Vector3> ds) {
      assembly.set_configuration(std::move(xs), std::move(ds));
      const statics::DegreesOfFreedom dofs = assembly.degrees_of_freedom();
      return assembly.residual(dofs, 1.0).norm() / assembly.load_norm(dofs, 1.0);
    };
    const int tip = strip.model.set("x_max")[1];
    std::vector<Vector3> x_ahead(x.size()), d_ahead(d.size());
    for (std::size_t i = 0; i < x.size(); ++i) {
      x_ahead[i] = 2.0 * x[i] - x_half[i];
      d_ahead[i] = Eigen::Quaterniond::FromTwoVectors(d_half[i], d[i]) * d[i];
    }
    Starts starts{};
    starts.tip_last_state = path.displacement(tip).z();
    starts.tip_extrapolated = starts.tip_last_state + (x[tip] - x_half[tip]).z();
    starts.extrapolated = relative_residual_at_one(x_ahead, d_ahead);
    starts.last_state = relative_residual_at_one(x, d);  // and the solver back at the converged state
    const int steps = path.report().load_steps;
    path.solve_to(1.0, 0.25);
    CHECK(path.report().load_steps == steps + 1);  // one step, not halved
    starts.reported = path.report().load_step_start_residual;
    starts.tip_converged = path.displacement(tip).z();
    return starts;
  };
  // The tip force of 1/3 bends the strip to a deflection near L/3. There
  // the straight-line extrapolation of the turning strip stretches its
  // membrane: it starts nearer the converged deflection but at a far larger
  // residual than the last state (the case LoadPredictor::last_state is for).
  const double tip_force = 1.0 / 3.0;
  const Starts from_last = third_step(statics::LoadPredictor::last_state, tip_force);
  const Starts from_extrapolation = third_step(statics::LoadPredictor::extrapolated, tip_force);
  std::printf("Strip, third load step starts at relative residual %.6e (last state; computed %.6e) and %.6e "
              "(extrapolated; computed %.6e); tip deflection %.6f, %.6f at the starts, %.6f converged\n",
              from_last.reported, from_last.last_state, from_extrapolation.reported, from_extrapolation.extrapolated,
              from_extrapolation.tip_last_state, from_extrapolation.tip_extrapolated,
              from_extrapolation.tip_converged);
  CHECK(from_last.reported == Approx(from_last.last_state).epsilon(1e-9));
  CHECK(from_extrapolation.reported == Approx(from_extrapolation.extrapolated).epsilon(1e-6));
  // The two starts differ by far more than the tolerances above.
  CHECK(std::abs(std::log(from_extrapolation.reported / from_last.reported)) > std::log(2.0));
  // The path is smooth in the deflection: the extrapolation starts nearer it.
  CHECK(std::abs(from_extrapolation.tip_extrapolated - from_extrapolation.tip_converged) <
        0.5 * std::abs(from_extrapolation.tip_last_state - from_extrapolation.tip_converged));
}

TEST_CASE("Statics: a displacement-control or arc-length step starts where the extrapolation in the control says",
          "[statics]") {
  // The strip under a tip force, its path followed by the tip's deflection
  // (steps of 0.5) and by arc length (steps of 0.3). Before the third step
  // the test extrapolates the last two converged states and load factors
  // itself, by the ratio of the step to the last one (1 for the equal
  // deflection steps; the arc length over the last step's root-mean-square
  // motion): the translations linearly, each director turned on by that
  // ratio of its last rotation. The relative residual there must be what the
  // third step reports it started from.
  Strip strip(11, 3);
  strip.conditions.add_force(strip.model.set("x_max"), Vector3(0.0, 0.0, 1.0 / 3.0));
  const int tip = strip.model.set("x_max")[1];
  auto extrapolated_residual = [](statics::TangentAssembly<NonlinearSolver>& assembly,
                                  const std::vector<Vector3>& x_before, const std::vector<Vector3>& d_before,
                                  double lambda_before, double lambda, double ratio) {
    const std::vector<Vector3> x = assembly.solver().positions(), d = assembly.solver().directors();
    std::vector<Vector3> x_ahead(x.size()), d_ahead(d.size());
    for (std::size_t i = 0; i < x.size(); ++i) {
      x_ahead[i] = x[i] + ratio * (x[i] - x_before[i]);
      const Vector3 axis = d_before[i].cross(d[i]);
      const double angle = std::atan2(axis.norm(), d_before[i].dot(d[i]));
      d_ahead[i] = axis.norm() > 0.0 ? Eigen::AngleAxisd(ratio * angle, axis.normalized()) * d[i] : d[i];
    }
    const double lambda_ahead = lambda + ratio * (lambda - lambda_before);
    assembly.set_configuration(x_ahead, d_ahead);
    const statics::DegreesOfFreedom dofs = assembly.degrees_of_freedom();
    const double relative = assembly.residual(dofs, lambda_ahead).norm() / assembly.load_norm(dofs, lambda_ahead);
    assembly.set_configuration(x, d);
    return relative;
  };
  statics::NewtonOptions options;
  options.tolerance = 1e-8;
  {
    NonlinearSolver solver(strip.model, {Strip::E, 0.0});
    statics::PathFollower<NonlinearSolver> path(solver, strip.conditions, options);
    const statics::ControlDisplacement w_tip{{{tip, 1.0}}, Vector3::UnitZ()};
    path.solve_to_displacement(w_tip, 0.5, 0.5);
    CHECK(path.report().load_step_start_residual == 0.0);  // from the unloaded state
    const std::vector<Vector3> x_before = solver.positions(), d_before = solver.directors();
    const double lambda_before = path.load_factor();
    path.solve_to_displacement(w_tip, 1.0, 0.5);
    const double computed =
        extrapolated_residual(path.assembly(), x_before, d_before, lambda_before, path.load_factor(), 1.0);
    const int steps = path.report().load_steps;
    path.solve_to_displacement(w_tip, 1.5, 0.5);
    REQUIRE(path.report().load_steps == steps + 1);  // one step, not halved
    const double reported = path.report().load_step_start_residual;
    std::printf("Strip, third displacement-control step starts at relative residual %.6e (computed %.6e)\n", reported,
                computed);
    CHECK(computed > 1e-6);
    CHECK(reported == Approx(computed).epsilon(1e-6));
  }
  {
    NonlinearSolver solver(strip.model, {Strip::E, 0.0});
    statics::PathFollower<NonlinearSolver> path(solver, strip.conditions, options);
    const double length = 0.3;
    REQUIRE(path.arc_length_step(length) == length);
    CHECK(path.report().load_step_start_residual == 0.0);  // from the unloaded state
    const std::vector<Vector3> x_before = solver.positions(), d_before = solver.directors();
    const double lambda_before = path.load_factor();
    REQUIRE(path.arc_length_step(length) == length);
    double squared = 0.0;
    for (std::size_t i = 0; i < x_before.size(); ++i) squared += (solver.positions()[i] - x_before[i]).squaredNorm();
    const double last_length = std::sqrt(squared / static_cast<double>(x_before.size()));
    const double computed = extrapolated_residual(path.assembly(), x_before, d_before, lambda_before,
                                                  path.load_factor(), length / last_length);
    REQUIRE(path.arc_length_step(length) == length);
    const double reported = path.report().load_step_start_residual;
    std::printf("Strip, third arc-length step starts at relative residual %.6e (computed %.6e)\n", reported, computed);
    CHECK(computed > 1e-6);
    CHECK(reported == Approx(computed).epsilon(1e-6));
  }
}

TEST_CASE("Statics: GMRES solves a nonsymmetric system to the tolerance asked, with and without a preconditioner",
          "[statics]") {
  // A convection–diffusion matrix (tridiagonal: a diagonal growing from 4
  // to 7, −1.3 below and −0.7 above): the solution checked against Eigen's
  // dense LU, the residual against the tolerance; an inexact preconditioner
  // (the diagonal) needs more products than the exact one (the LU itself,
  // one product).
  const int n = 60;
  Eigen::MatrixXd a = Eigen::MatrixXd::Zero(n, n);
  for (int i = 0; i < n; ++i) {
    a(i, i) = 4.0 + 3.0 * i / n;
    if (i > 0) a(i, i - 1) = -1.3;
    if (i + 1 < n) a(i, i + 1) = -0.7;
  }
  Eigen::VectorXd b(n);
  for (int i = 0; i < n; ++i) b[i] = std::sin(1.0 + 0.75 * i);
  const Eigen::VectorXd exact = a.partialPivLu().solve(b);
  const auto apply = [&](const Eigen::VectorXd& v) { return Eigen::VectorXd(a * v); };
  Eigen::VectorXd x;
  const statics::KrylovSolve plain =
      statics::gmres(apply, [](const Eigen::VectorXd& v) { return v; }, b, 1e-10, n, x);
  CHECK(plain.converged);
  CHECK(plain.iterations <= n);  // in exact arithmetic at most n: the Krylov space is then the whole space
  CHECK((b - a * x).norm() <= 1.01e-10 * b.norm());
  CHECK((x - exact).norm() <= 1e-8 * exact.norm());
  CHECK(plain.relative_residual == Approx((b - a * x).norm() / b.norm()).epsilon(1e-3).margin(1e-14));
  const Eigen::PartialPivLU<Eigen::MatrixXd> lu(a);
  const statics::KrylovSolve exact_preconditioner =
      statics::gmres(apply, [&](const Eigen::VectorXd& v) { return Eigen::VectorXd(lu.solve(v)); }, b, 1e-10, n, x);
  CHECK(exact_preconditioner.iterations == 1);
  CHECK((x - exact).norm() <= 1e-10 * exact.norm());
  const statics::KrylovSolve jacobi =
      statics::gmres(apply, [&](const Eigen::VectorXd& v) { return Eigen::VectorXd(v.cwiseQuotient(a.diagonal())); }, b,
                     1e-10, n, x);
  CHECK(jacobi.converged);
  CHECK(jacobi.iterations > exact_preconditioner.iterations);
  CHECK((x - exact).norm() <= 1e-8 * exact.norm());
  // A budget too small: not converged, the best iterate still lowers the residual.
  const statics::KrylovSolve short_budget =
      statics::gmres(apply, [](const Eigen::VectorXd& v) { return v; }, b, 1e-10, 3, x);
  CHECK_FALSE(short_budget.converged);
  CHECK(short_budget.iterations == 3);
  CHECK((b - a * x).norm() < b.norm());
  CHECK(short_budget.relative_residual == Approx((b - a * x).norm() / b.norm()).epsilon(1e-6));
  // The identity plus a rank-3 nonsymmetric part: its minimal polynomial has
  // degree at most 4, so GMRES ends in at most 4 products (to rounding), at
  // Eigen's direct solution.
  Eigen::MatrixXd u(n, 3), w(n, 3);
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < 3; ++j) {
      u(i, j) = std::cos(0.3 * (i + 1) * (j + 1));
      w(i, j) = std::sin(0.17 * (i + 2) + j);
    }
  const Eigen::MatrixXd low_rank = Eigen::MatrixXd::Identity(n, n) + 0.1 * u * w.transpose();
  const Eigen::VectorXd low_rank_exact = low_rank.partialPivLu().solve(b);
  const statics::KrylovSolve four = statics::gmres(
      [&](const Eigen::VectorXd& v) { return Eigen::VectorXd(low_rank * v); },
      [](const Eigen::VectorXd& v) { return v; }, b, 1e-12, n, x);
  std::printf("GMRES: %d products on the 60 x 60 tridiagonal, %d with its diagonal as preconditioner, %d on the "
              "identity plus rank 3\n",
              plain.iterations, jacobi.iterations, four.iterations);
  CHECK(four.converged);
  CHECK(four.iterations <= 4);
  CHECK((x - low_rank_exact).norm() <= 1e-11 * low_rank_exact.norm());
}

TEST_CASE("Statics: the tangent's product by differences equals the assembled tangent times the vector",
          "[statics]") {
  // The strip bent by a tip force (off the reference state, so geometric
  // terms are in), then K v by tangent_product against the assembled tangent
  // applied to the same v, and along single degrees of freedom against the
  // tangent's columns. Both are central differences of the same Jacobian
  // with steps of 1e-7 (of the spacing, or rad): their truncation error is
  // of order 1e-14 and their round-off about 1e-16 / 1e-7 = 1e-9 of the
  // forces' scale, so they agree to far better than the 1e-6 asked.
  Strip strip(11, 3);
  strip.conditions.add_force(strip.model.set("x_max"), Vector3(0.0, 0.0, 0.2));
  NonlinearSolver solver(strip.model, {Strip::E, 0.0});
  statics::PathFollower<NonlinearSolver> path(solver, strip.conditions);
  path.solve_to(1.0, 0.5);
  statics::TangentAssembly<NonlinearSolver>& assembly = path.assembly();
  const statics::DegreesOfFreedom dofs = assembly.degrees_of_freedom();
  const std::vector<Vector3> x0 = solver.positions(), d0 = solver.directors();
  const statics::SparseMatrix k = assembly.tangent(dofs);
  Eigen::VectorXd v(dofs.count());
  for (int i = 0; i < dofs.count(); ++i) v[i] = std::sin(1.0 + 0.7548776662 * i) * (dofs.is_rotation[i] ? 0.1 : 1.0);
  const Eigen::VectorXd assembled = k * v;
  const Eigen::VectorXd product = assembly.tangent_product(dofs, x0, d0, v);
  std::printf("Tangent product by differences against the assembled tangent: relative difference %.3e\n",
              (product - assembled).norm() / assembled.norm());
  CHECK((product - assembled).norm() <= 1e-6 * assembled.norm());
  int translation = -1, rotation = -1;
  for (int i = 0; i < dofs.count(); ++i) {
    if (dofs.is_rotation[i] && rotation < 0 && i > dofs.count() / 2) rotation = i;
    if (!dofs.is_rotation[i] && translation < 0 && i > dofs.count() / 2) translation = i;
  }
  REQUIRE(translation >= 0);
  REQUIRE(rotation >= 0);
  for (const int column : {translation, rotation}) {
    const Eigen::VectorXd unit = Eigen::VectorXd::Unit(dofs.count(), column);
    const Eigen::VectorXd expected = k * unit;
    const Eigen::VectorXd along = assembly.tangent_product(dofs, x0, d0, unit);
    CHECK((along - expected).norm() <= 1e-6 * expected.norm());
  }
}

TEST_CASE("Statics: the observer sees each converged point in order, and a bifurcation where the compressed strip "
          "passes Euler's load",
          "[statics]") {
  // The strip under an axial tip load of 1 N, followed by load control in
  // steps of 0.6 N: the observer's points must be numbered from 1, one per
  // converged step, with the follower's load factor, residual and Newton
  // updates. Along the straight path the tangent has one negative eigenvalue
  // above Euler's load P_cr = π²EI/(4L²) = 2.467 N and none below (the
  // points at 2.4 and 3.0 N lie 2.7 % below and 22 % above it); the change is
  // a bifurcation: the buckling mode is transverse, no work on the axial load.
  Strip strip(21, 3);
  strip.compress_tip(1.0);
  const double P_cr = pi * pi * strip.EI() / (4.0 * Strip::L * Strip::L);
  NonlinearSolver solver(strip.model, {Strip::E, 0.0});
  statics::PathFollower<NonlinearSolver> path(solver, strip.conditions);
  std::vector<statics::PathPoint> points;
  path.observe([&points](const statics::PathPoint& point) { points.push_back(point); },
               statics::PathStability::compute);
  for (int k = 1; k <= 5; ++k) {
    path.solve_to(0.6 * k, 0.6);
    REQUIRE(points.size() == static_cast<std::size_t>(k));
    const statics::PathPoint& point = points.back();
    std::printf("Compressed strip, step %d: P = %.3f N, %d negative eigenvalues, load share %.3e, event %d\n",
                point.step, point.load_factor, point.negative_eigenvalues, point.load_share,
                static_cast<int>(point.event));
    CHECK(point.step == k);
    CHECK(path.steps_taken() == k);
    CHECK(point.load_factor == path.load_factor());
    CHECK(point.control == statics::PathControl::load);
    CHECK(std::isnan(point.control_value));
    CHECK(point.relative_residual <= statics::NewtonOptions{}.tolerance);
    CHECK(point.relative_residual == path.last_relative_residual());
    CHECK(point.iterations == path.last_iterations());
    CHECK(point.negative_eigenvalues == (point.load_factor > P_cr ? 1 : 0));
    CHECK(point.event == (k == 5 ? statics::PathEvent::bifurcation : statics::PathEvent::none));
  }
  // Without the stability the points carry none.
  path.observe([&points](const statics::PathPoint& point) { points.push_back(point); });
  path.solve_to(3.3, 0.3);
  REQUIRE(points.size() == 6);
  CHECK(points.back().step == 6);
  CHECK(points.back().negative_eigenvalues == -1);
  CHECK(std::isnan(points.back().load_share));
  CHECK(points.back().event == statics::PathEvent::none);
}

TEST_CASE("Statics: the hinged roof's snap-through is flagged as a limit point where the load factor turns, and "
          "the path's CSV reads back as the observed points",
          "[statics]") {
  // One quarter of the hinged cylindrical roof of Sze, Liu & Lo (2004, §3.8,
  // t = 12.7; R = 2540, an opening of 0.1 rad either side of the crown, 2L =
  // 508, straight edges hinged, curved edges free, E = 3102.75, ν = 0.3),
  // 9 × 9 particles, P/4 = 750 on the centre particle, the centre's inward
  // deflection prescribed in steps of 1 to 14, past the load's maximum. The
  // count of negative eigenvalues must change once, from 0 to 1, flagged as
  // a limit point at the first point past the maximum of the load factor, as
  // the test finds it independently: the slope of the path dλ/dw at each
  // point, 1 / (g · K⁻¹ f) with K the tangent (solved by LU), f the load and
  // g the control's gradient, must change sign there and only there; and the
  // vertex of the parabola through the highest point and its two neighbours
  // must lie between the flagged point and the one before it.
  const double R = 2540.0, half_length = 254.0, theta = 0.1, t = 12.7, P = 3000.0, step = 1.0;
  const int n = 9;
  const ShellModel model = ShellModel::cylindrical_panel(R, half_length, theta, n, n, t);
  REQUIRE((model.particle_position[0] - Vector3(R, 0.0, 0.0)).norm() < 1e-9 * R);
  statics::Conditions conditions(model.particle_count());
  conditions.symmetry_plane(model.set("theta_min"), Vector3::UnitY());
  conditions.symmetry_plane(model.set("z_min"), Vector3::UnitZ());
  for (const Vector3& direction : {Vector3(Vector3::UnitX()), Vector3(Vector3::UnitY()), Vector3(Vector3::UnitZ())})
    conditions.hold_translation(model.set("theta_max"), direction);
  conditions.add_force({0}, Vector3(-P / 4.0, 0.0, 0.0));
  NonlinearSolver solver(model, {3102.75, 0.3});
  statics::PathFollower<NonlinearSolver> path(solver, conditions);
  const statics::ControlDisplacement centre{{{0, 1.0}}, -Vector3::UnitX()};
  const std::filesystem::path file = std::filesystem::temp_directory_path() / "sphshell_statics_roof_path.csv";
  std::vector<statics::PathPoint> points;
  statics::PathCsv csv(file.string());
  path.observe(
      [&points, csv](const statics::PathPoint& point) mutable {
        points.push_back(point);
        csv(point);
      },
      statics::PathStability::compute);
  // The slope dλ/dw of the path at the current point.
  auto slope = [&path, &centre]() {
    statics::TangentAssembly<NonlinearSolver>& assembly = path.assembly();
    const statics::DegreesOfFreedom dofs = assembly.degrees_of_freedom();
    statics::SparseMatrix K = assembly.tangent(dofs);
    K.makeCompressed();
    Eigen::SparseLU<statics::SparseMatrix> lu(K);
    REQUIRE(lu.info() == Eigen::Success);
    const Eigen::VectorXd response = lu.solve(assembly.external_load(dofs));
    double along_control = 0.0;
    for (const auto& [particle, weight] : centre.weights)
      for (int k = dofs.first[particle]; k < dofs.first[particle + 1]; ++k)
        if (!dofs.is_rotation[k]) along_control += weight * centre.direction.dot(dofs.direction[k]) * response[k];
    return 1.0 / along_control;
  };
  std::vector<double> slopes;
  for (int k = 1; k <= 14; ++k) {
    path.solve_to_displacement(centre, step * k, step);
    REQUIRE(points.size() == static_cast<std::size_t>(k));  // one step a call: a slope for every point
    slopes.push_back(slope());
    CHECK(points.back().load_factor == path.load_factor());
    CHECK(points.back().control == statics::PathControl::displacement);
    CHECK(points.back().control_value == path.displacement_of(centre));
  }
  // Observing (the stability at each point, and the slopes above) leaves the
  // path as it is, to round-off: the same steps without them reach the same
  // load factors. (Not bit for bit: each tangent assembly puts the
  // configuration back through Solver::set_configuration, which normalises
  // the directors again, an ulp's change.)
  {
    NonlinearSolver unobserved_solver(model, {3102.75, 0.3});
    statics::PathFollower<NonlinearSolver> unobserved(unobserved_solver, conditions);
    double largest = 0.0;
    for (int k = 1; k <= 14; ++k) {
      unobserved.solve_to_displacement(centre, step * k, step);
      largest = std::max(largest, std::abs(unobserved.load_factor() / points[k - 1].load_factor - 1.0));
    }
    std::printf("Hinged roof 9 x 9: load factors with and without the observer differ by %.2e at most (relative)\n",
                largest);
    CHECK(largest < 1e-12);  // measured 4.6e-14
  }
  std::size_t flagged = 0, highest = 0;
  for (std::size_t k = 0; k < points.size(); ++k) {
    const statics::PathPoint& point = points[k];
    std::printf("Hinged roof 9 x 9, step %d: -W_C = %.3f, P/P_max = %.5f, slope %+.4e, %d negative eigenvalues, "
                "load share %.3e, event %d\n",
                point.step, point.control_value, point.load_factor, slopes[k], point.negative_eigenvalues,
                point.load_share, static_cast<int>(point.event));
    CHECK(point.step == static_cast<int>(k) + 1);
    if (point.event != statics::PathEvent::none && flagged == 0) flagged = k;
  }
  while (highest + 1 < points.size() && points[highest + 1].load_factor > points[highest].load_factor) ++highest;
  REQUIRE(highest > 0);
  REQUIRE(highest + 1 < points.size());  // the path went past its maximum
  REQUIRE(flagged > 0);
  CHECK(points[flagged].event == statics::PathEvent::limit_point);
  for (std::size_t k = 0; k < points.size(); ++k) {
    CHECK(points[k].negative_eigenvalues == (k < flagged ? 0 : 1));
    CHECK((slopes[k] > 0.0) == (k < flagged));
  }
  // The parabola through the highest point and its neighbours.
  const double s0 = points[highest - 1].control_value, s1 = points[highest].control_value,
               s2 = points[highest + 1].control_value;
  const double l0 = points[highest - 1].load_factor, l1 = points[highest].load_factor,
               l2 = points[highest + 1].load_factor;
  const double d01 = (l1 - l0) / (s1 - s0), d12 = (l2 - l1) / (s2 - s1), curvature = (d12 - d01) / (s2 - s0);
  const double vertex = 0.5 * (s0 + s1) - d01 / (2.0 * curvature);
  std::printf("Hinged roof 9 x 9: the load's maximum near -W_C = %.3f (parabola), flagged at step %d\n", vertex,
              points[flagged].step);
  REQUIRE(curvature < 0.0);
  CHECK(points[flagged - 1].control_value < vertex);
  CHECK(vertex < points[flagged].control_value);

  // The CSV, read while its writer is still open (each row is flushed).
  std::ifstream in(file);
  std::string line;
  REQUIRE(std::getline(in, line));
  std::string header;
  for (const std::string& column : statics::PathCsv::columns()) header += (header.empty() ? "" : ",") + column;
  CHECK(line == header);
  std::size_t rows = 0;
  while (std::getline(in, line)) {
    REQUIRE(rows < points.size());
    std::vector<double> values;
    std::size_t begin = 0;
    for (std::size_t comma; (comma = line.find(',', begin)) != std::string::npos; begin = comma + 1)
      values.push_back(std::strtod(line.substr(begin, comma - begin).c_str(), nullptr));
    values.push_back(std::strtod(line.substr(begin).c_str(), nullptr));
    REQUIRE(values.size() == 10);
    const statics::PathPoint& point = points[rows++];
    CHECK(values[0] == point.step);
    CHECK(values[1] == point.load_factor);
    CHECK(values[2] == static_cast<int>(point.control));
    CHECK(values[3] == point.control_value);
    CHECK(values[4] == point.relative_residual);
    CHECK(values[5] == point.iterations);
    CHECK(values[6] == point.negative_eigenvalues);
    CHECK(values[7] == point.eigenvalue_nearest_zero);
    CHECK(values[8] == point.load_share);
    CHECK(values[9] == static_cast<int>(point.event));
  }
  CHECK(rows == points.size());
  CHECK_THROWS_WITH(statics::PathCsv((file / "no_such_directory" / "path.csv").string()),
                    Catch::Contains("no_such_directory"));
}

TEST_CASE("Statics: the automatic arc length follows l sqrt(target / used) within its bounds", "[statics]") {
  using statics::ArcLengthAdaptation;
  using statics::adapted_arc_length;
  // The rule on exact figures: √(4/16) = 1/2, √(4/1) = 2, √(1/9) = 1/3.
  CHECK(adapted_arc_length(1.0, 16, {0.1, 2.0, 4}) == 0.5);
  CHECK(adapted_arc_length(1.0, 1, {0.1, 3.0, 4}) == 2.0);
  CHECK(adapted_arc_length(1.0, 0, {0.1, 3.0, 4}) == 2.0);  // no update counts as one
  CHECK(adapted_arc_length(0.3, 9, {0.01, 1.0, 1}) == Approx(0.1).epsilon(1e-15));
  CHECK(adapted_arc_length(1.0, 1, {0.1, 1.5, 4}) == 1.5);    // the upper bound
  CHECK(adapted_arc_length(1.0, 400, {0.2, 2.0, 4}) == 0.2);  // the lower bound (0.1 before it)
  CHECK_THROWS_WITH(adapted_arc_length(1.0, 4, {0.0, 1.0, 4}), Catch::Contains("ArcLengthAdaptation::min_length = 0"));
  CHECK_THROWS_WITH(adapted_arc_length(1.0, 4, {0.5, 0.25, 4}),
                    Catch::Contains("ArcLengthAdaptation::max_length = 0.25") && Catch::Contains("min_length"));
  CHECK_THROWS_WITH(adapted_arc_length(1.0, 4, {0.5, std::numeric_limits<double>::infinity(), 4}),
                    Catch::Contains("ArcLengthAdaptation::max_length = inf"));
  CHECK_THROWS_WITH(adapted_arc_length(1.0, 4, {0.5, 1.0, 0}),
                    Catch::Contains("ArcLengthAdaptation::target_iterations = 0"));
  // On the strip under a tip force: each next length from the last step's
  // length and the Newton updates the observer saw it take.
  Strip strip(11, 3);
  strip.conditions.add_force(strip.model.set("x_max"), Vector3(0.0, 0.0, 1.0 / 3.0));
  NonlinearSolver solver(strip.model, {Strip::E, 0.0});
  statics::PathFollower<NonlinearSolver> path(solver, strip.conditions);
  CHECK_THROWS_WITH(path.next_arc_length({0.05, 1.0, 4}), Catch::Contains("needs an arc-length step"));
  std::vector<statics::PathPoint> points;
  path.observe([&points](const statics::PathPoint& point) { points.push_back(point); });
  const ArcLengthAdaptation rule{0.05, 0.6, 3};
  double length = 0.3, travelled = 0.0;
  for (int k = 1; k <= 4; ++k) {
    const double taken = path.arc_length_step(length);
    travelled += taken;
    REQUIRE(points.size() == static_cast<std::size_t>(k));
    CHECK(points.back().control == statics::PathControl::arc_length);
    CHECK(points.back().control_value == Approx(travelled).epsilon(1e-14));
    const int used = std::max(1, points.back().iterations);
    const double expected = std::min(0.6, std::max(0.05, taken * std::sqrt(3.0 / used)));
    const double next = path.next_arc_length(rule);
    std::printf("Strip, arc-length step %d of %.4f took %d updates: next %.4f\n", k, taken,
                points.back().iterations, next);
    CHECK(next == Approx(expected).epsilon(1e-15));
    length = next;
  }
}

TEST_CASE("Statics: the energy line search takes the stiffening clamped plate in one load step where whole Newton "
          "updates overshoot and halve it",
          "[statics]") {
  // A square plate, L = 1, t = 0.01, E = 1e7, nu = 0.3, clamped on all
  // edges, 11 x 11 particles, under a uniform dead load q (equal shares)
  // whose linear (Kirchhoff) centre deflection 0.00126 q L^4 / D is 50 t. The
  // membrane stiffening holds the true deflection near 4 t, so the first
  // Newton update, the linear answer, overshoots it twelvefold, and so do
  // the next ones: without the line search the iteration diverges and the
  // load step is halved. With NewtonOptions::line_search the overshooting
  // updates are shortened to the energy's minimum along them, and the one
  // step converges. Both reach the same equilibrium (to the tolerance).
  const double L = 1.0, t = 0.01, E = 1e7, nu = 0.3, D = E * t * t * t / (12.0 * (1.0 - nu * nu));
  const double q = 50.0 * t * D / (0.00126 * L * L * L * L);
  const int n = 11;
  const ShellModel model = ShellModel::rectangular_plate(L, L, n, n, t);
  statics::Conditions conditions(model.particle_count());
  for (const char* edge : {"x_min", "x_max", "y_min", "y_max"}) conditions.clamp(model.set(edge));
  ParticleSet all(model.particle_count());
  for (std::size_t i = 0; i < all.size(); ++i) all[i] = static_cast<int>(i);
  conditions.add_force(all, Vector3(0.0, 0.0, q * L * L / static_cast<double>(model.particle_count())));
  const int centre = (n * n) / 2;
  REQUIRE((model.particle_position[centre] - Vector3(0.5 * L, 0.5 * L, 0.0)).norm() < 1e-12);
  struct Run {
    int steps, iterations;
    long trials;
    double deflection;
  };
  auto run = [&](statics::LineSearch line_search) {
    NonlinearSolver solver(model, {E, nu});
    statics::NewtonOptions options;
    options.line_search = line_search;
    statics::PathFollower<NonlinearSolver> path(solver, conditions, options);
    path.solve_to(1.0, 1.0);
    return Run{path.steps_taken(), path.report().iterations, path.report().line_search_trials,
               path.displacement(centre).z()};
  };
  const Run whole = run(statics::LineSearch::none);
  const Run searched = run(statics::LineSearch::energy);
  std::printf("Clamped plate, linear w/t = 50, one load step: whole updates %d steps, %d iterations; line search %d "
              "steps, %d iterations (%ld trials); w/t %.6f and %.6f\n",
              whole.steps, whole.iterations, searched.steps, searched.iterations, searched.trials,
              whole.deflection / t, searched.deflection / t);
  CHECK(whole.steps > 1);  // the premise: whole updates overshoot and the step is halved (measured 3 steps, 41 updates)
  CHECK(searched.steps == 1);
  CHECK(searched.trials > 0);
  CHECK(searched.iterations <= 8);  // measured 6
  CHECK(searched.iterations < whole.iterations / 4);
  CHECK(searched.deflection > 3.0 * t);
  CHECK(searched.deflection < 5.0 * t);
  CHECK(searched.deflection == Approx(whole.deflection).epsilon(1e-5));
  // Under displacement control (the centre prescribed at 10 t in one step,
  // the load factor solved for) the search shortens updates too and reaches
  // the same point.
  auto run_displacement = [&](statics::LineSearch line_search) {
    NonlinearSolver solver(model, {E, nu});
    statics::NewtonOptions options;
    options.line_search = line_search;
    statics::PathFollower<NonlinearSolver> path(solver, conditions, options);
    path.solve_to_displacement({{{centre, 1.0}}, Vector3::UnitZ()}, 10.0 * t, 10.0 * t);
    return std::pair<double, statics::NewtonReport>(path.load_factor(), path.report());
  };
  const auto [whole_factor, whole_report] = run_displacement(statics::LineSearch::none);
  const auto [searched_factor, searched_report] = run_displacement(statics::LineSearch::energy);
  std::printf("Clamped plate, centre at 10 t in one step: whole updates %d iterations, line search %d (%ld trials); "
              "load factors %.8f and %.8f\n",
              whole_report.iterations, searched_report.iterations, searched_report.line_search_trials, whole_factor,
              searched_factor);
  CHECK(searched_report.line_search_trials > 0);
  CHECK(searched_factor == Approx(whole_factor).epsilon(1e-5));
  // Where the path turns the search does not pay: the cantilever under end
  // shear in one load step to a tip deflection near 0.3 L. The straight line
  // of the linear update stretches the strip, so the energy's minimum along
  // it lies at a few per cent of it, and the shortened updates take longer
  // to find the way (docs/user-guide.md gives the counts); the point reached
  // is the same.
  auto run_cantilever = [](statics::LineSearch line_search) {
    Strip strip(11, 3);
    strip.conditions.add_force(strip.model.set("x_max"), Vector3(0.0, 0.0, 1.0 / 3.0));
    NonlinearSolver solver(strip.model, {Strip::E, 0.0});
    statics::NewtonOptions options;
    options.line_search = line_search;
    statics::PathFollower<NonlinearSolver> path(solver, strip.conditions, options);
    path.solve_to(1.0, 1.0);
    return std::pair<double, int>(path.displacement(strip.model.set("x_max")[1]).z(), path.report().iterations);
  };
  const auto [whole_tip, whole_updates] = run_cantilever(statics::LineSearch::none);
  const auto [searched_tip, searched_updates] = run_cantilever(statics::LineSearch::energy);
  std::printf("Cantilever, end shear in one load step: tip w %.6f, whole updates %d, line search %d\n", whole_tip,
              whole_updates, searched_updates);
  CHECK(whole_tip > 0.25 * Strip::L);
  CHECK(searched_tip == Approx(whole_tip).epsilon(1e-5));
  // Bad options are named.
  NonlinearSolver solver(model, {E, nu});
  statics::NewtonOptions bad;
  bad.line_search_tolerance = 1.0;
  CHECK_THROWS_WITH(statics::PathFollower<NonlinearSolver>(solver, conditions, bad),
                    Catch::Contains("NewtonOptions::line_search_tolerance = 1"));
  bad = {};
  bad.max_line_search_trials = 0;
  CHECK_THROWS_WITH(statics::PathFollower<NonlinearSolver>(solver, conditions, bad),
                    Catch::Contains("NewtonOptions::max_line_search_trials = 0"));
}

TEST_CASE("Statics: the automatic load and displacement steps follow step sqrt(target / used) within their bounds",
          "[statics]") {
  using statics::StepAdaptation;
  using statics::adapted_step;
  // The rule on exact figures: √(4/16) = 1/2, √(4/1) = 2, √(1/9) = 1/3.
  CHECK(adapted_step(1.0, 16, {0.1, 2.0, 4}) == 0.5);
  CHECK(adapted_step(1.0, 1, {0.1, 3.0, 4}) == 2.0);
  CHECK(adapted_step(1.0, 0, {0.1, 3.0, 4}) == 2.0);  // no update counts as one
  CHECK(adapted_step(0.3, 9, {0.01, 1.0, 1}) == Approx(0.1).epsilon(1e-15));
  CHECK(adapted_step(1.0, 1, {0.1, 1.5, 4}) == 1.5);    // the upper bound
  CHECK(adapted_step(1.0, 400, {0.2, 2.0, 4}) == 0.2);  // the lower bound (0.1 before it)
  CHECK_THROWS_WITH(adapted_step(1.0, 4, {0.0, 1.0, 4}), Catch::Contains("StepAdaptation::min_step = 0"));
  CHECK_THROWS_WITH(adapted_step(1.0, 4, {0.5, 0.25, 4}),
                    Catch::Contains("StepAdaptation::max_step = 0.25") && Catch::Contains("min_step"));
  CHECK_THROWS_WITH(adapted_step(1.0, 4, {0.5, std::numeric_limits<double>::infinity(), 4}),
                    Catch::Contains("StepAdaptation::max_step = inf"));
  CHECK_THROWS_WITH(adapted_step(1.0, 4, {0.5, 1.0, 0}), Catch::Contains("StepAdaptation::target_iterations = 0"));

  // On the strip under a tip force: each step from the last step's size and
  // the Newton updates the observer saw it take, the last one cut at the target.
  Strip strip(11, 3);
  strip.conditions.add_force(strip.model.set("x_max"), Vector3(0.0, 0.0, 1.0 / 3.0));
  const int tip = strip.model.set("x_max")[1];
  auto check_steps = [](const std::vector<double>& values, const std::vector<int>& iterations, double start,
                        double target, double first, const StepAdaptation& rule) {
    REQUIRE(values.size() >= 3);
    CHECK(values.back() == Approx(target).epsilon(1e-12));
    double before = start, expected = first;
    for (std::size_t k = 0; k < values.size(); ++k) {
      const double taken = values[k] - before;
      std::printf("  step %zu of %.5f (expected %.5f) took %d updates\n", k + 1, taken, expected, iterations[k]);
      CHECK(taken == Approx(std::min(expected, target - before)).epsilon(1e-12));
      expected = std::min(rule.max_step, std::max(rule.min_step, taken * std::sqrt(rule.target_iterations /
                                                                                   std::max(1.0, 1.0 * iterations[k]))));
      before = values[k];
    }
  };
  {
    NonlinearSolver solver(strip.model, {Strip::E, 0.0});
    statics::PathFollower<NonlinearSolver> path(solver, strip.conditions);
    std::vector<double> factors;
    std::vector<int> iterations;
    path.observe([&](const statics::PathPoint& point) {
      factors.push_back(point.load_factor);
      iterations.push_back(point.iterations);
    });
    const StepAdaptation rule{0.05, 0.4, 3};
    CHECK_THROWS_WITH(path.solve_to(1.0, 0.5, rule),
                      Catch::Contains("first load step = 0.5") && Catch::Contains("StepAdaptation::max_step"));
    CHECK_THROWS_WITH(path.solve_to(1.0, 0.1, StepAdaptation{0.0, 0.4, 3}),
                      Catch::Contains("StepAdaptation::min_step = 0"));
    REQUIRE(factors.empty());
    std::printf("Strip, automatic load steps:\n");
    path.solve_to(1.0, 0.1, rule);
    check_steps(factors, iterations, 0.0, 1.0, 0.1, rule);
  }
  {
    NonlinearSolver solver(strip.model, {Strip::E, 0.0});
    statics::PathFollower<NonlinearSolver> path(solver, strip.conditions);
    const statics::ControlDisplacement tip_w{{{tip, 1.0}}, Vector3::UnitZ()};
    std::vector<double> deflections;
    std::vector<int> iterations;
    path.observe([&](const statics::PathPoint& point) {
      deflections.push_back(point.control_value);
      iterations.push_back(point.iterations);
    });
    const StepAdaptation rule{0.1, 0.8, 3};
    CHECK_THROWS_WITH(path.solve_to_displacement(tip_w, 3.0, 0.05, rule),
                      Catch::Contains("first displacement step = 0.05"));
    std::printf("Strip, automatic displacement steps:\n");
    path.solve_to_displacement(tip_w, 3.0, 0.2, rule);
    check_steps(deflections, iterations, 0.0, 3.0, 0.2, rule);
  }
}

TEST_CASE("Statics: a critical point between the start and the first observed point is flagged on that point",
          "[statics]") {
  // The strip under an axial tip load, taken in one load step from the
  // unloaded start to 1.2 times Euler's load P_cr = π²EI/(4L²): the
  // straight path crosses the bifurcation within that step. The start's
  // tangent is positive definite, the first point's has one negative
  // eigenvalue: a bifurcation, flagged on the first point.
  Strip strip(21, 3);
  strip.compress_tip(1.0);
  const double P_cr = pi * pi * strip.EI() / (4.0 * Strip::L * Strip::L);
  NonlinearSolver solver(strip.model, {Strip::E, 0.0});
  statics::PathFollower<NonlinearSolver> path(solver, strip.conditions);
  std::vector<statics::PathPoint> points;
  path.observe([&points](const statics::PathPoint& point) { points.push_back(point); },
               statics::PathStability::compute);
  path.solve_to(1.2 * P_cr, 1.2 * P_cr);
  REQUIRE(points.size() == 1);
  CHECK(points[0].negative_eigenvalues == 1);
  CHECK(points[0].event == statics::PathEvent::bifurcation);
  // Observed again from here: the next step stays past the load, no event.
  path.observe([&points](const statics::PathPoint& point) { points.push_back(point); },
               statics::PathStability::compute);
  path.solve_to(1.3 * P_cr, 0.1 * P_cr);
  REQUIRE(points.size() == 2);
  CHECK(points[1].negative_eigenvalues == 1);
  CHECK(points[1].event == statics::PathEvent::none);
}

TEST_CASE("Statics: the path as ParaView frames, one per converged point, read back", "[statics]") {
  // The strip under a tip force in three load steps, then two displacement
  // steps: a frame per point in particles.pvd (and stress_points.pvd), at
  // the path parameter (the load factor, then the control displacement) or
  // the step; each frame's points are the converged positions and its
  // displacement array their motion, to the last digit (float64).
  Strip strip(11, 3);
  strip.conditions.add_force(strip.model.set("x_max"), Vector3(0.0, 0.0, 1.0 / 3.0));
  const int tip = strip.model.set("x_max")[1];
  NonlinearSolver solver(strip.model, {Strip::E, 0.0});
  statics::PathFollower<NonlinearSolver> path(solver, strip.conditions);
  const std::string folder = "statics_path_frames";
  std::filesystem::remove_all(folder);
  std::filesystem::create_directories(folder);
  {
    std::ofstream stale(folder + "/particles_000099.vtu");  // an earlier run's frame: removed
  }
  statics::PathFrameOptions options;
  options.format.precision = io::VtuPrecision::float64;
  statics::PathFrames<NonlinearSolver> frames(solver, folder, options);
  std::vector<std::vector<Vector3>> positions;
  std::vector<double> times;
  path.observe([&](const statics::PathPoint& point) {
    frames(point);
    positions.push_back(solver.positions());
    times.push_back(point.control == statics::PathControl::load ? point.load_factor : point.control_value);
    CHECK(statics::PathFrames<NonlinearSolver>::time_of(point, statics::PathFrameTime::step) == point.step);
    CHECK(statics::PathFrames<NonlinearSolver>::time_of(point, statics::PathFrameTime::load_factor) ==
          point.load_factor);
  });
  path.solve_to(0.3, 0.1);
  path.solve_to_displacement({{{tip, 1.0}}, Vector3::UnitZ()}, 2.0, 0.4);
  REQUIRE(positions.size() >= 5);
  CHECK(frames.frames_written() == static_cast<long>(positions.size()));
  CHECK_FALSE(std::filesystem::exists(folder + "/particles_000099.vtu"));
  for (const char* series : {"particles", "stress_points"}) {
    const std::vector<test_support::PvdEntry> listed =
        test_support::read_pvd(folder + "/" + std::string(series) + ".pvd");
    REQUIRE(listed.size() == positions.size());
    for (std::size_t k = 0; k < listed.size(); ++k) CHECK(listed[k].time == times[k]);
  }
  const std::vector<test_support::PvdEntry> listed = test_support::read_pvd(folder + "/particles.pvd");
  for (std::size_t k = 0; k < listed.size(); ++k) {
    const test_support::Vtu vtu = test_support::read_vtu(folder + "/" + listed[k].file);
    REQUIRE(vtu.points() == strip.model.particle_count());
    CHECK(vtu.cells() == strip.model.cells().size());
    const std::vector<double>& points = vtu.array("Points", "Points").values;
    const std::vector<double>& displacement = vtu.array("PointData", "displacement").values;
    REQUIRE(points.size() == 3 * positions[k].size());
    REQUIRE(displacement.size() == points.size());
    std::size_t differing = 0;
    for (std::size_t i = 0; i < positions[k].size(); ++i)
      for (int c = 0; c < 3; ++c) {
        differing += points[3 * i + c] != positions[k][i][c];
        differing += displacement[3 * i + c] != positions[k][i][c] - strip.model.particle_position[i][c];
      }
    CHECK(differing == 0);
    CHECK(vtu.array("FieldData", "TimeValue").values.at(0) == times[k]);
    REQUIRE_FALSE(vtu.comments.empty());
    CHECK(vtu.comments[0].find("equilibrium path, step " + std::to_string(k + 1)) != std::string::npos);
  }
  CHECK_THROWS_WITH(statics::PathFrames<NonlinearSolver>(solver, folder + "/particles.pvd/inside"),
                    Catch::Contains("particles.pvd"));
}
