#!/usr/bin/env bash
# Quick start, second command: install what is missing, build in Release and
# run the whole test suite (this is exactly what CI runs).
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/install_dependencies.sh
build_dir=${SPHSHELL_BUILD_DIR:-build}
jobs=$(nproc 2>/dev/null || echo 2)
cmake -S . -B "$build_dir" -DCMAKE_BUILD_TYPE=Release
cmake --build "$build_dir" -j "$jobs"
ctest --test-dir "$build_dir" -j "$jobs" --output-on-failure --timeout 900
