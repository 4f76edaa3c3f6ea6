// The partitioner and the ownership map (include/sphshell/mpi/partition.hpp,
// layout.hpp), run on 1, 2 and 3 ranks: every particle and every integration
// point owned exactly once, every row's neighbours present on the rank that
// computes it, every point that reaches an owned particle computed there, and
// the owned particles' force sums taken over the serial slots in the serial
// order (the bitwise-identity argument of docs/distributed.md).
#include <sphshell/mpi/all.hpp>

#include "mpi_test_support.hpp"

#include <catch2/catch.hpp>

#include <algorithm>
#include <cstddef>
#include <numeric>
#include <string>
#include <utility>
#include <vector>

using namespace sphshell;

namespace {

void check_decomposition(const mpi::Communicator& comm, const mpi_test::Case& c) {
  INFO(c.name << " on " << comm.size() << " ranks, rank " << comm.rank());
  const mpi::DecompositionInput input = c.input();
  const mpi::Partition partition = mpi::partition(input, comm.size());
  const mpi::RankLayout layout = mpi::rank_layout(input, partition, comm.rank());
  const std::size_t n = c.model.particle_count();

  // Every rank computed the same owners without communicating.
  const std::vector<int> all_owners = comm.all_gather_v(partition.particle_owner);
  bool same = all_owners.size() == n * static_cast<std::size_t>(comm.size());
  for (std::size_t k = 0; same && k < all_owners.size(); ++k) same = all_owners[k] == partition.particle_owner[k % n];
  CHECK(same);

  // Every particle owned once: the owned lists of all ranks are a permutation of 0 … n−1.
  std::vector<int> owned = comm.all_gather_v(layout.owned);
  std::sort(owned.begin(), owned.end());
  std::vector<int> expected(n);
  std::iota(expected.begin(), expected.end(), 0);
  CHECK(owned == expected);
  CHECK(layout.owned_count() > 0);

  // The rank's rows as the solver builds them (IntegrationPoints::subset).
  const mpi_test::Points local_points = c.points->subset(layout.computed, layout.local_of, layout.local_count());
  for (std::size_t g = 0; g < mpi::group_count; ++g) {
    const approx::ShapeFunctions& shape = *input.groups[g].shape;
    // Every point owned once, by a rank that computes it.
    std::vector<int> mine;
    for (std::size_t k = 0; k < layout.computed[g].size(); ++k)
      if (layout.computed_is_owned[g][k]) mine.push_back(static_cast<int>(layout.computed[g][k]));
    std::vector<int> points_owned = comm.all_gather_v(mine);
    std::sort(points_owned.begin(), points_owned.end());
    std::vector<int> all_rows(shape.rows());
    std::iota(all_rows.begin(), all_rows.end(), 0);
    CHECK(points_owned == all_rows);

    // Computed here exactly when the row (in full capacity) reaches an owned particle.
    std::vector<char> computed(shape.rows(), 0);
    for (std::size_t row : layout.computed[g]) computed[row] = 1;
    std::size_t wrong = 0, missing_neighbours = 0;
    for (std::size_t row = 0; row < shape.rows(); ++row) {
      bool reaches = false;
      for (std::size_t s = shape.row_begin[row]; s < shape.row_begin[row + 1]; ++s) {
        reaches = reaches || partition.particle_owner[shape.neighbour[s]] == comm.rank();
        if (computed[row] && layout.local_of[shape.neighbour[s]] < 0) ++missing_neighbours;
      }
      if (reaches != static_cast<bool>(computed[row])) ++wrong;
    }
    CHECK(wrong == 0);
    CHECK(missing_neighbours == 0);

    // The local rows: the same slots, in the same places, with local indices.
    const approx::ShapeFunctions& local = local_points.shape(solver::point_groups[g]);
    std::size_t mismatched = 0;
    for (std::size_t k = 0; k < layout.computed[g].size(); ++k) {
      const std::size_t row = layout.computed[g][k];
      if (local.capacity(k) != shape.capacity(row) || local.row_size[k] != shape.row_size[row]) {
        ++mismatched;
        continue;
      }
      for (std::size_t s = 0; s < shape.capacity(row); ++s) {
        const std::size_t global_slot = shape.row_begin[row] + s, local_slot = local.row_begin[k] + s;
        if (layout.global_of(static_cast<std::size_t>(local.neighbour[local_slot])) != shape.neighbour[global_slot] ||
            local.value[local_slot].phi != shape.value[global_slot].phi || local.value[local_slot].dphi_d1 != shape.value[global_slot].dphi_d1)
          ++mismatched;
      }
    }
    CHECK(mismatched == 0);
  }

  // Ghosts: not owned, owned by the rank the layout names, ascending.
  std::size_t bad_ghosts = 0;
  for (std::size_t k = 0; k < layout.ghost_count(); ++k)
    if (partition.particle_owner[layout.ghost[k]] == comm.rank() ||
        partition.particle_owner[layout.ghost[k]] != layout.ghost_owner[k] ||
        (k > 0 && layout.ghost[k] <= layout.ghost[k - 1]))
      ++bad_ghosts;
  CHECK(bad_ghosts == 0);
  if (comm.size() == 1) CHECK(layout.ghost_count() == 0);

  // The force sum of each owned particle: the serial transpose lists its
  // force entries by group and row; the rank's computed rows, walked in their
  // order, must give the same (group, row) sequence — the same terms in the
  // same order.
  const std::vector<std::size_t>& begin = c.points->particle_slot_begin();
  const auto& entries = c.points->force_entries();
  std::vector<std::vector<std::pair<std::size_t, std::size_t>>> local_order(layout.owned_count());
  for (std::size_t g = 0; g < mpi::group_count; ++g) {
    const approx::ShapeFunctions& shape = *input.groups[g].shape;
    for (std::size_t row : layout.computed[g])
      for (std::size_t s = shape.row_begin[row]; s < shape.row_begin[row] + shape.row_size[row]; ++s) {
        const int local = layout.local_of[shape.neighbour[s]];
        if (local >= 0 && static_cast<std::size_t>(local) < layout.owned_count()) local_order[local].push_back({g, row});
      }
  }
  std::size_t different_sums = 0;
  for (std::size_t k = 0; k < layout.owned_count(); ++k) {
    const auto i = static_cast<std::size_t>(layout.owned[k]);
    std::vector<std::pair<std::size_t, std::size_t>> serial;
    for (std::size_t m = begin[i]; m < begin[i + 1]; ++m) {
      const std::size_t p = entries[m].point;
      serial.push_back({solver::index_of(c.points->group_of(p)), c.points->row_of(p)});
    }
    if (serial != local_order[k]) ++different_sums;
  }
  CHECK(different_sums == 0);

  const mpi::PartitionQuality quality = mpi::assess(input, partition);
  CHECK(quality.imbalance >= 0.0);
  if (comm.size() == 1) CHECK(quality.edge_cut == 0);
  if (comm.size() > 1) CHECK(quality.edge_cut > 0);
}

}  // namespace

TEST_CASE("partitioner: every particle and point owned once, rows complete on 1-3 ranks", "[mpi][partition]") {
  const mpi::Communicator comm;
  check_decomposition(comm, mpi_test::paper_plate(51));
  check_decomposition(comm, mpi_test::closed_tube(2.5e-3, 0.2));
  check_decomposition(comm, mpi_test::spherical_cap(25));
}

TEST_CASE("partitioner: RCB cuts a uniform grid along its long side into equal weights", "[mpi][partition]") {
  // 12 × 4 particles, unit spacing, weight 1 each: three parts are the
  // column blocks [0,4), [4,8), [8,12); two parts [0,6), [6,12).
  std::vector<Vector3> x;
  for (int j = 0; j < 4; ++j)
    for (int i = 0; i < 12; ++i) x.emplace_back(i, j, 0.0);
  mpi::DecompositionInput input;
  input.particle_position = &x;
  mpi::PartitionWeights weights;
  weights.per_particle = 1.0;
  for (int parts : {2, 3}) {
    const mpi::Partition partition = mpi::partition(input, parts, weights);
    std::size_t wrong = 0;
    for (int j = 0; j < 4; ++j)
      for (int i = 0; i < 12; ++i)
        if (partition.particle_owner[j * 12 + i] != i / (12 / parts)) ++wrong;
    CHECK(wrong == 0);
    CHECK(mpi::assess(input, partition, weights).imbalance == 0.0);
  }
  // Four parts: 12/2 along x, then each half (6 × 4) along x again.
  const mpi::Partition four = mpi::partition(input, 4, weights);
  for (int i = 0; i < 12; ++i) CHECK(four.particle_owner[i] == i / 3);
}

TEST_CASE("partitioner: weights follow the integration points homed on each particle", "[mpi][partition]") {
  const mpi_test::Case plate = mpi_test::paper_plate(11);
  const mpi::Partition partition = mpi::partition(plate.input(), 1);
  // 11 × 11 particles, 10 × 10 stress points at the cell centres, each homed on
  // its lowest-index corner (the four corners tie), and a point per particle.
  for (int j = 0; j < 11; ++j)
    for (int i = 0; i < 11; ++i) {
      const double stress_points = (i < 10 && j < 10) ? 1.0 : 0.0;
      CHECK(partition.particle_weight[j * 11 + i] == 1.0 + stress_points);
    }
  for (int q = 0; q < 100; ++q) CHECK(partition.home_particle[0][q] == (q / 10) * 11 + q % 10);
}

TEST_CASE("partitioner: bad input is an Error on every rank", "[mpi][partition][errors]") {
  const mpi::Communicator comm;
  std::vector<Vector3> two{Vector3(0, 0, 0), Vector3(1, 0, 0)};
  mpi::DecompositionInput input;
  input.particle_position = &two;
  // More ranks than particles: the same message on every rank.
  try {
    mpi::collectively(comm, [&] { mpi::partition(input, comm.size() + 2); });
    FAIL_CHECK("no Error for a rank count above the particle count");
  } catch (const Error& error) {
    CHECK_THAT(error.what(), Catch::Contains("invalid parameter rank count = " + std::to_string(comm.size() + 2)) &&
                                 Catch::Contains("exceeds the particle count 2"));
  }
  CHECK_THROWS_WITH(mpi::partition(input, 0), Catch::Contains("rank count = 0"));
  mpi::DecompositionInput empty;
  CHECK_THROWS_WITH(mpi::partition(empty, 1), Catch::Contains("particle count = 0"));
  // External owners: out of range, or a rank left without particles.
  CHECK_THROWS_WITH(mpi::partition_from_owners(input, 2, {0, 2}), Catch::Contains("owner of particle 1 = 2"));
  CHECK_THROWS_WITH(mpi::partition_from_owners(input, 2, {0, 0}), Catch::Contains("rank 1 particle count"));
  CHECK_THROWS_WITH(mpi::partition_from_owners(input, 2, {0}), Catch::Contains("particle owner count = 1"));
  const mpi::Partition fine = mpi::partition_from_owners(input, 2, {1, 0});
  CHECK_THROWS_WITH(mpi::rank_layout(input, fine, 2), Catch::Contains("invalid parameter rank = 2"));
}
