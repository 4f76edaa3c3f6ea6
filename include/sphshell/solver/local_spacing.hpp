#pragma once
// The local spacing Δ at every evaluation point, from which its smoothing
// length h = support_radius_factor · Δ / kernel support factor follows
// (docs/method.md, "Support radius"), so that one large cell widens its own
// row and not every row of the sheet:
//   stress point q: the largest of its cell's √(area per particle) (the
//     quad's area, twice a triangle's; ShellModel::stress_point_spacing), its
//     cell's longest side and its distance to its cell's farthest corner;
//   particle i of a model with cells: the largest, over the cells it is a
//     corner of, of the cell's √(area per particle), its longest side and its
//     distance from i to the cell's farthest corner over √2;
//   particle i of a model without cells (the general constructor): the
//     largest √A_j of the particles j with |x_j − x_i| < particle_spacing_reach
//     · √A_j, itself included. Its own area is a half or a quarter of its
//     neighbours' on an edge or at a corner; the neighbours' keeps its row as
//     wide as the inner rows there.
// Why the longest side and not √A alone: on a cell longer than wide (a 3 × 1
// cell's √A is 1.7, its long side 3) a radius from √A reaches only the cell's
// own two corners along the long side, so the row cannot tell a linear from a
// curved field in that direction (the pinched hemisphere's cells near its hole
// and the slit annular plate's outer cells, aspect ≈ 3 : 1). The corner terms
// keep a distorted cell's corners inside the row (the edge-tied shear needs
// them): the corner cells of ShellModel::spherical_cap (an interior angle near
// 175°) have their corners at 2.02 √A. On a square cell every term is the side
// or less (the farthest corner at 0.71 side, the diagonal over √2 the side),
// so a uniform sheet keeps the single global spacing it had. A particle's Δ
// comes from the particles and cells it touches, never from a stress point's
// integration area, so one stress point standing for a large area widens its
// own row only.

#include <sphshell/approx/neighbour_search.hpp>
#include <sphshell/shell/cell.hpp>
#include <sphshell/shell/model.hpp>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <vector>

namespace sphshell::solver {

// A particle takes the spacing of every particle j whose own spacing √A_j
// reaches it within this many spacings: on a grid the diagonal neighbour lies
// at √2 spacings, so a corner particle (a quarter area) sees the inner one.
inline constexpr double particle_spacing_reach = 1.5;

struct LocalSpacing {
  std::vector<double> stress_point;  // Δ_q, per stress point (m)
  std::vector<double> particle;      // Δ_i, per particle (m)

  double largest() const {
    double value = 0.0;
    for (const std::vector<double>* set : {&stress_point, &particle})
      for (double spacing : *set) value = std::max(value, spacing);
    return value;
  }
};

// The middle value (the upper one of an even count): the cell width of a
// search whose radii vary from point to point.
inline double median_of(std::vector<double> values) {
  if (values.empty()) return 0.0;
  const auto middle = values.begin() + static_cast<std::ptrdiff_t>(values.size() / 2);
  std::nth_element(values.begin(), middle, values.end());
  return *middle;
}

inline LocalSpacing local_spacing(const ShellModel& model) {
  LocalSpacing spacing;
  spacing.stress_point.resize(model.stress_point_count());
  for (std::size_t q = 0; q < spacing.stress_point.size(); ++q) spacing.stress_point[q] = model.stress_point_spacing(q);
  if (!model.cells().empty()) {
    spacing.particle.assign(model.particle_count(), 0.0);
    const double sqrt2 = std::sqrt(2.0);
    for (std::size_t c = 0; c < model.cells().size(); ++c) {
      const Cell& cell = model.cells()[c];
      double cell_spacing = model.stress_point_spacing(c);
      for (std::size_t k = 0; k < cell.size(); ++k) {
        const std::size_t a = static_cast<std::size_t>(cell[k]), b = static_cast<std::size_t>(cell[(k + 1) % cell.size()]);
        cell_spacing = std::max(cell_spacing, (model.particle_position[a] - model.particle_position[b]).norm());
      }
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
  const approx::CellList particles(model.particle_position, median_of(reach));
  for (std::size_t j = 0; j < own.size(); ++j)
    particles.for_each_within(model.particle_position[j], reach[j], [&](int i, double) {
      double& target = spacing.particle[static_cast<std::size_t>(i)];
      target = std::max(target, own[j]);
    });
  return spacing;
}

}  // namespace sphshell::solver
