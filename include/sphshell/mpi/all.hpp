#pragma once
// The distributed layer (docs/distributed.md): link sphshell::mpi, which brings
// MPI::MPI_CXX. Not part of <sphshell/sphshell.hpp>, which needs no MPI.

#include <sphshell/mpi/communicator.hpp>
#include <sphshell/mpi/distributed_solver.hpp>
#include <sphshell/mpi/error_agreement.hpp>
#include <sphshell/core/exact_sum.hpp>
#include <sphshell/mpi/halo.hpp>
#include <sphshell/mpi/layout.hpp>
#include <sphshell/mpi/partition.hpp>
#include <sphshell/mpi/reductions.hpp>
