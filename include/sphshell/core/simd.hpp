#pragma once
// The SIMD instruction set of a program built on sphshell. The CMake package
// chooses it when the library is configured (SPHSHELL_SIMD, AUTO by default:
// the widest set the build machine runs) and passes its flags, with
// SPHSHELL_SIMD_CONFIGURED=<set>, through the sphshell::sphshell target;
// programs print both so that a figure can be traced to the code that
// produced it.

namespace sphshell::simd {

// Widest set the compiler may use in this translation unit, read from its
// predefined macros: "AVX_512" (F, DQ and VL), "AVX2_256" (AVX2 with FMA),
// "SSE2", or "NONE" (no x86 vector set). With SPHSHELL_SIMD=NONE on x86-64 it
// is "SSE2", the compiler's default target.
constexpr const char* instruction_set() noexcept {
#if defined(__AVX512F__) && defined(__AVX512DQ__) && defined(__AVX512VL__)
  return "AVX_512";
#elif defined(__AVX2__) && defined(__FMA__)
  return "AVX2_256";
#elif defined(__SSE2__) || defined(_M_X64)
  return "SSE2";
#else
  return "NONE";
#endif
}

#define SPHSHELL_SIMD_DETAIL_TEXT(set) #set
#define SPHSHELL_SIMD_DETAIL_EXPANDED_TEXT(set) SPHSHELL_SIMD_DETAIL_TEXT(set)

// The set SPHSHELL_SIMD resolved to when the package was configured ("AUTO"
// never appears: it is resolved then), or "unknown" for a program that uses
// the headers without the CMake target or sphshell.pc (plain -I).
constexpr const char* configured_instruction_set() noexcept {
#ifdef SPHSHELL_SIMD_CONFIGURED
  return SPHSHELL_SIMD_DETAIL_EXPANDED_TEXT(SPHSHELL_SIMD_CONFIGURED);
#else
  return "unknown";
#endif
}

#undef SPHSHELL_SIMD_DETAIL_EXPANDED_TEXT
#undef SPHSHELL_SIMD_DETAIL_TEXT

}  // namespace sphshell::simd
