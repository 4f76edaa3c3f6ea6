// Must not compile: an enabled crack policy whose visibility test lacks the
// tangent frame the solver passes.
#include <sphshell/approx/mls.hpp>
#include <sphshell/crack/line_segments.hpp>
#include <sphshell/kernel/cubic_spline.hpp>
#include <sphshell/material/elastic.hpp>
#include <sphshell/solver.hpp>
#include <sphshell/thickness/gauss.hpp>

struct CrackWithoutFrame : sphshell::crack::LineSegments {
  static constexpr const char* name = "crack without frame";
  bool visible(const sphshell::Vector3& a, const sphshell::Vector3& b) const {
    return a != b;
  }
};

using BrokenSolver = sphshell::Solver<sphshell::approx::MLS<sphshell::kernel::CubicSpline>,
                                      sphshell::thickness::Gauss<5>, sphshell::material::Elastic,
                                      CrackWithoutFrame>;

int main() { return static_cast<int>(sizeof(BrokenSolver)); }
