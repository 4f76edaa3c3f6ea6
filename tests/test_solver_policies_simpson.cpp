// Every Simpson rule and the global model with every material law composes a solver that gets the
// cantilever strip right and runs (tests/support/policy_smoke.hpp).
#include "support/policy_smoke.hpp"

using namespace sphshell;

using Approximation = approx::MLS<kernel::CubicSpline>;
using test_support::run_with_every_material;

TEST_CASE("Simpson rules and Global run with every material", "[solver][policies]") {
  run_with_every_material<Approximation, thickness::Simpson<3>>("Simpson<3>");
  run_with_every_material<Approximation, thickness::Simpson<5>>("Simpson<5>");
  run_with_every_material<Approximation, thickness::Simpson<7>>("Simpson<7>");
  run_with_every_material<Approximation, thickness::Global>("Global");
}
