#pragma once
// One frame of a solver's ParaView output, drawn from the process's share
// (solver/output.hpp writes it): the shell as its cells
// (ShellModel::cells(): the quads or triangles whose centres are the stress
// points), so ParaView's default Surface view shows a surface:
//   particles       the particles as the corners of the same cells (plus a
//                   vertex cell for a particle none holds), with the
//                   particle data as point data;
//   stress_points   one cell per active stress point over its corner
//                   particles, with the stress-point data as cell data; a
//                   removed stress point has no cell, so a crack is a gap,
//                   and one whose cell a crack cuts (it no longer sees a
//                   corner) is a vertex cell at its own position, so that a
//                   slit between rows of particles shows as a gap too;
//   cracks          the crack segments as lines.
// A model from the general constructor has no cells: its frames are point
// clouds (one vertex cell per particle, and per active stress point).
// Points sit at the deformed or the reference positions
// (OutputOptions::frame_coordinates); every grid says which in its note and
// carries the point array "displacement".

#include <sphshell/core/frame.hpp>
#include <sphshell/core/types.hpp>
#include <sphshell/io/vtu_writer.hpp>
#include <sphshell/solver/integration_points.hpp>
#include <sphshell/solver/options.hpp>
#include <sphshell/solver/output_probes.hpp>
#include <sphshell/solver/particles.hpp>
#include <sphshell/solver/section_states.hpp>

#include <array>
#include <cstddef>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

namespace sphshell::solver {

// The note at the top of a frame file: what it draws, at which time, and where its points sit.
inline std::string frame_note(const std::string& what, double time, bool deformed) {
  std::ostringstream text;
  text.precision(17);
  text << "sphshell frame, t = " << time << " s: " << what << "\n     Points: "
       << (deformed ? "the deformed (current) positions. The point array displacement (current minus reference "
                        "position) is for colouring: Warp By Vector would apply it a second time."
                      : "the reference positions. Warp By Vector with the point array displacement (scale 1) "
                        "shows the deformed shell.");
  return text.str();
}

// The grids of one frame drawn from a solver's share (solver.hpp; the
// Solver's friend): this process's particles and the active stress points
// it owns, serially all of them; a distributed run writes one piece per
// process. The shell is drawn as its cells
// (ShellModel::cells()), corners numbered in the piece's particles (a
// piece's particles are the process's local ones: owned, then ghosts, so a
// cell at the share's edge has its corners), with cracks as gaps (see the
// header comment).
template <class Solver>
class FramePiece {
 public:
  FramePiece(const Solver& solver, FrameCoordinates coordinates)
      : s_(solver), deformed_(coordinates == FrameCoordinates::deformed) {
    const ShellModel& model = s_.model();
    with_cells_ = !model.cells().empty();
    for (const std::size_t row : s_.domain_.owned_stress_rows()) {
      const Drawn point{s_.domain_.global_stress_point(row), row,
                        s_.points_->point(PointGroup::stress_points, row)};
      owned_.push_back(point);
      if (!s_.states_->active(point.point)) continue;
      (with_cells_ && (is_cut(point.stress_point) || !corners_local(point.stress_point)) ? cut_ : drawn_)
          .push_back(point);
    }
    const std::size_t n = s_.domain_.local_count();
    particles_.resize(n);
    displacement_.resize(n);
    for (std::size_t i = 0; i < n; ++i) {
      displacement_[i] = s_.particles_.position[i] - s_.reference_position_[i];
      particles_[i] = deformed_ ? s_.particles_.position[i] : s_.reference_position_[i];
    }
  }

  // The particles with the cells of the drawn stress points over them (a
  // particle it owns that no drawn cell holds is a vertex cell), particle
  // data as point data; distributed, with each point's global_id.
  io::VtuGrid particle_grid() const {
    const std::size_t n = particles_.size();
    io::VtuGrid grid;
    grid.time = s_.time();
    grid.points = particles_;
    std::vector<char> covered(n, 0);
    if (with_cells_) add_drawn_cells(grid.cells, &covered);
    for (std::size_t i = 0; i < s_.domain_.owned_count(); ++i)
      if (!covered[i]) grid.cells.add_vertex(static_cast<int>(i));
    std::vector<Vector3> rotation(n);
    for (std::size_t i = 0; i < n; ++i)
      rotation[i] = rotation_vector(s_.reference_normal_[i], s_.particles_.director[i]);
    grid.point_fields = {vector_field("displacement", displacement_),
                         vector_field("velocity", s_.particles_.velocity), vector_field("rotation", rotation),
                         vector_field("director", s_.particles_.director)};
    if constexpr (Solver::crack_type::enabled) {
      io::PointField fragment{"fragment", 1, {}, {}, io::FieldValues::integer};
      for (std::size_t i = 0; i < n; ++i)
        fragment.values.push_back(s_.fracture_.is_fragment(static_cast<std::size_t>(s_.domain_.global_of(i))) ? 1 : 0);
      grid.point_fields.push_back(fragment);
    }
    if constexpr (Solver::domain_type::is_distributed) {
      io::PointField id{"global_id", 1, {}, {}, io::FieldValues::integer};
      for (std::size_t i = 0; i < n; ++i) id.values.push_back(s_.domain_.global_of(i));
      grid.point_fields.push_back(id);
    }
    grid.note = note(with_cells_ ? "the particles with the cells of the active stress points over them, but for cells "
                                   "a crack cuts (a particle no such cell holds is a vertex cell); particle data as "
                                   "point data."
                                 : "the particles, one vertex cell each (the model has no cells).");
    return grid;
  }

  // Per active stress point: one array per integral-point quantity with a
  // component per thickness output point (named by position, ζ ascending),
  // the resultants, the wall thickness and the stress point's index.
  io::VtuGrid stress_point_grid() const {
    const ShellModel& model = s_.model();
    io::VtuGrid grid;
    grid.time = s_.time();
    // Cell data follow the cells: the drawn stress points, then the cut ones.
    std::vector<Drawn> active = drawn_;
    active.insert(active.end(), cut_.begin(), cut_.end());
    if (with_cells_) {
      grid.points = particles_;
      add_drawn_cells(grid.cells, nullptr);
      std::vector<Vector3> displacement = displacement_;
      for (const Drawn& point : cut_) {
        const Vector3 current = s_.stress_point_position(point.row);
        const Vector3& reference = model.stress_point_position[point.stress_point];
        grid.cells.add_vertex(static_cast<int>(grid.points.size()));
        grid.points.push_back(deformed_ ? current : reference);
        displacement.push_back(current - reference);
      }
      grid.point_fields = {vector_field("displacement", displacement)};
    } else {
      // The stress points it owns, removed ones too; a vertex cell at each active one.
      std::vector<Vector3> displacement;
      for (std::size_t k = 0; k < owned_.size(); ++k) {
        const Vector3 current = s_.stress_point_position(owned_[k].row);
        const Vector3& reference = model.stress_point_position[owned_[k].stress_point];
        grid.points.push_back(deformed_ ? current : reference);
        displacement.push_back(current - reference);
        if (s_.states_->active(owned_[k].point)) grid.cells.add_vertex(static_cast<int>(k));
      }
      grid.point_fields = {vector_field("displacement", displacement)};
    }
    constexpr int output_points = Solver::output_points;
    const std::vector<std::string> names = thickness_point_names<typename Solver::rule_type>();
    for (const IntegralPointQuantityInfo& info : integral_point_quantities) {
      if (info.needs_damage_law && !Solver::material_type::has_damage) continue;
      io::CellField field{info.name, output_points, {}, names};
      field.values.reserve(active.size() * output_points);
      for (const Drawn& point : active)
        for (int k = 0; k < output_points; ++k) field.values.push_back(s_.states_->quantity(info.quantity, point.point, k));
      grid.cell_fields.push_back(std::move(field));
    }
    io::CellField membrane{"membrane_force", 3, {}, {"Nxx", "Nyy", "Nxy"}};
    io::CellField moment{"bending_moment", 3, {}, {"Mxx", "Myy", "Mxy"}};
    io::CellField thickness{"thickness", 1, {}};
    io::CellField index{"stress_point", 1, {}, {}, io::FieldValues::integer};
    for (const Drawn& point : active) {
      for (int c = 0; c < 3; ++c) {
        membrane.values.push_back(s_.states_->membrane_force(point.point)[c]);
        moment.values.push_back(s_.states_->bending_moment(point.point)[c]);
      }
      thickness.values.push_back(model.stress_point_thickness(point.stress_point));
      index.values.push_back(static_cast<int>(point.stress_point));
    }
    grid.cell_fields.push_back(std::move(membrane));
    grid.cell_fields.push_back(std::move(moment));
    grid.cell_fields.push_back(std::move(thickness));
    grid.cell_fields.push_back(std::move(index));
    const std::string heights =
        " Through-thickness points are named by their height zeta along the director as a fraction of the wall "
        "thickness d: bottom (zeta < 0, the side the director points away from) to top (zeta > 0).";
    grid.note = note((with_cells_ ? std::string("one cell per active stress point over its corner particles (the "
                                                "first points are the particles); a removed stress point has no "
                                                "cell, so cracks show as gaps; a stress point whose cell a crack "
                                                "cuts is a vertex cell at its own position (points after the "
                                                "particles), so slits show too; stress-point data as cell data.")
                                  : std::string("the stress points, a vertex cell per active one (the model has no "
                                                "cells); stress-point data as cell data.")) +
                     heights);
    return grid;
  }

  // The crack segments as a line set, whole (collective; a distributed run's
  // process 0 writes it): a damaged stress point's crack point follows the
  // interpolated motion of the stress point, a pre-crack point the
  // displacement of its nearest particle; their owners place them.
  io::VtuGrid crack_grid() const {
    const auto& crack = s_.crack();
    const ShellModel& model = s_.model();
    const std::vector<Vector3>& reference = crack.points();
    std::vector<std::pair<std::size_t, Vector3>> mine;
    std::vector<char> from_stress_point(reference.size(), 0);
    for (std::size_t q = 0; q < model.stress_point_count(); ++q) {
      const int k = crack.crack_point_of_stress_point(static_cast<int>(q));
      if (k >= 0) from_stress_point[static_cast<std::size_t>(k)] = 1;
    }
    for (const Drawn& point : owned_) {
      const int k = crack.crack_point_of_stress_point(static_cast<int>(point.stress_point));
      if (k >= 0) mine.push_back({static_cast<std::size_t>(k), s_.stress_point_position(point.row)});
    }
    for (std::size_t k = 0; k < reference.size(); ++k) {
      if (from_stress_point[k]) continue;
      const int nearest = model.nearest_particle(reference[k]);
      if (!s_.domain_.owns(nearest)) continue;
      const auto i = static_cast<std::size_t>(s_.domain_.local_of(static_cast<std::size_t>(nearest)));
      mine.push_back({k, reference[k] + displacement_[i]});
    }
    const std::vector<Vector3> current = s_.domain_.assembled(reference.size(), mine);
    std::vector<Vector3> displacement(reference.size());
    for (std::size_t k = 0; k < reference.size(); ++k) displacement[k] = current[k] - reference[k];
    io::VtuGrid grid;
    grid.time = s_.time();
    grid.points = deformed_ ? current : reference;
    io::CellField crack_id{"crack_id", 1, {}, {}, io::FieldValues::integer};
    for (const auto& segment : crack.segments()) {
      grid.cells.add_line(segment.start_point, segment.end_point);
      crack_id.values.push_back(segment.crack_id);
    }
    grid.point_fields = {vector_field("displacement", displacement)};
    grid.cell_fields = {crack_id};
    grid.note = note("the crack segments as lines (crack_id per segment).");
    return grid;
  }

 private:
  // A stress point of the piece: its index, its local stress-point row and its local point.
  struct Drawn {
    std::size_t stress_point, row, point;
  };

  std::string note(const std::string& what) const { return frame_note(what, s_.time(), deformed_); }
  static io::PointField vector_field(const std::string& name, const std::vector<Vector3>& values) {
    io::PointField field{name, 3, {}};
    field.values.reserve(3 * values.size());
    for (const Vector3& v : values) field.values.insert(field.values.end(), {v.x(), v.y(), v.z()});
    return field;
  }

  // Whether a crack runs through stress point q's cell: q no longer sees one
  // of its corners (the crack policy's visibility, in the reference
  // configuration, as for the shape functions). Drawn whole, such a cell
  // would bridge the crack, a slit between particle rows would not show.
  bool is_cut(std::size_t q) const {
    if constexpr (Solver::crack_type::enabled) {
      const auto& crack = s_.crack();
      if (crack.segments().empty()) return false;
      const ShellModel& model = s_.model();
      const TangentFrame frame = tangent_frame(model.stress_point_normal[q]);
      for (const int corner : model.cells()[q])
        if (!crack.visible(model.stress_point_position[q], model.particle_position[std::size_t(corner)], frame))
          return true;
    }
    (void)q;
    return false;
  }
  // Whether every corner of q's cell is a particle of the piece (always, serially).
  bool corners_local(std::size_t q) const {
    for (const int corner : s_.model().cells()[q])
      if (s_.domain_.local_of(static_cast<std::size_t>(corner)) < 0) return false;
    return true;
  }
  // The drawn stress points' cells (triangles, quads) over the piece's particles.
  void add_drawn_cells(io::VtuCells& cells, std::vector<char>* covered) const {
    const std::vector<Cell>& model_cells = s_.model().cells();
    for (const Drawn& point : drawn_) {
      const Cell& cell = model_cells[point.stress_point];
      std::array<int, 4> corners{};
      for (std::size_t c = 0; c < cell.size(); ++c)
        corners[c] = static_cast<int>(s_.domain_.local_of(static_cast<std::size_t>(cell[c])));
      const int* end = corners.data() + cell.size();
      cells.add_polygon(corners.data(), end);
      if (covered)
        for (const int* corner = corners.data(); corner != end; ++corner) (*covered)[std::size_t(*corner)] = 1;
    }
  }

  const Solver& s_;
  bool deformed_;
  bool with_cells_ = false;
  std::vector<Drawn> owned_, drawn_, cut_;
  std::vector<Vector3> particles_, displacement_;
};


}  // namespace sphshell::solver
