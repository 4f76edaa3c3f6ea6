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
  using Vector6 = Eigen::Matrix<double, 6, 1>;
  using Matrix6 = Eigen::Matrix<double, 6, 6>;

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

    stiffness_.setZero();
    stiffness_.template topLeftCorner<3, 3>() = d * gamma;
    stiffness_.template bottomRightCorner<3, 3>() = d * d * d / 12.0 * gamma;
    compliance_.setZero();
    compliance_.template topLeftCorner<3, 3>() = (d * gamma).inverse();
    compliance_.template bottomRightCorner<3, 3>() = (d * d * d / 12.0 * gamma).inverse();

    uncoupled_metric_.setZero();
    uncoupled_metric_.template topLeftCorner<3, 3>() = xi / (d * d);
    uncoupled_metric_.template bottomRightCorner<3, 3>() = 16.0 * xi / (d * d * d * d);
    coupling_metric_.setZero();
    coupling_metric_.template topRightCorner<3, 3>() = 2.0 * xi / (std::sqrt(3.0) * d * d * d);
    coupling_metric_.template bottomLeftCorner<3, 3>() = 2.0 * xi / (std::sqrt(3.0) * d * d * d);

    // Γ and Ξ share the eigenvectors q_i (docs/method.md §5), so the 6×6 return decouples
    // into three 2×2 systems in (N·q_i, M·q_i); ΓΞ q_i = λ_i q_i.
    modal_basis_ << 1.0 / std::sqrt(2.0), 1.0 / std::sqrt(2.0), 0.0,
                    1.0 / std::sqrt(2.0), -1.0 / std::sqrt(2.0), 0.0,
                    0.0, 0.0, 1.0;
    for (int i = 0; i < 3; ++i) {
      const Vector3 q = modal_basis_.col(i);
      mises_eigenvalues_[std::size_t(i)] = q.dot(xi * q);
      flow_eigenvalues_[std::size_t(i)] = q.dot(gamma * xi * q);
    }
    section_stiffness_ << d, 0.0, 0.0, d * d * d / 12.0;
    uncoupled_modal_metric_ << 1.0 / (d * d), 0.0, 0.0, 16.0 / (d * d * d * d);
    coupling_modal_metric_ << 0.0, 2.0 / (std::sqrt(3.0) * d * d * d),
                              2.0 / (std::sqrt(3.0) * d * d * d), 0.0;

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
    Vector6 d_generalized_strain;
    d_generalized_strain << d_membrane_strain, d_curvature;
    const Vector6 trial = pack(state) / (1.0 - state.D) + stiffness_ * d_generalized_strain;
    Vector6 effective = trial;
    if constexpr (Law::has_plasticity) {
      if (equivalent(trial) > state.sigma_y) {
        const ReturnResult result = plastic_return(trial, state.sigma_y);
        effective = result.resultants;
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
    const Vector6 nominal = (1.0 - state.D) * effective;
    state.membrane = nominal.template head<3>();
    state.moment = nominal.template tail<3>();
    return resultants(state);
  }

  Resultants resultants(const State& state) const { return {state.membrane, state.moment}; }

  // The single output point is the Ilyushin generalized equivalent stress σ̄_I.
  double equivalent_stress(const State& state, int k) const {
    check(k);
    return equivalent(pack(state));
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
    const Vector6 x = pack(state);
    return 0.5 * x.dot(compliance_ * x) / (1.0 - state.D);
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
    const double equivalent_stress = equivalent(pack(state));
    return equivalent_stress * equivalent_stress /
           ((1.0 - state.D) * (1.0 - state.D) * state.sigma_y * state.sigma_y);
  }

 private:
  struct ReturnResult {
    Vector6 resultants;
    double d_eps_p;
  };

  static void check(int k) {
    if (k != 0)
      sphshell::detail::invalid_parameter("output point index", k, "Global has only point 0");
  }

  static Vector6 pack(const State& state) {
    Vector6 x;
    x << state.membrane, state.moment;
    return x;
  }

  // 4 NᵀΞM/(√3 d³) = σs² Q_tm/√3: the signed coupling term of σ̄_I².
  double coupling_term(const Vector6& x) const { return x.dot(coupling_metric_ * x); }

  double equivalent(const Vector6& x) const {
    return std::sqrt(x.dot(uncoupled_metric_ * x) + std::abs(coupling_term(x)));
  }

  ReturnResult plastic_return(const Vector6& trial, double sigma_y_n) const {
    const double tolerance = ridge_tolerance * sigma_y_n * sigma_y_n;
    // Pure bending or pure tension: the trial is on the ridge and s = 0 keeps it there.
    if (std::abs(coupling_term(trial)) <= tolerance) {
      const ReturnResult uncoupled = return_onto(trial, sigma_y_n, 0.0);
      if (std::abs(coupling_term(uncoupled.resultants)) <= tolerance) return uncoupled;
    }
    const double first_side = coupling_term(trial) >= 0.0 ? 1.0 : -1.0;
    const ReturnResult first = return_onto(trial, sigma_y_n, first_side);
    const double first_coupling = coupling_term(first.resultants);
    if (first_side * first_coupling >= -tolerance) return first;
    const ReturnResult second = return_onto(trial, sigma_y_n, -first_side);
    const double second_coupling = coupling_term(second.resultants);
    if (-first_side * second_coupling >= -tolerance) return second;

    // Ridge: the coupling term changes sign between s = first_side and −first_side.
    double s_a = first_side, s_b = -first_side;
    double h_a = first_coupling, h_b = second_coupling;
    int retained = 0;
    for (int iteration = 0; iteration < max_ridge_iterations; ++iteration) {
      const double s = (s_a * h_b - s_b * h_a) / (h_b - h_a);
      const ReturnResult ridge = return_onto(trial, sigma_y_n, s);
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
  // s ∈ [−1, 1], solved mode by mode: y_i = (I + c λ_i K S_s)⁻¹ y_i* with
  // y_i = (N·q_i, M·q_i), K = diag(d, d³/12), S_s the 2×2 metric, c = d Δε̄p/σs.
  ReturnResult return_onto(const Vector6& trial, double sigma_y_n, double s) const {
    const Matrix2 metric = uncoupled_modal_metric_ + s * coupling_modal_metric_;
    const Matrix2 flow = section_stiffness_ * metric;
    Eigen::Matrix<double, 2, 3> modal_trial;
    modal_trial.row(0) = (modal_basis_.transpose() * trial.template head<3>()).transpose();
    modal_trial.row(1) = (modal_basis_.transpose() * trial.template tail<3>()).transpose();
    Eigen::Matrix<double, 2, 3> modal = modal_trial;
    const double d = thickness_;
    const double hardening = hardening_modulus_;
    auto residual = [&](double d_eps_p, double& derivative) {
      const double sigma_y = sigma_y_n + hardening * d_eps_p;
      const double c = d * d_eps_p / sigma_y;
      const double dc_dp = d * sigma_y_n / (sigma_y * sigma_y);
      double g = -sigma_y * sigma_y;
      derivative = -2.0 * sigma_y * hardening;
      for (int i = 0; i < 3; ++i) {
        const double lambda = flow_eigenvalues_[std::size_t(i)];
        const double weight = mises_eigenvalues_[std::size_t(i)];
        const Matrix2 inverse = (Matrix2::Identity() + c * lambda * flow).inverse();
        const Vector2 y = inverse * modal_trial.col(i);
        const Vector2 dy_dc = -inverse * (lambda * flow * y);
        modal.col(i) = y;
        g += weight * y.dot(metric * y);
        derivative += 2.0 * weight * y.dot(metric * dy_dc) * dc_dp;
      }
      return g;
    };
    auto resultants_of = [&]() {
      Vector6 x;
      x << modal_basis_ * modal.row(0).transpose(), modal_basis_ * modal.row(1).transpose();
      return x;
    };

    double derivative = 0.0;
    if (residual(0.0, derivative) <= 0.0) return {trial, 0.0};
    // Bracket [lower, upper] with g(lower) > 0 > g(upper); upper < 0 means not found yet.
    double lower = 0.0, upper = -1.0, d_eps_p = 0.0;
    const double growth_step =
        std::sqrt(trial.dot((uncoupled_metric_ + s * coupling_metric_) * trial)) /
        law_.youngs_modulus();
    for (int iteration = 0; iteration < max_newton_iterations; ++iteration) {
      const double g = residual(d_eps_p, derivative);
      const double sigma_y = sigma_y_n + hardening * d_eps_p;
      if (std::abs(g) <= residual_tolerance * sigma_y * sigma_y) return {resultants_of(), d_eps_p};
      if (g > 0.0) lower = d_eps_p; else upper = d_eps_p;
      if (upper >= 0.0 && upper - lower <= bracket_tolerance * upper) return {resultants_of(), d_eps_p};
      double next = derivative < 0.0 ? d_eps_p - g / derivative : -1.0;
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
  Matrix6 stiffness_, compliance_;
  Matrix6 uncoupled_metric_, coupling_metric_;
  Matrix3 modal_basis_;
  std::array<double, 3> mises_eigenvalues_{};
  std::array<double, 3> flow_eigenvalues_{};
  Matrix2 section_stiffness_, uncoupled_modal_metric_, coupling_modal_metric_;
  double initial_yield_stress_ = std::numeric_limits<double>::infinity();
  double hardening_modulus_ = 0.0;
  double damage_threshold_ = 0.0;
  double critical_damage_ = 1.0;
  double damage_rate_ = 0.0;
};

}  // namespace sphshell::thickness
