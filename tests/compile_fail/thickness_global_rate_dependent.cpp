// Must not compile: the resultant model (Global) has no integral points to
// carry a rate-dependent law's state.
#include <sphshell/material/johnson_cook.hpp>
#include <sphshell/thickness/global.hpp>

int main() {
  sphshell::material::JohnsonCook::Parameters parameters{};
  parameters.E = 210e9;
  parameters.nu = 0.3;
  parameters.A = 235e6;
  parameters.n = 1.0;
  parameters.reference_strain_rate = 1.0;
  parameters.m = 1.0;
  parameters.reference_temperature = 293.0;
  parameters.melting_temperature = 1793.0;
  parameters.initial_temperature = 293.0;
  parameters.D1 = 1.0;
  const sphshell::material::JohnsonCook law(parameters);
  const sphshell::thickness::Section<sphshell::thickness::Global, sphshell::material::JohnsonCook> section(law, 0.01);
  return section.output_points;
}
