#!/usr/bin/env bash
# Quick start, first command: install what is missing, build in Release and run
# the main example end to end. Extra arguments go to the example. The example
# runs inside the build directory, so its output folder (--output, default
# square_plate) lands there and nothing is written into the source tree; a
# relative --output is taken from the build directory.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/install_dependencies.sh
build_dir=${SPHSHELL_BUILD_DIR:-build}
jobs=$(nproc 2>/dev/null || echo 2)
# SPHSHELL_SMOKE_BUILD=OFF: the example compiled for speed, also in a tree that
# scripts/run_tests.sh configured for its smoke runs.
cmake -S . -B "$build_dir" -DCMAKE_BUILD_TYPE=Release -DSPHSHELL_SMOKE_BUILD=OFF
cmake --build "$build_dir" -j "$jobs" --target square_plate

output=square_plate
help=no
previous=""
for argument in "$@"; do
  case "$argument" in
    --output=*) output=${argument#--output=} ;;
    --help | -h) help=yes ;;
  esac
  if [ "$previous" = "--output" ]; then output=$argument; fi
  previous=$argument
done

cd "$build_dir"
./examples/square_plate "$@"
if [ "$help" = no ]; then
  case "$output" in
    /*) folder=$output ;;
    *) folder=$(pwd)/$output ;;
  esac
  echo "square_plate wrote its output into $folder"
fi
