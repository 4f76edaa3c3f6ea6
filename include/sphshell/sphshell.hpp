#pragma once
// Umbrella header: every policy of every family, the shell model and the solver.

// SPHSHELL_VERSION_MAJOR/MINOR/PATCH/STRING: <sphshell/version.hpp> is generated
// by CMake, so it exists in the build tree, for add_subdirectory users and in an
// installation. A source tree used through -I<sphshell>/include alone has none;
// the umbrella still compiles there, without the version macros.
#if __has_include(<sphshell/version.hpp>)
#include <sphshell/version.hpp>
#endif

#include <sphshell/core/error.hpp>
#include <sphshell/core/frame.hpp>
#include <sphshell/core/types.hpp>

#include <sphshell/approx/all.hpp>
#include <sphshell/contact/all.hpp>
#include <sphshell/crack/all.hpp>
#include <sphshell/kernel/all.hpp>
#include <sphshell/material/all.hpp>
#include <sphshell/thickness/all.hpp>

#include <sphshell/io/abaqus_reader.hpp>
#include <sphshell/io/csv_probe.hpp>
#include <sphshell/io/gmsh_reader.hpp>
#include <sphshell/io/pvd_collection.hpp>
#include <sphshell/io/svg_plot.hpp>
#include <sphshell/io/vtu_writer.hpp>

#include <sphshell/shell/model.hpp>
#include <sphshell/shell/spherical_cap_ogrid.hpp>
#include <sphshell/solver.hpp>
#include <sphshell/statics/all.hpp>
