// The halo plan and exchange (include/sphshell/mpi/halo.hpp) on 1, 2 and 3
// ranks: a field of global ids round-trips into every ghost, and the surface
// gradients a rank gathers from its local rows after the exchange are bitwise
// the serial ones.
#include <sphshell/mpi/all.hpp>

#include "mpi_test_support.hpp"

#include <catch2/catch.hpp>

#include <cmath>
#include <cstddef>
#include <limits>
#include <string>
#include <vector>

using namespace sphshell;

namespace {

// Distinct per global id and exactly representable.
Vector3 id_field(int global) { return Vector3(global, -2.0 * global, 0.5 * global + 0.25); }
Vector3 second_field(int global) { return Vector3(global * 1e-3, 7.0, -static_cast<double>(global) * global); }

void check_round_trip(const mpi::Communicator& comm, const mpi_test::Case& c) {
  INFO(c.name << " on " << comm.size() << " ranks, rank " << comm.rank());
  const mpi::DecompositionInput input = c.input();
  const mpi::Partition partition = mpi::partition(input, comm.size());
  const mpi::RankLayout layout = mpi::rank_layout(input, partition, comm.rank());
  const mpi::HaloPlan plan(comm, layout);
  CHECK(plan.received_particles() == layout.ghost_count());
  // What is sent is what is received, over all ranks.
  CHECK(comm.sum(static_cast<std::int64_t>(plan.sent_particles())) ==
        comm.sum(static_cast<std::int64_t>(plan.received_particles())));
  if (comm.size() > 1) CHECK(!plan.neighbours().empty());

  const double nan = std::numeric_limits<double>::quiet_NaN();
  std::vector<Vector3> a(layout.local_count(), Vector3::Constant(nan)), b = a;
  for (std::size_t k = 0; k < layout.owned_count(); ++k) {
    a[k] = id_field(layout.owned[k]);
    b[k] = second_field(layout.owned[k]);
  }
  mpi::HaloExchange exchange;
  for (int round = 0; round < 2; ++round) {  // the buffers are reused
    exchange.exchange(comm, plan, {&a, &b});
    std::size_t wrong = 0;
    for (std::size_t k = 0; k < layout.local_count(); ++k)
      if (a[k] != id_field(layout.global_of(k)) || b[k] != second_field(layout.global_of(k))) ++wrong;
    CHECK(wrong == 0);
    for (std::size_t k = 0; k < layout.owned_count(); ++k) a[k] += Vector3::Constant(1.0);
    for (std::size_t k = 0; k < layout.owned_count(); ++k) a[k] -= Vector3::Constant(1.0);
  }

  // The gathered a1, a2, n, n1, n2 of every computed row from a moved
  // configuration: bitwise the serial gather.
  std::vector<Vector3> x_global(c.model.particle_count()), d_global(c.model.particle_count());
  for (std::size_t i = 0; i < x_global.size(); ++i) {
    const double s = std::sin(0.37 * static_cast<double>(i));
    x_global[i] = c.model.particle_position[i] + 1e-3 * Vector3(s, s * s, std::cos(1.3 * static_cast<double>(i)));
    d_global[i] = (c.model.particle_normal[i] + 0.05 * Vector3(s, -s, 0.0)).normalized();
  }
  std::vector<Vector3> x(layout.local_count(), Vector3::Constant(nan)), d = x;
  for (std::size_t k = 0; k < layout.owned_count(); ++k) {
    x[k] = x_global[layout.owned[k]];
    d[k] = d_global[layout.owned[k]];
  }
  exchange.exchange(comm, plan, {&x, &d});
  std::size_t different = 0;
  const mpi_test::Points local_points = c.points->subset(layout.computed, layout.local_of, layout.local_count());
  for (solver::PointGroup group : solver::point_groups) {
    const std::size_t g = solver::index_of(group);
    const approx::ShapeFunctions& local = local_points.shape(group);
    for (std::size_t k = 0; k < layout.computed[g].size(); ++k) {
      const shell::SurfaceGradients serial = c.points->gather(group, layout.computed[g][k], x_global, d_global);
      shell::SurfaceGradients mine;
      for (std::size_t s = local.row_begin[k]; s < local.row_begin[k] + local.row_size[k]; ++s) {
        const int j = local.neighbour[s];
        mine.a1 += local.value[s].dphi_d1 * x[j];
        mine.a2 += local.value[s].dphi_d2 * x[j];
        mine.n += local.value[s].phi * d[j];
        mine.n1 += local.value[s].dphi_d1 * d[j];
        mine.n2 += local.value[s].dphi_d2 * d[j];
      }
      if (mine.a1 != serial.a1 || mine.a2 != serial.a2 || mine.n != serial.n || mine.n1 != serial.n1 ||
          mine.n2 != serial.n2)
        ++different;
    }
  }
  CHECK(different == 0);
}

}  // namespace

TEST_CASE("halo: a field of global ids round-trips into the ghosts on 1-3 ranks", "[mpi][halo]") {
  const mpi::Communicator comm;
  check_round_trip(comm, mpi_test::paper_plate(51));
  check_round_trip(comm, mpi_test::closed_tube(2.5e-3, 0.2));
  check_round_trip(comm, mpi_test::spherical_cap(25));
}

TEST_CASE("halo: bad input is an Error", "[mpi][halo][errors]") {
  const mpi::Communicator comm;
  const mpi_test::Case plate = mpi_test::paper_plate(11);
  const mpi::DecompositionInput input = plate.input();
  const mpi::Partition partition = mpi::partition(input, comm.size());
  const mpi::RankLayout layout = mpi::rank_layout(input, partition, comm.rank());
  const mpi::HaloPlan plan(comm, layout);
  std::vector<Vector3> short_field(layout.local_count() + 1, Vector3::Zero());
  mpi::HaloExchange exchange;
  CHECK_THROWS_WITH(exchange.exchange(comm, plan, {&short_field}),
                    Catch::Contains("halo field size = " + std::to_string(layout.local_count() + 1)));
  // A layout of another rank.
  const mpi::RankLayout other = mpi::rank_layout(input, partition, (comm.rank() + 1) % comm.size());
  if (comm.size() > 1)
    CHECK_THROWS_WITH(mpi::HaloPlan(comm, other), Catch::Contains("halo layout rank"));
  // Ranks whose partitions disagree: an owner is asked for a particle it
  // does not own; every rank stops with the same message.
  if (comm.size() > 1) {
    std::vector<int> owners = partition.particle_owner;
    if (comm.rank() == 0)
      for (int& owner : owners) owner = (owner + 1) % comm.size();
    const mpi::Partition skewed = mpi::partition_from_owners(input, comm.size(), owners);
    const mpi::RankLayout skewed_layout = mpi::rank_layout(input, skewed, comm.rank());
    std::string message;
    try {
      const mpi::HaloPlan bad(comm, skewed_layout);
    } catch (const Error& error) {
      message = error.what();
    }
    CHECK_THAT(message, Catch::Contains("which it does not own"));
    const std::vector<int> lengths = comm.all_gather(static_cast<int>(message.size()));
    for (int length : lengths) CHECK(length == static_cast<int>(message.size()));
  }
}

TEST_CASE("halo: after a crack rebuild the local rows still gather the serial values bitwise", "[mpi][halo]") {
  // A crack hides slots of rows; the rows keep their capacity, so the layout
  // made before the crack still holds every neighbour. A row is rebuilt on its
  // global form (as the serial solver does) and localised again.
  const mpi::Communicator comm;
  mpi_test::Case plate = mpi_test::paper_plate(31);
  const mpi::DecompositionInput input = plate.input();
  const mpi::Partition partition = mpi::partition(input, comm.size());
  const mpi::RankLayout layout = mpi::rank_layout(input, partition, comm.rank());
  const mpi::HaloPlan plan(comm, layout);
  // Hide every particle with an index divisible by 7 from the stress points
  // in the middle band of the plate (a crack-like cut of many rows).
  const solver::PointGroup group = solver::PointGroup::stress_points;
  const std::size_t g = solver::index_of(group);
  std::size_t rebuilt = 0;
  for (std::size_t row : layout.computed[g]) {
    const Vector3& at = plate.model.stress_point_position[row];
    if (std::abs(at.y() - 0.25) > 0.1) continue;
    plate.points->rebuild_row(plate.model, group, row, [](std::size_t, std::size_t j) { return j % 7 != 0; });
    ++rebuilt;
  }
  CHECK(rebuilt > 0);
  std::vector<Vector3> x_global(plate.model.particle_count()), d_global(plate.model.particle_count());
  for (std::size_t i = 0; i < x_global.size(); ++i) {
    x_global[i] = plate.model.particle_position[i] + 1e-4 * Vector3(std::sin(double(i)), 0.0, std::cos(0.5 * i));
    d_global[i] = plate.model.particle_normal[i];
  }
  std::vector<Vector3> x(layout.local_count(), Vector3::Zero()), d = x;
  for (std::size_t k = 0; k < layout.owned_count(); ++k) {
    x[k] = x_global[layout.owned[k]];
    d[k] = d_global[layout.owned[k]];
  }
  mpi::HaloExchange exchange;
  exchange.exchange(comm, plan, {&x, &d});
  const mpi_test::Points local_points =
      plate.points->subset(layout.computed, layout.local_of, layout.local_count());
  const approx::ShapeFunctions& local = local_points.shape(group);
  std::size_t different = 0, shrunk = 0;
  for (std::size_t k = 0; k < layout.computed[g].size(); ++k) {
    const std::size_t row = layout.computed[g][k];
    if (local.row_size[k] < static_cast<int>(local.capacity(k))) ++shrunk;
    const shell::SurfaceGradients serial = plate.points->gather(group, row, x_global, d_global);
    Vector3 a1 = Vector3::Zero(), n = Vector3::Zero();
    for (std::size_t s = local.row_begin[k]; s < local.row_begin[k] + local.row_size[k]; ++s) {
      a1 += local.value[s].dphi_d1 * x[local.neighbour[s]];
      n += local.value[s].phi * d[local.neighbour[s]];
    }
    if (a1 != serial.a1 || n != serial.n) ++different;
  }
  CHECK(shrunk > 0);
  CHECK(different == 0);
}
