#pragma once
// Every approximation of the family, with their storage and neighbour search.

#include <sphshell/approx/approx.hpp>
#include <sphshell/approx/memory_estimate.hpp>
#include <sphshell/approx/mls.hpp>
#include <sphshell/approx/neighbour_search.hpp>
#include <sphshell/approx/nsph.hpp>
#include <sphshell/approx/shape_functions.hpp>
