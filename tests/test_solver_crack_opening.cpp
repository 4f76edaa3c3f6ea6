// A centre crack in a sheet under remote tension, solved statically by dynamic
// relaxation: the opening at the crack centre against the closed form of
// linear elastic fracture mechanics, COD = 4σa/E (plane stress, infinite
// sheet; Westergaard), times the finite-width factor √sec(πa/W) (Feddersen).
// The discrete crack behaves as if about one spacing longer than drawn, so the
// opening converges at first order; the test checks the order and the
// extrapolated limit.
#include <sphshell/approx/mls.hpp>
#include <sphshell/crack/line_segments.hpp>
#include <sphshell/kernel/cubic_spline.hpp>
#include <sphshell/material/elastic.hpp>
#include <sphshell/solver.hpp>
#include <sphshell/thickness/gauss.hpp>

#include <catch2/catch.hpp>

#include <cmath>

using namespace sphshell;

namespace {

using CrackedSheet =
    Solver<approx::MLS<kernel::CubicSpline>, thickness::Gauss<2>, material::Elastic, crack::LineSegments>;

constexpr double width = 1.0, half_crack = 0.1, E = 210e9, nu = 0.3, d = 0.01, sigma = 10e6, rho = 7850.0;

// Crack opening at the centre divided by the closed form, on an nx × (nx + 1)
// grid (the extra row puts a stress-point row, and so the crack, at mid-height).
double opening_ratio(int nx) {
  const double spacing = width / (nx - 1), height = nx * spacing, mid = 0.5 * height;
  SolverOptions options;
  options.nonlinear = false;
  options.density = rho;
  options.rotary_inertia_scale = 100.0;  // rotations are fixed; only the step matters
  const double omega = M_PI * std::sqrt(E / (rho * (1 - nu * nu))) / (2 * height);
  options.damping = 2 * omega;  // near critical for the fundamental stretching mode
  CrackedSheet solver(ShellModel::rectangular_plate(width, height, nx, nx + 1, d), {E, nu}, options);
  const ShellModel& model = solver.model();
  solver.add_precrack({Vector3(0.5 - half_crack, mid, 0), Vector3(0.5 + half_crack, mid, 0)});
  REQUIRE(solver.precrack_stress_point_count() == static_cast<std::size_t>(std::lround(2 * half_crack / spacing)));

  // In-plane problem: no deflection, no rotation; symmetry about x = 0.5 and
  // one particle held in y against drift (its reaction is zero at equilibrium).
  const ParticleSet all = model.all_particles();
  solver.fix_translation(all, Vector3::UnitZ());
  solver.fix_rotation(all, Vector3::UnitX());
  solver.fix_rotation(all, Vector3::UnitY());
  ParticleSet centre_line;
  for (std::size_t i = 0; i < model.particle_count(); ++i)
    if (std::abs(model.particle_position[i].x() - 0.5) < 1e-9) centre_line.push_back(static_cast<int>(i));
  solver.fix_translation(centre_line, Vector3::UnitX());
  solver.fix_translation({model.nearest_particle(Vector3(0.5, 0.0, 0.0))}, Vector3::UnitY());
  // Remote stress σ as edge forces σ d × tributary length.
  for (std::size_t i = 0; i < model.particle_count(); ++i) {
    const Vector3& X = model.particle_position[i];
    const bool corner = X.x() < 1e-9 || X.x() > width - 1e-9;
    const double force = sigma * d * spacing * (corner ? 0.5 : 1.0);
    if (X.y() > height - 1e-9) solver.add_point_force({static_cast<int>(i)}, Vector3(0, force, 0));
    if (X.y() < 1e-9) solver.add_point_force({static_cast<int>(i)}, Vector3(0, -force, 0));
  }

  const int above = model.nearest_particle(Vector3(0.5, mid + 0.5 * spacing, 0));
  const int below = model.nearest_particle(Vector3(0.5, mid - 0.5 * spacing, 0));
  auto opening = [&] { return solver.displacement(above).y() - solver.displacement(below).y(); };
  const double period = 2 * M_PI / omega;
  double previous = 0.0;
  for (int k = 1; k <= 40; ++k) {
    solver.run_until(k * period);
    if (std::abs(opening() - previous) < 2e-5 * std::abs(opening())) break;
    previous = opening();
  }
  const double closed_form = 4 * sigma * half_crack / E * std::sqrt(1.0 / std::cos(M_PI * half_crack / width));
  return opening() / closed_form;
}

}  // namespace

TEST_CASE("Centre-cracked sheet: the crack opening converges to 4σa/E √sec(πa/W)", "[fracture][solver][validation]") {
  const double coarse = opening_ratio(21) - 1.0;  // spacing 50 mm: the crack spans 4 spacings
  const double fine = opening_ratio(41) - 1.0;    // spacing 25 mm: 8 spacings
  const double extrapolated = 2 * fine - coarse;  // first-order Richardson
  WARN("crack opening error: " << 100 * coarse << " % at 50 mm, " << 100 * fine << " % at 25 mm, extrapolated "
                               << 100 * extrapolated << " %");
  CHECK(coarse > 0.0);
  CHECK(fine > 0.0);
  CHECK(fine < 0.6 * coarse);  // first order: the error halves with the spacing
  CHECK(std::abs(extrapolated) < 0.05);
}
