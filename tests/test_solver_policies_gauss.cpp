// Every Gauss rule with every material law composes a solver that gets the
// cantilever strip right and runs (tests/support/policy_smoke.hpp).
#include "support/policy_smoke.hpp"

using namespace sphshell;

using Approximation = approx::MLS<kernel::CubicSpline>;
using test_support::run_with_every_material;

TEST_CASE("Every Gauss rule runs with every material", "[solver][policies]") {
  run_with_every_material<Approximation, thickness::Gauss<1>>("Gauss<1>");
  run_with_every_material<Approximation, thickness::Gauss<2>>("Gauss<2>");
  run_with_every_material<Approximation, thickness::Gauss<3>>("Gauss<3>");
  run_with_every_material<Approximation, thickness::Gauss<4>>("Gauss<4>");
  run_with_every_material<Approximation, thickness::Gauss<5>>("Gauss<5>");
  run_with_every_material<Approximation, thickness::Gauss<6>>("Gauss<6>");
  run_with_every_material<Approximation, thickness::Gauss<7>>("Gauss<7>");
}
