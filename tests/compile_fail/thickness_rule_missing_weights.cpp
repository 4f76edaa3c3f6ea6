// Must not compile: the rule has no reference_weights.
#include <sphshell/thickness/section.hpp>

#include <sphshell/material/elastic.hpp>

#include <array>

struct RuleWithoutWeights {
  static constexpr int num_points = 2;
  static constexpr std::array<double, 2> reference_points{-0.5, 0.5};
  static constexpr const char* name = "RuleWithoutWeights";
};

int main() {
  const sphshell::material::Elastic law({210e9, 0.3});
  const sphshell::thickness::Section<RuleWithoutWeights, sphshell::material::Elastic> section(
      law, 0.01);
  return section.output_points;
}
