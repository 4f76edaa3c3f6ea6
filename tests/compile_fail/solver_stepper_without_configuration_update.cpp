// Must not compile: a stepper without advance_configuration as the fifth parameter.
#include <sphshell/approx/mls.hpp>
#include <sphshell/kernel/cubic_spline.hpp>
#include <sphshell/material/elastic.hpp>
#include <sphshell/solver.hpp>
#include <sphshell/thickness/gauss.hpp>

struct HalfAStepper {
  double velocity_step(long, double time_step) const { return time_step; }
  void advance_velocities(const sphshell::stepper::StepContext&, sphshell::solver::ParticleState&,
                          const sphshell::solver::Inertia&, const sphshell::solver::ParticleForces&, std::size_t,
                          std::size_t) {}
};

int main() {
  using namespace sphshell;
  Solver<approx::MLS<kernel::CubicSpline>, thickness::Gauss<3>, material::Elastic, crack::None, HalfAStepper> solver(
      ShellModel::rectangular_plate(0.1, 0.1, 5, 5, 0.01), {210e9, 0.3});
  solver.step();
}
