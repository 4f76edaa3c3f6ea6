#pragma once
// Every crack policy of the family.

#include <sphshell/crack/crack.hpp>
#include <sphshell/crack/line_segments.hpp>
#include <sphshell/crack/none.hpp>
