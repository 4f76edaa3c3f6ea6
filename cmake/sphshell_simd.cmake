# SPHSHELL_SIMD: the instruction set the sphshell::sphshell target asks its
# consumers to compile for, after GROMACS's GMX_SIMD. AUTO picks the widest set
# the build machine can run (a test program is compiled with the set's flags and
# run); a named set pins it, e.g. SSE2 for binaries that must run anywhere.
# NONE adds no flag (the compiler's default target).
set(sphshell_simd_values AUTO AVX_512 AVX2_256 SSE2 NONE)
set(SPHSHELL_SIMD NONE CACHE STRING
    "SIMD instruction set for sphshell::sphshell consumers: AUTO, AVX_512, AVX2_256, SSE2 or NONE")
set_property(CACHE SPHSHELL_SIMD PROPERTY STRINGS ${sphshell_simd_values})
string(TOUPPER "${SPHSHELL_SIMD}" sphshell_simd_request)
if(NOT sphshell_simd_request IN_LIST sphshell_simd_values)
  message(FATAL_ERROR "SPHSHELL_SIMD is '${SPHSHELL_SIMD}'; allowed values: AUTO, AVX_512, AVX2_256, SSE2, NONE")
endif()

set(sphshell_simd_flags_AVX_512 -mavx512f -mavx512dq -mavx512vl -mavx2 -mfma)
set(sphshell_simd_flags_AVX2_256 -mavx2 -mfma)
set(sphshell_simd_flags_SSE2 -msse2)
set(sphshell_simd_flags_NONE "")

# A program that uses one instruction of the set, so it fails to run (SIGILL)
# on a processor without it.
set(sphshell_simd_probe_AVX_512 [=[
#include <immintrin.h>
int main() {
  volatile double in = 1.0;
  __m512d a = _mm512_set1_pd(in);
  __m256d b = _mm512_extractf64x4_pd(_mm512_fmadd_pd(a, a, a), 1);
  __m256i c = _mm256_cvtpd_epi64(b);
  return _mm256_extract_epi64(c, 0) == 2 ? 0 : 1;
}]=])
set(sphshell_simd_probe_AVX2_256 [=[
#include <immintrin.h>
int main() {
  volatile double in = 1.0;
  __m256d a = _mm256_set1_pd(in);
  __m256d b = _mm256_fmadd_pd(a, a, a);
  __m256i c = _mm256_add_epi64(_mm256_castpd_si256(b), _mm256_castpd_si256(b));
  return _mm256_extract_epi64(c, 0) != 0 ? 0 : 1;
}]=])
set(sphshell_simd_probe_SSE2 [=[
#include <emmintrin.h>
int main() {
  volatile double in = 1.0;
  __m128d a = _mm_set1_pd(in);
  return _mm_cvtsd_f64(_mm_add_pd(a, a)) == 2.0 ? 0 : 1;
}]=])

if(sphshell_simd_request STREQUAL "AUTO")
  include(CheckCXXSourceRuns)
  include(CMakePushCheckState)
  set(sphshell_simd_chosen NONE)
  if(CMAKE_CXX_COMPILER_ID MATCHES "GNU|Clang")
    foreach(candidate AVX_512 AVX2_256 SSE2)
      cmake_push_check_state(RESET)
      string(REPLACE ";" " " CMAKE_REQUIRED_FLAGS "${sphshell_simd_flags_${candidate}}")
      set(CMAKE_REQUIRED_QUIET ON)
      check_cxx_source_runs("${sphshell_simd_probe_${candidate}}" sphshell_simd_runs_${candidate})
      cmake_pop_check_state()
      if(sphshell_simd_runs_${candidate})
        set(sphshell_simd_chosen ${candidate})
        break()
      endif()
    endforeach()
  endif()
else()
  set(sphshell_simd_chosen ${sphshell_simd_request})
endif()
if(NOT sphshell_simd_chosen STREQUAL "NONE" AND NOT CMAKE_CXX_COMPILER_ID MATCHES "GNU|Clang")
  message(FATAL_ERROR "SPHSHELL_SIMD=${sphshell_simd_chosen} needs GCC or Clang flags; use SPHSHELL_SIMD=NONE")
endif()
set(SPHSHELL_SIMD_CHOSEN ${sphshell_simd_chosen} CACHE INTERNAL "The instruction set SPHSHELL_SIMD resolved to")
set(SPHSHELL_SIMD_FLAGS ${sphshell_simd_flags_${sphshell_simd_chosen}})
string(REPLACE ";" " " sphshell_simd_flags_text "${SPHSHELL_SIMD_FLAGS}")
message(STATUS "sphshell: SIMD instruction set: ${SPHSHELL_SIMD_CHOSEN} (flags: ${sphshell_simd_flags_text})")
