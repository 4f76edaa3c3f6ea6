// Must not compile: the static analysis (sphshell/statics) of a distributed
// solver (statics/tangent.hpp); the message names solve_static's relaxation,
// which runs over the ranks.
#include <sphshell/approx/mls.hpp>
#include <sphshell/kernel/cubic_spline.hpp>
#include <sphshell/material/elastic.hpp>
#include <sphshell/mpi/distributed_solver.hpp>
#include <sphshell/solver.hpp>
#include <sphshell/statics/path_following.hpp>
#include <sphshell/thickness/gauss.hpp>

using Distributed = sphshell::mpi::DistributedSolver<sphshell::approx::MLS<sphshell::kernel::CubicSpline>,
                                                     sphshell::thickness::Gauss<3>, sphshell::material::Elastic>;

int main() { return sizeof(sphshell::statics::PathFollower<Distributed>) > 0 ? 0 : 1; }
