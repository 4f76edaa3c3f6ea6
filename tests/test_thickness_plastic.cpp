// Plastic and damaged sections: the fully plastic bending limit per rule, the Global
// (Ilyushin) resultant plasticity and its damage reduction, every Rule × Law.

// The batched section update whatever the instruction set (section.hpp picks
// it by default with AVX-512 only): "every Rule x Law" below holds it bitwise
// to the law's single-point update().
#define SPHSHELL_BATCHED_SECTIONS 1
#include <sphshell/thickness/all.hpp>

#include <sphshell/material/all.hpp>

#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <limits>
#include <random>
#include <sstream>
#include <type_traits>
#include <vector>

// After the merge: namespace law = sphshell::material;
namespace law = sphshell::material;

using namespace sphshell::thickness;
using sphshell::StrainVoigt;
using sphshell::StressVoigt;

namespace {

constexpr double E = 210e9, nu = 0.3, sigma_y0 = 235e6, d = 0.01;
const law::J2Plasticity perfectly_plastic{{E, nu, sigma_y0, 0.0}};
const law::J2Plasticity hardening{{E, nu, sigma_y0, 2e9}};
const law::LemaitreDamage damaging{{E, nu, sigma_y0, 1e9, 0.02, 0.37, 0.24}};
const law::Elastic elastic{{E, nu}};

double mises(const StressVoigt& v) { return std::sqrt(v.x() * v.x() - v.x() * v.y() + v.y() * v.y() + 3.0 * v.z() * v.z()); }

// Curvature (1, −½, 0)κ: once fully plastic, the flow direction Ξσ ∥ (1, −½, 0) makes
// every fibre uniaxial, σ = ±σs e_x, so M → σs Σ A_k |ζ_k| for a rule and M0 = σs d²/4
// for the exact integral. Outer-fibre strain is driven to 1000 ε_y.
template <class Rule>
Resultants bend_far_beyond_yield() {
  const Section<Rule, law::J2Plasticity> section(perfectly_plastic, d);
  auto state = section.initial_state();
  const double yield_curvature = 2.0 * sigma_y0 / (E * d);
  const int steps = 4000;
  const StrainVoigt d_curvature = 1000.0 * yield_curvature / steps * StrainVoigt(1.0, -0.5, 0.0);
  Resultants result;
  for (int step = 0; step < steps; ++step)
    result = section.update(state, StrainVoigt::Zero(), d_curvature);
  return result;
}

template <class Rule>
double discrete_limit_ratio() {  // Σ w_k |ξ_k| = (Σ A_k |ζ_k|)/(d²/4)
  double sum = 0.0;
  for (int k = 0; k < Rule::num_points; ++k)
    sum += Rule::reference_weights[k] * std::abs(Rule::reference_points[k]);
  return sum;
}

struct LimitRow {
  const char* rule;
  int n;
  double ratio;     // M_x/M0 computed
  double expected;  // Σ w|ξ|
};

template <class Rule>
LimitRow limit_row(const char* label) {
  const Resultants result = bend_far_beyond_yield<Rule>();
  const double M0 = sigma_y0 * d * d / 4.0;
  return {label, Rule::num_points, result.moment.x() / M0, discrete_limit_ratio<Rule>()};
}

}  // namespace

TEST_CASE("thickness plastic bending limit tends to sigma_s d^2/4 as N grows", "[thickness]") {
  const LimitRow rows[] = {
      limit_row<Gauss<1>>("Gauss"),     limit_row<Gauss<2>>("Gauss"),
      limit_row<Gauss<3>>("Gauss"),     limit_row<Gauss<4>>("Gauss"),
      limit_row<Gauss<5>>("Gauss"),     limit_row<Gauss<6>>("Gauss"),
      limit_row<Gauss<7>>("Gauss"),     limit_row<Simpson<3>>("Simpson"),
      limit_row<Simpson<5>>("Simpson"), limit_row<Simpson<7>>("Simpson"),
      limit_row<Simpson<9>>("Simpson"), limit_row<Simpson<11>>("Simpson"),
      limit_row<Simpson<21>>("Simpson"), limit_row<Simpson<23>>("Simpson"),
      limit_row<Global>("Global")};
  std::ostringstream table;
  table << "Fully plastic bending, M_x/M0 (M0 = sigma_s d^2/4), outer fibre at 1000 eps_y\n"
        << "rule      N   M_x/M0      error      sum w|xi| - 1\n";
  for (const LimitRow& row : rows) {
    table << std::left << std::setw(9) << row.rule << std::right << std::setw(3) << row.n
          << std::fixed << std::setprecision(6) << std::setw(11) << row.ratio << std::showpos
          << std::setw(11) << row.ratio - 1.0 << std::noshowpos;
    if (row.n > 0)
      table << std::showpos << std::setw(13) << row.expected - 1.0 << std::noshowpos;
    else
      table << "          n/a";
    table << '\n';
  }
  WARN(table.str());

  for (const LimitRow& row : rows) {
    INFO(row.rule << " N = " << row.n);
    if (row.n == 0)  // Global: the Ilyushin surface is exact in pure bending
      CHECK(row.ratio == Approx(1.0).epsilon(1e-9));
    else  // every fibre at ±σs: the rule's own quadrature of |ζ|
      CHECK(row.ratio == Approx(row.expected).epsilon(1e-6));
  }
  auto error = [&](int index) { return std::abs(rows[index].ratio - 1.0); };
  // Gauss: a point on the mid-surface is wasted in bending, so the error shrinks along
  // the even and the odd N separately.
  CHECK(error(0) == Approx(1.0));
  CHECK(error(3) < error(1));
  CHECK(error(5) < error(3));
  CHECK(error(4) < error(2));
  CHECK(error(6) < error(4));
  CHECK(error(5) < 0.025);
  CHECK(error(6) < 0.035);
  // Simpson is exact when the kink at ζ = 0 is a panel boundary, (N − 1)/2 even, and
  // converges like 1/N² otherwise.
  CHECK(error(8) < 1e-6);
  CHECK(error(10) < 1e-6);
  CHECK(error(12) < 1e-6);
  CHECK(error(9) < error(7));
  CHECK(error(11) < error(9));
  CHECK(error(13) < error(11));
  CHECK(error(13) < 0.01);
}

TEST_CASE("thickness Global: pure bending and pure tension returns sit on M0 and N0",
          "[thickness]") {
  const Section<Global, law::J2Plasticity> section(perfectly_plastic, d);
  const double N0 = sigma_y0 * d, M0 = sigma_y0 * d * d / 4.0;
  SECTION("one large step of pure curvature") {
    for (const StrainVoigt& curvature : {StrainVoigt(1.0, 0, 0), StrainVoigt(0.3, 0.7, -0.2),
                                         StrainVoigt(-2.0, 1.0, 0.5)}) {
      auto state = section.initial_state();
      const Resultants result = section.update(state, StrainVoigt::Zero(), curvature);
      CHECK(mises(result.moment) == Approx(M0).epsilon(1e-12));
      CHECK(result.membrane.norm() <= 1e-12 * N0);
      CHECK(state.eps_p > 0.0);
    }
  }
  SECTION("one large step of pure membrane strain") {
    auto state = section.initial_state();
    const Resultants result = section.update(state, StrainVoigt(0.01, -0.002, 0.003), StrainVoigt::Zero());
    CHECK(mises(result.membrane) == Approx(N0).epsilon(1e-12));
    CHECK(result.moment.norm() <= 1e-12 * M0);
  }
  SECTION("uniaxial tension path reaches N = (N0, 0, 0)") {
    auto state = section.initial_state();
    Resultants result;
    // The transient from the elastic direction (1, −½, 0) ≠ (1, −ν, 0) decays with the
    // plastic strain; 0.1 is ≈ 90 ε_y.
    for (int step = 0; step < 5000; ++step)
      result = section.update(state, StrainVoigt(2e-5, -1e-5, 0.0), StrainVoigt::Zero());
    CHECK(result.membrane.x() == Approx(N0).epsilon(1e-9));
    CHECK(std::abs(result.membrane.y()) <= 1e-9 * N0);
  }
  SECTION("combined N and M on the interaction curve") {
    // Uniaxial N_x, M_x: F = n² + m² + |n m|/√3 with n = N/N0, m = M/M0.
    auto state = section.initial_state();
    Resultants result;
    for (int step = 0; step < 20000; ++step)
      result = section.update(state, StrainVoigt(0.5e-5, -0.25e-5, 0.0),
                              StrainVoigt(2e-3, -1e-3, 0.0));
    const double n = result.membrane.x() / N0, m = result.moment.x() / M0;
    CHECK(n > 0.05);
    CHECK(m > 0.05);
    CHECK(n * n + m * m + std::abs(n * m) / std::sqrt(3.0) == Approx(1.0).epsilon(1e-6));
  }
}

TEST_CASE("thickness Global: resultants stay on or inside the yield surface", "[thickness]") {
  const Section<Global, law::J2Plasticity> section(hardening, d);
  std::mt19937 generator(2015);
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  const double strain_scale = 4e-4, curvature_scale = 8e-2;
  auto state = section.initial_state();
  int plastic_steps = 0, ridge_like = 0;
  double previous_eps_p = 0.0;
  for (int step = 0; step < 3000; ++step) {
    // Blocks of 30 steps in one random direction, so it both loads and reverses.
    static StrainVoigt strain_rate, curvature_rate;
    if (step % 30 == 0) {
      strain_rate = strain_scale * StrainVoigt(uniform(generator), uniform(generator), uniform(generator));
      curvature_rate = curvature_scale * StrainVoigt(uniform(generator), uniform(generator), uniform(generator));
      if (step % 90 == 0) strain_rate.setZero();  // pure bending sits on the ridge
    }
    section.update(state, strain_rate, curvature_rate);
    INFO("step " << step);
    const double F = section.ilyushin_function(state);
    REQUIRE(F <= 1.0 + 1e-10);
    REQUIRE(state.eps_p >= previous_eps_p);
    if (state.eps_p > previous_eps_p) {
      ++plastic_steps;
      CHECK(F == Approx(1.0).epsilon(1e-10));
      // Hardening through the generalized equivalent plastic strain.
      CHECK(state.sigma_y == Approx(sigma_y0 + 2e9 * state.eps_p).epsilon(1e-12));
      const double N0 = state.sigma_y * d, M0 = state.sigma_y * d * d / 4.0;
      const double coupling = (state.membrane.x() * (state.moment.x() - 0.5 * state.moment.y()) +
                               state.membrane.y() * (state.moment.y() - 0.5 * state.moment.x()) +
                               3.0 * state.membrane.z() * state.moment.z()) / (N0 * M0);
      if (std::abs(coupling) < 1e-9) ++ridge_like;
    }
    previous_eps_p = state.eps_p;
  }
  INFO("plastic steps " << plastic_steps << ", on the ridge " << ridge_like);
  CHECK(plastic_steps > 500);
  CHECK(ridge_like > 0);
}

TEST_CASE("thickness Global membrane plasticity equals the integral model", "[thickness]") {
  // With no curvature every integral point carries the same stress, and the Global
  // return restricted to N is the same consistent J2 return on N/d.
  const Section<Global, law::J2Plasticity> global(hardening, d);
  const Section<Gauss<3>, law::J2Plasticity> integral(hardening, d);
  auto global_state = global.initial_state();
  auto integral_state = integral.initial_state();
  const StrainVoigt directions[] = {StrainVoigt(2e-5, 0.0, 0.0), StrainVoigt(-1e-5, 3e-5, 1e-5),
                                    StrainVoigt(0.0, -2e-5, -2e-5)};
  for (const StrainVoigt& direction : directions) {
    for (int step = 0; step < 300; ++step) {
      const Resultants a = global.update(global_state, direction, StrainVoigt::Zero());
      const Resultants b = integral.update(integral_state, direction, StrainVoigt::Zero());
      // Loose enough for any converged return map, far below the 3× error of an
      // inconsistently scaled flow (docs/method.md §5).
      REQUIRE((a.membrane - b.membrane).norm() <= 1e-7 * b.membrane.norm());
    }
  }
  CHECK(global.equivalent_plastic_strain(global_state, 0) ==
        Approx(integral.equivalent_plastic_strain(integral_state, 1)).epsilon(1e-7));
  CHECK(global.equivalent_stress(global_state, 0) ==
        Approx(integral.equivalent_stress(integral_state, 1)).epsilon(1e-7));
}

TEST_CASE("thickness Global damage is monotone, bounded by Dc and fails at eps_c", "[thickness]") {
  const Section<Global, law::LemaitreDamage> section(damaging, d);
  auto state = section.initial_state();
  double previous_D = 0.0, previous_eps_p = 0.0;
  int step = 0;
  int damaged_returns = 0;
  for (; step < 100000 && !section.all_failed(state); ++step) {
    const StrainVoigt curvature = (step / 500) % 2 == 0 ? StrainVoigt(0.4, -0.2, 0.0)
                                                        : StrainVoigt(-0.1, 0.05, 0.0);
    section.update(state, StrainVoigt(2e-5, -1e-5, 0.0), curvature * 1e-3);
    const double D = section.damage(state, 0);
    INFO("step " << step << " D " << D);
    REQUIRE(D >= previous_D);
    REQUIRE(D >= 0.0);
    REQUIRE(D <= 0.24);
    if (!state.failed) {
      // D = Dc (ε̄p − ε̄sp)/(ε̄cp − ε̄sp) above the threshold (T = 1/3 reduction).
      const double expected = state.eps_p <= 0.02 ? 0.0 : 0.24 * (state.eps_p - 0.02) / 0.35;
      REQUIRE(D == Approx(expected).margin(1e-12));
      REQUIRE(section.ilyushin_function(state) <= 1.0 + 1e-10);
      if (state.eps_p > previous_eps_p) {
        // σ̄_I = (1 − D) σs after every return.
        REQUIRE(section.equivalent_stress(state, 0) ==
                Approx((1.0 - D) * state.sigma_y).epsilon(1e-10));
        if (D > 0.0) ++damaged_returns;
      }
    }
    previous_D = D;
    previous_eps_p = state.eps_p;
  }
  REQUIRE(section.all_failed(state));
  CHECK(damaged_returns > 100);
  CHECK(state.eps_p >= 0.37);
  CHECK(section.damage(state, 0) == 0.24);
  const Resultants after = section.update(state, StrainVoigt(1e-3, 0, 0), StrainVoigt(1, 0, 0));
  CHECK(after.membrane.norm() == 0.0);
  CHECK(after.moment.norm() == 0.0);
  CHECK(section.elastic_energy(state) == 0.0);
}

TEST_CASE("thickness Global rejects non-finite strain increments", "[thickness]") {
  const Section<Global, law::J2Plasticity> section(hardening, d);
  auto state = section.initial_state();
  const double nan = std::numeric_limits<double>::quiet_NaN();
  CHECK_THROWS_AS(section.update(state, StrainVoigt(nan, 0, 0), StrainVoigt::Zero()),
                  sphshell::Error);
  CHECK_THROWS_AS(section.update(state, StrainVoigt::Zero(), StrainVoigt(0, 0, nan)),
                  sphshell::Error);
}

TEST_CASE("thickness integral damage: a stress point fails only when every point has",
          "[thickness]") {
  const Section<Gauss<3>, law::LemaitreDamage> section(damaging, d);
  SECTION("pure bending never fails the mid-surface point") {
    auto state = section.initial_state();
    for (int step = 0; step < 4000; ++step)
      section.update(state, StrainVoigt::Zero(), StrainVoigt(0.5, -0.25, 0.0));
    CHECK(section.damage(state, 0) == Approx(0.24).margin(1e-12));
    CHECK(section.damage(state, 2) == Approx(0.24).margin(1e-12));
    CHECK(section.damage(state, 1) == 0.0);
    CHECK(section.resultants(state).moment.norm() == 0.0);
    CHECK_FALSE(section.all_failed(state));
  }
  SECTION("tension fails them all") {
    auto state = section.initial_state();
    int step = 0;
    while (!section.all_failed(state) && step < 10000) {
      section.update(state, StrainVoigt(1e-3, -0.5e-3, 0.0), StrainVoigt::Zero());
      ++step;
    }
    CHECK(section.all_failed(state));
    CHECK(section.resultants(state).membrane.norm() == 0.0);
  }
}

namespace {

template <class Rule, class Law>
void exercise(const Law& material) {
  const Section<Rule, Law> section(material, d);
  auto state = section.initial_state();
  static_assert(decltype(section)::output_points == (Rule::num_points == 0 ? 1 : Rule::num_points));
  // An integral rule's section (batched or not) must give every point the
  // state of the law's single-point update() at e + zeta_k kappa: the same
  // bits, unless the compiler may fuse a*b + c into one rounding (FMA), which
  // it may do in one path and not the other. The deviation is measured in
  // stress against sigma_y0 and in plastic strain and damage against 1.
  std::vector<typename Law::State> reference(std::size_t(Rule::num_points), material.initial_state());
  double deviation = 0.0;
  Resultants result;
  for (int step = 0; step < 200; ++step) {
    const double sign = step < 100 ? 1.0 : -1.0;
    const StrainVoigt d_membrane = sign * StrainVoigt(1e-4, 0.5e-4, -0.3e-4),
                      d_curvature = sign * StrainVoigt(0.05, -0.02, 0.01);
    result = section.update(state, d_membrane, d_curvature);
    if constexpr (Rule::num_points >= 1) {
      static_assert(decltype(section)::batched == !std::is_same_v<Law, law::LemaitreDamage>);
      for (int k = 0; k < Rule::num_points; ++k) {
        auto& point = reference[std::size_t(k)];
        material.update(point, d_membrane + section.zeta(k) * d_curvature);
        const auto& computed = state[std::size_t(k)];
        deviation = std::max({deviation, (computed.stress - point.stress).cwiseAbs().maxCoeff() / sigma_y0,
                              std::abs(material.equivalent_plastic_strain(computed) -
                                       material.equivalent_plastic_strain(point)),
                              std::abs(material.damage(computed) - material.damage(point))});
      }
    }
  }
#if defined(__FMA__)
  CHECK(deviation <= 1e-12);
#else
  CHECK(deviation == 0.0);
#endif
  CHECK(result.membrane.allFinite());
  CHECK(result.moment.allFinite());
  CHECK(section.elastic_energy(state) >= 0.0);
  for (int k = 0; k < section.output_points; ++k) {
    CHECK(std::isfinite(section.equivalent_stress(state, k)));
    CHECK(section.equivalent_plastic_strain(state, k) >= 0.0);
    CHECK(section.damage(state, k) >= 0.0);
    CHECK(std::isfinite(section.zeta(k)));
    CHECK(section.weight(k) > 0.0);
  }
  if constexpr (Law::has_plasticity) {
    double largest = 0.0;
    for (int k = 0; k < section.output_points; ++k)
      largest = std::max(largest, section.equivalent_plastic_strain(state, k));
    CHECK(largest > 0.0);
  }
  CHECK_FALSE(section.all_failed(state));
}

}  // namespace

TEMPLATE_TEST_CASE("thickness every Rule x Law compiles and runs", "[thickness]", Gauss<1>,
                   Gauss<2>, Gauss<3>, Gauss<4>, Gauss<5>, Gauss<6>, Gauss<7>, Simpson<3>,
                   Simpson<5>, Simpson<7>, Simpson<9>, Global) {
  exercise<TestType>(elastic);
  exercise<TestType>(hardening);
  exercise<TestType>(damaging);
}
