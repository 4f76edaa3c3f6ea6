// Static solutions (Solver::solve_static, statics/static_solve.hpp): the
// clamped plate against Mindlin's values and an independent linear solve of
// the same discrete system, the elastica under an end moment (closed form) and
// an end shear (an elastica computed here by shooting), and the Errors.
#include "support/static_plate.hpp"

#include <sphshell/sphshell.hpp>

#include <catch2/catch.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <sstream>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

using namespace sphshell;

namespace {

using PlateSolver = Solver<approx::MLS<kernel::CubicSpline>, thickness::Gauss<2>, material::Elastic>;
using StripSolver = Solver<approx::MLS<kernel::CubicSpline>, thickness::Gauss<3>, material::Elastic>;

// The clamped L = 1 m plate of test_solver_plate (q = 1 kPa, linear, 21 x 21).
struct Plate {
  double slenderness, d, D;
  PlateSolver solver;
  explicit Plate(double slenderness_)
      : slenderness(slenderness_),
        d(1.0 / slenderness_),
        D(210e9 * d * d * d / (12 * (1 - 0.09))),
        solver(ShellModel::rectangular_plate(1.0, 1.0, 21, 21, d), {210e9, 0.3}, options()) {
    solver.clamp(solver.model().set("boundary"));
    solver.add_uniform_pressure(solver.model().all_particles(), 1e3, time_function::Step{}, PressureDirection::fixed);
  }
  static SolverOptions options() {
    SolverOptions o;
    o.nonlinear = false;
    o.density = 7850;
    return o;
  }
  // w_centre D / (q L⁴).
  double coefficient() const { return -solver.displacement(solver.model().set("centre")[0]).z() * D / 1e3; }
};

// Mindlin values of test_solver_plate / test_solver_shear_locking.
constexpr double mindlin_50 = 0.0012754, mindlin_100 = 0.0012679;

// The cantilever strip of test_solver_shells (L = 0.5 m, 0.1 m wide, d = 0.02 m,
// ν = 0, so it bends like a beam), clamped at x = 0, nonlinear.
struct Strip {
  static constexpr double L = 0.5, width = 0.1, d = 0.02, E = 210e9;
  static constexpr double EI = E * width * d * d * d / 12.0;
  StripSolver solver;
  explicit Strip(int n = 21) : solver(ShellModel::rectangular_plate(L, width, n, 5, d), {E, 0.0}, options()) {
    solver.clamp(solver.model().set("x_min"));
  }
  static SolverOptions options() {
    SolverOptions o;
    o.nonlinear = true;
    o.density = 7850;
    return o;
  }
  const ParticleSet& tip() const { return solver.model().set("x_max"); }
  // Mean tip displacement.
  Vector3 tip_displacement() const {
    Vector3 u = Vector3::Zero();
    for (int i : tip()) u += solver.displacement(i) / static_cast<double>(tip().size());
    return u;
  }
};

// The elastica of a cantilever under a fixed end force P normal to its
// undeformed axis: θ'' = −(P/EI) cos θ, θ(0) = 0, θ'(L) = 0, shot on θ'(0)
// with RK4 and bisection. Returns the tip (x, w) / L.
std::pair<double, double> elastica_end_shear(double alpha) {  // alpha = P L² / EI
  const int steps = 4000;
  const double h = 1.0 / steps;  // s / L
  struct Tip { double theta, kappa, x, w; };
  auto shoot = [&](double kappa0) {
    // y = (θ, θ', x, w) in s/L; θ'' = −α cos θ.
    std::array<double, 4> y{0.0, kappa0, 0.0, 0.0};
    auto f = [&](const std::array<double, 4>& z) {
      return std::array<double, 4>{z[1], -alpha * std::cos(z[0]), std::cos(z[0]), std::sin(z[0])};
    };
    for (int k = 0; k < steps; ++k) {
      std::array<double, 4> k1 = f(y), y2, y3, y4;
      for (int c = 0; c < 4; ++c) y2[c] = y[c] + 0.5 * h * k1[c];
      const std::array<double, 4> k2 = f(y2);
      for (int c = 0; c < 4; ++c) y3[c] = y[c] + 0.5 * h * k2[c];
      const std::array<double, 4> k3 = f(y3);
      for (int c = 0; c < 4; ++c) y4[c] = y[c] + h * k3[c];
      const std::array<double, 4> k4 = f(y4);
      for (int c = 0; c < 4; ++c) y[c] += h / 6.0 * (k1[c] + 2 * k2[c] + 2 * k3[c] + k4[c]);
    }
    return Tip{y[0], y[1], y[2], y[3]};
  };
  // θ'(L) = θ'(0) − α ∫cos θ: negative at θ'(0) = 0, positive at θ'(0) = α (the root moment is at most P L).
  double low = 0.0, high = alpha;
  for (int k = 0; k < 100; ++k) {
    const double mid = 0.5 * (low + high);
    (shoot(mid).kappa > 0.0 ? high : low) = mid;
  }
  const Tip tip = shoot(0.5 * (low + high));
  return {tip.x, tip.w};
}

}  // namespace

TEST_CASE("The shooting elastica reproduces the tabulated tip deflections", "[static][reference]") {
  // Bisshopp & Drucker (1945), Mattiasson (1981): PL²/EI = 1 → w/L = 0.30172, 2 → 0.49346;
  // 2 → horizontal tip displacement 1 − x/L = 0.16064.
  CHECK(elastica_end_shear(1.0).second == Approx(0.30172).epsilon(2e-4));
  CHECK(elastica_end_shear(2.0).second == Approx(0.49346).epsilon(2e-4));
  CHECK(1.0 - elastica_end_shear(2.0).first == Approx(0.16064).epsilon(1e-3));
}

TEST_CASE("Static clamped plates: Mindlin's deflection and the independent linear solve", "[static][plate]") {
  for (const auto& [slenderness, mindlin, tolerance] :
       {std::tuple<double, double, double>{50, mindlin_50, 0.04}, {100, mindlin_100, 0.03}}) {
    Plate newton(slenderness);
    solver::StaticParameters parameters;
    parameters.mass = solver::StaticMass::tangent;
    const solver::StaticResult result = newton.solver.solve_static(parameters);
    // The same discrete system solved by the tests' own assembly (support/static_plate.hpp).
    Plate direct(slenderness);
    const Eigen::VectorXd w = test_support::clamped_plate_deflection(direct.solver, {21, 21},
                                                                     direct.solver.model().set("boundary"), 1e3, 1e-7);
    const double independent = -w[direct.solver.model().set("centre")[0]] * direct.D / 1e3;
    WARN("L/d = " << slenderness << ": static solve w D/(q L^4) = " << newton.coefficient() << " ("
                  << 100 * (newton.coefficient() / mindlin - 1) << " % from Mindlin), independent linear solve "
                  << independent << "; " << result.iterations << " Newton iterations, " << result.force_evaluations
                  << " force evaluations, residual " << result.residual);
    CHECK(result.residual <= 1e-6);
    // The clamped plate's tangent is positive definite: Cholesky where the build has CHOLMOD.
    CHECK(result.factorisation == (statics::cholmod_available ? statics::FactorisationMethod::cholmod_cholesky
                                                              : statics::FactorisationMethod::simplicial_ldlt));
    CHECK(newton.coefficient() == Approx(mindlin).epsilon(tolerance));
    CHECK(newton.coefficient() == Approx(independent).epsilon(1e-4));
  }
}

TEST_CASE("Static clamped plate by adaptive dynamic relaxation (Gershgorin masses, Underwood damping)",
          "[static][plate]") {
  Plate relaxed(50);
  solver::StaticParameters parameters;
  parameters.mass = solver::StaticMass::particle_bound;
  parameters.damping = solver::StaticDamping::viscous;
  const solver::StaticResult result = relaxed.solver.solve_static(parameters);
  Plate newton(50);
  solver::StaticParameters tangent;
  tangent.mass = solver::StaticMass::tangent;
  newton.solver.solve_static(tangent);
  WARN("dynamic relaxation: w D/(q L^4) = " << relaxed.coefficient() << " in " << result.iterations
                                            << " steps; Newton " << newton.coefficient());
  CHECK(relaxed.coefficient() == Approx(mindlin_50).epsilon(0.04));
  // Both stop at ‖r‖ ≤ 1e-6 ‖f‖; the deflection agrees far more closely than the discretisation error.
  CHECK(relaxed.coefficient() == Approx(newton.coefficient()).epsilon(1e-3));
}

TEST_CASE("The static state is at rest in equilibrium: explicit steps from it stay there", "[static][plate]") {
  Plate plate(50);
  solver::StaticParameters tangent;
  tangent.mass = solver::StaticMass::tangent;
  plate.solver.solve_static(tangent);
  const double before = plate.coefficient();
  for (int k = 0; k < 200; ++k) plate.solver.step();
  INFO("after 200 explicit steps: " << plate.coefficient() << " (was " << before << ")");
  CHECK(plate.coefficient() == Approx(before).epsilon(1e-4));
  CHECK(std::abs(plate.solver.energy().balance()) <= 1e-6 * plate.solver.energy().elastic);
}

TEST_CASE("Static elastica: an end moment rolls the cantilever into a half circle", "[static][nonlinear][validation]") {
  Strip strip;
  // M = π EI / L: curvature π / L, the tip at x = L sin(π)/π = 0, w = −2L/π.
  const double M = M_PI * Strip::EI / Strip::L;
  strip.solver.add_point_moment(strip.tip(), Vector3(0.0, M / static_cast<double>(strip.tip().size()), 0.0));
  solver::StaticParameters parameters;
  parameters.load_factors = {0.125, 0.25, 0.375, 0.5, 0.625, 0.75, 0.875, 1.0};
  std::vector<solver::StaticIteration> seen;
  const solver::StaticResult result =
      strip.solver.solve_static(parameters, [&](const solver::StaticIteration& it) { seen.push_back(it); });
  const Vector3 u = strip.tip_displacement();
  const double x = Strip::L + u.x(), w = u.z();
  WARN("end moment pi EI/L: tip x = " << x << " m (0), w = " << w << " m (" << -2 * Strip::L / M_PI << "); "
                                      << result.iterations << " relaxation steps, " << result.force_evaluations
                                      << " force evaluations");
  CHECK(std::abs(x) <= 0.02 * Strip::L);
  CHECK(w == Approx(-2 * Strip::L / M_PI).epsilon(0.02));
  REQUIRE(!seen.empty());
  CHECK(seen.back().load_step == 8);  // 1-based: the eighth of eight
  CHECK(seen.back().load_factor == 1.0);
  CHECK(seen.back().residual <= parameters.tolerance);
}

TEST_CASE("Static elastica: a cantilever under end shear against the shooting elastica", "[static][nonlinear]") {
  for (double alpha : {1.0, 2.0}) {
    Strip strip;
    const double P = alpha * Strip::EI / (Strip::L * Strip::L);
    strip.solver.add_point_force(strip.tip(), Vector3(0, 0, -P / static_cast<double>(strip.tip().size())));
    solver::StaticParameters parameters;
    parameters.load_factors = {0.5, 1.0};
    const solver::StaticResult result = strip.solver.solve_static(parameters);
    const auto [x, w] = elastica_end_shear(alpha);
    const Vector3 u = strip.tip_displacement();
    WARN("end shear PL^2/EI = " << alpha << ": tip w/L = " << -u.z() / Strip::L << " (elastica " << w
                                << "), 1 - x/L = " << -u.x() / Strip::L << " (" << 1 - x << "); "
                                << result.iterations << " relaxation steps");
    // The damped run of test_solver_shells holds 3 % at this resolution.
    CHECK(-u.z() / Strip::L == Approx(w).epsilon(0.03));
    CHECK(-u.x() / Strip::L == Approx(1 - x).epsilon(0.05));
  }
}

TEST_CASE("Static solve errors name the cause", "[static][errors]") {
  SECTION("a free plate has a rigid-body mode, and is left as it was") {
    PlateSolver free(ShellModel::rectangular_plate(1.0, 1.0, 9, 9, 0.02), {210e9, 0.3}, Plate::options());
    free.add_uniform_pressure(free.model().all_particles(), 1e3);
    for (int k = 0; k < 5; ++k) free.step();
    const Vector3 moved = free.displacement(0);
    REQUIRE(moved.norm() > 0.0);
    CHECK_THROWS_WITH(free.solve_static(), Catch::Contains("free rigid-body mode"));
    CHECK(free.displacement(0) == moved);
  }
  SECTION("a plate held at one edge against z only can still slide in its plane") {
    PlateSolver sliding(ShellModel::rectangular_plate(1.0, 1.0, 9, 9, 0.02), {210e9, 0.3}, Plate::options());
    sliding.fix_translation(sliding.model().set("x_min"), Vector3::UnitZ());
    sliding.fix_rotation(sliding.model().set("x_min"), Vector3::UnitY());
    sliding.add_uniform_pressure(sliding.model().all_particles(), 1e3);
    CHECK_THROWS_WITH(sliding.solve_static(), Catch::Contains("free rigid-body mode"));
  }
  Plate plate(50);
  SECTION("load factors must increase") {
    solver::StaticParameters p;
    p.load_factors = {0.5, 0.5};
    CHECK_THROWS_WITH(plate.solver.solve_static(p), Catch::Contains("load_factors[1] = 0.5") &&
                                                         Catch::Contains("must be positive"));
    p.load_factors = {-1.0};
    CHECK_THROWS_WITH(plate.solver.solve_static(p), Catch::Contains("load_factors[0] = -1"));
    p.load_factors = {};
    CHECK_THROWS_WITH(plate.solver.solve_static(p), Catch::Contains("load_factors size"));
  }
  SECTION("a tolerance outside (0, 1)") {
    solver::StaticParameters p;
    p.tolerance = 0.0;
    CHECK_THROWS_WITH(plate.solver.solve_static(p), Catch::Contains("StaticParameters::tolerance"));
  }
  SECTION("an exhausted budget names it, the method, the residual and the load step") {
    solver::StaticParameters p;
    p.mass = solver::StaticMass::particle_bound;
    p.max_relaxation_steps = 10;
    p.load_factors = {0.7};
    CHECK_THROWS_WITH(plate.solver.solve_static(p), Catch::Contains("max_relaxation_steps = 10") &&
                                                         Catch::Contains("StaticMass::particle_bound") &&
                                                         Catch::Contains("load step 1 of 1 (load factor 0.7)") &&
                                                         Catch::Contains("lowest residual"));
    CHECK_THROWS_AS(plate.solver.solve_static(p), solver::StaticNotConverged);
  }
  SECTION("bad parameters leave the solver as it was, also after a solve") {
    solver::StaticParameters tangent;
    tangent.mass = solver::StaticMass::tangent;
    plate.solver.solve_static(tangent);
    const Vector3 solved = plate.solver.displacement(plate.solver.model().set("centre")[0]);
    REQUIRE(solved.z() < 0.0);
    solver::StaticParameters bad;
    bad.max_relaxation_steps = 0;
    CHECK_THROWS_WITH(plate.solver.solve_static(bad), Catch::Contains("max_relaxation_steps = 0"));
    CHECK(plate.solver.displacement(plate.solver.model().set("centre")[0]) == solved);
  }
  SECTION("loads that are off at load_time") {
    PlateSolver ramped(ShellModel::rectangular_plate(1.0, 1.0, 9, 9, 0.02), {210e9, 0.3}, Plate::options());
    ramped.clamp(ramped.model().set("boundary"));
    ramped.add_uniform_pressure(ramped.model().all_particles(), 1e3, time_function::Ramp{1e-3});
    CHECK_THROWS_WITH(ramped.solve_static(), Catch::Contains("load_time"));
    solver::StaticParameters p;
    p.load_time = 2e-3;
    p.mass = solver::StaticMass::tangent;
    CHECK_NOTHROW(ramped.solve_static(p));
  }
}

TEST_CASE("The static solve writes a progress line to the chosen stream", "[static][output]") {
  std::ostringstream lines;
  SolverOptions options = Plate::options();
  options.progress_stream = &lines;
  PlateSolver solver(ShellModel::rectangular_plate(1.0, 1.0, 9, 9, 0.02), {210e9, 0.3}, options);
  solver.clamp(solver.model().set("boundary"));
  solver.add_uniform_pressure(solver.model().all_particles(), 1e3);
  solver::StaticParameters p;
  p.progress_interval = 1;
  p.mass = solver::StaticMass::tangent;
  solver.solve_static(p);
  INFO(lines.str());
  CHECK(lines.str().find("static load step 1/1") != std::string::npos);
  CHECK(lines.str().find("residual") != std::string::npos);
}

namespace {

// An 11 x 11 clamped plate (L/d = 50, linear) under q = 1 kPa.
struct SmallPlate {
  PlateSolver solver;
  SmallPlate() : solver(ShellModel::rectangular_plate(1.0, 1.0, 11, 11, 0.02), {210e9, 0.3}, Plate::options()) {
    solver.clamp(solver.model().set("boundary"));
    solver.add_uniform_pressure(solver.model().all_particles(), 1e3, time_function::Step{}, PressureDirection::fixed);
  }
  double centre_deflection() const { return solver.displacement(solver.model().set("centre")[0]).z(); }
};

}  // namespace

TEST_CASE("A static solve that cannot reach its tolerance keeps its best state and says where it is",
          "[static][errors]") {
  for (const solver::StaticMass mass : {solver::StaticMass::tangent, solver::StaticMass::particle_bound}) {
    const bool newton = mass == solver::StaticMass::tangent;
    INFO((newton ? "Newton" : "dynamic relaxation"));
    // A separate solve of the same plate at a tolerance it reaches.
    SmallPlate reachable;
    solver::StaticParameters parameters;
    parameters.mass = mass;
    parameters.tolerance = 1e-8;
    const solver::StaticResult reference = reachable.solver.solve_static(parameters);
    REQUIRE(reference.converged);
    REQUIRE(reference.residual <= 1e-8);
    CHECK(reference.load_step == 1);

    // The same plate asked for a residual below round-off, with a budget
    // longer than the reachable solve needed (so the last state is not the one kept).
    SmallPlate plate;
    parameters.tolerance = 1e-15;
    if (newton)
      parameters.max_newton_iterations = reference.iteration + 3;
    else
      parameters.max_relaxation_steps = 2 * reference.iteration;
    std::vector<solver::StaticIteration> seen;
    std::string message;
    solver::StaticResult kept;
    try {
      plate.solver.solve_static(parameters, [&](const solver::StaticIteration& it) { seen.push_back(it); });
      FAIL("a tolerance of 1e-15 was reached");
    } catch (const solver::StaticNotConverged& e) {
      message = e.what();
      kept = e.result();
    }
    INFO(message);
    REQUIRE(!seen.empty());
    // The observer's lowest residual is the event the Error names, numbered the same way.
    const auto best = std::min_element(seen.begin(), seen.end(), [](const auto& a, const auto& b) {
      return a.residual < b.residual;
    });
    CHECK(best->load_step == 1);
    CHECK(best->load_steps == 1);
    CHECK(kept.load_step == best->load_step);
    CHECK(kept.iteration == best->iteration);
    CHECK(kept.residual == best->residual);
    CHECK(kept.load_factor == 1.0);
    CHECK_FALSE(kept.converged);
    CHECK(kept.residual <= 1e-8);
    std::ostringstream residual_text;
    residual_text.precision(6);
    residual_text << best->residual;
    CHECK_THAT(message, Catch::Contains("load step " + std::to_string(best->load_step) + " of 1 (load factor 1)") &&
                            Catch::Contains("lowest residual |r|/|lambda f_ext| = " + residual_text.str()) &&
                            Catch::Contains("at iteration " + std::to_string(best->iteration) + " of the load step") &&
                            Catch::Contains(newton ? "StaticMass::tangent" : "StaticMass::particle_bound") &&
                            Catch::Contains("left at that lowest-residual state"));
    // The solver holds the best state, not the start: the reachable solve's deflection.
    REQUIRE(reachable.centre_deflection() < 0.0);
    CHECK(plate.centre_deflection() == Approx(reachable.centre_deflection()).epsilon(1e-6));
    // At rest, and it steps on from there.
    CHECK(plate.solver.energy().kinetic == 0.0);
    for (int k = 0; k < 20; ++k) plate.solver.step();
    CHECK(plate.centre_deflection() == Approx(reachable.centre_deflection()).epsilon(1e-3));
  }
}

TEST_CASE("The automatic relaxation budget grows with the particles per side and the slenderness",
          "[static][budget]") {
  // √κ ln(1/tol) with √κ = L²/(s min(s, d)) (statics/static_solve.hpp), at least 200 000; here
  // for square plates of side 1 m (L = √2 m, s = 1/(n − 1) m).
  auto expected = [](int n, double d, double tolerance) {
    const double s = 1.0 / (n - 1);
    return std::max(200000.0, std::ceil(2.0 / (s * std::min(s, d)) * std::log(1.0 / tolerance)));
  };
  auto budget = [](int n, double d, double tolerance) {
    return static_cast<double>(
        solver::automatic_relaxation_steps(ShellModel::rectangular_plate(1.0, 1.0, n, n, d), tolerance));
  };
  // Small and thick: the floor.
  CHECK(budget(11, 0.02, 1e-6) == 200000.0);
  // The plate of the issue (51 x 51, L/d = 500, tolerance 1e-8): about 9.2e5 steps.
  CHECK(budget(51, 0.002, 1e-8) == Approx(expected(51, 0.002, 1e-8)).epsilon(1e-9));
  CHECK(budget(51, 0.002, 1e-8) == Approx(2.0 / (0.02 * 0.002) * std::log(1e8)).epsilon(1e-5));
  // Twice the particles per side at a thickness below the spacing: twice the budget.
  CHECK(budget(101, 0.002, 1e-8) == Approx(2.0 * budget(51, 0.002, 1e-8)).epsilon(0.01));
  // Twice as slender: twice the budget.
  CHECK(budget(51, 0.001, 1e-8) == Approx(2.0 * budget(51, 0.002, 1e-8)).epsilon(0.01));
}

TEST_CASE("Newton's steps by GMRES on a kept factorisation reach the equilibrium full Newton reaches",
          "[static][plate]") {
  // The clamped plate at L/d = 100, nonlinear, under a pressure that bends it
  // to about its thickness (membrane action: Newton iterates), in two load
  // steps to the relative residual 1e-9: a fresh tangent at every Newton
  // iteration, and GMRES on the current tangent preconditioned by the
  // factorisation of an earlier one (StaticParameters::krylov_iterations).
  // Both stop below 1e-9, so their deflections agree to about that.
  auto solve = [](int krylov_iterations, solver::StaticResult& result) {
    SolverOptions options = Plate::options();
    options.nonlinear = true;
    const double d = 0.01;
    PlateSolver plate(ShellModel::rectangular_plate(1.0, 1.0, 21, 21, d), {210e9, 0.3}, options);
    plate.clamp(plate.model().set("boundary"));
    // w ≈ 0.00126 q L⁴ / D ≈ d at q = d D / (0.00126 L⁴).
    const double D = 210e9 * d * d * d / (12 * (1 - 0.09)), q = d * D / 0.00126;
    plate.add_uniform_pressure(plate.model().all_particles(), q, time_function::Step{}, PressureDirection::fixed);
    solver::StaticParameters parameters;
    parameters.mass = solver::StaticMass::tangent;
    parameters.load_factors = {0.5, 1.0};
    parameters.tolerance = 1e-9;
    parameters.krylov_iterations = krylov_iterations;
    result = plate.solve_static(parameters);
    return -plate.displacement(plate.model().set("centre")[0]).z() / d;
  };
  solver::StaticResult newton, krylov;
  const double w_newton = solve(0, newton), w_krylov = solve(20, krylov);
  WARN("nonlinear clamped plate, w/d at the centre: full Newton " << w_newton << " (" << newton.iterations
                                                                  << " iterations, " << newton.factorisations
                                                                  << " factorisations), GMRES " << w_krylov << " ("
                                                                  << krylov.iterations << " iterations, "
                                                                  << krylov.factorisations << " factorisations, "
                                                                  << krylov.krylov_iterations << " products)");
  CHECK(newton.converged);
  CHECK(krylov.converged);
  CHECK(newton.residual <= 1e-9);
  CHECK(krylov.residual <= 1e-9);
  // Membrane action: the deflection is well below the linear one (about d).
  CHECK(w_newton > 0.3);
  CHECK(w_newton < 0.9);
  CHECK(w_krylov == Approx(w_newton).epsilon(1e-6));
  // Full Newton factorises at every iteration; GMRES keeps one factorisation
  // as its preconditioner across iterations and load steps.
  CHECK(newton.factorisations == newton.iterations);
  CHECK(newton.krylov_iterations == 0);
  CHECK(krylov.krylov_iterations > 0);
  CHECK(krylov.factorisations < krylov.iterations);
  // Bad GMRES parameters are named.
  Plate plate(50);
  solver::StaticParameters bad;
  bad.mass = solver::StaticMass::tangent;
  bad.krylov_iterations = -1;
  CHECK_THROWS_WITH(plate.solver.solve_static(bad), Catch::Contains("StaticParameters::krylov_iterations"));
  bad.krylov_iterations = 10;
  bad.krylov_tolerance = 1.0;
  CHECK_THROWS_WITH(plate.solver.solve_static(bad), Catch::Contains("StaticParameters::krylov_tolerance"));
}

// The tangent's factorisation part (statics/sparse_factorisation.hpp) on
// matrices with closed-form solutions: the second-difference matrix
// tridiag(−1, 2, −1) of order n, whose solution for a right-hand side of ones
// is x_i = i (n + 1 − i)/2 (i = 1..n, the discrete parabola), positive
// definite; the same with its first diagonal entry −1, indefinite; an upper
// bidiagonal, unsymmetric one; and a singular one.
TEST_CASE("The sparse factorisation solves positive definite, indefinite and general tangents",
          "[static][factorisation]") {
  using Matrix = statics::SparseMatrix;
  constexpr int n = 40;
  const auto second_difference = [&](double first_diagonal, double scale) {
    std::vector<Eigen::Triplet<double>> entries;
    for (int i = 0; i < n; ++i) {
      entries.emplace_back(i, i, scale * (i == 0 ? first_diagonal : 2.0));
      if (i + 1 < n) entries.emplace_back(i, i + 1, -scale), entries.emplace_back(i + 1, i, -scale);
    }
    Matrix m(n, n);
    m.setFromTriplets(entries.begin(), entries.end());
    return m;
  };
  const Eigen::VectorXd ones = Eigen::VectorXd::Ones(n);
  double largest_error = 0.0;
  statics::SparseFactorisation<Matrix> factorisation;
  // Twice with the same pattern and other values (the analysis kept), scale 1 then 3.
  for (const double scale : {1.0, 3.0}) {
    REQUIRE(factorisation.factorise_symmetric(second_difference(2.0, scale)));
    CHECK(factorisation.method() == (statics::cholmod_available ? statics::FactorisationMethod::cholmod_cholesky
                                                                : statics::FactorisationMethod::simplicial_ldlt));
    const Eigen::VectorXd x = factorisation.solve(ones);
    for (int i = 1; i <= n; ++i)
      largest_error = std::max(largest_error, std::abs(x[i - 1] * scale - 0.5 * i * (n + 1 - i)) / (0.125 * n * n));
  }
  CHECK(largest_error < 1e-12);
  // Indefinite: LDLT, and from then on LDLT at once; checked against the
  // residual (the matrix is nonsingular: its determinant is 1 − 2n).
  const Matrix indefinite = second_difference(-1.0, 1.0);
  REQUIRE(factorisation.factorise_symmetric(indefinite));
  CHECK(factorisation.method() == statics::FactorisationMethod::simplicial_ldlt);
  CHECK((indefinite * factorisation.solve(ones) - ones).norm() < 1e-10 * n);
  REQUIRE(factorisation.factorise_symmetric(second_difference(2.0, 1.0)));
  CHECK(factorisation.method() == statics::FactorisationMethod::simplicial_ldlt);
  const Eigen::VectorXd middle = factorisation.solve(ones);
  CHECK(std::abs(middle[n / 2 - 1] - 0.5 * (n / 2) * (n + 1 - n / 2)) < 1e-10 * n * n);
  // General: U = I + superdiagonal 1; U x = 1 gives x = (0 or 1) alternating from the last: x_n = 1, x_{n−1} = 0, ...
  std::vector<Eigen::Triplet<double>> upper;
  for (int i = 0; i < n; ++i) {
    upper.emplace_back(i, i, 1.0);
    if (i + 1 < n) upper.emplace_back(i, i + 1, 1.0);
  }
  Matrix general(n, n);
  general.setFromTriplets(upper.begin(), upper.end());
  REQUIRE(factorisation.factorise_general(general));
  CHECK(factorisation.method() == statics::FactorisationMethod::lu);
  const Eigen::VectorXd y = factorisation.solve(ones);
  for (int i = 0; i < n; ++i) CHECK(y[i] == Approx((n - 1 - i) % 2 == 0 ? 1.0 : 0.0).margin(1e-12));
  // Singular: the second difference with a zero first row and column.
  Matrix singular = second_difference(2.0, 1.0);
  singular.coeffRef(0, 0) = 0.0, singular.coeffRef(0, 1) = 0.0, singular.coeffRef(1, 0) = 0.0;
  statics::SparseFactorisation<Matrix> fresh;
  CHECK_FALSE(fresh.factorise_symmetric(singular));
  CHECK_FALSE(fresh.valid());
  CHECK_FALSE(fresh.factorise_general(singular));
  CHECK_FALSE(fresh.valid());
}
