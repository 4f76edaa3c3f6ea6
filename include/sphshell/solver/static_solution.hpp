#pragma once
// Solver::solve_static's parameters and results under the solver's names; the
// load stepping, Newton's method and the dynamic relaxation are the static
// family's (statics/static_solve.hpp, on its tangent assembly statics/coupling.hpp).

#include <sphshell/statics/static_solve.hpp>

namespace sphshell::solver {

using statics::automatic_relaxation_steps;
using statics::is_path_independent_v;
using statics::StaticDamping;
using statics::StaticIteration;
using statics::StaticMass;
using statics::StaticNotConverged;
using statics::StaticParameters;
using statics::StaticResult;
using statics::StaticSystem;
using statics::solve_static;
using statics::validate;

}  // namespace sphshell::solver
