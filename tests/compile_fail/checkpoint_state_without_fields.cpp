// Must not compile: checkpointing a solver whose material law's State does not
// list its fields (material/material.hpp, "Checkpoints").
#include <sphshell/approx/mls.hpp>
#include <sphshell/kernel/cubic_spline.hpp>
#include <sphshell/material/elastic.hpp>
#include <sphshell/solver.hpp>
#include <sphshell/thickness/gauss.hpp>

// Elastic, but with a State of its own that has no for_each_field.
struct SilentElastic : sphshell::material::Elastic {
  using Elastic::Elastic;
  struct State {
    sphshell::StressVoigt stress;
  };
  State initial_state() const { return {sphshell::StressVoigt::Zero()}; }
  UpdateResult update(State&, const sphshell::StrainVoigt&) const { return {false, 0}; }
  double equivalent_stress(const State&) const { return 0.0; }
  double equivalent_plastic_strain(const State&) const { return 0.0; }
  double damage(const State&) const { return 0.0; }
  bool failed(const State&) const { return false; }
  double elastic_energy_density(const State&) const { return 0.0; }
};

int main() {
  using namespace sphshell;
  Solver<approx::MLS<kernel::CubicSpline>, thickness::Gauss<3>, SilentElastic> solver(
      ShellModel::rectangular_plate(0.1, 0.1, 5, 5, 0.01), {210e9, 0.3});
  solver.save_checkpoint("never_written.ckpt");
}
