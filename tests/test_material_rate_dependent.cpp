// The rate-dependent laws (JohnsonCook, CowperSymonds) against their closed
// forms, written out here: the flow stress at the achieved ε̄p and rate, the
// rate-independent limits, the adiabatic temperature rise, the Johnson–Cook
// failure strain at the triaxialities of plane stress, and bad input. The
// strain paths are driven through the laws' public update() with the step's
// UpdateContext.
#include "support/mesh_files.hpp"

#include <sphshell/approx/all.hpp>
#include <sphshell/crack/all.hpp>
#include <sphshell/kernel/all.hpp>
#include <sphshell/material/all.hpp>
#include <sphshell/solver.hpp>
#include <sphshell/thickness/all.hpp>

#include <catch2/catch.hpp>

#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

using namespace sphshell;
using namespace sphshell::material;

namespace {

static_assert(check_material_law<JohnsonCook>(), "JohnsonCook must satisfy the material contract");
static_assert(check_material_law<CowperSymonds>(), "CowperSymonds must satisfy the material contract");
static_assert(is_rate_dependent_v<JohnsonCook> && is_rate_dependent_v<CowperSymonds>);
static_assert(!is_rate_dependent_v<J2Plasticity> && !is_rate_dependent_v<Elastic> &&
              !is_rate_dependent_v<LemaitreDamage>);

// A law that declares rate_dependent without the context update breaks the contract.
struct RateFlagWithoutContext : J2Plasticity {
  static constexpr bool rate_dependent = true;
};
static_assert(!is_material_law_v<RateFlagWithoutContext>);

constexpr double infinite_time_step = std::numeric_limits<double>::infinity();

// Johnson & Cook (1983), Table 1, 4340 steel: A = 792 MPa, B = 510 MPa,
// n = 0.26, C = 0.014, m = 1.03, Tm = 1793 K; ε̇0 = 1/s, Tr = 293 K.
// Failure constants of Johnson & Cook (1985), Table 3, 4340 steel: D1 = −0.80,
// D2 = 2.10, D3 = −0.5, D4 = 0.002, D5 = 0.61. E, ν of steel.
JohnsonCook::Parameters steel_4340() {
  JohnsonCook::Parameters p{};
  p.E = 200e9;
  p.nu = 0.29;
  p.A = 792e6;
  p.B = 510e6;
  p.n = 0.26;
  p.C = 0.014;
  p.reference_strain_rate = 1.0;
  p.m = 1.03;
  p.reference_temperature = 293.0;
  p.melting_temperature = 1793.0;
  p.initial_temperature = 293.0;
  p.D1 = -0.80;
  p.D2 = 2.10;
  p.D3 = -0.5;
  p.D4 = 0.002;
  p.D5 = 0.61;
  return p;
}

// The closed forms, independently of the law.
double jc_flow_stress(const JohnsonCook::Parameters& p, double eps_p, double plastic_rate, double temperature) {
  const double rate = plastic_rate / p.reference_strain_rate;
  const double homologous = (temperature - p.reference_temperature) / (p.melting_temperature - p.reference_temperature);
  const double rate_factor = rate > 1.0 ? 1.0 + p.C * std::log(rate) : 1.0;
  const double thermal_factor = homologous > 0.0 ? 1.0 - std::pow(homologous, p.m) : 1.0;
  return (p.A + p.B * std::pow(eps_p, p.n)) * rate_factor * thermal_factor;
}
double jc_failure_strain(const JohnsonCook::Parameters& p, double triaxiality, double plastic_rate,
                         double temperature) {
  const double rate = plastic_rate / p.reference_strain_rate;
  const double homologous = (temperature - p.reference_temperature) / (p.melting_temperature - p.reference_temperature);
  return (p.D1 + p.D2 * std::exp(p.D3 * triaxiality)) * (1.0 + p.D4 * (rate > 1.0 ? std::log(rate) : 0.0)) *
         (1.0 + p.D5 * homologous);
}
double cs_flow_stress(const CowperSymonds::Parameters& p, double eps_p, double plastic_rate) {
  return (p.sigma_y0 + p.Ep * eps_p) * (1.0 + std::pow(plastic_rate / p.D, 1.0 / p.q));
}

double von_mises(const StressVoigt& s) { return std::sqrt(s.x() * s.x() + s.y() * s.y() - s.x() * s.y() + 3.0 * s.z() * s.z()); }

// One step of uniaxial stress (σyy = σxy = 0): the axial increment d_eps_x and
// the lateral increment that keeps σyy = 0, found by the secant method on the
// law itself; `state` ends in the accepted state.
template <class Law>
void uniaxial_step(const Law& law, typename Law::State& state, double d_eps_x, double time_step) {
  const double tolerance = 1e-12 * law.parameters().E * std::abs(d_eps_x) + 1e-3;
  typename Law::State trial = state;
  const auto lateral_stress = [&](double d_eps_y) {
    trial = state;
    law.update(trial, StrainVoigt(d_eps_x, d_eps_y, 0.0), UpdateContext{time_step});
    return trial.stress.y();
  };
  double x0 = -law.poisson_ratio() * d_eps_x, x1 = -0.5 * d_eps_x;
  double f0 = lateral_stress(x0);
  if (std::abs(f0) <= tolerance) {
    state = trial;
    return;
  }
  double f1 = lateral_stress(x1);
  for (int iteration = 0; iteration < 100; ++iteration) {
    if (std::abs(f1) <= tolerance) {
      state = trial;
      return;
    }
    if (f1 == f0) break;
    const double x2 = x1 - f1 * (x1 - x0) / (f1 - f0);
    x0 = x1;
    f0 = f1;
    x1 = x2;
    f1 = lateral_stress(x1);
  }
  throw std::runtime_error("uniaxial_step: lateral strain secant did not converge");
}

}  // namespace

TEST_CASE("Johnson-Cook: uniaxial flow stress at constant strain rates is the JC formula",
          "[material][rate]") {
  for (const double temperature : {293.0, 700.0}) {
    for (const double rate : {1e-2, 10.0, 1e3, 1e5}) {
      JohnsonCook::Parameters p = steel_4340();
      p.initial_temperature = temperature;
      const JohnsonCook law(p);
      const double time_step = 1e-4 / rate;  // axial increments of 1e-4
      const double d_eps = rate * time_step;
      JohnsonCook::State state = law.initial_state();
      int plastic_steps = 0;
      for (int step = 0; step < 400; ++step) {
        const JohnsonCook::State before = state;
        uniaxial_step(law, state, d_eps, time_step);
        const double increment = state.eps_p - before.eps_p;
        if (increment <= 0.0) continue;
        ++plastic_steps;
        const double expected = jc_flow_stress(p, state.eps_p, increment / time_step, temperature);
        INFO("T0 = " << temperature << " K, rate " << rate << " /s, step " << step);
        REQUIRE(state.stress.x() == Approx(expected).epsilon(1e-6));
        REQUIRE(von_mises(state.stress) == Approx(expected).epsilon(1e-6));
        REQUIRE(state.sigma_y == Approx(expected).epsilon(1e-6));
        REQUIRE(state.strain_rate == Approx(increment / time_step).epsilon(1e-12));
      }
      CHECK(plastic_steps > 300);
      // Well past yield the plastic rate is nearly the applied one (the
      // elastic part is the hardening slope over E, about 1 % here).
      CHECK(state.strain_rate == Approx(rate).epsilon(0.05));
    }
  }
}

TEST_CASE("Johnson-Cook: rates at or below the reference and C = 0 give the rate-independent hardening",
          "[material][rate]") {
  JohnsonCook::Parameters p = steel_4340();
  const double d_eps = 1e-4;
  SECTION("ε̇* ≤ 1: ln ε̇* taken as 0") {
    const JohnsonCook law(p);
    const double time_step = 2.0 * d_eps / p.reference_strain_rate;  // ε̇* = ½
    JohnsonCook::State state = law.initial_state();
    for (int step = 0; step < 200; ++step) uniaxial_step(law, state, d_eps, time_step);
    REQUIRE(state.eps_p > 0.01);
    CHECK(state.stress.x() == Approx(p.A + p.B * std::pow(state.eps_p, p.n)).epsilon(1e-9));
  }
  SECTION("C = 0 at a high rate") {
    p.C = 0.0;
    const JohnsonCook law(p);
    JohnsonCook::State state = law.initial_state();
    for (int step = 0; step < 200; ++step) uniaxial_step(law, state, d_eps, 1e-9);
    REQUIRE(state.eps_p > 0.01);
    CHECK(state.stress.x() == Approx(p.A + p.B * std::pow(state.eps_p, p.n)).epsilon(1e-9));
  }
  SECTION("n = 1, C = 0, T = Tr: J2Plasticity with σs0 = A, Ep = B, on a multiaxial path") {
    p.C = 0.0;
    p.n = 1.0;
    const JohnsonCook law(p);
    const J2Plasticity j2({p.E, p.nu, p.A, p.B});
    JohnsonCook::State state = law.initial_state();
    J2Plasticity::State reference = j2.initial_state();
    for (int step = 0; step < 300; ++step) {
      const double angle = 0.02 * step;
      const StrainVoigt d(2e-4 * std::cos(angle), -1e-4 * std::cos(angle) + 5e-5 * std::sin(angle),
                          3e-4 * std::sin(angle));
      law.update(state, d, UpdateContext{1e-6});
      j2.update(reference, d);
      REQUIRE((state.stress - reference.stress).norm() <= 1e-9 * reference.stress.norm() + 1e-3);
      REQUIRE(state.eps_p == Approx(reference.eps_p).epsilon(1e-9).margin(1e-15));
    }
    CHECK(reference.eps_p > 0.005);
  }
}

TEST_CASE("Johnson-Cook: the adiabatic temperature rise is β∫σ dε̄p/(ρ cp)", "[material][rate]") {
  // Linear hardening (n = 1), no rate term (C = 0), linear softening (m = 1):
  // with θ = 1 − T*, dT = β σ dε̄p/(ρ cp) and σ = (A + B ε̄p) θ give
  //   dθ/dε̄p = −k (A + B ε̄p) θ,  k = β/(ρ cp (Tm − Tr)),
  //   T(ε̄p) = Tm − (Tm − T0) exp(−k (A ε̄p + B ε̄p²/2)).
  JohnsonCook::Parameters p = steel_4340();
  p.n = 1.0;
  p.C = 0.0;
  p.m = 1.0;
  p.taylor_quinney = 0.9;
  p.density = 7850.0;
  p.specific_heat = 477.0;
  p.D1 = 10.0;  // no failure on this path
  const JohnsonCook law(p);
  const double heat_capacity = p.density * p.specific_heat;
  const double k = p.taylor_quinney / (heat_capacity * (p.melting_temperature - p.reference_temperature));
  JohnsonCook::State state = law.initial_state();
  double discrete_rise = 0.0;
  for (int step = 0; step < 2500; ++step) {
    const JohnsonCook::State before = state;
    uniaxial_step(law, state, 1e-4, 1e-6);
    const double increment = state.eps_p - before.eps_p;
    // The step's plastic work at its flow stress (T of the step's start).
    discrete_rise += p.taylor_quinney * jc_flow_stress(p, state.eps_p, 0.0, before.temperature) * increment /
                     heat_capacity;
    REQUIRE(state.temperature - p.initial_temperature == Approx(discrete_rise).epsilon(1e-9));
  }
  const double eps = state.eps_p;
  REQUIRE(eps > 0.2);
  const double closed_form =
      p.melting_temperature - (p.melting_temperature - p.initial_temperature) *
                                  std::exp(-k * (p.A * eps + 0.5 * p.B * eps * eps));
  const double rise = state.temperature - p.initial_temperature;
  INFO("rise " << rise << " K, closed form " << closed_form - p.initial_temperature << " K");
  CHECK(rise > 40.0);
  CHECK(rise == Approx(closed_form - p.initial_temperature).epsilon(2e-3));

  SECTION("β = 0: isothermal") {
    JohnsonCook::Parameters cold = p;
    cold.taylor_quinney = 0.0;
    cold.density = 0.0;  // unused without heating
    const JohnsonCook isothermal(cold);
    JohnsonCook::State s = isothermal.initial_state();
    for (int step = 0; step < 200; ++step) uniaxial_step(isothermal, s, 1e-4, 1e-6);
    CHECK(s.eps_p > 0.01);
    CHECK(s.temperature == p.initial_temperature);
  }
}

TEST_CASE("Johnson-Cook: uniaxial damage reaches 1 at the failure strain of triaxiality 1/3",
          "[material][rate][damage]") {
  JohnsonCook::Parameters p = steel_4340();
  p.D1 = 0.05;
  p.D2 = 0.2;
  p.D3 = -1.5;
  const JohnsonCook law(p);
  // Quasi-static (ε̇* < 1) at Tr: εf = D1 + D2 exp(D3/3).
  const double failure_strain = p.D1 + p.D2 * std::exp(p.D3 / 3.0);
  const double d_eps = 1e-4;
  JohnsonCook::State state = law.initial_state();
  double last_intact_eps_p = 0.0;
  for (int step = 0; step < 5000 && !state.failed; ++step) {
    const JohnsonCook::State before = state;
    uniaxial_step(law, state, d_eps, infinite_time_step);
    if (state.failed) {
      last_intact_eps_p = before.eps_p;
      break;
    }
    REQUIRE(JohnsonCook::triaxiality(state.stress) == Approx(1.0 / 3.0).epsilon(1e-9));
    REQUIRE(state.D == Approx(state.eps_p / failure_strain).epsilon(1e-9));
  }
  REQUIRE(state.failed);
  CHECK(law.failed(state));
  CHECK(law.damage(state) >= 1.0);
  CHECK(state.stress == StressVoigt::Zero());
  // Within one step of εf: the last intact step was below it, the failing one reached it.
  CHECK(last_intact_eps_p < failure_strain);
  CHECK(state.eps_p >= failure_strain * (1.0 - 1e-9));
  CHECK(state.eps_p - last_intact_eps_p <= 1.5 * d_eps);
  // A failed point stays at zero stress.
  law.update(state, StrainVoigt(1e-3, 0.0, 0.0), UpdateContext{1e-6});
  CHECK(state.stress == StressVoigt::Zero());
  // Through a section: every integral point of a uniform membrane state has failed.
  const thickness::Section<thickness::Gauss<3>, JohnsonCook> section(law, 0.01);
  auto section_state = section.initial_state();
  CHECK_FALSE(section.all_failed(section_state));
  for (auto& point : section_state) point = state;
  CHECK(section.all_failed(section_state));
}

TEST_CASE("Johnson-Cook: the triaxiality of pure shear is 0 and of equibiaxial tension 2/3",
          "[material][rate][damage]") {
  JohnsonCook::Parameters p = steel_4340();
  p.D1 = 0.05;
  p.D2 = 0.6;
  p.D3 = -1.5;
  const JohnsonCook law(p);
  CHECK(JohnsonCook::triaxiality(StressVoigt(0.0, 0.0, 1e8)) == 0.0);
  CHECK(JohnsonCook::triaxiality(StressVoigt(1e8, 1e8, 0.0)) == Approx(2.0 / 3.0).epsilon(1e-15));
  CHECK(JohnsonCook::triaxiality(StressVoigt(1e8, 0.0, 0.0)) == Approx(1.0 / 3.0).epsilon(1e-15));
  CHECK(JohnsonCook::triaxiality(StressVoigt(-1e8, -1e8, 0.0)) == Approx(-2.0 / 3.0).epsilon(1e-15));
  struct Path {
    const char* name;
    StrainVoigt increment;
    double triaxiality;
  };
  for (const Path& path : {Path{"pure shear", StrainVoigt(0.0, 0.0, 2e-4), 0.0},
                           Path{"equibiaxial", StrainVoigt(1e-4, 1e-4, 0.0), 2.0 / 3.0}}) {
    INFO(path.name);
    JohnsonCook::State state = law.initial_state();
    for (int step = 0; step < 100; ++step) law.update(state, path.increment, UpdateContext{infinite_time_step});
    REQUIRE(state.eps_p > 0.005);
    REQUIRE_FALSE(state.failed);
    CHECK(JohnsonCook::triaxiality(state.stress) == Approx(path.triaxiality).margin(1e-12));
    CHECK(state.D == Approx(state.eps_p / jc_failure_strain(p, path.triaxiality, 0.0, 293.0)).epsilon(1e-9));
  }
}

TEST_CASE("Johnson-Cook: the damage increment uses the step's rate and temperature", "[material][rate][damage]") {
  JohnsonCook::Parameters p = steel_4340();
  p.D4 = 0.05;  // larger than 4340's, so the rate term is well above round-off
  p.initial_temperature = 600.0;
  const JohnsonCook law(p);
  const double time_step = 1e-7;
  JohnsonCook::State state = law.initial_state();
  double expected_damage = 0.0;
  for (int step = 0; step < 300; ++step) {
    const JohnsonCook::State before = state;
    uniaxial_step(law, state, 1e-4, time_step);
    const double increment = state.eps_p - before.eps_p;
    if (increment > 0.0)
      expected_damage += increment / jc_failure_strain(p, 1.0 / 3.0, increment / time_step, before.temperature);
    REQUIRE(state.D == Approx(expected_damage).epsilon(1e-9));
  }
  CHECK(state.D > 0.01);
}

namespace {

// The plane-stress return of a trial stress σ* for the Johnson–Cook flow stress
// at T = Tr, independently of the law's eigen-decomposition and iteration: the
// literal matrices of eq. (2.32–2.33), σ(Δε̄p) = (I + (Δε̄p/σs) Γ Ξ)⁻¹ σ*
// (engineering shear, Ξ the von Mises matrix), solved by Cramer's rule in long
// double, and the root of σ̄(σ(Δε̄p))/σs(Δε̄p) − 1 found by bisection on ln Δε̄p.
struct ReferenceReturn {
  long double increment;    // Δε̄p
  long double flow_stress;  // σs(ε̄p,n + Δε̄p, Δε̄p/Δt)
  long double stress[3];
  long double sensitivity;  // d(σ̄/σs)/d ln Δε̄p at the root
};

long double jc_flow_stress_long(const JohnsonCook::Parameters& p, long double eps_p_n, long double increment,
                                double time_step) {
  const long double rate = increment / (static_cast<long double>(time_step) * p.reference_strain_rate);
  const long double rate_factor = rate > 1.0L ? 1.0L + p.C * std::log(rate) : 1.0L;
  return (p.A + p.B * std::pow(eps_p_n + increment, static_cast<long double>(p.n))) * rate_factor;
}

long double determinant(const long double m[3][3]) {
  return m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1]) - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0]) +
         m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]);
}

// σ̄(σ(Δε̄p))/σs(Δε̄p) − 1, and σ(Δε̄p) in `stress`.
long double relative_overstress(const JohnsonCook::Parameters& p, const long double trial[3], long double eps_p_n,
                                long double increment, double time_step, long double stress[3]) {
  const long double flow = jc_flow_stress_long(p, eps_p_n, increment, time_step);
  const long double c = increment / flow;
  const long double nu = p.nu, biaxial = p.E / (1.0L - nu * nu);
  const long double gamma[3][3] = {{biaxial, biaxial * nu, 0.0L}, {biaxial * nu, biaxial, 0.0L},
                                   {0.0L, 0.0L, 0.5L * biaxial * (1.0L - nu)}};
  const long double xi[3][3] = {{1.0L, -0.5L, 0.0L}, {-0.5L, 1.0L, 0.0L}, {0.0L, 0.0L, 3.0L}};
  long double l[3][3];
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) {
      long double product = 0.0L;
      for (int k = 0; k < 3; ++k) product += gamma[i][k] * xi[k][j];
      l[i][j] = (i == j ? 1.0L : 0.0L) + c * product;
    }
  const long double det = determinant(l);
  for (int column = 0; column < 3; ++column) {
    long double replaced[3][3];
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) replaced[i][j] = j == column ? trial[i] : l[i][j];
    stress[column] = determinant(replaced) / det;
  }
  const long double equivalent = std::sqrt(stress[0] * stress[0] + stress[1] * stress[1] - stress[0] * stress[1] +
                                           3.0L * stress[2] * stress[2]);
  return equivalent / flow - 1.0L;
}

ReferenceReturn reference_return(const JohnsonCook::Parameters& p, const long double trial[3], long double eps_p_n,
                                 double time_step) {
  long double stress[3];
  const auto overstress = [&](long double log_increment) {
    return relative_overstress(p, trial, eps_p_n, std::exp(log_increment), time_step, stress);
  };
  // ln Δε̄p from −11000 (Δε̄p ≈ 1e-4777, far below any root here) to 0 (Δε̄p = 1).
  long double lower = -11000.0L, upper = 0.0L;
  REQUIRE(overstress(lower) > 0.0L);
  REQUIRE(overstress(upper) < 0.0L);
  for (int iteration = 0; iteration < 200; ++iteration) {
    const long double middle = 0.5L * (lower + upper);
    (overstress(middle) > 0.0L ? lower : upper) = middle;
  }
  const long double root = 0.5L * (lower + upper);
  const long double step = 1e-6L;
  const long double sensitivity = (overstress(root + step) - overstress(root - step)) / (2.0L * step);
  ReferenceReturn result{};
  overstress(root);
  result.increment = std::exp(root);
  result.flow_stress = jc_flow_stress_long(p, eps_p_n, result.increment, time_step);
  for (int i = 0; i < 3; ++i) result.stress[i] = stress[i];
  result.sensitivity = sensitivity;
  return result;
}

}  // namespace

TEST_CASE("Johnson-Cook: a small hardening exponent returns from eps_p = 0 onto the surface",
          "[material][rate]") {
  // σ̄* − A = 0.01 B from ε̄p = 0: the root Δε̄p is near 0.01^(1/n), 1e-40 for
  // n = 0.05 and 1e-200 for n = 0.01, tens of powers of two below the
  // perfectly plastic start; a second step adds another 0.01 B from there.
  // Time steps: quasi-static, 1 µs (for n < 1 ε̇* < 1 at the root: no rate
  // term) and one for which ε̇* = Δε̄p/(ε̇0Δt) exceeds 1 at the root (the rate
  // term active). n = 1 returns as before (the iteration in Δε̄p).
  for (const double n : {0.05, 0.01, 1.0}) {
    JohnsonCook::Parameters p = steel_4340();
    p.n = n;
    const JohnsonCook law(p);
    const PlaneStressElasticity elasticity(p.E, p.nu);
    const double rate_active_step = 1e-3 * std::pow(0.01, 1.0 / n) / p.reference_strain_rate;
    for (const double time_step : {infinite_time_step, 1e-6, rate_active_step}) {
      for (const StrainVoigt& direction : {StrainVoigt(1.0, -p.nu, 0.0), StrainVoigt(1.0, 0.5, 0.3)}) {
        // Each step's strain increment raises σ̄ by 0.01 B elastically (the
        // first from zero stress to A + 0.01 B).
        const double unit_equivalent = von_mises(elasticity.stress_increment(direction));
        JohnsonCook::State state = law.initial_state();
        for (int step = 0; step < 2; ++step) {
          const double target = step == 0 ? p.A + 0.01 * p.B : 0.01 * p.B;
          const StrainVoigt d_eps = direction * (target / unit_equivalent);
          const StressVoigt increment_stress = elasticity.stress_increment(d_eps);
          const long double trial[3] = {
              static_cast<long double>(state.stress.x()) + increment_stress.x(),
              static_cast<long double>(state.stress.y()) + increment_stress.y(),
              static_cast<long double>(state.stress.z()) + increment_stress.z()};
          const JohnsonCook::State before = state;
          INFO("n = " << n << ", time step " << time_step << " s, direction (" << direction.transpose()
                      << "), step " << step);
          JohnsonCook::UpdateResult result{};
          REQUIRE_NOTHROW(result = law.update(state, d_eps, UpdateContext{time_step}));
          REQUIRE(result.plastic);
          CHECK(result.iterations <= 10);
          const ReferenceReturn reference = reference_return(p, trial, before.eps_p, time_step);
          const double increment = state.eps_p - before.eps_p;
          INFO("reference Δε̄p " << static_cast<double>(reference.increment) << ", law's " << increment
                                << ", sensitivity " << static_cast<double>(reference.sensitivity));
          // The law stops at |S² − 1| ≤ 1e-12, |σ̄/σs − 1| ≤ 5e-13, which
          // moves ln Δε̄p by at most 5e-13/sensitivity; twice that, and the
          // round-off of the difference of ε̄p.
          const double tolerance = 1e-12 / std::abs(static_cast<double>(reference.sensitivity)) +
                                   4e-16 * state.eps_p / static_cast<double>(reference.increment);
          CHECK(std::abs(increment / static_cast<double>(reference.increment) - 1.0) <= tolerance);
          if (step == 0 && n < 1.0) CHECK(increment < 1e-30);  // the steep start
          const double flow = static_cast<double>(reference.flow_stress);
          for (int i = 0; i < 3; ++i)
            CHECK(std::abs(state.stress[i] - static_cast<double>(reference.stress[i])) <= 1e-12 * flow);
          // On the surface of the flow stress at the law's ε̄p and rate.
          const double surface = jc_flow_stress(p, state.eps_p, state.strain_rate, p.initial_temperature);
          CHECK(std::abs(von_mises(state.stress) / surface - 1.0) <= 1e-12);
          CHECK(state.sigma_y == Approx(surface).epsilon(1e-12));
          if (time_step == rate_active_step) CHECK(state.strain_rate > p.reference_strain_rate);
        }
      }
    }
  }
}

TEST_CASE("Johnson-Cook: a state rebuilt from the fields it lists continues bit for bit", "[material][rate]") {
  // What a checkpoint stores is what for_each_field lists. The series' anchors
  // and the earlier rates that start the return are state too: a state whose
  // listed fields are copied onto one of another history (so that a field
  // left out keeps that history's value) must continue exactly as the
  // original along a smoothly swinging tension-shear stream.
  JohnsonCook::Parameters p = steel_4340();
  p.A = 235e6;
  p.taylor_quinney = 0.9;
  p.density = 7850.0;
  p.specific_heat = 477.0;
  const JohnsonCook law(p);
  const UpdateContext context{1e-7};
  const auto increment = [](int k, double magnitude) {
    const double pi = 3.14159265358979323846;
    const double angle = 0.25 * pi * (1.0 - std::cos(4.0 * pi * k / 500.0));
    const double size = magnitude * (1.0 + 0.5 * std::sin(6.0 * pi * k / 500.0));
    return StrainVoigt(size * std::cos(angle), -0.5 * size * std::cos(angle), std::sqrt(3.0) * size * std::sin(angle));
  };
  const StrainVoigt preload = 1.2 * p.A / p.E * StrainVoigt(1.0, -0.5, 0.0);
  JohnsonCook::State state = law.initial_state(), other = law.initial_state();
  for (int step = 0; step < 10; ++step) law.update(state, preload / 10.0, context);
  for (int step = 0; step < 15; ++step) law.update(other, 1.3 * preload / 15.0, context);
  for (int k = 0; k < 200; ++k) law.update(state, increment(k, 5e-6), context);
  for (int k = 0; k < 150; ++k) law.update(other, increment(k + 40, 8e-6), context);
  JohnsonCook::State rebuilt = other;
  JohnsonCook::State::for_each_field(state, [&](const auto&... from) {
    JohnsonCook::State::for_each_field(rebuilt, [&](auto&... to) { ((to = from), ...); });
  });
  int plastic_steps = 0;
  for (int k = 200; k < 400; ++k) {
    plastic_steps += law.update(state, increment(k, 5e-6), context).plastic;
    law.update(rebuilt, increment(k, 5e-6), context);
    REQUIRE(rebuilt.eps_p == state.eps_p);
    REQUIRE(rebuilt.D == state.D);
    REQUIRE(rebuilt.temperature == state.temperature);
    REQUIRE(rebuilt.yield_stress == state.yield_stress);
    REQUIRE((rebuilt.stress.array() == state.stress.array()).all());
  }
  CHECK(plastic_steps > 150);
}

TEST_CASE("Cowper-Symonds: uniaxial flow stress at constant strain rates is the CS formula", "[material][rate]") {
  // Mild steel, D = 40.4 /s, q = 5 (Jones, Structural Impact, 2012, Table 8.2);
  // the paper's σs0 = 235 MPa and a plastic modulus of 1 GPa. q = 4.3 takes
  // the law's std::pow path, q = 5 its integer power.
  for (const double q : {5.0, 4.3}) {
  const CowperSymonds::Parameters p{210e9, 0.3, 235e6, 1e9, 40.4, q};
  const CowperSymonds law(p);
  for (const double rate : {1e-3, 1.0, 100.0, 1e4}) {
    const double time_step = 1e-4 / rate;  // axial increments of 1e-4
    CowperSymonds::State state = law.initial_state();
    int plastic_steps = 0;
    for (int step = 0; step < 300; ++step) {
      const CowperSymonds::State before = state;
      uniaxial_step(law, state, 1e-4, time_step);
      const double increment = state.eps_p - before.eps_p;
      if (increment <= 0.0) continue;
      ++plastic_steps;
      const double expected = cs_flow_stress(p, state.eps_p, increment / time_step);
      INFO("q " << q << ", rate " << rate << " /s, step " << step);
      REQUIRE(state.stress.x() == Approx(expected).epsilon(1e-6));
      REQUIRE(state.flow_stress == Approx(expected).epsilon(1e-6));
      REQUIRE(state.sigma_y == Approx(p.sigma_y0 + p.Ep * state.eps_p).epsilon(1e-12));
    }
    CHECK(plastic_steps > 250);
    CHECK(state.strain_rate == Approx(rate).epsilon(0.05));
  }
  }
}

TEST_CASE("Cowper-Symonds: a huge D is J2Plasticity bit for bit", "[material][rate]") {
  const CowperSymonds law({210e9, 0.3, 235e6, 1e9, 1e300, 5.0});
  const J2Plasticity j2({210e9, 0.3, 235e6, 1e9});
  CowperSymonds::State state = law.initial_state();
  J2Plasticity::State reference = j2.initial_state();
  int plastic = 0;
  for (int step = 0; step < 500; ++step) {
    const double angle = 0.013 * step;
    const StrainVoigt d(1.5e-5 * std::cos(angle), -0.7e-5 * std::cos(3.0 * angle), 2.5e-5 * std::sin(angle));
    const auto result = law.update(state, d, UpdateContext{1e-7});
    const auto expected = j2.update(reference, d);
    plastic += expected.plastic ? 1 : 0;
    REQUIRE(result.plastic == expected.plastic);
    REQUIRE(result.iterations == expected.iterations);
    REQUIRE(state.stress.x() == reference.stress.x());
    REQUIRE(state.stress.y() == reference.stress.y());
    REQUIRE(state.stress.z() == reference.stress.z());
    REQUIRE(state.eps_p == reference.eps_p);
    REQUIRE(state.sigma_y == reference.sigma_y);
  }
  CHECK(plastic > 100);
}

TEST_CASE("Rate-dependent laws: the returned stress lies on the rate-scaled yield surface", "[material][rate]") {
  JohnsonCook::Parameters jc = steel_4340();
  jc.taylor_quinney = 0.9;
  jc.density = 7850.0;
  jc.specific_heat = 477.0;
  jc.initial_temperature = 400.0;
  jc.A = 235e6;  // yields on the same path as the Cowper-Symonds steel
  jc.D1 = 10.0;
  const JohnsonCook johnson_cook(jc);
  const CowperSymonds::Parameters cs{210e9, 0.3, 235e6, 1e9, 40.4, 5.0};
  const CowperSymonds cowper_symonds(cs);
  for (const double time_step : {1e-8, 1e-6, 1e-3}) {
    JohnsonCook::State a = johnson_cook.initial_state();
    CowperSymonds::State b = cowper_symonds.initial_state();
    int plastic_a = 0, plastic_b = 0;
    for (int step = 0; step < 400; ++step) {
      const double angle = 0.031 * step;
      const StrainVoigt d(3e-5 * std::cos(angle), 2e-5 * std::sin(2.0 * angle), 4e-5 * std::sin(angle));
      INFO("time step " << time_step << " s, step " << step);
      const JohnsonCook::State a_before = a;
      if (johnson_cook.update(a, d, UpdateContext{time_step}).plastic) {
        ++plastic_a;
        REQUIRE(std::abs(a.strain_rate * time_step - (a.eps_p - a_before.eps_p)) <= 1e-15 * a.eps_p);
        REQUIRE(von_mises(a.stress) ==
                Approx(jc_flow_stress(jc, a.eps_p, a.strain_rate, a_before.temperature)).epsilon(1e-10));
      } else {
        REQUIRE(von_mises(a.stress) <= jc_flow_stress(jc, a.eps_p, 0.0, a.temperature) * (1.0 + 1e-12));
      }
      const CowperSymonds::State b_before = b;
      if (cowper_symonds.update(b, d, UpdateContext{time_step}).plastic) {
        ++plastic_b;
        // The rate the law reports (Δε̄p/Δt): at the smallest time step Δε̄p
        // falls below the spacing of doubles near ε̄p, so ε̄p's change does
        // not resolve it.
        REQUIRE(std::abs(b.strain_rate * time_step - (b.eps_p - b_before.eps_p)) <= 1e-15 * b.eps_p);
        REQUIRE(von_mises(b.stress) == Approx(cs_flow_stress(cs, b.eps_p, b.strain_rate)).epsilon(1e-10));
      } else {
        REQUIRE(von_mises(b.stress) <= (cs.sigma_y0 + cs.Ep * b.eps_p) * (1.0 + 1e-12));
      }
    }
    CHECK(plastic_a > 50);
    CHECK(plastic_b > 100);
  }
}

TEST_CASE("Rate-dependent laws: the time step is required once the point flows", "[material][rate]") {
  const JohnsonCook johnson_cook(steel_4340());
  const CowperSymonds cowper_symonds({210e9, 0.3, 235e6, 1e9, 40.4, 5.0});
  const double nan = std::numeric_limits<double>::quiet_NaN();
  for (const double bad : {nan, 0.0, -1e-6}) {
    JohnsonCook::State a = johnson_cook.initial_state();
    CowperSymonds::State b = cowper_symonds.initial_state();
    // Elastic steps need no time step.
    CHECK_NOTHROW(johnson_cook.update(a, StrainVoigt(1e-4, 0.0, 0.0), UpdateContext{bad}));
    CHECK_NOTHROW(cowper_symonds.update(b, StrainVoigt(1e-4, 0.0, 0.0), UpdateContext{bad}));
    CHECK_THROWS_WITH(johnson_cook.update(a, StrainVoigt(1e-2, 0.0, 0.0), UpdateContext{bad}),
                      Catch::Contains("parameter time_step ="));
    CHECK_THROWS_WITH(cowper_symonds.update(b, StrainVoigt(1e-2, 0.0, 0.0), UpdateContext{bad}),
                      Catch::Contains("parameter time_step ="));
  }
}

TEST_CASE("Sections pass the step's context to rate-dependent laws and update the others as before",
          "[material][rate][thickness]") {
  const StrainVoigt d_membrane(4e-4, -1e-4, 2e-4), d_curvature(0.3, 0.1, -0.2);
  SECTION("J2Plasticity: the context changes nothing") {
    const J2Plasticity j2({210e9, 0.3, 235e6, 1e9});
    const thickness::Section<thickness::Gauss<5>, J2Plasticity> section(j2, 0.01);
    auto with = section.initial_state(), without = section.initial_state();
    for (int step = 0; step < 20; ++step) {
      const auto r1 = section.update(with, d_membrane, d_curvature, UpdateContext{1e-7});
      const auto r2 = section.update(without, d_membrane, d_curvature);
      REQUIRE(r1.membrane == r2.membrane);
      REQUIRE(r1.moment == r2.moment);
    }
  }
  SECTION("CowperSymonds: each integral point is the law's update with the context") {
    const CowperSymonds law({210e9, 0.3, 235e6, 1e9, 40.4, 5.0});
    const thickness::Section<thickness::Gauss<5>, CowperSymonds> section(law, 0.01);
    auto state = section.initial_state();
    auto points = section.initial_state();
    for (int step = 0; step < 20; ++step) {
      section.update(state, d_membrane, d_curvature, UpdateContext{1e-6});
      for (int k = 0; k < 5; ++k)
        law.update(points[std::size_t(k)], d_membrane + section.zeta(k) * d_curvature, UpdateContext{1e-6});
    }
    for (int k = 0; k < 5; ++k) {
      CHECK(state[std::size_t(k)].stress == points[std::size_t(k)].stress);
      CHECK(state[std::size_t(k)].eps_p == points[std::size_t(k)].eps_p);
    }
    // The rate raised the flow stress above the quasi-static one at the yielded points.
    CHECK(state[0].flow_stress > 1.05 * state[0].sigma_y);
  }
}

TEST_CASE("Rate-dependent laws: bad parameters are refused by name", "[material][rate][bad_input]") {
  const auto refuses = [](JohnsonCook::Parameters p, const char* expected) {
    INFO(expected);
    CHECK_THROWS_WITH(JohnsonCook(p), Catch::Contains(expected));
  };
  const JohnsonCook::Parameters p = steel_4340();
  CHECK_NOTHROW(JohnsonCook(p));
  using Change = void (*)(JohnsonCook::Parameters&);
  const std::vector<std::pair<Change, const char*>> bad_parameters{
      {[](JohnsonCook::Parameters& q) { q.A = 0.0; }, "parameter A = 0"},
      {[](JohnsonCook::Parameters& q) { q.A = -1.0; }, "parameter A = -1"},
      {[](JohnsonCook::Parameters& q) { q.B = -1.0; }, "parameter B = -1"},
      {[](JohnsonCook::Parameters& q) { q.n = 0.0; }, "parameter n = 0"},
      {[](JohnsonCook::Parameters& q) { q.reference_strain_rate = 0.0; }, "parameter reference_strain_rate = 0"},
      {[](JohnsonCook::Parameters& q) { q.melting_temperature = q.reference_temperature; },
       "parameter melting_temperature = 293"},
      {[](JohnsonCook::Parameters& q) { q.C = -0.01; }, "parameter C = -0.01"},
      {[](JohnsonCook::Parameters& q) { q.m = 0.0; }, "parameter m = 0"},
      {[](JohnsonCook::Parameters& q) { q.taylor_quinney = 0.9, q.density = 7850.0, q.specific_heat = 0.0; },
       "parameter density*specific_heat = 0"},
      {[](JohnsonCook::Parameters& q) { q.taylor_quinney = 0.9, q.density = -7850.0, q.specific_heat = 477.0; },
       "parameter density*specific_heat = -"},
      {[](JohnsonCook::Parameters& q) { q.taylor_quinney = 1.5; }, "parameter taylor_quinney = 1.5"},
      {[](JohnsonCook::Parameters& q) { q.taylor_quinney = -0.1; }, "parameter taylor_quinney = -0.1"},
      {[](JohnsonCook::Parameters& q) { q.initial_temperature = 250.0; }, "parameter initial_temperature = 250"},
      {[](JohnsonCook::Parameters& q) { q.D1 = -3.0; }, "parameter D1 + D2*exp(D3*triaxiality) ="},
      {[](JohnsonCook::Parameters& q) { q.E = 0.0; }, "parameter E = 0"}};
  for (const auto& [change, expected] : bad_parameters) {
    JohnsonCook::Parameters q = p;
    change(q);
    refuses(q, expected);
  }
  {
    // Heating with a positive ρ·cp is accepted.
    JohnsonCook::Parameters q = p;
    q.taylor_quinney = 0.9, q.density = 7850.0, q.specific_heat = 477.0;
    CHECK_NOTHROW(JohnsonCook(q));
  }
  const CowperSymonds::Parameters cs{210e9, 0.3, 235e6, 1e9, 40.4, 5.0};
  CHECK_NOTHROW(CowperSymonds(cs));
  for (const double bad : {0.0, -40.4}) {
    auto q = cs;
    q.D = bad;
    CHECK_THROWS_WITH(CowperSymonds(q), Catch::Contains("parameter D = ") && Catch::Contains("> 0"));
    q = cs;
    q.q = bad;
    CHECK_THROWS_WITH(CowperSymonds(q), Catch::Contains("parameter q = ") && Catch::Contains("> 0"));
  }
}

TEST_CASE("Rate-dependent laws run in a Solver and restart from a checkpoint", "[material][rate][solver]") {
  // A 7 × 7 clamped plate under a pressure that yields it near the clamp
  // within a few explicit steps (tests/support/policy_smoke.hpp): each law
  // flows plastically with the solver's time step and stays finite.
  constexpr int max_steps = 3000;
  const auto run = [&](auto parameters, auto law_tag, auto other_parameters, const std::string& changed) {
    using Law = decltype(law_tag);
    SolverOptions options;
    options.nonlinear = true;
    Solver<approx::MLS<kernel::CubicSpline>, thickness::Gauss<3>, Law> solver(
        ShellModel::rectangular_plate(0.06, 0.06, 7, 7, 0.01), parameters, options);
    solver.clamp(solver.model().set("x_min"));
    solver.add_uniform_pressure(solver.model().all_particles(), 5e7);
    double largest_eps_p = 0.0;
    bool finite = true;
    int steps = 0;
    // Steps until some integral point has flowed, and ten more.
    for (int yielded_steps = 0; steps < max_steps && yielded_steps < 10; ++steps) {
      solver.step();
      largest_eps_p = 0.0;
      for (int p = 0; p < int(solver.model().stress_point_count()); ++p)
        for (int k = 0; k < 3; ++k) {
          largest_eps_p = std::max(largest_eps_p, solver.equivalent_plastic_strain(p, k));
          finite = finite && std::isfinite(solver.equivalent_stress(p, k));
        }
      if (largest_eps_p > 0.0) ++yielded_steps;
    }
    INFO(steps << " steps, largest plastic strain " << largest_eps_p);
    for (std::size_t i = 0; i < solver.particle_count(); ++i) finite = finite && solver.positions()[i].allFinite();
    CHECK(finite);
    CHECK(largest_eps_p > 0.0);
    CHECK(std::isfinite(solver.energy().balance()));
    // The State lists every field (for_each_field): a run reloaded from a
    // checkpoint repeats the uninterrupted one bit for bit (the last step's
    // rate, which starts the next Newton iteration, included).
    test_support::ScratchDirectory scratch(std::string("rate_dependent_") + Law::name);
    const std::string checkpoint = (scratch / "run.ckpt").string();
    solver.save_checkpoint(checkpoint);
    for (int step = 0; step < 10; ++step) solver.step();
    const std::vector<Vector3> uninterrupted = solver.positions();
    solver.load_checkpoint(checkpoint);
    for (int step = 0; step < 10; ++step) solver.step();
    for (std::size_t i = 0; i < uninterrupted.size(); ++i) {
      REQUIRE(solver.positions()[i].x() == uninterrupted[i].x());
      REQUIRE(solver.positions()[i].y() == uninterrupted[i].y());
      REQUIRE(solver.positions()[i].z() == uninterrupted[i].z());
    }
    // A law with another rate, temperature or failure constant does not
    // continue this run: the checkpoint is refused, naming the constant.
    Solver<approx::MLS<kernel::CubicSpline>, thickness::Gauss<3>, Law> other(
        ShellModel::rectangular_plate(0.06, 0.06, 7, 7, 0.01), other_parameters, options);
    CHECK_THROWS_WITH(other.load_checkpoint(checkpoint), Catch::Contains(changed));
  };
  JohnsonCook::Parameters jc = steel_4340();
  jc.A = 235e6;  // yields under the smoke test's pressure
  jc.taylor_quinney = 0.9;
  jc.density = 7850.0;
  jc.specific_heat = 477.0;
  JohnsonCook::Parameters jc_other_rate = jc;
  jc_other_rate.C *= 1.5;
  run(jc, JohnsonCook(jc), jc_other_rate, "material: C is");
  JohnsonCook::Parameters jc_other_failure = jc;
  jc_other_failure.D5 += 0.1;
  run(jc, JohnsonCook(jc), jc_other_failure, "material: D5 is");
  const CowperSymonds::Parameters cs{210e9, 0.3, 235e6, 1e9, 40.4, 5.0};
  run(cs, CowperSymonds(cs), CowperSymonds::Parameters{210e9, 0.3, 235e6, 1e9, 40.4, 4.0}, "material: Cowper-Symonds q is");
}

TEST_CASE("Johnson-Cook failure feeds the crack handler", "[material][rate][damage][solver]") {
  // The smoke test's clamped plate with a failure strain of 0.2 %: the
  // integral points that reach D = 1 fail, and a stress point whose points
  // have all failed leaves the integration as a damaged stress point.
  JohnsonCook::Parameters jc = steel_4340();
  jc.A = 235e6;
  jc.D1 = 0.002;
  jc.D2 = 0.0;
  jc.D3 = 0.0;
  SolverOptions options;
  options.nonlinear = true;
  Solver<approx::MLS<kernel::CubicSpline>, thickness::Gauss<3>, JohnsonCook, crack::LineSegments> solver(
      ShellModel::rectangular_plate(0.06, 0.06, 7, 7, 0.01), jc, options);
  solver.clamp(solver.model().set("x_min"));
  solver.add_uniform_pressure(solver.model().all_particles(), 5e7);
  int steps = 0;
  for (; steps < 3000 && solver.damaged_stress_point_count() == 0; ++steps) solver.step();
  INFO(steps << " steps");
  REQUIRE(solver.damaged_stress_point_count() > 0);
  // Every integral point of a damaged stress point has D >= 1.
  int damaged_points_checked = 0;
  for (int p = 0; p < int(solver.model().stress_point_count()); ++p) {
    bool all_failed = true;
    for (int k = 0; k < 3; ++k) all_failed = all_failed && solver.damage(p, k) >= 1.0;
    damaged_points_checked += all_failed ? 1 : 0;
  }
  CHECK(damaged_points_checked >= int(solver.damaged_stress_point_count()));
}
