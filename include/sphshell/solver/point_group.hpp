#pragma once
// The two kinds of integration point (docs/method.md, "Particles, stress
// points and integral points"): solver/integration_points.hpp numbers them
// across both groups, the stress points first.

#include <array>
#include <cstddef>

namespace sphshell::solver {

enum class PointGroup { stress_points, particles };
inline constexpr std::array<PointGroup, 2> point_groups{PointGroup::stress_points, PointGroup::particles};
inline constexpr std::size_t index_of(PointGroup group) { return group == PointGroup::stress_points ? 0 : 1; }
inline const char* name_of(PointGroup group) {
  return group == PointGroup::stress_points ? "stress point" : "particle";
}

}  // namespace sphshell::solver
