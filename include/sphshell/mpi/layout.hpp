#pragma once
// One rank's share of a partition (docs/distributed.md, "Ownership and the
// ghost layer"): the particles it owns, the integration points it computes,
// the ghost particles those points read, and the local numbering.
//
// The design: ghost integration points are computed redundantly. A rank
// computes every point whose row (in full capacity) reaches one of its owned
// particles, not only the points it owns. Then every slot that adds to an
// owned particle's force is computed on the owner itself, and the owner sums
// them over the same slots in the same order as a single process does
// (solver::IntegrationPoints::build_slot_transpose lists them by group and
// row; the local points keep the global order): the internal forces of owned
// particles are bitwise those of the serial run, with one halo exchange
// (positions and directors) per step and no reverse communication. The price:
// the ghost layer is two supports deep (the rows of the redundant points) and
// the points within one support of the rank boundary are computed twice.
//
// Local numbering: owned particles first, [0, owned), then the ghosts,
// [owned, owned + ghosts), each ascending in global index — the ranges of
// solver::ParticleState. Computed rows are listed ascending in global row
// order, group by group. This header needs no MPI.

#include <sphshell/approx/shape_functions.hpp>
#include <sphshell/core/error.hpp>
#include <sphshell/mpi/partition.hpp>

#include <algorithm>
#include <array>
#include <cstddef>
#include <string>
#include <vector>

namespace sphshell::mpi {

struct RankLayout {
  int rank = 0;
  std::vector<int> owned;                                       // global particle ids, ascending
  std::vector<int> ghost;                                       // global particle ids, ascending
  std::vector<int> ghost_owner;                                 // per ghost: its owning rank
  std::vector<int> local_of;                                    // global particle → local index, or −1
  std::array<std::vector<std::size_t>, group_count> computed;   // global rows computed here, ascending
  std::array<std::vector<char>, group_count> computed_is_owned; // per computed row: owned here

  std::size_t owned_count() const { return owned.size(); }
  std::size_t ghost_count() const { return ghost.size(); }
  std::size_t local_count() const { return owned.size() + ghost.size(); }
  // Global id of a local particle.
  int global_of(std::size_t local) const {
    return local < owned.size() ? owned[local] : ghost[local - owned.size()];
  }
  std::size_t owned_point_count(std::size_t group) const {
    return static_cast<std::size_t>(std::count(computed_is_owned[group].begin(), computed_is_owned[group].end(), 1));
  }
  // Points computed here but owned elsewhere (the redundant work).
  std::size_t redundant_point_count() const {
    std::size_t count = 0;
    for (std::size_t g = 0; g < group_count; ++g) count += computed[g].size() - owned_point_count(g);
    return count;
  }
};

// The layout of one rank.
inline RankLayout rank_layout(const DecompositionInput& input, const Partition& partition, int rank) {
  if (rank < 0 || rank >= partition.parts)
    sphshell::detail::invalid_parameter("rank", rank, "must lie in [0, " + std::to_string(partition.parts) + ")");
  const std::size_t n = input.particle_count();
  if (partition.particle_owner.size() != n)
    sphshell::detail::invalid_parameter("partition particle count", partition.particle_owner.size(),
                                        "must equal the input's " + std::to_string(n));
  RankLayout layout;
  layout.rank = rank;
  std::vector<char> needed(n, 0);
  for (std::size_t i = 0; i < n; ++i)
    if (partition.particle_owner[i] == rank) layout.owned.push_back(static_cast<int>(i));
  for (std::size_t g = 0; g < group_count; ++g) {
    const PointGroupRows& group = input.groups[g];
    for (std::size_t row = 0; row < group.rows(); ++row) {
      const approx::ShapeFunctions& shape = *group.shape;
      bool reaches_owned = false;
      for (std::size_t s = shape.row_begin[row]; s < shape.row_begin[row + 1] && !reaches_owned; ++s)
        reaches_owned = partition.particle_owner[shape.neighbour[s]] == rank;
      if (!reaches_owned) continue;
      layout.computed[g].push_back(row);
      layout.computed_is_owned[g].push_back(partition.point_owner[g][row] == rank ? 1 : 0);
      for (std::size_t s = shape.row_begin[row]; s < shape.row_begin[row + 1]; ++s) needed[shape.neighbour[s]] = 1;
    }
  }
  for (std::size_t i = 0; i < n; ++i)
    if (needed[i] && partition.particle_owner[i] != rank) {
      layout.ghost.push_back(static_cast<int>(i));
      layout.ghost_owner.push_back(partition.particle_owner[i]);
    }
  layout.local_of.assign(n, -1);
  for (std::size_t k = 0; k < layout.local_count(); ++k) layout.local_of[layout.global_of(k)] = static_cast<int>(k);
  return layout;
}

// How good a partition is (docs/scaling.md reports these for the paper's
// cases): the neighbour graph's edge cut, the weight imbalance, and what the
// ghost layer costs.
struct PartitionQuality {
  std::size_t edges = 0, edge_cut = 0;  // particle pairs sharing a row; those split between ranks
  double imbalance = 0.0;               // max rank weight / mean − 1
  double computed_imbalance = 0.0;      // the same with redundant points counted where computed
  std::size_t max_ghosts = 0;           // largest ghost layer of a rank
  double mean_ghosts = 0.0;
  std::size_t max_redundant_points = 0; // points computed on a rank that does not own them
  std::size_t max_neighbour_ranks = 0;  // ranks a rank receives ghosts from
  std::size_t max_owned = 0, min_owned = 0;
};

// The neighbour graph: particles i and j are adjacent when the row of a
// particle point (or, without particle points, of any point) holds both.
inline std::vector<std::vector<int>> neighbour_graph(const DecompositionInput& input) {
  const std::size_t n = input.particle_count();
  std::vector<std::vector<int>> adjacent(n);
  const std::size_t particle_group = solver::index_of(solver::PointGroup::particles);
  const bool by_particle_rows = input.groups[particle_group].rows() == n;
  for (std::size_t g = 0; g < group_count; ++g) {
    if (by_particle_rows && g != particle_group) continue;
    const PointGroupRows& group = input.groups[g];
    for (std::size_t row = 0; row < group.rows(); ++row) {
      const approx::ShapeFunctions& shape = *group.shape;
      const std::size_t begin = shape.row_begin[row], end = shape.row_begin[row + 1];
      auto connect = [&](int i, int j) {
        if (i == j) return;
        adjacent[i].push_back(j);
        adjacent[j].push_back(i);
      };
      if (by_particle_rows) {
        for (std::size_t b = begin; b < end; ++b) connect(static_cast<int>(row), shape.neighbour[b]);
      } else {
        for (std::size_t a = begin; a < end; ++a)
          for (std::size_t b = a + 1; b < end; ++b) connect(shape.neighbour[a], shape.neighbour[b]);
      }
    }
  }
  for (std::vector<int>& list : adjacent) {
    std::sort(list.begin(), list.end());
    list.erase(std::unique(list.begin(), list.end()), list.end());
  }
  return adjacent;
}

inline PartitionQuality assess(const DecompositionInput& input, const Partition& partition, const PartitionWeights& weights = {}) {
  PartitionQuality quality;
  const std::vector<std::vector<int>> adjacent = neighbour_graph(input);
  for (std::size_t i = 0; i < adjacent.size(); ++i)
    for (int j : adjacent[i])
      if (static_cast<std::size_t>(j) > i) {
        ++quality.edges;
        if (partition.particle_owner[i] != partition.particle_owner[j]) ++quality.edge_cut;
      }
  std::vector<double> weight(static_cast<std::size_t>(partition.parts), 0.0);
  for (std::size_t i = 0; i < partition.particle_weight.size(); ++i)
    weight[partition.particle_owner[i]] += partition.particle_weight[i];
  const double mean = std::accumulate(weight.begin(), weight.end(), 0.0) / partition.parts;
  quality.imbalance = *std::max_element(weight.begin(), weight.end()) / mean - 1.0;
  double computed_max = 0.0;
  quality.min_owned = input.particle_count();
  for (int r = 0; r < partition.parts; ++r) {
    const RankLayout layout = rank_layout(input, partition, r);
    double computed_weight = weights.per_particle * static_cast<double>(layout.owned_count());
    for (std::size_t g = 0; g < group_count; ++g)
      for (std::size_t row : layout.computed[g])
        computed_weight += weights.per_point + weights.per_slot * static_cast<double>(input.groups[g].shape->capacity(row));
    computed_max = std::max(computed_max, computed_weight);
    quality.max_ghosts = std::max(quality.max_ghosts, layout.ghost_count());
    quality.mean_ghosts += static_cast<double>(layout.ghost_count()) / partition.parts;
    quality.max_redundant_points = std::max(quality.max_redundant_points, layout.redundant_point_count());
    std::vector<int> sources = layout.ghost_owner;
    std::sort(sources.begin(), sources.end());
    sources.erase(std::unique(sources.begin(), sources.end()), sources.end());
    quality.max_neighbour_ranks = std::max(quality.max_neighbour_ranks, sources.size());
    quality.max_owned = std::max(quality.max_owned, layout.owned_count());
    quality.min_owned = std::min(quality.min_owned, layout.owned_count());
  }
  // Against the serial work (every point once), not the inflated total.
  quality.computed_imbalance = computed_max / mean - 1.0;
  return quality;
}

}  // namespace sphshell::mpi
