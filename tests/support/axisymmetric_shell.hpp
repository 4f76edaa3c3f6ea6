#pragma once
// An independent reference for axisymmetric shell dynamics: a one-dimensional
// Mindlin–Reissner shell of revolution, written for the tests without any of
// the library's material, kinematics or approximation code (Eigen only), so
// that the SPH shell's results on the clamped spherical cap can be compared
// with a second, differently discretised solution of the same shell theory.
//
// Geometry and unknowns. The meridian runs from the apex (on the axis, r = 0)
// to the rim. Each node carries the current meridian position (r, z) and the
// director angle β measured from the +z axis towards +r, so the unit director
// is d = (sin β, cos β) in the (r, z) plane. In the reference configuration
// the director is the surface normal (for a sphere of radius R: β₀ = polar
// angle θ, pointing outward). The linear variant uses the same unknowns as
// displacements Δr, Δz, Δβ from the reference.
//
// Strains (geometrically exact variant). With s the reference arc length
// along the meridian, a = ∂(r, z)/∂s the meridional base vector and
// d' = ∂d/∂s = β' (cos β, −sin β), the Green strains of the mid-surface and
// their first-order change through the thickness, in physical components of
// the reference meridional (s) and hoop (θ) directions, are
//   e_s = ½ (a·a − 1)                     e_θ = ½ ((r/r₀)² − 1)
//   κ_s = a·d' − (same in the reference)  κ_θ = r sin β / r₀² − sin β₀ / r₀
//   γ   = a·d − (same in the reference)   (transverse shear, zero at rest)
// (the hoop base vector is r e_θ and ∂d/∂θ = sin β e_θ). A fibre at height ζ
// along the director strains ε(ζ) = e + ζ κ (truncated linearly in ζ, the
// first-order shell theory); there is no torsion or in-plane shear in an
// axisymmetric state. Rigid translations along the axis create no strain.
// The linear variant uses the first-order part of the same expressions around
// the reference configuration: ε = B₀ (q − q₀) with B₀ = ∂ε/∂q at q₀.
//
// Constitutive law. Through the thickness d the section is split into
// `layers` equal layers, each integrated with two Gauss points (exact for the
// elastic section, which is cubic in ζ at most). At each point a plane-stress
// J2 law with linear isotropic hardening acts on (σ_s, σ_θ) (σ_sθ = 0 by
// symmetry), additively in the Green strain increments:
//   σ = C (ε − εᵖ),  C = E/(1−ν²) [[1, ν], [ν, 1]],
//   f = σ̄ − σ_y,     σ̄² = σ_s² − σ_s σ_θ + σ_θ²,  σ_y = σ_y0 + H ε̄ᵖ,
//   Δεᵖ = Δλ ∂(½σ̄²)/∂σ,  Δε̄ᵖ = Δλ σ̄  (plastic work σ:Δεᵖ = σ̄ Δε̄ᵖ).
// In the modes a = (σ_s + σ_θ)/√2 and b = (σ_s − σ_θ)/√2 the elasticity and
// the flow rule are both diagonal (σ̄² = a²/2 + 3b²/2, stiffnesses E/(1−ν)
// and 2G), so the backward-Euler return from the trial stress is
//   a = a* / (1 + Δλ E/(2(1−ν))),  b = b* / (1 + 3G Δλ),
// and Δλ solves F(Δλ) = σ̄(Δλ)(1 − H Δλ) − σ_y,n = 0 by Newton's method
// (F is convex and decreasing, so Newton from Δλ = 0 converges monotonically).
// The transverse shear is elastic: Q = κs G d γ. Resultants
//   N = Σ w_k σ(ζ_k),  M = Σ w_k ζ_k σ(ζ_k).
//
// Discretisation. Two-node elements along the meridian, r, z and β linear in
// s, every strain evaluated at the element's midpoint (one-point rule; for a
// two-node Mindlin element this is the classic locking-free choice: the
// shear strain is constant over the element, and no spurious mechanism
// remains because each element still sees five independent strains for its
// six degrees of freedom less the axial translation). The element's reference
// area is that of its conical frustum, 2π r₀,m h (exact by Pappus' rule), and
// the internal virtual work is
//   δW = Σ_e 2π r₀,m h (N_s δe_s + N_θ δe_θ + M_s δκ_s + M_θ δκ_θ + Q δγ),
// whose gradient gives the nodal forces exactly (the discrete system is
// conservative for elastic material).
//
// Inertia and loads. Each node owns the surface between the midpoints of its
// two elements (each half element a frustum, area π h (3 r_node + r_other)/4;
// the apex node owns the disc of radius h/2): m = ρ d A, rotary inertia
// ρ d³/12 A. These dual-cell areas, not the linear shape functions' shares
// 2π h (2 r_a + r_b)/6, balance the one-point element forces of a uniform
// membrane state at the apex (with the shares the apex node of a pressurised
// sphere carries 4/3 of its load, and its deflection is 4 % high at 32
// elements on a hemisphere). The uniform pressure p(t) pushes against the
// normal with the force −p A d at each node (reference area, current
// director: the library's follower pressure), or along the reference normal
// (fixed).
//
// Time integration. Explicit central differences (leapfrog) with optional
// mass-proportional damping c (dynamic relaxation):
//   v_{n+½} = [(1 − c Δt/2) v_{n−½} + Δt M⁻¹ (f_ext − f_int)(x_n)] / (1 + c Δt/2),
//   x_{n+1} = x_n + Δt v_{n+½},  starting from rest with v_{½} = Δt/2 M⁻¹ f(0).
// The stable step is bounded by the element eigenvalue theorem: ω_max² of the
// assembled system is at most the largest eigenvalue of any element's
// K_e φ = ω² M_e φ (K_e the linear elastic element stiffness, M_e the
// element's shares of the lumped masses); Δt = safety · 2/ω_max.
// Energies: kinetic ½ Σ m v_{n−½}·v_{n+½}, elastic from the stresses
// (½ σᵀC⁻¹σ through the thickness, ½ Q γ), plastic dissipation σ_{n+1}·Δεᵖ,
// external work by the trapezoidal rule; their balance tests that the nodal
// forces are the gradient of the strain energy.
//
// Boundary conditions. Apex node: r = 0 and β = 0 (on the axis). Rim: clamped
// (r, z, β fixed) or equator symmetry (z and β fixed, r free: the mirror plane
// of a full sphere cut at its equator, for closed-form checks).

#include <Eigen/Dense>

#include <algorithm>
#include <array>
#include <cmath>
#include <functional>
#include <limits>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

namespace sphshell::test_support::axisymmetric {

inline constexpr double pi = 3.14159265358979323846;

// ---------------------------------------------------------------------------
// Plane-stress J2 plasticity on the two normal stresses (σ_s, σ_θ).

struct LayerState {
  double stress_s = 0.0;
  double stress_theta = 0.0;
  double plastic_strain = 0.0;  // equivalent plastic strain ε̄ᵖ
};

class PlaneStressJ2 {
 public:
  // yield_stress = +∞ makes the law purely elastic.
  PlaneStressJ2(double youngs_modulus, double poisson_ratio, double yield_stress, double plastic_modulus)
      : E_(youngs_modulus), nu_(poisson_ratio), yield0_(yield_stress), H_(plastic_modulus) {
    if (!(E_ > 0.0) || !(nu_ > -1.0 && nu_ < 0.5) || !(yield0_ > 0.0) || !(H_ >= 0.0))
      throw std::invalid_argument("PlaneStressJ2: needs E > 0, −1 < ν < 0.5, σ_y0 > 0, H ≥ 0");
  }

  struct Update {
    bool plastic = false;
    int iterations = 0;
    double dissipation = 0.0;  // σ_{n+1}·Δεᵖ per unit volume
  };

  double yield_stress(const LayerState& state) const { return yield0_ + H_ * state.plastic_strain; }
  static double equivalent_stress(double s, double t) { return std::sqrt(s * s - s * t + t * t); }

  // Adds the strain increment (Δε_s, Δε_θ) and returns the stress to the yield
  // surface if the elastic trial lies outside it.
  Update update(LayerState& state, double d_strain_s, double d_strain_theta) const {
    const double c = E_ / (1.0 - nu_ * nu_);
    const double trial_s = state.stress_s + c * (d_strain_s + nu_ * d_strain_theta);
    const double trial_t = state.stress_theta + c * (nu_ * d_strain_s + d_strain_theta);
    const double yield_n = yield_stress(state);
    const double trial_eq = equivalent_stress(trial_s, trial_t);
    if (trial_eq <= yield_n) {
      state.stress_s = trial_s;
      state.stress_theta = trial_t;
      return {};
    }
    const double a_trial = (trial_s + trial_t) / std::sqrt(2.0);
    const double b_trial = (trial_s - trial_t) / std::sqrt(2.0);
    const double k_a = E_ / (2.0 * (1.0 - nu_));  // ½ × E/(1−ν), the spherical mode
    const double k_b = 3.0 * E_ / (2.0 * (1.0 + nu_));  // 3G, the deviatoric mode
    double lambda = 0.0, a = a_trial, b = b_trial, eq = trial_eq;
    Update result{true, 0};
    for (; result.iterations < max_iterations; ++result.iterations) {
      const double residual = eq * (1.0 - H_ * lambda) - yield_n;
      if (std::abs(residual) <= tolerance * yield_n) break;
      const double da = -a * k_a / (1.0 + k_a * lambda);
      const double db = -b * k_b / (1.0 + k_b * lambda);
      const double d_eq = (0.5 * a * da + 1.5 * b * db) / eq;
      const double slope = d_eq * (1.0 - H_ * lambda) - H_ * eq;
      lambda -= residual / slope;
      a = a_trial / (1.0 + k_a * lambda);
      b = b_trial / (1.0 + k_b * lambda);
      eq = std::sqrt(0.5 * a * a + 1.5 * b * b);
    }
    if (result.iterations == max_iterations)
      throw std::runtime_error("PlaneStressJ2: the return map did not converge");
    state.stress_s = (a + b) / std::sqrt(2.0);
    state.stress_theta = (a - b) / std::sqrt(2.0);
    state.plastic_strain += lambda * eq;
    // Δεᵖ = C⁻¹ (σ* − σ), C⁻¹ = [[1, −ν], [−ν, 1]]/E.
    const double ds = trial_s - state.stress_s, dt = trial_t - state.stress_theta;
    result.dissipation = (state.stress_s * (ds - nu_ * dt) + state.stress_theta * (dt - nu_ * ds)) / E_;
    return result;
  }

  // ½ σᵀ C⁻¹ σ per unit volume.
  double elastic_energy_density(const LayerState& state) const {
    const double s = state.stress_s, t = state.stress_theta;
    return (s * s - 2.0 * nu_ * s * t + t * t) / (2.0 * E_);
  }
  double youngs_modulus() const { return E_; }
  double poisson_ratio() const { return nu_; }
  double shear_modulus() const { return E_ / (2.0 * (1.0 + nu_)); }

 private:
  static constexpr double tolerance = 1e-13;
  static constexpr int max_iterations = 50;
  double E_, nu_, yield0_, H_;
};

// ---------------------------------------------------------------------------
// Reference meridians (nodes from the apex to the rim).

struct Meridian {
  std::vector<double> r, z, angle;  // reference position and director angle β₀
};

// Sphere of radius R cut at polar half angle α, nodes equally spaced in arc
// length on the exact sphere, director = outward normal.
inline Meridian spherical_cap_meridian(double radius, double half_angle, int elements) {
  if (!(radius > 0.0) || !(half_angle > 0.0 && half_angle <= pi / 2) || elements < 2)
    throw std::invalid_argument("spherical_cap_meridian: needs R > 0, 0 < α ≤ π/2, ≥ 2 elements");
  Meridian m;
  for (int i = 0; i <= elements; ++i) {
    const double theta = half_angle * i / elements;
    m.r.push_back(i == 0 ? 0.0 : radius * std::sin(theta));
    m.z.push_back(radius * std::cos(theta));
    m.angle.push_back(theta);
  }
  return m;
}

// Flat disc of radius a in the plane z = 0, director +z.
inline Meridian circular_plate_meridian(double plate_radius, int elements) {
  if (!(plate_radius > 0.0) || elements < 2)
    throw std::invalid_argument("circular_plate_meridian: needs a > 0 and ≥ 2 elements");
  Meridian m;
  for (int i = 0; i <= elements; ++i) {
    m.r.push_back(plate_radius * i / elements);
    m.z.push_back(0.0);
    m.angle.push_back(0.0);
  }
  return m;
}

// ---------------------------------------------------------------------------
// The shell of revolution.

enum class Kinematics { linear, geometrically_exact };
enum class PressureDirection { director, reference_normal };
enum class RimSupport { clamped, equator_symmetry };

struct ShellProperties {
  double thickness = 0.0;
  double youngs_modulus = 0.0;
  double poisson_ratio = 0.0;
  double density = 0.0;
  double yield_stress = std::numeric_limits<double>::infinity();  // σ_y0; ∞ = elastic
  double plastic_modulus = 0.0;                                   // H = E Et/(E − Et)
  double shear_correction = 5.0 / 6.0;                            // κs
  int layers = 8;  // equal layers through the thickness, two Gauss points each
};

struct RunOptions {
  Kinematics kinematics = Kinematics::geometrically_exact;
  PressureDirection pressure_direction = PressureDirection::director;
  RimSupport rim = RimSupport::clamped;
  double safety_factor = 0.8;  // Δt = safety · 2/ω_max
  double damping = 0.0;        // mass-proportional damping c, 1/s
};

// Energies at time `time` (one step behind the state: the kinetic energy at
// t_n is ½ Σ m v_{n−½}·v_{n+½}). The elastic energy comes from the stresses
// (½ σᵀC⁻¹σ through the thickness plus ½ Q γ), not from the nodal forces, so
// the balance checks that the forces are the gradient of the energy.
struct Energies {
  double time = 0.0;
  double kinetic = 0.0;
  double elastic = 0.0;
  double plastic_dissipation = 0.0;
  double external_work = 0.0;  // trapezoidal rule on the nodal loads
  double damping_work = 0.0;
  double balance() const { return kinetic + elastic + plastic_dissipation + damping_work - external_work; }
};

class AxisymmetricShell {
 public:
  static constexpr int dofs_per_node = 3;  // r, z, β
  using ElementVector = Eigen::Matrix<double, 6, 1>;
  using StrainVector = Eigen::Matrix<double, 5, 1>;  // e_s, e_θ, κ_s, κ_θ, γ
  using StrainMatrix = Eigen::Matrix<double, 5, 6>;

  AxisymmetricShell(Meridian meridian, const ShellProperties& properties, const RunOptions& options)
      : reference_(std::move(meridian)),
        properties_(properties),
        options_(options),
        law_(properties.youngs_modulus, properties.poisson_ratio, properties.yield_stress,
             properties.plastic_modulus) {
    const std::size_t nodes = reference_.r.size();
    if (nodes < 3 || reference_.z.size() != nodes || reference_.angle.size() != nodes)
      throw std::invalid_argument("AxisymmetricShell: the meridian needs ≥ 3 nodes with r, z, angle each");
    if (std::abs(reference_.r[0]) > 0.0 || std::abs(reference_.angle[0]) > 0.0)
      throw std::invalid_argument("AxisymmetricShell: the first node must be the apex (r = 0, β = 0)");
    if (!(properties_.thickness > 0.0) || !(properties_.density > 0.0) || properties_.layers < 1 ||
        !(properties_.shear_correction > 0.0))
      throw std::invalid_argument("AxisymmetricShell: needs d > 0, ρ > 0, κs > 0, ≥ 1 layer");
    if (!(options_.safety_factor > 0.0 && options_.safety_factor < 1.0) || options_.damping < 0.0)
      throw std::invalid_argument("AxisymmetricShell: needs 0 < safety < 1 and damping ≥ 0");
    set_up_thickness_points();
    set_up_elements();
    set_up_masses_and_constraints();
    stable_time_step_ = compute_stable_time_step();
    time_step_ = options_.safety_factor * stable_time_step_;
    const std::size_t n = dofs_per_node * nodes;
    q_ = Eigen::VectorXd(n);
    for (std::size_t i = 0; i < nodes; ++i) q_.segment<3>(3 * i) << reference_.r[i], reference_.z[i], reference_.angle[i];
    q0_ = q_;
    v_ = Eigen::VectorXd::Zero(n);
    layer_states_.assign(elements() * thickness_points(), LayerState{});
    strains_.assign(elements(), StrainVector::Zero());
    f_int_ = internal_forces();
    f_ext_ = external_forces(0.0);
  }

  // Pressure history p(t), Pa; positive pushes against the director (inward
  // on a cap with outward directors). A step of p0 by default.
  void set_pressure(std::function<double(double)> pressure) {
    pressure_ = std::move(pressure);
    f_ext_ = external_forces(time_);
  }
  void set_pressure(double p0) {
    set_pressure([p0](double) { return p0; });
  }

  double stable_time_step() const { return stable_time_step_; }
  double time_step() const { return time_step_; }
  void set_time_step(double dt) {
    if (!(dt > 0.0 && dt <= stable_time_step_))
      throw std::invalid_argument("AxisymmetricShell::set_time_step: must lie in (0, stable step]");
    time_step_ = dt;
  }
  double time() const { return time_; }
  long steps() const { return steps_; }
  std::size_t nodes() const { return reference_.r.size(); }
  std::size_t elements() const { return nodes() - 1; }
  int thickness_points() const { return 2 * properties_.layers; }

  void step() {
    const double dt = time_step_, c = options_.damping;
    // The first kick spans half a step: the state starts at rest at t = 0,
    // so v_{½} = Δt/2 M⁻¹ f(0) (a full first kick would start the load Δt/2
    // early).
    const double kick = steps_ == 0 ? 0.5 * dt : dt;
    const Eigen::VectorXd v_old = v_;
    for (Eigen::Index k = 0; k < q_.size(); ++k) {
      if (fixed_[std::size_t(k)]) continue;
      const double accel = (f_ext_[k] - f_int_[k]) / mass_[k];
      v_[k] = ((1.0 - 0.5 * c * kick) * v_[k] + kick * accel) / (1.0 + 0.5 * c * kick);
    }
    energies_.time = time_;
    energies_.kinetic = 0.5 * (mass_.array() * v_old.array() * v_.array()).sum();
    energies_.elastic = elastic_energy_;
    energies_.plastic_dissipation = plastic_dissipation_;
    energies_.external_work = external_work_;
    energies_.damping_work = damping_work_;
    const Eigen::VectorXd dq = dt * v_;
    damping_work_ += c * dt * (mass_.array() * v_.array().square()).sum();
    q_ += dq;
    time_ += dt;
    ++steps_;
    const Eigen::VectorXd f_ext_new = external_forces(time_);
    external_work_ += 0.5 * dq.dot(f_ext_ + f_ext_new);
    f_ext_ = f_ext_new;
    f_int_ = internal_forces();
  }

  // Steps until t_end; observe(*this) after every step.
  template <class Observer>
  void run_until(double t_end, Observer&& observe) {
    while (time_ < t_end - 0.5 * time_step_) {
      step();
      observe(*this);
    }
  }
  void run_until(double t_end) {
    run_until(t_end, [](const AxisymmetricShell&) {});
  }

  // Displacements of node i (m, m, rad).
  double radial_displacement(std::size_t i) const { return q_[Eigen::Index(3 * i)] - q0_[Eigen::Index(3 * i)]; }
  double axial_displacement(std::size_t i) const { return q_[Eigen::Index(3 * i + 1)] - q0_[Eigen::Index(3 * i + 1)]; }
  double rotation(std::size_t i) const { return q_[Eigen::Index(3 * i + 2)] - q0_[Eigen::Index(3 * i + 2)]; }
  // The apex moves along −z under an inward load: positive inward.
  double apex_inward_displacement() const { return -axial_displacement(0); }
  double max_speed() const {
    double fastest = 0.0;
    for (std::size_t i = 0; i < nodes(); ++i)
      fastest = std::max(fastest, std::hypot(v_[Eigen::Index(3 * i)], v_[Eigen::Index(3 * i + 1)]));
    return fastest;
  }
  const Energies& energies() const { return energies_; }
  const Meridian& reference() const { return reference_; }
  // Equivalent plastic strain, largest over all thickness points of element e.
  double max_plastic_strain(std::size_t e) const {
    double largest = 0.0;
    for (int k = 0; k < thickness_points(); ++k)
      largest = std::max(largest, layer_states_[e * std::size_t(thickness_points()) + std::size_t(k)].plastic_strain);
    return largest;
  }
  // Stress at thickness point k of element e (ζ ascending).
  const LayerState& layer_state(std::size_t e, int k) const {
    return layer_states_.at(e * std::size_t(thickness_points()) + std::size_t(k));
  }
  double zeta(int k) const { return zeta_.at(std::size_t(k)); }
  const PlaneStressJ2& law() const { return law_; }

 private:
  struct Element {
    double length;   // reference chord h
    double area;     // 2π r₀,m h
    double r0_mid;   // reference radius at the midpoint
    StrainVector reference_measures;  // the strain measures' values in the reference
    StrainMatrix reference_B;         // ∂ε/∂q at the reference (linear variant)
  };

  void set_up_thickness_points() {
    const double d = properties_.thickness, layer = d / properties_.layers;
    const double offset = layer / (2.0 * std::sqrt(3.0));
    for (int l = 0; l < properties_.layers; ++l) {
      const double centre = -0.5 * d + (l + 0.5) * layer;
      zeta_.push_back(centre - offset);
      zeta_.push_back(centre + offset);
      weight_.push_back(0.5 * layer);
      weight_.push_back(0.5 * layer);
    }
  }

  // Local values at an element's midpoint: r', z', r_m, β_m, β'.
  struct Local {
    double dr, dz, r, beta, dbeta;
  };
  static Local local_values(const Eigen::Ref<const Eigen::VectorXd>& q, std::size_t e, double h) {
    const Eigen::Index a = Eigen::Index(3 * e), b = a + 3;
    return {(q[b] - q[a]) / h, (q[b + 1] - q[a + 1]) / h, 0.5 * (q[a] + q[b]),
            0.5 * (q[a + 2] + q[b + 2]), (q[b + 2] - q[a + 2]) / h};
  }
  // The strain measures before subtracting their reference values.
  static StrainVector measures(const Local& l, double r0) {
    const double cb = std::cos(l.beta), sb = std::sin(l.beta);
    StrainVector m;
    m << 0.5 * (l.dr * l.dr + l.dz * l.dz - 1.0), 0.5 * ((l.r / r0) * (l.r / r0) - 1.0),
        l.dbeta * (l.dr * cb - l.dz * sb), l.r * sb / (r0 * r0), l.dr * sb + l.dz * cb;
    return m;
  }
  // ∂(measures)/∂(element dofs r_a, z_a, β_a, r_b, z_b, β_b).
  static StrainMatrix strain_matrix(const Local& l, double r0, double h) {
    const double cb = std::cos(l.beta), sb = std::sin(l.beta);
    // Rows: strains; columns: r', z', r_m, β_m, β'.
    Eigen::Matrix<double, 5, 5> J = Eigen::Matrix<double, 5, 5>::Zero();
    J(0, 0) = l.dr;
    J(0, 1) = l.dz;
    J(1, 2) = l.r / (r0 * r0);
    J(2, 0) = l.dbeta * cb;
    J(2, 1) = -l.dbeta * sb;
    J(2, 3) = -l.dbeta * (l.dr * sb + l.dz * cb);
    J(2, 4) = l.dr * cb - l.dz * sb;
    J(3, 2) = sb / (r0 * r0);
    J(3, 3) = l.r * cb / (r0 * r0);
    J(4, 0) = sb;
    J(4, 1) = cb;
    J(4, 3) = l.dr * cb - l.dz * sb;
    Eigen::Matrix<double, 5, 6> T = Eigen::Matrix<double, 5, 6>::Zero();
    T(0, 0) = -1.0 / h, T(0, 3) = 1.0 / h;
    T(1, 1) = -1.0 / h, T(1, 4) = 1.0 / h;
    T(2, 0) = 0.5, T(2, 3) = 0.5;
    T(3, 2) = 0.5, T(3, 5) = 0.5;
    T(4, 2) = -1.0 / h, T(4, 5) = 1.0 / h;
    return J * T;
  }

  void set_up_elements() {
    const Eigen::Index n = Eigen::Index(3 * nodes());
    Eigen::VectorXd q(n);
    for (std::size_t i = 0; i < nodes(); ++i) q.segment<3>(Eigen::Index(3 * i)) << reference_.r[i], reference_.z[i], reference_.angle[i];
    for (std::size_t e = 0; e + 1 < nodes(); ++e) {
      Element element;
      element.length = std::hypot(reference_.r[e + 1] - reference_.r[e], reference_.z[e + 1] - reference_.z[e]);
      element.r0_mid = 0.5 * (reference_.r[e] + reference_.r[e + 1]);
      if (!(element.length > 0.0) || !(element.r0_mid > 0.0))
        throw std::invalid_argument("AxisymmetricShell: an element has zero length or lies on the axis");
      element.area = 2.0 * pi * element.r0_mid * element.length;
      const Local l = local_values(q, e, element.length);
      element.reference_measures = measures(l, element.r0_mid);
      element.reference_B = strain_matrix(l, element.r0_mid, element.length);
      elements_.push_back(element);
    }
  }

  // Area of the half of an element (chord h, end radii r_near, r_far) next to
  // its node at r_near: a frustum of length h/2 from r_near to the midpoint.
  static double half_frustum_area(double h, double r_near, double r_far) {
    return pi * h * (3.0 * r_near + r_far) / 4.0;
  }

  void set_up_masses_and_constraints() {
    const std::size_t n = 3 * nodes();
    nodal_area_.assign(nodes(), 0.0);
    for (std::size_t e = 0; e < elements(); ++e) {
      const double h = elements_[e].length, ra = reference_.r[e], rb = reference_.r[e + 1];
      nodal_area_[e] += half_frustum_area(h, ra, rb);
      nodal_area_[e + 1] += half_frustum_area(h, rb, ra);
    }
    const double rho = properties_.density, d = properties_.thickness;
    mass_ = Eigen::VectorXd(Eigen::Index(n));
    for (std::size_t i = 0; i < nodes(); ++i) {
      mass_[Eigen::Index(3 * i)] = mass_[Eigen::Index(3 * i + 1)] = rho * d * nodal_area_[i];
      mass_[Eigen::Index(3 * i + 2)] = rho * d * d * d / 12.0 * nodal_area_[i];
    }
    fixed_.assign(n, 0);
    fixed_[0] = fixed_[2] = 1;  // apex on the axis: r = 0, β = 0
    const std::size_t rim = 3 * (nodes() - 1);
    if (options_.rim == RimSupport::clamped) fixed_[rim] = fixed_[rim + 1] = fixed_[rim + 2] = 1;
    else fixed_[rim + 1] = fixed_[rim + 2] = 1;
  }

  // Elastic section stiffness (N_s, N_θ, M_s, M_θ, Q) = D ε.
  Eigen::Matrix<double, 5, 5> elastic_section() const {
    const double E = law_.youngs_modulus(), nu = law_.poisson_ratio();
    Eigen::Matrix2d C;
    C << 1.0, nu, nu, 1.0;
    C *= E / (1.0 - nu * nu);
    double w0 = 0.0, w2 = 0.0;
    for (std::size_t k = 0; k < zeta_.size(); ++k) {
      w0 += weight_[k];
      w2 += weight_[k] * zeta_[k] * zeta_[k];
    }
    Eigen::Matrix<double, 5, 5> D = Eigen::Matrix<double, 5, 5>::Zero();
    D.block<2, 2>(0, 0) = w0 * C;
    D.block<2, 2>(2, 2) = w2 * C;
    D(4, 4) = properties_.shear_correction * law_.shear_modulus() * properties_.thickness;
    return D;
  }

  double compute_stable_time_step() const {
    const Eigen::Matrix<double, 5, 5> D = elastic_section();
    double omega_squared = 0.0;
    const double rho = properties_.density, d = properties_.thickness;
    for (std::size_t e = 0; e < elements(); ++e) {
      const Element& el = elements_[e];
      const Eigen::Matrix<double, 6, 6> K = el.area * el.reference_B.transpose() * D * el.reference_B;
      const double ra = reference_.r[e], rb = reference_.r[e + 1], h = el.length;
      const double area_a = half_frustum_area(h, ra, rb), area_b = half_frustum_area(h, rb, ra);
      Eigen::Matrix<double, 6, 1> m;
      m << rho * d * area_a, rho * d * area_a, rho * d * d * d / 12.0 * area_a, rho * d * area_b,
          rho * d * area_b, rho * d * d * d / 12.0 * area_b;
      // M^{-1/2} K M^{-1/2} is symmetric with the eigenvalues of K φ = ω² M φ.
      const Eigen::Matrix<double, 6, 1> s = m.cwiseSqrt().cwiseInverse();
      const Eigen::Matrix<double, 6, 6> A = s.asDiagonal() * K * s.asDiagonal();
      Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, 6, 6>> eigen(A, Eigen::EigenvaluesOnly);
      omega_squared = std::max(omega_squared, eigen.eigenvalues().maxCoeff());
    }
    return 2.0 / std::sqrt(omega_squared);
  }

  Eigen::VectorXd internal_forces() {
    Eigen::VectorXd f = Eigen::VectorXd::Zero(q_.size());
    const double shear_stiffness =
        properties_.shear_correction * law_.shear_modulus() * properties_.thickness;
    const int points = thickness_points();
    double elastic = 0.0, dissipation = 0.0;
    for (std::size_t e = 0; e < elements(); ++e) {
      const Element& el = elements_[e];
      StrainVector strain;
      StrainMatrix B;
      if (options_.kinematics == Kinematics::geometrically_exact) {
        const Local l = local_values(q_, e, el.length);
        strain = measures(l, el.r0_mid) - el.reference_measures;
        B = strain_matrix(l, el.r0_mid, el.length);
      } else {
        strain = el.reference_B * (q_.segment<6>(Eigen::Index(3 * e)) - q0_.segment<6>(Eigen::Index(3 * e)));
        B = el.reference_B;
      }
      const StrainVector d_strain = strain - strains_[e];
      strains_[e] = strain;
      StrainVector resultant = StrainVector::Zero();
      for (int k = 0; k < points; ++k) {
        LayerState& state = layer_states_[e * std::size_t(points) + std::size_t(k)];
        const double z = zeta_[std::size_t(k)], w = weight_[std::size_t(k)];
        const PlaneStressJ2::Update update =
            law_.update(state, d_strain[0] + z * d_strain[2], d_strain[1] + z * d_strain[3]);
        dissipation += el.area * w * update.dissipation;
        elastic += el.area * w * law_.elastic_energy_density(state);
        resultant[0] += w * state.stress_s;
        resultant[1] += w * state.stress_theta;
        resultant[2] += w * z * state.stress_s;
        resultant[3] += w * z * state.stress_theta;
      }
      resultant[4] = shear_stiffness * strain[4];
      elastic += el.area * 0.5 * resultant[4] * strain[4];
      f.segment<6>(Eigen::Index(3 * e)) += el.area * (B.transpose() * resultant);
    }
    elastic_energy_ = elastic;
    plastic_dissipation_ += dissipation;
    return f;
  }

  Eigen::VectorXd external_forces(double t) const {
    Eigen::VectorXd f = Eigen::VectorXd::Zero(q_.size());
    if (!pressure_) return f;
    const double p = pressure_(t);
    for (std::size_t i = 0; i < nodes(); ++i) {
      const double beta = options_.pressure_direction == PressureDirection::director
                              ? q_[Eigen::Index(3 * i + 2)]
                              : reference_.angle[i];
      f[Eigen::Index(3 * i)] = -p * nodal_area_[i] * std::sin(beta);
      f[Eigen::Index(3 * i + 1)] = -p * nodal_area_[i] * std::cos(beta);
    }
    return f;
  }

  Meridian reference_;
  ShellProperties properties_;
  RunOptions options_;
  PlaneStressJ2 law_;
  std::vector<double> zeta_, weight_;
  std::vector<Element> elements_;
  std::vector<double> nodal_area_;
  Eigen::VectorXd mass_;
  std::vector<char> fixed_;
  double stable_time_step_ = 0.0, time_step_ = 0.0, time_ = 0.0;
  long steps_ = 0;
  Eigen::VectorXd q_, q0_, v_, f_int_, f_ext_;
  std::vector<LayerState> layer_states_;
  std::vector<StrainVector> strains_;
  std::function<double(double)> pressure_;
  Energies energies_;
  double elastic_energy_ = 0.0, plastic_dissipation_ = 0.0, external_work_ = 0.0, damping_work_ = 0.0;
};

}  // namespace sphshell::test_support::axisymmetric
