#pragma once
// Geometric cuts (docs/method.md §6, "Cuts"): polylines on the mid-surface
// along which the shell is separated from the start, whatever the crack
// policy (crack::None too). Particles find their neighbours by distance, so
// two edges of a model that touch without being joined (the faces of a slit,
// the rim of a cut-out) would be glued; a cut hides every pair whose
// connecting segment crosses it, with the same exact segment test as cracks
// (crack/segment_intersection.hpp), at the shape-function build and in every
// crack rebuild.
//
// The rules, checked when a cut is added (ShellModel::add_cut):
//   - a polyline of at least two points, each on the shell (within one spacing
//     of a particle and near its tangent plane), no piece of zero length;
//   - it passes through no stress point (the point would sit on both faces);
//   - it passes through a particle only where the particle is duplicated (a
//     coincident copy on the other face, as from_quads with a slit) or at one
//     of its two ends (a slit's tip, joined to both faces);
//   - in a model with cells it crosses no cell: it never separates a cell's
//     stress point from one of the cell's corners (a cell's area and its
//     edge-tied shear cannot be split), so it runs along cell edges.
// Coincident particles that share no cell are the two faces of a slit: a
// solver refuses them unless a cut separates them (CutVisibility).
//
// A particle on a cut lies on its line, where the segment test sees it from
// both faces; its copy of each face is told apart by a side point, moved a
// tiny fraction of the way towards the centres of its own cells.

#include <sphshell/approx/neighbour_search.hpp>
#include <sphshell/core/error.hpp>
#include <sphshell/core/frame.hpp>
#include <sphshell/core/types.hpp>
#include <sphshell/crack/line_segments.hpp>
#include <sphshell/crack/segment_intersection.hpp>
#include <sphshell/shell/cell.hpp>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>
#include <optional>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

namespace sphshell::shell {

// A point closer than this fraction of the spacing to a cut lies on it (as for pre-cracks).
inline constexpr double on_cut_in_spacings = 1e-6;
// Cut pieces shorter than this fraction of the spacing have zero length.
inline constexpr double cut_zero_length_in_spacings = 1e-9;
// A cut point farther than this (in spacings) from the tangent plane of its
// nearest particle is off the surface.
inline constexpr double cut_off_surface_in_spacings = 0.25;
// A duplicated particle's side point: this fraction of the way from the
// particle to the mean centre of its cells (far above round-off, far below
// the spacing).
inline constexpr double side_point_fraction = 1e-3;

// What the cut checks and the visibility read of a model.
struct CutGeometry {
  const std::vector<Vector3>& particle_position;
  const std::vector<Vector3>& particle_normal;
  const std::vector<Vector3>& stress_point_position;
  const std::vector<Vector3>& stress_point_normal;
  const std::vector<Cell>& cells;  // empty for a model without cells
  // Near-coincident particles that share no cell (i < j, sorted): slit faces.
  const std::vector<std::pair<int, int>>& coincident_particles;
  double spacing;
};

namespace cut_detail {

inline std::string number(double value) {
  std::ostringstream text;
  text << value;
  return text.str();
}
inline std::string point_text(const Vector3& point) {
  std::ostringstream text;
  text << "(" << point.transpose() << ")";
  return text.str();
}

// The points of `positions` (indexed by `index`, built with a radius of at
// least `spacing`) within `tolerance` (≤ spacing) of the polyline, ascending.
inline std::vector<int> points_near(const approx::CellList& index, const std::vector<Vector3>& positions,
                                    const std::vector<Vector3>& polyline, double spacing, double tolerance) {
  std::vector<int> found;
  for (std::size_t k = 0; k + 1 < polyline.size(); ++k) {
    const Vector3& start = polyline[k];
    const Vector3& end = polyline[k + 1];
    // Queries of one spacing every half spacing cover the piece and a band of
    // half a spacing around it.
    const int samples = static_cast<int>(std::ceil((end - start).norm() / (0.5 * spacing))) + 1;
    for (int sample = 0; sample < samples; ++sample) {
      const Vector3 centre = start + (end - start) * (double(sample) / double(samples - 1));
      index.for_each_within(centre, spacing, [&](int i, double) {
        if (crack::distance_to_segment(positions[static_cast<std::size_t>(i)], start, end) <= tolerance)
          found.push_back(i);
      });
    }
  }
  std::sort(found.begin(), found.end());
  found.erase(std::unique(found.begin(), found.end()), found.end());
  return found;
}

inline double distance_to_polyline(const Vector3& point, const std::vector<Vector3>& polyline) {
  double distance = std::numeric_limits<double>::infinity();
  for (std::size_t k = 0; k + 1 < polyline.size(); ++k)
    distance = std::min(distance, crack::distance_to_segment(point, polyline[k], polyline[k + 1]));
  return distance;
}

inline Vector3 cell_centre(const Cell& cell, const std::vector<Vector3>& positions) {
  Vector3 centre = Vector3::Zero();
  for (int corner : cell) centre += positions[static_cast<std::size_t>(corner)];
  return centre / static_cast<double>(cell.size());
}

}  // namespace cut_detail

// The checks of ShellModel::add_cut; `cut` numbers the cut in messages.
inline void check_cut(const std::vector<Vector3>& polyline, std::size_t cut, const CutGeometry& model) {
  const std::string name = "cut " + std::to_string(cut);
  if (polyline.size() < 2)
    sphshell::detail::invalid_parameter(name + " polyline size", polyline.size(), "a cut needs at least 2 points");
  const double spacing = model.spacing;
  for (std::size_t k = 0; k < polyline.size(); ++k)
    if (!polyline[k].allFinite())
      sphshell::detail::invalid_parameter(name + " point " + std::to_string(k), polyline[k].transpose(),
                                          "must be finite");
  for (std::size_t k = 0; k + 1 < polyline.size(); ++k) {
    const double length = (polyline[k + 1] - polyline[k]).norm();
    if (!(length > cut_zero_length_in_spacings * spacing))
      sphshell::detail::invalid_parameter("length of " + name + " piece " + std::to_string(k) + "-" +
                                              std::to_string(k + 1),
                                          length, "a cut piece must not have zero length");
  }
  // Every point on the shell: near a particle and near its tangent plane.
  const approx::CellList particles(model.particle_position, spacing);
  for (std::size_t k = 0; k < polyline.size(); ++k) {
    int nearest = -1;
    double nearest_squared = 0.0;
    particles.for_each_within(polyline[k], spacing, [&](int i, double distance_squared) {
      if (nearest < 0 || distance_squared < nearest_squared) nearest = i, nearest_squared = distance_squared;
    });
    const std::string point = name + " point " + std::to_string(k);
    if (nearest < 0)
      sphshell::detail::invalid_parameter(point, polyline[k].transpose(),
                                          "lies outside the model: a cut must lie on the shell, within one spacing (" +
                                              cut_detail::number(spacing) + " m) of a particle");
    const auto i = static_cast<std::size_t>(nearest);
    const double off_surface = std::abs((polyline[k] - model.particle_position[i]).dot(model.particle_normal[i]));
    if (off_surface > cut_off_surface_in_spacings * spacing)
      sphshell::detail::invalid_parameter(
          point, polyline[k].transpose(),
          "lies off the shell's surface: " + cut_detail::number(off_surface) +
              " m from the tangent plane of the nearest particle " + std::to_string(nearest) + ", at most " +
              cut_detail::number(cut_off_surface_in_spacings * spacing) + " m allowed");
  }
  const double tolerance = on_cut_in_spacings * spacing;
  // No stress point on it.
  const approx::CellList stress_points(model.stress_point_position, spacing);
  for (int p : cut_detail::points_near(stress_points, model.stress_point_position, polyline, spacing, tolerance))
    sphshell::detail::invalid_parameter(
        name + " distance to stress point " + std::to_string(p),
        cut_detail::distance_to_polyline(model.stress_point_position[static_cast<std::size_t>(p)], polyline),
        "a cut must pass no stress point (closer than " + cut_detail::number(tolerance) +
            " m): the point would sit on both faces; run the cut along cell edges");
  // Particles on it: duplicated ones (a slit's faces) or its ends (tips).
  std::vector<char> duplicated(model.particle_position.size(), 0);
  for (const auto& [i, j] : model.coincident_particles) duplicated[i] = duplicated[j] = 1;
  for (int i : cut_detail::points_near(particles, model.particle_position, polyline, spacing, tolerance)) {
    const Vector3& x = model.particle_position[static_cast<std::size_t>(i)];
    const bool at_end = (x - polyline.front()).norm() <= tolerance || (x - polyline.back()).norm() <= tolerance;
    if (!duplicated[static_cast<std::size_t>(i)] && !at_end)
      sphshell::detail::invalid_parameter(
          name + " distance to particle " + std::to_string(i), cut_detail::distance_to_polyline(x, polyline),
          "a cut passes a particle " + cut_detail::point_text(x) +
              " that joins both faces: a cut runs between duplicated particles (one copy per face, e.g. "
              "from_quads with a slit) and may end at a particle (a tip)");
  }
  if (model.cells.empty()) return;
  // No cell crossed: the cut never separates a cell's stress point from a corner.
  double cell_reach = 0.0;
  for (std::size_t c = 0; c < model.cells.size(); ++c)
    for (int corner : model.cells[c])
      cell_reach = std::max(cell_reach, (model.particle_position[static_cast<std::size_t>(corner)] -
                                         model.stress_point_position[c])
                                            .norm());
  const double reach = std::max(spacing, cell_reach);
  const approx::CellList centres(model.stress_point_position, reach);
  for (int c : cut_detail::points_near(centres, model.stress_point_position, polyline, reach, reach)) {
    const auto cell_index = static_cast<std::size_t>(c);
    const Vector3& centre = model.stress_point_position[cell_index];
    const TangentFrame frame = tangent_frame(model.stress_point_normal[cell_index]);
    for (std::size_t k = 0; k + 1 < polyline.size(); ++k) {
      if (crack::distance_to_segment(centre, polyline[k], polyline[k + 1]) > reach) continue;
      for (int corner : model.cells[cell_index])
        if (crack::pair_is_cut_in_tangent_plane(centre, model.particle_position[static_cast<std::size_t>(corner)],
                                                polyline[k], polyline[k + 1], frame, centre))
          sphshell::detail::invalid_parameter(
              name + " piece " + std::to_string(k) + "-" + std::to_string(k + 1),
              cut_detail::point_text(polyline[k]) + " to " + cut_detail::point_text(polyline[k + 1]),
              "crosses cell " + std::to_string(c) + " (it separates the cell's stress point from its corner particle " +
                  std::to_string(corner) +
                  "): a cell's area and edge-tied shear cannot be split, so a cut runs along cell edges, between "
                  "duplicated particles");
    }
  }
}

// Which particle pairs the cuts hide, for the approximation's visibility
// predicate. Pairs are judged as cracks judge them (crack::LineSegments::visible):
// in the tangent plane at the evaluation point, against the cut pieces within
// max(support radius, pair length) of it. A particle with a coincident copy
// is represented by its side point.
class CutVisibility {
 public:
  CutVisibility() = default;

  // Also checks that every pair of coincident particles sharing no cell is
  // separated by a cut (the Error names the pair).
  CutVisibility(const CutGeometry& model, const std::vector<std::vector<Vector3>>& cuts, double support_radius)
      : support_radius_(support_radius) {
    for (const std::vector<Vector3>& polyline : cuts)
      for (std::size_t k = 0; k + 1 < polyline.size(); ++k) {
        pieces_.push_back({polyline[k], polyline[k + 1]});
        longest_piece_ = std::max(longest_piece_, (polyline[k + 1] - polyline[k]).norm());
      }
    if (!pieces_.empty()) {
      side_point_ = model.particle_position;
      std::vector<Vector3> centre_sum(side_point_.size(), Vector3::Zero());
      std::vector<int> cell_count(side_point_.size(), 0);
      for (const Cell& cell : model.cells) {
        const Vector3 centre = cut_detail::cell_centre(cell, model.particle_position);
        for (int corner : cell) centre_sum[corner] += centre, ++cell_count[corner];
      }
      for (const auto& [i, j] : model.coincident_particles)
        for (int particle : {i, j}) {
          const auto slot = static_cast<std::size_t>(particle);
          if (cell_count[slot] == 0) continue;
          const Vector3 towards = centre_sum[slot] / static_cast<double>(cell_count[slot]);
          side_point_[slot] += side_point_fraction * (towards - side_point_[slot]);
        }
      std::vector<Vector3> midpoints;
      for (const Piece& piece : pieces_) midpoints.push_back(0.5 * (piece.start + piece.end));
      index_.emplace(midpoints, crack::LineSegments::cell_margin * (support_radius_ + 0.5 * longest_piece_));
    }
    for (const auto& [i, j] : model.coincident_particles) {
      const auto first = static_cast<std::size_t>(i), second = static_cast<std::size_t>(j);
      if (pieces_.empty() ||
          visible(side_point_[first], side_point_[second], tangent_frame(model.particle_normal[first])))
        sphshell::detail::invalid_parameter(
            "particles " + std::to_string(i) + " and " + std::to_string(j),
            cut_detail::point_text(model.particle_position[first]),
            "coincide and share no cell, but no cut separates them: they are the two faces of a slit or cut-out, "
            "which would be glued; declare it with ShellModel::add_cut(polyline along it)");
    }
  }

  bool empty() const { return pieces_.empty(); }
  // Where particle i stands in the cut test (its position unless it has a coincident copy).
  const Vector3& side_point(std::size_t particle) const { return side_point_[particle]; }

  // Whether the pair from a (the evaluation point) to b is not cut, judged in
  // the tangent plane of frame at a.
  bool visible(const Vector3& a, const Vector3& b, const TangentFrame& frame) const {
    if (pieces_.empty()) return true;
    const double reach = std::max(support_radius_, (a - b).norm());
    const double query_radius = reach + 0.5 * longest_piece_;
    auto cuts = [&](const Piece& piece) {
      return crack::distance_to_segment(a, piece.start, piece.end) <= reach &&
             crack::pair_is_cut_in_tangent_plane(a, b, piece.start, piece.end, frame, a);
    };
    if (query_radius > index_->radius()) {
      for (const Piece& piece : pieces_)
        if (cuts(piece)) return false;
      return true;
    }
    bool cut = false;
    index_->for_each_within(a, query_radius, [&](int k, double) {
      if (!cut && cuts(pieces_[static_cast<std::size_t>(k)])) cut = true;
    });
    return !cut;
  }

 private:
  struct Piece {
    Vector3 start, end;
  };
  std::vector<Piece> pieces_;
  std::vector<Vector3> side_point_;  // per particle, when there are cuts
  double support_radius_ = 0.0;
  double longest_piece_ = 0.0;
  std::optional<approx::CellList> index_;  // piece midpoints
};

}  // namespace sphshell::shell
