#!/usr/bin/env bash
# Quick start, first command: install what is missing, build in Release and run
# the main example end to end. Extra arguments go to the example.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/install_dependencies.sh
build_dir=${SPHSHELL_BUILD_DIR:-build}
jobs=$(nproc 2>/dev/null || echo 2)
cmake -S . -B "$build_dir" -DCMAKE_BUILD_TYPE=Release
cmake --build "$build_dir" -j "$jobs" --target square_plate
"$build_dir"/examples/square_plate "$@"
