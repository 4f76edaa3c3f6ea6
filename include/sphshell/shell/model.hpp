#pragma once
// The shell's geometry in the reference configuration: particles on the
// mid-surface and the stress points staggered between them (docs/method.md §1),
// in structure-of-arrays storage, with builders for the usual shapes.

#include <sphshell/core/error.hpp>
#include <sphshell/core/frame.hpp>
#include <sphshell/core/types.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <functional>
#include <map>
#include <string>
#include <utility>
#include <vector>

namespace sphshell {

using ParticleSet = std::vector<int>;

// Four particle indices of a quadrilateral cell, counter-clockwise seen from the
// side the normals point to; a stress point sits at each cell's centre.
using Quad = std::array<int, 4>;

class ShellModel {
 public:
  // Particles: reference position, unit director (pseudo-normal), tributary area.
  std::vector<Vector3> particle_position;
  std::vector<Vector3> particle_normal;
  std::vector<double> particle_area;
  // Stress points: reference position, unit normal, area weight.
  std::vector<Vector3> stress_point_position;
  std::vector<Vector3> stress_point_normal;
  std::vector<double> stress_point_area;

  // General constructor: the user's own particles and stress points. Areas are
  // integration weights (m²); the two sets of areas should each cover the
  // mid-surface once.
  ShellModel(std::vector<Vector3> positions, std::vector<Vector3> normals,
             std::vector<double> areas, std::vector<Vector3> stress_positions,
             std::vector<Vector3> stress_normals, std::vector<double> stress_areas,
             double thickness)
      : particle_position(std::move(positions)),
        particle_normal(std::move(normals)),
        particle_area(std::move(areas)),
        stress_point_position(std::move(stress_positions)),
        stress_point_normal(std::move(stress_normals)),
        stress_point_area(std::move(stress_areas)),
        thickness_(thickness) {
    validate();
    particle_thickness_.assign(particle_position.size(), thickness_);
    stress_point_thickness_.assign(stress_point_position.size(), thickness_);
  }

  // Particles at the nodes of user quads, stress points at the quad centres
  // (positions and normals averaged), areas from the quads: each quad's area goes
  // to its stress point and a quarter of it to each of its four particles.
  static ShellModel from_quads(std::vector<Vector3> positions, std::vector<Vector3> normals,
                               const std::vector<Quad>& quads, double thickness) {
    check_sizes(positions, normals);
    std::vector<Vector3> centres;
    std::vector<Vector3> centre_normals;
    for (const Quad& quad : quads) {
      check_quad(quad, positions.size());
      Vector3 centre = Vector3::Zero();
      Vector3 normal = Vector3::Zero();
      for (int corner : quad) {
        centre += positions[corner] / 4.0;
        normal += normals[corner];
      }
      centres.push_back(centre);
      centre_normals.push_back(normal);
    }
    return from_quads(std::move(positions), std::move(normals), quads, std::move(centres),
                      std::move(centre_normals), thickness);
  }

  // As above with the stress points' positions and normals given (builders of
  // curved shells put them on the exact surface).
  static ShellModel from_quads(std::vector<Vector3> positions, std::vector<Vector3> normals,
                               const std::vector<Quad>& quads,
                               std::vector<Vector3> stress_positions,
                               std::vector<Vector3> stress_normals, double thickness) {
    check_sizes(positions, normals);
    if (stress_positions.size() != quads.size() || stress_normals.size() != quads.size())
      detail::invalid_parameter("stress point count", stress_positions.size(),
                                "must equal the number of quads (" + std::to_string(quads.size()) + ")");
    std::vector<double> areas(positions.size(), 0.0);
    std::vector<double> stress_areas;
    stress_areas.reserve(quads.size());
    for (const Quad& quad : quads) {
      check_quad(quad, positions.size());
      const Vector3 diagonal1 = positions[quad[2]] - positions[quad[0]];
      const Vector3 diagonal2 = positions[quad[3]] - positions[quad[1]];
      const double area = 0.5 * diagonal1.cross(diagonal2).norm();
      stress_areas.push_back(area);
      for (int corner : quad) areas[corner] += area / 4.0;
    }
    ShellModel model(std::move(positions), std::move(normals), std::move(areas),
                     std::move(stress_positions), std::move(stress_normals),
                     std::move(stress_areas), thickness);
    model.quads_ = quads;
    return model;
  }

  // Flat rectangular plate in the xy-plane, corner at the origin, normals +z:
  // nx × ny particles, (nx−1)(ny−1) stress points at the cell centres (51×51
  // particles give the paper's 2500 stress points). Named sets: "x_min", "x_max",
  // "y_min", "y_max" (edges), "boundary", "centre" (the particle nearest the centre).
  static ShellModel rectangular_plate(double length_x, double length_y, int nx, int ny,
                                      double thickness) {
    detail::require_positive("length_x", length_x);
    detail::require_positive("length_y", length_y);
    require_count("nx", nx, 2);
    require_count("ny", ny, 2);
    auto surface = [&](double u, double v) {
      return std::make_pair(Vector3(u * length_x, v * length_y, 0.0), Vector3(0.0, 0.0, 1.0));
    };
    ShellModel model = structured(nx, ny, false, surface, thickness);
    const double tolerance = 1e-9 * std::max(length_x, length_y);
    model.define_set("x_min", [&](const Vector3& x) { return x.x() < tolerance; });
    model.define_set("x_max", [&](const Vector3& x) { return x.x() > length_x - tolerance; });
    model.define_set("y_min", [&](const Vector3& x) { return x.y() < tolerance; });
    model.define_set("y_max", [&](const Vector3& x) { return x.y() > length_y - tolerance; });
    model.define_set("boundary", [&](const Vector3& x) {
      return x.x() < tolerance || x.x() > length_x - tolerance || x.y() < tolerance ||
             x.y() > length_y - tolerance;
    });
    model.sets_["centre"] = {model.nearest_particle(Vector3(length_x / 2, length_y / 2, 0.0))};
    return model;
  }

  // Cylindrical panel about the z-axis: radius, axial length (z from 0), opening
  // angle (radians, from the x-axis; 2π makes a closed tube without a seam),
  // n_circumferential × n_axial particles, normals pointing outward. Named sets:
  // "z_min", "z_max" (the ends), and for an open panel "theta_min", "theta_max".
  static ShellModel cylindrical_panel(double radius, double length, double angle,
                                      int n_circumferential, int n_axial, double thickness) {
    detail::require_positive("radius", radius);
    detail::require_positive("length", length);
    if (!(angle > 0.0 && angle <= 2.0 * kPi + 1e-12))
      detail::invalid_parameter("angle", angle, "must lie in (0, 2π]");
    const bool closed = angle > 2.0 * kPi - 1e-12;
    require_count("n_circumferential", n_circumferential, closed ? 3 : 2);
    require_count("n_axial", n_axial, 2);
    auto surface = [&](double u, double v) {
      const double theta = u * angle;
      const Vector3 normal(std::cos(theta), std::sin(theta), 0.0);
      return std::make_pair(Vector3(radius * normal.x(), radius * normal.y(), v * length), normal);
    };
    ShellModel model = structured(n_circumferential, n_axial, closed, surface, thickness);
    const double tolerance = 1e-9 * std::max(radius, length);
    model.define_set("z_min", [&](const Vector3& x) { return x.z() < tolerance; });
    model.define_set("z_max", [&](const Vector3& x) { return x.z() > length - tolerance; });
    if (!closed) {
      const int n = n_circumferential;
      ParticleSet first, last;
      for (int j = 0; j < n_axial; ++j) {
        first.push_back(j * n);
        last.push_back(j * n + n - 1);
      }
      model.sets_["theta_min"] = first;
      model.sets_["theta_max"] = last;
    }
    return model;
  }

  // Spherical cap of a sphere of the given radius centred on the z-axis, apex at
  // (0, 0, radius), opening half-angle (radians). A square grid of n × n
  // particles is mapped onto the disc (the elliptical grid map u√(1−v²/2),
  // v√(1−u²/2)) and then onto the sphere by polar angle ∝ disc radius: no pole
  // singularity, but the cells near the four rim corners are distorted (interior
  // angles up to ≈ 175°, areas up to ≈ 6× the smallest at n = 21).
  // Normals point outward. Named sets: "boundary" (the rim), "apex".
  static ShellModel spherical_cap(double radius, double half_angle, int n, double thickness) {
    detail::require_positive("radius", radius);
    if (!(half_angle > 0.0 && half_angle < kPi / 2))
      detail::invalid_parameter("half_angle", half_angle, "must lie in (0, π/2)");
    require_count("n", n, 3);
    auto surface = [&](double u, double v) {
      const double s = 2.0 * u - 1.0;
      const double t = 2.0 * v - 1.0;
      const double disc_x = s * std::sqrt(1.0 - t * t / 2.0);
      const double disc_y = t * std::sqrt(1.0 - s * s / 2.0);
      const double disc_radius = std::min(1.0, std::hypot(disc_x, disc_y));
      const double polar = disc_radius * half_angle;
      const double azimuth = std::atan2(disc_y, disc_x);
      const Vector3 normal(std::sin(polar) * std::cos(azimuth), std::sin(polar) * std::sin(azimuth),
                           std::cos(polar));
      return std::make_pair(Vector3(radius * normal), normal);
    };
    ShellModel model = structured(n, n, false, surface, thickness);
    ParticleSet rim;
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i)
        if (i == 0 || j == 0 || i == n - 1 || j == n - 1) rim.push_back(j * n + i);
    model.sets_["boundary"] = rim;
    model.sets_["apex"] = {model.nearest_particle(Vector3(0.0, 0.0, radius))};
    return model;
  }

  // The thickness the model was built with; set_thickness can change it in regions.
  double thickness() const { return thickness_; }
  // Wall thickness at a particle and at a stress point (m).
  double particle_thickness(std::size_t i) const { return particle_thickness_.at(i); }
  double stress_point_thickness(std::size_t p) const { return stress_point_thickness_.at(p); }
  double minimum_thickness() const {
    return std::min(*std::min_element(particle_thickness_.begin(), particle_thickness_.end()),
                    *std::min_element(stress_point_thickness_.begin(), stress_point_thickness_.end()));
  }
  // Gives every particle and stress point whose reference position satisfies
  // where(X) the thickness d (a thinned band such as a machined surface notch,
  // a doubler, a tapered wall). The mid-surface stays where it is. Returns how
  // many points changed; a region that holds no point is an Error.
  template <class Predicate>
  std::size_t set_thickness(Predicate&& where, double d) {
    detail::require_positive("thickness", d);
    std::size_t count = 0;
    for (std::size_t i = 0; i < particle_position.size(); ++i)
      if (where(particle_position[i])) particle_thickness_[i] = d, ++count;
    for (std::size_t p = 0; p < stress_point_position.size(); ++p)
      if (where(stress_point_position[p])) stress_point_thickness_[p] = d, ++count;
    if (count == 0)
      detail::invalid_parameter("set_thickness region", d, "holds no particle and no stress point");
    return count;
  }
  std::size_t particle_count() const { return particle_position.size(); }
  std::size_t stress_point_count() const { return stress_point_position.size(); }
  const std::vector<Quad>& quads() const { return quads_; }

  // Characteristic particle spacing: the smallest distance between a stress
  // point's neighbouring particles is not known without a search, so use the
  // square root of the smallest stress-point area (the cell size of a sheet).
  double minimum_spacing() const {
    double smallest = *std::min_element(stress_point_area.begin(), stress_point_area.end());
    return std::sqrt(smallest);
  }
  double maximum_spacing() const {
    double largest = *std::max_element(stress_point_area.begin(), stress_point_area.end());
    return std::sqrt(largest);
  }

  // Named particle sets, for boundary conditions, loads and probes.
  template <class Predicate>
  const ParticleSet& define_set(const std::string& name, Predicate&& contains) {
    ParticleSet members;
    for (std::size_t i = 0; i < particle_position.size(); ++i)
      if (contains(particle_position[i])) members.push_back(static_cast<int>(i));
    if (members.empty())
      detail::invalid_parameter("particle set " + name, "(empty)", "no particle satisfies the predicate");
    return sets_[name] = std::move(members);
  }
  const ParticleSet& set(const std::string& name) const {
    auto found = sets_.find(name);
    if (found == sets_.end()) detail::invalid_parameter("particle set name", name, "no such set");
    return found->second;
  }
  bool has_set(const std::string& name) const { return sets_.count(name) != 0; }
  std::vector<std::string> set_names() const {
    std::vector<std::string> names;
    for (const auto& entry : sets_) names.push_back(entry.first);
    return names;
  }

  // Every particle, e.g. for a load over the whole shell.
  ParticleSet all_particles() const {
    ParticleSet all(particle_position.size());
    for (std::size_t i = 0; i < all.size(); ++i) all[i] = static_cast<int>(i);
    return all;
  }

  int nearest_particle(const Vector3& point) const {
    return nearest(particle_position, point);
  }
  int nearest_stress_point(const Vector3& point) const {
    return nearest(stress_point_position, point);
  }

 private:
  static constexpr double kPi = 3.14159265358979323846;

  // Particles at the nodes of an nu × nv parametric grid on [0,1]², stress points
  // at the cell centres; `periodic_u` closes the grid in u (a full tube).
  template <class Surface>
  static ShellModel structured(int nu, int nv, bool periodic_u, Surface&& surface, double thickness) {
    std::vector<Vector3> positions, normals;
    const int columns = periodic_u ? nu : nu - 1;
    auto u_of = [&](double i) { return i / columns; };
    for (int j = 0; j < nv; ++j)
      for (int i = 0; i < nu; ++i) {
        auto point = surface(u_of(i), static_cast<double>(j) / (nv - 1));
        positions.push_back(point.first);
        normals.push_back(point.second);
      }
    std::vector<Quad> quads;
    std::vector<Vector3> centres, centre_normals;
    for (int j = 0; j + 1 < nv; ++j)
      for (int i = 0; i < columns; ++i) {
        const int next = (i + 1) % nu;
        quads.push_back({j * nu + i, j * nu + next, (j + 1) * nu + next, (j + 1) * nu + i});
        auto centre = surface(u_of(i + 0.5), (j + 0.5) / (nv - 1));
        centres.push_back(centre.first);
        centre_normals.push_back(centre.second);
      }
    return from_quads(std::move(positions), std::move(normals), quads, std::move(centres),
                      std::move(centre_normals), thickness);
  }

  static void require_count(const char* name, int value, int minimum) {
    if (value < minimum)
      detail::invalid_parameter(name, value, "must be at least " + std::to_string(minimum));
  }
  static void check_sizes(const std::vector<Vector3>& positions, const std::vector<Vector3>& normals) {
    if (normals.size() != positions.size())
      detail::invalid_parameter("normal count", normals.size(),
                                "must equal the particle count (" + std::to_string(positions.size()) + ")");
  }
  static void check_quad(const Quad& quad, std::size_t particle_count) {
    for (int corner : quad)
      if (corner < 0 || static_cast<std::size_t>(corner) >= particle_count)
        detail::invalid_parameter("quad corner index", corner, "out of range");
  }
  static int nearest(const std::vector<Vector3>& points, const Vector3& point) {
    int best = 0;
    double best_distance = (points[0] - point).squaredNorm();
    for (std::size_t i = 1; i < points.size(); ++i) {
      const double distance = (points[i] - point).squaredNorm();
      if (distance < best_distance) {
        best_distance = distance;
        best = static_cast<int>(i);
      }
    }
    return best;
  }

  void validate() {
    detail::require_positive("thickness", thickness_);
    const std::size_t n = particle_position.size();
    if (n == 0) detail::invalid_parameter("particle count", 0, "a shell needs particles");
    if (particle_normal.size() != n || particle_area.size() != n)
      detail::invalid_parameter("particle array sizes", particle_normal.size(),
                                "positions, normals and areas must have the same length");
    const std::size_t m = stress_point_position.size();
    if (m == 0) detail::invalid_parameter("stress point count", 0, "a shell needs stress points");
    if (stress_point_normal.size() != m || stress_point_area.size() != m)
      detail::invalid_parameter("stress point array sizes", stress_point_normal.size(),
                                "positions, normals and areas must have the same length");
    normalize_all(particle_position, particle_normal, particle_area, "particle");
    normalize_all(stress_point_position, stress_point_normal, stress_point_area, "stress point");
  }
  static void normalize_all(const std::vector<Vector3>& positions, std::vector<Vector3>& normals,
                            const std::vector<double>& areas, const std::string& what) {
    for (std::size_t i = 0; i < positions.size(); ++i) {
      const std::string name = what + " " + std::to_string(i);
      if (!positions[i].allFinite())
        detail::invalid_parameter(name + " position", positions[i].transpose(), "must be finite");
      const double length = normals[i].norm();
      if (!(length > 0.0) || !std::isfinite(length))
        detail::invalid_parameter(name + " normal length", length, "must be finite and non-zero");
      normals[i] /= length;
      detail::require_positive(name + " area", areas[i]);
    }
  }

  double thickness_;
  std::vector<double> particle_thickness_;
  std::vector<double> stress_point_thickness_;
  std::vector<Quad> quads_;
  std::map<std::string, ParticleSet> sets_;
};

}  // namespace sphshell
