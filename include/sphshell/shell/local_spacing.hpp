#pragma once
// The local spacing Δ at every evaluation point, from which its smoothing
// length h = support_radius_factor · Δ / kernel support factor follows
// (docs/method.md, "Support radius"), so that one large cell widens its own
// row and not every row of the sheet:
//   stress point q: Δ_q = √(area per particle of its own cell) (the quad's
//     area, twice a triangle's; ShellModel::stress_point_spacing), or its
//     distance to its cell's farthest corner if that is larger. The second
//     term keeps the cell's corners inside the row (the edge-tied shear needs
//     them) on a distorted cell: the corner cells of ShellModel::spherical_cap
//     (an interior angle near 175°) have their corners at 2.02 √A; on a
//     square cell the farthest corner lies at 0.71 √A, on the O-grid cap's
//     cells at most 0.94 √A, so it changes nothing there;
//   particle i of a model with cells: the largest, over the cells it is a
//     corner of, of the cell's √(area per particle) and of its distance to
//     the cell's farthest corner over √2. The second term is the spacing
//     along the cell's long side for cells longer than wide (a 4 × 1 cell's
//     √A is 2, its long side 4: the corner particle's row would hold its
//     neighbours along the short side only, on one line); on a square cell
//     both terms are the side;
//   particle i of a model without cells (the general constructor): the
//     largest √A_j of the particles j with |x_j − x_i| < particle_spacing_reach
//     · √A_j, itself included. Its own area is a half or a quarter of its
//     neighbours' on an edge or at a corner; the neighbours' keeps its row as
//     wide as the inner rows there.
// On cells longer than wide the rows are thin along the long side (first-order
// consistent still); docs/method.md, "Support radius", says what that costs a
// curved shell meshed so and why the long side is not used instead.
// On a uniform sheet every Δ is the sheet's spacing (up to the rounding of
// the cell areas), as the single global spacing was. A particle's Δ comes
// from the particles and cells it touches, never from a stress point's
// integration area, so one stress point standing for a large area widens its
// own row only.

#include <sphshell/approx/neighbour_search.hpp>
#include <sphshell/shell/cell.hpp>
#include <sphshell/shell/model.hpp>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <vector>

namespace sphshell {

// A particle takes the spacing of every particle j whose own spacing √A_j
// reaches it within this many spacings: on a grid the diagonal neighbour lies
// at √2 spacings, so a corner particle (a quarter area) sees the inner one.
inline constexpr double particle_spacing_reach = 1.5;

struct LocalSpacing {
  std::vector<double> stress_point;  // Δ_q, per stress point (m)
  std::vector<double> particle;      // Δ_i, per particle (m)
};

inline LocalSpacing local_spacing(const ShellModel& model) {
  LocalSpacing spacing;
  spacing.stress_point.resize(model.stress_point_count());
  for (std::size_t q = 0; q < spacing.stress_point.size(); ++q) spacing.stress_point[q] = model.stress_point_spacing(q);
  if (!model.cells().empty()) {
    spacing.particle.assign(model.particle_count(), 0.0);
    const double sqrt2 = std::sqrt(2.0);
    for (std::size_t c = 0; c < model.cells().size(); ++c) {
      const Cell& cell = model.cells()[c];
      const double cell_spacing = model.stress_point_spacing(c);
      double corner_reach = 0.0;
      for (int k : cell)
        corner_reach = std::max(
            corner_reach, (model.particle_position[static_cast<std::size_t>(k)] - model.stress_point_position[c]).norm());
      spacing.stress_point[c] = std::max(cell_spacing, corner_reach);
      for (int i : cell) {
        double farthest = 0.0;
        for (int k : cell)
          farthest = std::max(farthest, (model.particle_position[static_cast<std::size_t>(k)] -
                                         model.particle_position[static_cast<std::size_t>(i)])
                                            .norm());
        double& target = spacing.particle[static_cast<std::size_t>(i)];
        target = std::max({target, cell_spacing, farthest / sqrt2});
      }
    }
    return spacing;
  }
  std::vector<double> own(model.particle_count()), reach(model.particle_count());
  for (std::size_t j = 0; j < own.size(); ++j) {
    own[j] = std::sqrt(model.particle_area[j]);
    reach[j] = particle_spacing_reach * own[j];
  }
  spacing.particle = own;
  const approx::CellList particles(model.particle_position, sphshell::detail::model_checks::median(reach));
  for (std::size_t j = 0; j < own.size(); ++j)
    particles.for_each_within(model.particle_position[j], reach[j], [&](int i, double) {
      double& target = spacing.particle[static_cast<std::size_t>(i)];
      target = std::max(target, own[j]);
    });
  return spacing;
}

}  // namespace sphshell
