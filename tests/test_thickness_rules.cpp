// Quadrature rules through the thickness: points, weights, polynomial exactness.

#include <sphshell/thickness/all.hpp>

#include <catch2/catch.hpp>

#include <cmath>
#include <numeric>

using namespace sphshell::thickness;

namespace {

// Exact ∫_{-d/2}^{d/2} ζ^p dζ.
double exact_moment(int p, double d) {
  return p % 2 == 1 ? 0.0 : 2.0 * std::pow(0.5 * d, p + 1) / (p + 1);
}

template <class Rule>
double rule_moment(int p, double d) {
  double sum = 0.0;
  for (int k = 0; k < Rule::num_points; ++k)
    sum += Rule::weight(k, d) * std::pow(Rule::zeta(k, d), p);
  return sum;
}

// P_N(x) by the three-term recurrence, independent of the tables.
double legendre(int n, double x) {
  double previous = 1.0, current = x;
  if (n == 0) return previous;
  for (int k = 2; k <= n; ++k) {
    const double next = ((2 * k - 1) * x * current - (k - 1) * previous) / k;
    previous = current;
    current = next;
  }
  return current;
}

double legendre_derivative(int n, double x) {
  return n * (x * legendre(n, x) - legendre(n - 1, x)) / (x * x - 1.0);
}

}  // namespace

static_assert(is_thickness_rule<Gauss<1>> && is_thickness_rule<Gauss<7>>);
static_assert(is_thickness_rule<Simpson<3>> && is_thickness_rule<Simpson<11>>);
static_assert(is_thickness_rule<Global>);
static_assert(!is_thickness_rule<int>);
static_assert(Gauss<5>::num_points == 5 && Simpson<9>::num_points == 9 && Global::num_points == 0);
// The tables are usable at compile time.
static_assert(Simpson<5>::reference_weights[1] == 4.0 * 0.5 / 3.0);
static_assert(Gauss<3>::zeta(2, 2.0) == Gauss<3>::reference_points[2]);

TEMPLATE_TEST_CASE("thickness rule: weights sum to 2, points symmetric inside [-1, 1]",
                   "[thickness]", Gauss<1>, Gauss<2>, Gauss<3>, Gauss<4>, Gauss<5>, Gauss<6>,
                   Gauss<7>, Simpson<3>, Simpson<5>, Simpson<7>, Simpson<9>) {
  const auto& points = TestType::reference_points;
  const auto& weights = TestType::reference_weights;
  CHECK(std::accumulate(weights.begin(), weights.end(), 0.0) == Approx(2.0).epsilon(1e-15));
  for (int k = 0; k < TestType::num_points; ++k) {
    const int mirror = TestType::num_points - 1 - k;
    CHECK(points[k] >= -1.0);
    CHECK(points[k] <= 1.0);
    CHECK(weights[k] > 0.0);
    CHECK(points[k] == Approx(-points[mirror]).margin(1e-16));
    CHECK(weights[k] == Approx(weights[mirror]).epsilon(1e-15));
    if (k > 0) CHECK(points[k] > points[k - 1]);
  }
}

TEST_CASE("Gauss points agree with closed forms", "[thickness]") {
  CHECK(Gauss<1>::reference_points[0] == 0.0);
  CHECK(Gauss<1>::reference_weights[0] == 2.0);
  CHECK(Gauss<2>::reference_points[1] == Approx(1.0 / std::sqrt(3.0)).epsilon(1e-15));
  CHECK(Gauss<3>::reference_points[2] == Approx(std::sqrt(0.6)).epsilon(1e-15));
  CHECK(Gauss<3>::reference_weights[0] == Approx(5.0 / 9.0).epsilon(1e-15));
  CHECK(Gauss<3>::reference_weights[1] == Approx(8.0 / 9.0).epsilon(1e-15));
  const double s = 2.0 / 7.0 * std::sqrt(6.0 / 5.0);
  CHECK(Gauss<4>::reference_points[3] == Approx(std::sqrt(3.0 / 7.0 + s)).epsilon(1e-15));
  CHECK(Gauss<4>::reference_points[2] == Approx(std::sqrt(3.0 / 7.0 - s)).epsilon(1e-15));
  CHECK(Gauss<4>::reference_weights[0] == Approx((18.0 - std::sqrt(30.0)) / 36.0).epsilon(1e-15));
  CHECK(Gauss<4>::reference_weights[1] == Approx((18.0 + std::sqrt(30.0)) / 36.0).epsilon(1e-15));
  const double r = 2.0 * std::sqrt(10.0 / 7.0);
  CHECK(Gauss<5>::reference_points[4] == Approx(std::sqrt(5.0 + r) / 3.0).epsilon(1e-15));
  CHECK(Gauss<5>::reference_points[3] == Approx(std::sqrt(5.0 - r) / 3.0).epsilon(1e-15));
  CHECK(Gauss<5>::reference_weights[2] == Approx(128.0 / 225.0).epsilon(1e-15));
  CHECK(Gauss<5>::reference_weights[0] ==
        Approx((322.0 - 13.0 * std::sqrt(70.0)) / 900.0).epsilon(1e-15));
  CHECK(Gauss<5>::reference_weights[1] ==
        Approx((322.0 + 13.0 * std::sqrt(70.0)) / 900.0).epsilon(1e-15));
  CHECK(Gauss<7>::reference_weights[3] == Approx(512.0 / 1225.0).epsilon(1e-15));
}

TEMPLATE_TEST_CASE_SIG("Gauss points are the roots of P_N, weights 2/((1-x^2) P_N'^2)",
                       "[thickness]", ((int N), N), 2, 3, 4, 5, 6, 7) {
  for (int k = 0; k < N; ++k) {
    const double x = Gauss<N>::reference_points[k];
    CHECK(std::abs(legendre(N, x)) < 1e-14);
    const double dp = legendre_derivative(N, x);
    CHECK(Gauss<N>::reference_weights[k] == Approx(2.0 / ((1.0 - x * x) * dp * dp)).epsilon(1e-13));
  }
}

TEMPLATE_TEST_CASE_SIG("Gauss<N> integrates degree <= 2N-1 exactly and not degree 2N",
                       "[thickness]", ((int N), N), 1, 2, 3, 4, 5, 6, 7) {
  for (double d : {1.0, 0.01, 3.7}) {
    for (int p = 0; p <= 2 * N - 1; ++p) {
      INFO("N = " << N << ", degree " << p << ", d = " << d);
      CHECK(rule_moment<Gauss<N>>(p, d) ==
            Approx(exact_moment(p, d)).margin(1e-14 * std::pow(0.5 * d, p + 1)));
    }
    const double exact = exact_moment(2 * N, d);
    const double error = rule_moment<Gauss<N>>(2 * N, d) - exact;
    INFO("N = " << N << ", degree 2N error " << error / exact);
    CHECK(std::abs(error) > 1e-3 * exact);
  }
}

TEMPLATE_TEST_CASE_SIG("Simpson<N> integrates cubics exactly and not quartics", "[thickness]",
                       ((int N), N), 3, 5, 7, 9, 11) {
  for (double d : {1.0, 0.01}) {
    for (int p = 0; p <= 3; ++p) {
      INFO("N = " << N << ", degree " << p);
      CHECK(rule_moment<Simpson<N>>(p, d) ==
            Approx(exact_moment(p, d)).margin(1e-14 * std::pow(0.5 * d, p + 1)));
    }
    // Composite Simpson error: −(b − a) h⁴ f⁗/180 with f⁗ = 24, h = d/(N − 1).
    const double h = d / (N - 1);
    const double error = rule_moment<Simpson<N>>(4, d) - exact_moment(4, d);
    CHECK(error == Approx(d * std::pow(h, 4) * 24.0 / 180.0).epsilon(1e-10));
    CHECK(error > 0.0);
  }
}

TEST_CASE("Scaled points and weights map [-1, 1] onto [-d/2, d/2]", "[thickness]") {
  const double d = 0.02;
  CHECK(Gauss<2>::zeta(0, d) == Approx(-0.01 / std::sqrt(3.0)).epsilon(1e-15));
  CHECK(Gauss<2>::weight(1, d) == Approx(0.01).epsilon(1e-15));
  CHECK(Simpson<3>::zeta(0, d) == Approx(-0.01).epsilon(1e-15));
  CHECK(Simpson<3>::zeta(2, d) == Approx(0.01).epsilon(1e-15));
  CHECK(Simpson<3>::weight(1, d) == Approx(4.0 * 0.01 / 3.0).epsilon(1e-15));
}
