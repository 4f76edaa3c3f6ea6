#pragma once
// The energy books of a distributed run (docs/distributed.md, "The energy
// ledger"): the serial ledger's terms (solver/energy_ledger.hpp, the same
// expressions per particle and per point), each rank adding those of the
// particles and points it owns into exact accumulators (mpi/exact_sum.hpp).
//
// Why exact sums: a sum split between ranks rounds differently from the serial
// loop and differently again for each rank count. The accumulators hold every
// term of the run exactly and round once when a report is due, so the books
// are the same for any rank count, and they differ from the serial ledger
// only by that ledger's own rounding (its running totals round once per
// step). Energies do not feed back into the motion, so the trajectories stay
// bitwise the serial ones whatever the books do.
//
// Communication: none per step. A report (the balance check every
// solver::EnergyLedger::check_interval steps, energy()) adds the ranks'
// accumulators in one all-reduce of 64-bit integers.

#include <sphshell/core/error.hpp>
#include <sphshell/core/parallel.hpp>
#include <sphshell/core/types.hpp>
#include <sphshell/mpi/communicator.hpp>
#include <sphshell/mpi/exact_sum.hpp>
#include <sphshell/solver/energy_ledger.hpp>
#include <sphshell/solver/options.hpp>
#include <sphshell/solver/particles.hpp>
#include <sphshell/stepper/stepper.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <vector>

namespace sphshell::mpi {

// The correctly rounded totals of several accumulators over all ranks, in one
// all-reduce (the limbs of each, side by side).
template <std::size_t N>
std::array<double, N> sum_each(const Communicator& comm, const std::array<const ExactSum*, N>& local) {
  std::vector<std::int64_t> raw;
  raw.reserve(N * ExactSum::raw_size);
  for (const ExactSum* accumulator : local) {
    ExactSum normalised = *accumulator;
    normalised.normalize();
    raw.insert(raw.end(), normalised.raw().begin(), normalised.raw().end());
  }
  comm.sum_in_place(raw);
  std::array<double, N> totals{};
  for (std::size_t k = 0; k < N; ++k) {
    ExactSum::Raw part{};
    std::copy_n(raw.begin() + static_cast<std::ptrdiff_t>(k * ExactSum::raw_size), ExactSum::raw_size, part.begin());
    totals[k] = ExactSum::from_raw(part).value();
  }
  return totals;
}

class DistributedLedger {
 public:
  // volume: Σ d_i A_i of the whole shell; youngs_modulus sets the round-off scale.
  DistributedLedger(const MonitoringOptions& monitoring, double youngs_modulus, double volume)
      : monitoring_(monitoring),
        round_off_energy_(youngs_modulus * volume * solver::EnergyLedger::round_off_strain_squared) {}

  // The serial ledger's chunk interface (solver::EnergyLedger, for the
  // particle pass, solver/particle_pass.hpp) over the owned particles; the
  // terms are added exactly in finish_step().
  void start_step(const solver::ParticleState& state) {
    owned_begin_ = state.ranges.owned_begin;
    owned_end_ = state.ranges.owned_end;
    terms_.prepare(owned_begin_, owned_end_);
  }
  std::size_t chunk_count(const solver::ParticleState& state) const {
    return solver::ParticleEnergyTerms::chunk_count(state.ranges.owned_begin, state.ranges.owned_end);
  }
  void remember_velocities(const solver::ParticleState& state, std::size_t first, std::size_t last) {
    terms_.remember_velocities(state, first, last);
  }
  void remember_free_velocities(const solver::ParticleState& state, std::size_t first, std::size_t last) {
    terms_.remember_free_velocities(state, first, last);
  }
  void book_chunk(const stepper::StepContext& context, const solver::ParticleState& state,
                  const solver::Inertia& inertia, const solver::ParticleForces& forces, std::size_t chunk) {
    terms_.book_chunk(context, state, inertia, forces, owned_begin_, owned_end_, chunk);
  }
  void finish_step() {
    kinetic_ = ExactSum();
    for (std::size_t i = owned_begin_; i < owned_end_; ++i) {
      external_work_.add(terms_.external()[i]);
      damping_work_.add(terms_.damping()[i]);
      kinetic_.add(terms_.kinetic()[i]);
    }
  }

  // The internal work of one force evaluation: the points this rank owns
  // (owned[p] != 0; a redundant copy's work is booked by its owner).
  void book_internal_work(const std::vector<double>& work_increments, const std::vector<char>& owned) {
    previous_internal_ = internal_;
    for (std::size_t p = 0; p < work_increments.size(); ++p)
      if (owned[p]) internal_.add(work_increments[p]);
  }

  // The books over all ranks, with the elastic energy held by this rank's
  // owned points and the energy the fracture released at them. Collective.
  EnergyReport report(const Communicator& comm, const ExactSum& elastic, const ExactSum& released) const {
    const std::array<double, 7> total = sum_each<7>(
        comm, {&kinetic_, &internal_, &previous_internal_, &external_work_, &damping_work_, &elastic, &released});
    EnergyReport report;
    report.kinetic = total[0];
    report.internal = total[1];
    report.elastic = total[5];
    report.plastic_dissipation = total[1] - total[5];
    report.external_work = total[3];
    report.damping_work = total[4];
    report.released_by_fracture = total[6];
    report.balance_ = total[0] + 0.5 * (total[2] + total[1]) + total[4] - total[3];
    return report;
  }

  // Checkpoints (DistributedSolver::save_checkpoint): this rank's
  // accumulators, exactly. The per-particle terms and remembered velocities
  // are rewritten by every step before use.
  template <class Writer>
  void save(Writer& out) const {
    for (const ExactSum* sum : {&internal_, &previous_internal_, &external_work_, &damping_work_, &kinetic_})
      out(sum->raw());
  }
  template <class Reader>
  void load(Reader& in) {
    for (ExactSum* sum : {&internal_, &previous_internal_, &external_work_, &damping_work_, &kinetic_}) {
      ExactSum::Raw raw{};
      in(raw);
      *sum = ExactSum::from_raw(raw);
    }
  }

  // The serial check (solver::EnergyLedger::check_balance) on the reduced
  // books: every rank decides alike, and when the balance is lost they find
  // the particle of largest kinetic energy together (ties: the lowest global
  // id, as the serial max_element) and throw the same Error. Collective.
  template <class GlobalId>
  void check_balance(const Communicator& comm, const StepTime& at, const EnergyReport& e, GlobalId&& global_id) const {
    if (!solver::EnergyLedger::balance_lost(at, e, monitoring_, round_off_energy_)) return;
    struct Largest {
      double energy;
      std::int64_t particle;
    } mine{-1.0, -1};
    const std::vector<double>& kinetic = terms_.kinetic();
    for (std::size_t i = 0; i < kinetic.size(); ++i)
      if (kinetic[i] > mine.energy) mine = {kinetic[i], global_id(i)};
    Largest largest{-1.0, -1};
    for (const Largest& candidate : comm.all_gather(mine))
      if (candidate.particle >= 0 &&
          (candidate.energy > largest.energy ||
           (candidate.energy == largest.energy && candidate.particle < largest.particle)))
        largest = candidate;
    sphshell::detail::fail_unstable(
        at, solver::EnergyLedger::balance_lost_message(e, static_cast<long long>(largest.particle), largest.energy));
  }

 private:
  MonitoringOptions monitoring_;
  double round_off_energy_;
  ExactSum internal_, previous_internal_, external_work_, damping_work_, kinetic_;
  std::size_t owned_begin_ = 0, owned_end_ = 0;
  solver::ParticleEnergyTerms terms_;
};

}  // namespace sphshell::mpi
