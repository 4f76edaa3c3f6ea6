#include <sphshell/material/all.hpp>

#include <Eigen/LU>
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <random>

#include "material_test_support.hpp"

using namespace sphshell;
using namespace sphshell::material;
using material_test::uniaxial_step;
using material_test::yield_stress;
using material_test::youngs_modulus;

namespace {

// Closed-form integral of eq. (2.41) at constant triaxiality T: with
// Y = ⅔(1+ν) + 3(1−2ν)T² constant, damage starts when Y ε̄p = ε̄sp (eq. 2.40) and
// grows linearly in ε̄p: D = Dc Y (ε̄p − ε̄sp/Y)/(ε̄cp − ε̄sp).
double damage_at_constant_triaxiality(double triaxiality, double nu, double eps_p, double eps_s,
                                      double eps_c, double critical) {
  const double y = 2.0 / 3.0 * (1.0 + nu) + 3.0 * (1.0 - 2.0 * nu) * triaxiality * triaxiality;
  return critical * y * std::max(0.0, eps_p - eps_s / y) / (eps_c - eps_s);
}

}  // namespace

TEST_CASE("Damage along a uniaxial stress path (T = 1/3) follows the integrated damage law",
          "[material][damage]") {
  const double nu = GENERATE(0.3, 0.2);
  const double plastic_modulus = 1e9;
  const double eps_s = 0.02, eps_c = 0.37, critical = 0.24;
  const LemaitreDamage law(
      {youngs_modulus, nu, yield_stress, plastic_modulus, eps_s, eps_c, critical});
  LemaitreDamage::State state = law.initial_state();
  // Coarse steps: the damage threshold is crossed inside a step, which the law must split.
  const double d_eps = 7.3e-4;
  double axial_strain = 0.0;
  bool damaged_seen = false;
  int step = 0;
  for (; step < 2000 && !state.failed; ++step) {
    LemaitreDamage::State before = state;
    LemaitreDamage::UpdateResult result{};
    uniaxial_step(law, state, d_eps, &result);
    axial_strain += d_eps;
    if (state.failed) {
      // The damage law itself reaches Dc within this step.
      CHECK(damage_at_constant_triaxiality(1.0 / 3.0, nu, state.eps_p, eps_s, eps_c, critical) >=
            critical * (1.0 - 1e-12));
      CHECK(damage_at_constant_triaxiality(1.0 / 3.0, nu, before.eps_p, eps_s, eps_c, critical) <
            critical);
      break;
    }
    const double expected_damage =
        damage_at_constant_triaxiality(1.0 / 3.0, nu, state.eps_p, eps_s, eps_c, critical);
    CHECK(state.D == Approx(expected_damage).margin(1e-12));
    if (state.D > 0.0) damaged_seen = true;
    if (!result.plastic) continue;
    // Strain equivalence: elastic strain σx/((1−D)E), the rest is plastic.
    const double measured_plastic_strain =
        axial_strain - state.stress.x() / ((1.0 - state.D) * youngs_modulus);
    CHECK(state.eps_p == Approx(measured_plastic_strain).epsilon(1e-8));
    CHECK(state.stress.x() ==
          Approx((1.0 - state.D) * (yield_stress + plastic_modulus * state.eps_p)).epsilon(1e-10));
    CHECK(law.equivalent_stress(state) == Approx((1.0 - state.D) * state.sigma_y).epsilon(1e-10));
  }
  CHECK(damaged_seen);
  REQUIRE(state.failed);
  CHECK(state.D == critical);
  CHECK(state.stress.norm() == 0.0);
  CHECK(law.failed(state));
  CHECK(law.elastic_energy_density(state) == 0.0);
  // With Y(1/3) = 1 for every ν, failure comes at ε̄p = ε̄cp.
  CHECK(state.eps_p == Approx(eps_c).margin(2 * d_eps));

  // A failed point ignores further strain and carries no stress.
  const LemaitreDamage::State failed_state = state;
  const auto result = law.update(state, StrainVoigt(1e-3, 2e-3, -1e-3));
  CHECK_FALSE(result.plastic);
  CHECK(result.iterations == 0);
  CHECK(state.stress.norm() == 0.0);
  CHECK(state.eps_p == failed_state.eps_p);
  CHECK(state.D == failed_state.D);
}

TEST_CASE("Damage under equibiaxial tension (T = 2/3) follows the integrated damage law",
          "[material][damage]") {
  const double nu = 0.3, eps_s = 0.01, eps_c = 0.2, critical = 0.5, plastic_modulus = 2e9;
  const LemaitreDamage law(
      {youngs_modulus, nu, yield_stress, plastic_modulus, eps_s, eps_c, critical});
  LemaitreDamage::State state = law.initial_state();
  for (int step = 0; step < 400 && !state.failed; ++step) {
    const auto result = law.update(state, StrainVoigt(4e-4, 4e-4, 0.0));
    if (state.failed) break;
    CHECK(state.stress.x() == Approx(state.stress.y()).epsilon(1e-13));
    CHECK(state.D ==
          Approx(damage_at_constant_triaxiality(2.0 / 3.0, nu, state.eps_p, eps_s, eps_c, critical))
              .margin(1e-12));
    if (result.plastic)
      CHECK(state.stress.x() == Approx((1.0 - state.D) * state.sigma_y).epsilon(1e-10));
  }
  CHECK(state.failed);
}

TEST_CASE("Without damage growth the damage law reproduces J2 plasticity exactly",
          "[material][damage]") {
  const J2Plasticity j2({youngs_modulus, 0.3, yield_stress, 3e9});
  const LemaitreDamage damage({youngs_modulus, 0.3, yield_stress, 3e9, 1e6, 2e6, 0.5});
  J2Plasticity::State j2_state = j2.initial_state();
  LemaitreDamage::State damage_state = damage.initial_state();
  std::mt19937_64 engine(7);
  std::normal_distribution<double> normal(0.0, 1.0);
  int plastic = 0;
  for (int step = 0; step < 2000; ++step) {
    const StrainVoigt d_eps = 2e-4 * StrainVoigt(normal(engine), normal(engine), normal(engine));
    const auto a = j2.update(j2_state, d_eps);
    const auto b = damage.update(damage_state, d_eps);
    REQUIRE(a.plastic == b.plastic);
    REQUIRE(a.iterations == b.iterations);
    plastic += a.plastic;
    REQUIRE((j2_state.stress - damage_state.stress).norm() <= 1e-15 * yield_stress);
    REQUIRE(j2_state.eps_p == damage_state.eps_p);
    REQUIRE(damage_state.D == 0.0);
  }
  CHECK(plastic > 100);
}

TEST_CASE(
    "Damaged elastic energy density is 1/2 sigma^T Gamma^-1 sigma/(1-D), unloading slope (1-D)E",
    "[material][damage]") {
  const LemaitreDamage law({youngs_modulus, 0.3, yield_stress, 1e9, 0.0, 0.1, 0.9});
  LemaitreDamage::State state = law.initial_state();
  for (int step = 0; step < 60; ++step) uniaxial_step(law, state, 5e-4);
  REQUIRE(state.D > 0.05);
  REQUIRE_FALSE(state.failed);
  const double damage = state.D;
  const Matrix3 compliance = law.elasticity_matrix().inverse();
  CHECK(law.elastic_energy_density(state) ==
        Approx(0.5 * state.stress.dot(compliance * state.stress) / (1.0 - damage)).epsilon(1e-12));
  const double before = state.stress.x();
  LemaitreDamage::UpdateResult result{};
  uniaxial_step(law, state, -1e-4, &result);
  CHECK_FALSE(result.plastic);
  CHECK(state.D == damage);
  CHECK(before - state.stress.x() == Approx((1.0 - damage) * youngs_modulus * 1e-4).epsilon(1e-8));
}

TEST_CASE("A damage step is the J2 return of the effective stress, with T at the returned stress",
          "[material][damage]") {
  const double nu = 0.3, eps_s = 0.05, eps_c = 0.4, critical = 0.6, plastic_modulus = 2e9;
  const LemaitreDamage law(
      {youngs_modulus, nu, yield_stress, plastic_modulus, eps_s, eps_c, critical});
  const J2Plasticity j2({youngs_modulus, nu, yield_stress, plastic_modulus});
  std::mt19937_64 engine(11);
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  int damaging = 0, crossing = 0;
  for (int trial = 0; trial < 500; ++trial) {
    LemaitreDamage::State state;
    state.eps_p = 0.1 * (1.0 + uniform(engine));  // 0 … 0.2: below and above the threshold
    state.sigma_y = yield_stress + plastic_modulus * state.eps_p;
    state.D = state.eps_p > eps_s ? 0.2 * (1.0 + uniform(engine)) : 0.0;
    state.failed = false;
    const StressVoigt direction(uniform(engine), uniform(engine), uniform(engine));
    state.stress = (1.0 - state.D) * state.sigma_y * direction /
                   std::sqrt(direction.x() * direction.x() - direction.x() * direction.y() +
                             direction.y() * direction.y() + 3 * direction.z() * direction.z());
    const StrainVoigt d_eps = 4e-3 * StrainVoigt(uniform(engine), uniform(engine), uniform(engine));

    // Independent expectation: J2 on σ̃ = σ/(1−D), then eq. (2.40)–(2.41) with T of the result.
    J2Plasticity::State effective{state.stress / (1.0 - state.D), state.eps_p, state.sigma_y};
    const auto j2_result = j2.update(effective, d_eps);
    const double hydrostatic = (effective.stress.x() + effective.stress.y()) / 3.0;
    const double triaxiality = hydrostatic / j2.equivalent_stress(effective);
    const double y = 2.0 / 3.0 * (1.0 + nu) + 3.0 * (1.0 - 2.0 * nu) * triaxiality * triaxiality;
    const double threshold = eps_s / y;
    const double active = std::max(0.0, effective.eps_p - std::max(state.eps_p, threshold));
    const double expected_damage =
        j2_result.plastic ? state.D + critical / (eps_c - eps_s) * y * active : state.D;
    if (state.eps_p < threshold && effective.eps_p > threshold) ++crossing;

    LemaitreDamage::State updated = state;
    const auto result = law.update(updated, d_eps);
    REQUIRE(result.plastic == j2_result.plastic);
    if (expected_damage >= critical) {
      CHECK(updated.failed);
      continue;
    }
    if (updated.D > state.D) ++damaging;
    CHECK(updated.D == Approx(expected_damage).epsilon(1e-12));
    CHECK(updated.eps_p == Approx(effective.eps_p).epsilon(1e-12));
    CHECK((updated.stress - (1.0 - expected_damage) * effective.stress).norm() <=
          1e-9 * yield_stress);
  }
  CHECK(damaging > 100);
  CHECK(crossing > 0);
}
