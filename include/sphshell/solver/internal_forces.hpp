#pragma once
// The internal-force assembler: the one hot loop of a step. For every active
// integration point: gather a1, a2, n, n1, n2 from its neighbours → strains
// (Green or linear, shell/kinematics.hpp) → material update through the
// thickness (Section) → resultants → the point's five conjugate forces (and
// the corner forces of its edge-tied shear) kept per point. The points go
// through this in groups of thickness::points_per_group (SectionGroup,
// section_group.hpp): the material update of a group's points runs side by
// side, a vector lane a pair of point and integral point; a point alone is
// the group of one. Then each particle
// sums, over the shape-function slots that refer to it and in a fixed order
// (IntegrationPoints::force_entries), the slot's share of its point's forces
// (the deterministic sum: no atomic additions, identical results for any thread
// count). The per-slot forces are formed where they are added, so no array of
// them is written and read back. The work of each point over the step is kept
// for the energy ledger.
//
// The two passes are interleaved (AssemblySchedule): the points integrate in
// runs of rows, and a particle is summed as soon as the run that completes
// its points is done, while those points' forces and shape functions are
// still in the cache. Done as two separate passes, the sum read them back
// from memory once the model outgrew the cache (a 401×401 plate's step cost
// 1.6 times a 51×51 plate's per particle; docs/performance.md). A particle's
// sum is the same whenever it is formed, so results do not change. The points'
// work is summed in the same pass, chunk by chunk (PointChunks), after the run
// that integrated the chunk's points.

#include <sphshell/core/error.hpp>
#include <sphshell/core/parallel.hpp>
#include <sphshell/core/statistics.hpp>
#include <sphshell/core/types.hpp>
#include <sphshell/material/material.hpp>
#include <sphshell/shell/cell_shear.hpp>
#include <sphshell/shell/kinematics.hpp>
#include <sphshell/solver/assembly_schedule.hpp>
#include <sphshell/solver/integration_points.hpp>
#include <sphshell/solver/particles.hpp>
#include <sphshell/thickness/section_group.hpp>
#include <sphshell/solver/section_states.hpp>

#include <algorithm>
#include <array>
#include <atomic>
#include <cstddef>
#include <cstdint>
#include <exception>
#include <limits>
#include <memory>
#include <string>
#include <utility>
#include <vector>

namespace sphshell::solver {

// Parts of the InternalForceAssembler below, kept outside its class.
namespace assembler_parts {

// One particle's sum (InternalForceAssembler::sum_particle_forces): what it
// reads, gathered once per pass: the points' conjugate forces and the tied
// shear's corner forces the assembler keeps.
template <class Approx>
class ForceSum {
 public:
  ForceSum(const IntegrationPoints<Approx>& points, const shell::ConjugateForces* conjugate,
           const Vector3* tied_force, const Vector3* tied_director_force)
      : begin_(points.particle_slot_begin().data()),
        entries_(points.force_entries().data()),
        conjugate_(conjugate),
        tied_force_(tied_force),
        tied_director_force_(tied_director_force),
        untied_(points.untied_corner()),
        // Each group's Φ, ∂Φ/∂X1, ∂Φ/∂X2, picked by whether the entry's point
        // is a particle point (those follow the stress points).
        value_of_{points.shape(PointGroup::stress_points).value.data(),
                  points.shape(PointGroup::particles).value.data()},
        first_particle_point_(points.point(PointGroup::particles, 0)) {}

  void operator()(std::size_t i, ParticleForces& forces) const {
    Vector3 force = Vector3::Zero(), director_force = Vector3::Zero();
    for (std::size_t k = begin_[i]; k < begin_[i + 1]; ++k) {
      const auto& entry = entries_[k];
      const shell::ConjugateForces& f = conjugate_[entry.point];
      const std::size_t g = entry.point >= first_particle_point_ ? 1 : 0;
      const approx::ShapeValue& value = value_of_[g][entry.slot];
      const double phi = value.phi, dphi_d1 = value.dphi_d1, dphi_d2 = value.dphi_d2;
      Vector3 slot_force = dphi_d1 * f.a1 + dphi_d2 * f.a2;
      Vector3 slot_director_force = phi * f.n + dphi_d1 * f.n1 + dphi_d2 * f.n2;
      if (entry.tied_corner != untied_) {
        slot_force += tied_force_[entry.tied_corner];
        slot_director_force += tied_director_force_[entry.tied_corner];
      }
      force += slot_force;
      director_force += slot_director_force;
    }
    forces.internal[i] = force;
    forces.internal_director[i] = director_force;
  }

 private:
  const std::size_t* begin_;
  const typename IntegrationPoints<Approx>::ForceEntry* entries_;
  const shell::ConjugateForces* conjugate_;
  const Vector3 *tied_force_, *tied_director_force_;
  std::size_t untied_;
  const approx::ShapeValue* value_of_[2];
  std::size_t first_particle_point_;
};

// The lowest failing point of a segment, in the order of the separate
// passes (every stress point before every particle point), so that the
// error names the same point for any number of threads.
struct PointFailure {
  std::size_t group = point_groups.size();  // index_of(group); point_groups.size(): none
  std::size_t row = 0;
  std::exception_ptr error;
  void keep_lowest(PointGroup failed_group, std::size_t failed_row, std::exception_ptr failed) {
    const std::size_t g = index_of(failed_group);
    if (g < group || (g == group && failed_row < row)) {
      group = g;
      row = failed_row;
      error = std::move(failed);
    }
  }
};

// Per band of the schedule: the segments still to report in this
// compute(). A segment's report releases the forces it wrote and the last
// one's acquires the others', so the band's sums read every point's forces
// of this step. (A copy starts without counts: compute() sets them.)
class BandCountdown {
 public:
  BandCountdown() = default;
  BandCountdown(const BandCountdown&) {}
  BandCountdown& operator=(const BandCountdown&) { return *this; }
  void start(const AssemblySchedule& schedule) {
    if (size_ != schedule.band_count()) {
      size_ = schedule.band_count();
      remaining_ = std::make_unique<std::atomic<std::uint32_t>[]>(size_);
    }
    for (std::size_t b = 0; b < size_; ++b) remaining_[b].store(schedule.band_parts(b), std::memory_order_relaxed);
  }
  // True for the segment that reports last.
  bool report(std::size_t band) { return remaining_[band].fetch_sub(1, std::memory_order_acq_rel) == 1; }

 private:
  std::size_t size_ = 0;
  std::unique_ptr<std::atomic<std::uint32_t>[]> remaining_;
};

}  // namespace assembler_parts

class InternalForceAssembler {
 public:
  template <class Approx>
  InternalForceAssembler(bool nonlinear, const IntegrationPoints<Approx>& points) : nonlinear_(nonlinear) {
    prepare(points);
  }

  // Strains → material → resultants → slot forces at every active point, then
  // the per-particle sums into forces.internal and forces.internal_director.
  // A failing point stops the run (after the loop: the points before it are
  // already updated, so the solver cannot continue).
  template <class Approx, class Rule, class Law>
  void compute(const StepTime& at, const ParticleState& particles, const IntegrationPoints<Approx>& points,
               SectionStates<Rule, Law>& states, ParticleForces& forces) {
    start_packing(particles.size());
    parallel::for_each_range(std::size_t{0}, particles.size(),
                             [&](std::size_t first, std::size_t last) noexcept { pack(particles, first, last); });
    compute_packed(at, points, states, forces);
  }

  // The gathers read each particle's position and director packed side by
  // side (PackedKinematics). compute() packs them in a pass of its own; the
  // solver's particle pass instead packs each chunk of particles right after
  // moving it (Solver::advance_particles), one parallel region less per step,
  // and then calls compute_packed(). start_packing(count) before the packing;
  // pack() for every particle since it last moved before compute_packed().
  void start_packing(std::size_t count) { packed_.resize(count); }
  void pack(const ParticleState& particles, std::size_t first, std::size_t last) noexcept {
    for (std::size_t i = first; i < last; ++i)
      packed_[i] = PackedKinematics{particles.position[i], particles.director[i]};
  }
  template <class Approx, class Rule, class Law>
  void compute_packed(const StepTime& at, const IntegrationPoints<Approx>& points, SectionStates<Rule, Law>& states,
                      ParticleForces& forces) {
    prepare(points);
    schedule_.update(points, forces.internal.size(), segment_count());
    // Each segment integrates its runs and sums the particles that each run
    // completes; a band of particles whose points lie in several segments is
    // summed by the segment that finishes its share of them last.
    const assembler_parts::ForceSum<Approx> sum(points, conjugate_.data(), tied_force_.data(),
                                                tied_director_force_.data());
    const PointChunks chunks(points);
    work_chunk_sums_.resize(chunks.count());
    const auto work_of = [this](std::size_t p) { return work_increment_[p]; };
    failures_.assign(schedule_.segments(), assembler_parts::PointFailure{});
    band_countdown_.start(schedule_);
    parallel::for_each_task(schedule_.segments(), [&](std::size_t segment) noexcept {
      assembler_parts::PointFailure& failure = failures_[segment];
      for (std::size_t run = schedule_.first_run(segment); run < schedule_.end_run(segment); ++run) {
        const AssemblySchedule::Run& rows = schedule_.run(run);
        integrate_rows(rows.group, rows.first_row, rows.end_row, points, states, failure);
        sum_run_chunks(points, chunks, rows, work_of, work_chunk_sums_.data());
        for (const std::uint32_t i : schedule_.completed_by(run)) sum(i, forces);
        for (const std::uint32_t band : schedule_.bands_after(run))
          if (band_countdown_.report(band))
            for (const std::uint32_t i : schedule_.band(band)) sum(i, forces);
      }
    });
    report_failure(at, points);
    internal_work_ = detail::interleaved_sum(work_chunk_sums_);
  }

  // Forces of one point's stored resultants (no material update), from the
  // current surface gradients, kept as its conjugate forces, plus the forces of
  // its edge-tied shear from the particles' configuration. Returns the tied
  // shear's elastic energy (0 for a point whose shear is not tied, or whose
  // cell has a corner outside its row).
  template <class Approx, class Rule, class Law>
  double scatter_point(PointGroup group, std::size_t row, const shell::SurfaceGradients& current,
                       const ParticleState& particles, const IntegrationPoints<Approx>& points,
                       const SectionStates<Rule, Law>& states) {
    return scatter(group, row, current, points, states,
                   [&](int j) -> const Vector3& { return particles.position[std::size_t(j)]; },
                   [&](int j) -> const Vector3& { return particles.director[std::size_t(j)]; });
  }

  // Zeroes the forces a point leaves on the slots of its row (a removed point).
  template <class Approx>
  void clear_slots(PointGroup group, std::size_t row, const IntegrationPoints<Approx>& points) {
    const Vector3 zero = Vector3::Zero();
    conjugate_[points.point(group, row)] = shell::ConjugateForces{zero, zero, zero, zero, zero};
    if (group == PointGroup::stress_points) clear_tied_corners(row);
  }

  // Deterministic per-particle sums: for each slot that refers to the particle,
  // in the order of IntegrationPoints::force_entries, the slot's force
  // ∂Φ/∂X1 F_a1 + ∂Φ/∂X2 F_a2 (director: Φ F_n + ∂Φ/∂X1 F_n1 + ∂Φ/∂X2 F_n2) of its
  // point, plus the tied shear's force on that corner (a slot whose particle
  // is a tied corner). A removed point's forces and the corner forces of a
  // cell whose shear is left out are kept zero, so those slots add zeros
  // instead of being skipped. Adding a zero changes no bit of the sum: it
  // starts at +0 and a sum of doubles is −0 only when both terms are, so it is
  // never −0, and x + (±0) is x for any other x.
  // (compute() forms the same sums interleaved with the points' updates.)
  template <class Approx>
  void sum_particle_forces(const IntegrationPoints<Approx>& points, ParticleForces& forces) const {
    const assembler_parts::ForceSum<Approx> sum(points, conjugate_.data(), tied_force_.data(),
                                                tied_director_force_.data());
    parallel::for_each(std::size_t{0}, forces.internal.size(), [&](std::size_t i) noexcept { sum(i, forces); });
  }

  // The sum over the points of value(p) in fixed chunks (PointChunks): each
  // chunk added in row order on the thread that updates its points in
  // compute(), whose core's cache then still holds their data, then the
  // chunks' sums in chunk order, so the sum is the same for any thread count.
  // A pass over the points in index order would move a quarter of them to the
  // other core and back on two threads (docs/performance.md, "Threads"); added on the
  // calling thread, half of them (docs/performance.md). Before
  // the first compute(), or after the points' force entries or the thread
  // count changed, each chunk is a task of its own (same sums, any thread).
  // value must not throw.
  template <class Approx, class Value>
  double sum_over_points(const IntegrationPoints<Approx>& points, Value&& value) const {
    const PointChunks chunks(points);
    std::vector<double> chunk_sums(chunks.count(), 0.0);
    if (schedule_.is_current(points, segment_count())) {
      parallel::for_each_task(schedule_.segments(), [&](std::size_t segment) noexcept {
        for (std::size_t run = schedule_.first_run(segment); run < schedule_.end_run(segment); ++run)
          sum_run_chunks(points, chunks, schedule_.run(run), value, chunk_sums.data());
      });
    } else {
      parallel::for_each_task(chunks.count(), [&](std::size_t c) noexcept {
        const PointGroup group = chunks.group(c);
        const std::size_t first = chunks.first_row(c);
        const AssemblySchedule::Run rows{group, first, std::min(first + PointChunks::rows, points.count(group))};
        sum_run_chunks(points, chunks, rows, value, chunk_sums.data());
      });
    }
    return detail::interleaved_sum(chunk_sums);
  }

  // The time step that the strain increments of the next compute() span,
  // passed to rate-dependent laws (material.hpp, UpdateContext); other laws
  // never read it. The Solver sets it before every force pass: the step's
  // Δt, or infinity for a static solution (quasi-static, no strain rate).
  // Until then it is NaN, which a rate-dependent law refuses as soon as it flows.
  void set_time_step(double time_step) { update_context_.time_step = time_step; }
  double time_step() const { return update_context_.time_step; }

  // The work of the generalized stresses over the last compute(), summed over
  // the points as sum_over_points() does.
  double internal_work() const { return internal_work_; }

  // The point whose failure stopped the last compute() (the lowest failing
  // index of its group).
  std::size_t failed_point() const { return failed_point_; }

  // Work of the generalized stresses over the last update, per point (zero
  // for inactive points): a distributed run books the owned points' exactly
  // (solver/energy_ledger.hpp, EnergyBooks).
  const std::vector<double>& work_increments() const { return work_increment_; }

  // Strains of point p's current gradients against its reference (the
  // reference's dot products, computed once, in the nonlinear analysis).
  template <class Approx>
  shell::Strains strains_of(const shell::SurfaceGradients& current, const IntegrationPoints<Approx>& points,
                            std::size_t p) const {
    return nonlinear_ ? shell::green_strains(current, points.reference_products(p))
                      : shell::linear_strains(current, points.reference(p));
  }

 private:

  // The sums of value(p) over the chunks of a run's rows (a run starts at a
  // chunk's first row and ends at a chunk's end), each in row order.
  template <class Approx, class Value>
  static void sum_run_chunks(const IntegrationPoints<Approx>& points, const PointChunks& chunks,
                             const AssemblySchedule::Run& rows, Value& value, double* chunk_sums) {
    for (std::size_t first = rows.first_row; first < rows.end_row; first += PointChunks::rows) {
      const std::size_t end = std::min(first + PointChunks::rows, rows.end_row);
      double sum = 0.0;
      for (std::size_t row = first; row < end; ++row) sum += value(points.point(rows.group, row));
      chunk_sums[chunks.chunk_of(rows.group, first)] = sum;
    }
  }


  template <class Approx>
  void report_failure(const StepTime& at, const IntegrationPoints<Approx>& points) {
    assembler_parts::PointFailure lowest;
    for (const assembler_parts::PointFailure& failure : failures_)
      if (failure.error) lowest.keep_lowest(point_groups[failure.group], failure.row, failure.error);
    if (!lowest.error) return;
    const PointGroup group = point_groups[lowest.group];
    failed_point_ = points.point(group, lowest.row);
    detail::fail_unstable(at, std::string(name_of(group)) + " " + std::to_string(points.global_row(group, lowest.row)) +
                                  ": " + parallel::what(lowest.error));
  }

  // Segments of the interleaved pass: one with one thread; with more, a few
  // per thread, so that a thread the system holds back leaves some of its
  // share to the others (core/parallel.hpp).
  static std::size_t segment_count() {
    const int threads = parallel::thread_count();
    return threads == 1 ? 1 : std::size_t(threads) * AssemblySchedule::segments_per_thread;
  }

  // Per-point arrays are sized once; the work is zero for points that do not integrate.
  template <class Approx>
  void prepare(const IntegrationPoints<Approx>& points) {
    if (conjugate_.size() != points.size()) {
      const Vector3 zero = Vector3::Zero();
      conjugate_.assign(points.size(), shell::ConjugateForces{zero, zero, zero, zero, zero});
      // Every stress point's corners (untied_corner() is their count).
      tied_force_.assign(points.untied_corner(), zero);
      tied_director_force_.assign(points.untied_corner(), zero);
    }
    // Every compute() writes every point's work (zero for an inactive one), so
    // it is zeroed only when sized, not by a serial pass every step.
    if (work_increment_.size() != points.size()) work_increment_.assign(points.size(), 0.0);
  }

  // The tied corner forces of a stress point whose cell's shear is left out.
  void clear_tied_corners(std::size_t row) {
    for (std::size_t k = 0; k < std::size_t(shell::max_cell_corners); ++k) {
      tied_force_[row * shell::max_cell_corners + k] = Vector3::Zero();
      tied_director_force_[row * shell::max_cell_corners + k] = Vector3::Zero();
    }
  }

  // What a point of a group keeps between its gather and its update.
  struct GroupMember {
    std::size_t row;
    shell::SurfaceGradients current;
    shell::Strains strains;
    StrainVoigt d_membrane, d_curvature;
    Vector2 d_shear;
  };

  // Integrates the rows [first_row, end_row) of a group of points, a
  // SectionGroup of up to points_per_group active points at a time (across
  // points: the active points of one block of the SectionStates, updated in
  // place): each point's gather and strains, then the group's material update
  // through the thickness (section_group.hpp), then each point's resultants,
  // work, conjugate forces and tied shear. A failing point is kept in
  // `failure` (the lowest row) and leaves the others of its group unaffected.
  template <class Approx, class Rule, class Law>
  void integrate_rows(PointGroup group, std::size_t first_row, std::size_t end_row,
                      const IntegrationPoints<Approx>& points, SectionStates<Rule, Law>& states,
                      assembler_parts::PointFailure& failure) {
    using Group = thickness::SectionGroup<Rule, Law>;
    // The runs start at a chunk's first row, so that a block of the states
    // (section_states.hpp) is never shared by two runs, which two threads
    // may integrate at once.
    static_assert(PointChunks::rows % std::size_t(Group::group_size) == 0,
                  "sphshell::solver: PointChunks::rows must be a multiple of points_per_group");
    Group section_group;
    std::array<GroupMember, std::size_t(Group::group_size)> members;
    for (std::size_t row = first_row; row < end_row;) {
      section_group.clear();
      // Across points the group is one block's points: the rows up to the block's end.
      std::size_t group_end = end_row;
      if constexpr (Group::across_points) {
        const std::size_t p = points.point(group, row);
        group_end = std::min(end_row, row + std::size_t(Group::group_size - states.lane_of(p)));
        section_group.use_block(states.block(p));
      }
      for (; row < group_end && !section_group.full(); ++row) {
        const std::size_t p = points.point(group, row);
        if (!states.active(p)) {
          work_increment_[p] = 0.0;
          continue;
        }
        try {
          GroupMember& member = members[std::size_t(section_group.size())];
          member.row = row;
          member.current = points.gather(group, row, packed_);
          member.strains = strains_of(member.current, points, p);
          member.d_membrane = member.strains.membrane - states.membrane_strain(p);
          member.d_curvature = member.strains.curvature - states.curvature(p);
          member.d_shear = member.strains.shear - states.shear_strain(p);
          if constexpr (Group::across_points)
            section_group.add(states.lane_of(p), states.section(p), member.d_membrane, member.d_curvature);
          else
            section_group.add(states.section(p), states.stored_state(p), member.d_membrane, member.d_curvature);
        } catch (...) {
          failure.keep_lowest(group, row, std::current_exception());
        }
      }
      // A rate-dependent law's sections get the step's context; every other
      // section is called as it always was (a Section of the user's own need
      // not take the context).
      section_group.update(update_context_);
      for (int g = 0; g < section_group.size(); ++g) {
        const GroupMember& member = members[std::size_t(g)];
        if (section_group.failure(g)) {
          failure.keep_lowest(group, member.row, section_group.failure(g));
          continue;
        }
        try {
          finish_point(group, member, section_group.resultants(g), points, states);
        } catch (...) {
          failure.keep_lowest(group, member.row, std::current_exception());
        }
      }
    }
  }

  // A point's bookkeeping after its material update: the new resultants and
  // strains kept, the work over the step, its conjugate forces and tied shear.
  template <class Approx, class Rule, class Law>
  void finish_point(PointGroup group, const GroupMember& member, const thickness::Resultants& resultants,
                    const IntegrationPoints<Approx>& points, SectionStates<Rule, Law>& states) {
    const std::size_t p = points.point(group, member.row);
    // The elastic transverse shear force (weighted: the shear weight holds
    // κs G d A) is updated incrementally like the other resultants, so a
    // change of shape functions (after a crack) leaves it continuous.
    const Vector2 shear_force = states.shear_force(p) + points.shear_weight(p) * member.d_shear;
    const double w = points.membrane_bending_weight(p);
    // Trapezoidal work of the generalized stresses over the strain increment.
    work_increment_[p] = w * (0.5 * (states.membrane_force(p) + resultants.membrane).dot(member.d_membrane) +
                              0.5 * (states.bending_moment(p) + resultants.moment).dot(member.d_curvature)) +
                         0.5 * (states.shear_force(p) + shear_force).dot(member.d_shear);
    states.restart_strains(p, member.strains);
    states.membrane_force(p) = resultants.membrane;
    states.bending_moment(p) = resultants.moment;
    states.shear_force(p) = shear_force;
    // The tied shear reads the corners from this step's packed kinematics
    // (the same numbers as the particle state's).
    const double tied_energy =
        scatter(group, member.row, member.current, points, states,
                [&](int j) -> const Vector3& { return packed_[std::size_t(j)].position; },
                [&](int j) -> const Vector3& { return packed_[std::size_t(j)].director; });
    // The tied shear is elastic and quadratic: its work over the step is
    // exactly the change of its energy.
    work_increment_[p] += tied_energy - states.tied_shear_energy(p);
    states.tied_shear_energy(p) = tied_energy;
  }

  // scatter_point with the particles' positions and directors read through
  // position(j) and director(j).
  template <class Approx, class Rule, class Law, class Position, class Director>
  double scatter(PointGroup group, std::size_t row, const shell::SurfaceGradients& current,
                 const IntegrationPoints<Approx>& points, const SectionStates<Rule, Law>& states,
                 const Position& position, const Director& director) {
    const std::size_t p = points.point(group, row);
    const double w = points.membrane_bending_weight(p);
    const shell::WeightedStresses weighted{w * states.membrane_force(p), w * states.bending_moment(p),
                                           states.shear_force(p)};
    conjugate_[p] = shell::conjugate_forces(nonlinear_ ? current : points.reference(p), weighted);
    return points.shear_tied(group, row) ? tied_shear(row, points, position, director) : 0.0;
  }

  // The forces of a stress point's edge-tied shear (shell/cell_shear.hpp) on
  // its cell's corners, written straight into its kept corner forces; returns
  // its energy. A corner hidden from the point by a crack leaves the cell's
  // shear out (energy 0, zero forces).
  template <class Approx, class Position, class Director>
  double tied_shear(std::size_t row, const IntegrationPoints<Approx>& points, const Position& position,
                    const Director& director) {
    if (!points.tied_corners_visible(row)) {
      clear_tied_corners(row);
      return 0.0;
    }
    const shell::CellShearTie& tying = points.shear_tying(row);
    const std::size_t first = row * shell::max_cell_corners;
    const auto corner_position = [&](int k) -> const Vector3& { return position(tying.particle[std::size_t(k)]); };
    const auto corner_director = [&](int k) -> const Vector3& { return director(tying.particle[std::size_t(k)]); };
    double energy = shell::corner_shear_forces(tying, points.shear_edges(row), corner_position, corner_director,
                                               nonlinear_, &tied_force_[first], &tied_director_force_[first]);
    // The cell's director hourglass (PhysicsOptions::director_hourglass) adds
    // to the same corner forces.
    if (const shell::CellHourglass* hourglass = points.hourglass(row);
        hourglass && tying.corners == shell::hourglass_corners)
      energy += shell::add_hourglass_forces(*hourglass, corner_position, corner_director, nonlinear_,
                                            &tied_force_[first], &tied_director_force_[first]);
    return energy;
  }


  bool nonlinear_;
  material::UpdateContext update_context_{std::numeric_limits<double>::quiet_NaN()};
  std::size_t failed_point_ = 0;
  // Per point: its conjugate forces (zero for a removed point). Per stress
  // point corner (row × max_cell_corners + corner): the tied shear's forces
  // on the corner particle and its director (zero where no tied shear acts).
  std::vector<shell::ConjugateForces> conjugate_;
  std::vector<Vector3> tied_force_, tied_director_force_;
  std::vector<double> work_increment_;
  std::vector<double> work_chunk_sums_;  // per PointChunks chunk, in the last compute()
  double internal_work_ = 0.0;
  std::vector<PackedKinematics> packed_;  // this step's positions and directors
  AssemblySchedule schedule_;
  std::vector<assembler_parts::PointFailure> failures_;  // per segment of the last compute()
  assembler_parts::BandCountdown band_countdown_;
};

}  // namespace sphshell::solver
