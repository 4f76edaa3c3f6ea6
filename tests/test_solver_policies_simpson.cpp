// Every Simpson rule and the global model with every material law composes a solver that gets the
// cantilever strip right and runs (tests/support/policy_smoke.hpp).
#include "support/policy_smoke.hpp"

using namespace sphshell;

namespace {
using Approximation = approx::MLS<kernel::CubicSpline>;

template <class Rule>
void every_material(const std::string& rule) {
  using test_support::run_policy_smoke_test;
  run_policy_smoke_test<Approximation, Rule, material::Elastic>(rule + " / elastic");
  run_policy_smoke_test<Approximation, Rule, material::J2Plasticity>(rule + " / J2");
  run_policy_smoke_test<Approximation, Rule, material::LemaitreDamage>(rule + " / damage");
}
}  // namespace

TEST_CASE("Simpson rules and Global run with every material", "[solver][policies]") {
  every_material<thickness::Simpson<3>>("Simpson<3>");
  every_material<thickness::Simpson<5>>("Simpson<5>");
  every_material<thickness::Simpson<7>>("Simpson<7>");
  every_material<thickness::Global>("Global");
}
