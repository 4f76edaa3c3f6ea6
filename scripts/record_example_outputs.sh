#!/usr/bin/env bash
# Developer tool for restructurings that must keep behaviour: runs every
# example at its coarse ctest settings (and a few more cases), keeps what each
# writes, and checksums it all.
#
#   scripts/record_example_outputs.sh BUILD_DIR OUT_DIR [THREADS]
#
# BUILD_DIR holds examples/<name> binaries; OUT_DIR (outside the source tree)
# is replaced. Wall-clock figures are masked in the printed output
# (stdout.txt), so two runs of the same binaries give the same OUT_DIR/SHA256SUMS.
# Compare two records with: diff A/SHA256SUMS B/SHA256SUMS.
#
# The records are made with BUILD_DIR configured with -DSPHSHELL_SIMD=NONE (the
# compiler's default target): another instruction set contracts multiply-adds
# and changes round-off, hence the bytes. The script refuses any other build.
set -uo pipefail
if [ $# -lt 2 ]; then
  echo "usage: $0 BUILD_DIR OUT_DIR [THREADS]" >&2
  exit 2
fi
simd=$(sed -n 's/^SPHSHELL_SIMD_CHOSEN:INTERNAL=//p' "$1/CMakeCache.txt" 2>/dev/null)
if [ "$simd" != "NONE" ]; then
  echo "$0: $1 is configured for the instruction set '${simd:-unknown}'; the records are made with" >&2
  echo "  SPHSHELL_SIMD=NONE: cmake -S . -B $1 -DSPHSHELL_SIMD=NONE" >&2
  exit 2
fi
bin=$(cd "$1" && pwd)/examples
out=$2
export OMP_NUM_THREADS=${3:-1}
rm -rf "$out"
mkdir -p "$out"
out=$(cd "$out" && pwd)
run() {
  local name=$1 exe=$2
  shift 2
  local dir="$out/$name"
  mkdir -p "$dir"
  (cd "$dir" && "$bin/$exe" "$@" > stdout.raw 2>&1; echo "exit $?" >> stdout.raw)
  sed -E "s/in [0-9.e+-]+ s \([0-9.e+-]+ µs per step\)/in <wall> s/; s/\( *[0-9.]+ s\)/(<wall> s)/; \
s/steps in [0-9.]+ s/steps in <wall> s/; s/[0-9.]+ s wall/<wall> s wall/; \
s/ [0-9.e+]+ steps\/s  ETA [^k]*/ <rate> /" "$dir/stdout.raw" > "$dir/stdout.txt"
}
run square_linear square_plate --case linear --n 15 --end-time 1e-3
run square_plastic square_plate --case plastic --n 15 --end-time 1e-3
run square_damage square_plate --case damage --n 15 --end-time 1e-3
run square_global square_plate --case plastic --rule global --n 15 --end-time 1e-3
run square_nonlinear_frames square_plate --case nonlinear --n 15 --end-time 5e-4 --frames
run square_fracture square_plate --case fracture --n 21 --end-time 2e-3 --frames
run plate_tearing plate_tearing --n 21 --end-displacement 0.03 --frames
run detonation_tube detonation_tube --spacing 5e-3 --end-time 3e-4 --frames
run detonation_notch detonation_tube --spacing 5e-3 --end-time 1e-4 --notch-ligament 2e-4
run detonation_axial detonation_tube --spacing 2.5e-3
run cap spherical_cap --n 9 --end-time 2e-4
run cap_plastic spherical_cap --plastic --n 9 --end-time 2e-4 --frames
run return_map_demo return_map_demo
run clamped_plate_minimal clamped_plate_minimal
(cd "$out" && find . -type f ! -name stdout.raw ! -name SHA256SUMS -print0 | sort -z | xargs -0 sha256sum > SHA256SUMS)
echo "$(wc -l < "$out/SHA256SUMS") files recorded in $out"
