#pragma once
// The library's one parallel seam. Every per-particle and per-point loop of a
// step runs through parallel::for_each, so the threading rule lives here once:
//  - a static schedule over the index range (each index is visited once, by
//    one thread; what a body writes to its own index is the same for any
//    thread count);
//  - sums over indices are never formed inside the loop: a body writes its
//    term to an array and the caller adds the array up in index order, so
//    reductions are identical for any thread count too;
//  - an exception must not leave an OpenMP region (that would call
//    std::terminate): each thread catches, the error of the lowest failing
//    index is kept, and it is rethrown after the loop, the same one whatever
//    the thread count.
// Without OpenMP the directives vanish (no -Wunknown-pragmas in user code) and
// the loops run serially.

#include <cstddef>
#include <exception>
#include <string>
#include <type_traits>
#include <utility>

#ifdef _OPENMP
#include <omp.h>
#define SPHSHELL_OMP(directive) _Pragma(directive)
#else
#define SPHSHELL_OMP(directive)
#endif

namespace sphshell::parallel {

// Calls body(i) for i in [begin, end) on the OpenMP threads (a body declared
// noexcept runs without the exception bookkeeping); on failure,
// on_failure(i, error) is called once, after the loop, with the lowest failing
// index and its exception (it is expected to throw; if it returns, the error
// is rethrown).
template <class Index, class Body, class OnFailure>
void for_each(Index begin, Index end, Body&& body, OnFailure&& on_failure) {
  static_assert(std::is_integral_v<Index>, "parallel::for_each: the index must be an integer type");
  using Signed = std::make_signed_t<Index>;
  const Signed first = static_cast<Signed>(begin), last = static_cast<Signed>(end);
  if constexpr (std::is_nothrow_invocable_v<Body&, Index>) {
    // Nothing to catch: the plain loop.
    SPHSHELL_OMP("omp parallel for schedule(static)")
    for (Signed i = first; i < last; ++i) body(static_cast<Index>(i));
    return;
  }
  Signed failed = last;
  std::exception_ptr failure;
  SPHSHELL_OMP("omp parallel for schedule(static)")
  for (Signed i = first; i < last; ++i) {
    try {
      body(static_cast<Index>(i));
    } catch (...) {
      SPHSHELL_OMP("omp critical(sphshell_parallel_failure)")
      if (i < failed) {
        failed = i;
        failure = std::current_exception();
      }
    }
  }
  if (failure) {
    on_failure(static_cast<Index>(failed), failure);
    std::rethrow_exception(failure);
  }
}

// As above; the lowest failing index's exception is rethrown as it is.
template <class Index, class Body>
void for_each(Index begin, Index end, Body&& body) {
  for_each(begin, end, std::forward<Body>(body), [](Index, const std::exception_ptr&) {});
}

// The message of a caught exception (for errors that add where they happened).
inline std::string what(const std::exception_ptr& error) {
  try {
    std::rethrow_exception(error);
  } catch (const std::exception& caught) {
    return caught.what();
  } catch (...) {
    return "unknown exception";
  }
}

}  // namespace sphshell::parallel
