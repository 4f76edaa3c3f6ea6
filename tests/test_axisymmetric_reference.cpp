// Trust tests of the axisymmetric reference solver (tests/support/
// axisymmetric_shell.hpp) before the spherical-cap validation uses it: static
// and dynamic closed forms of a pressurised sphere, the Mindlin clamped
// circular plate, the layer return map on closed-form strain paths, the
// energy balance of the cap runs, and its convergence in the meridian
// resolution on the cap. None of it touches the library.
#include "support/axisymmetric_shell.hpp"
#include "support/spherical_cap_case.hpp"

#include <catch2/catch.hpp>

#include <cmath>
#include <vector>

using namespace sphshell::test_support::axisymmetric;
namespace cap = sphshell::test_support::spherical_cap;

namespace {

// Aluminium-like sphere of the cap's radius and thickness.
constexpr double sphere_radius = 0.5657, sphere_thickness = 0.010414;
constexpr double aluminium_E = 72.4e9, aluminium_nu = 0.3, aluminium_rho = 2618.0;

ShellProperties aluminium(double thickness) {
  ShellProperties p;
  p.thickness = thickness;
  p.youngs_modulus = aluminium_E;
  p.poisson_ratio = aluminium_nu;
  p.density = aluminium_rho;
  return p;
}

// Membrane theory of a closed sphere under uniform pressure: N = pR/2 in
// every direction, so u = pR²(1−ν)/(2Ed) (radially inward).
double sphere_membrane_deflection(double p) {
  return p * sphere_radius * sphere_radius * (1.0 - aluminium_nu) / (2.0 * aluminium_E * sphere_thickness);
}
// Breathing frequency of a membrane sphere: ω² = 2E/(ρR²(1−ν)).
double sphere_breathing_frequency() {
  return std::sqrt(2.0 * aluminium_E / (aluminium_rho * sphere_radius * sphere_radius * (1.0 - aluminium_nu)));
}

// A hemisphere (a full sphere cut at its mirror plane, the equator) under
// uniform pressure along the reference normal.
AxisymmetricShell hemisphere(int elements, Kinematics kinematics, double damping) {
  RunOptions options;
  options.kinematics = kinematics;
  options.rim = RimSupport::equator_symmetry;
  options.pressure_direction = PressureDirection::reference_normal;
  options.damping = damping;
  return AxisymmetricShell(spherical_cap_meridian(sphere_radius, pi / 2, elements), aluminium(sphere_thickness), options);
}

}  // namespace

TEST_CASE("Axisymmetric reference: a pressurised sphere deflects by the membrane closed form",
          "[axisymmetric][reference]") {
  // Static state by dynamic relaxation: damping at half the critical value
  // of the breathing mode, 40 of its periods.
  const double p = 1e5, u = sphere_membrane_deflection(p), omega = sphere_breathing_frequency();
  for (Kinematics kinematics : {Kinematics::linear, Kinematics::geometrically_exact}) {
    AxisymmetricShell shell = hemisphere(96, kinematics, omega);
    shell.set_pressure(p);
    shell.run_until(40 * 2 * pi / omega);
    INFO("kinematics " << int(kinematics) << ": apex " << shell.apex_inward_displacement() / u
                       << " × closed form, equator " << -shell.radial_displacement(shell.nodes() - 1) / u);
    CHECK(shell.max_speed() < 1e-6 * omega * u);  // static: no oscillation left
    // Discretisation error O(h²): 3e-4 at the apex with 96 elements (7e-4 at
    // 64, 3e-3 at 32); the bending stiffness adds ~ d²/(12R²) ≈ 3e-5.
    CHECK(shell.apex_inward_displacement() == Approx(u).epsilon(5e-4));
    CHECK(-shell.radial_displacement(shell.nodes() - 1) == Approx(u).epsilon(5e-4));
    CHECK(std::abs(shell.rotation(shell.nodes() / 2)) < 1e-3 * u / sphere_radius);
  }
}

TEST_CASE("Axisymmetric reference: a sphere under step pressure breathes as u_s (1 − cos ωt)",
          "[axisymmetric][reference]") {
  // The uniform radial motion is the breathing eigenmode, so a step load
  // gives the peak 2 u_s at t = π/ω. Checks the masses, the time integration
  // and its start-up (a full first kick would make the peak 0.3 % early).
  const double p = 1e5, u = sphere_membrane_deflection(p), omega = sphere_breathing_frequency();
  for (Kinematics kinematics : {Kinematics::linear, Kinematics::geometrically_exact}) {
    AxisymmetricShell shell = hemisphere(96, kinematics, 0.0);
    shell.set_pressure(p);
    cap::History apex{{0.0}, {0.0}}, equator{{0.0}, {0.0}};
    shell.run_until(1.5 * pi / omega, [&](const AxisymmetricShell& s) {
      apex.time.push_back(s.time());
      apex.apex.push_back(s.apex_inward_displacement());
      equator.time.push_back(s.time());
      equator.apex.push_back(-s.radial_displacement(s.nodes() - 1));
    });
    for (const cap::History* h : {&apex, &equator}) {
      const cap::Peak peak = cap::first_peak(*h);
      INFO("kinematics " << int(kinematics) << ": peak " << peak.value / (2 * u) << " × 2 u_s at "
                         << peak.time * omega / pi << " × π/ω");
      REQUIRE(peak.found);
      CHECK(peak.value == Approx(2 * u).epsilon(5e-4));
      CHECK(peak.time == Approx(pi / omega).epsilon(5e-4));
    }
  }
}

TEST_CASE("Axisymmetric reference: a clamped circular plate matches the Mindlin closed form",
          "[axisymmetric][reference]") {
  // Mindlin plate, clamped edge r = a, uniform p:
  //   w(r) = p (a² − r²)² / (64 D) + p (a² − r²) / (4 κs G d),
  //   director tilt |β(r)| = p r (a² − r²) / (16 D).
  // a/d = 20 makes the shear term 1.1 % of the centre deflection, so a
  // Kirchhoff-only solver would fail the 2e-4 tolerance.
  const double a = 0.2, d = 0.01, E = 210e9, nu = 0.3, rho = 7850.0, p = 1e5, kappa = 5.0 / 6.0;
  const double D = E * d * d * d / (12 * (1 - nu * nu)), G = E / (2 * (1 + nu));
  auto mindlin = [&](double r) {
    return p * (a * a - r * r) * (a * a - r * r) / (64 * D) + p * (a * a - r * r) / (4 * kappa * G * d);
  };
  auto tilt = [&](double r) { return p * r * (a * a - r * r) / (16 * D); };
  const double kirchhoff_centre = p * a * a * a * a / (64 * D);
  REQUIRE(std::abs(mindlin(0.0) - kirchhoff_centre) > 0.01 * mindlin(0.0));
  const double omega1 = 10.2158 / (a * a) * std::sqrt(D / (rho * d));  // lowest clamped-plate mode
  for (Kinematics kinematics : {Kinematics::linear, Kinematics::geometrically_exact}) {
    ShellProperties properties;
    properties.thickness = d;
    properties.youngs_modulus = E;
    properties.poisson_ratio = nu;
    properties.density = rho;
    RunOptions options;
    options.kinematics = kinematics;
    options.pressure_direction = PressureDirection::reference_normal;
    options.damping = 2 * omega1;  // critical for the lowest mode
    const int elements = 100;
    AxisymmetricShell plate(circular_plate_meridian(a, elements), properties, options);
    plate.set_pressure(p);
    plate.run_until(10 * 2 * pi / omega1);
    const std::size_t half = elements / 2;  // node at r = a/2
    INFO("kinematics " << int(kinematics) << ": centre " << plate.apex_inward_displacement() / mindlin(0.0)
                       << " × Mindlin, r = a/2 " << -plate.axial_displacement(half) / mindlin(a / 2)
                       << ", tilt " << std::abs(plate.rotation(half)) / tilt(a / 2));
    CHECK(plate.max_speed() < 1e-6 * omega1 * mindlin(0.0));
    // The deflection w/d ≈ 0.013 makes the geometrically exact plate's
    // membrane stiffening ≈ 1e-5 of the deflection.
    CHECK(plate.apex_inward_displacement() == Approx(mindlin(0.0)).epsilon(2e-4));
    CHECK(-plate.axial_displacement(half) == Approx(mindlin(a / 2)).epsilon(2e-4));
    CHECK(std::abs(plate.rotation(half)) == Approx(tilt(a / 2)).epsilon(1e-3));
  }
}

namespace {

const PlaneStressJ2 cap_law(cap::youngs_modulus, cap::poisson_ratio, cap::yield_stress, cap::plastic_modulus);

// Drives one layer along ε_s = t·a_s, ε_θ = t·a_θ up to t = 1 in `steps`
// increments.
LayerState strain_path(double a_s, double a_theta, int steps) {
  LayerState state;
  for (int k = 0; k < steps; ++k) cap_law.update(state, a_s / steps, a_theta / steps);
  return state;
}

}  // namespace

TEST_CASE("Axisymmetric reference: the layer return map follows closed-form strain paths",
          "[axisymmetric][reference][material]") {
  const double E = cap::youngs_modulus, nu = cap::poisson_ratio, s0 = cap::yield_stress, H = cap::plastic_modulus;
  const double G = E / (2 * (1 + nu));
  const double strain = 10 * s0 / E;  // far into the plastic range
  for (int steps : {1, 7, 200}) {
    INFO(steps << " increments");
    {  // equibiaxial
      // σ_s = σ_θ = σ: ε = σ(1−ν)/E + ε̄ᵖ/2 and σ = σ_y0 + H ε̄ᵖ.
      const double sigma = (strain + s0 / (2 * H)) / ((1 - nu) / E + 1 / (2 * H));
      const LayerState state = strain_path(strain, strain, steps);
      CHECK(state.stress_s == Approx(sigma).epsilon(1e-11));
      CHECK(state.stress_theta == Approx(sigma).epsilon(1e-11));
      CHECK(state.plastic_strain == Approx((sigma - s0) / H).epsilon(1e-10));
    }
    {  // pure shear
      // σ_s = −σ_θ = τ: σ̄ = √3 τ, ε = τ(1+ν)/E + (√3/2) ε̄ᵖ.
      const double tau = (strain + std::sqrt(3.0) * s0 / (2 * H)) / (1 / (2 * G) + 1.5 / H);
      const LayerState state = strain_path(strain, -strain, steps);
      CHECK(state.stress_s == Approx(tau).epsilon(1e-11));
      CHECK(state.stress_theta == Approx(-tau).epsilon(1e-11));
      CHECK(state.plastic_strain == Approx((std::sqrt(3.0) * tau - s0) / H).epsilon(1e-10));
    }
  }
  {  // uniaxial stress, the hoop strain found so that σ_θ = 0
    // σ = σ_y0 + H ε̄ᵖ, ε_s = σ/E + ε̄ᵖ, ε_θ = −νσ/E − ε̄ᵖ/2: the bilinear
    // curve with tangent modulus Et = E H/(E + H) = 1.448 GPa.
    LayerState state;
    double hoop = 0.0;
    const int steps = 100;
    for (int k = 1; k <= steps; ++k) {
      const double target = strain * k / steps;
      const double previous_axial = strain * (k - 1) / steps;
      // Secant iteration on the hoop strain increment.
      double x0 = -nu * (target - previous_axial), x1 = -0.5 * (target - previous_axial);
      auto lateral_stress = [&](double x) {
        LayerState trial = state;
        cap_law.update(trial, target - previous_axial, x);
        return trial.stress_theta;
      };
      double f0 = lateral_stress(x0), f1 = lateral_stress(x1);
      for (int it = 0; it < 60 && std::abs(f1) > 1e-3; ++it) {
        const double x2 = x1 - f1 * (x1 - x0) / (f1 - f0);
        x0 = x1, f0 = f1, x1 = x2, f1 = lateral_stress(x1);
      }
      cap_law.update(state, target - previous_axial, x1);
      hoop += x1;
    }
    const double sigma = (strain + s0 / H) / (1 / E + 1 / H);
    CHECK(state.stress_s == Approx(sigma).epsilon(1e-9));
    CHECK(std::abs(state.stress_theta) < 1e-3);  // Pa
    CHECK(state.plastic_strain == Approx((sigma - s0) / H).epsilon(1e-8));
    CHECK(hoop == Approx(-nu * sigma / E - 0.5 * state.plastic_strain).epsilon(1e-8));
    CHECK(sigma == Approx(s0 + cap::tangent_modulus * (strain - s0 / E)).epsilon(1e-12));
  }
  {  // a non-proportional step ends on the yield surface with normal flow; unloading is elastic
    LayerState state = strain_path(2 * s0 / E, 0.0, 3);
    const LayerState before = state;
    const double d_s = -0.5 * s0 / E, d_t = 4 * s0 / E;
    const PlaneStressJ2::Update update = cap_law.update(state, d_s, d_t);
    REQUIRE(update.plastic);
    const double sigma_bar = PlaneStressJ2::equivalent_stress(state.stress_s, state.stress_theta);
    CHECK(sigma_bar == Approx(cap_law.yield_stress(state)).epsilon(1e-12));
    // Δεᵖ = Δε − C⁻¹Δσ must be parallel to ∂σ̄/∂σ ∝ (2σ_s − σ_θ, 2σ_θ − σ_s).
    const double ds = state.stress_s - before.stress_s, dt = state.stress_theta - before.stress_theta;
    const double plastic_s = d_s - (ds - nu * dt) / E, plastic_t = d_t - (dt - nu * ds) / E;
    const double normal_s = 2 * state.stress_s - state.stress_theta, normal_t = 2 * state.stress_theta - state.stress_s;
    CHECK(std::abs(plastic_s * normal_t - plastic_t * normal_s) <
          1e-10 * std::hypot(plastic_s, plastic_t) * std::hypot(normal_s, normal_t));
    // Plastic work σ:Δεᵖ = σ̄ Δε̄ᵖ.
    CHECK(update.dissipation == Approx(sigma_bar * (state.plastic_strain - before.plastic_strain)).epsilon(1e-9));
    LayerState unloaded = state;
    const PlaneStressJ2::Update back = cap_law.update(unloaded, -d_s * 0.1, -d_t * 0.1);
    CHECK_FALSE(back.plastic);
    CHECK(unloaded.plastic_strain == state.plastic_strain);
    CHECK(unloaded.stress_theta - state.stress_theta ==
          Approx(-0.1 * E / (1 - nu * nu) * (nu * d_s + d_t)).epsilon(1e-12));
  }
}

TEST_CASE("Axisymmetric reference: the cap runs balance their energy",
          "[axisymmetric][reference]") {
  // Elastic energy from the stresses, kinetic from the velocities, external
  // work from the loads: a nodal force that is not the gradient of the
  // strain energy breaks the balance (1 % off in one term of ∂κ_θ/∂β gives
  // 1e-3 of the external work), the leapfrog's own error is ≈ 5e-8.
  for (cap::Case c : {cap::Case::nonlinear_elastic, cap::Case::elastoplastic}) {
    RunOptions options;
    AxisymmetricShell shell(spherical_cap_meridian(cap::radius, cap::half_angle, 200), cap::reference_properties(c), options);
    shell.set_pressure(cap::pressure);
    double worst = 0.0;
    shell.run_until(cap::end_time, [&](const AxisymmetricShell& s) { worst = std::max(worst, std::abs(s.energies().balance())); });
    const Energies& e = shell.energies();
    INFO(cap::name(c) << ": kinetic " << e.kinetic << " J, elastic " << e.elastic << " J, plastic "
                      << e.plastic_dissipation << " J, external " << e.external_work << " J, worst balance " << worst);
    CHECK(e.external_work > 500.0);
    CHECK(worst < (c == cap::Case::elastoplastic ? 1e-4 : 1e-6) * e.external_work);
    if (c == cap::Case::elastoplastic) CHECK(e.plastic_dissipation > 0.5 * e.external_work);
  }
}

TEST_CASE("Axisymmetric reference: the cap's first apex peak converges in the meridian resolution",
          "[axisymmetric][reference][validation]") {
  // 200, 400, 800 elements: the first peak and its time must change by less
  // than 0.5 % between the two finest (measured: ≤ 0.003 % and ≤ 0.03 %).
  for (cap::Case c : {cap::Case::linear, cap::Case::nonlinear_elastic, cap::Case::elastoplastic}) {
    std::vector<cap::Peak> peaks;
    for (int elements : {200, 400, 800})
      peaks.push_back(cap::first_peak(cap::reference_history(c, elements, cap::Span::to_first_peak)));
    WARN(cap::name(c) << " reference first apex peak (200/400/800 elements): " << peaks[0].value * 1e3 << " / "
                      << peaks[1].value * 1e3 << " / " << peaks[2].value * 1e3 << " mm at " << peaks[0].time * 1e6
                      << " / " << peaks[1].time * 1e6 << " / " << peaks[2].time * 1e6 << " µs");
    for (const cap::Peak& p : peaks) REQUIRE(p.found);
    CHECK(peaks[1].value == Approx(peaks[2].value).epsilon(5e-3));
    CHECK(peaks[1].time == Approx(peaks[2].time).epsilon(5e-3));
    CHECK(peaks[0].value == Approx(peaks[2].value).epsilon(5e-3));
  }
}
