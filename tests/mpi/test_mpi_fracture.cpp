// Fracture across rank boundaries (docs/distributed.md, "Fracture"): the
// paper's clamped plate tearing (Lemaitre damage, line-segment cracks) and a
// pre-cracked strip pulled apart, run by the serial Solver (on every rank, the
// independent reference) and by mpi::DistributedSolver. The crack topology
// (segments, damaged stress points, fragments) must be the serial one on every
// rank, and the motion bitwise the serial one.
#include <sphshell/approx/mls.hpp>
#include <sphshell/crack/line_segments.hpp>
#include <sphshell/kernel/cubic_spline.hpp>
#include <sphshell/material/lemaitre_damage.hpp>
#include <sphshell/mpi/distributed_solver.hpp>
#include <sphshell/solver.hpp>
#include <sphshell/thickness/gauss.hpp>

#include "mpi_test_support.hpp"

#include <catch2/catch.hpp>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

using namespace sphshell;

namespace {

using Approximation = approx::MLS<kernel::CubicSpline>;
using Serial = Solver<Approximation, thickness::Gauss<3>, material::LemaitreDamage, crack::LineSegments>;
using Distributed = mpi::DistributedSolver<Approximation, thickness::Gauss<3>, material::LemaitreDamage, crack::LineSegments>;
const material::LemaitreDamage::Parameters table_3_steel{210e9, 0.3, 235e6, 0.0, 0.02, 0.37, 0.24};

void compare(const std::string& label, const Serial& serial, Distributed& distributed, const mpi::Communicator& comm) {
  INFO(label << " on " << comm.size() << " ranks, rank " << comm.rank() << ", step " << serial.steps());
  CHECK(distributed.steps() == serial.steps());
  CHECK(mpi_test::differing_components(distributed.positions(), serial.positions()) == 0);
  CHECK(mpi_test::differing_components(distributed.directors(), serial.directors()) == 0);
  CHECK(mpi_test::differing_components(distributed.velocities(), serial.velocities()) == 0);
  CHECK(mpi_test::differing_components(distributed.angular_velocities(), serial.angular_velocities()) == 0);
  CHECK(distributed.crack().segments() == serial.crack().segments());
  CHECK(distributed.crack().points() == serial.crack().points());
  CHECK(distributed.damaged_stress_point_count() == serial.damaged_stress_point_count());
  CHECK(distributed.precrack_stress_point_count() == serial.precrack_stress_point_count());
  CHECK(distributed.fragment_count() == serial.fragment_count());
  std::size_t fragment_differences = 0;
  for (std::size_t i = 0; i < serial.particle_count(); ++i)
    fragment_differences += distributed.is_fragment(static_cast<int>(i)) != serial.is_fragment(static_cast<int>(i));
  CHECK(fragment_differences == 0);
  const EnergyReport e = distributed.energy(), s = serial.energy();
  const double scale = std::max({s.external_work, s.kinetic, s.internal});
  CHECK(std::abs(e.released_by_fracture - s.released_by_fracture) <= 1e-12 * scale);
  CHECK(std::abs(e.internal - s.internal) <= 1e-12 * std::abs(s.internal));
  CHECK(std::abs(e.kinetic - s.kinetic) <= 1e-12 * s.kinetic);
  if (comm.is_root())
    WARN(label << " on " << comm.size() << " ranks, step " << serial.steps() << ": "
               << serial.damaged_stress_point_count() << " damaged stress points, "
               << serial.crack().segments().size() << " segments, " << serial.fragment_count()
               << " fragments; released " << s.released_by_fracture << " J (distributed "
               << e.released_by_fracture << " J)");
}

}  // namespace

TEST_CASE("Distributed tearing plate: the serial crack topology on every rank", "[mpi][fracture]") {
  // The paper's plate, 21 x 21, clamped, 12 MPa (tests/test_solver_fracture.cpp).
  const mpi::Communicator comm;
  const ShellModel model = ShellModel::rectangular_plate(0.5, 0.5, 21, 21, 0.01);
  Serial serial(model, table_3_steel);
  serial.clamp(model.set("boundary"));
  serial.add_uniform_pressure(model.all_particles(), 12e6);
  Distributed distributed(comm, model, table_3_steel);
  distributed.clamp("boundary");
  distributed.add_uniform_pressure(model.all_particles(), 12e6);
  const double end_time = 1.3e-3;
  bool compared_at_first_crack = false;
  // A checkpoint mid-tear (a few crack segments), for the restart below.
  namespace fs = std::filesystem;
  const std::string folder =
      (fs::temp_directory_path() / ("sphshell_test_mpi_fracture_np" + std::to_string(comm.size()))).string();
  if (comm.is_root()) fs::create_directories(folder);
  comm.all_gather(0);
  const std::string checkpoint = folder + "/mid_tear";
  long saved_at = -1;
  while (serial.time() < end_time - 0.5 * serial.time_step()) {
    serial.step();
    distributed.step();
    if (!compared_at_first_crack && serial.damaged_stress_point_count() > 0) {
      compare("tearing plate, first damage", serial, distributed, comm);
      compared_at_first_crack = true;
    }
    if (saved_at < 0 && serial.crack().segments().size() >= 4) {
      distributed.save_checkpoint(checkpoint);
      saved_at = distributed.steps();
    }
  }
  CHECK(compared_at_first_crack);
  CHECK(serial.crack().segments().size() > 10);  // the cracks grew
  // The cracks cross rank boundaries: damaged stress points owned by more
  // than one rank.
  int damaged_here = 0;
  const mpi::RankLayout& layout = distributed.layout();
  for (std::size_t k = 0; k < layout.computed[0].size(); ++k)
    if (layout.computed_is_owned[0][k] && serial.crack().is_damaged(static_cast<int>(layout.computed[0][k])))
      ++damaged_here;
  int ranks_with_damage = 0;
  for (int count : comm.all_gather(damaged_here)) ranks_with_damage += count > 0 ? 1 : 0;
  CHECK(ranks_with_damage == comm.size());
  compare("tearing plate", serial, distributed, comm);

  // The same solver (its rows rebuilt by the cracks since) back to the
  // checkpoint: the rows, crack set, flags and books of mid-tear, then on to
  // the same end.
  REQUIRE(saved_at > 0);
  distributed.load_checkpoint(checkpoint);
  CHECK(distributed.steps() == saved_at);
  CHECK(distributed.crack().segments().size() < serial.crack().segments().size());
  while (distributed.steps() < serial.steps()) distributed.step();
  compare("tearing plate, restarted mid-tear", serial, distributed, comm);
  comm.all_gather(0);
  if (comm.is_root()) fs::remove_all(folder);
}

TEST_CASE("Distributed pre-cracked strip separates as the serial one", "[mpi][fracture]") {
  // 0.2 m x 0.1 m strip clamped at x = 0, pulled at x = 0.2 m, a through
  // pre-crack at x = 0.105 m (tests/test_solver_fracture.cpp).
  const mpi::Communicator comm;
  const ShellModel model = ShellModel::rectangular_plate(0.2, 0.1, 21, 11, 0.005);
  const std::vector<Vector3> precrack{Vector3(0.105, -0.002, 0.0), Vector3(0.105, 0.102, 0.0)};
  auto pull = [](const Vector3&, double) { return Vector3(2.0, 0.0, 0.0); };
  Serial serial(model, table_3_steel);
  serial.add_precrack(precrack);
  serial.clamp(model.set("x_min"));
  serial.prescribe_velocity(model.set("x_max"), pull);
  // Frames of the distributed run: one written at the end (output_interval 0).
  namespace fs = std::filesystem;
  const std::string folder =
      (fs::temp_directory_path() / ("sphshell_test_mpi_strip_np" + std::to_string(comm.size()))).string();
  SolverOptions options;
  options.output_directory = folder;
  Distributed distributed(comm, model, table_3_steel, options);
  distributed.add_precrack(precrack);
  distributed.clamp("x_min");
  distributed.prescribe_velocity(model.set("x_max"), pull);
  CHECK(serial.precrack_stress_point_count() > 0);
  serial.run_until(2e-4);
  distributed.run_until(2e-4);
  compare("pre-cracked strip", serial, distributed, comm);
  // The crack frame: rank 0 writes the whole crack set as lines, listed in cracks.pvd.
  distributed.write_frame();
  if (comm.is_root()) {
    std::ifstream frame(folder + "/cracks_000000.vtu"), series(folder + "/cracks.pvd");
    std::stringstream frame_text, series_text;
    frame_text << frame.rdbuf();
    series_text << series.rdbuf();
    CHECK(frame_text.str().find("NumberOfCells=\"" + std::to_string(serial.crack().segments().size()) + "\"") !=
          std::string::npos);
    CHECK(series_text.str().find("cracks_000000.vtu") != std::string::npos);
    CHECK(fs::exists(folder + "/stress_points_000000.pvtu"));
  }
  comm.all_gather(0);
  if (comm.is_root()) fs::remove_all(folder);
}
