#pragma once
// A rigid sphere of the given radius about the body's centre.

#include <sphshell/contact/contact.hpp>
#include <sphshell/core/error.hpp>

namespace sphshell::contact {

class Sphere {
 public:
  static constexpr bool bounded = true;

  explicit Sphere(double radius) : radius_(radius) { sphshell::detail::require_positive("sphere radius", radius); }

  SurfaceProximity proximity(const Vector3& point) const {
    const double distance = point.norm();
    // At the centre every direction is nearest; +z is chosen.
    const Vector3 normal = distance > 0.0 ? Vector3(point / distance) : Vector3::UnitZ();
    return {distance - radius_, normal, radius_ * normal};
  }

  double radius() const { return radius_; }

 private:
  double radius_;
};

}  // namespace sphshell::contact
