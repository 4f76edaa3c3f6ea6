// Deterministic reductions and the Error rule (include/sphshell/core/exact_sum.hpp,
// reductions.hpp, error_agreement.hpp) on 1, 2 and 3 ranks: ExactSum is the
// correctly rounded sum (checked against an exact 113-bit reference), the
// same for any order and any split between ranks; the global-order sum is the
// serial loop's; an Error on one rank reaches every rank with one message.
#include <sphshell/mpi/all.hpp>

#include <catch2/catch.hpp>

#include <algorithm>
#include <cfloat>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <optional>
#include <random>
#include <string>
#include <vector>

using namespace sphshell;

namespace {

__extension__ typedef __float128 Binary128;

// Terms k 2^-40 with |k| < 2^50 and sums below 2^64 · 2^-40: every partial
// sum needs at most 2^-40 … 2^24, 64 bits, so a 113-bit binary128 sum is
// exact, and its conversion to double is the correctly rounded sum.
std::vector<double> dyadic_terms(std::size_t count, std::uint32_t seed) {
  std::mt19937_64 random(seed);
  std::uniform_int_distribution<std::int64_t> mantissa(-(std::int64_t{1} << 50), std::int64_t{1} << 50);
  std::uniform_int_distribution<int> scale(0, 40);
  std::vector<double> terms(count);
  // Mixed magnitudes, 2^-40 … 2^10: the naive double sum loses the small ones.
  for (double& term : terms) term = std::ldexp(static_cast<double>(mantissa(random)), -40 - scale(random));
  return terms;
}
double exact_reference(const std::vector<double>& terms) {
  Binary128 sum = 0;
  for (double term : terms) sum += static_cast<Binary128>(term);
  return static_cast<double>(sum);
}
double exact_sum_of(const std::vector<double>& terms) {
  sphshell::ExactSum sum;
  for (double term : terms) sum.add(term);
  return sum.value();
}
bool same_bits(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; }

}  // namespace

TEST_CASE("ExactSum: the correctly rounded sum", "[mpi][reductions]") {
  for (std::uint32_t seed : {1u, 2u, 3u}) {
    const std::vector<double> terms = dyadic_terms(20000, seed);
    const double reference = exact_reference(terms);
    CHECK(same_bits(exact_sum_of(terms), reference));
    double naive = 0.0;
    for (double term : terms) naive += term;
    // The case is hard enough that the plain loop misses (the test can fail).
    CHECK(!same_bits(naive, reference));
  }
  // Cancellation, ties to even, subnormals, the edge of the range, signs.
  CHECK(exact_sum_of({1e100, 1.0, -1e100}) == 1.0);
  CHECK(exact_sum_of({std::ldexp(1.0, 53), 1.0}) == std::ldexp(1.0, 53));
  CHECK(exact_sum_of({std::ldexp(1.0, 53), 3.0}) == std::ldexp(1.0, 53) + 4.0);
  CHECK(exact_sum_of({std::ldexp(1.0, 53), 1.0, std::ldexp(1.0, -1000)}) == std::ldexp(1.0, 53) + 2.0);
  CHECK(exact_sum_of({-std::ldexp(1.0, 53), -1.0, -std::ldexp(1.0, -1000)}) == -(std::ldexp(1.0, 53) + 2.0));
  const double tiny = std::numeric_limits<double>::denorm_min();
  CHECK(exact_sum_of({tiny, tiny, tiny}) == 3 * tiny);
  CHECK(exact_sum_of({DBL_MIN, -tiny}) == DBL_MIN - tiny);
  CHECK(exact_sum_of({DBL_MAX, DBL_MAX, -DBL_MAX}) == DBL_MAX);
  CHECK(std::isinf(exact_sum_of({DBL_MAX, DBL_MAX})));
  CHECK(exact_sum_of({0.1, 0.2, -0.3}) == static_cast<double>(static_cast<Binary128>(0.1) + 0.2 - 0.3));
  CHECK(exact_sum_of({}) == 0.0);
  CHECK(exact_sum_of({-2.5}) == -2.5);
  // Non-finite terms.
  const double inf = std::numeric_limits<double>::infinity();
  CHECK(std::isnan(exact_sum_of({1.0, std::numeric_limits<double>::quiet_NaN()})));
  CHECK(std::isnan(exact_sum_of({inf, -inf})));
  CHECK(exact_sum_of({inf, 1.0}) == inf);
  CHECK(exact_sum_of({-inf, 1.0}) == -inf);
}

TEST_CASE("ExactSum: independent of the order and of the split into accumulators", "[mpi][reductions]") {
  std::vector<double> terms = dyadic_terms(5000, 7);
  for (double& term : terms) term *= 1e-3;  // not dyadic any more: a general case
  const double first = exact_sum_of(terms);
  std::mt19937 random(11);
  for (int shuffle = 0; shuffle < 5; ++shuffle) {
    std::shuffle(terms.begin(), terms.end(), random);
    CHECK(same_bits(exact_sum_of(terms), first));
    sphshell::ExactSum a, b, c;
    for (std::size_t k = 0; k < terms.size(); ++k) (k % 3 == 0 ? a : k % 3 == 1 ? b : c).add(terms[k]);
    c += a;
    c += b;
    CHECK(same_bits(c.value(), first));
  }
}

TEST_CASE("reductions: identical on 1, 2 and 3 ranks", "[mpi][reductions]") {
  const mpi::Communicator comm;
  const std::vector<double> all = dyadic_terms(30001, 5);
  const double reference = exact_reference(all);
  double serial_loop = 0.0;
  for (double term : all) serial_loop += term;
  // A split that is not contiguous: term i on rank i mod P.
  std::vector<double> mine;
  std::vector<int> mine_index;
  for (std::size_t i = static_cast<std::size_t>(comm.rank()); i < all.size(); i += static_cast<std::size_t>(comm.size())) {
    mine.push_back(all[i]);
    mine_index.push_back(static_cast<int>(i));
  }
  const double exact = mpi::exact_sum(comm, mine);
  CHECK(same_bits(exact, reference));
  const double ordered = mpi::global_order_sum(comm, mine_index, mine);
  CHECK(same_bits(ordered, serial_loop));
  // Every rank holds the same bits.
  const std::vector<double> exact_everywhere = comm.all_gather(exact);
  for (double value : exact_everywhere) CHECK(same_bits(value, exact));
  // max and min.
  CHECK(comm.max(static_cast<double>(comm.rank())) == comm.size() - 1);
  CHECK(comm.min(-static_cast<double>(comm.rank())) == -(comm.size() - 1));
  CHECK(comm.sum(std::int64_t{1}) == comm.size());
  // A non-finite term on one rank makes the sum non-finite everywhere.
  sphshell::ExactSum local;
  local.add(comm.rank() == comm.size() - 1 ? std::numeric_limits<double>::quiet_NaN() : 1.0);
  CHECK(std::isnan(mpi::sum(comm, local)));
  // Indices that do not cover [0, total) once are an Error on every rank.
  std::vector<int> doubled = mine_index;
  if (!doubled.empty()) doubled[0] = (doubled[0] + 1) % static_cast<int>(all.size());
  CHECK_THROWS_WITH(mpi::global_order_sum(comm, doubled, mine), Catch::Contains("global_order_sum index"));
}

TEST_CASE("Error rule: a failure on one rank stops every rank with one message", "[mpi][errors]") {
  const mpi::Communicator comm;
  // Nothing failed: every rank returns.
  CHECK_NOTHROW(mpi::agree_on_failure(comm, std::nullopt));
  // Ranks 1 … P−1 fail with keys 100 − rank: the highest rank's message wins
  // (the lowest key, as the serial loop would have stopped there first).
  std::optional<mpi::Failure> failure;
  if (comm.rank() > 0 || comm.size() == 1)
    failure = mpi::Failure{100 - comm.rank(), "failure at key " + std::to_string(100 - comm.rank()), nullptr};
  const std::string expected = "failure at key " + std::to_string(100 - (comm.size() - 1));
  CHECK_THROWS_WITH(mpi::agree_on_failure(comm, failure), expected);
  // Equal keys: the lowest failing rank's message.
  CHECK_THROWS_WITH(mpi::agree_on_failure(comm, mpi::Failure{5, "rank " + std::to_string(comm.rank()), nullptr}), "rank 0");
  // collectively: an Error thrown on the last rank only.
  CHECK_THROWS_WITH(mpi::collectively(comm,
                                      [&] {
                                        if (comm.rank() == comm.size() - 1)
                                          throw Error("sphshell: simulation unstable at step 12: particle 7");
                                      }),
                    "sphshell: simulation unstable at step 12: particle 7");
  CHECK_NOTHROW(mpi::collectively(comm, [] {}));
  // A reserved key is refused (on every rank alike).
  CHECK_THROWS_WITH(mpi::agree_on_failure(comm, mpi::Failure{std::numeric_limits<long>::max(), "x", nullptr}),
                    Catch::Contains("failure key"));
}
