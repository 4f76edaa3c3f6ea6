#pragma once
// A rigid body bounded by a closed triangle surface, given in the body frame:
// vertices and triangles (vertex indices, counter-clockwise seen from outside,
// so that the right-hand normals point outward).
//
// The signed distance of a point is that of the nearest triangle: the nearest
// point on each triangle is found, the closest one kept, and the sign taken
// from the angle-weighted pseudonormal of the feature (face, edge or vertex)
// it lies on, which decides inside from outside correctly on a closed
// surface (Bærentzen & Aanæs, IEEE TVCG 11(3), 2005). The search is brute
// force: one query costs O(number of triangles) (a 1280-triangle sphere:
// 1280 point-triangle tests).
//
// Checked at construction: indices in range, no degenerate triangle (area
// below 1e-12 of the squared bounding-box diagonal), every edge shared by
// exactly two triangles that run it in opposite directions (closed and
// consistently oriented), and a positive enclosed volume (outward normals).

#include <sphshell/contact/contact.hpp>
#include <sphshell/core/error.hpp>

#include <array>
#include <cmath>
#include <cstddef>
#include <limits>
#include <map>
#include <string>
#include <utility>
#include <vector>

namespace sphshell::contact {

struct TriangleSurfaceParameters {
  std::vector<Vector3> vertices;
  std::vector<std::array<int, 3>> triangles;
};

class TriangleSurface {
 public:
  static constexpr bool bounded = true;
  // A triangle whose area is below this fraction of the squared bounding-box
  // diagonal is degenerate.
  static constexpr double degenerate_area_fraction = 1e-12;
  // A point closer than this fraction of the bounding-box diagonal lies on the
  // surface: its normal is the pseudonormal.
  static constexpr double on_surface_fraction = 1e-12;

  explicit TriangleSurface(TriangleSurfaceParameters parameters)
      : vertices_(std::move(parameters.vertices)), triangles_(std::move(parameters.triangles)) {
    validate_and_prepare();
  }

  SurfaceProximity proximity(const Vector3& point) const {
    double best_squared = std::numeric_limits<double>::infinity();
    Vector3 best_point = Vector3::Zero();
    Vector3 best_pseudonormal = Vector3::UnitZ();
    for (std::size_t t = 0; t < triangles_.size(); ++t) {
      const NearestOnTriangle nearest = nearest_on_triangle(t, point);
      const double squared = (point - nearest.point).squaredNorm();
      if (squared < best_squared) {
        best_squared = squared;
        best_point = nearest.point;
        best_pseudonormal = pseudonormal(t, nearest.feature);
      }
    }
    const Vector3 offset = point - best_point;
    const double distance = std::sqrt(best_squared);
    const double sign = offset.dot(best_pseudonormal) >= 0.0 ? 1.0 : -1.0;
    // On the surface the offset has no direction: the pseudonormal stands in.
    const Vector3 normal = distance > surface_tolerance_ ? Vector3(sign * offset / distance) : best_pseudonormal;
    return {sign * distance, normal, best_point};
  }

  const std::vector<Vector3>& vertices() const { return vertices_; }
  const std::vector<std::array<int, 3>>& triangles() const { return triangles_; }
  double volume() const { return volume_; }

 private:
  // Which part of a triangle holds the nearest point: its face, edge k (from
  // corner k to corner k+1) or corner k.
  enum class Feature { face, edge0, edge1, edge2, vertex0, vertex1, vertex2 };
  struct NearestOnTriangle {
    Vector3 point;
    Feature feature;
  };

  // The nearest point of triangle t to p, by the Voronoi regions of its
  // corners, edges and face (Ericson, Real-Time Collision Detection, 2005, §5.1.5).
  NearestOnTriangle nearest_on_triangle(std::size_t t, const Vector3& p) const {
    const Vector3& a = vertices_[triangles_[t][0]];
    const Vector3& b = vertices_[triangles_[t][1]];
    const Vector3& c = vertices_[triangles_[t][2]];
    const Vector3 ab = b - a;
    const Vector3 ac = c - a;
    const Vector3 ap = p - a;
    const double d1 = ab.dot(ap);
    const double d2 = ac.dot(ap);
    if (d1 <= 0.0 && d2 <= 0.0) return {a, Feature::vertex0};
    const Vector3 bp = p - b;
    const double d3 = ab.dot(bp);
    const double d4 = ac.dot(bp);
    if (d3 >= 0.0 && d4 <= d3) return {b, Feature::vertex1};
    const double region_c = d1 * d4 - d3 * d2;
    if (region_c <= 0.0 && d1 >= 0.0 && d3 <= 0.0) return {a + d1 / (d1 - d3) * ab, Feature::edge0};
    const Vector3 cp = p - c;
    const double d5 = ab.dot(cp);
    const double d6 = ac.dot(cp);
    if (d6 >= 0.0 && d5 <= d6) return {c, Feature::vertex2};
    const double region_b = d5 * d2 - d1 * d6;
    if (region_b <= 0.0 && d2 >= 0.0 && d6 <= 0.0) return {a + d2 / (d2 - d6) * ac, Feature::edge2};
    const double region_a = d3 * d6 - d5 * d4;
    if (region_a <= 0.0 && d4 - d3 >= 0.0 && d5 - d6 >= 0.0)
      return {b + (d4 - d3) / ((d4 - d3) + (d5 - d6)) * (c - b), Feature::edge1};
    const double inverse = 1.0 / (region_a + region_b + region_c);
    return {a + ab * (region_b * inverse) + ac * (region_c * inverse), Feature::face};
  }

  const Vector3& pseudonormal(std::size_t t, Feature feature) const {
    switch (feature) {
      case Feature::face: return face_normals_[t];
      case Feature::edge0: return edge_normals_[t][0];
      case Feature::edge1: return edge_normals_[t][1];
      case Feature::edge2: return edge_normals_[t][2];
      case Feature::vertex0: return vertex_normals_[triangles_[t][0]];
      case Feature::vertex1: return vertex_normals_[triangles_[t][1]];
      case Feature::vertex2: return vertex_normals_[triangles_[t][2]];
    }
    return face_normals_[t];
  }

  static std::string triangle_name(std::size_t t) { return "triangle " + std::to_string(t); }

  void validate_and_prepare() {
    if (vertices_.size() < 4)
      sphshell::detail::invalid_parameter("triangle surface vertex count", vertices_.size(),
                                          "a closed surface needs at least 4 vertices");
    if (triangles_.size() < 4)
      sphshell::detail::invalid_parameter("triangle surface triangle count", triangles_.size(),
                                          "a closed surface needs at least 4 triangles");
    Vector3 lower = vertices_[0];
    Vector3 upper = vertices_[0];
    for (std::size_t v = 0; v < vertices_.size(); ++v) {
      if (!all_finite(vertices_[v]))
        sphshell::detail::invalid_parameter("vertex " + std::to_string(v) + " x", vertices_[v].x(),
                                            "vertex coordinates must be finite");
      lower = lower.cwiseMin(vertices_[v]);
      upper = upper.cwiseMax(vertices_[v]);
    }
    const double diagonal_squared = (upper - lower).squaredNorm();
    surface_tolerance_ = on_surface_fraction * std::sqrt(diagonal_squared);
    const int vertex_count = static_cast<int>(vertices_.size());
    // Each directed edge (from, to) and the triangle and edge slot that runs it.
    std::map<std::pair<int, int>, std::pair<std::size_t, int>> directed_edges;
    face_normals_.resize(triangles_.size());
    for (std::size_t t = 0; t < triangles_.size(); ++t) {
      for (int corner = 0; corner < 3; ++corner) {
        const int index = triangles_[t][corner];
        if (index < 0 || index >= vertex_count)
          sphshell::detail::invalid_parameter(triangle_name(t) + " corner " + std::to_string(corner), index,
                                              "must index a vertex, 0 to " + std::to_string(vertex_count - 1));
      }
      const Vector3& a = vertices_[triangles_[t][0]];
      const Vector3 area_vector = 0.5 * (vertices_[triangles_[t][1]] - a).cross(vertices_[triangles_[t][2]] - a);
      const double area = area_vector.norm();
      if (!(area > degenerate_area_fraction * diagonal_squared))
        sphshell::detail::invalid_parameter(triangle_name(t) + " area", area,
                                            "degenerate: must exceed 1e-12 of the squared bounding-box diagonal");
      face_normals_[t] = area_vector / area;
      for (int k = 0; k < 3; ++k) {
        const std::pair<int, int> edge{triangles_[t][k], triangles_[t][(k + 1) % 3]};
        if (!directed_edges.emplace(edge, std::make_pair(t, k)).second)
          sphshell::detail::invalid_parameter(
              triangle_name(t) + " edge " + std::to_string(edge.first) + "-" + std::to_string(edge.second),
              "repeated", "an edge must be run once each way: the triangles overlap or turn inconsistently");
      }
    }
    // Closed and consistently oriented: every directed edge has its reverse.
    // The edge pseudonormal is the sum of the two face normals (Bærentzen & Aanæs).
    edge_normals_.resize(triangles_.size());
    for (const auto& [edge, owner] : directed_edges) {
      const auto reverse = directed_edges.find({edge.second, edge.first});
      if (reverse == directed_edges.end())
        sphshell::detail::invalid_parameter(
            triangle_name(owner.first) + " edge " + std::to_string(edge.first) + "-" + std::to_string(edge.second),
            "unmatched", "the surface must be closed: every edge shared by two triangles running it in opposite directions");
      edge_normals_[owner.first][owner.second] =
          (face_normals_[owner.first] + face_normals_[reverse->second.first]).normalized();
    }
    // Vertex pseudonormals: face normals weighted by the face's angle at the vertex.
    vertex_normals_.assign(vertices_.size(), Vector3::Zero());
    volume_ = 0.0;
    for (std::size_t t = 0; t < triangles_.size(); ++t) {
      for (int k = 0; k < 3; ++k) {
        const Vector3& here = vertices_[triangles_[t][k]];
        const Vector3 to_next = vertices_[triangles_[t][(k + 1) % 3]] - here;
        const Vector3 to_previous = vertices_[triangles_[t][(k + 2) % 3]] - here;
        const double angle = std::atan2(to_next.cross(to_previous).norm(), to_next.dot(to_previous));
        vertex_normals_[triangles_[t][k]] += angle * face_normals_[t];
      }
      // Divergence theorem: V = Σ a · (b × c) / 6.
      volume_ += vertices_[triangles_[t][0]].dot(vertices_[triangles_[t][1]].cross(vertices_[triangles_[t][2]])) / 6.0;
    }
    for (std::size_t v = 0; v < vertices_.size(); ++v) {
      const double length = vertex_normals_[v].norm();
      if (!(length > 0.0))
        sphshell::detail::invalid_parameter("vertex " + std::to_string(v) + " triangle count", 0,
                                            "every vertex must belong to a triangle");
      vertex_normals_[v] /= length;
    }
    if (!(volume_ > 0.0))
      sphshell::detail::invalid_parameter("triangle surface volume", volume_,
                                          "must be > 0: list each triangle's corners counter-clockwise seen from outside");
  }

  std::vector<Vector3> vertices_;
  std::vector<std::array<int, 3>> triangles_;
  std::vector<Vector3> face_normals_;
  std::vector<std::array<Vector3, 3>> edge_normals_;
  std::vector<Vector3> vertex_normals_;
  double surface_tolerance_ = 0.0;
  double volume_ = 0.0;
};

}  // namespace sphshell::contact
