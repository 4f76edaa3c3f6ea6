#pragma once
// A rigid plane (a wall): in its body frame it passes through the origin with
// the given outward normal; the body's position is a point of the wall.

#include <sphshell/contact/contact.hpp>
#include <sphshell/core/error.hpp>

#include <cmath>

namespace sphshell::contact {

class Plane {
 public:
  static constexpr bool bounded = false;

  explicit Plane(const Vector3& outward_normal) {
    const double length = outward_normal.norm();
    if (!(length > 0.0) || !std::isfinite(length))
      sphshell::detail::invalid_parameter("plane normal length", length, "must be finite and > 0");
    normal_ = outward_normal / length;
  }

  SurfaceProximity proximity(const Vector3& point) const {
    const double gap = normal_.dot(point);
    return {gap, normal_, point - gap * normal_};
  }

  const Vector3& normal() const { return normal_; }

 private:
  Vector3 normal_;
};

}  // namespace sphshell::contact
