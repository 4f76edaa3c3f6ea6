#pragma once
// The shell's geometry in the reference configuration: particles on the
// mid-surface and the stress points staggered between them (docs/method.md §1),
// in structure-of-arrays storage, with builders for the usual shapes.

#include <sphshell/approx/neighbour_search.hpp>
#include <sphshell/core/error.hpp>
#include <sphshell/core/frame.hpp>
#include <sphshell/core/types.hpp>
#include <sphshell/shell/cell.hpp>
#include <sphshell/shell/cuts.hpp>
#include <sphshell/shell/model_checks.hpp>

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
  // Cells (stress point indices, ascending) whose corner order the builder
  // reversed to agree with their neighbours: from_quads turns a quad that
  // runs clockwise about its own corners' normals when its neighbours across
  // shared edges run the other way; the mesh readers turn elements listed
  // the other way round from most of their part (io/mesh_data.hpp). Empty
  // when none was turned.
  std::vector<int> turned_cells;

  // General constructor: the user's own particles and stress points. Areas are
  // integration weights (m²); the two sets of areas should each cover the
  // mid-surface once.
  ShellModel(std::vector<Vector3> positions, std::vector<Vector3> normals,
             std::vector<double> areas, std::vector<Vector3> stress_positions,
             std::vector<Vector3> stress_normals, std::vector<double> stress_areas,
             double thickness)
      : ShellModel(std::move(positions), std::move(normals), std::move(areas), std::move(stress_positions),
                   std::move(stress_normals), std::move(stress_areas), thickness, {}) {}

  // Particles at the nodes of user quads, stress points at the quad centres
  // (positions and normals averaged), areas from the quads: each quad's area goes
  // to its stress point and a quarter of it to each of its four particles. A
  // quad listed clockwise about its corners' normals whose neighbours across
  // shared edges run the other way is turned (turned_cells lists it).
  static ShellModel from_quads(std::vector<Vector3> positions, std::vector<Vector3> normals,
                               const std::vector<Quad>& quads, double thickness) {
    const double estimate = detail::model_checks::require_model_memory(
        "ShellModel::from_quads", static_cast<double>(positions.size()), static_cast<double>(quads.size()));
    return detail::model_checks::guard_building("ShellModel::from_quads", estimate, [&] {
      detail::model_checks::check_sizes(positions, normals);
      std::vector<int> turned;  // the overload below turns them again and keeps the note
      detail::model_checks::check_quads(positions, normals, oriented_quads(positions, normals, quads, turned));
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
    });
  }

  // As above with the stress points' positions and normals given (builders of
  // curved shells put them on the exact surface).
  static ShellModel from_quads(std::vector<Vector3> positions, std::vector<Vector3> normals,
                               const std::vector<Quad>& given_quads,
                               std::vector<Vector3> stress_positions,
                               std::vector<Vector3> stress_normals, double thickness) {
    const double estimate = detail::model_checks::require_model_memory(
        "ShellModel::from_quads", static_cast<double>(positions.size()), static_cast<double>(given_quads.size()));
    return detail::model_checks::guard_building("ShellModel::from_quads", estimate, [&] {
      detail::model_checks::check_sizes(positions, normals);
      std::vector<int> turned;
      const std::vector<Quad> quads = oriented_quads(positions, normals, given_quads, turned);
      detail::model_checks::check_quads(positions, normals, quads);
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
      std::vector<Cell> cells(quads.begin(), quads.end());
      ShellModel model(std::move(positions), std::move(normals), std::move(areas),
                       std::move(stress_positions), std::move(stress_normals),
                       std::move(stress_areas), thickness, std::move(cells));
      model.quads_ = quads;
      model.turned_cells = std::move(turned);
      return model;
    });
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
    const double estimate = detail::model_checks::require_model_memory(
        "ShellModel::from_cells", static_cast<double>(positions.size()), static_cast<double>(cells.size()));
    return detail::model_checks::guard_building("ShellModel::from_cells", estimate, [&] {
      if (cells.empty()) detail::invalid_parameter("cell count", 0, "a shell needs cells");
      detail::model_checks::check_finite("particle", "position", positions);
      for (std::size_t c = 0; c < cells.size(); ++c) detail::model_checks::check_cell(cells[c], c, positions.size());
      if (const std::optional<CellEdgeProblem> problem = detail::model_checks::find_cell_edge_problem(cells))
        detail::invalid_parameter(
            "cells", std::to_string(problem->first_cell) + " and " + std::to_string(problem->second_cell),
            detail::model_checks::describe_edge_problem(*problem, "particles"));
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
                       std::move(cell_normals), std::move(cell_areas), thickness, cells);
      if (std::none_of(cells.begin(), cells.end(), [](const Cell& cell) { return cell.is_triangle(); }))
        for (const Cell& cell : cells) model.quads_.push_back({cell[0], cell[1], cell[2], cell[3]});
      return model;
    });
  }

  // The first orientation flip or junction among cells in the order given, or
  // none (shell/model_checks.hpp); the mesh readers name it by element.
  static std::optional<CellEdgeProblem> find_cell_edge_problem(const std::vector<Cell>& cells) {
    return detail::model_checks::find_cell_edge_problem(cells);
  }

  // Flat rectangular plate in the xy-plane, corner at the origin, normals +z:
  // nx × ny particles, (nx−1)(ny−1) stress points at the cell centres (51×51
  // particles give the paper's 2500 stress points). Named sets: "x_min", "x_max",
  // "y_min", "y_max" (edges), "boundary", "centre" (the particle nearest the centre).
  static ShellModel rectangular_plate(double length_x, double length_y, int nx, int ny,
                                      double thickness);

  // Cylindrical panel about the z-axis: radius, axial length (z from 0), opening
  // angle (radians, from the x-axis; 2π makes a closed tube without a seam),
  // n_circumferential × n_axial particles, normals pointing outward. Named sets:
  // "z_min", "z_max" (the ends), and for an open panel "theta_min", "theta_max".
  static ShellModel cylindrical_panel(double radius, double length, double angle,
                                      int n_circumferential, int n_axial, double thickness);

  // Spherical cap of a sphere of the given radius centred on the z-axis, apex at
  // (0, 0, radius), opening half-angle (radians). A square grid of n × n
  // particles is mapped onto the disc (the elliptical grid map u√(1−v²/2),
  // v√(1−u²/2)) and then onto the sphere by polar angle ∝ disc radius: no pole
  // singularity, but the cells near the four rim corners are distorted (interior
  // angles up to ≈ 175°, areas up to ≈ 6× the smallest at n = 21).
  // Normals point outward. Named sets: "boundary" (the rim), "apex".
  static ShellModel spherical_cap(double radius, double half_angle, int n, double thickness);

  // The thickness the model was built with; set_thickness can change it in regions.
  double thickness() const { return thickness_; }
  // Wall thickness at a particle and at a stress point (m).
  double particle_thickness(std::size_t i) const {
    detail::model_checks::check_index("particle", i, particle_count());
    return particle_thickness_[i];
  }
  // Every particle's wall thickness, indexed as the particles (m).
  const std::vector<double>& particle_thicknesses() const { return particle_thickness_; }
  double stress_point_thickness(std::size_t p) const {
    detail::model_checks::check_index("stress point", p, stress_point_count());
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
    detail::model_checks::require_thin("thickness", d, extent());
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
    detail::model_checks::check_index("particle", i, particle_count());
    detail::model_checks::require_thin("particle " + std::to_string(i) + " thickness", d, extent());
    particle_thickness_[i] = d;
  }
  void set_stress_point_thickness(std::size_t p, double d) {
    detail::model_checks::check_index("stress point", p, stress_point_count());
    detail::model_checks::require_thin("stress point " + std::to_string(p) + " thickness", d, extent());
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
  // The spacing of stress point p's own cell, √(area per particle) as above;
  // the solver's local support radius starts from it (shell/local_spacing.hpp).
  double stress_point_spacing(std::size_t p) const {
    detail::model_checks::check_index("stress point", p, stress_point_count());
    return std::sqrt(area_per_particle(p));
  }

  // Cuts (shell/cuts.hpp, docs/method.md §6): a polyline on the mid-surface
  // (reference coordinates) along which the shell is separated from the start,
  // with any crack policy: particle pairs whose connecting segment crosses it
  // do not interact. Use it for two edges of the model that touch without
  // being joined: a slit (duplicated particles along it, one copy per face,
  // e.g. from_quads with a slit), a cut-out, a seam left open. A polyline of
  // fewer than 2 points or with a zero-length piece, a point off the shell, a
  // cut through a stress point, through a particle that is neither duplicated
  // nor at its end, or across a cell is an Error naming it. A cut that ends on
  // an edge should go on half a spacing past it: near a concave edge a pair
  // can otherwise see around its end through the hole.
  void add_cut(std::vector<Vector3> polyline) {
    shell::check_cut(polyline, cuts_.size(), cut_geometry());
    cuts_.push_back(std::move(polyline));
  }
  const std::vector<std::vector<Vector3>>& cuts() const { return cuts_; }
  // Near-coincident particles that share no cell (i < j): the faces of a slit,
  // which a solver refuses unless a cut separates them.
  const std::vector<std::pair<int, int>>& coincident_particles() const { return coincident_particles_; }
  // What the cut checks and the solver's cut visibility read.
  shell::CutGeometry cut_geometry() const {
    return {particle_position, particle_normal, stress_point_position, stress_point_normal,
            cells_,            coincident_particles_, maximum_spacing()};
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
    return nearest(particle_position, point, "nearest_particle");
  }
  int nearest_stress_point(const Vector3& point) const {
    return nearest(stress_point_position, point, "nearest_stress_point");
  }

 private:
  static constexpr double kPi = 3.14159265358979323846;

  // The quads with those turned that run clockwise about all four of their
  // corners' normals (an inverted quad) while propagation across shared edges
  // from their neighbours turns them too (shell/model_checks.hpp
  // orient_cells); `turned` gets their indices. Quads that agree with their
  // normals are never touched, and without an inverted quad nothing is
  // searched. A quad inverted with all its neighbours stays, for check_quads
  // to refuse.
  static std::vector<Quad> oriented_quads(const std::vector<Vector3>& positions, const std::vector<Vector3>& normals,
                                          const std::vector<Quad>& quads, std::vector<int>& turned) {
    const auto inverted = [&](const Quad& quad) {
      for (int corner : quad)
        if (corner < 0 || static_cast<std::size_t>(corner) >= positions.size()) return false;  // check_quads names it
      const Vector3 axis = (positions[quad[2]] - positions[quad[0]]).cross(positions[quad[3]] - positions[quad[1]]);
      for (int corner : quad)
        if (!(normals[corner].dot(axis) < 0.0)) return false;
      return true;
    };
    if (std::none_of(quads.begin(), quads.end(), inverted)) return quads;
    for (const Quad& quad : quads)
      for (std::size_t k = 0; k < 4; ++k)
        for (std::size_t l = 0; l < k; ++l)
          if (quad[k] == quad[l] || quad[k] < 0 || static_cast<std::size_t>(quad[k]) >= positions.size())
            return quads;  // invalid corners: check_quads names them
    const std::vector<Cell> cells(quads.begin(), quads.end());
    const detail::model_checks::Orientation orientation = detail::model_checks::orient_cells(cells);
    std::vector<Quad> result = quads;
    for (int q : orientation.turned)
      if (inverted(quads[q])) {
        result[q] = {quads[q][0], quads[q][3], quads[q][2], quads[q][1]};
        turned.push_back(q);
      }
    return result;
  }

  // The constructors' common path; `cells` are the model's cells (empty for
  // the general constructor), known before the checks so that coincident
  // particles of a slit (sharing no cell) can be told from a mistake.
  ShellModel(std::vector<Vector3> positions, std::vector<Vector3> normals, std::vector<double> areas,
             std::vector<Vector3> stress_positions, std::vector<Vector3> stress_normals,
             std::vector<double> stress_areas, double thickness, std::vector<Cell> cells)
      : particle_position(std::move(positions)),
        particle_normal(std::move(normals)),
        particle_area(std::move(areas)),
        stress_point_position(std::move(stress_positions)),
        stress_point_normal(std::move(stress_normals)),
        stress_point_area(std::move(stress_areas)),
        thickness_(thickness),
        cells_(std::move(cells)) {
    validate();
    particle_thickness_.assign(particle_position.size(), thickness_);
    stress_point_thickness_.assign(stress_point_position.size(), thickness_);
  }

  // Particles at the nodes of an nu × nv parametric grid on [0,1]², stress points
  // at the cell centres; `periodic_u` closes the grid in u (a full tube).
  template <class Surface>
  static ShellModel structured(int nu, int nv, bool periodic_u, Surface&& surface, double thickness);

  // The bounding-box diagonal of the particles: a shell's thickness lies below it.
  double extent() const { return detail::model_checks::extent(particle_position); }
  double area_per_particle(std::size_t p) const {
    const bool triangle = !cells_.empty() && cells_[p].is_triangle();
    return triangle ? 2.0 * stress_point_area[p] : stress_point_area[p];
  }
  // A NaN coordinate would make every distance NaN and silently pick index 0.
  static int nearest(const std::vector<Vector3>& points, const Vector3& point, const char* caller) {
    if (!point.allFinite())
      detail::invalid_parameter(std::string(caller) + " point", point.transpose(), "must be finite");
    if (points.empty()) detail::invalid_parameter(std::string(caller) + ": the model's point count", 0, "is zero");
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
    detail::model_checks::check_spans_a_surface(particle_position, particle_normal, stress_point_normal);
    detail::model_checks::require_thin("thickness", thickness_, extent());
    detail::model_checks::check_area_sums(particle_area, stress_point_area);
    detail::model_checks::check_orientation(particle_position, particle_normal, stress_point_position,
                                            stress_point_normal, particle_area);
    coincident_particles_ = detail::model_checks::check_separation(particle_position, particle_area, cells_);
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
  std::vector<std::pair<int, int>> coincident_particles_;
  std::vector<std::vector<Vector3>> cuts_;
  std::map<std::string, ParticleSet> sets_;
};

}  // namespace sphshell

#include <sphshell/shell/model_builders.hpp>
