#!/usr/bin/env bash
# Installs, from Debian 12's packages, whatever sphshell's build needs and the
# machine lacks. Does nothing (and needs no privileges) when all is present.
# pkg-config is for the test that consumes the installed sphshell.pc; zlib1g-dev
# for compressed ParaView frames; python3-vtk9 for the test that reads the
# frames with VTK's own reader (skipped without it; about 52 MB to download,
# 250 MB installed). libopenmpi-dev (with openmpi-bin's mpirun) is for the
# optional MPI layer sphshell::mpi and its tests on 1, 2 and 3 ranks (tests/mpi/).
# libsuitesparse-dev gives CHOLMOD, which factorises the positive definite
# tangents of static solutions (optional: without it Eigen's LDLT does).
# ninja-build lets the test command keep every core busy across the build.
# SPHSHELL_DOCS=1 also installs doxygen for the API reference and its test
# (optional: with its LLVM/Clang libraries about 220 MB on a fresh system; the
# test is skipped without it).
set -euo pipefail
packages=(g++ make cmake libeigen3-dev catch2 libbenchmark-dev pkg-config zlib1g-dev python3-vtk9 libopenmpi-dev openmpi-bin libsuitesparse-dev ninja-build)
if [ "${SPHSHELL_DOCS:-0}" = 1 ]; then packages+=(doxygen); fi
missing=()
for package in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$package" 2>/dev/null | grep -q "install ok installed" || missing+=("$package")
done
if [ ${#missing[@]} -eq 0 ]; then
  exit 0
fi
echo "sphshell: installing missing packages: ${missing[*]}"
if [ "$(id -u)" -eq 0 ]; then sudo=(); else sudo=(sudo); fi
export DEBIAN_FRONTEND=noninteractive
"${sudo[@]}" apt-get update -q
"${sudo[@]}" apt-get install -y -q --no-install-recommends "${missing[@]}"
