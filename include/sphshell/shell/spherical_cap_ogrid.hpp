#pragma once
// A spherical cap meshed as an O-grid: a central block of m × m cells around
// the apex and rings of 4m cells out to the rim, so no cell is distorted the
// way the corners of a square grid mapped onto a disc are
// (ShellModel::spherical_cap: interior angles up to ≈ 175° near the rim's four
// corners, which also force a small stable step). Use this builder for curved
// caps whose response must converge (docs/method.md, docs/validation.md).
//
// The grid is drawn in the cap's geodesic polar plane — plane radius ρ = R θ
// (θ the polar angle), azimuth φ — and mapped onto the exact sphere:
// X = R (sin θ cos φ, sin θ sin φ, cos θ), normal X/R (outward).
// - Central block: half-width b = block_fraction · Rα, its sides bulging
//   outward by bulge · b at their midpoints (parabolic), which opens the
//   block's corners from 90° to 2·atan(2·bulge) + 90° (120° at the default
//   bulge, so the corner cells inside and the two ring cells outside share
//   the 360° equally); the interior is the Coons patch of the four sides.
// - Rings: each of the block's 4m boundary nodes is joined by a straight line
//   to a rim node at uniform azimuth (the block's corners to ±45°, ±135°);
//   the ring nodes divide these lines with a spacing that grows linearly from
//   the block's boundary spacing 2b/m to the rim's circumferential spacing
//   2π R sin α / (4m), so the cells stay close to square at both ends.
// Named sets: "boundary" (the rim nodes), "apex" (the block's centre node).
// At m = 16 the cells' interior angles lie in 64.7–121.2° and their areas
// within a factor 2.97.

#include <sphshell/core/error.hpp>
#include <sphshell/core/types.hpp>
#include <sphshell/shell/model.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <limits>
#include <vector>

namespace sphshell {

struct OGridOptions {
  double block_fraction = 0.5;  // block half-width / meridian length Rα
  double bulge = 0.134;         // side bulge / half-width (tan 15° / 2: 120° corners)
  // Radial spacing at the rim, from the block's spacing (0: uniform radial
  // spacing, rim cells longer round than across) to the rim's
  // circumferential spacing (1: square rim cells, fewer rings).
  double radial_growth = 1.0;
};

struct OGridQuality {
  int rings = 0;
  double largest_angle = 0.0;   // largest interior angle of any cell, degrees
  double smallest_angle = 0.0;  // smallest, degrees
  double area_ratio = 0.0;      // largest / smallest cell area
};

namespace detail::ogrid {
inline constexpr double pi = 3.14159265358979323846;
// The largest m whose (m + 1)² block nodes have int indices.
inline constexpr int max_block_divisions = 46339;

struct Plane {
  double x, y;
};
inline Plane operator+(Plane a, Plane b) { return {a.x + b.x, a.y + b.y}; }
inline Plane operator-(Plane a, Plane b) { return {a.x - b.x, a.y - b.y}; }
inline Plane operator*(double s, Plane a) { return {s * a.x, s * a.y}; }
inline double length(Plane a) { return std::hypot(a.x, a.y); }

struct Layout {
  std::vector<Plane> nodes;
  std::vector<Quad> quads;
  std::vector<int> rim;
  int apex = 0;
  int rings = 0;
};

inline Layout layout(double radius, double half_angle, int m, const OGridOptions& options) {
  sphshell::detail::require_positive("radius", radius);
  if (!(half_angle > 0.0 && half_angle < pi / 2))
    sphshell::detail::invalid_parameter("half_angle", half_angle, "must lie in (0, π/2)");
  if (m < 2 || m % 2 != 0)
    sphshell::detail::invalid_parameter("m", m, "must be even and at least 2 (the apex is the block's centre node)");
  if (!(options.block_fraction > 0.0 && options.block_fraction * std::sqrt(2.0) < 1.0))
    sphshell::detail::invalid_parameter("block_fraction", options.block_fraction,
                                        "must lie in (0, 1/√2): the block's corners must stay inside the rim");
  if (!(options.radial_growth >= 0.0 && options.radial_growth <= 1.0))
    sphshell::detail::invalid_parameter("radial_growth", options.radial_growth, "must lie in [0, 1]");
  if (!(options.bulge >= 0.0 && options.bulge < 0.5))
    sphshell::detail::invalid_parameter("bulge", options.bulge, "must lie in [0, 0.5)");
  // The bulged sides' midpoints lie at b (1 + bulge) from the apex.
  if (!(options.block_fraction * (1.0 + options.bulge) < 1.0))
    sphshell::detail::invalid_parameter("block_fraction × (1 + bulge)", options.block_fraction * (1.0 + options.bulge),
                                        "must be below 1: the block's bulged sides must stay inside the rim");
  // (m + 1)² block nodes (and the rings around them, checked below) with int indices.
  if (m > max_block_divisions)
    sphshell::detail::invalid_parameter("m", m, "must be at most " + std::to_string(max_block_divisions) +
                                                    " (the library's particle indices are int)");
  const double L = radius * half_angle, b = options.block_fraction * L, c = options.bulge;
  Layout g;
  // Block sides (parameter t ∈ [−1, 1]) and their Coons patch.
  auto side = [&](double t) { return b * (1.0 + c * (1.0 - t * t)); };
  auto block_point = [&](double u, double v) {
    const Plane bottom{b * u, -side(u)}, top{b * u, side(u)}, left{-side(v), b * v}, right{side(v), b * v};
    const Plane bilinear{b * u, b * v};
    return 0.5 * (1.0 - v) * bottom + 0.5 * (1.0 + v) * top + 0.5 * (1.0 - u) * left +
           0.5 * (1.0 + u) * right - bilinear;
  };
  auto block_index = [m](int i, int j) { return j * (m + 1) + i; };
  for (int j = 0; j <= m; ++j)
    for (int i = 0; i <= m; ++i) g.nodes.push_back(block_point(-1.0 + 2.0 * i / m, -1.0 + 2.0 * j / m));
  for (int j = 0; j < m; ++j)
    for (int i = 0; i < m; ++i)
      g.quads.push_back({block_index(i, j), block_index(i + 1, j), block_index(i + 1, j + 1), block_index(i, j + 1)});
  g.apex = block_index(m / 2, m / 2);
  // The block's boundary, counter-clockwise from the corner (b, −b).
  const int around = 4 * m;
  std::vector<int> boundary;
  for (int k = 0; k < m; ++k) boundary.push_back(block_index(m, k));
  for (int k = 0; k < m; ++k) boundary.push_back(block_index(m - k, m));
  for (int k = 0; k < m; ++k) boundary.push_back(block_index(0, m - k));
  for (int k = 0; k < m; ++k) boundary.push_back(block_index(k, 0));
  // Rings: spacing growing linearly from h_in to h_out along each ray.
  const double h_in = 2.0 * b / m, h_rim = 2.0 * pi * radius * std::sin(half_angle) / around;
  const double h_out = h_in + options.radial_growth * (h_rim - h_in);
  double mean_width = 0.0;
  for (int node : boundary) mean_width += (L - length(g.nodes[std::size_t(node)])) / around;
  const double rings = std::max(1.0, std::round(mean_width / (0.5 * (h_in + h_out))));
  const double nodes = double(g.nodes.size()) + double(around) * rings;
  if (!(nodes <= double(std::numeric_limits<int>::max())))
    sphshell::detail::invalid_parameter("m", m, "gives " + std::to_string(nodes) +
                                                    " particles with these options; at most 2^31 - 1 (int indices)");
  g.rings = int(rings);
  // Normalized position along a ray, s(t) = a t + (1 − a) t² with
  // s'(0)/s'(1) = h_in/h_out.
  const double ratio = h_in / h_out, a = 2.0 * ratio / (1.0 + ratio);
  std::vector<int> previous = boundary;
  for (int l = 1; l <= g.rings; ++l) {
    const double t = double(l) / g.rings, s = a * t + (1.0 - a) * t * t;
    std::vector<int> ring;
    for (int k = 0; k < around; ++k) {
      const double azimuth = -pi / 4 + 2.0 * pi * k / around;
      const Plane inner = g.nodes[std::size_t(boundary[std::size_t(k)])];
      const Plane outer{L * std::cos(azimuth), L * std::sin(azimuth)};
      ring.push_back(int(g.nodes.size()));
      g.nodes.push_back(inner + s * (outer - inner));
    }
    for (int k = 0; k < around; ++k) {
      const int next = (k + 1) % around;
      g.quads.push_back({previous[std::size_t(k)], ring[std::size_t(k)], ring[std::size_t(next)],
                         previous[std::size_t(next)]});
    }
    previous = ring;
  }
  g.rim = previous;
  return g;
}

// Plane point → sphere point (and outward unit normal).
inline Vector3 on_sphere(double radius, Plane p) {
  const double theta = length(p) / radius, phi = std::atan2(p.y, p.x);
  return radius * Vector3(std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi), std::cos(theta));
}
}  // namespace detail::ogrid

// The O-grid cap: particles at the grid's nodes, stress points at the cells'
// centres (the centre of the four corners in the polar plane, on the sphere).
inline ShellModel spherical_cap_ogrid(double radius, double half_angle, int m, double thickness,
                                      const OGridOptions& options = {}) {
  // The block's (m + 1)² nodes and m² cells, counted before the layout is
  // allocated (the rings around it add fewer); an allocation that fails
  // anyway is an Error with this estimate.
  const double block_nodes = (m + 1.0) * (m + 1.0), block_cells = 1.0 * m * m;
  // (An m the layout refuses is named by it first.)
  const bool countable = m >= 2 && m <= detail::ogrid::max_block_divisions;
  const double estimate =
      countable ? sphshell::detail::model_checks::require_model_memory("spherical_cap_ogrid", block_nodes, block_cells)
                : 0.0;
  return sphshell::detail::model_checks::guard_building("spherical_cap_ogrid", estimate, [&] {
    const detail::ogrid::Layout g = detail::ogrid::layout(radius, half_angle, m, options);
    std::vector<Vector3> positions, normals, centres, centre_normals;
    for (const detail::ogrid::Plane& p : g.nodes) {
      positions.push_back(detail::ogrid::on_sphere(radius, p));
      normals.push_back(positions.back() / radius);
    }
    for (const Quad& q : g.quads) {
      detail::ogrid::Plane centre{0.0, 0.0};
      for (int corner : q) centre = centre + 0.25 * g.nodes[std::size_t(corner)];
      centres.push_back(detail::ogrid::on_sphere(radius, centre));
      centre_normals.push_back(centres.back() / radius);
    }
    ShellModel model = ShellModel::from_quads(positions, normals, g.quads, centres, centre_normals, thickness);
    const double tolerance = 1e-9 * radius;
    const double rim_height = radius * std::cos(half_angle);
    const Vector3 apex = positions[std::size_t(g.apex)];
    model.define_set("boundary", [&](const Vector3& x) { return x.z() < rim_height + tolerance; });
    model.define_set("apex", [&](const Vector3& x) { return (x - apex).norm() < tolerance; });
    return model;
  });
}

// Shape figures of the O-grid cells on the sphere.
inline OGridQuality spherical_cap_ogrid_quality(double radius, double half_angle, int m, const OGridOptions& options = {}) {
  const detail::ogrid::Layout g = detail::ogrid::layout(radius, half_angle, m, options);
  OGridQuality quality;
  quality.rings = g.rings;
  quality.smallest_angle = 360.0;
  double smallest_area = std::numeric_limits<double>::infinity(), largest_area = 0.0;
  for (const Quad& q : g.quads) {
    std::array<Vector3, 4> x;
    for (int k = 0; k < 4; ++k) x[std::size_t(k)] = detail::ogrid::on_sphere(radius, g.nodes[std::size_t(q[std::size_t(k)])]);
    for (int k = 0; k < 4; ++k) {
      const Vector3 to_next = x[std::size_t((k + 1) % 4)] - x[std::size_t(k)];
      const Vector3 to_previous = x[std::size_t((k + 3) % 4)] - x[std::size_t(k)];
      const double angle = std::acos(std::clamp(to_next.normalized().dot(to_previous.normalized()), -1.0, 1.0)) *
                           180.0 / detail::ogrid::pi;
      quality.largest_angle = std::max(quality.largest_angle, angle);
      quality.smallest_angle = std::min(quality.smallest_angle, angle);
    }
    const double area = 0.5 * (x[2] - x[0]).cross(x[3] - x[1]).norm();
    smallest_area = std::min(smallest_area, area);
    largest_area = std::max(largest_area, area);
  }
  quality.area_ratio = largest_area / smallest_area;
  return quality;
}

}  // namespace sphshell
