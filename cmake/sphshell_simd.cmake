# SPHSHELL_SIMD: the instruction set the sphshell::sphshell target asks its
# consumers to compile for, after GROMACS's GMX_SIMD. AUTO (the default) picks
# the widest set the build machine runs: a test program using one instruction
# of the set is compiled with the set's flags and run, widest first. A named set
# pins it, e.g. SSE2 for binaries that must run on any x86-64. NONE adds no flag
# (the compiler's default target).
#
# AUTO falls back to NONE when no probe can be run: a compiler other than GCC
# or Clang (the flags are theirs), a cross build (the build machine is not the
# target), or a processor that is not x86 (the probes do not compile).
#
# The choice is recorded, not redone by consumers: the flags are part of the
# target's interface options, so the installed package (sphshellTargets.cmake)
# and sphshell.pc carry the set chosen here, and every program built against
# one installation compiles for the same set, the one its tests ran with. A
# consumer on a different machine installs its own copy with SPHSHELL_SIMD set
# (docs/user-guide.md, build options).
set(sphshell_simd_values AUTO AVX_512 AVX2_256 SSE2 NONE)
set(SPHSHELL_SIMD AUTO CACHE STRING
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
# on a processor, or under an operating system, without it.
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

set(sphshell_simd_can_probe OFF)
if(CMAKE_CXX_COMPILER_ID MATCHES "GNU|Clang" AND NOT CMAKE_CROSSCOMPILING)
  set(sphshell_simd_can_probe ON)
endif()
include(CheckCXXSourceRuns)
include(CMakePushCheckState)
# Sets <result> to TRUE when the build machine compiles and runs the probe of <set>.
function(sphshell_simd_runs set result)
  cmake_push_check_state(RESET)
  string(REPLACE ";" " " CMAKE_REQUIRED_FLAGS "${sphshell_simd_flags_${set}}")
  set(CMAKE_REQUIRED_QUIET ON)
  check_cxx_source_runs("${sphshell_simd_probe_${set}}" sphshell_simd_runs_${set})
  cmake_pop_check_state()
  set(${result} ${sphshell_simd_runs_${set}} PARENT_SCOPE)
endfunction()

# GCC before 13 at -O2 with the AVX-512 flags miscompiles the library's cell
# shear tying (shell/cell_shear.hpp: a quad's corner of about 88° comes out
# degenerate, sine 0, and the solver's set-up throws); the same source is right
# at -O1, with AVX2, with Clang, and with GCC's sanitizers on. AUTO therefore
# stops at AVX2_256 under those compilers; a pinned AVX_512 warns.
set(sphshell_simd_gcc_avx512_bug OFF)
if(CMAKE_CXX_COMPILER_ID STREQUAL "GNU" AND CMAKE_CXX_COMPILER_VERSION VERSION_LESS 13)
  set(sphshell_simd_gcc_avx512_bug ON)
endif()
if(sphshell_simd_request STREQUAL "AVX_512" AND sphshell_simd_gcc_avx512_bug)
  message(WARNING "SPHSHELL_SIMD=AVX_512 with GCC ${CMAKE_CXX_COMPILER_VERSION}: GCC before 13 miscompiles "
                  "sphshell's cell shear tying with these flags (a validation test fails); use AVX2_256, or GCC 13 "
                  "or Clang")
endif()

if(sphshell_simd_request STREQUAL "AUTO")
  set(sphshell_simd_chosen NONE)
  set(sphshell_simd_candidates AVX_512 AVX2_256 SSE2)
  if(sphshell_simd_gcc_avx512_bug)
    list(REMOVE_ITEM sphshell_simd_candidates AVX_512)
  endif()
  if(sphshell_simd_can_probe)
    foreach(candidate ${sphshell_simd_candidates})
      sphshell_simd_runs(${candidate} runs)
      if(runs)
        set(sphshell_simd_chosen ${candidate})
        break()
      endif()
    endforeach()
  endif()
else()
  set(sphshell_simd_chosen ${sphshell_simd_request})
  if(NOT sphshell_simd_chosen STREQUAL "NONE" AND sphshell_simd_can_probe)
    sphshell_simd_runs(${sphshell_simd_chosen} runs)
    if(NOT runs)
      message(WARNING "SPHSHELL_SIMD=${sphshell_simd_chosen}: this machine cannot run that instruction set; "
                      "the project's own tests, examples and benchmarks will not run here")
    endif()
  endif()
endif()
if(NOT sphshell_simd_chosen STREQUAL "NONE" AND NOT CMAKE_CXX_COMPILER_ID MATCHES "GNU|Clang")
  message(FATAL_ERROR "SPHSHELL_SIMD=${sphshell_simd_chosen} needs GCC or Clang flags; use SPHSHELL_SIMD=NONE")
endif()
set(SPHSHELL_SIMD_CHOSEN ${sphshell_simd_chosen} CACHE INTERNAL "The instruction set SPHSHELL_SIMD resolved to")
set(SPHSHELL_SIMD_FLAGS ${sphshell_simd_flags_${sphshell_simd_chosen}})
string(REPLACE ";" " " sphshell_simd_flags_text "${SPHSHELL_SIMD_FLAGS}")
if(sphshell_simd_flags_text STREQUAL "")
  set(sphshell_simd_flags_text "none, the compiler's default target")
endif()
message(STATUS "sphshell: SIMD instruction set: ${SPHSHELL_SIMD_CHOSEN} "
               "(SPHSHELL_SIMD=${sphshell_simd_request}; flags: ${sphshell_simd_flags_text})")
if(sphshell_simd_request STREQUAL "AUTO" AND sphshell_simd_gcc_avx512_bug)
  message(STATUS "sphshell: AUTO leaves AVX_512 out under GCC ${CMAKE_CXX_COMPILER_VERSION} (before 13 it "
                 "miscompiles the cell shear tying with those flags)")
endif()

# What consumers receive: the flags (C++ sources only, so that a CUDA or C file
# of the same program is not handed GCC's -m options) and
# SPHSHELL_SIMD_CONFIGURED=<set>, which <sphshell/core/simd.hpp> turns into
# sphshell::simd::configured_instruction_set(). The same two in sphshell.pc.
set(SPHSHELL_SIMD_COMPILE_OPTIONS)
foreach(flag IN LISTS SPHSHELL_SIMD_FLAGS)
  list(APPEND SPHSHELL_SIMD_COMPILE_OPTIONS $<$<COMPILE_LANGUAGE:CXX>:${flag}>)
endforeach()
set(SPHSHELL_SIMD_DEFINITION SPHSHELL_SIMD_CONFIGURED=${SPHSHELL_SIMD_CHOSEN})
set(sphshell_pc_cflags_simd " -D${SPHSHELL_SIMD_DEFINITION}")
if(SPHSHELL_SIMD_FLAGS)
  string(REPLACE ";" " " sphshell_pc_cflags_simd_flags "${SPHSHELL_SIMD_FLAGS}")
  string(APPEND sphshell_pc_cflags_simd " ${sphshell_pc_cflags_simd_flags}")
endif()
