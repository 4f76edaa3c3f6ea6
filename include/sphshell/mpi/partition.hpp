#pragma once
// Decomposition of a shell in its reference configuration (docs/distributed.md):
// which rank owns each particle and each integration point.
//
// The shape-function rows are fixed in the reference configuration (total
// Lagrangian; a crack only hides slots of a row, it never adds any), so the
// partition is made once, from reference positions and the rows' full
// capacity.
//
// Every integration point has a home particle, the nearest particle of its
// row (ties: the lowest index; a particle's own point is homed on the particle)
// and is owned by the home particle's owner. A particle's weight is its own
// cost plus the cost of the points homed on it, so cutting particles by weight
// balances the work of the step, whose cost is the integration points'
// material updates (solver/internal_forces.hpp).
//
// Recursive coordinate bisection (RCB) splits the particles along the longest
// side of their bounding box at the weighted median, parts/2 to one side, the
// rest to the other, until each part is one rank. It is deterministic: every
// rank computes the same partition from the same (replicated) input without
// communicating. This header needs no MPI.

#include <sphshell/approx/shape_functions.hpp>
#include <sphshell/core/error.hpp>
#include <sphshell/core/types.hpp>
#include <sphshell/shell/model.hpp>
#include <sphshell/solver/integration_points.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <numeric>
#include <string>
#include <vector>

namespace sphshell::mpi {

// The two groups of integration points, in the solver's order (stress points
// first, then the particle points; solver::PointGroup).
inline constexpr std::size_t group_count = 2;

// One group's rows and the reference positions of its evaluation points; a
// group that does not integrate has no rows (shape == nullptr or 0 rows).
struct PointGroupRows {
  const approx::ShapeFunctions* shape = nullptr;
  const std::vector<Vector3>* positions = nullptr;
  std::size_t rows() const { return shape ? shape->rows() : 0; }
};

// What a decomposition is made from: the particles' reference positions and
// the rows of both groups (slots in row capacity, neighbours in global
// particle indices).
struct DecompositionInput {
  const std::vector<Vector3>* particle_position = nullptr;
  std::array<PointGroupRows, group_count> groups{};
  std::size_t particle_count() const { return particle_position ? particle_position->size() : 0; }
};

// The input of a solver's model and integration points (read only).
template <class Approx>
DecompositionInput decomposition_input(const ShellModel& model, const solver::IntegrationPoints<Approx>& points) {
  DecompositionInput input;
  input.particle_position = &model.particle_position;
  for (solver::PointGroup group : solver::point_groups)
    input.groups[solver::index_of(group)] = {&points.shape(group), &points.positions(model, group)};
  return input;
}

// The cost model of a particle's weight: per_point for each integration point
// homed on it (its material update through the thickness), per_slot for each
// slot of such a point's row (the gather and scatter), per_particle for the
// particle itself (time integration, loads). Relative units.
struct PartitionWeights {
  double per_point = 1.0;
  double per_slot = 0.0;
  double per_particle = 0.0;
};

enum class PartitionMethod { recursive_coordinate_bisection };

// Owners of particles and points, and the weights they were balanced with.
struct Partition {
  int parts = 0;
  std::vector<int> particle_owner;                                // per particle
  std::array<std::vector<int>, group_count> home_particle;        // per group row
  std::array<std::vector<int>, group_count> point_owner;          // per group row
  std::vector<double> particle_weight;                            // per particle
};

namespace detail {

inline void check_input(const DecompositionInput& input) {
  if (input.particle_position == nullptr || input.particle_count() == 0)
    sphshell::detail::invalid_parameter("decomposition particle count", 0, "must be > 0");
  const std::size_t n = input.particle_count();
  for (std::size_t g = 0; g < group_count; ++g) {
    const PointGroupRows& group = input.groups[g];
    if (group.rows() == 0) continue;
    if (group.positions == nullptr || group.positions->size() != group.rows())
      sphshell::detail::invalid_parameter("decomposition group " + std::to_string(g) + " positions",
                                          group.positions ? group.positions->size() : 0,
                                          "one position per row (" + std::to_string(group.rows()) + ")");
    for (int j : group.shape->neighbour)
      if (j < 0 || static_cast<std::size_t>(j) >= n)
        sphshell::detail::invalid_parameter("decomposition row neighbour", j,
                                            "must lie in [0, " + std::to_string(n) + ")");
  }
}

inline void check_parts(int parts, std::size_t particles) {
  if (parts < 1) sphshell::detail::invalid_parameter("rank count", parts, "must be >= 1");
  if (static_cast<std::size_t>(parts) > particles)
    sphshell::detail::invalid_parameter("rank count", parts,
                                        "exceeds the particle count " + std::to_string(particles) +
                                            ": every rank must own at least one particle");
}

// Squared distances closer than this relative difference are a tie: the
// corners of a cell are equidistant from its centre up to round-off.
inline constexpr double home_tie_tolerance = 1e-9;

// The nearest particle of a row (capacity slots), the lowest index on ties.
inline int nearest_in_row(const approx::ShapeFunctions& shape, std::size_t row, const Vector3& at,
                          const std::vector<Vector3>& particles) {
  int best = -1;
  double best_distance = 0.0;
  for (std::size_t s = shape.row_begin[row]; s < shape.row_begin[row + 1]; ++s) {
    const int j = shape.neighbour[s];
    const double distance = (particles[j] - at).squaredNorm();
    const bool tie = std::abs(distance - best_distance) <= home_tie_tolerance * best_distance;
    if (best < 0 || (!tie && distance < best_distance) || (tie && j < best)) {
      best = j;
      best_distance = distance;
    }
  }
  if (best < 0) sphshell::detail::invalid_parameter("decomposition row " + std::to_string(row), 0, "has no slot");
  return best;
}

// RCB of items[first, last) (particle indices) into parts owners first_part …
inline void bisect(const std::vector<Vector3>& x, const std::vector<double>& weight, std::vector<int>& items,
                   std::size_t first, std::size_t last, int first_part, int parts, std::vector<int>& owner) {
  if (parts == 1) {
    for (std::size_t k = first; k < last; ++k) owner[items[k]] = first_part;
    return;
  }
  Vector3 low = x[items[first]], high = low;
  for (std::size_t k = first; k < last; ++k) {
    low = low.cwiseMin(x[items[k]]);
    high = high.cwiseMax(x[items[k]]);
  }
  int axis = 0;
  (high - low).maxCoeff(&axis);
  const auto begin = items.begin() + static_cast<std::ptrdiff_t>(first);
  const auto end = items.begin() + static_cast<std::ptrdiff_t>(last);
  std::sort(begin, end, [&](int a, int b) { return x[a][axis] < x[b][axis] || (x[a][axis] == x[b][axis] && a < b); });
  const int left_parts = parts / 2;
  double total = 0.0;
  for (std::size_t k = first; k < last; ++k) total += weight[items[k]];
  const double target = total * left_parts / parts;
  // The split k (left = [first, k)) whose left weight is nearest the target,
  // leaving each side at least one item per part.
  const std::size_t lowest = first + static_cast<std::size_t>(left_parts);
  const std::size_t highest = last - static_cast<std::size_t>(parts - left_parts);
  std::size_t split = lowest;
  double left = 0.0;
  for (std::size_t k = first; k < lowest; ++k) left += weight[items[k]];
  double best = std::abs(left - target);
  for (std::size_t k = lowest; k < highest; ++k) {
    left += weight[items[k]];
    const double miss = std::abs(left - target);
    if (miss < best) {
      best = miss;
      split = k + 1;
    }
  }
  bisect(x, weight, items, first, split, first_part, left_parts, owner);
  bisect(x, weight, items, split, last, first_part + left_parts, parts - left_parts, owner);
}

}  // namespace detail

// Home particles and weights of an input (the part of a partition that does
// not depend on the method).
inline Partition prepare_partition(const DecompositionInput& input, int parts, const PartitionWeights& weights) {
  detail::check_input(input);
  detail::check_parts(parts, input.particle_count());
  Partition partition;
  partition.parts = parts;
  const std::vector<Vector3>& x = *input.particle_position;
  partition.particle_weight.assign(x.size(), weights.per_particle);
  for (std::size_t g = 0; g < group_count; ++g) {
    const PointGroupRows& group = input.groups[g];
    partition.home_particle[g].resize(group.rows());
    for (std::size_t row = 0; row < group.rows(); ++row) {
      // A particle point's row is its own particle's (the second group
      // evaluates at the particles themselves).
      const int home = g == solver::index_of(solver::PointGroup::particles) && group.rows() == x.size()
                           ? static_cast<int>(row)
                           : detail::nearest_in_row(*group.shape, row, (*group.positions)[row], x);
      partition.home_particle[g][row] = home;
      partition.particle_weight[home] +=
          weights.per_point + weights.per_slot * static_cast<double>(group.shape->capacity(row));
    }
  }
  return partition;
}

// Points follow their home particle's owner.
inline void assign_points(Partition& partition) {
  for (std::size_t g = 0; g < group_count; ++g) {
    partition.point_owner[g].resize(partition.home_particle[g].size());
    for (std::size_t row = 0; row < partition.home_particle[g].size(); ++row)
      partition.point_owner[g][row] = partition.particle_owner[partition.home_particle[g][row]];
  }
}

// The partition of an input into `parts` ranks. More ranks than particles is an Error.
inline Partition partition(const DecompositionInput& input, int parts, const PartitionWeights& weights = {},
                           PartitionMethod method = PartitionMethod::recursive_coordinate_bisection) {
  Partition result = prepare_partition(input, parts, weights);
  const std::vector<Vector3>& x = *input.particle_position;
  result.particle_owner.assign(x.size(), -1);
  switch (method) {
    case PartitionMethod::recursive_coordinate_bisection: {
      std::vector<int> items(x.size());
      std::iota(items.begin(), items.end(), 0);
      detail::bisect(x, result.particle_weight, items, 0, items.size(), 0, parts, result.particle_owner);
      break;
    }
  }
  assign_points(result);
  return result;
}

// A partition from particle owners found elsewhere (a graph partitioner, a
// user's own split): checked, with the points assigned by the same rule.
inline Partition partition_from_owners(const DecompositionInput& input, int parts, std::vector<int> particle_owner,
                                       const PartitionWeights& weights = {}) {
  Partition result = prepare_partition(input, parts, weights);
  if (particle_owner.size() != input.particle_count())
    sphshell::detail::invalid_parameter("particle owner count", particle_owner.size(),
                                        "must equal the particle count " + std::to_string(input.particle_count()));
  std::vector<char> used(static_cast<std::size_t>(parts), 0);
  for (std::size_t i = 0; i < particle_owner.size(); ++i) {
    if (particle_owner[i] < 0 || particle_owner[i] >= parts)
      sphshell::detail::invalid_parameter("owner of particle " + std::to_string(i), particle_owner[i],
                                          "must lie in [0, " + std::to_string(parts) + ")");
    used[particle_owner[i]] = 1;
  }
  for (int r = 0; r < parts; ++r)
    if (!used[r]) sphshell::detail::invalid_parameter("rank " + std::to_string(r) + " particle count", 0, "must be > 0");
  result.particle_owner = std::move(particle_owner);
  assign_points(result);
  return result;
}

}  // namespace sphshell::mpi
