#!/usr/bin/env bash
# Quick start, second command: install what is missing, build in Release and
# run the whole test suite (this is exactly what CI runs).
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/install_dependencies.sh
# A build tree of its own (build-tests, or SPHSHELL_BUILD_DIR), so that the
# tree the user builds for speed (build/, the README's commands) is never
# reconfigured by it.
build_dir=${SPHSHELL_BUILD_DIR:-build-tests}
jobs=$(nproc 2>/dev/null || echo 2)
# Ninja when it is installed (it keeps every core busy across directories),
# chosen only for a new tree: a tree keeps the generator it was made with.
generator=()
if [ ! -f "$build_dir/CMakeCache.txt" ] && command -v ninja >/dev/null 2>&1; then
  generator=(-G Ninja)
fi
# SPHSHELL_SMOKE_BUILD: the examples and benchmarks are compiled for their smoke
# runs, not for speed (docs/user-guide.md, "Build options"); configure without
# it, as a user does, for their figures.
cmake -S . -B "$build_dir" "${generator[@]}" -DCMAKE_BUILD_TYPE=Release -DSPHSHELL_SMOKE_BUILD=ON
cmake --build "$build_dir" -j "$jobs"
ctest --test-dir "$build_dir" -j "$jobs" --output-on-failure --timeout 900
