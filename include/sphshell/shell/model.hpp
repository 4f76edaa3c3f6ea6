#pragma once
// The shell's geometry in the reference configuration: particles on the
// mid-surface and the stress points staggered between them (docs/method.md §1),
// in structure-of-arrays storage, with builders for the usual shapes.

#include <sphshell/approx/neighbour_search.hpp>
#include <sphshell/core/error.hpp>
#include <sphshell/core/frame.hpp>
#include <sphshell/core/types.hpp>

#include <Eigen/Eigenvalues>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <functional>
#include <limits>
#include <map>
#include <optional>
#include <sstream>
#include <string>
#include <unordered_map>
#include <utility>
#include <vector>

namespace sphshell {

using ParticleSet = std::vector<int>;

// Four particle indices of a quadrilateral cell, counter-clockwise seen from the
// side the normals point to; a stress point sits at each cell's centre.
using Quad = std::array<int, 4>;

// Corner particle indices of a triangular (3) or quadrilateral (4) cell, in
// counter-clockwise order seen from the side the normals point to; the cell's
// stress point sits at its centre.
class Cell {
 public:
  Cell(int a, int b, int c) : corners_{a, b, c, -1}, size_(3) {}
  Cell(int a, int b, int c, int d) : corners_{a, b, c, d}, size_(4) {}
  explicit Cell(const Quad& quad) : corners_(quad), size_(4) {}
  std::size_t size() const { return size_; }
  bool is_triangle() const { return size_ == 3; }
  int operator[](std::size_t k) const { return corners_[k]; }
  const int* begin() const { return corners_.data(); }
  const int* end() const { return corners_.data() + size_; }

 private:
  std::array<int, 4> corners_;
  std::size_t size_;
};

// Two cells that share an edge and run along it in the same direction (their
// normals flip across it), or a third cell on an edge (a junction, which one
// director per particle cannot represent).
struct CellEdgeProblem {
  enum class Kind { flipped, junction };
  Kind kind;
  int first_cell;
  int second_cell;
  int edge_start;  // particle indices of the shared edge
  int edge_end;
};

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
    check_quads(positions, normals, quads);
    std::vector<Vector3> centres;
    std::vector<Vector3> centre_normals;
    for (const Quad& quad : quads) {
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
    check_quads(positions, normals, quads);
    if (stress_positions.size() != quads.size() || stress_normals.size() != quads.size())
      detail::invalid_parameter("stress point count", stress_positions.size(),
                                "must equal the number of quads (" + std::to_string(quads.size()) + ")");
    std::vector<double> areas(positions.size(), 0.0);
    std::vector<double> stress_areas;
    stress_areas.reserve(quads.size());
    for (const Quad& quad : quads) {
      const Vector3 diagonal1 = positions[quad[2]] - positions[quad[0]];
      const Vector3 diagonal2 = positions[quad[3]] - positions[quad[1]];
      const double area = 0.5 * diagonal1.cross(diagonal2).norm();
      stress_areas.push_back(area);
      for (int corner : quad) areas[corner] += area / 4.0;
    }
    for (std::size_t i = 0; i < positions.size(); ++i)
      if (!(areas[i] > 0.0))
        detail::invalid_parameter("particle " + std::to_string(i), positions[i].transpose(),
                                  "belongs to no quad: every particle must be a corner of a quad");
    ShellModel model(std::move(positions), std::move(normals), std::move(areas),
                     std::move(stress_positions), std::move(stress_normals),
                     std::move(stress_areas), thickness);
    model.quads_ = quads;
    for (const Quad& quad : quads) model.cells_.emplace_back(quad);
    return model;
  }

  // Particles at the nodes of a triangle, quadrilateral or mixed mesh, one
  // stress point per cell at its centre (the mean of its corners). A triangle's
  // area goes to its stress point and a third of it to each corner particle; a
  // quad's area (from its diagonals) and a quarter of it to each corner, as in
  // from_quads. A stress point's normal is its cell's (the cross product of a
  // triangle's edges, of a quad's diagonals); a particle's normal is the
  // area-weighted mean of the normals of the cells around it. Cells that share
  // an edge must run along it in opposite directions (consistent orientation);
  // a flip, an edge of three or more cells, a degenerate cell or a particle of
  // no cell is an Error. quads() is filled only when every cell is a quad.
  static ShellModel from_cells(std::vector<Vector3> positions, const std::vector<Cell>& cells,
                               double thickness) {
    if (cells.empty()) detail::invalid_parameter("cell count", 0, "a shell needs cells");
    check_finite("particle", "position", positions);
    for (std::size_t c = 0; c < cells.size(); ++c) check_cell(cells[c], c, positions.size());
    if (const std::optional<CellEdgeProblem> problem = find_cell_edge_problem(cells))
      detail::invalid_parameter(
          "cells", std::to_string(problem->first_cell) + " and " + std::to_string(problem->second_cell),
          describe_edge_problem(*problem, "particles"));
    std::vector<Vector3> normals(positions.size(), Vector3::Zero());
    std::vector<double> areas(positions.size(), 0.0);
    std::vector<Vector3> centres, cell_normals;
    std::vector<double> cell_areas;
    centres.reserve(cells.size());
    cell_normals.reserve(cells.size());
    cell_areas.reserve(cells.size());
    for (std::size_t c = 0; c < cells.size(); ++c) {
      const Cell& cell = cells[c];
      const double corners = static_cast<double>(cell.size());
      // Twice the area times the unit normal, for a planar cell exactly.
      const Vector3 doubled_area =
          cell.is_triangle() ? Vector3((positions[cell[1]] - positions[cell[0]])
                                           .cross(positions[cell[2]] - positions[cell[0]]))
                             : Vector3((positions[cell[2]] - positions[cell[0]])
                                           .cross(positions[cell[3]] - positions[cell[1]]));
      const double area = 0.5 * doubled_area.norm();
      if (!(area > 0.0))
        detail::invalid_parameter("cell " + std::to_string(c) + " area", area, "must be > 0 (degenerate cell)");
      Vector3 centre = Vector3::Zero();
      for (int corner : cell) {
        centre += positions[corner] / corners;
        areas[corner] += area / corners;
        normals[corner] += doubled_area;
      }
      centres.push_back(centre);
      cell_normals.push_back(doubled_area);
      cell_areas.push_back(area);
    }
    for (std::size_t i = 0; i < positions.size(); ++i)
      if (!(areas[i] > 0.0))
        detail::invalid_parameter("particle " + std::to_string(i), positions[i].transpose(), "belongs to no cell");
    ShellModel model(std::move(positions), std::move(normals), std::move(areas), std::move(centres),
                     std::move(cell_normals), std::move(cell_areas), thickness);
    model.cells_ = cells;
    if (std::none_of(cells.begin(), cells.end(), [](const Cell& cell) { return cell.is_triangle(); }))
      for (const Cell& cell : cells) model.quads_.push_back({cell[0], cell[1], cell[2], cell[3]});
    return model;
  }

  // The first orientation flip or junction among cells in the order given, or
  // none. Cells' corners must be valid and distinct (from_cells checks them).
  static std::optional<CellEdgeProblem> find_cell_edge_problem(const std::vector<Cell>& cells) {
    struct EdgeUse {
      int cell;
      bool ascending;  // the first cell runs from the lower to the higher index
      int count;
    };
    std::unordered_map<std::uint64_t, EdgeUse> uses;
    for (std::size_t c = 0; c < cells.size(); ++c) {
      const Cell& cell = cells[c];
      for (std::size_t k = 0; k < cell.size(); ++k) {
        const int from = cell[k], to = cell[(k + 1) % cell.size()];
        const int low = std::min(from, to), high = std::max(from, to);
        const std::uint64_t key = (static_cast<std::uint64_t>(static_cast<std::uint32_t>(low)) << 32) |
                                  static_cast<std::uint32_t>(high);
        const EdgeUse use{static_cast<int>(c), from < to, 1};
        auto [found, inserted] = uses.try_emplace(key, use);
        if (inserted) continue;
        if (found->second.count >= 2)
          return CellEdgeProblem{CellEdgeProblem::Kind::junction, found->second.cell, use.cell, from, to};
        if (found->second.ascending == use.ascending)
          return CellEdgeProblem{CellEdgeProblem::Kind::flipped, found->second.cell, use.cell, from, to};
        ++found->second.count;
      }
    }
    return std::nullopt;
  }

  // What went wrong, for a message; `corner_names` says what the edge's ends are
  // ("particles", "nodes").
  static std::string describe_edge_problem(const CellEdgeProblem& problem, const std::string& corner_names) {
    const std::string edge = "the edge between " + corner_names + " " + std::to_string(problem.edge_start) +
                             " and " + std::to_string(problem.edge_end);
    if (problem.kind == CellEdgeProblem::Kind::flipped)
      return "they run along " + edge +
             " in the same direction, so their normals flip there; reverse the corner order of one side";
    return "a third cell meets at " + edge + "; a junction of three or more cells is not supported";
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
  double particle_thickness(std::size_t i) const {
    check_index("particle", i, particle_count());
    return particle_thickness_[i];
  }
  double stress_point_thickness(std::size_t p) const {
    check_index("stress point", p, stress_point_count());
    return stress_point_thickness_[p];
  }
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
    require_thin("thickness", d, extent());
    std::size_t count = 0;
    for (std::size_t i = 0; i < particle_position.size(); ++i)
      if (where(particle_position[i])) particle_thickness_[i] = d, ++count;
    for (std::size_t p = 0; p < stress_point_position.size(); ++p)
      if (where(stress_point_position[p])) stress_point_thickness_[p] = d, ++count;
    if (count == 0)
      detail::invalid_parameter("set_thickness region", d, "holds no particle and no stress point");
    return count;
  }
  // The wall thickness of one particle or one stress point (m), e.g. from a
  // mesh file's shell sections; the mid-surface stays where it is.
  void set_particle_thickness(std::size_t i, double d) {
    check_index("particle", i, particle_count());
    require_thin("particle " + std::to_string(i) + " thickness", d, extent());
    particle_thickness_[i] = d;
  }
  void set_stress_point_thickness(std::size_t p, double d) {
    check_index("stress point", p, stress_point_count());
    require_thin("stress point " + std::to_string(p) + " thickness", d, extent());
    stress_point_thickness_[p] = d;
  }
  std::size_t particle_count() const { return particle_position.size(); }
  std::size_t stress_point_count() const { return stress_point_position.size(); }
  // The corners of stress point q's quad, for models built from quads only
  // (empty for a model with triangles or without cells).
  const std::vector<Quad>& quads() const { return quads_; }
  // The corners of stress point q's cell, for models built from cells or quads
  // (empty for the general constructor).
  const std::vector<Cell>& cells() const { return cells_; }

  // Characteristic particle spacing: the smallest distance between a stress
  // point's neighbouring particles is not known without a search, so use the
  // square root of the smallest area per particle around a stress point (the
  // cell size of a sheet): a quad's area, twice a triangle's (a triangulation
  // has about two triangles per node, a quad mesh one quad).
  double minimum_spacing() const {
    double smallest = area_per_particle(0);
    for (std::size_t p = 1; p < stress_point_count(); ++p) smallest = std::min(smallest, area_per_particle(p));
    return std::sqrt(smallest);
  }
  double maximum_spacing() const {
    double largest = area_per_particle(0);
    for (std::size_t p = 1; p < stress_point_count(); ++p) largest = std::max(largest, area_per_particle(p));
    return std::sqrt(largest);
  }

  // Named particle sets, for boundary conditions, loads and probes.
  template <class Predicate>
  // A name in use (a builder's own set such as "boundary" too) is an Error:
  // replacing a set silently would move the conditions and loads that use it.
  const ParticleSet& define_set(const std::string& name, Predicate&& contains) {
    if (has_set(name))
      detail::invalid_parameter("particle set name", name, "a set of that name exists; choose another name");
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
  // A named set from particle indices (e.g. a mesh file's node set). A name in
  // use, an empty set, an index out of range or one listed twice is an Error
  // naming it.
  const ParticleSet& add_set(const std::string& name, ParticleSet members) {
    if (has_set(name)) detail::invalid_parameter("particle set name", name, "a set of that name exists");
    if (members.empty()) detail::invalid_parameter("particle set " + name, "(empty)", "a set needs members");
    std::vector<char> listed(particle_count(), 0);
    for (int member : members) {
      if (member < 0 || static_cast<std::size_t>(member) >= particle_count())
        detail::invalid_parameter("particle set " + name + " member", member,
                                  "must lie in [0, " + std::to_string(particle_count()) + ")");
      if (listed[member]) detail::invalid_parameter("particle set " + name + " member", member, "listed twice");
      listed[member] = 1;
    }
    return sets_[name] = std::move(members);
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

  // Geometry checks (docs/method.md §1; the limits are named so a message can state them).
  // A quad whose area is below this fraction of its longest side squared is degenerate.
  static constexpr double degenerate_area_fraction = 1e-12;
  // A normal closer than this to a cell's plane (cosine of the angle to the
  // cell normal, cos 80°) lies "in the sheet's plane".
  static constexpr double in_plane_cosine = 0.17364817766693033;
  // Particles closer than this fraction of the local spacing √A_i are near-coincident
  // (small enough for cells a thousand times longer than wide).
  static constexpr double coincident_spacing_fraction = 1e-3;
  // The two area sets (particles, stress points) cover the same surface: their
  // sums may differ by at most this fraction.
  static constexpr double area_sum_tolerance = 0.02;
  // One area this many times the median of its set is an outlier: the support
  // radius follows the largest spacing, so it would widen every row.
  static constexpr double area_outlier_ratio = 64.0;
  // Particles whose spread across their main line is below this fraction of
  // their extent lie on one line; a sheet flat to this fraction is planar.
  static constexpr double collinear_fraction = 1e-6;
  static constexpr double planar_fraction = 1e-9;

  static void check_finite(const char* what, const char* quantity, const std::vector<Vector3>& values) {
    for (std::size_t i = 0; i < values.size(); ++i)
      if (!values[i].allFinite())
        detail::invalid_parameter(std::string(what) + " " + std::to_string(i) + " " + quantity,
                                  values[i].transpose(), "must be finite");
  }
  static std::string corners_text(const Quad& quad) {
    return "{" + std::to_string(quad[0]) + ", " + std::to_string(quad[1]) + ", " + std::to_string(quad[2]) + ", " +
           std::to_string(quad[3]) + "}";
  }
  // Every quad by index: corners in range and distinct, not degenerate, not
  // self-intersecting, and counter-clockwise seen from its corners' normals.
  static void check_quads(const std::vector<Vector3>& positions, const std::vector<Vector3>& normals,
                          const std::vector<Quad>& quads) {
    if (quads.empty()) detail::invalid_parameter("quad count", 0, "a shell needs quads");
    check_finite("particle", "position", positions);
    check_finite("particle", "normal", normals);
    for (std::size_t q = 0; q < quads.size(); ++q) {
      const Quad& quad = quads[q];
      const auto quad_name = [q] { return "quad " + std::to_string(q); };
      for (std::size_t k = 0; k < 4; ++k) {
        if (quad[k] < 0 || static_cast<std::size_t>(quad[k]) >= positions.size())
          detail::invalid_parameter(quad_name() + " corner " + std::to_string(k), quad[k],
                                    "must lie in [0, " + std::to_string(positions.size()) + ")");
        for (std::size_t l = 0; l < k; ++l)
          if (quad[l] == quad[k])
            detail::invalid_parameter(quad_name() + " corners", corners_text(quad),
                                      "particle " + std::to_string(quad[k]) +
                                          " is listed twice: four distinct corners (a degenerate quad)");
      }
      const Vector3 doubled_area = (positions[quad[2]] - positions[quad[0]]).cross(positions[quad[3]] - positions[quad[1]]);
      double longest_squared = 0.0;
      for (std::size_t k = 0; k < 4; ++k)
        longest_squared = std::max(longest_squared, (positions[quad[(k + 1) % 4]] - positions[quad[k]]).squaredNorm());
      // The largest corner triangle: zero only when all four corners lie on one line.
      Vector3 largest_corner = Vector3::Zero();
      for (std::size_t k = 0; k < 4; ++k) {
        const Vector3& here = positions[quad[k]];
        const Vector3 corner = (positions[quad[(k + 1) % 4]] - here).cross(positions[quad[(k + 3) % 4]] - here);
        if (corner.norm() > largest_corner.norm()) largest_corner = corner;
      }
      const double area = 0.5 * doubled_area.norm();
      if (!(0.5 * largest_corner.norm() > degenerate_area_fraction * longest_squared))
        detail::invalid_parameter(quad_name() + " area", area,
                                  "must be > 0: corners " + corners_text(quad) +
                                      " are collinear or coincident (a degenerate quad)");
      // A bow-tie's diagonals may have a zero cross product: then its largest corner gives the axis.
      const bool diagonals_span = area > degenerate_area_fraction * longest_squared;
      const Vector3 axis = diagonals_span ? doubled_area.normalized() : largest_corner.normalized();
      // Turning direction at each corner about the quad's own normal: a simple
      // quad turns one way at three or four corners, a bow-tie at two only.
      int reversed_turns = 0;
      for (std::size_t k = 0; k < 4; ++k) {
        const Vector3& here = positions[quad[k]];
        const Vector3 next = positions[quad[(k + 1) % 4]] - here, previous = positions[quad[(k + 3) % 4]] - here;
        if (next.cross(previous).dot(axis) < 0.0) ++reversed_turns;
      }
      if (reversed_turns >= 2 || !diagonals_span)
        detail::invalid_parameter(quad_name() + " corners", corners_text(quad),
                                  "its edges cross (a bow-tie quad): list the corners in order around the quad");
      int against = 0;
      for (int corner : quad)
        if (normals[corner].dot(axis) < 0.0) ++against;
      if (against == 4)
        detail::invalid_parameter(quad_name() + " corners", corners_text(quad),
                                  "run clockwise seen from the side the normals point to (an inverted quad): list "
                                  "them counter-clockwise");
      for (int corner : quad) {
        const double length = normals[corner].norm();
        const double cosine = length > 0.0 ? normals[corner].dot(axis) / length : 0.0;
        if (cosine < 0.0)
          detail::invalid_parameter("particle " + std::to_string(corner) + " normal", normals[corner].transpose(),
                                    "points against " + quad_name() + " (corners " + corners_text(quad) +
                                        ") while its other corners' normals agree with it: neighbouring normals "
                                        "must share one orientation");
        if (length > 0.0 && cosine < in_plane_cosine)
          detail::invalid_parameter("particle " + std::to_string(corner) + " normal", normals[corner].transpose(),
                                    "lies (within 10°) in the plane of " + quad_name() +
                                        ": a normal must point out of the sheet");
      }
    }
  }
  // The bounding-box diagonal of the particles: a shell's thickness lies below it.
  double extent() const {
    Vector3 lower = particle_position.front(), upper = lower;
    for (const Vector3& x : particle_position) lower = lower.cwiseMin(x), upper = upper.cwiseMax(x);
    return (upper - lower).norm();
  }
  static void require_thin(const std::string& name, double d, double extent) {
    detail::require_positive(name, d);
    if (!(d < extent))
      detail::invalid_parameter(name, d,
                                "must be below the shell's extent " + std::to_string(extent) +
                                    " m (the diagonal of its particles' bounding box): a shell is thin");
  }
  static double median(std::vector<double> values) {
    const auto middle = values.begin() + static_cast<std::ptrdiff_t>(values.size() / 2);
    std::nth_element(values.begin(), middle, values.end());
    return *middle;
  }
  static void check_outliers(const std::vector<double>& areas, const std::string& what) {
    const double typical = median(areas);
    for (std::size_t i = 0; i < areas.size(); ++i)
      if (areas[i] > area_outlier_ratio * typical)
        detail::invalid_parameter(what + " " + std::to_string(i) + " area", areas[i],
                                  "is " + std::to_string(areas[i] / typical) + " times the median " +
                                      std::to_string(typical) + " m²; at most " + std::to_string(area_outlier_ratio) +
                                      " times: the support radius follows the largest spacing, so one large area "
                                      "widens every row");
  }
  // The sheet spans a surface: not one line; a flat sheet's normals point out of its plane.
  void check_spans_a_surface() const {
    Vector3 mean = Vector3::Zero();
    for (const Vector3& x : particle_position) mean += x;
    mean /= static_cast<double>(particle_position.size());
    Matrix3 scatter = Matrix3::Zero();
    for (const Vector3& x : particle_position) scatter += (x - mean) * (x - mean).transpose();
    const Eigen::SelfAdjointEigenSolver<Matrix3> principal(scatter);
    const Vector3 spread = principal.eigenvalues().cwiseMax(0.0).cwiseSqrt();  // ascending
    if (!(spread[1] > collinear_fraction * spread[2]))
      detail::invalid_parameter("particle positions", "(all on one line)",
                                "a shell needs particles spanning a surface, at least 3 not on one line");
    if (spread[0] > planar_fraction * spread[2]) return;
    const Vector3 plane_normal = principal.eigenvectors().col(0);
    auto check = [&](const std::vector<Vector3>& normals, const std::string& what) {
      for (std::size_t i = 0; i < normals.size(); ++i)
        if (std::abs(normals[i].dot(plane_normal)) < in_plane_cosine)
          detail::invalid_parameter(what + " " + std::to_string(i) + " normal", normals[i].transpose(),
                                    "lies (within 10°) in the plane of the flat sheet: a normal must point out of "
                                    "the sheet");
    };
    check(particle_normal, "particle");
    check(stress_point_normal, "stress point");
  }
  // Each particle's normal agrees in orientation with its nearest stress point's.
  void check_orientation() const {
    // The nearest stress point of a grid lies within 0.71 spacings; a particle
    // with none within one spacing is not checked.
    const double reach = std::sqrt(*std::max_element(stress_point_area.begin(), stress_point_area.end()));
    const approx::CellList stress_points(stress_point_position, reach);
    for (std::size_t i = 0; i < particle_count(); ++i) {
      int nearest_point = -1;
      double nearest_distance = std::numeric_limits<double>::infinity();
      stress_points.for_each_within(particle_position[i], reach, [&](int p, double distance_squared) {
        if (distance_squared < nearest_distance) nearest_distance = distance_squared, nearest_point = p;
      });
      if (nearest_point >= 0 && particle_normal[i].dot(stress_point_normal[nearest_point]) < 0.0)
        detail::invalid_parameter("particle " + std::to_string(i) + " normal", particle_normal[i].transpose(),
                                  "points against the normal (" +
                                      vector_text(stress_point_normal[nearest_point]) + ") of the nearest stress point " +
                                      std::to_string(nearest_point) +
                                      ": neighbouring normals must share one orientation");
    }
  }
  static std::string vector_text(const Vector3& v) {
    std::ostringstream text;
    text << v.transpose();
    return text.str();
  }
  // No two particles closer than coincident_spacing_fraction × √A_i.
  void check_separation() const {
    // Cells about one spacing wide: a few particles each (cells as narrow as
    // the tolerance would be mostly empty and slow to search).
    double reach = 0.0;
    for (double area : particle_area) reach = std::max(reach, std::sqrt(area));
    const approx::CellList particles(particle_position, reach);
    for (std::size_t i = 0; i < particle_count(); ++i) {
      const double limit = coincident_spacing_fraction * std::sqrt(particle_area[i]);
      particles.for_each_within(particle_position[i], limit, [&](int j, double distance_squared) {
        if (static_cast<std::size_t>(j) <= i) return;
        detail::invalid_parameter(
            "distance between particles " + std::to_string(i) + " and " + std::to_string(j),
            std::sqrt(distance_squared),
            "must be at least " + std::to_string(coincident_spacing_fraction) + " of the local spacing √A = " +
                std::to_string(std::sqrt(particle_area[i])) + " m: near-coincident particles (merge them)");
      });
    }
  }
  void check_area_sums() const {
    double particles = 0.0, stress_points = 0.0;
    for (double area : particle_area) particles += area;
    for (double area : stress_point_area) stress_points += area;
    if (std::abs(particles - stress_points) > area_sum_tolerance * std::max(particles, stress_points))
      detail::invalid_parameter("sum of the particle areas", particles,
                                "must equal the sum of the stress point areas " + std::to_string(stress_points) +
                                    " m² within " + std::to_string(100.0 * area_sum_tolerance) +
                                    " %: each set of areas covers the mid-surface once");
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
  static void check_cell(const Cell& cell, std::size_t index, std::size_t particle_count) {
    const std::string name = "cell " + std::to_string(index) + " corner index";
    for (std::size_t k = 0; k < cell.size(); ++k) {
      if (cell[k] < 0 || static_cast<std::size_t>(cell[k]) >= particle_count)
        detail::invalid_parameter(name, cell[k], "must lie in [0, " + std::to_string(particle_count) + ")");
      for (std::size_t l = 0; l < k; ++l)
        if (cell[l] == cell[k]) detail::invalid_parameter(name, cell[k], "listed twice (a degenerate cell)");
    }
  }
  static void check_index(const char* what, std::size_t index, std::size_t count) {
    if (index >= count)
      detail::invalid_parameter(std::string(what) + " index", index,
                                "must be below the count (" + std::to_string(count) + ")");
  }
  double area_per_particle(std::size_t p) const {
    const bool triangle = !cells_.empty() && cells_[p].is_triangle();
    return triangle ? 2.0 * stress_point_area[p] : stress_point_area[p];
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
    // Particle and stress point numbers are int (sets, quads, neighbour lists).
    constexpr auto largest_index = static_cast<std::size_t>(std::numeric_limits<int>::max());
    if (n > largest_index || m > largest_index)
      detail::invalid_parameter("particle and stress point counts", std::to_string(n) + " and " + std::to_string(m),
                                "must be at most 2^31 - 1 each (the library's indices are int)");
    if (n < 3)
      detail::invalid_parameter("particle count", n, "a shell needs at least 3 particles, not on one line");
    normalize_all(particle_position, particle_normal, particle_area, "particle");
    normalize_all(stress_point_position, stress_point_normal, stress_point_area, "stress point");
    check_spans_a_surface();
    require_thin("thickness", thickness_, extent());
    check_outliers(stress_point_area, "stress point");
    check_outliers(particle_area, "particle");
    check_area_sums();
    check_orientation();
    check_separation();
  }
  static void normalize_all(const std::vector<Vector3>& positions, std::vector<Vector3>& normals,
                            const std::vector<double>& areas, const std::string& what) {
    // The names are formed only for an error: a model of millions of
    // particles would otherwise spend seconds building strings.
    auto name = [&](std::size_t i, const char* quantity) { return what + " " + std::to_string(i) + " " + quantity; };
    for (std::size_t i = 0; i < positions.size(); ++i) {
      if (!positions[i].allFinite())
        detail::invalid_parameter(name(i, "position"), positions[i].transpose(), "must be finite");
      const double length = normals[i].norm();
      if (!(length > 0.0) || !std::isfinite(length))
        detail::invalid_parameter(name(i, "normal length"), length, "must be finite and non-zero");
      normals[i] /= length;
      if (!(areas[i] > 0.0) || !std::isfinite(areas[i])) detail::require_positive(name(i, "area"), areas[i]);
    }
  }

  double thickness_;
  std::vector<double> particle_thickness_;
  std::vector<double> stress_point_thickness_;
  std::vector<Quad> quads_;
  std::vector<Cell> cells_;
  std::map<std::string, ParticleSet> sets_;
};

}  // namespace sphshell
