#pragma once
// The energy ledger (docs/method.md, "Energy accounting"): the work of the
// external loads and prescribed motions, the work removed by damping, the
// kinetic energy, the internal work done on the material, and their balance,
// checked while the run goes.
//
// Every sum over particles or points adds fixed chunks of them, each in index
// (or row) order on a thread, then the chunks' sums in a fixed order
// (ParticleEnergyTerms here, PointChunks for the points), so the books are
// identical for any thread count.

#include <sphshell/core/error.hpp>
#include <sphshell/core/parallel.hpp>
#include <sphshell/core/types.hpp>
#include <sphshell/solver/options.hpp>
#include <sphshell/solver/particles.hpp>
#include <sphshell/stepper/stepper.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

namespace sphshell {

struct EnergyReport {
  double kinetic = 0.0;
  double internal = 0.0;             // work done on the shell's material (elastic + dissipated)
  double elastic = 0.0;              // recoverable part of internal
  double plastic_dissipation = 0.0;  // internal − elastic
  double external_work = 0.0;        // loads and prescribed motions
  double damping_work = 0.0;         // removed by mass-proportional damping
  double released_by_fracture = 0.0; // elastic energy held by integration points when they were removed (part of plastic_dissipation)
  // Rigid bodies and their contact (contact/body_set.hpp); all zero in a run without bodies.
  double rigid_body_kinetic = 0.0;     // the bodies' kinetic energy
  double contact_energy = 0.0;         // held by the contact springs
  double friction_dissipation = 0.0;   // dissipated by contact friction
  double contact_work_on_shell = 0.0;  // the contact forces' work on the shell (part of external_work)
  double rigid_body_work = 0.0;        // put into the bodies from outside the contact (initial motion, gravity, drives)
  // kinetic + internal + damping − external, zero up to the time-discretization
  // error. The leapfrog velocities live at half steps, so the internal energy
  // enters at the half step too (the mean of its two neighbouring values).
  // With rigid bodies, that of the whole system (contact/body_set.hpp):
  // + contact_work_on_shell + rigid_body_kinetic + contact_energy
  // + friction_dissipation − rigid_body_work.
  double balance() const { return balance_; }

  // The bodies' and contacts' terms, into the report and its balance.
  template <class ContactEnergy>
  void add_rigid_bodies(const ContactEnergy& energy) {
    rigid_body_kinetic = energy.body_kinetic;
    contact_energy = energy.spring;
    friction_dissipation = energy.friction_dissipation;
    contact_work_on_shell = energy.shell_contact_work;
    rigid_body_work = energy.body_work;
    balance_ += contact_work_on_shell + rigid_body_kinetic + contact_energy + friction_dissipation - rigid_body_work;
  }

  double balance_ = 0.0;
};

namespace solver {

// The per-particle terms of one step's books, for the particles [begin, end)
// a ledger books (all of them serially, the owned ones on an MPI rank): the
// work over the step of the external forces and moments with the reactions of
// the kinematic conditions, f · Δt · (v^{n−½} + v^{n+½})/2 with the reactions
// m (v − v_free)/Δt; the damping work c m |v̄|²Δt; the kinetic energy at n+½.
// Each term is written to an array. The serial ledger adds them in fixed
// chunks of sum_chunk particles, each in index order, then the chunks' sums in
// chunk order (book_chunk(), total()); the MPI one in index order. So the
// books are identical for any thread count.
//
// The members taking a range [first, last) are for the solver's particle
// pass (Solver::advance_particles): the terms of a chunk of particles are
// formed on the thread that steps that chunk, while its velocities are in
// that core's cache. Done in a pass of their own on the calling thread, they
// pulled half of the particles' velocities to that core every step, and the
// stepper's next writes had to take them back (docs/performance.md).
// Call prepare() before a pass.
class ParticleEnergyTerms {
 public:
  // Particles per partial sum in book_chunk(): fixed, not per thread, so that
  // the sums are the same whatever the thread count.
  static constexpr std::size_t sum_chunk = 256;

  // The arrays for particles [0, end), and chunk sums for the chunks of [begin, end).
  void prepare(std::size_t begin, std::size_t end) {
    size_velocities(end);
    size_terms(end);
    chunk_sums_.assign(chunk_count(begin, end), Sums{});
  }
  static std::size_t chunk_count(std::size_t begin, std::size_t end) {
    return (end - begin + sum_chunk - 1) / sum_chunk;
  }

  // v^{n−½} and ω^{n−½} of particles [first, last), before the stepper updates them.
  void remember_velocities(const ParticleState& state, std::size_t first, std::size_t last) {
    for (std::size_t i = first; i < last; ++i) {
      old_velocity_[i] = state.velocity[i];
      old_angular_velocity_[i] = state.angular_velocity[i];
    }
  }
  // The velocities the unconstrained update produced, before the kinematic
  // conditions: their difference is the reactions' impulse.
  void remember_free_velocities(const ParticleState& state, std::size_t first, std::size_t last) {
    for (std::size_t i = first; i < last; ++i) free_velocity_[i] = state.velocity[i];
  }
  // The sums over particles [begin, end) of the three terms.
  struct Sums {
    double external = 0.0, damping = 0.0, kinetic = 0.0;
  };
  // The particles [first, last) of the chunks of [begin, end) that start at
  // `begin`: chunk k holds [begin + k sum_chunk, begin + (k + 1) sum_chunk).
  static std::size_t chunk_first(std::size_t begin, std::size_t chunk) { return begin + chunk * sum_chunk; }
  static std::size_t chunk_last(std::size_t begin, std::size_t end, std::size_t chunk) {
    return std::min(end, begin + (chunk + 1) * sum_chunk);
  }
  // The terms of chunk `chunk` of [begin, end) and their sums, added in index order.
  void book_chunk(const stepper::StepContext& context, const ParticleState& state, const Inertia& inertia,
                  const ParticleForces& forces, std::size_t begin, std::size_t end, std::size_t chunk) {
    Sums sums;
    const std::size_t last = chunk_last(begin, end, chunk);
    for (std::size_t i = chunk_first(begin, chunk); i < last; ++i) {
      compute_particle(i, context, state, inertia, forces);
      sums.external += external_[i];
      sums.damping += damping_[i];
      sums.kinetic += kinetic_[i];
    }
    chunk_sums_[chunk] = sums;
  }
  // The chunks' sums (book_chunk) added in chunk order.
  Sums total() const {
    Sums total;
    for (const Sums& sums : chunk_sums_) {
      total.external += sums.external;
      total.damping += sums.damping;
      total.kinetic += sums.kinetic;
    }
    return total;
  }

  const std::vector<double>& external() const { return external_; }
  const std::vector<double>& damping() const { return damping_; }
  const std::vector<double>& kinetic() const { return kinetic_; }

 private:
  void size_velocities(std::size_t end) {
    old_velocity_.resize(end);
    old_angular_velocity_.resize(end);
    free_velocity_.resize(end);
  }
  void size_terms(std::size_t end) {
    external_.resize(end);
    damping_.resize(end);
    kinetic_.resize(end);
  }
  void compute_particle(std::size_t i, const stepper::StepContext& context, const ParticleState& state,
                        const Inertia& inertia, const ParticleForces& forces) {
    const double dt = context.velocity_step;
    const double c = context.damping;
    const Vector3 average = 0.5 * (old_velocity_[i] + state.velocity[i]);
    const Vector3 average_angular = 0.5 * (old_angular_velocity_[i] + state.angular_velocity[i]);
    const Vector3 reaction = inertia.mass[i] * (state.velocity[i] - free_velocity_[i]) / dt;
    external_[i] =
        dt * (forces.external[i] + reaction).dot(average) + dt * forces.external_moment[i].dot(average_angular);
    damping_[i] = dt * c * inertia.mass[i] * average.squaredNorm() +
                  dt * c * inertia.rotary_inertia[i] * average_angular.squaredNorm();
    kinetic_[i] = 0.5 * inertia.mass[i] * state.velocity[i].squaredNorm() +
                  0.5 * inertia.rotary_inertia[i] * state.angular_velocity[i].squaredNorm();
  }

  std::vector<Vector3> old_velocity_, old_angular_velocity_, free_velocity_;
  std::vector<double> external_, damping_, kinetic_;
  std::vector<Sums> chunk_sums_;
};

// The ledger's rules: when the balance is checked, how the particles are
// chunked, when the balance is lost and what the run then says.
struct EnergyLedger {
  // The balance is checked every check_interval steps (the elastic energy
  // costs a pass over all states: about 2 % of a step's time when checked
  // every step, on the square plate), from step first_checked_step on: the
  // start-up half step leaves a balance error that decays over the first
  // steps (|balance| / largest energy, worst of a point moment, a point force,
  // pressure, gravity and prescribed velocities on a 21 × 11 plate: 0.37 at
  // step 1, 0.05 at step 4, about 0.025 from step 8 on), so checks from
  // step 8 stay a factor 4 below the default tolerance 0.1 and leave only the
  // first 7 steps unchecked.
  static constexpr long check_interval = 4;
  static constexpr long first_checked_step = 8;
  // Below the energy of this strain throughout the shell the sums are
  // round-off (e.g. before a travelling load arrives) and carry no balance.
  static constexpr double round_off_strain_squared = 1e-20;

  // The particles [first, last) of chunk `chunk`.
  static std::pair<std::size_t, std::size_t> particle_chunk(const ParticleState& state, std::size_t chunk) {
    return {ParticleEnergyTerms::chunk_first(state.ranges.owned_begin, chunk),
            ParticleEnergyTerms::chunk_last(state.ranges.owned_begin, state.ranges.owned_end, chunk)};
  }
  // Whether step n is one whose balance is checked.
  static bool is_check_step(long step) { return step % check_interval == 0; }

  // Whether the balance is lost at `at`: |balance| above the tolerance times
  // the largest energy in play, once the start-up steps are past and the
  // energies are above round-off.
  static bool balance_lost(const StepTime& at, const EnergyReport& e, const MonitoringOptions& monitoring,
                           double round_off_energy) {
    const double scale =
        std::max({std::abs(e.external_work), e.kinetic, std::abs(e.internal), e.rigid_body_kinetic});
    return at.step >= first_checked_step && scale > round_off_energy &&
           std::abs(e.balance()) > monitoring.energy_tolerance * scale;
  }
  // The message of a lost balance; largest_particle < 0 when no particle is named.
  static std::string balance_lost_message(const EnergyReport& e, long long largest_particle, double largest_energy) {
    std::ostringstream message;
    message << "energy balance lost (kinetic " << e.kinetic << " J, internal " << e.internal
            << " J, external work " << e.external_work << " J, balance " << e.balance()
            << " J); reduce the time step or check the loads";
    // The particle holding the most kinetic energy is where a run that blows up is going.
    if (largest_particle >= 0)
      message << "; the largest kinetic energy is at particle " << largest_particle << " (" << largest_energy << " J)";
    return message.str();
  }
};

// The books of a run over a domain (domain/domain.hpp). One process keeps
// running totals, each step's added once (the chunks' sums in chunk order),
// so they are the same for any thread count. Several keep exact
// accumulators of every owned particle's and point's term (core/exact_sum.hpp)
// and round once when a report is due (one all-reduce, collective): the
// books are the same for any rank count and differ from the serial ones only
// by the serial rounding; energies do not feed back into the motion. No
// communication per step.
template <class Domain>
class EnergyBooks : public EnergyLedger {
  static constexpr bool distributed = Domain::is_distributed;
  using Sum = typename Domain::EnergySum;

 public:
  // volume: Σ d_i A_i of the shell; youngs_modulus sets the round-off scale.
  EnergyBooks(const MonitoringOptions& monitoring, double youngs_modulus, double volume)
      : monitoring_(monitoring), round_off_energy_(youngs_modulus * volume * round_off_strain_squared) {}

  // The step's books (the particles' part of the step, solver/particle_pass.hpp):
  // start_step() before the pass; in it, for each chunk of particles
  // (particle_chunk()), remember_velocities() before the stepper updates the
  // velocities, remember_free_velocities() after it and before the kinematic
  // conditions (their difference is the reactions' impulse), book_chunk()
  // after them: the chunk's work of the external forces (reactions included)
  // and of the damping, and its kinetic energy at n+½ (ParticleEnergyTerms);
  // finish_step() after the pass. The particles are the owned ones.
  void start_step(const ParticleState& state) {
    owned_begin_ = state.ranges.owned_begin;
    owned_end_ = state.ranges.owned_end;
    terms_.prepare(owned_begin_, owned_end_);
  }
  std::size_t chunk_count(const ParticleState& state) const {
    return ParticleEnergyTerms::chunk_count(state.ranges.owned_begin, state.ranges.owned_end);
  }
  void remember_velocities(const ParticleState& state, std::size_t first, std::size_t last) {
    terms_.remember_velocities(state, first, last);
  }
  void remember_free_velocities(const ParticleState& state, std::size_t first, std::size_t last) {
    terms_.remember_free_velocities(state, first, last);
  }
  void book_chunk(const stepper::StepContext& context, const ParticleState& state, const Inertia& inertia,
                  const ParticleForces& forces, std::size_t chunk) {
    terms_.book_chunk(context, state, inertia, forces, owned_begin_, owned_end_, chunk);
  }
  void finish_step() {
    if constexpr (distributed) {
      kinetic_ = Sum();
      for (std::size_t i = owned_begin_; i < owned_end_; ++i) {
        external_work_.add(terms_.external()[i]);
        damping_work_.add(terms_.damping()[i]);
        kinetic_.add(terms_.kinetic()[i]);
      }
    } else {
      const ParticleEnergyTerms::Sums sums = terms_.total();
      external_work_ += sums.external;
      damping_work_ += sums.damping;
      kinetic_ = sums.kinetic;
    }
  }

  // The internal work of one force evaluation: serially its sum over the
  // points (InternalForceAssembler::internal_work); distributed, the points
  // this rank owns (owned[p] != 0; a redundant copy's work is booked by its owner).
  template <class Assembler>
  void book_internal_work(const Assembler& assembler, const std::vector<char>& owned) {
    previous_internal_ = internal_;
    if constexpr (distributed) {
      const std::vector<double>& work = assembler.work_increments();
      for (std::size_t p = 0; p < work.size(); ++p)
        if (owned[p]) internal_.add(work[p]);
    } else {
      internal_ += assembler.internal_work();
    }
  }

  // After a static solve (solver/static_solution.hpp): the shell at rest
  // holding `elastic` (the total over the processes), booked as work the
  // loads did, so the balance of a run that follows starts at zero.
  // Distributed, process 0's books hold the totals, the others' nothing.
  void restart_at_rest(const Domain& domain, double elastic) {
    Sum held{}, zero{};
    if constexpr (distributed) {
      if (domain.is_root()) held.add(elastic);
    } else {
      held = elastic;
    }
    previous_internal_ = internal_ = external_work_ = held;
    damping_work_ = kinetic_ = zero;
  }

  // The books (over all processes: collective), with the elastic energy now
  // held and the energy the fracture released (this process's shares).
  EnergyReport report(const Domain& domain, const Sum& elastic, const Sum& released) const {
    std::array<double, 7> total{};
    if constexpr (distributed)
      total = domain.totals(std::array<const Sum*, 7>{&kinetic_, &internal_, &previous_internal_, &external_work_,
                                                      &damping_work_, &elastic, &released});
    else
      total = {kinetic_, internal_, previous_internal_, external_work_, damping_work_, elastic, released};
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

  // Checkpoints (solver/checkpoint.hpp): the books (distributed: this rank's
  // accumulators, exactly). The per-particle terms and remembered velocities
  // are rewritten by every step before use.
  template <class Writer>
  void save(Writer& out) const {
    if constexpr (distributed) {
      for (const Sum* sum : {&internal_, &previous_internal_, &external_work_, &damping_work_, &kinetic_})
        out(sum->raw());
    } else {
      out(previous_internal_, internal_, external_work_, damping_work_, kinetic_);
    }
  }
  template <class Reader>
  void load(Reader& in) {
    if constexpr (distributed) {
      for (Sum* sum : {&internal_, &previous_internal_, &external_work_, &damping_work_, &kinetic_}) {
        typename Sum::Raw raw{};
        in(raw);
        *sum = Sum::from_raw(raw);
      }
    } else {
      in(previous_internal_, internal_, external_work_, damping_work_, kinetic_);
    }
  }

  // Stops the run when the balance is lost (balance_lost), naming the
  // particle of largest kinetic energy (ties: the lowest global id; over all
  // processes, which decide alike on the reduced books). Collective.
  void check_balance(const Domain& domain, const StepTime& at, const EnergyReport& e) const {
    if (!balance_lost(at, e, monitoring_, round_off_energy_)) return;
    const std::vector<double>& kinetic = terms_.kinetic();
    long long particle = -1;
    double energy = -1.0;
    for (std::size_t i = 0; i < kinetic.size(); ++i)
      if (kinetic[i] > energy) {
        energy = kinetic[i];
        particle = domain.global_of(i);
      }
    const std::pair<long long, double> largest = domain.largest({particle, energy});
    detail::fail_unstable(at, balance_lost_message(e, largest.first, largest.first >= 0 ? largest.second : 0.0));
  }

 private:
  MonitoringOptions monitoring_;
  double round_off_energy_;
  Sum previous_internal_{}, internal_{}, external_work_{}, damping_work_{}, kinetic_{};
  std::size_t owned_begin_ = 0, owned_end_ = 0;
  ParticleEnergyTerms terms_;
};

}  // namespace solver
}  // namespace sphshell
