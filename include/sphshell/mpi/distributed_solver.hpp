#pragma once
// The Solver over the ranks of a communicator: Solver<..., mpi::Domain>
// (solver.hpp has the step, solver/output.hpp the frames in pieces and the
// probes written by the owning rank; docs/distributed.md the method).
//
// mpi::DistributedSolver<Approx, Rule, Material, Crack, Stepper> is the old
// name of Solver<Approx, Rule, Material, Crack, Stepper, mpi::Domain>, kept
// for existing code (deprecated: use the Solver with mpi::Domain).

#include <sphshell/mpi/communicator.hpp>
#include <sphshell/mpi/domain.hpp>
#include <sphshell/core/exact_sum.hpp>
#include <sphshell/solver.hpp>

namespace sphshell::mpi {
// Deprecated name (see above): the constructor takes the communicator, the
// model, the material parameters, the options and the partition weights.
template <class Approx, class Rule, class Material, class Crack = crack::None,
          class Stepper = stepper::CentralDifference>
using DistributedSolver = Solver<Approx, Rule, Material, Crack, Stepper, Domain>;
}  // namespace sphshell::mpi
