// Every thickness rule with every material law composes a solver that runs.
#include "support/policy_smoke.hpp"

using namespace sphshell;

namespace {
using Approx = approx::MLS<kernel::CubicSpline>;

template <class Rule>
void every_material(const std::string& rule) {
  test_support::run_policy_smoke_test<Approx, Rule, material::Elastic>(rule + " / elastic");
  test_support::run_policy_smoke_test<Approx, Rule, material::J2Plasticity>(rule + " / J2");
  test_support::run_policy_smoke_test<Approx, Rule, material::LemaitreDamage>(rule + " / damage");
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

TEST_CASE("Simpson rules and Global run with every material", "[solver][policies]") {
  every_material<thickness::Simpson<3>>("Simpson<3>");
  every_material<thickness::Simpson<5>>("Simpson<5>");
  every_material<thickness::Simpson<7>>("Simpson<7>");
  every_material<thickness::Global>("Global");
}
