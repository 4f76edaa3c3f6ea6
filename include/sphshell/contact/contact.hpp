#pragma once
// The contact family: rigid bodies and the penalty contact of shell particles
// against them; body_set.hpp is how the Solver steps them (add_rigid_body).
//
// A rigid shape describes a surface in its body frame (the body's centre at
// the origin) and provides
//   SurfaceProximity proximity(const Vector3& point) const;
//       the signed distance (gap, > 0 outside, < 0 inside) from a body-frame
//       point to the surface, the outward unit normal at the nearest surface
//       point (the direction in which the gap grows) and that nearest point;
//   static constexpr bool bounded;
//       whether the shape is a finite solid (a plane is not: it has no finite
//       rotational inertia, so a free plane only translates).
// rigid_body.hpp places a shape in the world (position, orientation) and moves
// it; penalty.hpp pushes shell particles out of it. shell_contact.hpp is the
// shell's penalty contact with itself (no rigid shape: the other side is the
// shell), stepped with the bodies.

#include <sphshell/core/types.hpp>

#include <type_traits>
#include <utility>

namespace sphshell::contact {

// Where a point is with respect to a surface.
struct SurfaceProximity {
  double gap = 0.0;  // signed distance: > 0 outside, < 0 inside (m)
  Vector3 normal = Vector3::UnitZ();  // outward unit normal at the nearest point
  Vector3 nearest = Vector3::Zero();  // nearest surface point
};

namespace detail {

template <class Shape, class = void>
struct has_proximity : std::false_type {};
template <class Shape>
struct has_proximity<Shape, std::void_t<decltype(std::declval<const Shape&>().proximity(std::declval<const Vector3&>()))>>
    : std::is_convertible<decltype(std::declval<const Shape&>().proximity(std::declval<const Vector3&>())),
                          SurfaceProximity> {};

template <class Shape, class = void>
struct has_bounded_flag : std::false_type {};
template <class Shape>
struct has_bounded_flag<Shape, std::void_t<decltype(bool{Shape::bounded})>> : std::true_type {};

}  // namespace detail

template <class Shape>
struct is_rigid_shape
    : std::bool_constant<detail::has_proximity<Shape>::value && detail::has_bounded_flag<Shape>::value> {};
template <class Shape>
inline constexpr bool is_rigid_shape_v = is_rigid_shape<Shape>::value;

template <class Shape>
constexpr bool check_rigid_shape() {
  static_assert(detail::has_proximity<Shape>::value,
                "rigid shape: add `SurfaceProximity proximity(const Vector3& body_frame_point) const` (signed gap, "
                "outward normal, nearest point)");
  static_assert(detail::has_bounded_flag<Shape>::value,
                "rigid shape: add `static constexpr bool bounded` (false for an unbounded surface such as a plane, "
                "which then cannot rotate freely)");
  return is_rigid_shape_v<Shape>;
}

}  // namespace sphshell::contact
