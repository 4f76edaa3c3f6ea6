// Discrete mechanics of the shell solver: rigid-body modes, conservation,
// objectivity, the patch test and the stable time step, checked on the
// assembled system and against closed forms.
#include "support/stiffness.hpp"

#include <sphshell/approx/mls.hpp>
#include <sphshell/kernel/cubic_spline.hpp>
#include <sphshell/material/elastic.hpp>
#include <sphshell/solver.hpp>
#include <sphshell/thickness/gauss.hpp>

#include <catch2/catch.hpp>

#include <Eigen/Eigenvalues>

#include <random>

using namespace sphshell;

namespace {

using ElasticSolver = Solver<approx::MLS<kernel::CubicSpline>, thickness::Gauss<2>, material::Elastic>;
const material::Elastic::Parameters steel{210e9, 0.3};

SolverOptions options(bool nonlinear, double rotary_inertia_scale = 1.0) {
  SolverOptions o;
  o.nonlinear = nonlinear;
  o.rotary_inertia_scale = rotary_inertia_scale;
  return o;
}

// A random smooth-ish configuration: displacements and director rotations.
void perturb(ElasticSolver& solver, double amplitude, unsigned seed) {
  std::mt19937 random(seed);
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  std::vector<Vector3> x = solver.positions(), d = solver.directors();
  for (std::size_t i = 0; i < x.size(); ++i) {
    x[i] += amplitude * Vector3(uniform(random), uniform(random), uniform(random));
    d[i] = Eigen::AngleAxisd(10 * amplitude, Vector3(uniform(random), uniform(random), 0).normalized()) * d[i];
  }
  solver.set_configuration(x, d);
}

}  // namespace

TEST_CASE("A free plate has exactly six zero-energy modes", "[solver][stability]") {
  ElasticSolver solver(ShellModel::rectangular_plate(0.5, 0.5, 11, 11, 0.01), steel, options(false));
  const test_support::DiscreteSystem system = test_support::assemble(solver, 1e-6);
  // Generalized eigenproblem K φ = ω² M φ, scaled by the mass so the spectrum is in (rad/s)².
  const Eigen::VectorXd inverse_sqrt_mass = system.mass.cwiseSqrt().cwiseInverse();
  const Eigen::MatrixXd scaled = inverse_sqrt_mass.asDiagonal() * system.stiffness * inverse_sqrt_mass.asDiagonal();
  const Eigen::VectorXd eigenvalues = Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(scaled).eigenvalues();
  const double largest = eigenvalues.maxCoeff();
  int zero_modes = 0;
  for (int k = 0; k < eigenvalues.size(); ++k) zero_modes += std::abs(eigenvalues[k]) < 1e-9 * largest;
  INFO("7th eigenvalue / largest = " << eigenvalues[6] / largest);
  CHECK(zero_modes == 6);
  CHECK(eigenvalues[6] > 1e-8 * largest);
}

// Without particle integration the stress points alone leave a spurious soft
// mode; any share from 0.02 up makes the seventh mode the free plate's first
// elastic one: ω = 13.468 √(D/(ρd)) / L² for ν = 0.3 (Leissa, Vibration of
// Plates, NASA SP-160, 1969).
TEST_CASE("Particle integration removes the spurious soft modes from a share of 0.02", "[solver][stability]") {
  const double L = 0.5, d = 0.01, E = steel.E, nu = steel.nu, rho = 7850.0;
  const double first_elastic = 13.468 * std::sqrt(E * d * d * d / (12 * (1 - nu * nu)) / (rho * d)) / (L * L);
  auto seventh_frequency = [&](double share) {
    SolverOptions o = options(false);
    o.particle_integration_share = share;
    ElasticSolver solver(ShellModel::rectangular_plate(L, L, 11, 11, d), steel, o);
    const test_support::DiscreteSystem system = test_support::assemble(solver, 1e-6);
    const Eigen::VectorXd inverse_sqrt_mass = system.mass.cwiseSqrt().cwiseInverse();
    const Eigen::MatrixXd scaled =
        inverse_sqrt_mass.asDiagonal() * system.stiffness * inverse_sqrt_mass.asDiagonal();
    const Eigen::VectorXd eigenvalues = Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(scaled).eigenvalues();
    return std::sqrt(std::max(0.0, eigenvalues[6]));
  };
  for (double share : {0.5, 0.1, 0.02}) {
    const double frequency = seventh_frequency(share);
    INFO("share " << share << ": seventh frequency " << frequency << " rad/s, Leissa " << first_elastic);
    CHECK(frequency == Approx(first_elastic).epsilon(0.05));
  }
  CHECK(seventh_frequency(0.0) < 0.5 * first_elastic);
}

TEST_CASE("The stable time step bounds the highest frequency of the discrete system", "[solver][time step]") {
  struct Case { double thickness; double rotary_inertia_scale; };
  for (const Case c : {Case{0.05, 1.0}, Case{0.01, 1.0}, Case{0.002, 1.0}, Case{0.002, 20.0}}) {
    ElasticSolver solver(ShellModel::rectangular_plate(0.5, 0.5, 11, 11, c.thickness), steel,
                         options(false, c.rotary_inertia_scale));
    const test_support::DiscreteSystem system = test_support::assemble(solver, 1e-6);
    const Eigen::VectorXd inverse_sqrt_mass = system.mass.cwiseSqrt().cwiseInverse();
    const Eigen::MatrixXd scaled =
        inverse_sqrt_mass.asDiagonal() * system.stiffness * inverse_sqrt_mass.asDiagonal();
    const double omega_max = std::sqrt(Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(scaled).eigenvalues().maxCoeff());
    const double exact_bound = 2.0 / omega_max;
    INFO("d = " << c.thickness << ", rotary scale " << c.rotary_inertia_scale << ": formula "
                << solver.stable_time_step() << " s, exact 2/ω_max " << exact_bound << " s");
    WARN("stable step: formula / exact = " << solver.stable_time_step() / exact_bound);
    CHECK(solver.stable_time_step() <= exact_bound);
    CHECK(solver.stable_time_step() >= 0.35 * exact_bound);  // not needlessly small
  }
}

TEST_CASE("Internal forces conserve linear and angular momentum", "[solver][conservation]") {
  ElasticSolver solver(ShellModel::spherical_cap(0.5, 0.5, 9, 0.01), steel, options(true));
  perturb(solver, 2e-3, 7);
  Vector3 force_sum = Vector3::Zero(), moment_sum = Vector3::Zero();
  double scale = 0.0;
  for (std::size_t i = 0; i < solver.particle_count(); ++i) {
    const Vector3& f = solver.internal_forces()[i];
    const Vector3& g = solver.internal_director_forces()[i];
    force_sum += f;
    moment_sum += solver.positions()[i].cross(f) + solver.directors()[i].cross(g);
    scale += f.norm();
  }
  CHECK(scale > 0.0);
  CHECK(force_sum.norm() < 1e-11 * scale);
  CHECK(moment_sum.norm() < 1e-11 * scale * 0.5);
}

TEST_CASE("Rigid motions create no stress under the nonlinear option", "[solver][objectivity]") {
  ElasticSolver solver(ShellModel::cylindrical_panel(0.1, 0.2, 1.5, 9, 9, 0.005), steel, options(true));
  const Eigen::Matrix3d rotation =
      (Eigen::AngleAxisd(M_PI / 2, Vector3::UnitX()) * Eigen::AngleAxisd(0.3, Vector3(1, 1, 1).normalized()))
          .toRotationMatrix();
  std::vector<Vector3> x = solver.positions(), d = solver.directors();
  for (std::size_t i = 0; i < x.size(); ++i) {
    x[i] = rotation * x[i] + Vector3(0.3, -2.0, 1.0);
    d[i] = rotation * d[i];
  }
  solver.set_configuration(x, d);
  double largest_force = 0.0, largest_resultant = 0.0;
  for (const Vector3& f : solver.internal_forces()) largest_force = std::max(largest_force, f.norm());
  for (std::size_t s = 0; s < solver.stress_point_count(); ++s)
    largest_resultant = std::max({largest_resultant, solver.membrane_force(static_cast<int>(s)).norm(),
                                  solver.bending_moment(static_cast<int>(s)).norm()});
  // A 1e-3 strain would give membrane forces of order E d 1e-3 ~ 1e6 N/m.
  CHECK(largest_resultant < 1e-3);
  CHECK(largest_force < 1e-3);
}

TEST_CASE("Patch test: a linear displacement field gives uniform exact strains and no interior force",
          "[solver][patch test]") {
  for (bool nonlinear : {false, true}) {
    ElasticSolver solver(ShellModel::rectangular_plate(0.7, 0.6, 15, 13, 0.01), steel, options(nonlinear));
    const Eigen::Matrix3d gradient = (Eigen::Matrix3d() << 1e-4, 2e-4, 0, -0.5e-4, 3e-4, 0, 0, 0, 0).finished();
    std::vector<Vector3> x = solver.positions();
    for (Vector3& xi : x) xi += gradient * xi;
    solver.set_configuration(x, solver.directors());
    // Exact strains: linear ε = sym(∇u); Green E = sym(∇u) + ½ ∇uᵀ∇u.
    const Eigen::Matrix2d grad = gradient.topLeftCorner<2, 2>();
    Eigen::Matrix2d strain = 0.5 * (grad + grad.transpose());
    if (nonlinear) strain += 0.5 * grad.transpose() * grad;
    const StrainVoigt voigt(strain(0, 0), strain(1, 1), 2 * strain(0, 1));
    const double E = steel.E, nu = steel.nu, d = 0.01;
    const Eigen::Matrix3d gamma =
        E / (1 - nu * nu) * (Eigen::Matrix3d() << 1, nu, 0, nu, 1, 0, 0, 0, (1 - nu) / 2).finished();
    const StressVoigt expected = d * gamma * voigt;
    for (std::size_t s = 0; s < solver.stress_point_count(); ++s) {
      CHECK((solver.membrane_force(static_cast<int>(s)) - expected).norm() < 1e-9 * expected.norm());
      CHECK(solver.bending_moment(static_cast<int>(s)).norm() < 1e-9 * expected.norm() * d);
    }
    // With non-interpolating shape functions the boundary traction spreads over
    // the particles whose support reaches the edge, and the integration points
    // near the edge see truncated supports: within 4 spacings of the edge a
    // particle may carry force; beyond, a uniform stress must leave none.
    double largest_interior = 0.0, largest = 0.0;
    for (std::size_t i = 0; i < solver.particle_count(); ++i) {
      const double f = solver.internal_forces()[i].norm();
      largest = std::max(largest, f);
      const Vector3& x = solver.model().particle_position[i];
      const double spacing = 0.05;
      if (x.x() > 4.5 * spacing && x.x() < 0.7 - 4.5 * spacing && x.y() > 4.5 * spacing &&
          x.y() < 0.6 - 4.5 * spacing)
        largest_interior = std::max(largest_interior, f);
    }
    INFO("nonlinear = " << nonlinear);
    CHECK(largest > 0.0);
    CHECK(largest_interior < 1e-9 * largest);
  }
}
