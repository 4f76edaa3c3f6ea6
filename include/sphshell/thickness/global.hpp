#pragma once
// Global: the resultant ("global") model of Maurel & Combescure (2008) and Caleyron
// et al. (2011) that the paper compares with (section 2.1). There are no integral
// points; the section works on the resultants directly:
//   N = d Γ e (membrane),   M = d³/12 Γ κ (bending),
// and, for plastic laws, resultant plasticity on the approximate Ilyushin yield surface
// of Crisfield (1974, "On an approximate yield criterion for thin steel shells", TRRL,
// Crowthorne; the paper cites it for the global model's resultant algorithm, §2.2):
//   F = Q_t + Q_m + |Q_tm|/√3 = 1,
//   Q_t = NᵀΞN/N0²,  Q_m = MᵀΞM/M0²,  Q_tm = NᵀΞM/(N0 M0),  N0 = σs d,  M0 = σs d²/4.
// It is exact for pure tension (N0) and pure bending (M0) of a Mises section and
// approximates Ilyushin's exact (parametric) surface in between.
//
// Return map. Write x = (N, M) and F = xᵀÂ_s x/σs² with
//   Â_s = [[Ξ/d², s·2Ξ/(√3 d³)], [s·2Ξ/(√3 d³), 16Ξ/d⁴]],  s = sign(Q_tm),
// so σ̄_I = √(xᵀÂ_s x) is a generalized equivalent stress (σ̄_I = σ in uniform tension).
// Associated flow Δε_gp = Δλ Âx/σ̄_I with Δλ = d Δε̄p makes the plastic work per area
// d σs Δε̄p, so ε̄p is the thickness-averaged equivalent plastic strain and the
// hardening σs = σs,n + Ep Δε̄p is the law's. Closest point, like the J2 map of docs/method.md §5:
//   x = (I + (d Δε̄p/σs) D Â_s)⁻¹ x*,  D = diag(dΓ, d³/12 Γ),  g(Δε̄p) = xᵀÂ_s x − σs² = 0,
// a scalar Newton safeguarded by bisection. |Q_tm| makes a ridge at Q_tm = 0 (which pure
// bending and pure tension sit on); when the return with s = ±1 leaves its own side,
// the return goes to the ridge: Koiter's flow there is a convex combination of the two
// gradients, i.e. the same return with an s in (−1, 1), found by Illinois regula falsi
// on Q_tm(s) = 0.
//
// Damage (LemaitreDamage), the project's reduction to resultants: the damage law of
// docs/method.md §6 (eq. 2.41) driven by the generalized ε̄p with the triaxiality fixed at T = 1/3
// (uniaxial tension, so the factor ⅔(1+ν) + 3(1−2ν)T² is exactly 1): D grows by
// Dc/(ε̄cp − ε̄sp) Δε̄p once ε̄p >= ε̄sp. A membrane-based triaxiality is undefined in pure
// bending, which is the dominant shell loading; T = 1/3 is the fibre state there.
// Integration is staggered: the plastic return uses the effective resultants x/(1 − D)
// and then x = (1 − D_{n+1}) x̃, so σ̄_I = (1 − D) σs after a return. When D reaches Dc
// the stress point has failed (D = Dc, zero resultants).

#include <sphshell/core/error.hpp>
#include <sphshell/core/types.hpp>
#include <sphshell/material/material.hpp>
#include <sphshell/thickness/section.hpp>
#include <sphshell/thickness/thickness.hpp>

#include <Eigen/Core>
#include <Eigen/LU>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

namespace sphshell::thickness {

struct Global {
  static constexpr int num_points = 0;
  static constexpr std::array<double, 0> reference_points{};
  static constexpr std::array<double, 0> reference_weights{};
  static constexpr const char* name = "Global";
};

// Everything a stress point carries under Global.
struct ResultantState {
  StressVoigt membrane = StressVoigt::Zero();  // N, N/m
  StressVoigt moment = StressVoigt::Zero();    // M, N·m/m
  double eps_p = 0.0;    // generalized (thickness-averaged) equivalent plastic strain
  double sigma_y = 0.0;  // current yield stress; +inf for laws without plasticity
  double D = 0.0;
  bool failed = false;
  // The fields a checkpoint stores (thickness.hpp).
  template <class S, class F>
  static void for_each_field(S& self, F&& field) {
    field(self.membrane, self.moment, self.eps_p, self.sigma_y, self.D, self.failed);
  }
};

template <class Law>
class Section<Global, Law> {
  static_assert(!material::is_rate_dependent_v<Law>,
                "sphshell::thickness::Section<Global, Law>: the resultant model integrates linear hardening "
                "(hardening()) only; a rate-dependent law needs integral points through the thickness "
                "(Gauss<N> or Simpson<N>)");

 public:
  static constexpr int num_points = 0;
  static constexpr int output_points = 1;
  using State = ResultantState;

  // Iteration caps of the ridge search and of the Newton solve on the plastic
  // multiplier; both converge in a few iterations, so reaching one is an error.
  static constexpr int max_ridge_iterations = 200;
  static constexpr int max_newton_iterations = 200;
  // A coupling term below this fraction of σs² is on the ridge (s = 0).
  static constexpr double ridge_tolerance = 1e-12;
  // |g| below this fraction of σs² is converged; brackets and the ridge
  // parameter narrower than this relative width stop the search.
  static constexpr double residual_tolerance = 1e-13;
  static constexpr double bracket_tolerance = 1e-15;

  Section(const Law& law, double thickness) : law_(law), thickness_(thickness) {
    sphshell::detail::require_positive("thickness", thickness);
    const double d = thickness;
    const Matrix3 gamma = law.elasticity_matrix();
    Matrix3 xi;
    xi << 1.0, -0.5, 0.0, -0.5, 1.0, 0.0, 0.0, 0.0, 3.0;

    membrane_stiffness_ = d * gamma;
    bending_stiffness_ = d * d * d / 12.0 * gamma;
    membrane_compliance_ = membrane_stiffness_.inverse();
    bending_compliance_ = bending_stiffness_.inverse();

    // Γ and Ξ share the eigenvectors q_i (docs/method.md §5), so the 6×6 return decouples
    // into three 2×2 systems in (N·q_i, M·q_i); ΓΞ q_i = λ_i q_i, Ξ q_i = w_i q_i.
    const double r = 1.0 / std::sqrt(2.0);
    const Vector3 q[3] = {Vector3(r, r, 0.0), Vector3(r, -r, 0.0), Vector3(0.0, 0.0, 1.0)};
    for (int i = 0; i < 3; ++i) {
      mises_eigenvalues_[std::size_t(i)] = q[i].dot(xi * q[i]);
      flow_eigenvalues_[std::size_t(i)] = q[i].dot(gamma * xi * q[i]);
    }
    membrane_scale_ = 1.0 / d;
    moment_scale_ = 4.0 / (d * d);
    for (int side = 0; side < 3; ++side) side_metrics_[std::size_t(side)] = ridge_metric(double(side - 1));

    if constexpr (Law::has_plasticity) {
      const material::HardeningParameters hardening = law.hardening();
      initial_yield_stress_ = hardening.initial_yield_stress;
      hardening_modulus_ = hardening.plastic_modulus;
    }
    if constexpr (Law::has_damage) {
      const material::DamageParameters damage = law.damage_parameters();
      damage_threshold_ = damage.threshold_strain;
      critical_damage_ = damage.critical_damage;
      damage_rate_ = damage.critical_damage / (damage.critical_strain - damage.threshold_strain);
    }
  }

  State initial_state() const {
    State state;
    state.sigma_y = initial_yield_stress_;
    return state;
  }

  Resultants update(State& state, const StrainVoigt& d_membrane_strain,
                    const StrainVoigt& d_curvature) const {
    if (!d_membrane_strain.allFinite() || !d_curvature.allFinite())
      sphshell::detail::invalid_parameter("strain increment", "non-finite",
                                          "membrane strain and curvature increments must be finite");
    if (state.failed) return {};
    // Elastic predictor on the effective resultants, block by block (the section
    // stiffness diag(dΓ, d³/12 Γ) has no membrane–bending coupling).
    Vector3 membrane = state.membrane, moment = state.moment;
    if constexpr (Law::has_damage) {
      membrane /= 1.0 - state.D;
      moment /= 1.0 - state.D;
    }
    membrane += membrane_stiffness_ * d_membrane_strain;
    moment += bending_stiffness_ * d_curvature;
    if constexpr (Law::has_plasticity) {
      const Modal trial = modal(membrane, moment);
      if (equivalent_squared(trial) > state.sigma_y * state.sigma_y) {
        const ReturnResult result = plastic_return(trial, state.sigma_y);
        if (result.d_eps_p > 0.0) cartesian(result.resultants, membrane, moment);
        state.eps_p += result.d_eps_p;
        state.sigma_y += hardening_modulus_ * result.d_eps_p;
        if constexpr (Law::has_damage) grow_damage(state, result.d_eps_p);
      }
    }
    if (state.failed) {
      state.membrane.setZero();
      state.moment.setZero();
      return {};
    }
    if constexpr (Law::has_damage) {
      membrane *= 1.0 - state.D;
      moment *= 1.0 - state.D;
    }
    state.membrane = membrane;
    state.moment = moment;
    return resultants(state);
  }

  Resultants resultants(const State& state) const { return {state.membrane, state.moment}; }

  // The single output point is the Ilyushin generalized equivalent stress σ̄_I.
  double equivalent_stress(const State& state, int k) const {
    check(k);
    return std::sqrt(equivalent_squared(modal(state.membrane, state.moment)));
  }
  double equivalent_plastic_strain(const State& state, int k) const {
    check(k);
    return state.eps_p;
  }
  double damage(const State& state, int k) const {
    check(k);
    return state.D;
  }
  bool all_failed(const State& state) const { return state.failed; }

  double elastic_energy(const State& state) const {
    if (state.failed) return 0.0;
    return 0.5 *
           (state.membrane.dot(membrane_compliance_ * state.membrane) +
            state.moment.dot(bending_compliance_ * state.moment)) /
           (1.0 - state.D);
  }

  // The one output point sits on the mid-surface and stands for the whole thickness.
  double zeta(int k) const {
    check(k);
    return 0.0;
  }
  double weight(int k) const {
    check(k);
    return thickness_;
  }
  double thickness() const { return thickness_; }
  const Law& law() const { return law_; }

  // F·σs² = xᵀÂ_s x with s = sign(Q_tm): exposed so callers and tests can check
  // admissibility (F <= 1) without redoing the algebra.
  double ilyushin_function(const State& state) const {
    const double equivalent_squared_stress = equivalent_squared(modal(state.membrane, state.moment));
    return equivalent_squared_stress / ((1.0 - state.D) * (1.0 - state.D) * state.sigma_y * state.sigma_y);
  }

 private:
  // Resultants in the modal basis, scaled to stresses: column i holds
  // (n_i, m_i) = (N·q_i/d, 4 M·q_i/d²), so pure tension N0 and pure bending M0
  // both read σs. In these variables
  //   σ̄_I² = Σ_i w_i (n_i² + m_i² + s n_i m_i/√3),  Q_tm σs²/√3 = Σ_i w_i n_i m_i/√3.
  using Modal = Eigen::Matrix<double, 2, 3>;

  struct ReturnResult {
    Modal resultants;
    double d_eps_p;
  };

  // The 2×2 metric of a mode in the symmetrized variables h = (n, m √3/2),
  //   R_s = [[1, s/3], [s/3, 4/3]] = Σ_k ω_k u_k u_kᵀ,
  // and its eigenpairs in closed form; the flow of mode i then scales the
  // components h·u_k by 1/(1 + λ_i ω_k Δε̄p/σs) (derivation at plastic_return).
  struct RidgeMetric {
    double s;
    std::array<double, 2> omega;
    Vector2 u0, u1;
  };

  static RidgeMetric ridge_metric(double s) {
    RidgeMetric metric;
    metric.s = s;
    const double root = std::sqrt(1.0 + 4.0 * s * s);
    metric.omega = {(7.0 - root) / 6.0, (7.0 + root) / 6.0};
    // (R_s − ω_0 I) u_0 = 0 with u_0 ∝ (ω_0 − 4/3, s/3) ∝ (1 + √(1+4s²), −2s), never zero.
    const Vector2 u(1.0 + root, -2.0 * s);
    metric.u0 = u / u.norm();
    metric.u1 = Vector2(-metric.u0.y(), metric.u0.x());
    return metric;
  }

  static void check(int k) {
    if (k != 0)
      sphshell::detail::invalid_parameter("output point index", k, "Global has only point 0");
  }

  // The modal basis q_i is symmetric and orthogonal: (a, a, 0), (a, −a, 0), (0, 0, 1).
  Modal modal(const Vector3& membrane, const Vector3& moment) const {
    const double a = 1.0 / std::sqrt(2.0);
    Modal x;
    x(0, 0) = membrane_scale_ * a * (membrane.x() + membrane.y());
    x(0, 1) = membrane_scale_ * a * (membrane.x() - membrane.y());
    x(0, 2) = membrane_scale_ * membrane.z();
    x(1, 0) = moment_scale_ * a * (moment.x() + moment.y());
    x(1, 1) = moment_scale_ * a * (moment.x() - moment.y());
    x(1, 2) = moment_scale_ * moment.z();
    return x;
  }

  void cartesian(const Modal& x, Vector3& membrane, Vector3& moment) const {
    const double a = 1.0 / std::sqrt(2.0);
    const double n = 1.0 / membrane_scale_, m = 1.0 / moment_scale_;
    membrane = Vector3(n * a * (x(0, 0) + x(0, 1)), n * a * (x(0, 0) - x(0, 1)), n * x(0, 2));
    moment = Vector3(m * a * (x(1, 0) + x(1, 1)), m * a * (x(1, 0) - x(1, 1)), m * x(1, 2));
  }

  // σs² Q_tm/√3 = 4 NᵀΞM/(√3 d³): the signed coupling term of σ̄_I².
  double coupling_term(const Modal& x) const {
    double sum = 0.0;
    for (int i = 0; i < 3; ++i) sum += mises_eigenvalues_[std::size_t(i)] * x(0, i) * x(1, i);
    return sum / std::sqrt(3.0);
  }

  double equivalent_squared(const Modal& x) const {
    double uncoupled = 0.0;
    for (int i = 0; i < 3; ++i)
      uncoupled += mises_eigenvalues_[std::size_t(i)] * (x(0, i) * x(0, i) + x(1, i) * x(1, i));
    return uncoupled + std::abs(coupling_term(x));
  }

  const RidgeMetric& side_metric(double side) const { return side_metrics_[std::size_t(int(side) + 1)]; }

  ReturnResult plastic_return(const Modal& trial, double sigma_y_n) const {
    const double tolerance = ridge_tolerance * sigma_y_n * sigma_y_n;
    // Pure bending or pure tension: the trial is on the ridge and s = 0 keeps it there.
    const double trial_coupling = coupling_term(trial);
    if (std::abs(trial_coupling) <= tolerance) {
      const ReturnResult uncoupled = return_onto(trial, sigma_y_n, side_metric(0.0));
      if (std::abs(coupling_term(uncoupled.resultants)) <= tolerance) return uncoupled;
    }
    const double first_side = trial_coupling >= 0.0 ? 1.0 : -1.0;
    const ReturnResult first = return_onto(trial, sigma_y_n, side_metric(first_side));
    const double first_coupling = coupling_term(first.resultants);
    if (first_side * first_coupling >= -tolerance) return first;
    const ReturnResult second = return_onto(trial, sigma_y_n, side_metric(-first_side));
    const double second_coupling = coupling_term(second.resultants);
    if (-first_side * second_coupling >= -tolerance) return second;

    // Ridge: the coupling term changes sign between s = first_side and −first_side.
    double s_a = first_side, s_b = -first_side;
    double h_a = first_coupling, h_b = second_coupling;
    int retained = 0;
    for (int iteration = 0; iteration < max_ridge_iterations; ++iteration) {
      const double s = (s_a * h_b - s_b * h_a) / (h_b - h_a);
      const ReturnResult ridge = return_onto(trial, sigma_y_n, ridge_metric(s));
      const double h = coupling_term(ridge.resultants);
      if (std::abs(h) <= tolerance || std::abs(s_b - s_a) <= bracket_tolerance) return ridge;
      if ((h > 0.0) == (h_a > 0.0)) {
        s_a = s;
        h_a = h;
        if (retained == -1) h_b *= 0.5;
        retained = -1;
      } else {
        s_b = s;
        h_b = h;
        if (retained == 1) h_a *= 0.5;
        retained = 1;
      }
    }
    throw Error("sphshell: Global resultant return map did not find the Ilyushin ridge");
  }

  // Closest-point return onto xᵀÂ_s x = σs² for a fixed coupling coefficient
  // s ∈ [−1, 1], mode by mode. In the scaled modal variables z_i = (n_i, m_i) the
  // metric is S_s = [[1, s/(2√3)], [s/(2√3), 1]] and the return of the header reads
  //   z_i = (I + λ_i (Δε̄p/σs) W S_s)⁻¹ z_i*,  W = diag(1, 4/3)
  // (W carries K = diag(d, d³/12) into the scaled variables). With h = W^(−1/2) z
  // the matrix becomes the symmetric R_s = W^(1/2) S_s W^(1/2) = Σ_k ω_k u_k u_kᵀ, so
  // with p_ik = u_k·h_i* and u_ik = σs + λ_i ω_k Δε̄p (σs = σs,n + Ep Δε̄p):
  //   h_i = Σ_k (σs/u_ik) p_ik u_k,   σ̄_I² = σs² S,   S(Δε̄p) = Σ_ik w_i ω_k p_ik²/u_ik²,
  // and g = σ̄_I² − σs² = σs² (S − 1). The Newton iteration runs on φ = 1/√S − 1 =
  // σs/σ̄_I − 1 (as the J2 map of docs/method.md §5 does): φ is a power mean of the
  // u_ik, linear in Δε̄p, so it is increasing and concave, exactly linear for a single
  // mode, and Newton from below converges monotonically in a few steps.
  ReturnResult return_onto(const Modal& trial, double sigma_y_n, const RidgeMetric& metric) const {
    constexpr int terms = 6;
    const double half_root3 = 0.5 * std::sqrt(3.0);
    std::array<double, terms> p{}, a{}, b{}, inverse{};
    for (int i = 0; i < 3; ++i) {
      const Vector2 h(trial(0, i), half_root3 * trial(1, i));
      const double w = mises_eigenvalues_[std::size_t(i)], lambda = flow_eigenvalues_[std::size_t(i)];
      for (int k = 0; k < 2; ++k) {
        const std::size_t j = std::size_t(2 * i + k);
        p[j] = (k == 0 ? metric.u0 : metric.u1).dot(h);
        a[j] = w * metric.omega[std::size_t(k)] * p[j] * p[j];
        b[j] = lambda * metric.omega[std::size_t(k)];
      }
    }
    const double hardening = hardening_modulus_;
    // S and dS/dΔε̄p at Δε̄p; leaves σs/u_ik in inverse (times σs after the call).
    auto evaluate = [&](double d_eps_p, double& derivative) {
      const double sigma_y = sigma_y_n + hardening * d_eps_p;
      double sum = 0.0;
      derivative = 0.0;
      for (std::size_t j = 0; j < std::size_t(terms); ++j) {
        inverse[j] = 1.0 / (sigma_y + b[j] * d_eps_p);
        const double term = a[j] * inverse[j] * inverse[j];
        sum += term;
        derivative -= 2.0 * term * inverse[j] * (hardening + b[j]);
      }
      return sum;
    };
    auto resultants_at = [&](double d_eps_p) {
      const double sigma_y = sigma_y_n + hardening * d_eps_p;
      Modal x;
      for (int i = 0; i < 3; ++i) {
        const std::size_t j = std::size_t(2 * i);
        const Vector2 h = (sigma_y * inverse[j] * p[j]) * metric.u0 +
                          (sigma_y * inverse[j + 1] * p[j + 1]) * metric.u1;
        x(0, i) = h.x();
        x(1, i) = h.y() / half_root3;
      }
      return ReturnResult{x, d_eps_p};
    };

    double derivative = 0.0;
    double S = evaluate(0.0, derivative);
    if (S <= 1.0) return {trial, 0.0};
    // Bracket [lower, upper] with S(lower) > 1 > S(upper); upper < 0 means not found yet.
    double lower = 0.0, upper = -1.0, d_eps_p = 0.0;
    double trial_squared = 0.0;
    for (double term : a) trial_squared += term;
    const double growth_step = std::sqrt(trial_squared) / law_.youngs_modulus();
    for (int iteration = 0; iteration < max_newton_iterations; ++iteration) {
      if (iteration > 0) S = evaluate(d_eps_p, derivative);
      if (std::abs(S - 1.0) <= residual_tolerance) return resultants_at(d_eps_p);
      if (S > 1.0) lower = d_eps_p; else upper = d_eps_p;
      if (upper >= 0.0 && upper - lower <= bracket_tolerance * upper) return resultants_at(d_eps_p);
      // Newton on φ = 1/√S − 1: Δε̄p − φ/φ' = Δε̄p + 2S (√S − 1)/S'.
      double next = derivative < 0.0
                        ? d_eps_p - 2.0 * S * (S - 1.0) / ((std::sqrt(S) + 1.0) * derivative)
                        : -1.0;
      const bool outside = !(next > lower) || (upper >= 0.0 && !(next < upper));
      if (outside) next = upper >= 0.0 ? 0.5 * (lower + upper) : 2.0 * lower + growth_step;
      d_eps_p = next;
    }
    throw Error("sphshell: Global resultant return map (Newton on the plastic multiplier) "
                "did not converge");
  }

  void grow_damage(State& state, double d_eps_p) const {
    const double previous_eps_p = state.eps_p - d_eps_p;
    const double active = state.eps_p - std::max(previous_eps_p, damage_threshold_);
    if (active > 0.0) state.D += damage_rate_ * active;
    if (state.D >= critical_damage_) {
      state.D = critical_damage_;
      state.failed = true;
    }
  }

  Law law_;
  double thickness_;
  Matrix3 membrane_stiffness_, bending_stiffness_, membrane_compliance_, bending_compliance_;
  std::array<double, 3> mises_eigenvalues_{};
  std::array<double, 3> flow_eigenvalues_{};
  double membrane_scale_ = 1.0, moment_scale_ = 1.0;
  std::array<RidgeMetric, 3> side_metrics_{};  // s = −1, 0, 1
  double initial_yield_stress_ = std::numeric_limits<double>::infinity();
  double hardening_modulus_ = 0.0;
  double damage_threshold_ = 0.0;
  double critical_damage_ = 1.0;
  double damage_rate_ = 0.0;
};

}  // namespace sphshell::thickness
