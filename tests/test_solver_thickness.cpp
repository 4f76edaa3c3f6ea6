// A wall thickness that varies over the shell (ShellModel::set_thickness):
// each integration point integrates with its own thickness, each particle
// carries its own mass and rotary inertia, and the stable step follows the
// thinnest wall. Checked against uniform-thickness models, closed forms and
// the assembled system's spectrum.
#include "support/stiffness.hpp"

#include <sphshell/approx/mls.hpp>
#include <sphshell/kernel/cubic_spline.hpp>
#include <sphshell/material/elastic.hpp>
#include <sphshell/solver.hpp>
#include <sphshell/thickness/gauss.hpp>

#include <catch2/catch.hpp>

#include <Eigen/Eigenvalues>

#include <cmath>

using namespace sphshell;

namespace {

using ElasticSolver = Solver<approx::MLS<kernel::CubicSpline>, thickness::Gauss<3>, material::Elastic>;
const material::Elastic::Parameters steel{210e9, 0.3};
constexpr double thick = 0.01, thin = 0.004;

bool in_band(const Vector3& x) { return x.x() > 0.3 && x.x() < 0.42; }

ShellModel plate(double thickness) { return ShellModel::rectangular_plate(0.7, 0.6, 15, 13, thickness); }

ShellModel banded_plate() {
  ShellModel model = plate(thick);
  model.set_thickness(in_band, thin);
  return model;
}

// A uniform stretch and a uniform curvature: positions x = X + G X, directors
// turned so that d(X) = n + K X (linear analysis).
template <class SolverType>
void stretch_and_bend(SolverType& solver) {
  const Eigen::Matrix3d gradient = (Eigen::Matrix3d() << 1e-4, 2e-4, 0, -0.5e-4, 3e-4, 0, 0, 0, 0).finished();
  const Eigen::Matrix3d director_gradient = (Eigen::Matrix3d() << 2e-3, 1e-3, 0, 0, -1e-3, 0, 0, 0, 0).finished();
  std::vector<Vector3> x = solver.positions(), d = solver.directors();
  for (std::size_t i = 0; i < x.size(); ++i) {
    d[i] = (d[i] + director_gradient * x[i]).normalized();
    x[i] += gradient * x[i];
  }
  solver.set_configuration(x, d);
}

}  // namespace

TEST_CASE("Resultants at each stress point follow its own thickness", "[solver][thickness]") {
  SolverOptions linear;
  linear.nonlinear = false;
  ElasticSolver banded(banded_plate(), steel, linear);
  ElasticSolver uniform_thick(plate(thick), steel, linear), uniform_thin(plate(thin), steel, linear);
  for (ElasticSolver* solver : {&banded, &uniform_thick, &uniform_thin}) stretch_and_bend(*solver);
  int thin_points = 0;
  for (std::size_t s = 0; s < banded.stress_point_count(); ++s) {
    const int p = static_cast<int>(s);
    const bool band = in_band(banded.model().stress_point_position[s]);
    thin_points += band;
    const ElasticSolver& reference = band ? uniform_thin : uniform_thick;
    INFO("stress point " << s << (band ? " (thin band)" : ""));
    CHECK((banded.membrane_force(p) - reference.membrane_force(p)).norm() <=
          1e-12 * reference.membrane_force(p).norm());
    CHECK((banded.bending_moment(p) - reference.bending_moment(p)).norm() <=
          1e-12 * reference.bending_moment(p).norm());
  }
  CHECK(thin_points == 2 * 12);  // two stress-point columns of twelve
  // Closed forms: N ∝ d and M ∝ d³ at the same strains (both uniform models
  // see the same configuration).
  const int s = 0;
  CHECK(uniform_thin.membrane_force(s).norm() == Approx(thin / thick * uniform_thick.membrane_force(s).norm()));
  CHECK(uniform_thin.bending_moment(s).norm() ==
        Approx(std::pow(thin / thick, 3) * uniform_thick.bending_moment(s).norm()));
}

TEST_CASE("Particle masses and inertias follow the thickness field", "[solver][thickness]") {
  const double density = 7850.0;
  SolverOptions options;
  options.density = density;
  ElasticSolver solver(banded_plate(), steel, options);
  const ShellModel& model = solver.model();
  double expected_mass = 0.0, mass = 0.0;
  int thin_particles = 0;
  for (std::size_t i = 0; i < model.particle_count(); ++i) {
    const double d = in_band(model.particle_position[i]) ? thin : thick;
    thin_particles += d == thin;
    CHECK(model.particle_thickness(i) == d);
    expected_mass += density * d * model.particle_area[i];
    mass += solver.masses()[i];
  }
  CHECK(thin_particles == 2 * 13);  // particle columns x = 0.35 and 0.40
  CHECK(mass == Approx(expected_mass).epsilon(1e-14));
  CHECK(model.minimum_thickness() == thin);
  CHECK(model.thickness() == thick);
}

TEST_CASE("The stable step still bounds the spectrum with thinner regions", "[solver][thickness][time step]") {
  // Thinning particles and stress points together is the benign case; a thin
  // particle inside thicker stress points (stiffness from the thick wall,
  // inertia from the thin one) is the critical one.
  struct Layout {
    const char* name;
    bool (*thin)(const Vector3&);
  };
  const Layout layouts[] = {
      {"band of particles and stress points", [](const Vector3& x) { return x.x() > 0.2 && x.x() < 0.3; }},
      {"one particle column only", [](const Vector3& x) { return std::abs(x.x() - 0.25) < 1e-9; }},
      {"stress-point row and the particle rows either side (a notch)",
       [](const Vector3& x) { return x.y() > 0.2 && x.y() < 0.3 && x.x() > 0.1 && x.x() < 0.4; }},
  };
  for (const Layout& layout : layouts)
    for (const double rotary_scale : {1.0, 100.0}) {
      ShellModel model = ShellModel::rectangular_plate(0.5, 0.5, 11, 11, 0.01);
      model.set_thickness(layout.thin, 0.002);
      SolverOptions linear;
      linear.nonlinear = false;
      linear.rotary_inertia_scale = rotary_scale;
      ElasticSolver solver(model, steel, linear);
      const test_support::DiscreteSystem system = test_support::assemble(solver, 1e-6);
      const Eigen::VectorXd inverse_sqrt_mass = system.mass.cwiseSqrt().cwiseInverse();
      const Eigen::MatrixXd scaled =
          inverse_sqrt_mass.asDiagonal() * system.stiffness * inverse_sqrt_mass.asDiagonal();
      const double exact_bound =
          2.0 / std::sqrt(Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(scaled).eigenvalues().maxCoeff());
      INFO(layout.name << ", rotary scale " << rotary_scale << ": formula " << solver.stable_time_step()
                       << " s, exact 2/ω_max " << exact_bound << " s");
      WARN("stable step, " << layout.name << ", rotary scale " << rotary_scale
                           << ": formula / exact = " << solver.stable_time_step() / exact_bound);
      CHECK(solver.stable_time_step() <= exact_bound);
      CHECK(solver.stable_time_step() >= 0.1 * exact_bound);
    }
}

TEST_CASE("set_thickness rejects a bad thickness and an empty region", "[solver][thickness][errors]") {
  ShellModel model = plate(thick);
  CHECK_THROWS_WITH(model.set_thickness(in_band, 0.0), Catch::Contains("thickness"));
  CHECK_THROWS_WITH(model.set_thickness(in_band, -1e-3), Catch::Contains("-0.001"));
  CHECK_THROWS_WITH(model.set_thickness([](const Vector3& x) { return x.x() > 5.0; }, thin),
                    Catch::Contains("set_thickness region") && Catch::Contains("holds no particle"));
  CHECK(model.minimum_thickness() == thick);  // nothing changed
}
