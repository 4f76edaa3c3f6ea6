// Every approximation with every kernel composes a solver that runs, with each
// material and with both the integral and the global thickness model.
#include "support/policy_smoke.hpp"

using namespace sphshell;

namespace {
template <class Approx>
void every_material_and_model(const std::string& approx) {
  test_support::run_policy_smoke_test<Approx, thickness::Gauss<5>, material::Elastic>(approx + " / Gauss<5> / elastic");
  test_support::run_policy_smoke_test<Approx, thickness::Gauss<5>, material::J2Plasticity>(approx + " / Gauss<5> / J2");
  test_support::run_policy_smoke_test<Approx, thickness::Gauss<5>, material::LemaitreDamage>(approx + " / Gauss<5> / damage");
  test_support::run_policy_smoke_test<Approx, thickness::Global, material::Elastic>(approx + " / Global / elastic");
  test_support::run_policy_smoke_test<Approx, thickness::Global, material::J2Plasticity>(approx + " / Global / J2");
  test_support::run_policy_smoke_test<Approx, thickness::Global, material::LemaitreDamage>(approx + " / Global / damage");
}
}  // namespace

TEST_CASE("MLS with every kernel runs with every material", "[solver][policies]") {
  every_material_and_model<approx::MLS<kernel::CubicSpline>>("MLS<CubicSpline>");
  every_material_and_model<approx::MLS<kernel::WendlandC2>>("MLS<WendlandC2>");
  every_material_and_model<approx::MLS<kernel::QuinticSpline>>("MLS<QuinticSpline>");
}

TEST_CASE("NSPH with every kernel runs with every material", "[solver][policies]") {
  every_material_and_model<approx::NSPH<kernel::CubicSpline>>("NSPH<CubicSpline>");
  every_material_and_model<approx::NSPH<kernel::WendlandC2>>("NSPH<WendlandC2>");
  every_material_and_model<approx::NSPH<kernel::QuinticSpline>>("NSPH<QuinticSpline>");
}
