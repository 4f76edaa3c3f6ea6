#pragma once
// The standard shell benchmarks as static problems (sphshell/statics/path_following.hpp):
// geometry, material, conditions, loads, the reported displacement and its
// published reference. Shared by test_validation_benchmarks and the
// shell_benchmarks example.
//
// Linear ("obstacle course": MacNeal & Harder, Finite Elements in Analysis and
// Design 1 (1985) 3–20; Belytschko et al., CMAME 51 (1985) 221–258):
//   Scordelis–Lo roof, pinched hemisphere with an 18° hole, pinched cylinder
//   with rigid end diaphragms.
// Geometrically nonlinear (Sze, Liu & Lo, Finite Elements in Analysis and
// Design 40 (2004) 1551–1569): cantilever under end shear, cantilever rolled
// up by an end moment. Their references are computed here (the elastica by
// shooting, the circle in closed form). Also from that paper, against its
// tables: the slit annular plate (§3.3), the hemisphere with an 18° hole under
// alternating forces (§3.4), the pull-out of an open-ended cylinder (§3.5),
// the pinched cylinder on rigid diaphragms (§3.6) and the hinged cylindrical
// roof's snap-through and snap-back (§3.8, its whole path).
//
// The inputs are the benchmarks' own numbers; they are unit-consistent (any
// consistent system), so they go into the SI-labelled solver unchanged.


#include <sphshell/approx/mls.hpp>
#include <sphshell/kernel/cubic_spline.hpp>
#include <sphshell/shell/model.hpp>
#include <sphshell/statics/path_following.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <functional>
#include <limits>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

namespace sphshell::test_support {

inline constexpr double benchmark_pi = 3.14159265358979323846;

// Particles on an nu × nv parametric grid on [0,1]², stress points at the cell
// centres on the exact surface; surface(u, v) returns {position, unit normal}
// and must run counter-clockwise (∂x/∂u × ∂x/∂v along the normal).
template <class Surface>
ShellModel structured_surface(int nu, int nv, Surface&& surface, double thickness) {
  std::vector<Vector3> positions, normals, centres, centre_normals;
  for (int j = 0; j < nv; ++j)
    for (int i = 0; i < nu; ++i) {
      const auto point = surface(static_cast<double>(i) / (nu - 1), static_cast<double>(j) / (nv - 1));
      positions.push_back(point.first);
      normals.push_back(point.second);
    }
  std::vector<Quad> quads;
  for (int j = 0; j + 1 < nv; ++j)
    for (int i = 0; i + 1 < nu; ++i) {
      quads.push_back({j * nu + i, j * nu + i + 1, (j + 1) * nu + i + 1, (j + 1) * nu + i});
      const auto centre = surface((i + 0.5) / (nu - 1), (j + 0.5) / (nv - 1));
      centres.push_back(centre.first);
      centre_normals.push_back(centre.second);
    }
  return ShellModel::from_quads(std::move(positions), std::move(normals), quads, std::move(centres),
                                std::move(centre_normals), thickness);
}

// Weights of particles' values, Σ w_j u_j: a particle itself, or the
// approximation's value at a point.
using ParticleWeights = std::vector<std::pair<int, double>>;

// The approximation's shape functions Φ_j at a point of the surface (unit
// normal `normal`), as the solver builds them (support radius factor ×
// ShellModel::maximum_spacing()). A point force P there does the work
// P · Σ Φ_j u_j: its consistent particle forces are Φ_j P, and the
// displacement under it is Σ Φ_j u_j. With a non-interpolating approximation
// (MLS) a particle's own displacement is not the field's value at the particle.
template <class Approx = approx::MLS<kernel::CubicSpline>>
ParticleWeights shape_function_weights(const ShellModel& model, const Vector3& point, const Vector3& normal,
                                       double support_radius_factor = 2.0) {
  const double h = support_radius_factor * model.maximum_spacing() / Approx::kernel_type::support_radius_factor;
  const approx::ShapeFunctions sf =
      Approx::build(model.particle_position, model.particle_area, {point}, {tangent_frame(normal)}, h);
  ParticleWeights weights;
  for (int k = 0; k < sf.row_size[0]; ++k) weights.push_back({sf.neighbour[k], sf.value[k].phi});
  return weights;
}

// How a point force is applied and its displacement read.
enum class PointLoad {
  particle,         // on the particle at the point, which reports its own displacement
  shape_functions,  // consistently: shared as Φ_j P, the displacement read as Σ Φ_j u_j
};

// A static benchmark: the model, its material, conditions and loads at load
// factor 1, and the displacement reported: Σ w_j u_j · direction.
struct StaticBenchmark {
  std::string name;
  ShellModel model;
  double E, nu;
  statics::Conditions conditions;
  ParticleWeights probe;
  Vector3 direction;
  double reference;  // the published (or closed-form) value of the reported displacement
};

// A point force at particle `at` (on the model's surface), applied as `how` says;
// returns the weights that read the displacement under it.
inline ParticleWeights add_point_force(const ShellModel& model, statics::Conditions& conditions, int at,
                                       const Vector3& force, PointLoad how, double support_radius_factor = 2.0) {
  ParticleWeights weights = {{at, 1.0}};
  if (how == PointLoad::shape_functions)
    weights = shape_function_weights(model, model.particle_position[at], model.particle_normal[at],
                                     support_radius_factor);
  for (const auto& [particle, weight] : weights) conditions.add_force({particle}, weight * force);
  return weights;
}

// The reported displacement of a solved benchmark.
template <class Solver>
double reported_displacement(const StaticBenchmark& benchmark, const Solver& solver) {
  double value = 0.0;
  for (const auto& [particle, weight] : benchmark.probe)
    value += weight * (solver.positions()[particle] - benchmark.model.particle_position[particle]).dot(benchmark.direction);
  return value;
}

// Scordelis–Lo roof: a cylindrical panel (R = 25, L = 50, 80° opening, t =
// 0.25, E = 4.32e8, ν = 0) on rigid end diaphragms (no translation in their
// plane), free long edges, under its weight 90 per unit area. Reported: the
// vertical displacement at the midpoint of a free edge. Reference 0.3024
// (MacNeal & Harder 1985; the deep-shell value is 0.3086, Belytschko et al. 1985).
// The whole roof, n × n particles (n odd), the axis along z.
inline StaticBenchmark scordelis_lo_roof(int n) {
  const double R = 25.0, L = 50.0, angle = 80.0 * benchmark_pi / 180.0, t = 0.25;
  ShellModel model = ShellModel::cylindrical_panel(R, L, angle, n, n, t);
  statics::Conditions conditions(model.particle_count());
  for (const char* end : {"z_min", "z_max"}) {
    conditions.hold_translation(model.set(end), Vector3::UnitX());
    conditions.hold_translation(model.set(end), Vector3::UnitY());
  }
  // The diaphragms leave the roof free to slide along its axis (a rigid
  // translation the tangent's start check refuses); the mid-span section
  // z = L/2 is a symmetry plane of the roof and its load, where u_z = 0.
  ParticleSet mid_span;
  for (int i = 0; i < n; ++i) mid_span.push_back((n - 1) / 2 * n + i);
  conditions.hold_translation(mid_span, Vector3::UnitZ());
  // The panel spans 0…80° from the x-axis: its crown (vertical) is at 40°.
  const Vector3 up(std::cos(angle / 2), std::sin(angle / 2), 0.0);
  const double weight = 90.0;
  for (std::size_t i = 0; i < model.particle_count(); ++i)
    conditions.force[i] = -weight * model.particle_area[i] * up;
  const int probe = (n - 1) / 2 * n;  // θ = 0, z = L/2
  return {"Scordelis-Lo roof", std::move(model), 4.32e8, 0.0, std::move(conditions), {{probe, 1.0}}, -up, 0.3024};
}

// Pinched hemisphere with an 18° hole (R = 10, t = 0.04, E = 6.825e7, ν =
// 0.3): radial forces 2 outward on the x-axis and inward on the y-axis (one
// quarter modelled: 1 each), free edges. Reported: the radial displacement
// under the outward load. Reference 0.094 (MacNeal & Harder 1985).
// Quarter 0 ≤ φ ≤ 90° with symmetry planes, n × n particles; one particle's
// z-translation is held (the z rigid motion; its reaction is zero).
inline StaticBenchmark pinched_hemisphere(int n, PointLoad how = PointLoad::particle) {
  const double R = 10.0, t = 0.04, hole = 18.0 * benchmark_pi / 180.0;
  auto surface = [&](double u, double v) {
    const double azimuth = u * benchmark_pi / 2;
    const double polar = benchmark_pi / 2 - v * (benchmark_pi / 2 - hole);
    const Vector3 normal(std::sin(polar) * std::cos(azimuth), std::sin(polar) * std::sin(azimuth), std::cos(polar));
    return std::make_pair(Vector3(R * normal), normal);
  };
  ShellModel model = structured_surface(n, n, surface, t);
  statics::Conditions conditions(model.particle_count());
  ParticleSet xz_plane, yz_plane;
  for (int j = 0; j < n; ++j) {
    xz_plane.push_back(j * n);
    yz_plane.push_back(j * n + n - 1);
  }
  conditions.symmetry_plane(xz_plane, Vector3::UnitY());
  conditions.symmetry_plane(yz_plane, Vector3::UnitX());
  const int on_x = 0, on_y = n - 1;
  conditions.hold_translation({on_x}, Vector3::UnitZ());
  ParticleWeights probe = add_point_force(model, conditions, on_x, Vector3(1.0, 0.0, 0.0), how);
  add_point_force(model, conditions, on_y, Vector3(0.0, -1.0, 0.0), how);
  return {"Pinched hemisphere", std::move(model), 6.825e7, 0.3, std::move(conditions), probe, Vector3::UnitX(), 0.094};
}

// Pinched cylinder with rigid end diaphragms (R = 300, L = 600, t = 3, E =
// 3e6, ν = 0.3): two opposite radial forces P = 1 at mid-length. Reported:
// the radial displacement under the load. Reference 1.8248e-5 (the
// thin-shell series solution, MacNeal & Harder 1985; Belytschko et al. 1985).
// One octant (0 ≤ θ ≤ 90°, 0 ≤ z ≤ L/2) with symmetry planes, n × n particles;
// the octant carries P/4.
inline StaticBenchmark pinched_cylinder(int n, PointLoad how = PointLoad::particle) {
  const double R = 300.0, L = 600.0, t = 3.0, P = 1.0;
  ShellModel model = ShellModel::cylindrical_panel(R, L / 2, benchmark_pi / 2, n, n, t);
  statics::Conditions conditions(model.particle_count());
  conditions.hold_translation(model.set("z_min"), Vector3::UnitX());
  conditions.hold_translation(model.set("z_min"), Vector3::UnitY());
  conditions.symmetry_plane(model.set("z_max"), Vector3::UnitZ());
  conditions.symmetry_plane(model.set("theta_min"), Vector3::UnitY());
  conditions.symmetry_plane(model.set("theta_max"), Vector3::UnitX());
  const int probe = (n - 1) * n;  // θ = 0, z = L/2
  const ParticleWeights weights = add_point_force(model, conditions, probe, Vector3(-P / 4, 0.0, 0.0), how);
  return {"Pinched cylinder", std::move(model), 3e6, 0.3, std::move(conditions), weights, -Vector3::UnitX(), 1.8248e-5};
}

// The cantilever strips of Sze, Liu & Lo (2004), §2.1–2.2: length L, width b
// = 1, t = 0.1, E = 1.2e6, ν = 0, clamped at x = 0; nx × ny particles. The end
// load is shared by the tip particles in proportion to their share of the
// edge (trapezoidal: half at the two corners).
struct CantileverStrip {
  ShellModel model;
  statics::Conditions conditions;
  ParticleSet tip;
  int tip_mid;  // the tip particle on the centre line (ny odd)
  double L, EI;
};
inline CantileverStrip cantilever_strip(double L, int nx, int ny) {
  const double b = 1.0, t = 0.1, E = 1.2e6;
  ShellModel model = ShellModel::rectangular_plate(L, b, nx, ny, t);
  statics::Conditions conditions(model.particle_count());
  conditions.clamp(model.set("x_min"));
  const ParticleSet tip = model.set("x_max");
  return {std::move(model), std::move(conditions), tip, (ny - 1) / 2 * nx + nx - 1, L, E * b * t * t * t / 12.0};
}
// The shares of an edge load on the tip particles (ordered along y).
inline std::vector<double> edge_shares(int ny) {
  std::vector<double> share(ny, 1.0 / (ny - 1));
  share.front() = share.back() = 0.5 / (ny - 1);
  return share;
}

// The elastica of a cantilever (EI, length L) under a dead transverse tip force
// P: θ'' = −(P/EI) cos θ, θ(0) = 0, θ'(L) = 0, by shooting on θ'(0) with RK4
// (4000 steps) and bisection. Returns the tip's {u = L − x, w} (the
// shortening along the axis and the transverse deflection).
struct TipDisplacement {
  double u, w;
};
inline TipDisplacement elastica_tip(double P, double EI, double L) {
  const int steps = 4000;
  const double h = L / steps, k = P / EI;
  // State (θ, θ', x, w) along the arc length.
  auto integrate = [&](double curvature0, double& end_curvature, double& x, double& w) {
    Eigen::Vector4d y(0.0, curvature0, 0.0, 0.0);
    auto f = [&](const Eigen::Vector4d& s) {
      return Eigen::Vector4d(s[1], -k * std::cos(s[0]), std::cos(s[0]), std::sin(s[0]));
    };
    for (int i = 0; i < steps; ++i) {
      const Eigen::Vector4d k1 = f(y), k2 = f(y + 0.5 * h * k1), k3 = f(y + 0.5 * h * k2), k4 = f(y + h * k3);
      y += h / 6.0 * (k1 + 2.0 * k2 + 2.0 * k3 + k4);
    }
    end_curvature = y[1];
    x = y[2];
    w = y[3];
  };
  // θ'(0) lies in (0, k L]: the root curvature is at most the linear one, P L / EI.
  double low = 0.0, high = k * L, x = 0.0, w = 0.0, end = 0.0;
  for (int i = 0; i < 200 && high - low > 1e-15 * k * L; ++i) {
    const double mid = 0.5 * (low + high);
    integrate(mid, end, x, w);
    // θ'(L) rises with θ'(0) here (one root on this bracket for a cantilever).
    (end > 0.0 ? high : low) = mid;
  }
  integrate(0.5 * (low + high), end, x, w);
  return {L - x, w};
}

// The tip of a cantilever (EI, length L) bent by an end moment M: a circular
// arc of radius EI/M; the tip's shortening u and deflection w. M = 2πEI/L
// closes the circle (u = L, w = 0).
inline TipDisplacement circle_tip(double M, double EI, double L) {
  if (M == 0.0) return {0.0, 0.0};
  const double radius = EI / M;
  return {L - radius * std::sin(L / radius), radius * (1.0 - std::cos(L / radius))};
}

// Sze, Liu & Lo (2004), §3.1, cantilever under end shear (L = 10, b = 1,
// t = 0.1, E = 1.2e6, ν = 0, P_max = 4): the paper's tabulated tip W and −U
// at P/P_max = 0.05, 0.10, …, 1 (a converged ABAQUS S4R mesh).
struct TabulatedPoint {
  double load_factor;  // P / P_max
  double first, second;
};
// A table at P/P_max = 0.05, 0.10, …, 1 from its two columns.
inline std::vector<TabulatedPoint> table_in_twentieths(const double (&first)[20], const double (&second)[20]) {
  std::vector<TabulatedPoint> table;
  for (int k = 0; k < 20; ++k) table.push_back({0.05 * (k + 1), first[k], second[k]});
  return table;
}
inline std::vector<TabulatedPoint> sze_end_shear_table() {
  const double w[] = {0.663, 1.309, 1.922, 2.493, 3.015, 3.488, 3.912, 4.292, 4.631, 4.933,
                      5.202, 5.444, 5.660, 5.855, 6.031, 6.190, 6.335, 6.467, 6.588, 6.698};
  const double u[] = {0.026, 0.103, 0.224, 0.381, 0.563, 0.763, 0.971, 1.184, 1.396, 1.604,
                      1.807, 2.002, 2.190, 2.370, 2.541, 2.705, 2.861, 3.010, 3.151, 3.286};
  return table_in_twentieths(w, u);
}

// A cantilever strip (tests' Sze cases) solved at the given load factors: the
// tip's centre-line shortening −u and deflection |w| at each.
struct CantileverPoint {
  double load_factor, u, w;
};
enum class EndLoad { shear, moment };
struct CantileverRun {
  std::vector<CantileverPoint> points;
  statics::NewtonReport report;
  double L = 0.0, EI = 0.0, full_load = 0.0;  // P_max = 4, or M_max = 2πEI/L
};
// End shear: L = 10, P_max = 4 along +z. End moment: L = 12, M_max = 2πEI/L
// about −y (the strip rolls up toward +z). Load steps of at most `step`.
template <class NonlinearSolver>
CantileverRun run_cantilever(EndLoad load, int nx, int ny, const std::vector<double>& factors, double step) {
  CantileverStrip strip = cantilever_strip(load == EndLoad::shear ? 10.0 : 12.0, nx, ny);
  const std::vector<double> share = edge_shares(ny);
  const double full = load == EndLoad::shear ? 4.0 : 2.0 * benchmark_pi * strip.EI / strip.L;
  for (int k = 0; k < ny; ++k) {
    if (load == EndLoad::shear)
      strip.conditions.add_force({strip.tip[k]}, Vector3(0.0, 0.0, full * share[k]));
    else
      strip.conditions.add_moment({strip.tip[k]}, Vector3(0.0, -full * share[k], 0.0));
  }
  NonlinearSolver solver(strip.model, {1.2e6, 0.0});
  statics::PathFollower<NonlinearSolver> statics(solver, strip.conditions);
  CantileverRun run{{}, {}, strip.L, strip.EI, full};
  for (double factor : factors) {
    statics.solve_to(factor, step);
    const Vector3 u = statics.displacement(strip.tip_mid);
    run.points.push_back({factor, -u.x(), std::abs(u.z())});
  }
  run.report = statics.report();
  return run;
}

// Sze, Liu & Lo (2004), §3.3, slit annular plate: inner radius 6, outer 10,
// t = 0.03, E = 21e6, ν = 0, clamped along one face of a radial slit, a
// transverse line force q (q_max = 0.8, P_max = 0.8 × 4 = 3.2) on the other
// face. The slit's faces are duplicated particles (the grid's first and last
// rows, at θ = 0 and 2π) separated by a cut (ShellModel::add_cut) run half a
// spacing past both edges. n_radial × n_circumferential particles.
struct SlitAnnularPlate {
  ShellModel model;
  statics::Conditions conditions;
  int inner, outer;  // points A (r = 6) and B (r = 10) of the loaded face
};
inline SlitAnnularPlate slit_annular_plate(int n_radial, int n_circumferential) {
  const double inner_radius = 6.0, outer_radius = 10.0, t = 0.03, q_max = 0.8;
  auto surface = [&](double u, double v) {
    const double r = inner_radius + u * (outer_radius - inner_radius), theta = 2.0 * benchmark_pi * v;
    return std::make_pair(Vector3(r * std::cos(theta), r * std::sin(theta), 0.0), Vector3::UnitZ());
  };
  ShellModel model = structured_surface(n_radial, n_circumferential, surface, t);
  const double half_spacing = 0.5 * (outer_radius - inner_radius) / (n_radial - 1);
  model.add_cut({Vector3(inner_radius - half_spacing, 0.0, 0.0), Vector3(outer_radius + half_spacing, 0.0, 0.0)});
  statics::Conditions conditions(model.particle_count());
  ParticleSet clamped, loaded;
  for (int i = 0; i < n_radial; ++i) {
    clamped.push_back(i);
    loaded.push_back((n_circumferential - 1) * n_radial + i);
  }
  conditions.clamp(clamped);
  const std::vector<double> share = edge_shares(n_radial);
  const double P_max = q_max * (outer_radius - inner_radius);
  for (int i = 0; i < n_radial; ++i) conditions.add_force({loaded[i]}, Vector3(0.0, 0.0, P_max * share[i]));
  return {std::move(model), std::move(conditions), loaded.front(), loaded.back()};
}

// Its tabulated reference (Sze, Liu & Lo 2004, §3.3, the table of W_A and
// W_B): P/P_max, W_A (inner), W_B (outer); the paper's points at 0.025 and
// 0.1 … 1.
inline std::vector<TabulatedPoint> sze_slit_annular_plate_table() {
  return {{0.025, 1.305, 1.789}, {0.10, 4.277, 5.876},  {0.20, 6.725, 9.160},  {0.30, 8.340, 11.213},
          {0.40, 9.529, 12.661}, {0.50, 10.468, 13.768}, {0.60, 11.257, 14.674}, {0.70, 11.970, 15.469},
          {0.80, 12.642, 16.202}, {0.90, 13.282, 16.886}, {1.00, 13.891, 17.528}};
}

// The slit plate solved at the table's load factors up to `last_factor`: W_A and W_B at each.
struct SlitPlateRun {
  std::vector<TabulatedPoint> points;  // load factor, W_A, W_B
  statics::NewtonReport report;
};
template <class NonlinearSolver>
SlitPlateRun run_slit_annular_plate(int n_radial, int n_circumferential, double step, double last_factor = 1.0) {
  SlitAnnularPlate plate = slit_annular_plate(n_radial, n_circumferential);
  NonlinearSolver solver(plate.model, {21e6, 0.0});
  statics::PathFollower<NonlinearSolver> statics(solver, plate.conditions);
  SlitPlateRun run;
  for (const TabulatedPoint& point : sze_slit_annular_plate_table()) {
    if (point.load_factor > last_factor + 1e-12) break;
    statics.solve_to(point.load_factor, step);
    run.points.push_back(
        {point.load_factor, statics.displacement(plate.inner).z(), statics.displacement(plate.outer).z()});
  }
  run.report = statics.report();
  return run;
}


// Sze, Liu & Lo (2004), §3.4, the hemisphere with an 18° hole (the pinched
// hemisphere's geometry and material, R = 10, t = 0.04, E = 6.825e7,
// ν = 0.3) under four alternating radial point forces on the equator, P_max =
// 400 each: pulled outward on the x-axis, pushed inward on the y-axis. The
// quarter of pinched_hemisphere (n × n particles, symmetry planes, one
// z-translation held) with P/2 = 200 at each of its two load points at load
// factor 1, applied through the shape functions.
struct SzeHemisphere {
  ShellModel model;
  statics::Conditions conditions;
  ParticleWeights pulled, pushed;  // read the displacements under the two forces
};
inline SzeHemisphere sze_hemisphere(int n) {
  StaticBenchmark quarter = pinched_hemisphere(n, PointLoad::shape_functions);
  const double half_P_max = 200.0;  // the linear case's quarter carries 1 per point
  for (Vector3& f : quarter.conditions.force) f *= half_P_max;
  const int on_y = n - 1;
  ParticleWeights pushed =
      shape_function_weights(quarter.model, quarter.model.particle_position[on_y], quarter.model.particle_normal[on_y]);
  return {std::move(quarter.model), std::move(quarter.conditions), std::move(quarter.probe), std::move(pushed)};
}

// Its tabulated reference (Sze, Liu & Lo 2004, §3.4): P/P_max, the outward
// radial displacement of the pulled point, the inward radial displacement of
// the pushed point, at P/P_max = 0.05 … 1.
inline std::vector<TabulatedPoint> sze_hemisphere_table() {
  const double pulled[] = {0.855, 1.499, 1.969, 2.321, 2.596, 2.819, 3.002, 3.158, 3.291, 3.406,
                           3.508, 3.598, 3.678, 3.750, 3.816, 3.875, 3.929, 3.979, 4.025, 4.067};
  const double pushed[] = {0.955, 1.840, 2.604, 3.261, 3.833, 4.339, 4.790, 5.196, 5.565, 5.902,
                           6.212, 6.497, 6.761, 7.006, 7.234, 7.448, 7.647, 7.835, 8.011, 8.178};
  return table_in_twentieths(pulled, pushed);
}

// Σ w_j u_j · direction for weights w read from the current configuration.
template <class Statics>
double weighted_displacement(const Statics& statics, const ParticleWeights& weights, const Vector3& direction) {
  double value = 0.0;
  for (const auto& [particle, weight] : weights) value += weight * statics.displacement(particle).dot(direction);
  return value;
}

// A table's two quantities computed at its load factors up to `last_factor`.
struct TabulatedRun {
  std::vector<TabulatedPoint> points;
  statics::NewtonReport report;
};

// The hemisphere solved at the table's load factors up to `last_factor`:
// the pulled point's outward and the pushed point's inward displacement.
template <class NonlinearSolver>
TabulatedRun run_sze_hemisphere(int n, double step, double last_factor = 1.0) {
  SzeHemisphere hemisphere = sze_hemisphere(n);
  NonlinearSolver solver(hemisphere.model, {6.825e7, 0.3});
  statics::PathFollower<NonlinearSolver> statics(solver, hemisphere.conditions);
  TabulatedRun run;
  for (const TabulatedPoint& point : sze_hemisphere_table()) {
    if (point.load_factor > last_factor + 1e-12) break;
    statics.solve_to(point.load_factor, step);
    run.points.push_back({point.load_factor, weighted_displacement(statics, hemisphere.pulled, Vector3::UnitX()),
                          weighted_displacement(statics, hemisphere.pushed, -Vector3::UnitY())});
  }
  run.report = statics.report();
  return run;
}

// The cylinders of Sze, Liu & Lo (2004), §3.5–3.6: two diametrically
// opposite radial point forces P at mid-length. One octant (0 ≤ θ ≤ 90°, the
// end at z = 0, the mid-length symmetry plane at z = L/2; n_circumferential ×
// n_axial particles) with symmetry planes; the octant carries P/4 at A = (R, 0,
// L/2), applied through the shape functions. B = (0, R, L/2) is 90° round from
// A at mid-length, C = (0, R, 0) at the end.
struct SzeCylinder {
  ShellModel model;
  statics::Conditions conditions;
  ParticleWeights a, b, c;
  double E, nu;
  SolverOptions options;  // the solver options the case is run with
};
inline SzeCylinder sze_cylinder_octant(double R, double L, double t, double E, double nu, double P_max, bool diaphragm,
                                       int n_circumferential, int n_axial, const SolverOptions& options = {}) {
  ShellModel model = ShellModel::cylindrical_panel(R, L / 2, benchmark_pi / 2, n_circumferential, n_axial, t);
  statics::Conditions conditions(model.particle_count());
  if (diaphragm) {  // rigid in its plane, free along the axis
    conditions.hold_translation(model.set("z_min"), Vector3::UnitX());
    conditions.hold_translation(model.set("z_min"), Vector3::UnitY());
  }
  conditions.symmetry_plane(model.set("z_max"), Vector3::UnitZ());
  conditions.symmetry_plane(model.set("theta_min"), Vector3::UnitY());
  conditions.symmetry_plane(model.set("theta_max"), Vector3::UnitX());
  const int n = n_circumferential;
  const int a = (n_axial - 1) * n, b = (n_axial - 1) * n + n - 1, c = n - 1;
  // Outward (pull-out, P_max > 0) or inward (pinching, P_max < 0) along x at A.
  // The load shared and the displacements read with the solver's own support.
  const double support = options.support_radius_factor;
  ParticleWeights at_a =
      add_point_force(model, conditions, a, Vector3(P_max / 4, 0.0, 0.0), PointLoad::shape_functions, support);
  ParticleWeights at_b = shape_function_weights(model, model.particle_position[b], model.particle_normal[b], support);
  ParticleWeights at_c = shape_function_weights(model, model.particle_position[c], model.particle_normal[c], support);
  return {std::move(model), std::move(conditions), std::move(at_a), std::move(at_b), std::move(at_c), E, nu, options};
}

// §3.5, pull-out of an open-ended cylinder: R = 4.953, L = 10.35, t = 0.094,
// E = 10.5e6, ν = 0.3125, both ends free, P_max = 40000 outward. Run with the
// director hourglass (PhysicsOptions::director_hourglass) by default: without
// it a spurious mode of alternating director rotations turns the octant
// unstable at P/P_max ≈ 0.27 (README, "What limits them").
inline SolverOptions pullout_options(bool director_hourglass = true) {
  SolverOptions options;
  options.director_hourglass = director_hourglass;
  return options;
}
inline SzeCylinder sze_pullout_cylinder(int n_circumferential, int n_axial,
                                        const SolverOptions& options = pullout_options()) {
  return sze_cylinder_octant(4.953, 10.35, 0.094, 10.5e6, 0.3125, 40000.0, false, n_circumferential, n_axial, options);
}
// §3.6, pinched cylinder on rigid diaphragms: R = 100, L = 200, t = 1,
// E = 30e3, ν = 0.3, P_max = 12000 inward. (The linear pinched cylinder's
// proportions, R/t = 100 and L/R = 2: at small loads −W_A → 164.24 P/(E t).)
// The concentrated dent needs a fine octant: −W_A at P/P_max = 0.05 is
// −3.0 / −0.56 / +0.25 % off at 25² / 33² / 41² (test_validation_benchmarks).
inline SzeCylinder sze_pinched_cylinder(int n_circumferential, int n_axial) {
  return sze_cylinder_octant(100.0, 200.0, 1.0, 30e3, 0.3, -12000.0, true, n_circumferential, n_axial);
}

// Their tabulated references (Sze, Liu & Lo 2004). §3.5: P/P_max, W_A
// (outward at the load), −U_B (inward at B), −U_C (inward at C); the response
// snaps between P/P_max = 0.5 and 0.525 (−U_B jumps, −U_C turns back).
struct TabulatedTriple {
  double load_factor;
  double a, b, c;
};
inline std::vector<TabulatedTriple> sze_pullout_table() {
  return {{0.025, 0.819, 0.864, 0.872}, {0.05, 1.260, 1.471, 1.493}, {0.075, 1.527, 1.901, 1.946},
          {0.10, 1.707, 2.217, 2.293},  {0.15, 1.936, 2.641, 2.792}, {0.20, 2.079, 2.904, 3.106},
          {0.25, 2.180, 3.087, 3.310},  {0.30, 2.257, 3.227, 3.452}, {0.35, 2.321, 3.342, 3.556},
          {0.40, 2.376, 3.443, 3.632},  {0.45, 2.425, 3.539, 3.688}, {0.50, 2.473, 3.653, 3.718},
          {0.525, 2.543, 4.061, 3.580}, {0.55, 2.577, 4.171, 3.518}, {0.60, 2.618, 4.274, 3.452},
          {0.65, 2.648, 4.338, 3.410},  {0.70, 2.672, 4.385, 3.378}, {0.75, 2.692, 4.423, 3.353},
          {0.80, 2.710, 4.455, 3.332},  {0.85, 2.726, 4.483, 3.313}, {0.90, 2.741, 4.508, 3.297},
          {0.95, 2.755, 4.530, 3.283},  {1.00, 2.768, 4.551, 3.269}};
}
// §3.6: P/P_max, −W_A (inward at the load), U_B (outward at B; slightly
// inward up to 0.15, the response snapping between 0.15 and 0.175).
inline std::vector<TabulatedPoint> sze_pinched_cylinder_table() {
  return {{0.05, 9.561, -0.233},   {0.075, 15.648, -0.922}, {0.10, 23.164, -2.391}, {0.125, 29.375, -3.872},
          {0.15, 36.208, -2.154},  {0.175, 51.499, 6.792},  {0.20, 56.373, 10.448}, {0.25, 61.877, 14.905},
          {0.30, 65.498, 17.979},  {0.35, 68.229, 20.365},  {0.40, 70.424, 22.321}, {0.45, 72.204, 23.916},
          {0.50, 73.790, 25.381},  {0.55, 75.139, 26.631},  {0.60, 76.331, 27.735}, {0.65, 77.472, 28.843},
          {0.70, 78.451, 29.772},  {0.75, 79.339, 30.604},  {0.80, 80.218, 31.471}, {0.85, 81.045, 32.299},
          {0.90, 81.766, 32.989},  {0.95, 82.435, 33.619},  {1.00, 83.102, 34.272}};
}

// A cylinder solved at the given load factors: the radial displacements at A,
// B and C (outward positive) at each.
struct CylinderRun {
  std::vector<TabulatedTriple> points;
  statics::NewtonReport report;
};
template <class NonlinearSolver>
CylinderRun run_sze_cylinder(const SzeCylinder& cylinder, const std::vector<double>& factors, double step,
                             statics::NewtonOptions newton = {}) {
  NonlinearSolver solver(cylinder.model, {cylinder.E, cylinder.nu}, cylinder.options);
  statics::PathFollower<NonlinearSolver> statics(solver, cylinder.conditions, newton);
  CylinderRun run;
  for (double factor : factors) {
    statics.solve_to(factor, step);
    run.points.push_back({factor, weighted_displacement(statics, cylinder.a, Vector3::UnitX()),
                          weighted_displacement(statics, cylinder.b, Vector3::UnitY()),
                          weighted_displacement(statics, cylinder.c, Vector3::UnitY())});
  }
  run.report = statics.report();
  return run;
}

// A load-deflection path followed by displacement control
// (statics::PathFollower::solve_to_displacement): per converged step the control
// displacement, the load factor and the displacements read.
struct PathPoint {
  double control, load_factor;
  std::vector<double> values;
};
struct PathRun {
  std::vector<PathPoint> path;  // from the unloaded state
  statics::NewtonReport report;
  double seconds = 0.0;
  std::string stopped;  // why the path ended before its last load factor (empty: it did not)
};
// A displacement to read along the path: Σ w_j u_j · direction.
using PathReading = statics::ControlDisplacement;

namespace detail {
// The loop both path followers share: advance(statics) takes one step and
// returns the path's control after it.
template <class NonlinearSolver, class Advance>
PathRun follow(const ShellModel& model, double E, double nu, const SolverOptions& options,
               const statics::Conditions& conditions, const std::vector<PathReading>& readings, double last_factor, int max_steps, statics::NewtonOptions newton,
               const std::function<void(const PathPoint&, const statics::NewtonReport&)>& progress, Advance&& advance) {
  const auto start = std::chrono::steady_clock::now();
  NonlinearSolver solver(model, {E, nu}, options);
  statics::PathFollower<NonlinearSolver> statics(solver, conditions, newton);
  PathRun run;
  run.path.push_back({0.0, 0.0, std::vector<double>(readings.size(), 0.0)});
  for (int k = 1; k <= max_steps && run.path.back().load_factor < last_factor; ++k) {
    double control = 0.0;
    try {
      control = advance(statics, k);
    } catch (const Error& error) {  // Newton gave up: keep the path so far
      run.stopped = error.what();
      break;
    }
    PathPoint point{control, statics.load_factor(), {}};
    for (const PathReading& reading : readings) point.values.push_back(statics.displacement_of(reading));
    run.path.push_back(std::move(point));
    if (progress) progress(run.path.back(), statics.report());
  }
  run.report = statics.report();
  run.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return run;
}
}  // namespace detail

// Follows the path of `conditions` on a new solver of `model` (E, ν, `options`) in steps of
// `step` of the control displacement until the load factor reaches
// `last_factor` (or `max_steps` steps were taken, or Newton failed: the path
// so far is returned with the reason); `progress` sees every step.
template <class NonlinearSolver>
PathRun follow_path(const ShellModel& model, double E, double nu, const SolverOptions& options,
                    const statics::Conditions& conditions,
                    const statics::ControlDisplacement& control, const std::vector<PathReading>& readings, double step,
                    double last_factor, int max_steps, statics::NewtonOptions newton = {},
                    const std::function<void(const PathPoint&, const statics::NewtonReport&)>& progress = {}) {
  return detail::follow<NonlinearSolver>(model, E, nu, options, conditions, readings, last_factor, max_steps, newton, progress,
                                         [&](statics::PathFollower<NonlinearSolver>& statics, int k) {
                                           statics.solve_to_displacement(control, k * step, step);
                                           return statics.displacement_of(control);
                                         });
}

// As follow_path, by arc length (statics::PathFollower::arc_length_step): steps of at
// most `length` (m) of the particles' root-mean-square motion, a step after one taken whole
// half as long again (up to `length`), one after a halved step as long as
// that. PathPoint::control is the length of the path so far.
template <class NonlinearSolver>
PathRun follow_arc_length(const ShellModel& model, double E, double nu, const SolverOptions& options,
                          const statics::Conditions& conditions,
                          const std::vector<PathReading>& readings, double length, double last_factor, int max_steps,
                          statics::NewtonOptions newton = {},
                          const std::function<void(const PathPoint&, const statics::NewtonReport&)>& progress = {}) {
  double next = length, travelled = 0.0;
  return detail::follow<NonlinearSolver>(model, E, nu, options, conditions, readings, last_factor, max_steps, newton, progress,
                                         [&](statics::PathFollower<NonlinearSolver>& statics, int) {
                                           const double taken = statics.arc_length_step(next);
                                           travelled += taken;
                                           next = taken < next ? taken : std::min(length, 1.5 * taken);
                                           return travelled;
                                         });
}

// The path between its points k − 1 and k (k ≥ 1) as a function of the
// control displacement s: the quadratic through those two points and the
// next (the one before, at the path's end; a line on a two-point path),
// evaluated for the quantity value_of(point).
struct PathStep {
  const std::vector<PathPoint>& path;
  std::size_t first, count;
  PathStep(const std::vector<PathPoint>& path_, std::size_t k)
      : path(path_),
        first(k + 1 < path_.size() ? k - 1 : (k >= 2 ? k - 2 : k - 1)),
        count(std::min<std::size_t>(3, path_.size() - first)) {}
  template <class ValueOf>
  double operator()(double s, ValueOf&& value_of) const {
    double sum = 0.0;
    for (std::size_t i = first; i < first + count; ++i) {
      double basis = 1.0;
      for (std::size_t j = first; j < first + count; ++j)
        if (j != i) basis *= (s - path[j].control) / (path[i].control - path[j].control);
      sum += basis * value_of(path[i]);
    }
    return sum;
  }
};

// The path's readings where its load factor first reaches `lambda` (what load
// control would give: past a snap-through, the far branch), by PathStep's
// interpolation in the control displacement over the step of the crossing.
// Empty when the path never reaches `lambda`.
inline std::vector<double> readings_at_load_factor(const std::vector<PathPoint>& path, double lambda) {
  std::size_t k = 1;
  while (k < path.size() && path[k].load_factor < lambda) ++k;
  if (k >= path.size()) return {};
  const PathStep lagrange(path, k);
  const auto load_factor = [](const PathPoint& point) { return point.load_factor; };
  // λ(s) − lambda changes sign on [s_{k−1}, s_k] (the interpolant passes through both points).
  double low = path[k - 1].control, high = path[k].control;
  for (int i = 0; i < 100; ++i) {
    const double mid = 0.5 * (low + high);
    (lagrange(mid, load_factor) < lambda ? low : high) = mid;
  }
  const double s = 0.5 * (low + high);
  std::vector<double> values;
  for (std::size_t r = 0; r < path[k].values.size(); ++r)
    values.push_back(lagrange(s, [r](const PathPoint& point) { return point.values[r]; }));
  return values;
}

// Sze, Liu & Lo (2004), §3.8, the hinged cylindrical roof under a central
// point force: radius R = 2540, straight edges 2L = 508 long and hinged
// (translations held, rotations free), an opening of θ = 0.1 rad either side
// of the crown (the arc is 508 long, the rise R(1 − cos θ) = 12.69), curved
// edges free, E = 3102.75, ν = 0.3, the force inward at the centre, P_max =
// 3000 for both thicknesses. At t = 12.7 the load passes a maximum and a
// minimum while the centre goes on down (a snap-through: displacement control
// of the centre follows it); at t = 6.35 the centre's deflection turns back
// as well (a snap-back: arc length).
enum class HingedRoofCase {
  thick,  // t = 12.7
  thin,   // t = 6.35
};
// One quarter, n × n particles (its 254 × 254 is square): the crown along the
// x-axis at θ = 0 (a symmetry plane, y = 0) to the hinged edge at θ = 0.1,
// the mid-length section z = 0 (a symmetry plane) to the free curved edge at
// z = L. The quarter carries P/4 at the centre C = (R, 0, 0), applied through
// the shape functions; the deflections are read the same way at C and at the
// free edge's midpoint (R, 0, L), inward (−x) positive.
struct SzeHingedRoof {
  ShellModel model;
  statics::Conditions conditions;
  ParticleWeights centre, free_edge;
  double E, nu;
  double rise;  // R(1 − cos θ)
};
inline SzeHingedRoof sze_hinged_roof(HingedRoofCase roof, int n) {
  const double R = 2540.0, L = 254.0, theta = 0.1, P_max = 3000.0;
  const double t = roof == HingedRoofCase::thick ? 12.7 : 6.35;
  ShellModel model = ShellModel::cylindrical_panel(R, L, theta, n, n, t);
  statics::Conditions conditions(model.particle_count());
  conditions.symmetry_plane(model.set("theta_min"), Vector3::UnitY());
  conditions.symmetry_plane(model.set("z_min"), Vector3::UnitZ());
  const ParticleSet hinged = model.set("theta_max");
  conditions.hold_translation(hinged, Vector3::UnitX());
  conditions.hold_translation(hinged, Vector3::UnitY());
  conditions.hold_translation(hinged, Vector3::UnitZ());
  const int centre = 0, free_edge = (n - 1) * n;
  ParticleWeights at_centre =
      add_point_force(model, conditions, centre, Vector3(-P_max / 4, 0.0, 0.0), PointLoad::shape_functions);
  ParticleWeights at_edge =
      shape_function_weights(model, model.particle_position[free_edge], model.particle_normal[free_edge]);
  return {std::move(model), std::move(conditions), std::move(at_centre), std::move(at_edge), 3102.75, 0.3,
          R * (1.0 - std::cos(theta))};
}

// A point of a tabulated load-deflection path.
struct LoadDeflection {
  double load_factor, deflection;
};
// The paper's table of the isotropic roofs (§3.8): P/P_max and −W_C, the
// centre's inward deflection, along the path (the load factor falls and, at
// t = 6.35, turns negative; there the deflection turns back too). As
// transcribed in MBDyn's test suite (tests/plates/sze2004/sze38/
// sze38_ref_a.dat and sze38_ref_d.dat, github.com/zanoni-mbdyn/MBDyn), whose
// transcription of the §3.6 table matches sze_pinched_cylinder_table digit
// for digit.
inline std::vector<LoadDeflection> sze_hinged_roof_table(HingedRoofCase roof) {
  if (roof == HingedRoofCase::thick)
    return {{0.0877, 0.693},  {0.1980, 1.638},  {0.3473, 3.087},  {0.4686, 4.477},  {0.5647, 5.802},
            {0.6381, 7.057},  {0.6908, 8.237},  {0.7246, 9.339},  {0.7412, 10.358}, {0.7421, 11.293},
            {0.7286, 12.141}, {0.7023, 12.903}, {0.6649, 13.583}, {0.6182, 14.188}, {0.5643, 14.728},
            {0.5055, 15.217}, {0.4442, 15.676}, {0.3830, 16.125}, {0.3245, 16.590}, {0.2717, 17.094},
            {0.2272, 17.657}, {0.1940, 18.299}, {0.1750, 19.028}, {0.1729, 19.852}, {0.1905, 20.771},
            {0.2303, 21.780}, {0.2950, 22.875}, {0.3871, 24.049}, {0.4443, 24.663}, {0.5093, 25.293},
            {0.5826, 25.940}, {0.6644, 26.601}, {0.7551, 27.276}, {0.8549, 27.964}, {0.9643, 28.663},
            {1.0835, 29.374}};
  return {{0.0517, 1.846},   {0.1182, 5.271},   {0.1583, 8.257},   {0.1837, 10.799},  {0.1914, 11.904},
          {0.1953, 12.892},  {0.1950, 13.752},  {0.1901, 14.472},  {0.1806, 15.050},  {0.1671, 15.501},
          {0.1323, 16.145},  {0.0923, 16.602},  {0.0504, 16.915},  {0.0083, 17.008},  {-0.0312, 16.697},
          {-0.0622, 15.780}, {-0.0739, 15.206}, {-0.0861, 14.767}, {-0.1001, 14.520}, {-0.1142, 14.451},
          {-0.1247, 14.862}, {-0.1288, 15.778}, {-0.1271, 16.961}, {-0.1196, 18.320}, {-0.1055, 19.817},
          {-0.0825, 21.420}, {-0.0484, 23.100}, {-0.0006, 24.824}, {0.0626, 26.565},  {0.1427, 28.302},
          {0.2403, 30.023},  {0.3559, 31.720},  {0.4898, 33.388},  {0.6417, 35.024},  {0.8114, 36.626},
          {1.0313, 38.450}};
}
// The table's limit load, its first maximum of P/P_max: the scale its load factors are compared on.
inline double limit_load_factor(const std::vector<LoadDeflection>& table) {
  double largest = 0.0;
  for (std::size_t k = 0; k < table.size() && table[k].load_factor >= largest; ++k) largest = table[k].load_factor;
  return largest;
}

// The distance from a tabulated point to a followed path in the plane of
// (load factor / load_scale, reading `reading` / deflection_scale): a path
// that turns back in both (a snap-back) has no single value at a load or a
// deflection, so a point is compared with the nearest point of the curve.
// Between steps the curve is PathStep's quadratic, as in
// readings_at_load_factor, sampled finely.
inline double distance_to_path(const std::vector<PathPoint>& path, std::size_t reading, const LoadDeflection& point,
                               double load_scale, double deflection_scale) {
  constexpr int samples = 128;
  double nearest = std::numeric_limits<double>::infinity();
  for (std::size_t k = 1; k < path.size(); ++k) {
    const PathStep lagrange(path, k);
    for (int m = 0; m <= samples; ++m) {
      const double s = path[k - 1].control + (path[k].control - path[k - 1].control) * m / samples;
      const double load = lagrange(s, [](const PathPoint& p) { return p.load_factor; });
      const double deflection = lagrange(s, [reading](const PathPoint& p) { return p.values[reading]; });
      nearest = std::min(nearest, std::hypot((load - point.load_factor) / load_scale,
                                             (deflection - point.deflection) / deflection_scale));
    }
  }
  return nearest;
}

// The roof's path followed to the table's last load factor: the thick roof by
// prescribing the centre's deflection in steps of `step`, the thin one by arc
// length (steps of at most `step` of the particles' root-mean-square motion).
// Readings: −W at the centre, then at the free edge's midpoint.
template <class NonlinearSolver>
PathRun follow_sze_hinged_roof(HingedRoofCase roof_case, int n, double step, statics::NewtonOptions newton = {},
                               const std::function<void(const PathPoint&, const statics::NewtonReport&)>& progress = {}) {
  const SzeHingedRoof roof = sze_hinged_roof(roof_case, n);
  const statics::ControlDisplacement centre{roof.centre, -Vector3::UnitX()}, free_edge{roof.free_edge, -Vector3::UnitX()};
  const double last_factor = sze_hinged_roof_table(roof_case).back().load_factor;
  // The paths are about 3 rises long in the centre's deflection (thick) and
  // 2 in the root-mean-square motion (thin); four times the steps that needs.
  const int max_steps = static_cast<int>(4.0 * 3.0 * roof.rise / step) + 10;
  if (roof_case == HingedRoofCase::thick)
    return follow_path<NonlinearSolver>(roof.model, roof.E, roof.nu, {}, roof.conditions, centre, {centre, free_edge},
                                        step, last_factor, max_steps, newton, progress);
  return follow_arc_length<NonlinearSolver>(roof.model, roof.E, roof.nu, {}, roof.conditions, {centre, free_edge}, step,
                                            last_factor, max_steps, newton, progress);
}

}  // namespace sphshell::test_support
