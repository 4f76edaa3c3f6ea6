#pragma once
// Local orthonormal frames on a surface.

#include <sphshell/core/error.hpp>
#include <sphshell/core/types.hpp>

#include <cmath>

namespace sphshell {

// Right-handed orthonormal frame (e1, e2, n) of a tangent plane.
struct TangentFrame {
  Vector3 e1;
  Vector3 e2;
  Vector3 normal;
};

// A deterministic tangent frame for a unit normal: e1 is the projection of the
// global axis least aligned with the normal (x unless the normal is close to x),
// so a plate in the xy-plane gets e1 = x, e2 = y, n = z.
inline TangentFrame tangent_frame(const Vector3& normal) {
  const double length = normal.norm();
  if (!(length > 0.0) || !std::isfinite(length))
    detail::invalid_parameter("normal", length, "a surface normal must have finite, non-zero length");
  const Vector3 n = normal / length;
  const Vector3 reference = std::abs(n.x()) < 0.9 ? Vector3::UnitX() : Vector3::UnitY();
  const Vector3 e1 = (reference - reference.dot(n) * n).normalized();
  return {e1, n.cross(e1), n};
}

}  // namespace sphshell
