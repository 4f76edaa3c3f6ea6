#!/usr/bin/env bash
# Quick start, second command: install what is missing, build in Release and
# run the whole test suite (this is exactly what CI runs).
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/install_dependencies.sh
build_dir=${SPHSHELL_BUILD_DIR:-build}
jobs=$(nproc 2>/dev/null || echo 2)
# SPHSHELL_SMOKE_BUILD: the examples and benchmarks are compiled for their smoke
# runs, not for speed (docs/user-guide.md, "Build options"); configure without
# it, as a user does, for their figures.
cmake -S . -B "$build_dir" -DCMAKE_BUILD_TYPE=Release -DSPHSHELL_SMOKE_BUILD=ON
cmake --build "$build_dir" -j "$jobs"
ctest --test-dir "$build_dir" -j "$jobs" --output-on-failure --timeout 900
