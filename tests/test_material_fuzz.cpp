// Random states and random strain increments: the invariants every return must
// keep, and agreement of the closed-form and generic 3×3 return maps.

#include <sphshell/material/all.hpp>

#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <random>

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
