// Cost of the integral-point stress update along a strain stream that keeps
// yielding, like the 500 steps of the paper's Table 1: J2's return map in its
// variants, and beside it the rate-dependent laws (JohnsonCook, CowperSymonds)
// on the same stream with a time step per increment.
//
// The stream: a state preloaded to 1.2× the uniaxial yield strain, then 500
// increments whose direction swings between tension (1, −½, 0) and shear
// (0, 0, √3) twice, with magnitudes 2.5–7.5e-6 — the size of one explicit time
// step in the paper's plate problems (σ* exceeds σs by ~0.5 %). A coarse
// variant (6× larger increments) is reported too. Each benchmark cycles
// through the stream and resets the state at every pass.

#include <sphshell/material/all.hpp>

#include <benchmark/benchmark.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <vector>

using namespace sphshell;
using namespace sphshell::material;

namespace {

constexpr double youngs_modulus = 210e9;
constexpr double poisson_ratio = 0.3;
constexpr double yield_stress = 235e6;
constexpr double plastic_modulus = 1e9;
constexpr int stream_length = 500;
constexpr double pi = 3.14159265358979323846;

const J2Plasticity j2_law({youngs_modulus, poisson_ratio, yield_stress, plastic_modulus});
const Elastic elastic_law({youngs_modulus, poisson_ratio});
// ε̄sp = 0: damage grows from the first plastic step; ε̄cp large so no point fails in the stream.
const LemaitreDamage damage_law({youngs_modulus, poisson_ratio, yield_stress, plastic_modulus, 0.0,
                                 0.5, 0.9});

// The rate-dependent laws on the same stream, one increment per time step of
// rate_time_step (the stream's 5e-6 increments then run at ~50 /s).
constexpr double rate_time_step = 1e-7;
// Johnson & Cook (1983) 4340 steel's B, n, C, m, Tm and (1985) failure
// constants, with the stream's E, ν and A = σs0 so that the preloaded state
// yields as J2's does; adiabatic heating on (β = 0.9, ρ = 7850, cp = 477).
JohnsonCook::Parameters johnson_cook_parameters() {
  JohnsonCook::Parameters p{};
  p.E = youngs_modulus;
  p.nu = poisson_ratio;
  p.A = yield_stress;
  p.B = 510e6;
  p.n = 0.26;
  p.C = 0.014;
  p.reference_strain_rate = 1.0;
  p.m = 1.03;
  p.reference_temperature = 293.0;
  p.melting_temperature = 1793.0;
  p.initial_temperature = 293.0;
  p.taylor_quinney = 0.9;
  p.density = 7850.0;
  p.specific_heat = 477.0;
  p.D1 = -0.80;
  p.D2 = 2.10;
  p.D3 = -0.5;
  p.D4 = 0.002;
  p.D5 = 0.61;
  return p;
}
const JohnsonCook johnson_cook_law(johnson_cook_parameters());
// Mild steel's Cowper–Symonds constants (D = 40.4 /s, q = 5) on J2's hardening.
const CowperSymonds cowper_symonds_law({youngs_modulus, poisson_ratio, yield_stress, plastic_modulus, 40.4, 5.0});
// D so large that the rate factor is 1 in double: J2's return plus the test for it.
const CowperSymonds cowper_symonds_static_law({youngs_modulus, poisson_ratio, yield_stress, plastic_modulus,
                                               1e300, 5.0});

std::vector<StrainVoigt> tension_shear_stream(double magnitude) {
  std::vector<StrainVoigt> stream;
  stream.reserve(stream_length);
  for (int k = 0; k < stream_length; ++k) {
    const double angle = 0.25 * pi * (1.0 - std::cos(4.0 * pi * k / stream_length));
    const double size = magnitude * (1.0 + 0.5 * std::sin(6.0 * pi * k / stream_length));
    stream.emplace_back(size * std::cos(angle), -0.5 * size * std::cos(angle),
                        std::sqrt(3.0) * size * std::sin(angle));
  }
  return stream;
}

template <class Law>
typename Law::State preloaded(const Law& law, const StrainVoigt& total_strain) {
  typename Law::State state = law.initial_state();
  for (int step = 0; step < 100; ++step) law.update(state, total_strain / 100.0);
  return state;
}

const StrainVoigt preload_strain =
    1.2 * yield_stress / youngs_modulus * StrainVoigt(1.0, -0.5, 0.0);
const std::vector<StrainVoigt> stream = tension_shear_stream(5e-6);
const std::vector<StrainVoigt> coarse_stream = tension_shear_stream(3e-5);
// From the unstressed state, increments a thousand times smaller: every step
// elastic (the yield test only), as most points of a run are most of the time.
const std::vector<StrainVoigt> elastic_stream = tension_shear_stream(5e-9);

// One update per iteration along `increments`, the state back at `start`
// after each pass; update(state, increment) is the law's call being timed.
template <class State, class Update>
void stream_updates(benchmark::State& benchmark_state, const State& start,
                    const std::vector<StrainVoigt>& increments, Update&& update) {
  State state = start;
  std::size_t index = 0;
  for (auto _ : benchmark_state) {
    auto result = update(state, increments[index]);
    benchmark::DoNotOptimize(result);
    benchmark::DoNotOptimize(state);
    if (++index == increments.size()) {
      index = 0;
      state = start;
    }
  }
  benchmark_state.SetItemsProcessed(benchmark_state.iterations());
}

template <class Law>
void run_stream(benchmark::State& benchmark_state, const Law& law, const typename Law::State& start,
                const std::vector<StrainVoigt>& increments, const ReturnMapOptions& options) {
  stream_updates(benchmark_state, start, increments,
                 [&](typename Law::State& state, const StrainVoigt& increment) {
                   return law.update(state, increment, options);
                 });
}

template <class Law>
void run_rate_stream(benchmark::State& benchmark_state, const Law& law, const typename Law::State& start,
                     const std::vector<StrainVoigt>& increments) {
  const UpdateContext context{rate_time_step};
  stream_updates(benchmark_state, start, increments,
                 [&](typename Law::State& state, const StrainVoigt& increment) {
                   return law.update(state, increment, context);
                 });
}

ReturnMapOptions options_with(ReturnMapForm form, InitialGuess guess,
                              NewtonFunction function = NewtonFunction::normalized,
                              int fixed_iterations = 0) {
  ReturnMapOptions options;
  options.form = form;
  options.initial_guess = guess;
  options.newton_function = function;
  options.fixed_iterations = fixed_iterations;
  return options;
}

void BM_elastic_update(benchmark::State& state) {
  run_stream(state, elastic_law, preloaded(elastic_law, preload_strain), stream, {});
}
void BM_j2_closed_appendix_b(benchmark::State& state) {
  run_stream(state, j2_law, preloaded(j2_law, preload_strain), stream, {});
}
void BM_j2_closed_zero_start(benchmark::State& state) {
  run_stream(state, j2_law, preloaded(j2_law, preload_strain), stream,
             options_with(ReturnMapForm::closed_form, InitialGuess::zero));
}
void BM_j2_closed_radial_start(benchmark::State& state) {
  run_stream(state, j2_law, preloaded(j2_law, preload_strain), stream,
             options_with(ReturnMapForm::closed_form, InitialGuess::radial_return));
}
void BM_j2_closed_squared_g(benchmark::State& state) {
  run_stream(
      state, j2_law, preloaded(j2_law, preload_strain), stream,
      options_with(ReturnMapForm::closed_form, InitialGuess::appendix_b, NewtonFunction::squared));
}
void BM_j2_closed_fixed_3(benchmark::State& state) {
  run_stream(state, j2_law, preloaded(j2_law, preload_strain), stream,
             options_with(ReturnMapForm::closed_form, InitialGuess::appendix_b,
                          NewtonFunction::normalized, 3));
}
void BM_j2_generic_appendix_b(benchmark::State& state) {
  run_stream(state, j2_law, preloaded(j2_law, preload_strain), stream,
             options_with(ReturnMapForm::generic, InitialGuess::appendix_b));
}
void BM_j2_closed_coarse_stream(benchmark::State& state) {
  run_stream(state, j2_law, preloaded(j2_law, preload_strain), coarse_stream, {});
}
void BM_damage_closed(benchmark::State& state) {
  run_stream(state, damage_law, preloaded(damage_law, preload_strain), stream, {});
}
void BM_johnson_cook(benchmark::State& state) {
  run_rate_stream(state, johnson_cook_law, preloaded(johnson_cook_law, preload_strain), stream);
}
void BM_cowper_symonds(benchmark::State& state) {
  run_rate_stream(state, cowper_symonds_law, preloaded(cowper_symonds_law, preload_strain), stream);
}
void BM_cowper_symonds_huge_d(benchmark::State& state) {
  run_rate_stream(state, cowper_symonds_static_law, preloaded(cowper_symonds_static_law, preload_strain), stream);
}
void BM_j2_elastic_steps(benchmark::State& state) {
  run_stream(state, j2_law, j2_law.initial_state(), elastic_stream, {});
}
void BM_johnson_cook_elastic_steps(benchmark::State& state) {
  run_rate_stream(state, johnson_cook_law, johnson_cook_law.initial_state(), elastic_stream);
}
void BM_cowper_symonds_elastic_steps(benchmark::State& state) {
  run_rate_stream(state, cowper_symonds_law, cowper_symonds_law.initial_state(), elastic_stream);
}

// One stress point: 5 integral points through the thickness (Gauss–Legendre
// positions), strains ε + ζκ with a membrane stream and a bending stream.
void BM_stress_point_5_integral_points(benchmark::State& benchmark_state) {
  constexpr int points = 5;
  constexpr double thickness = 0.01;
  const std::array<double, points> zeta = {
      -0.9061798459386640 * thickness / 2, -0.5384693101056831 * thickness / 2, 0.0,
      0.5384693101056831 * thickness / 2, 0.9061798459386640 * thickness / 2};
  std::vector<StrainVoigt> curvature_stream(stream.size());
  for (std::size_t k = 0; k < stream.size(); ++k)
    curvature_stream[k] = stream[(k + stream.size() / 2) % stream.size()] / (thickness / 2);
  std::array<J2Plasticity::State, points> start;
  for (int p = 0; p < points; ++p)
    start[p] = preloaded(j2_law, preload_strain * (1.0 + 0.3 * zeta[p] / thickness));
  std::array<J2Plasticity::State, points> states = start;
  std::size_t index = 0;
  for (auto _ : benchmark_state) {
    for (int p = 0; p < points; ++p) {
      auto result = j2_law.update(states[p], stream[index] + zeta[p] * curvature_stream[index]);
      benchmark::DoNotOptimize(result);
    }
    benchmark::DoNotOptimize(states);
    if (++index == stream.size()) {
      index = 0;
      states = start;
    }
  }
  benchmark_state.SetItemsProcessed(benchmark_state.iterations() * points);
}

// Batched updates (update_lanes, material/lanes.hpp), N lanes per call; the
// counter ns_per_lane is the time per call over N. Lane k follows the stream
// from offset 37k (so the lanes differ), from the preloaded state scaled by
// 1 + 0.3(k/(N−1) − ½) (all on the yield surface). `plastic_share` is the
// share of lane updates that yielded.
template <int N>
std::vector<VoigtLanes<N>> lane_stream(const std::vector<StrainVoigt>& increments, bool alternate_sign) {
  std::vector<VoigtLanes<N>> lanes(increments.size());
  for (std::size_t i = 0; i < increments.size(); ++i)
    for (int k = 0; k < N; ++k) {
      const double sign = alternate_sign && i % 2 ? -1.0 : 1.0;
      lanes[i].set(k, sign * increments[(i + 37 * std::size_t(k)) % increments.size()]);
    }
  return lanes;
}

double lane_scale(int k, int lanes) { return lanes == 1 ? 1.0 : 1.0 + 0.3 * (double(k) / (lanes - 1) - 0.5); }

template <int N>
void run_lanes(benchmark::State& benchmark_state, const J2Plasticity::Lanes<N>& start,
               const std::vector<VoigtLanes<N>>& increments) {
  J2Plasticity::Lanes<N> lanes = start;
  std::size_t index = 0;
  long plastic = 0;
  for (auto _ : benchmark_state) {
    plastic += j2_law.update_lanes(lanes, increments[index]);
    benchmark::DoNotOptimize(lanes);
    if (++index == increments.size()) {
      index = 0;
      lanes = start;
    }
  }
  benchmark_state.SetItemsProcessed(benchmark_state.iterations() * N);
  benchmark_state.counters["ns_per_lane"] =
      benchmark::Counter(N * 1e-9, benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kInvert);
  benchmark_state.counters["plastic_share"] = double(plastic) / (double(benchmark_state.iterations()) * N);
}

// Every lane yields at (nearly) every step: the closed-form return for all lanes.
template <int N>
void BM_j2_batched_plastic(benchmark::State& benchmark_state) {
  J2Plasticity::Lanes<N> start;
  for (int k = 0; k < N; ++k) start.set_state(k, preloaded(j2_law, lane_scale(k, N) * preload_strain));
  run_lanes(benchmark_state, start, lane_stream<N>(stream, false));
}

// No lane yields: the elastic predictor and the yield check. The lanes start
// inside the surface (half the preload) and the increments alternate in sign.
template <int N>
void BM_j2_batched_elastic(benchmark::State& benchmark_state) {
  J2Plasticity::Lanes<N> start;
  for (int k = 0; k < N; ++k) start.set_state(k, preloaded(j2_law, 0.5 * lane_scale(k, N) * preload_strain));
  run_lanes(benchmark_state, start, lane_stream<N>(stream, true));
}

// BM_stress_point_5_integral_points through the batched update: the section's
// states stay an array of State, copied into lanes and back around the call
// (material::update_lanes), as a section loop that keeps its storage would do.
void BM_stress_point_5_integral_points_batched(benchmark::State& benchmark_state) {
  constexpr int points = 5;
  constexpr double thickness = 0.01;
  const std::array<double, points> zeta = {
      -0.9061798459386640 * thickness / 2, -0.5384693101056831 * thickness / 2, 0.0,
      0.5384693101056831 * thickness / 2, 0.9061798459386640 * thickness / 2};
  std::vector<StrainVoigt> curvature_stream(stream.size());
  for (std::size_t k = 0; k < stream.size(); ++k)
    curvature_stream[k] = stream[(k + stream.size() / 2) % stream.size()] / (thickness / 2);
  std::array<J2Plasticity::State, points> start;
  for (int p = 0; p < points; ++p)
    start[p] = preloaded(j2_law, preload_strain * (1.0 + 0.3 * zeta[p] / thickness));
  std::array<J2Plasticity::State, points> states = start;
  std::size_t index = 0;
  for (auto _ : benchmark_state) {
    VoigtLanes<points> d_eps;
    for (int p = 0; p < points; ++p) d_eps.set(p, stream[index] + zeta[p] * curvature_stream[index]);
    benchmark::DoNotOptimize(material::update_lanes(j2_law, states, d_eps));
    benchmark::DoNotOptimize(states);
    if (++index == stream.size()) {
      index = 0;
      states = start;
    }
  }
  benchmark_state.SetItemsProcessed(benchmark_state.iterations() * points);
}

BENCHMARK_TEMPLATE(BM_j2_batched_plastic, 1);
BENCHMARK_TEMPLATE(BM_j2_batched_plastic, 5);
BENCHMARK_TEMPLATE(BM_j2_batched_plastic, 8);
BENCHMARK_TEMPLATE(BM_j2_batched_plastic, 16);
BENCHMARK_TEMPLATE(BM_j2_batched_plastic, 32);
BENCHMARK_TEMPLATE(BM_j2_batched_elastic, 1);
BENCHMARK_TEMPLATE(BM_j2_batched_elastic, 5);
BENCHMARK_TEMPLATE(BM_j2_batched_elastic, 8);
BENCHMARK_TEMPLATE(BM_j2_batched_elastic, 16);
BENCHMARK_TEMPLATE(BM_j2_batched_elastic, 32);
BENCHMARK(BM_stress_point_5_integral_points_batched);
BENCHMARK(BM_elastic_update);
BENCHMARK(BM_j2_closed_appendix_b);
BENCHMARK(BM_j2_closed_zero_start);
BENCHMARK(BM_j2_closed_radial_start);
BENCHMARK(BM_j2_closed_squared_g);
BENCHMARK(BM_j2_closed_fixed_3);
BENCHMARK(BM_j2_generic_appendix_b);
BENCHMARK(BM_j2_closed_coarse_stream);
BENCHMARK(BM_damage_closed);
BENCHMARK(BM_johnson_cook);
BENCHMARK(BM_cowper_symonds);
BENCHMARK(BM_cowper_symonds_huge_d);
BENCHMARK(BM_j2_elastic_steps);
BENCHMARK(BM_johnson_cook_elastic_steps);
BENCHMARK(BM_cowper_symonds_elastic_steps);
BENCHMARK(BM_stress_point_5_integral_points);

void print_histogram(const char* label, const std::vector<StrainVoigt>& increments,
                     const ReturnMapOptions& options) {
  std::array<int, 5> counts{};  // 0, 1, 2, 3, > 3 corrections
  int plastic = 0;
  J2Plasticity::State state = preloaded(j2_law, preload_strain);
  for (const StrainVoigt& d_eps : increments) {
    const auto result = j2_law.update(state, d_eps, options);
    if (!result.plastic) continue;
    ++plastic;
    ++counts[static_cast<std::size_t>(std::min(result.iterations, 4))];
  }
  std::printf("  %-40s %5d %5d %5d %5d %5d   of %d plastic (%.1f %% in <= 1)\n", label, counts[0],
              counts[1], counts[2], counts[3], counts[4], plastic,
              100.0 * (counts[0] + counts[1]) / std::max(plastic, 1));
}

template <class Law>
void print_rate_histogram(const char* label, const Law& law) {
  std::array<int, 5> counts{};  // 0, 1, 2, 3, > 3 corrections
  int plastic = 0;
  typename Law::State state = preloaded(law, preload_strain);
  for (const StrainVoigt& d_eps : stream) {
    const auto result = law.update(state, d_eps, UpdateContext{rate_time_step});
    if (!result.plastic) continue;
    ++plastic;
    ++counts[static_cast<std::size_t>(std::min(result.iterations, 4))];
  }
  std::printf("  %-40s %5d %5d %5d %5d %5d   of %d plastic\n", label, counts[0], counts[1], counts[2], counts[3],
              counts[4], plastic);
}

// Error of a return against a round-off reference (12 plain Newton steps),
// every step started from the same state on the converged path.
void print_return_error(const char* label, const std::vector<StrainVoigt>& increments,
                        const ReturnMapOptions& options) {
  const ReturnMapOptions reference_options = options_with(
      ReturnMapForm::closed_form, InitialGuess::appendix_b, NewtonFunction::normalized, 12);
  J2Plasticity::State state = preloaded(j2_law, preload_strain);
  double worst_strain = 0.0, worst_stress = 0.0, sum_strain = 0.0;
  int plastic = 0;
  for (const StrainVoigt& d_eps : increments) {
    J2Plasticity::State candidate = state;
    const J2Plasticity::State before = state;
    const auto result = j2_law.update(state, d_eps, reference_options);
    j2_law.update(candidate, d_eps, options);
    if (!result.plastic) continue;
    ++plastic;
    const double increment = state.eps_p - before.eps_p;
    const double strain_error = std::abs(candidate.eps_p - state.eps_p) / increment;
    worst_strain = std::max(worst_strain, strain_error);
    sum_strain += strain_error;
    worst_stress = std::max(worst_stress, (candidate.stress - state.stress).norm() / state.sigma_y);
  }
  std::printf("  %-44s max %.2e  mean %.2e  max |d sigma|/sigma_s %.2e\n", label, worst_strain,
              sum_strain / std::max(plastic, 1), worst_stress);
}

void print_stream_report() {
  std::printf(
      "Newton corrections per plastic step (columns: 0 1 2 3 >3), tolerance |g| <= 1e-12 "
      "sigma_s^2\n");
  std::printf(" stream (increments 2.5-7.5e-6):\n");
  print_histogram("Appendix B start, phi = 1 - sigma_s/sigma", stream, {});
  print_histogram("zero start, phi", stream,
                  options_with(ReturnMapForm::closed_form, InitialGuess::zero));
  print_histogram("radial-return start, phi", stream,
                  options_with(ReturnMapForm::closed_form, InitialGuess::radial_return));
  print_histogram(
      "Appendix B start, squared g (eq. 2.36)", stream,
      options_with(ReturnMapForm::closed_form, InitialGuess::appendix_b, NewtonFunction::squared));
  print_histogram(
      "zero start, squared g", stream,
      options_with(ReturnMapForm::closed_form, InitialGuess::zero, NewtonFunction::squared));
  print_histogram("radial-return start, squared g", stream,
                  options_with(ReturnMapForm::closed_form, InitialGuess::radial_return,
                               NewtonFunction::squared));
  print_histogram("generic 3x3, Appendix B start, phi", stream,
                  options_with(ReturnMapForm::generic, InitialGuess::appendix_b));
  std::printf(" stream, rate-dependent laws (dt = %g s):\n", rate_time_step);
  print_rate_histogram("Johnson-Cook", johnson_cook_law);
  print_rate_histogram("Cowper-Symonds", cowper_symonds_law);
  print_rate_histogram("Cowper-Symonds, D = 1e300", cowper_symonds_static_law);
  std::printf(" coarse stream (increments 1.5-4.5e-5):\n");
  print_histogram("Appendix B start, phi", coarse_stream, {});
  print_histogram("zero start, phi", coarse_stream,
                  options_with(ReturnMapForm::closed_form, InitialGuess::zero));
  print_histogram("radial-return start, phi", coarse_stream,
                  options_with(ReturnMapForm::closed_form, InitialGuess::radial_return));
  print_histogram(
      "Appendix B start, squared g", coarse_stream,
      options_with(ReturnMapForm::closed_form, InitialGuess::appendix_b, NewtonFunction::squared));
  std::printf("Relative error of d(eps_p) against a round-off reference:\n");
  for (const auto* increments : {&stream, &coarse_stream}) {
    std::printf(" %s:\n", increments == &stream ? "stream" : "coarse stream");
    print_return_error("converged (default: Appendix B, phi)", *increments, {});
    print_return_error("fixed 3 steps, Appendix B start, phi", *increments,
                       options_with(ReturnMapForm::closed_form, InitialGuess::appendix_b,
                                    NewtonFunction::normalized, 3));
    print_return_error(
        "fixed 3 steps, zero start, squared g", *increments,
        options_with(ReturnMapForm::closed_form, InitialGuess::zero, NewtonFunction::squared, 3));
    print_return_error("fixed 1 step, Appendix B start, phi", *increments,
                       options_with(ReturnMapForm::closed_form, InitialGuess::appendix_b,
                                    NewtonFunction::normalized, 1));
  }
  std::fflush(stdout);
}

}  // namespace

int main(int argc, char** argv) {
  print_stream_report();
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
