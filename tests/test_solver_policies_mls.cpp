// MLS with every kernel composes a solver that gets the cantilever strip right
// and runs (tests/support/policy_smoke.hpp), with each material and with both
// the integral and the global thickness model. The policy combinations are
// spread over four test files so that their compilation shares both cores.
#include "support/policy_smoke.hpp"

using namespace sphshell;

namespace {
template <class Approximation>
void every_material_and_model(const std::string& approximation) {
  using test_support::run_policy_smoke_test;
  run_policy_smoke_test<Approximation, thickness::Gauss<5>, material::Elastic>(approximation + " / Gauss<5> / elastic");
  run_policy_smoke_test<Approximation, thickness::Gauss<5>, material::J2Plasticity>(approximation + " / Gauss<5> / J2");
  run_policy_smoke_test<Approximation, thickness::Gauss<5>, material::LemaitreDamage>(approximation + " / Gauss<5> / damage");
  run_policy_smoke_test<Approximation, thickness::Global, material::Elastic>(approximation + " / Global / elastic");
  run_policy_smoke_test<Approximation, thickness::Global, material::J2Plasticity>(approximation + " / Global / J2");
  run_policy_smoke_test<Approximation, thickness::Global, material::LemaitreDamage>(approximation + " / Global / damage");
}
}  // namespace

TEST_CASE("MLS with every kernel runs with every material", "[solver][policies]") {
  every_material_and_model<approx::MLS<kernel::CubicSpline>>("MLS<CubicSpline>");
  every_material_and_model<approx::MLS<kernel::WendlandC2>>("MLS<WendlandC2>");
  every_material_and_model<approx::MLS<kernel::QuinticSpline>>("MLS<QuinticSpline>");
}
