// Must not compile: the law declares rate_dependent but has no update taking
// the step's UpdateContext.
#include <sphshell/material/j2_plasticity.hpp>
#include <sphshell/material/material.hpp>

struct RateFlagWithoutContext : sphshell::material::J2Plasticity {
  using J2Plasticity::J2Plasticity;
  static constexpr bool rate_dependent = true;
};

static_assert(sphshell::material::check_material_law<RateFlagWithoutContext>());

int main() { return 0; }
