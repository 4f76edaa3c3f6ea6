// Must not compile: a pre-crack on a solver whose crack policy is crack::None.
#include <sphshell/approx/mls.hpp>
#include <sphshell/kernel/cubic_spline.hpp>
#include <sphshell/material/elastic.hpp>
#include <sphshell/solver.hpp>
#include <sphshell/thickness/gauss.hpp>

int main() {
  using namespace sphshell;
  Solver<approx::MLS<kernel::CubicSpline>, thickness::Gauss<3>, material::Elastic, crack::None> solver(
      ShellModel::rectangular_plate(0.1, 0.1, 5, 5, 0.01), {210e9, 0.3});
  solver.add_precrack({Vector3(0.05, 0.0, 0.0), Vector3(0.05, 0.1, 0.0)});
}
