#pragma once
// The edge-tied transverse shear of the stress points
// (TransverseShear::cell_edges, shell/cell_shear.hpp) and the director
// hourglass term of their cells (PhysicsOptions::director_hourglass,
// shell/cell_hourglass.hpp): per stress point of a model with cells, built
// once in the reference configuration beside the integration points
// (solver/integration_points.hpp, whose stress-point rows must hold every
// corner of their cell).

#include <sphshell/approx/approx.hpp>
#include <sphshell/core/error.hpp>
#include <sphshell/core/frame.hpp>
#include <sphshell/shell/cell_hourglass.hpp>
#include <sphshell/shell/cell_shear.hpp>
#include <sphshell/shell/model.hpp>
#include <sphshell/solver/options.hpp>

#include <algorithm>
#include <cstddef>
#include <string>
#include <vector>

namespace sphshell::solver {

class TiedShear {
 public:
  TiedShear() = default;  // no stress point tied

  // Ties every stress point's shear to its cell's edges (a model with cells
  // and TransverseShear::cell_edges; else none is tied). A corner outside the
  // point's row (`shape`, the stress points' shape functions) would leave its
  // forces nowhere to go: the support is too small for the cell, an Error
  // naming the row's support_radius(row). `keep_edges`: a linear analysis,
  // which reads the reference edges.
  template <class SupportRadius>
  TiedShear(const ShellModel& model, const PhysicsOptions& physics, const approx::ShapeFunctions& shape,
            const std::vector<TangentFrame>& frames, SupportRadius&& support_radius, double shear_modulus,
            double poisson_ratio, bool keep_edges) {
    if (physics.director_hourglass) {
      if (physics.transverse_shear != TransverseShear::cell_edges)
        detail::invalid_parameter("director_hourglass", "true", "needs transverse_shear = TransverseShear::cell_edges");
      if (model.cells().empty())
        detail::invalid_parameter("director_hourglass", "true", "needs a model with cells (this one has none)");
      if (!(poisson_ratio > -1.0 && poisson_ratio < 0.5))
        detail::invalid_parameter("poisson_ratio (for director_hourglass)", poisson_ratio, "must lie in (-1, 0.5)");
    }
    if (physics.transverse_shear != TransverseShear::cell_edges || model.cells().empty()) return;
    if (physics.director_hourglass) hourglass_.resize(model.stress_point_count());
    tying_.resize(model.stress_point_count());
    if (keep_edges) edges_.resize(tying_.size());
    // Every corner is in its row (checked below) until a crack hides one.
    corners_visible_.assign(tying_.size(), 1);
    for (std::size_t row = 0; row < tying_.size(); ++row) {
      const Cell& cell = model.cells()[row];
      for (int corner : cell) {
        bool found = false;
        for (std::size_t s = shape.row_begin[row]; s < shape.row_begin[row] + shape.row_size[row]; ++s)
          found = found || shape.neighbour[s] == corner;
        if (!found)
          detail::invalid_parameter("support_radius_factor", physics.support_radius_factor,
                                    "too small: corner particle " + std::to_string(corner) + " of cell " +
                                        std::to_string(row) + " lies outside its stress point's support radius " +
                                        std::to_string(support_radius(row)) + " m");
      }
      const double stiffness = physics.shear_correction * shear_modulus * model.stress_point_thickness(row);
      const shell::CellShearTying tying =
          shell::tie_cell_shear(cell.begin(), static_cast<int>(cell.size()), model.particle_position,
                                model.particle_normal, frames[row], stiffness, model.stress_point_area[row]);
      tying_[row] = tying;
      if (keep_edges) edges_[row] = tying;
      // A triangle's directors have no ξη part: its hourglass term stays zero.
      if (!hourglass_.empty() && cell.size() == std::size_t(shell::hourglass_corners)) {
        const double thickness = model.stress_point_thickness(row);
        // E d³ / (12 (1 − ν²)) with E = 2 G (1 + ν).
        const double bending = shear_modulus * thickness * thickness * thickness / (6.0 * (1.0 - poisson_ratio));
        hourglass_[row] = shell::tie_cell_hourglass(cell.begin(), model.particle_position, model.particle_normal,
                                                    frames[row], bending, poisson_ratio, model.stress_point_area[row]);
      }
    }
  }

  // The rows of a subset (IntegrationPoints::subset), their corners
  // renumbered by local(particle, row).
  template <class Local>
  TiedShear subset(const std::vector<std::size_t>& rows, Local&& local) const {
    TiedShear part;
    if (tying_.empty()) return part;
    for (std::size_t row : rows) {
      part.corners_visible_.push_back(corners_visible_[row]);
      part.tying_.push_back(tying_[row]);
      if (!edges_.empty()) part.edges_.push_back(edges_[row]);
      if (!hourglass_.empty()) part.hourglass_.push_back(hourglass_[row]);
      shell::CellShearTie& tying = part.tying_.back();
      for (int k = 0; k < tying.corners; ++k) tying.particle[k] = local(tying.particle[k], row);
    }
    return part;
  }

  // Whether stress point `row` is tied; its `corners` is 0 for a point whose
  // shear comes from the shape functions.
  bool tied(std::size_t row) const { return !tying_.empty() && tying_[row].corners > 0; }
  const shell::CellShearTie& tying(std::size_t row) const { return tying_[row]; }
  // A tied stress point's director hourglass term (null: none, the option is off).
  const shell::CellHourglass* hourglass(std::size_t row) const {
    return hourglass_.empty() ? nullptr : &hourglass_[row];
  }
  // Its reference edges, which the linear analysis reads (null in a nonlinear
  // one, which keeps none: 192 bytes a stress point).
  const shell::CellShearEdges* edges(std::size_t row) const { return edges_.empty() ? nullptr : &edges_[row]; }
  // Whether every corner of a tied stress point's cell is among its row's
  // used slots (a crack can hide one: the cell's shear is then left out).
  // Kept per row, refreshed wherever a row changes, so the step does not
  // search the row for its corners.
  bool corners_visible(std::size_t row) const { return corners_visible_[row] != 0; }

  // Refreshes corners_visible of a changed row of `shape` (rows are rebuilt
  // in parallel: each sets its own flag, in an array sized once); hide_corners
  // clears it before a rebuild that may throw.
  void check_corners(const approx::ShapeFunctions& shape, std::size_t row) {
    if (!tied(row)) return;
    const shell::CellShearTie& tying = tying_[row];
    const auto used_begin = shape.neighbour.begin() + std::ptrdiff_t(shape.row_begin[row]);
    const auto used_end = used_begin + shape.row_size[row];
    bool visible = true;
    for (int k = 0; k < tying.corners; ++k)
      visible = visible && std::find(used_begin, used_end, tying.particle[std::size_t(k)]) != used_end;
    corners_visible_[row] = visible ? 1 : 0;
  }
  void hide_corners(std::size_t row) {
    if (tied(row)) corners_visible_[row] = 0;
  }

 private:
  std::vector<shell::CellShearTie> tying_;      // per stress point, or empty
  std::vector<shell::CellShearEdges> edges_;    // per stress point with tying_ in a linear analysis
  std::vector<unsigned char> corners_visible_;  // per stress point with tying_
  std::vector<shell::CellHourglass> hourglass_;  // per stress point with tying_ when director_hourglass, or empty
};

}  // namespace sphshell::solver
