#pragma once
// The SIMD instruction set this translation unit is compiled for, read from the
// compiler's predefined macros. The CMake package chooses it (SPHSHELL_SIMD) and
// passes its flags through the sphshell::sphshell target; programs print it so a
// figure can be traced to the code that produced it.

namespace sphshell::simd {

// Widest set the compiler may use here: "AVX_512" (F, DQ and VL), "AVX2_256"
// (AVX2 with FMA), "SSE2", or "NONE" (no x86 vector set).
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

}  // namespace sphshell::simd
