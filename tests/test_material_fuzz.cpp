// Random states and random strain increments: the invariants every return must
// keep, agreement of the closed-form and generic 3×3 return maps, and of the
// batched update (update_lanes) with the single-point one.

#include <sphshell/material/all.hpp>

#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <array>
#include <random>
#include <string>

using namespace sphshell;
using namespace sphshell::material;

namespace {

constexpr int increments_per_law = 100000;

double mises(const StressVoigt& s) {
  return std::sqrt(s.x() * s.x() - s.x() * s.y() + s.y() * s.y() + 3.0 * s.z() * s.z());
}

struct Sampler {
  std::mt19937_64 engine{20150213};
  std::normal_distribution<double> normal{0.0, 1.0};
  std::uniform_real_distribution<double> uniform{0.0, 1.0};

  Eigen::Vector3d direction() {
    Eigen::Vector3d v(normal(engine), normal(engine), normal(engine));
    while (v.norm() < 1e-3) v = Eigen::Vector3d(normal(engine), normal(engine), normal(engine));
    return v.normalized();
  }
  // Magnitude log-uniform in [1e-6, 1e-2].
  StrainVoigt strain_increment() {
    return std::pow(10.0, -6.0 + 4.0 * uniform(engine)) * direction();
  }
  // A stress with σ̄ = radius, radius on the surface in 30 % of the draws.
  StressVoigt stress_with_equivalent(double radius) {
    const double fraction = uniform(engine) < 0.3 ? 1.0 : uniform(engine);
    const StressVoigt d = direction();
    return fraction * radius / mises(d) * d;
  }
};

// Largest violation seen, with the draw that produced it, so a failure is reproducible.
struct Worst {
  double value = 0.0;
  int draw = -1;
  void see(double candidate, int index) {
    if (!(candidate <= value)) {  // NaN also lands here and stays
      value = candidate;
      draw = index;
    }
  }
};

}  // namespace

TEST_CASE("Fuzz: J2 returns stay on the yield surface, eps_p never decreases, both forms agree",
          "[material][fuzz]") {
  const J2Plasticity law({210e9, 0.3, 235e6, 1.5e9});
  const ReturnMapOptions generic_options{ReturnMapForm::generic, InitialGuess::appendix_b, 0,
                                         NewtonFunction::normalized};
  Sampler sampler;
  Worst outside, off_surface, form_mismatch_stress, form_mismatch_strain, hardening_drift,
      start_mismatch;
  int non_finite = 0, decreasing = 0, plastic_count = 0;
  for (int draw = 0; draw < increments_per_law; ++draw) {
    J2Plasticity::State state;
    state.eps_p = 0.3 * sampler.uniform(sampler.engine);
    state.sigma_y = 235e6 + 1.5e9 * state.eps_p;
    state.stress = sampler.stress_with_equivalent(state.sigma_y);
    const StrainVoigt d_eps = sampler.strain_increment();

    J2Plasticity::State closed = state, generic = state;
    const auto result = law.update(closed, d_eps);
    law.update(generic, d_eps, generic_options);

    if (!closed.stress.allFinite() || !std::isfinite(closed.eps_p) || !generic.stress.allFinite())
      ++non_finite;
    if (closed.eps_p < state.eps_p) ++decreasing;
    outside.see(mises(closed.stress) / closed.sigma_y - 1.0, draw);
    hardening_drift.see(std::abs(closed.sigma_y - (235e6 + 1.5e9 * closed.eps_p)) / closed.sigma_y,
                        draw);
    if (result.plastic) {
      ++plastic_count;
      off_surface.see(std::abs(mises(closed.stress) / closed.sigma_y - 1.0), draw);
    }
    form_mismatch_stress.see((closed.stress - generic.stress).norm() / closed.sigma_y, draw);
    const double increment = closed.eps_p - state.eps_p;
    // Relative to Δε̄p + σs/E: |g| ≤ 1e-12 σs² pins Δε̄p only to ~1e-12 σs/E absolutely.
    form_mismatch_strain.see(std::abs(generic.eps_p - closed.eps_p) / (increment + 235e6 / 210e9),
                             draw);
    // Every tenth draw also through the other starts and the squared Newton function.
    if (draw % 10 == 0 && result.plastic) {
      for (const InitialGuess guess : {InitialGuess::zero, InitialGuess::radial_return}) {
        for (const NewtonFunction function :
             {NewtonFunction::normalized, NewtonFunction::squared}) {
          J2Plasticity::State other = state;
          law.update(other, d_eps,
                     ReturnMapOptions{ReturnMapForm::closed_form, guess, 0, function});
          // |g| ≤ 1e-12 σs² pins Δε̄p to ~1e-12 σs/E in absolute terms, hence the floor.
          start_mismatch.see(std::abs(other.eps_p - closed.eps_p) / (increment + 235e6 / 210e9),
                             draw);
        }
      }
    }
  }
  CAPTURE(outside.draw, off_surface.draw, form_mismatch_stress.draw, form_mismatch_strain.draw,
          start_mismatch.draw);
  CHECK(non_finite == 0);
  CHECK(decreasing == 0);
  CHECK(plastic_count > increments_per_law / 4);
  CHECK(outside.value <= 1e-10);
  CHECK(off_surface.value <= 1e-10);
  CHECK(hardening_drift.value <= 1e-13);
  CHECK(form_mismatch_stress.value <= 1e-9);
  CHECK(form_mismatch_strain.value <= 1e-9);
  CHECK(start_mismatch.value <= 1e-9);
}

TEST_CASE("Fuzz: damage stays within (1-D) sigma_s, D and eps_p never decrease, D <= Dc",
          "[material][fuzz]") {
  const LemaitreDamage::Parameters parameters{210e9, 0.3, 235e6, 1.5e9, 0.02, 0.37, 0.24};
  const LemaitreDamage law(parameters);
  const ReturnMapOptions generic_options{ReturnMapForm::generic, InitialGuess::appendix_b, 0,
                                         NewtonFunction::normalized};
  Sampler sampler;
  Worst outside, off_surface, form_mismatch_stress, form_mismatch_damage;
  int non_finite = 0, decreasing = 0, above_critical = 0, failed_with_stress = 0, failures = 0,
      damaging = 0;
  for (int draw = 0; draw < increments_per_law; ++draw) {
    LemaitreDamage::State state;
    state.eps_p = 0.4 * sampler.uniform(sampler.engine);
    state.sigma_y = 235e6 + 1.5e9 * state.eps_p;
    state.D = state.eps_p > 0.02 ? 0.999 * parameters.Dc * sampler.uniform(sampler.engine) : 0.0;
    state.failed = false;
    state.stress = sampler.stress_with_equivalent((1.0 - state.D) * state.sigma_y);
    const StrainVoigt d_eps = sampler.strain_increment();

    LemaitreDamage::State closed = state, generic = state;
    const auto result = law.update(closed, d_eps);
    law.update(generic, d_eps, generic_options);

    if (!closed.stress.allFinite() || !std::isfinite(closed.eps_p) || !std::isfinite(closed.D) ||
        !generic.stress.allFinite())
      ++non_finite;
    if (closed.eps_p < state.eps_p || closed.D < state.D) ++decreasing;
    if (closed.D > parameters.Dc) ++above_critical;
    if (closed.D > state.D) ++damaging;
    if (closed.failed) {
      ++failures;
      if (closed.stress.norm() != 0.0 || closed.D != parameters.Dc) ++failed_with_stress;
      continue;
    }
    const double damaged_yield = (1.0 - closed.D) * closed.sigma_y;
    outside.see(mises(closed.stress) / damaged_yield - 1.0, draw);
    if (result.plastic) off_surface.see(std::abs(mises(closed.stress) / damaged_yield - 1.0), draw);
    form_mismatch_stress.see((closed.stress - generic.stress).norm() / closed.sigma_y, draw);
    form_mismatch_damage.see(std::abs(closed.D - generic.D), draw);
  }
  CAPTURE(outside.draw, off_surface.draw, form_mismatch_stress.draw, form_mismatch_damage.draw,
          failures, damaging);
  CHECK(non_finite == 0);
  CHECK(decreasing == 0);
  CHECK(above_critical == 0);
  CHECK(failed_with_stress == 0);
  CHECK(failures > 0);
  CHECK(damaging > increments_per_law / 10);
  CHECK(outside.value <= 1e-10);
  CHECK(off_surface.value <= 1e-10);
  CHECK(form_mismatch_stress.value <= 1e-9);
  CHECK(form_mismatch_damage.value <= 1e-10);
}

// The default closed form runs a reorganized fast path (return_map.hpp,
// closed_form_default) and leaves for the kernel path on anything unusual; both
// must give the same converged return, within what the tolerance allows.
TEST_CASE("Fuzz: the closed form's fast path agrees with the kernel path", "[material]") {
  Sampler sampler;
  std::uniform_real_distribution<double> exponent(-9.0, 1.0);
  int fast_one_correction = 0;
  for (const double nu : {-0.5, 0.0, 0.3, 0.49}) {
    for (const double scale : {1.0, 1e6, 210e9}) {
      const PlaneStressElasticity elasticity(scale, nu);
      for (const double plastic_fraction : {0.0, 1e-3, 0.3}) {
        const return_map::ClosedFormConstants constants(elasticity, plastic_fraction * scale);
        for (int draw = 0; draw < 2000; ++draw) {
          const double yield_stress = scale * 1e-3 * (0.5 + sampler.uniform(sampler.engine));
          // σ̄* from just above the surface to 11× it: both series limits and the bracket get hit.
          const StressVoigt trial = sampler.stress_with_equivalent(
              yield_stress * (1.0 + std::pow(10.0, exponent(sampler.engine))));
          if (!(mises(trial) > yield_stress)) continue;
          const auto fast = return_map::closed_form(constants, trial, yield_stress);
          const auto reference =
              return_map::detail::closed_form_general(constants, trial, yield_stress, {});
          const double sigma_s =
              yield_stress + plastic_fraction * scale * fast.plastic_strain_increment;
          CHECK(std::abs(mises(fast.stress) / sigma_s - 1.0) <= 1e-12);
          CHECK((fast.stress - reference.stress).norm() <= 2e-12 * yield_stress);
          CHECK(std::abs(fast.iterations - reference.iterations) <= 1);
          if (fast.iterations == 1) ++fast_one_correction;
        }
      }
    }
  }
  CHECK(fast_one_correction > 0);
}

// The batched update (lanes.hpp) against update(), lane by lane, over the fuzz
// stream (states on or inside the surface, increments 1e-6..1e-2) and over a
// stream of explicit-step increments (1e-7..1e-5, where the closed form's fast
// path serves nearly every lane), in batches of 1, 5, 8 and 16 lanes. The two
// run the same operations, so they should agree to the last bit or, where the
// compiler contracts multiply-adds differently (-march with FMA), to round-off.
template <int N>
void check_lanes_against_update(double smallest_exponent, double largest_exponent, int draws) {
  const J2Plasticity law({210e9, 0.3, 235e6, 1.5e9});
  const Elastic elastic({210e9, 0.3});
  Sampler sampler;
  Worst stress_difference, strain_difference, elastic_difference;
  int plastic = 0, reported_plastic = 0, fast = 0, unequal_bits = 0;
  for (int batch = 0; batch < draws / N; ++batch) {
    std::array<J2Plasticity::State, N> states;
    std::array<Elastic::State, N> elastic_states;
    VoigtLanes<N> d_eps;
    for (int k = 0; k < N; ++k) {
      J2Plasticity::State& state = states[std::size_t(k)];
      state.eps_p = 0.3 * sampler.uniform(sampler.engine);
      state.sigma_y = 235e6 + 1.5e9 * state.eps_p;
      state.stress = sampler.stress_with_equivalent(state.sigma_y);
      elastic_states[std::size_t(k)].stress = state.stress;
      const double magnitude =
          std::pow(10.0, smallest_exponent + (largest_exponent - smallest_exponent) * sampler.uniform(sampler.engine));
      d_eps.set(k, magnitude * sampler.direction());
    }
    J2Plasticity::Lanes<N> lanes;
    Elastic::Lanes<N> elastic_lanes;
    for (int k = 0; k < N; ++k) {
      lanes.set_state(k, states[std::size_t(k)]);
      elastic_lanes.set_state(k, elastic_states[std::size_t(k)]);
    }
    reported_plastic += law.update_lanes(lanes, d_eps);
    elastic.update_lanes(elastic_lanes, d_eps);
    for (int k = 0; k < N; ++k) {
      J2Plasticity::State single = states[std::size_t(k)];
      const StrainVoigt increment = d_eps.at(k);
      const StressVoigt trial = single.stress + law.elasticity().stress_increment(increment);
      if (law.update(single, increment).plastic) {
        ++plastic;
        const double sum = trial.x() + trial.y(), diff = trial.x() - trial.y();
        const double a = 0.25 * sum * sum, b = 0.75 * diff * diff + 3.0 * trial.z() * trial.z();
        fast += return_map::detail::closed_form_lane(return_map::ClosedFormConstants(law.elasticity(), 1.5e9), sum,
                                                     diff, trial.z(), a, b, std::sqrt(a + b),
                                                     states[std::size_t(k)].sigma_y)
                    .fast;
      }
      const J2Plasticity::State batched = lanes.state(k);
      stress_difference.see((batched.stress - single.stress).norm() / single.sigma_y, batch * N + k);
      strain_difference.see(std::abs(batched.eps_p - single.eps_p) / (single.eps_p + 235e6 / 210e9), batch * N + k);
      if (!(batched.stress == single.stress && batched.eps_p == single.eps_p && batched.sigma_y == single.sigma_y))
        ++unequal_bits;
      Elastic::State elastic_single = elastic_states[std::size_t(k)];
      elastic.update(elastic_single, increment);
      elastic_difference.see((elastic_lanes.state(k).stress - elastic_single.stress).norm() / 235e6, batch * N + k);
    }
  }
  CAPTURE(N, plastic, fast, unequal_bits, stress_difference.draw, strain_difference.draw);
  INFO("largest differences: stress " << stress_difference.value << " of sigma_s, eps_p "
                                      << strain_difference.value << ", elastic stress " << elastic_difference.value);
  CHECK(reported_plastic == plastic);
  CHECK(plastic > draws / 10);
  CHECK(stress_difference.value <= 1e-14);
  CHECK(strain_difference.value <= 1e-14);
  CHECK(elastic_difference.value <= 1e-14);
  // Without FMA contraction the operations are the same, hence bitwise equal.
#if !defined(__FMA__)
  CHECK(unequal_bits == 0);
#endif
  WARN("update_lanes<" << N << ">: " << plastic << " plastic lanes (" << fast << " on the fast path), "
                       << unequal_bits << " not bitwise equal; largest stress difference "
                       << stress_difference.value << " of sigma_s");
}

TEST_CASE("Fuzz: the batched update (update_lanes) agrees with update() lane by lane", "[material][fuzz]") {
  // The fuzz stream: increments 1e-6..1e-2.
  check_lanes_against_update<1>(-6.0, -2.0, 20000);
  check_lanes_against_update<5>(-6.0, -2.0, 50000);
  check_lanes_against_update<8>(-6.0, -2.0, 50000);
  check_lanes_against_update<16>(-6.0, -2.0, 50000);
  // Explicit-step increments: the fast path.
  check_lanes_against_update<5>(-7.0, -5.0, 50000);
  check_lanes_against_update<16>(-7.0, -5.0, 50000);
}

TEST_CASE("The batched update refuses a non-finite increment with update()'s message", "[material]") {
  const J2Plasticity law({210e9, 0.3, 235e6, 1.5e9});
  J2Plasticity::Lanes<5> lanes;
  for (int k = 0; k < 5; ++k) lanes.set_state(k, law.initial_state());
  VoigtLanes<5> d_eps;
  d_eps.set(3, StrainVoigt(0.0, std::nan(""), 0.0));
  J2Plasticity::State single = law.initial_state();
  std::string expected;
  try {
    law.update(single, d_eps.at(3));
  } catch (const Error& error) {
    expected = error.what();
  }
  CHECK(!expected.empty());
  CHECK_THROWS_WITH(law.update_lanes(lanes, d_eps), expected);
  // Nothing changed.
  for (int k = 0; k < 5; ++k) CHECK(lanes.state(k).stress == StressVoigt::Zero());
}
