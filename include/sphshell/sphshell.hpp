#pragma once
// Umbrella header: everything a user needs to compose a Solver.

#include <sphshell/core/error.hpp>
#include <sphshell/core/frame.hpp>
#include <sphshell/core/types.hpp>
