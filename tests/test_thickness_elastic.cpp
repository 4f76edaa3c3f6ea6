// Elastic sections: membrane N = dΓe and bending M = d³/12 Γκ for every rule that can
// represent a linear stress profile, and input validation.

#include <sphshell/thickness/all.hpp>

#include <sphshell/material/all.hpp>

#include <catch2/catch.hpp>

#include <cmath>
#include <limits>
#include <string>

// After the merge: namespace law = sphshell::material;
namespace law = sphshell::material;

using namespace sphshell::thickness;
using sphshell::StrainVoigt;

namespace {

const law::Elastic steel{{210e9, 0.3}};
constexpr double thickness = 0.01;

void check_close(const Eigen::Vector3d& actual, const Eigen::Vector3d& expected) {
  const double scale = expected.norm();
  INFO("actual   " << actual.transpose() << "\nexpected " << expected.transpose());
  CHECK((actual - expected).norm() <= 1e-13 * scale);
}

}  // namespace

TEMPLATE_TEST_CASE("thickness elastic section: M = d^3/12 Gamma kappa and N = d Gamma e",
                   "[thickness]", Gauss<2>, Gauss<3>, Gauss<4>, Gauss<5>, Gauss<6>, Gauss<7>,
                   Simpson<3>, Simpson<5>, Simpson<7>, Global) {
  const Section<TestType, law::Elastic> section(steel, thickness);
  const Eigen::Matrix3d gamma = steel.elasticity_matrix();
  const double E = 210e9, nu = 0.3;
  const double d = thickness;

  SECTION("pure curvature") {
    auto state = section.initial_state();
    const StrainVoigt curvature(0.3, -0.1, 0.05);
    Resultants result;
    for (int step = 0; step < 4; ++step)  // incremental: the sum of the steps counts
      result = section.update(state, StrainVoigt::Zero(), curvature / 4.0);
    check_close(result.moment, d * d * d / 12.0 * gamma * curvature);
    CHECK(result.membrane.norm() <= 1e-12 * E * d * d * curvature.norm());
    // The scalar form E d³/(12(1 − ν²)) κ for uniaxial curvature.
    auto uniaxial = section.initial_state();
    const Resultants uniaxial_result =
        section.update(uniaxial, StrainVoigt::Zero(), StrainVoigt(0.2, 0.0, 0.0));
    CHECK(uniaxial_result.moment.x() ==
          Approx(E * d * d * d / (12.0 * (1.0 - nu * nu)) * 0.2).epsilon(1e-13));
    CHECK(uniaxial_result.moment.y() ==
          Approx(nu * E * d * d * d / (12.0 * (1.0 - nu * nu)) * 0.2).epsilon(1e-13));
    // Bending energy ½ κᵀ (d³/12 Γ) κ per unit area.
    CHECK(section.elastic_energy(state) ==
          Approx(0.5 * curvature.dot(d * d * d / 12.0 * gamma * curvature)).epsilon(1e-12));
    check_close(section.resultants(state).moment, result.moment);
  }

  SECTION("pure membrane strain") {
    auto state = section.initial_state();
    const StrainVoigt strain(1e-4, 3e-4, -2e-4);
    const Resultants result = section.update(state, strain, StrainVoigt::Zero());
    check_close(result.membrane, d * gamma * strain);
    CHECK(result.moment.norm() <= 1e-12 * E * d * d * strain.norm());
    CHECK(section.elastic_energy(state) ==
          Approx(0.5 * strain.dot(d * gamma * strain)).epsilon(1e-12));
  }

  SECTION("membrane and curvature superpose") {
    auto state = section.initial_state();
    const StrainVoigt strain(1e-4, 0.0, 2e-4);
    const StrainVoigt curvature(0.0, 0.4, 0.1);
    const Resultants result = section.update(state, strain, curvature);
    check_close(result.membrane, d * gamma * strain);
    check_close(result.moment, d * d * d / 12.0 * gamma * curvature);
  }

  SECTION("the output points report the stress and no plasticity or damage") {
    auto state = section.initial_state();
    section.update(state, StrainVoigt(1e-4, 0.0, 0.0), StrainVoigt::Zero());
    for (int k = 0; k < section.output_points; ++k) {
      CHECK(section.equivalent_stress(state, k) == Approx(E / (1.0 - nu * nu) *
                                                          std::sqrt(1.0 - nu + nu * nu) * 1e-4)
                                                       .epsilon(1e-12));
      CHECK(section.equivalent_plastic_strain(state, k) == 0.0);
      CHECK(section.damage(state, k) == 0.0);
    }
    CHECK_FALSE(section.all_failed(state));
    double weight_sum = 0.0;
    for (int k = 0; k < section.output_points; ++k) weight_sum += section.weight(k);
    CHECK(weight_sum == Approx(d).epsilon(1e-14));
  }
}

TEST_CASE("thickness elastic Gauss<1> has no bending stiffness", "[thickness]") {
  // One point on the mid-surface cannot see a linear profile: documented, not a bug.
  const Section<Gauss<1>, law::Elastic> section(steel, thickness);
  auto state = section.initial_state();
  const Resultants result = section.update(state, StrainVoigt::Zero(), StrainVoigt(1.0, 0, 0));
  CHECK(result.moment.norm() == 0.0);
}

TEMPLATE_TEST_CASE("thickness section rejects thickness <= 0 or non-finite", "[thickness]",
                   Gauss<3>, Simpson<5>, Global) {
  for (double bad : {0.0, -0.01, std::numeric_limits<double>::quiet_NaN(),
                     std::numeric_limits<double>::infinity()}) {
    INFO("thickness " << bad);
    CHECK_THROWS_AS((Section<TestType, law::Elastic>(steel, bad)), sphshell::Error);
    CHECK_THROWS_WITH((Section<TestType, law::Elastic>(steel, bad)),
                      Catch::Contains("thickness"));
  }
  const Section<TestType, law::Elastic> section(steel, thickness);
  CHECK_THROWS_AS(section.zeta(-1), sphshell::Error);
  CHECK_THROWS_AS(section.weight(section.output_points), sphshell::Error);
}
