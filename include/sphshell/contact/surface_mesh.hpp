#pragma once
// Triangulations of the rigid shapes' surfaces, for drawing a body beside the
// shell (io/rigid_body_surfaces.hpp writes them into the frames). Contact
// never uses them: it asks the exact shape (proximity()).
//
// Each function returns the surface in the body frame, triangles listed
// counter-clockwise seen from outside (right-hand normals outward), as
// TriangleSurface wants them:
//   Sphere, Cylinder     a surface of revolution: a profile from pole to pole
//                        (radius, axial position) turned about the axis in
//                        `segments` steps; closed;
//   TriangleSurface      its own triangles;
//   Plane                a square patch (two triangles) of the given half side
//                        about a given point, since a plane has no extent of
//                        its own; place_surface_mesh() sizes it to the model.
// place_surface_mesh() puts a body's triangulation where the body is now.

#include <sphshell/contact/contact.hpp>
#include <sphshell/contact/cylinder.hpp>
#include <sphshell/contact/plane.hpp>
#include <sphshell/contact/rigid_body.hpp>
#include <sphshell/contact/sphere.hpp>
#include <sphshell/contact/triangle_surface.hpp>
#include <sphshell/core/error.hpp>
#include <sphshell/core/frame.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <type_traits>
#include <utility>
#include <vector>

namespace sphshell::contact {

struct SurfaceMesh {
  std::vector<Vector3> vertices;
  std::vector<std::array<int, 3>> triangles;
};

// How finely a curved surface is drawn: `segments` steps round the axis (and
// segments/2 from pole to pole of a sphere or hemisphere).
struct SurfaceMeshResolution {
  static constexpr int minimum_segments = 3;
  int segments = 32;
};

// An axis-aligned box holding the model (world frame), to size a plane's patch.
struct ModelExtent {
  Vector3 lower = Vector3::Zero();
  Vector3 upper = Vector3::Zero();
};

// How far a plane's drawn patch reaches beyond the model, as a fraction of the
// model's extent: the wall is seen round the shell.
inline constexpr double plane_patch_margin = 0.25;

namespace detail {

inline void check_segments(const SurfaceMeshResolution& resolution) {
  if (resolution.segments < SurfaceMeshResolution::minimum_segments)
    sphshell::detail::invalid_parameter("surface mesh segments", resolution.segments, "must be at least 3");
}

// A surface of revolution about `axis` through the origin: profile points
// (radius, axial position) from the lower pole (radius 0) to the upper pole
// (radius 0), every point between them off the axis. The rings turn
// counter-clockwise about the axis, so the triangles (ring k, j), (k, j+1),
// (k+1, j+1) and (k, j), (k+1, j+1), (k+1, j) face outward (the ring's
// tangent × the axis is the outward radial direction).
inline SurfaceMesh revolved(const Vector3& axis, const std::vector<std::pair<double, double>>& profile,
                            int segments) {
  const TangentFrame frame = tangent_frame(axis);
  const double pi = std::acos(-1.0);
  SurfaceMesh mesh;
  const int rings = static_cast<int>(profile.size()) - 2;
  mesh.vertices.push_back(profile.front().second * frame.normal);
  for (int k = 1; k <= rings; ++k)
    for (int j = 0; j < segments; ++j) {
      const double angle = 2.0 * pi * j / segments;
      const auto [radius, along] = profile[k];
      mesh.vertices.push_back(along * frame.normal +
                              radius * (std::cos(angle) * frame.e1 + std::sin(angle) * frame.e2));
    }
  mesh.vertices.push_back(profile.back().second * frame.normal);
  const int lower_pole = 0;
  const int upper_pole = static_cast<int>(mesh.vertices.size()) - 1;
  auto ring = [segments](int k, int j) { return 1 + (k - 1) * segments + (j % segments); };
  for (int j = 0; j < segments; ++j) mesh.triangles.push_back({lower_pole, ring(1, j + 1), ring(1, j)});
  for (int k = 1; k < rings; ++k)
    for (int j = 0; j < segments; ++j) {
      mesh.triangles.push_back({ring(k, j), ring(k, j + 1), ring(k + 1, j + 1)});
      mesh.triangles.push_back({ring(k, j), ring(k + 1, j + 1), ring(k + 1, j)});
    }
  for (int j = 0; j < segments; ++j) mesh.triangles.push_back({ring(rings, j), ring(rings, j + 1), upper_pole});
  return mesh;
}

// A hemisphere's profile points between its pole and its equator (both
// excluded), `steps` arcs of equal angle: the lower one from the pole up.
inline void append_hemisphere(std::vector<std::pair<double, double>>& profile, double radius, double centre,
                              int steps, bool lower) {
  const double pi = std::acos(-1.0);
  for (int k = 1; k < steps; ++k) {
    const double polar = 0.5 * pi * (lower ? k : steps - k) / steps;
    profile.emplace_back(radius * std::sin(polar), centre + (lower ? -1.0 : 1.0) * radius * std::cos(polar));
  }
}

}  // namespace detail

inline SurfaceMesh surface_mesh(const Sphere& sphere, const SurfaceMeshResolution& resolution = {}) {
  detail::check_segments(resolution);
  const int steps = std::max(2, resolution.segments / 4);  // per hemisphere
  std::vector<std::pair<double, double>> profile{{0.0, -sphere.radius()}};
  detail::append_hemisphere(profile, sphere.radius(), 0.0, steps, true);
  profile.emplace_back(sphere.radius(), 0.0);
  detail::append_hemisphere(profile, sphere.radius(), 0.0, steps, false);
  profile.emplace_back(0.0, sphere.radius());
  return detail::revolved(Vector3::UnitZ(), profile, resolution.segments);
}

inline SurfaceMesh surface_mesh(const Cylinder& cylinder, const SurfaceMeshResolution& resolution = {}) {
  detail::check_segments(resolution);
  const double radius = cylinder.radius();
  const double half_length = 0.5 * cylinder.length();
  std::vector<std::pair<double, double>> profile;
  if (cylinder.ends() == CylinderEnds::flat) {
    profile = {{0.0, -half_length}, {radius, -half_length}, {radius, half_length}, {0.0, half_length}};
  } else {
    const int steps = std::max(2, resolution.segments / 4);
    profile.emplace_back(0.0, -half_length - radius);
    detail::append_hemisphere(profile, radius, -half_length, steps, true);
    profile.emplace_back(radius, -half_length);
    if (half_length > 0.0) profile.emplace_back(radius, half_length);
    detail::append_hemisphere(profile, radius, half_length, steps, false);
    profile.emplace_back(0.0, half_length + radius);
  }
  return detail::revolved(cylinder.axis(), profile, resolution.segments);
}

inline SurfaceMesh surface_mesh(const TriangleSurface& surface, const SurfaceMeshResolution& = {}) {
  return {surface.vertices(), surface.triangles()};
}

// A square of half side `half_side` in the plane, centred on the foot of
// `near` (body frame) on it.
inline SurfaceMesh surface_mesh(const Plane& plane, const Vector3& near, double half_side) {
  sphshell::detail::require_positive("plane patch half side", half_side);
  const TangentFrame frame = tangent_frame(plane.normal());
  const Vector3 centre = near - plane.normal().dot(near) * plane.normal();
  SurfaceMesh mesh;
  for (const auto& [a, b] : {std::pair{-1.0, -1.0}, {1.0, -1.0}, {1.0, 1.0}, {-1.0, 1.0}})
    mesh.vertices.push_back(centre + half_side * (a * frame.e1 + b * frame.e2));
  mesh.triangles = {{0, 1, 2}, {0, 2, 3}};  // counter-clockwise about the normal (e1 × e2 = n)
  return mesh;
}

// A body's triangulation where it is now (world frame). A plane's patch is
// centred on the foot of the model's centre and reaches past the model's
// extent by plane_patch_margin on each side.
template <class Shape, class Motion>
SurfaceMesh place_surface_mesh(const RigidBody<Shape, Motion>& body, const ModelExtent& model,
                               const SurfaceMeshResolution& resolution = {}) {
  SurfaceMesh mesh;
  if constexpr (std::is_same_v<Shape, Plane>) {
    const Vector3 centre = 0.5 * (model.lower + model.upper);
    const double diagonal = (model.upper - model.lower).norm();
    // A model of no extent (one particle) still gets a patch of unit size.
    const double half_side = diagonal > 0.0 ? (0.5 + plane_patch_margin) * diagonal : 1.0;
    mesh = surface_mesh(body.shape(), body.orientation().conjugate() * (centre - body.position()), half_side);
  } else {
    mesh = surface_mesh(body.shape(), resolution);
  }
  for (Vector3& vertex : mesh.vertices) vertex = body.position() + body.orientation() * vertex;
  return mesh;
}

}  // namespace sphshell::contact
