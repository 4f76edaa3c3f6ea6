// NSPH with every kernel composes a solver that gets the cantilever strip right
// and runs (tests/support/policy_smoke.hpp), with each material and with both
// the integral and the global thickness model. The policy combinations are
// spread over four test files so that their compilation shares both cores.
#include "support/policy_smoke.hpp"

using namespace sphshell;

using test_support::run_with_every_material_and_model;

TEST_CASE("NSPH with every kernel runs with every material", "[solver][policies]") {
  run_with_every_material_and_model<approx::NSPH<kernel::CubicSpline>>("NSPH<CubicSpline>");
  run_with_every_material_and_model<approx::NSPH<kernel::WendlandC2>>("NSPH<WendlandC2>");
  run_with_every_material_and_model<approx::NSPH<kernel::QuinticSpline>>("NSPH<QuinticSpline>");
}
