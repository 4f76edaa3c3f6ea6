#pragma once
// The O-grid cap of the validation tests is the library's builder
// (include/sphshell/shell/spherical_cap_ogrid.hpp); these names keep the tests'
// spelling.

#include <sphshell/shell/spherical_cap_ogrid.hpp>

namespace sphshell::test_support {

using OGridOptions = sphshell::OGridOptions;
using OGridQuality = sphshell::OGridQuality;

inline ShellModel ogrid_spherical_cap(double radius, double half_angle, int m, double thickness,
                                      const OGridOptions& options = {}) {
  return spherical_cap_ogrid(radius, half_angle, m, thickness, options);
}
inline OGridQuality ogrid_quality(double radius, double half_angle, int m, const OGridOptions& options = {}) {
  return spherical_cap_ogrid_quality(radius, half_angle, m, options);
}

}  // namespace sphshell::test_support
