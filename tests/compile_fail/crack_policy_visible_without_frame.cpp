// Must not compile: an enabled crack policy whose visibility test lacks the
// tangent frame the solver passes.
#include <sphshell/sphshell.hpp>

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
