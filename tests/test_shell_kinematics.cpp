// The shell kinematics of an integration point in lanes (shell/kinematics.hpp;
// docs/method.md §3), eight points side by side as the assembler runs them:
// each lane's Green strains against the definition written here with Eigen
// (½(a_α·a_β − A_α·A_β), ...), the linear strains against the exact
// derivative of the Green strains (they are quadratic in the gradients, so a
// central difference of step 1 is exact up to round-off), the conjugate
// forces against the virtual work of the weighted stresses on the same
// derivative, and every lane against the function of one point.
#include <sphshell/core/types.hpp>
#include <sphshell/shell/kinematics.hpp>

#include <catch2/catch.hpp>

#include <Eigen/Dense>

#include <algorithm>
#include <array>
#include <cmath>
#include <random>
#include <utility>

using namespace sphshell;

namespace {

constexpr int lanes = 8;

Vector3 random_vector(std::mt19937_64& random, double scale) {
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  return scale * Vector3(uniform(random), uniform(random), uniform(random));
}

// A point's gradients near a unit reference frame: tangents of length ~1,
// a director of length ~1, director derivatives of a curvature ~10.
shell::SurfaceGradients random_gradients(std::mt19937_64& random) {
  shell::SurfaceGradients g;
  g.a1 = Vector3(1.0, 0.0, 0.0) + random_vector(random, 0.2);
  g.a2 = Vector3(0.0, 1.0, 0.0) + random_vector(random, 0.2);
  g.n = Vector3(0.0, 0.0, 1.0) + random_vector(random, 0.2);
  g.n1 = random_vector(random, 10.0);
  g.n2 = random_vector(random, 10.0);
  return g;
}

shell::SurfaceGradients combine(const shell::SurfaceGradients& x, double t, const shell::SurfaceGradients& y) {
  return shell::SurfaceGradients{x.a1 + t * y.a1, x.a2 + t * y.a2, x.n + t * y.n, x.n1 + t * y.n1, x.n2 + t * y.n2};
}

// The Green strains from their definition (docs/method.md §3), vector (e11,
// e22, 2e12, κ11, κ22, 2κ12, γ1, γ2).
Eigen::Matrix<double, 8, 1> green_definition(const shell::SurfaceGradients& g, const shell::SurfaceGradients& r) {
  const auto half_sym = [](const Vector3& a, const Vector3& n_b, const Vector3& b, const Vector3& n_a) {
    return 0.5 * (a.dot(n_b) + b.dot(n_a));
  };
  Eigen::Matrix<double, 8, 1> s;
  s << 0.5 * (g.a1.dot(g.a1) - r.a1.dot(r.a1)), 0.5 * (g.a2.dot(g.a2) - r.a2.dot(r.a2)),
      2.0 * 0.5 * (g.a1.dot(g.a2) - r.a1.dot(r.a2)), g.a1.dot(g.n1) - r.a1.dot(r.n1),
      g.a2.dot(g.n2) - r.a2.dot(r.n2),
      2.0 * (half_sym(g.a1, g.n2, g.a2, g.n1) - half_sym(r.a1, r.n2, r.a2, r.n1)), g.a1.dot(g.n) - r.a1.dot(r.n),
      g.a2.dot(g.n) - r.a2.dot(r.n);
  return s;
}

Eigen::Matrix<double, 8, 1> flat(const shell::StrainLanes<lanes>& s, int l) {
  Eigen::Matrix<double, 8, 1> v;
  v << s.membrane.c[0][l], s.membrane.c[1][l], s.membrane.c[2][l], s.curvature.c[0][l], s.curvature.c[1][l],
      s.curvature.c[2][l], s.shear.c[0][l], s.shear.c[1][l];
  return v;
}

Eigen::Matrix<double, 8, 1> flat(const shell::Strains& s) {
  Eigen::Matrix<double, 8, 1> v;
  v << s.membrane, s.curvature, s.shear;
  return v;
}

struct Group {
  std::array<shell::SurfaceGradients, lanes> current, reference, variation;
  shell::SurfaceGradientLanes<lanes> current_lanes, reference_lanes;
  shell::ReferenceProductLanes<lanes> products;
};

Group random_group(std::mt19937_64& random) {
  Group group;
  for (int l = 0; l < lanes; ++l) {
    group.reference[std::size_t(l)] = random_gradients(random);
    group.current[std::size_t(l)] = random_gradients(random);
    group.variation[std::size_t(l)] = shell::SurfaceGradients{random_vector(random, 1e-3), random_vector(random, 1e-3),
                                                              random_vector(random, 1e-3), random_vector(random, 1e-2),
                                                              random_vector(random, 1e-2)};
    group.current_lanes.set(l, group.current[std::size_t(l)]);
    group.reference_lanes.set(l, group.reference[std::size_t(l)]);
    group.products.set(l, shell::reference_products(group.reference[std::size_t(l)]));
  }
  return group;
}

double relative_difference(const Eigen::VectorXd& x, const Eigen::VectorXd& y) {
  return (x - y).cwiseAbs().maxCoeff() / std::max(y.cwiseAbs().maxCoeff(), 1e-300);
}

}  // namespace

TEST_CASE("kinematics in lanes: Green strains of every lane against their definition", "[kinematics]") {
  std::mt19937_64 random(39);
  for (int trial = 0; trial < 20; ++trial) {
    const Group group = random_group(random);
    shell::StrainLanes<lanes> strains;
    shell::green_strains(group.current_lanes, group.products, strains);
    for (int l = 0; l < lanes; ++l) {
      const shell::SurfaceGradients& current = group.current[std::size_t(l)];
      const shell::SurfaceGradients& reference = group.reference[std::size_t(l)];
      INFO("trial " << trial << " lane " << l);
      CHECK(relative_difference(flat(strains, l), green_definition(current, reference)) < 1e-13);
      // The one-point function is the lanes' formula at one lane: equal to
      // round-off in every build (bitwise where no multiply-adds are contracted).
      CHECK(relative_difference(flat(shell::green_strains(current, reference)), flat(strains, l)) < 1e-15);
    }
  }
}

TEST_CASE("kinematics in lanes: linear strains are the derivative of the Green strains", "[kinematics]") {
  // G(r + t u) = G(r) + t L(u) + t² Q(u) with L the linear strains of u about
  // r, so L(u) = (G(r + u) − G(r − u)) / 2 exactly.
  std::mt19937_64 random(3939);
  for (int trial = 0; trial < 20; ++trial) {
    const Group group = random_group(random);
    shell::StrainLanes<lanes> strains;
    shell::linear_strains(group.current_lanes, group.reference_lanes, strains);
    for (int l = 0; l < lanes; ++l) {
      const shell::SurfaceGradients& r = group.reference[std::size_t(l)];
      const shell::SurfaceGradients u = combine(group.current[std::size_t(l)], -1.0, r);
      const Eigen::Matrix<double, 8, 1> derivative =
          0.5 * (green_definition(combine(r, 1.0, u), r) - green_definition(combine(r, -1.0, u), r));
      INFO("trial " << trial << " lane " << l);
      CHECK(relative_difference(flat(strains, l), derivative) < 1e-12);
      CHECK(relative_difference(flat(shell::linear_strains(group.current[std::size_t(l)], r)), flat(strains, l)) <
            1e-15);
    }
  }
}

TEST_CASE("kinematics in lanes: conjugate forces do the virtual work of the stresses", "[kinematics]") {
  // Σ F·δg = N·δe + M·δκ + Q·δγ for any variation δg of the gradients, the
  // strain variations taken at the current gradients (exactly, as above).
  std::mt19937_64 random(393939);
  for (int trial = 0; trial < 20; ++trial) {
    const Group group = random_group(random);
    shell::WeightedStressLanes<lanes> stresses;
    std::array<Eigen::Matrix<double, 8, 1>, lanes> stress_of{};
    std::uniform_real_distribution<double> uniform(-1.0, 1.0);
    for (int l = 0; l < lanes; ++l) {
      for (int i = 0; i < 8; ++i) stress_of[std::size_t(l)][i] = 1e6 * uniform(random);
      const auto& s = stress_of[std::size_t(l)];
      stresses.set(l, shell::Strains{StrainVoigt(s[0], s[1], s[2]), StrainVoigt(s[3], s[4], s[5]), Vector2(s[6], s[7])});
    }
    shell::ConjugateForceLanes<lanes> forces;
    shell::conjugate_forces(group.current_lanes, stresses, forces);
    for (int l = 0; l < lanes; ++l) {
      const shell::SurfaceGradients& b = group.current[std::size_t(l)];
      const shell::SurfaceGradients& v = group.variation[std::size_t(l)];
      const shell::SurfaceGradients f = forces.at(l);
      const double work = f.a1.dot(v.a1) + f.a2.dot(v.a2) + f.n.dot(v.n) + f.n1.dot(v.n1) + f.n2.dot(v.n2);
      const Eigen::Matrix<double, 8, 1> d_strain =
          0.5 * (green_definition(combine(b, 1.0, v), b) - green_definition(combine(b, -1.0, v), b));
      const double expected = stress_of[std::size_t(l)].dot(d_strain);
      // The scale of the sum's terms, for the round-off.
      const double scale = stress_of[std::size_t(l)].cwiseAbs().dot(d_strain.cwiseAbs());
      INFO("trial " << trial << " lane " << l << ": work " << work << ", expected " << expected);
      CHECK(std::abs(work - expected) < 1e-11 * scale);
      const auto& s = stress_of[std::size_t(l)];
      const shell::ConjugateForces one = shell::conjugate_forces(
          b, shell::WeightedStresses{StressVoigt(s[0], s[1], s[2]), StressVoigt(s[3], s[4], s[5]), Vector2(s[6], s[7])});
      for (const auto& [x, y] : {std::pair{one.a1, f.a1}, std::pair{one.a2, f.a2}, std::pair{one.n, f.n},
                                 std::pair{one.n1, f.n1}, std::pair{one.n2, f.n2}})
        CHECK((x - y).norm() <= 1e-15 * std::max(y.norm(), 1e-300) * 4.0);
    }
  }
}
