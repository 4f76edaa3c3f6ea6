#pragma once
// Deterministic reductions over ranks (docs/distributed.md, "Sums over
// ranks"): the energy books, the stable step and the finite-state check of a
// distributed run give the same value for any rank count.
//
//  - max and min are exact: Communicator::max / min.
//  - sum(comm, ExactSum): each rank's exact accumulator (core/exact_sum.hpp),
//    added limb by limb with MPI_SUM on 64-bit integers — integer addition is
//    associative, so the reduction tree does not matter — and rounded once.
//    The result is the correctly rounded sum of all terms, the same for 1, 2
//    or 3 ranks, at the cost of one 568-byte all-reduce.
//  - global_order_sum: the terms gathered by global index and added in index
//    order on every rank: the very rounding of the single-process loop, at the
//    cost of moving every term (O(N) bytes); for checks, not for production.

#include <sphshell/core/error.hpp>
#include <sphshell/mpi/communicator.hpp>
#include <sphshell/core/exact_sum.hpp>

#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace sphshell::mpi {

// The exact sums of several accumulators over all ranks (sum k of every
// rank's local[k]), each rounded once, in one all-reduce of their limbs side
// by side; the same on every rank.
template <std::size_t N>
std::array<double, N> sums(const Communicator& comm, const std::array<const ExactSum*, N>& local) {
  std::vector<std::int64_t> raw;
  raw.reserve(N * ExactSum::raw_size);
  for (const ExactSum* accumulator : local) {
    ExactSum normalised = *accumulator;
    normalised.normalize();
    raw.insert(raw.end(), normalised.raw().begin(), normalised.raw().end());
  }
  comm.sum_in_place(raw);
  std::array<double, N> result{};
  for (std::size_t k = 0; k < N; ++k) {
    ExactSum::Raw part{};
    std::copy_n(raw.begin() + static_cast<std::ptrdiff_t>(k * ExactSum::raw_size), ExactSum::raw_size, part.begin());
    result[k] = ExactSum::from_raw(part).value();
  }
  return result;
}

// The exact sum of every rank's accumulator, rounded once; the same on every rank.
inline double sum(const Communicator& comm, const ExactSum& local) {
  return sums(comm, std::array<const ExactSum*, 1>{&local})[0];
}

// Σ terms over all ranks, order-independent.
inline double exact_sum(const Communicator& comm, const std::vector<double>& local_terms) {
  ExactSum accumulator;
  for (double term : local_terms) accumulator.add(term);
  return sum(comm, accumulator);
}

// Σ terms in global index order, as one process adds them: every rank's
// (global index, term) pairs gathered, then added left to right. The indices
// must cover [0, total) exactly once over all ranks (an Error otherwise).
inline double global_order_sum(const Communicator& comm, const std::vector<int>& global_index,
                               const std::vector<double>& terms) {
  if (global_index.size() != terms.size())
    sphshell::detail::invalid_parameter("global_order_sum terms", terms.size(),
                                        "one per global index (" + std::to_string(global_index.size()) + ")");
  struct Term {
    std::int64_t index;
    double value;
  };
  std::vector<Term> mine(terms.size());
  for (std::size_t k = 0; k < terms.size(); ++k) mine[k] = {global_index[k], terms[k]};
  const std::vector<Term> all = comm.all_gather_v(mine);
  std::vector<double> ordered(all.size(), 0.0);
  std::vector<char> seen(all.size(), 0);
  for (const Term& term : all) {
    if (term.index < 0 || static_cast<std::size_t>(term.index) >= all.size() || seen[term.index])
      sphshell::detail::invalid_parameter("global_order_sum index", term.index,
                                          "each of [0, " + std::to_string(all.size()) + ") exactly once");
    seen[term.index] = 1;
    ordered[term.index] = term.value;
  }
  double total = 0.0;
  for (double value : ordered) total += value;
  return total;
}

}  // namespace sphshell::mpi
