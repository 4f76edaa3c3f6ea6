#pragma once
// Umbrella header: every policy of every family, the shell model and the solver.

#include <sphshell/core/error.hpp>
#include <sphshell/core/frame.hpp>
#include <sphshell/core/types.hpp>

#include <sphshell/approx/all.hpp>
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
#include <sphshell/solver.hpp>
