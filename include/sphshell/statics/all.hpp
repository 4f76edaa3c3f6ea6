#pragma once
// Every part of the static analysis family (statics/statics.hpp states the contract).
#include <sphshell/statics/statics.hpp>

#include <sphshell/statics/buckling.hpp>
#include <sphshell/statics/buckling_frames.hpp>
#include <sphshell/statics/conditions.hpp>
#include <sphshell/statics/coupling.hpp>
#include <sphshell/statics/krylov.hpp>
#include <sphshell/statics/path_csv.hpp>
#include <sphshell/statics/path_frames.hpp>
#include <sphshell/statics/path_following.hpp>
#include <sphshell/statics/sparse_factorisation.hpp>
#include <sphshell/statics/stability.hpp>
#include <sphshell/statics/static_solve.hpp>
#include <sphshell/statics/tangent.hpp>
