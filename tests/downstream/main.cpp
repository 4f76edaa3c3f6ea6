// A consumer of sphshell: includes the umbrella header and uses one public
// type, so a missing header or a broken target fails to build. It also checks
// the version macros the umbrella brings: SPHSHELL_VERSION_STRING must read
// MAJOR.MINOR.PATCH and equal SPHSHELL_EXPECTED_VERSION (the project's version,
// passed by the check). Built with SPHSHELL_INCLUDE_ONLY it stands for a
// source tree used through -I<sphshell>/include alone, which has no version.
#include <sphshell/core/simd.hpp>
#include <sphshell/sphshell.hpp>

#include <iostream>
#include <string>

int main() {
#ifndef SPHSHELL_INCLUDE_ONLY
#ifndef SPHSHELL_VERSION_STRING
#error "<sphshell/sphshell.hpp> did not bring the version macros of <sphshell/version.hpp>"
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
  try {
    sphshell::detail::require_positive("E", -1.0);
  } catch (const sphshell::Error& error) {
    std::cout << "downstream OK: " << error.what() << '\n';
    return 0;
  }
  return 1;
}
