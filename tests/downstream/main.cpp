// A consumer of sphshell: includes the library's headers and uses public
// types, so a missing header or a broken target fails to build. It also checks
// the version macros: SPHSHELL_VERSION_STRING must read MAJOR.MINOR.PATCH and
// equal SPHSHELL_EXPECTED_VERSION (the project's version, passed by the check).
// Built with SPHSHELL_INCLUDE_ONLY it stands for a source tree used through
// -I<sphshell>/include alone, which has no version.
//
// What it includes depends on what a check proves
// (tests/downstream/check_package.cmake). By default the umbrella header, whole:
// every installed (or source) header compiles for a consumer, and the umbrella
// brings the version macros. With SPHSHELL_DOWNSTREAM_CORE_ONLY, for the checks
// of how the package is found (find_package, pkg-config, add_subdirectory, no
// MPI), the generated version header and core headers that need Eigen: the
// include directories, Eigen, the definitions and flags reach the consumer,
// without compiling the whole library once more per check.
#ifdef SPHSHELL_DOWNSTREAM_CORE_ONLY
#include <sphshell/core/error.hpp>
#include <sphshell/core/frame.hpp>
#include <sphshell/core/simd.hpp>
#include <sphshell/core/types.hpp>
#ifndef SPHSHELL_INCLUDE_ONLY
#include <sphshell/version.hpp>
#endif
#else
#include <sphshell/core/simd.hpp>
#include <sphshell/sphshell.hpp>
#endif

#include <iostream>
#include <string>

int main() {
#ifndef SPHSHELL_INCLUDE_ONLY
#ifndef SPHSHELL_VERSION_STRING
#error "the version macros of <sphshell/version.hpp> are missing (<sphshell/sphshell.hpp> brings them)"
#endif
  const std::string composed = std::to_string(SPHSHELL_VERSION_MAJOR) + "." +
                               std::to_string(SPHSHELL_VERSION_MINOR) + "." +
                               std::to_string(SPHSHELL_VERSION_PATCH);
  if (composed != SPHSHELL_VERSION_STRING) {
    std::cout << "version macros disagree: " << composed << " vs " << SPHSHELL_VERSION_STRING << '\n';
    return 1;
  }
#ifdef SPHSHELL_EXPECTED_VERSION
  if (std::string(SPHSHELL_VERSION_STRING) != SPHSHELL_EXPECTED_VERSION) {
    std::cout << "version " << SPHSHELL_VERSION_STRING << ", expected " << SPHSHELL_EXPECTED_VERSION << '\n';
    return 1;
  }
#endif
  std::cout << "sphshell " << SPHSHELL_VERSION_STRING << '\n';
#endif
  // The instruction set the compiler targets here must be the one the package
  // was configured with: the flags and the definition naming the set reached
  // this consumer through the target (NONE: no flag, the compiler's default).
#ifdef SPHSHELL_EXPECTED_SIMD
  if (std::string(sphshell::simd::configured_instruction_set()) != SPHSHELL_EXPECTED_SIMD) {
    std::cout << "configured instruction set " << sphshell::simd::configured_instruction_set()
              << ", package configured for " << SPHSHELL_EXPECTED_SIMD << '\n';
    return 1;
  }
  if (std::string(SPHSHELL_EXPECTED_SIMD) != "NONE" &&
      std::string(sphshell::simd::instruction_set()) != SPHSHELL_EXPECTED_SIMD) {
    std::cout << "instruction set " << sphshell::simd::instruction_set() << ", package configured for "
              << SPHSHELL_EXPECTED_SIMD << '\n';
    return 1;
  }
  std::cout << "instruction set " << sphshell::simd::instruction_set() << '\n';
#endif
  // Eigen through the target (or the .pc file's flags): a frame of the core.
  const sphshell::TangentFrame frame = sphshell::tangent_frame(sphshell::Vector3(0.0, 0.0, 2.0));
  if (!(frame.e1.cross(frame.e2) - frame.normal).isZero(1e-15)) {
    std::cout << "tangent frame not right-handed\n";
    return 1;
  }
  try {
    sphshell::detail::require_positive("E", -1.0);
  } catch (const sphshell::Error& error) {
    std::cout << "downstream OK: " << error.what() << '\n';
    return 0;
  }
  return 1;
}
