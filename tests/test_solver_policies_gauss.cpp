// Every Gauss rule with every material law composes a solver that gets the
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

TEST_CASE("Every Gauss rule runs with every material", "[solver][policies]") {
  every_material<thickness::Gauss<1>>("Gauss<1>");
  every_material<thickness::Gauss<2>>("Gauss<2>");
  every_material<thickness::Gauss<3>>("Gauss<3>");
  every_material<thickness::Gauss<4>>("Gauss<4>");
  every_material<thickness::Gauss<5>>("Gauss<5>");
  every_material<thickness::Gauss<6>>("Gauss<6>");
  every_material<thickness::Gauss<7>>("Gauss<7>");
}
