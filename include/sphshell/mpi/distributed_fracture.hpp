#pragma once
// Fracture across rank boundaries (docs/distributed.md, "Fracture"): the
// serial FractureManager's rules (solver/fracture.hpp) with the crack set
// held whole on every rank.
//
// Each step every rank finds the failed points among those it computes (a
// redundant copy has the same state as its owner's, so it fails alike). The
// newly damaged stress points each rank owns are gathered: every rank gets
// the serial list (ascending stress point index) and adds it to its own copy
// of the crack topology, so the segments, the fragments and the active flags
// of all stress points (which the fragment rule reads) are the serial ones on
// every rank. Visibility rebuilds touch only the rows a rank computes: they
// run on the whole model's rows (a rebuild orders a row by global particle
// index) and are copied into the local rows, so a rebuilt local row is bit
// for bit the serial one. Points a rebuild cut loose are gathered too, after
// the rebuilds, so the replicated active flags stay whole.
//
// The released energy is counted by the owners of the removed points, in an
// exact accumulator (mpi/exact_sum.hpp), reduced with the other books.

#include <sphshell/core/error.hpp>
#include <sphshell/core/parallel.hpp>
#include <sphshell/core/types.hpp>
#include <sphshell/mpi/communicator.hpp>
#include <sphshell/mpi/exact_sum.hpp>
#include <sphshell/mpi/layout.hpp>
#include <sphshell/shell/model.hpp>
#include <sphshell/solver/integration_points.hpp>
#include <sphshell/solver/fracture.hpp>
#include <sphshell/solver/internal_forces.hpp>
#include <sphshell/solver/particles.hpp>
#include <sphshell/solver/section_states.hpp>

#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>
#include <utility>
#include <vector>

namespace sphshell::mpi {

// What a crack changes on one rank, handed over by the distributed solver.
template <class Approx, class Rule, class Law>
struct DistributedFractureParts {
  const Communicator& comm;
  const ShellModel& model;
  const RankLayout& layout;
  const solver::ParticleState& particles;
  solver::IntegrationPoints<Approx>& all_points;  // the whole model's rows: rebuilds run here
  solver::IntegrationPoints<Approx>& points;      // this rank's rows
  solver::SectionStates<Rule, Law>& states;
  solver::InternalForceAssembler& assembler;
  solver::ParticleForces& forces;
  const std::vector<char>& point_owned;  // per local point
};

// Without cracks there is nothing to track (crack::None).
template <class Crack, bool = Crack::enabled>
class DistributedFracture {
 public:
  template <class Approx>
  void initialize(const ShellModel&, const solver::IntegrationPoints<Approx>&, const RankLayout&) {}
  template <class Parts>
  void update(const Parts&) {}
  const Crack& crack() const { return crack_; }
  std::size_t damaged_stress_point_count() const { return 0; }
  std::size_t precrack_stress_point_count() const { return 0; }
  const ExactSum& released_energy() const { return released_energy_; }
  bool is_fragment(std::size_t) const { return false; }
  std::size_t fragment_count() const { return 0; }
  template <class Writer>
  void save(Writer&) const {}
  template <class Reader>
  void load(Reader&) {}

 private:
  Crack crack_;
  ExactSum released_energy_;
};

template <class Crack>
class DistributedFracture<Crack, true> {
 public:
  template <class Approx>
  void initialize(const ShellModel& model, const solver::IntegrationPoints<Approx>& all_points,
                  const RankLayout& layout) {
    // As the serial manager: searches bounded by the largest row support.
    crack_.initialize(model.stress_point_position, model.stress_point_normal, model.maximum_spacing(),
                      all_points.largest_support_radius());
    fragment_.assign(model.particle_count(), 0);
    stress_point_active_.assign(model.stress_point_count(), 1);
    // The particles around each stress point, as the serial manager finds them.
    solver::fracture_detail::StressPointNeighbourhoods maps =
        solver::fracture_detail::stress_point_neighbourhoods(model);
    particles_of_stress_point_ = std::move(maps.particles_of_stress_point);
    stress_points_of_particle_ = std::move(maps.stress_points_of_particle);
    // The local rows of each group: their evaluation points and the local
    // point of each global row.
    for (solver::PointGroup group : solver::point_groups) {
      const std::size_t g = solver::index_of(group);
      const std::vector<Vector3>& eval = all_points.positions(model, group);
      local_eval_[g].clear();
      local_row_of_[g].assign(all_points.count(group), -1);
      for (std::size_t k = 0; k < layout.computed[g].size(); ++k) {
        local_eval_[g].push_back(eval[layout.computed[g][k]]);
        local_row_of_[g][layout.computed[g][k]] = static_cast<long>(k);
      }
    }
  }

  // Per step, collective: failed points leave, the new crack segments and
  // fragments cut the local rows near them.
  template <class Parts>
  void update(const Parts& parts) {
    const std::size_t local_stress_points = parts.points.count(solver::PointGroup::stress_points);
    std::vector<char> failed(parts.points.size(), 0);
    parallel::for_each(std::size_t{0}, failed.size(), [&](std::size_t p) noexcept {
      failed[p] = parts.states.active(p) && parts.states.all_failed(p);
    });
    std::vector<std::int64_t> mine;
    for (std::size_t k = 0; k < local_stress_points; ++k)
      if (failed[k] && parts.point_owned[k]) mine.push_back(static_cast<std::int64_t>(parts.layout.computed[0][k]));
    std::vector<std::int64_t> gathered = parts.comm.all_gather_v(mine);
    std::sort(gathered.begin(), gathered.end());
    const std::vector<int> newly_damaged(gathered.begin(), gathered.end());
    bool removed_particle_point = false;
    for (std::size_t p = local_stress_points; p < failed.size(); ++p)
      if (failed[p]) {
        deactivate(p, parts);
        removed_particle_point = true;
      }
    if (newly_damaged.empty()) {
      if (removed_particle_point) parts.assembler.sum_particle_forces(parts.points, parts.forces);
      return;
    }
    for (int q : newly_damaged) remove_stress_point(q, parts);
    damaged_stress_points_ += newly_damaged.size();
    const auto segments = crack_.add_damaged_stress_points(newly_damaged);
    std::vector<int> new_fragments;
    for (int q : newly_damaged) take_fragments_around(q, parts, new_fragments);
    rebuild_near(segments, new_fragments, parts);
  }

  // A pre-crack (Solver::add_precrack), on every rank alike. Collective.
  template <class Parts>
  void add_precrack(const std::vector<Vector3>& polyline, const Parts& parts) {
    solver::fracture_detail::reject_particles_on(crack_, polyline, parts.model);
    const std::vector<int> absorbed = crack_.add_precrack(polyline);
    std::vector<int> new_fragments;
    for (int q : absorbed) {
      remove_stress_point(q, parts);
      take_fragments_around(q, parts, new_fragments);
    }
    precrack_stress_points_ += absorbed.size();
    rebuild_near(crack_.segments(), new_fragments, parts);
  }

  const Crack& crack() const { return crack_; }
  std::size_t damaged_stress_point_count() const { return damaged_stress_points_; }
  std::size_t precrack_stress_point_count() const { return precrack_stress_points_; }
  // This rank's share of the released energy (the owners' points), exact.
  const ExactSum& released_energy() const { return released_energy_; }
  bool is_fragment(std::size_t particle) const { return fragment_[particle] != 0; }
  std::size_t fragment_count() const {
    return static_cast<std::size_t>(std::count(fragment_.begin(), fragment_.end(), 1));
  }
  // Whether a stress point still integrates (on any rank).
  bool stress_point_active(std::size_t q) const { return stress_point_active_[q] != 0; }

  // Checkpoints (DistributedSolver::save_checkpoint): the crack set and the
  // flags, the same on every rank, and this rank's released energy.
  template <class Writer>
  void save(Writer& out) const {
    crack_.save(out);
    out(fragment_, stress_point_active_, static_cast<std::uint64_t>(damaged_stress_points_),
        static_cast<std::uint64_t>(precrack_stress_points_), released_energy_.raw());
  }
  template <class Reader>
  void load(Reader& in) {
    crack_.load(in);
    in.read_exact(fragment_, "fragment flags");
    in.read_exact(stress_point_active_, "stress point flags");
    std::uint64_t damaged = 0, precrack = 0;
    ExactSum::Raw released{};
    in(damaged, precrack, released);
    damaged_stress_points_ = static_cast<std::size_t>(damaged);
    precrack_stress_points_ = static_cast<std::size_t>(precrack);
    released_energy_ = ExactSum::from_raw(released);
  }

 private:
  enum class Rebuild : char { skipped, rebuilt, cut_loose };

  template <class Parts>
  void deactivate(std::size_t p, const Parts& parts) {
    if (parts.point_owned[p]) released_energy_.add(stored_energy(p, parts));
    parts.states.deactivate(p);
    parts.assembler.clear_slots(parts.points.group_of(p), parts.points.row_of(p), parts.points);
  }
  template <class Parts>
  static double stored_energy(std::size_t p, const Parts& parts) {
    return parts.states.stored_energy(p, parts.points.membrane_bending_weight(p), parts.points.shear_weight(p));
  }
  // The local copy of a global point, or −1.
  template <class Parts>
  long local_point_of(solver::PointGroup group, std::size_t global_row, const Parts& parts) const {
    const long k = local_row_of_[solver::index_of(group)][global_row];
    return k < 0 ? -1 : static_cast<long>(parts.points.point(group, static_cast<std::size_t>(k)));
  }

  // A stress point leaves everywhere: the replicated flag, and the local copy.
  template <class Parts>
  void remove_stress_point(int q, const Parts& parts) {
    stress_point_active_[q] = 0;
    const long p = local_point_of(solver::PointGroup::stress_points, static_cast<std::size_t>(q), parts);
    if (p >= 0 && parts.states.active(static_cast<std::size_t>(p))) deactivate(static_cast<std::size_t>(p), parts);
  }

  template <class Parts>
  void take_fragments_around(int removed_stress_point, const Parts& parts, std::vector<int>& new_fragments) {
    for (int corner : particles_of_stress_point_[removed_stress_point])
      if (!fragment_[corner] && all_removed_around(corner)) {
        fragment_[corner] = 1;
        new_fragments.push_back(corner);
        if (parts.all_points.count(solver::PointGroup::particles) == 0) continue;
        const long own = local_point_of(solver::PointGroup::particles, static_cast<std::size_t>(corner), parts);
        if (own >= 0 && parts.states.active(static_cast<std::size_t>(own)))
          deactivate(static_cast<std::size_t>(own), parts);
      }
  }
  bool all_removed_around(int particle) const {
    const std::vector<int>& around = stress_points_of_particle_[particle];
    return !around.empty() &&
           std::all_of(around.begin(), around.end(), [&](int q) { return stress_point_active_[q] == 0; });
  }

  // The serial rebuild_near on this rank's rows; then the stress points cut
  // loose anywhere are gathered into the replicated flags.
  template <class Segments, class Parts>
  void rebuild_near(const Segments& segments, const std::vector<int>& new_fragments, const Parts& parts) {
    std::vector<std::int64_t> cut_loose_here;
    for (solver::PointGroup group : solver::point_groups) {
      if (parts.points.count(group) == 0) continue;
      const std::vector<std::size_t> rows = rows_near(group, segments, new_fragments, parts);
      std::vector<Rebuild> outcome(rows.size(), Rebuild::skipped);
      std::vector<double> dropped(rows.size(), 0.0);
      parallel::for_each(std::size_t{0}, rows.size(),
                         [&](std::size_t k) { outcome[k] = rebuild_row(group, rows[k], parts, dropped[k]); });
      for (std::size_t k = 0; k < rows.size(); ++k) {
        const std::size_t p = parts.points.point(group, rows[k]);
        if (parts.point_owned[p]) released_energy_.add(dropped[k]);
        if (outcome[k] == Rebuild::cut_loose) {
          if (parts.point_owned[p]) {
            released_energy_.add(stored_energy(p, parts));
            if (group == solver::PointGroup::stress_points)
              cut_loose_here.push_back(static_cast<std::int64_t>(parts.layout.computed[0][rows[k]]));
          }
          parts.states.deactivate(p);
          parts.assembler.clear_slots(group, rows[k], parts.points);
        }
      }
    }
    parts.points.build_slot_transpose(parts.layout.local_count());
    parts.assembler.sum_particle_forces(parts.points, parts.forces);
    for (std::int64_t q : parts.comm.all_gather_v(cut_loose_here)) stress_point_active_[static_cast<std::size_t>(q)] = 0;
  }

  // Local rows within the support of a new segment or of a new fragment.
  template <class Segments, class Parts>
  std::vector<std::size_t> rows_near(solver::PointGroup group, const Segments& segments,
                                     const std::vector<int>& new_fragments, const Parts& parts) const {
    const std::vector<Vector3>& eval = local_eval_[solver::index_of(group)];
    std::vector<std::size_t> rows = crack_.affected_points(eval, segments);
    if (!new_fragments.empty()) {
      std::vector<char> near(eval.size(), 0);
      parallel::for_each(std::size_t{0}, eval.size(), [&](std::size_t row) noexcept {
        const double support_radius = parts.points.support_radius(group, row);  // the local row's own
        for (int particle : new_fragments)
          if ((eval[row] - parts.model.particle_position[particle]).norm() < support_radius) near[row] = 1;
      });
      for (std::size_t row = 0; row < eval.size(); ++row)
        if (near[row]) rows.push_back(row);
    }
    std::sort(rows.begin(), rows.end());
    rows.erase(std::unique(rows.begin(), rows.end()), rows.end());
    return rows;
  }

  // One local row: rebuilt on the whole model's row, copied here, then the
  // serial restart of its strains and tied shear.
  template <class Parts>
  Rebuild rebuild_row(solver::PointGroup group, std::size_t row, const Parts& parts, double& dropped_tied_energy) const {
    const std::size_t p = parts.points.point(group, row);
    if (!parts.states.active(p)) return Rebuild::skipped;
    const std::size_t global_row = parts.layout.computed[solver::index_of(group)][row];
    const Vector3& x = parts.all_points.positions(parts.model, group)[global_row];
    const TangentFrame& frame = parts.all_points.frame(group, global_row);
    auto visible = [&](std::size_t, std::size_t j) {
      return !fragment_[j] && crack_.visible(x, parts.model.particle_position[j], frame);
    };
    bool nothing_visible = false;
    try {
      parts.all_points.rebuild_row(parts.model, group, global_row, visible);
    } catch (const Error&) {
      nothing_visible = true;  // the row changed all the same
    }
    parts.points.copy_row(group, row, parts.all_points, global_row, parts.layout.local_of);
    if (nothing_visible || parts.points.shape(group).shepard[row]) return Rebuild::cut_loose;
    const shell::SurfaceGradients current =
        parts.points.gather(group, row, parts.particles.position, parts.particles.director);
    parts.states.restart_strains(p, parts.assembler.strains_of(current, parts.points, p));
    parts.assembler.clear_slots(group, row, parts.points);
    const double tied_energy =
        parts.assembler.scatter_point(group, row, current, parts.particles, parts.points, parts.states);
    dropped_tied_energy = parts.states.tied_shear_energy(p) - tied_energy;
    parts.states.tied_shear_energy(p) = tied_energy;
    return Rebuild::rebuilt;
  }

  Crack crack_;
  std::vector<unsigned char> fragment_;             // per particle (global)
  std::vector<unsigned char> stress_point_active_;  // per stress point (global)
  std::vector<std::vector<int>> particles_of_stress_point_, stress_points_of_particle_;
  std::array<std::vector<Vector3>, 2> local_eval_;  // per group: evaluation points of the local rows
  std::array<std::vector<long>, 2> local_row_of_;   // per group: global row → local row, or −1
  std::size_t damaged_stress_points_ = 0;
  std::size_t precrack_stress_points_ = 0;
  ExactSum released_energy_;
};

}  // namespace sphshell::mpi
