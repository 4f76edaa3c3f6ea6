#pragma once
// Every kernel of the family.

#include <sphshell/kernel/cubic_spline.hpp>
#include <sphshell/kernel/kernel.hpp>
#include <sphshell/kernel/quintic_spline.hpp>
#include <sphshell/kernel/wendland_c2.hpp>
