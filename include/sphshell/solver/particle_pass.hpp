#pragma once
// The particles' part of a Solver's step (on one process or many),
// in one parallel pass over the energy books' chunks of the owned particles
// (ParticleEnergyTerms::sum_chunk), each chunk on one thread while its data
// is in that core's cache: its loads, the copy of v^{n−½}, the stepper's
// velocity update, the copy of the free velocities, the kinematic
// conditions, its energy terms, the configuration update, a look for
// non-finite values and, serially, the packing of its positions and directors
// for the force pass's gathers (InternalForceAssembler::pack). The parts one
// after the other took nine parallel regions, each costing two threads more
// than the part's work on the paper's plate (docs/performance.md). Serial
// loads (user pressure functions, detail::Load::serial) are applied by the
// caller before the pass. The rigid bodies' contact (contact/body_set.hpp),
// when the run has bodies, adds its loads after the chunk's loads and books
// its work after the chunk's energy terms; the bodies move after the pass.
//
// Nothing is thrown: the pass returns what failed, for the caller to report
// as the parts would one after the other (a non-finite load at the lowest
// particle, then the first failing condition in the order they were added,
// then the lowest particle with a non-finite state) — at once in a serial
// run, through the agreement with global ids in a distributed one.

#include <sphshell/contact/body_set.hpp>
#include <sphshell/core/parallel.hpp>
#include <sphshell/core/types.hpp>
#include <sphshell/shell/constraints.hpp>
#include <sphshell/shell/loads.hpp>
#include <sphshell/solver/energy_ledger.hpp>
#include <sphshell/solver/internal_forces.hpp>
#include <sphshell/solver/particles.hpp>
#include <sphshell/stepper/stepper.hpp>

#include <atomic>
#include <cstddef>
#include <exception>
#include <mutex>
#include <utility>
#include <vector>

namespace sphshell::solver {

struct ParticlePassFailures {
  std::size_t load;                  // lowest particle whose load is not finite (owned end if none)
  std::size_t condition;             // the first failing condition, in the order added (condition count if none)
  std::exception_ptr condition_error;
  std::size_t state;                 // lowest particle with a non-finite state (owned end if none)
};

// The parts the pass works on. ledger: the energy books' chunk interface
// (EnergyLedger, or the distributed one); packer: null when the gathers need
// particles the pass does not step (a distributed run's ghosts); bodies: null
// when the run has no rigid bodies (prepared by the caller otherwise).
template <class Ledger, class Stepper>
struct ParticlePass {
  ExternalLoads& loads;
  detail::LoadContext load_context;
  detail::Constraints& constraints;
  const std::vector<Vector3>& reference_position;
  double time_step;
  Ledger& ledger;
  Stepper& stepper;
  ParticleState& particles;
  const Inertia& inertia;
  const ParticleForces& forces;
  InternalForceAssembler* packer;
  contact::RigidBodySet* bodies;

  ParticlePassFailures run(const stepper::StepContext& context, bool loads_in_pass) {
    if (loads_in_pass) loads.start_step(context.at.time);
    constraints.prepare();
    ledger.start_step(particles);
    if (packer) packer->start_packing(particles.size());
    const std::size_t end = particles.ranges.owned_end;
    std::atomic<std::size_t> load_failure{end}, state_failure{end};
    std::mutex condition_mutex;
    ParticlePassFailures failed{end, constraints.particles().size(), nullptr, end};
    parallel::for_each_task(ledger.chunk_count(particles), [&](std::size_t chunk) noexcept {
      const auto [first, last] = EnergyLedger::particle_chunk(particles, chunk);
      if (loads_in_pass) {
        const std::size_t i = loads.apply_range(load_context, first, last);
        if (i < last) parallel::keep_lowest(load_failure, i);
      }
      if (bodies) bodies->load_chunk(chunk, first, last);
      ledger.remember_velocities(particles, first, last);
      stepper.advance_velocities(context, particles, inertia, forces, first, last);
      ledger.remember_free_velocities(particles, first, last);
      constraints.impose(context.at, reference_position, time_step, particles.director, particles.velocity,
                         particles.angular_velocity, first, last, [&](std::size_t k, std::exception_ptr error) {
                           std::lock_guard<std::mutex> lock(condition_mutex);
                           if (k < failed.condition) {
                             failed.condition = k;
                             failed.condition_error = std::move(error);
                           }
                         });
      ledger.book_chunk(context, particles, inertia, forces, chunk);
      if (bodies) bodies->book_chunk(chunk, first, last, context.velocity_step);
      stepper.advance_configuration(context, particles, first, last);
      for (std::size_t i = first; i < last; ++i)
        if (!all_finite(particles.position[i], particles.director[i], particles.velocity[i],
                        particles.angular_velocity[i])) {
          parallel::keep_lowest(state_failure, i);
          break;
        }
      if (packer) packer->pack(particles, first, last);
    });
    failed.load = load_failure.load();
    failed.state = state_failure.load();
    return failed;
  }
};

}  // namespace sphshell::solver
