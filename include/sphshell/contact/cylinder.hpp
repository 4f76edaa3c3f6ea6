#pragma once
// A rigid cylinder about the body's centre: its axis (a unit vector in the
// body frame), radius R and length L of the cylindrical part, which runs from
// −L/2 to +L/2 along the axis. Its ends are flat discs, or hemispheres of
// radius R centred at ±L/2 on the axis (a capsule, L + 2R long overall).

#include <sphshell/contact/contact.hpp>
#include <sphshell/core/error.hpp>
#include <sphshell/core/frame.hpp>

#include <algorithm>
#include <cmath>

namespace sphshell::contact {

enum class CylinderEnds { flat, hemispherical };

struct CylinderParameters {
  Vector3 axis = Vector3::UnitZ();
  double radius = 0.0;  // m
  double length = 0.0;  // of the cylindrical part (m)
  CylinderEnds ends = CylinderEnds::flat;
};

class Cylinder {
 public:
  static constexpr bool bounded = true;

  explicit Cylinder(const CylinderParameters& parameters)
      : radius_(parameters.radius), half_length_(0.5 * parameters.length), ends_(parameters.ends) {
    sphshell::detail::require_positive("cylinder radius", parameters.radius);
    // A capsule may have no cylindrical part (a sphere); a flat-ended cylinder may not.
    if (ends_ == CylinderEnds::flat)
      sphshell::detail::require_positive("cylinder length", parameters.length);
    else
      sphshell::detail::require_nonnegative("cylinder length", parameters.length);
    const double axis_length = parameters.axis.norm();
    if (!(axis_length > 0.0) || !std::isfinite(axis_length))
      sphshell::detail::invalid_parameter("cylinder axis length", axis_length, "must be finite and > 0");
    axis_ = parameters.axis / axis_length;
    // The radial direction taken on the axis itself, where every one is nearest.
    fallback_radial_ = tangent_frame(axis_).e1;
  }

  SurfaceProximity proximity(const Vector3& point) const {
    const double along = axis_.dot(point);
    const Vector3 radial_vector = point - along * axis_;
    const double radial = radial_vector.norm();
    const Vector3 radial_direction = radial > 0.0 ? Vector3(radial_vector / radial) : fallback_radial_;
    if (ends_ == CylinderEnds::hemispherical) {
      // Distance to the axis segment minus R.
      const Vector3 on_axis = std::clamp(along, -half_length_, half_length_) * axis_;
      const Vector3 offset = point - on_axis;
      const double distance = offset.norm();
      const Vector3 normal = distance > 0.0 ? Vector3(offset / distance) : radial_direction;
      return {distance - radius_, normal, on_axis + radius_ * normal};
    }
    // Flat ends: the distance in the (radial, axial) half-plane to the rectangle
    // [0, R] × [−L/2, L/2].
    const double side = radial - radius_;                   // > 0 outside the mantle
    const double cap = std::abs(along) - half_length_;     // > 0 beyond an end
    const Vector3 cap_normal = along >= 0.0 ? Vector3(axis_) : Vector3(-axis_);
    if (side > 0.0 && cap > 0.0) {  // nearest the rim
      const double distance = std::hypot(side, cap);
      const Vector3 rim = radius_ * radial_direction + half_length_ * cap_normal;
      return {distance, (point - rim) / distance, rim};
    }
    const bool side_nearer = (side > 0.0) || (cap <= 0.0 && side >= cap);
    if (side_nearer)
      return {side, radial_direction, along * axis_ + radius_ * radial_direction};
    return {cap, cap_normal, radial * radial_direction + half_length_ * cap_normal};
  }

  const Vector3& axis() const { return axis_; }
  double radius() const { return radius_; }
  double length() const { return 2.0 * half_length_; }
  CylinderEnds ends() const { return ends_; }

 private:
  Vector3 axis_;
  Vector3 fallback_radial_;
  double radius_;
  double half_length_;
  CylinderEnds ends_;
};

}  // namespace sphshell::contact
