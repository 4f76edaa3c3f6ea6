#pragma once
// The stable step of the central difference scheme (docs/method.md, "The
// stable step"): Δt ≤ 2/ω_max, with ω_max bounded from the wave speeds over
// the smallest particle distance Δ:
//   membrane  ω_m² = k c_m² / Δ²,   c_m² = E / (ρ (1 − ν²)),
//   rotation  ω_r² = (12 κs G / (ρ d²) + k c_m² / Δ²) / s_I + k c_s² / Δ²,   c_s² = κs G / ρ,
// where the rotational line is the director's oscillator (transverse shear
// stiffness κs G d and bending stiffness E d³/(12(1−ν²)) over Δ², against the
// rotary inertia ρ d³/12 scaled by s_I) plus the shear wave it couples to, and
// k = highest_mode_factor. ω_max² = ω_m² + ω_r²: on curved shells the
// membrane and rotation modes couple, and a run at 0.8 × the larger of the two
// alone went unstable on a thin tube with the two equal. The tests check the
// bound against the exact spectrum of the assembled system.
// With a varying thickness a particle's inertia follows its own thickness d_i
// while its stiffness comes from the integration points that reach it, the
// thickest of them D_i: with r = D_i / d_i the membrane and shear-wave terms
// scale by r, the transverse-shear term by r and the bending term by r³,
// particle by particle.

#include <sphshell/approx/neighbour_search.hpp>
#include <sphshell/shell/model.hpp>
#include <sphshell/solver/integration_points.hpp>
#include <sphshell/shell/local_spacing.hpp>
#include <sphshell/solver/options.hpp>
#include <sphshell/solver/section_states.hpp>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>
#include <vector>

namespace sphshell::solver {

// k in ω² = k c²/Δ²: covers the highest mode of a square grid with this
// approximation (8.0 measured for the membrane).
inline constexpr double highest_mode_factor = 9.0;

// Smallest distance between two particles that interact: on distorted grids
// (the corners of a spherical cap) it is shorter than the square root of the
// cell area. Pairs a cut separates (the coincident faces of a slit) do not count.
// Each particle's nearest neighbour is sought within two of its local
// spacings (shell/local_spacing.hpp); infinity when none lies that close.
inline double nearest_particle_distance(const ShellModel& model, const shell::CutVisibility& cuts) {
  const std::vector<double>& local = local_spacing(model).particle;
  std::vector<double> reach(local.size());
  for (std::size_t i = 0; i < local.size(); ++i) reach[i] = 2.0 * local[i];
  const approx::CellList cells(model.particle_position, sphshell::detail::model_checks::median(reach));
  double nearest = std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < model.particle_count(); ++i)
    cells.for_each_within(model.particle_position[i], reach[i], [&](int j, double distance_squared) {
      const auto other = static_cast<std::size_t>(j);
      if (other == i || std::sqrt(distance_squared) >= nearest) return;
      if (!cuts.empty() &&
          !cuts.visible(cuts.side_point(i), cuts.side_point(other), tangent_frame(model.particle_normal[i])))
        return;
      nearest = std::sqrt(distance_squared);
    });
  return nearest;
}

// Per particle: the thickest integration point whose row reaches it.
template <class Approx, class Rule, class Law>
std::vector<double> thickest_integration_point_reaching_each_particle(const ShellModel& model,
                                                                      const IntegrationPoints<Approx>& points,
                                                                      const SectionStates<Rule, Law>& states) {
  std::vector<double> thickest(model.particle_count(), 0.0);
  for (PointGroup group : point_groups)
    for (std::size_t row = 0; row < points.count(group); ++row) {
      const double d = states.section(points.point(group, row)).thickness();
      const approx::ShapeFunctions& shape = points.shape(group);
      const std::size_t end = shape.row_begin[row] + shape.row_size[row];
      for (std::size_t s = shape.row_begin[row]; s < end; ++s) {
        const auto j = static_cast<std::size_t>(shape.neighbour[s]);
        thickest[j] = std::max(thickest[j], d);
      }
    }
  return thickest;
}

template <class Approx, class Rule, class Law>
double stable_time_step(const ShellModel& model, const Law& law, const PhysicsOptions& physics,
                        const IntegrationPoints<Approx>& points, const SectionStates<Rule, Law>& states) {
  const double E = law.youngs_modulus(), nu = law.poisson_ratio();
  const double rho = physics.density;
  const double G = law.shear_modulus();
  const double spacing = std::min(model.minimum_spacing(), nearest_particle_distance(model, points.cuts()));
  const double membrane_speed_squared = E / (rho * (1.0 - nu * nu));
  const double shear_speed_squared = physics.shear_correction * G / rho;
  const double membrane = highest_mode_factor * membrane_speed_squared / (spacing * spacing);
  const double shear_wave = highest_mode_factor * shear_speed_squared / (spacing * spacing);
  const std::vector<double> stiffest = thickest_integration_point_reaching_each_particle(model, points, states);
  double omega_squared = 0.0;
  for (std::size_t i = 0; i < model.particle_count(); ++i) {
    const double d = model.particle_thickness(i);
    const double r = std::max(stiffest[i], d) / d;
    const double rotation =
        (12.0 * shear_speed_squared / (d * d) * r + membrane * r * r * r) / physics.rotary_inertia_scale +
        shear_wave * r;
    omega_squared = std::max(omega_squared, membrane * r + rotation);
  }
  return 2.0 / std::sqrt(omega_squared);
}

}  // namespace sphshell::solver
