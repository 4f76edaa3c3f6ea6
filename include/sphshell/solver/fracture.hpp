#pragma once
// The fracture manager (docs/method.md, "Damage, fracture and visibility";
// the paper's §2.6): the crack policy, which particles are fragments, the maps
// between stress points and the particles around them, and the counters.
//
// Each step, stress points whose integral points have all failed leave the
// integration and join the crack topology; particle points that failed just
// leave. The shape functions of every point within the support of a new crack
// segment or fragment are rebuilt with the cut pairs hidden. With crack::None
// the manager is empty: points keep integrating whatever their state.
//
// Over several processes (the domain part, domain/domain.hpp) the crack set
// is held whole on every process. Each step every process finds the failed
// points among those it computes (a redundant copy has the same state as its
// owner's, so it fails alike); the newly damaged stress points each owns are
// gathered, so every process adds the serial list (ascending stress point
// index) to its copy of the crack topology, and the segments, the fragments
// and the active flags of all stress points (which the fragment rule reads)
// are the serial ones everywhere. Rebuilds touch only the rows a process
// computes: they run on the whole model's rows (a rebuild orders a row by
// global particle index) and are copied into the local rows, so a rebuilt
// local row is bit for bit the serial one; stress points a rebuild cut loose
// are gathered too. The released energy is counted by the owners of the
// removed points. On one process the whole model's rows are the rows.

#include <sphshell/approx/neighbour_search.hpp>
#include <sphshell/core/error.hpp>
#include <sphshell/core/parallel.hpp>
#include <sphshell/core/types.hpp>
#include <sphshell/shell/model.hpp>
#include <sphshell/solver/integration_points.hpp>
#include <sphshell/solver/internal_forces.hpp>
#include <sphshell/solver/particles.hpp>
#include <sphshell/solver/section_states.hpp>

#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>
#include <sstream>
#include <type_traits>
#include <utility>
#include <vector>

namespace sphshell::solver {

// The parts a crack changes, handed to the manager by the solver.
template <class Approx, class Rule, class Law, class Domain>
struct FractureParts {
  const Domain& domain;
  const ShellModel& model;
  const ParticleState& particles;
  IntegrationPoints<Approx>& all_points;  // the whole model's rows: rebuilds run here (serially: points)
  IntegrationPoints<Approx>& points;      // this process's rows
  SectionStates<Rule, Law>& states;
  InternalForceAssembler& assembler;
  ParticleForces& forces;
  const std::vector<char>& point_owned;  // per local point, distributed; empty serially (all owned)
  bool owned(std::size_t p) const { return point_owned.empty() || point_owned[p] != 0; }
};

template <class Crack, class Domain, bool = Crack::enabled>
class FractureManager {
 public:
  using Sum = typename Domain::EnergySum;
  // Nothing to track without cracks.
  template <class Approx>
  void initialize(const ShellModel&, const IntegrationPoints<Approx>&, const Domain&) {}
  template <class Parts>
  void update(const Parts&) {}
  const Crack& crack() const { return crack_; }
  std::size_t damaged_stress_point_count() const { return 0; }
  std::size_t precrack_stress_point_count() const { return 0; }
  const Sum& released_energy() const { return released_energy_; }
  bool is_fragment(std::size_t) const { return false; }
  std::size_t fragment_count() const { return 0; }
  // Checkpoints: nothing to store.
  template <class Writer>
  void save(Writer&) const {}
  template <class Reader>
  void load(Reader&) {}

 private:
  Crack crack_;
  Sum released_energy_{};
};

namespace fracture_detail {
template <class Policy, class Writer, class = void>
struct has_checkpoint_members : std::false_type {};
template <class Policy, class Writer>
struct has_checkpoint_members<Policy, Writer,
                              std::void_t<decltype(std::declval<const Policy&>().save(std::declval<Writer&>()))>>
    : std::true_type {};

// The particles around each stress point (the corners of its cell, quad or
// triangle, or, for a model without cells, the particles within its own
// spacing, ShellModel::stress_point_spacing) and the inverse, the same on
// every process.
struct StressPointNeighbourhoods {
  std::vector<std::vector<int>> particles_of_stress_point, stress_points_of_particle;
};
inline StressPointNeighbourhoods stress_point_neighbourhoods(const ShellModel& model) {
  StressPointNeighbourhoods maps;
  maps.particles_of_stress_point.assign(model.stress_point_count(), {});
  if (!model.cells().empty()) {
    for (std::size_t q = 0; q < model.cells().size(); ++q)
      maps.particles_of_stress_point[q].assign(model.cells()[q].begin(), model.cells()[q].end());
  } else {
    const std::vector<double>& reach = local_spacing(model).stress_point;
    const approx::CellList cells(model.particle_position, sphshell::detail::model_checks::median(reach));
    for (std::size_t q = 0; q < model.stress_point_count(); ++q)
      cells.for_each_within(model.stress_point_position[q], reach[q],
                            [&](int i, double) { maps.particles_of_stress_point[q].push_back(i); });
  }
  maps.stress_points_of_particle.assign(model.particle_count(), {});
  for (std::size_t q = 0; q < maps.particles_of_stress_point.size(); ++q)
    for (int i : maps.particles_of_stress_point[q]) maps.stress_points_of_particle[i].push_back(static_cast<int>(q));
  return maps;
}

// A particle on a crack line would see both faces and tie them together: an
// Error naming it (a pre-crack, serial or distributed).
template <class Crack>
void reject_particles_on(const Crack& crack, const std::vector<Vector3>& polyline, const ShellModel& model) {
  const double tolerance = Crack::on_precrack_in_spacings * crack.spacing();
  for (std::size_t k = 0; k + 1 < polyline.size(); ++k)
    for (std::size_t i = 0; i < model.particle_count(); ++i)
      if (Crack::distance_to_precrack_piece(model.particle_position[i], polyline[k], polyline[k + 1]) <= tolerance) {
        std::ostringstream message;
        message << "sphshell: the pre-crack passes through particle " << i << " at ("
                << model.particle_position[i].transpose()
                << "); a particle on a crack would tie its faces together: move the pre-crack off the particles "
                   "(along a row of stress points, or a fraction of the spacing aside)";
        throw Error(message.str());
      }
}

// Released energy: a plain sum on one process (in the serial order), an
// exact one over several (core/exact_sum.hpp: the same for any process count).
inline void book(double& sum, double energy) { sum += energy; }
template <class Sum>
void book(Sum& sum, double energy) {
  sum.add(energy);
}
}  // namespace fracture_detail

template <class Crack, class Domain>
class FractureManager<Crack, Domain, true> {
  static constexpr bool distributed = Domain::is_distributed;

 public:
  using Sum = typename Domain::EnergySum;

  template <class Approx>
  void initialize(const ShellModel& model, const IntegrationPoints<Approx>& all_points, const Domain& domain) {
    // The crack policy bounds its searches by the largest row support: every
    // row's own support lies within it (rows_near then keeps a fragment's
    // rebuilds to the rows whose own support reaches it).
    crack_.initialize(model.stress_point_position, model.stress_point_normal, model.maximum_spacing(),
                      all_points.largest_support_radius());
    fragment_.assign(model.particle_count(), 0);
    stress_point_active_.assign(model.stress_point_count(), 1);
    fracture_detail::StressPointNeighbourhoods maps = fracture_detail::stress_point_neighbourhoods(model);
    particles_of_stress_point_ = std::move(maps.particles_of_stress_point);
    stress_points_of_particle_ = std::move(maps.stress_points_of_particle);
    // The local rows of each group: their evaluation points and the local row of each global row.
    for (PointGroup group : point_groups) {
      const std::size_t g = index_of(group);
      const std::vector<Vector3>& eval = all_points.positions(model, group);
      local_eval_[g].clear();
      local_row_of_[g].assign(all_points.count(group), -1);
      for (std::size_t k = 0; k < domain.local_row_count(g); ++k) {
        const std::size_t row = domain.global_row(g, k);
        local_eval_[g].push_back(eval[row]);
        local_row_of_[g][row] = static_cast<long>(k);
      }
    }
  }

  // Per step (collective): the failed points leave, the new crack segments
  // and fragments cut the rows near them.
  template <class Parts>
  void update(const Parts& parts) {
    const std::size_t local_stress_points = parts.points.count(PointGroup::stress_points);
    std::vector<char> failed(parts.points.size(), 0);
    parallel::for_each(std::size_t{0}, failed.size(), [&](std::size_t p) noexcept {
      failed[p] = parts.states.active(p) && parts.states.all_failed(p);
    });
    std::vector<std::int64_t> mine;
    for (std::size_t k = 0; k < local_stress_points; ++k)
      if (failed[k] && parts.owned(k)) mine.push_back(static_cast<std::int64_t>(parts.domain.global_row(0, k)));
    std::vector<std::int64_t> gathered = parts.domain.gathered_ids(mine);
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

  // A pre-crack (see Solver::add_precrack), on every process alike: the
  // stress points on it become its crack points and leave the integration.
  template <class Parts>
  void add_precrack(const std::vector<Vector3>& polyline, const Parts& parts) {
    fracture_detail::reject_particles_on(crack_, polyline, parts.model);
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
  // Elastic energy the removed points held when they left (part of the
  // plastic dissipation); distributed, this process's owned points' share.
  const Sum& released_energy() const { return released_energy_; }
  bool is_fragment(std::size_t particle) const { return fragment_[particle] != 0; }
  std::size_t fragment_count() const {
    return static_cast<std::size_t>(std::count(fragment_.begin(), fragment_.end(), 1));
  }

  // Checkpoints (solver/checkpoint.hpp): the crack policy's topology, the
  // fragments, the counters and the released energy (distributed: the
  // stress points' active flags too, and the exact sum). The maps between
  // stress points and particles follow from the model.
  template <class Writer>
  void save(Writer& out) const {
    static_assert(fracture_detail::has_checkpoint_members<Crack, Writer>::value,
                  "save_checkpoint: the crack policy cannot be checkpointed; add `template <class Writer> void "
                  "save(Writer&) const` and `template <class Reader> void load(Reader&)` (crack/crack.hpp)");
    crack_.save(out);
    const auto damaged = static_cast<std::uint64_t>(damaged_stress_points_);
    const auto precrack = static_cast<std::uint64_t>(precrack_stress_points_);
    if constexpr (distributed)
      out(fragment_, stress_point_active_, damaged, precrack, released_energy_.raw());
    else
      out(fragment_, damaged, precrack, released_energy_);
  }
  template <class Reader>
  void load(Reader& in) {
    crack_.load(in);
    std::uint64_t damaged = 0, precrack = 0;
    in.read_exact(fragment_, "fragment flags");
    if constexpr (distributed) {
      in.read_exact(stress_point_active_, "stress point flags");
      typename Sum::Raw released{};
      in(damaged, precrack, released);
      released_energy_ = Sum::from_raw(released);
    } else {
      in(damaged, precrack, released_energy_);
    }
    damaged_stress_points_ = static_cast<std::size_t>(damaged);
    precrack_stress_points_ = static_cast<std::size_t>(precrack);
  }

 private:
  enum class Rebuild : char { skipped, rebuilt, cut_loose };

  // Removes an integration point from the force integration, keeping its
  // stored elastic energy in the books as released (by its owner).
  template <class Parts>
  void deactivate(std::size_t p, const Parts& parts) {
    if (parts.owned(p)) fracture_detail::book(released_energy_, stored_energy(p, parts));
    parts.states.deactivate(p);
    parts.assembler.clear_slots(parts.points.group_of(p), parts.points.row_of(p), parts.points);
  }
  template <class Parts>
  static double stored_energy(std::size_t p, const Parts& parts) {
    return parts.states.stored_energy(p, parts.points.membrane_bending_weight(p), parts.points.shear_weight(p));
  }
  // The local copy of a global row's point, or −1.
  template <class Parts>
  long local_point_of(PointGroup group, std::size_t global_row, const Parts& parts) const {
    const long k = local_row_of_[index_of(group)][global_row];
    return k < 0 ? -1 : static_cast<long>(parts.points.point(group, static_cast<std::size_t>(k)));
  }
  // A stress point leaves everywhere: its flag, and the local copy.
  template <class Parts>
  void remove_stress_point(int q, const Parts& parts) {
    stress_point_active_[static_cast<std::size_t>(q)] = 0;
    const long p = local_point_of(PointGroup::stress_points, static_cast<std::size_t>(q), parts);
    if (p >= 0 && parts.states.active(static_cast<std::size_t>(p))) deactivate(static_cast<std::size_t>(p), parts);
  }

  // Particles around a removed stress point that are left with every stress
  // point around them removed become fragments; their own integration points
  // leave too.
  template <class Parts>
  void take_fragments_around(int removed_stress_point, const Parts& parts, std::vector<int>& new_fragments) {
    for (int corner : particles_of_stress_point_[removed_stress_point])
      if (!fragment_[corner] && all_removed_around(corner, parts)) {
        fragment_[corner] = 1;
        new_fragments.push_back(corner);
        if (parts.all_points.count(PointGroup::particles) == 0) continue;
        const long own = local_point_of(PointGroup::particles, static_cast<std::size_t>(corner), parts);
        if (own >= 0 && parts.states.active(static_cast<std::size_t>(own)))
          deactivate(static_cast<std::size_t>(own), parts);
      }
  }
  // One process reads its states (every stress point is its own), several
  // the replicated flags (a checkpoint of one process keeps no flags).
  template <class Parts>
  bool all_removed_around(int particle, const Parts& parts) const {
    const std::vector<int>& around = stress_points_of_particle_[particle];
    return !around.empty() && std::all_of(around.begin(), around.end(), [&](int q) {
             if constexpr (distributed) return stress_point_active_[static_cast<std::size_t>(q)] == 0;
             else return !parts.states.active(static_cast<std::size_t>(q));
           });
  }

  // Rebuilds the shape functions of every local row within the support of a
  // new crack segment or of a new fragment, hiding the pairs the cracks cut
  // and the fragments. The strain bookkeeping restarts from the new
  // approximation so the change of functions itself creates no strain. Then
  // the stress points cut loose anywhere are gathered into the flags.
  template <class Segments, class Parts>
  void rebuild_near(const Segments& segments, const std::vector<int>& new_fragments, const Parts& parts) {
    std::vector<std::int64_t> cut_loose_here;
    for (PointGroup group : point_groups) {
      if (parts.points.count(group) == 0) continue;
      const std::vector<std::size_t> rows = rows_near(group, segments, new_fragments, parts);
      std::vector<Rebuild> outcome(rows.size(), Rebuild::skipped);
      std::vector<double> dropped(rows.size(), 0.0);  // tied shear energy a hidden cell corner lets go
      parallel::for_each(std::size_t{0}, rows.size(),
                         [&](std::size_t k) { outcome[k] = rebuild_row(group, rows[k], parts, dropped[k]); });
      // Released energies are booked in row order, whatever the thread count.
      for (std::size_t k = 0; k < rows.size(); ++k) {
        const std::size_t p = parts.points.point(group, rows[k]);
        if (parts.owned(p)) fracture_detail::book(released_energy_, dropped[k]);
        if (outcome[k] == Rebuild::cut_loose) {
          if (parts.owned(p)) {
            fracture_detail::book(released_energy_, stored_energy(p, parts));
            if (group == PointGroup::stress_points)
              cut_loose_here.push_back(static_cast<std::int64_t>(parts.domain.global_row(0, rows[k])));
          }
          parts.states.deactivate(p);
          parts.assembler.clear_slots(group, rows[k], parts.points);
        }
      }
    }
    parts.points.build_slot_transpose(parts.domain.local_count());
    parts.assembler.sum_particle_forces(parts.points, parts.forces);
    for (std::int64_t q : parts.domain.gathered_ids(cut_loose_here)) stress_point_active_[static_cast<std::size_t>(q)] = 0;
  }

  // Local rows within the support of a new segment or of a new fragment.
  template <class Segments, class Parts>
  std::vector<std::size_t> rows_near(PointGroup group, const Segments& segments,
                                     const std::vector<int>& new_fragments, const Parts& parts) const {
    const std::vector<Vector3>& eval = local_eval_[index_of(group)];
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

  // One local row: rebuilt on the whole model's row (distributed: then
  // copied here), then its strains and tied shear restart.
  template <class Parts>
  Rebuild rebuild_row(PointGroup group, std::size_t row, const Parts& parts, double& dropped_tied_energy) const {
    const std::size_t p = parts.points.point(group, row);
    if (!parts.states.active(p)) return Rebuild::skipped;
    const std::size_t global_row = parts.domain.global_row(index_of(group), row);
    const Vector3& x = parts.all_points.positions(parts.model, group)[global_row];
    const TangentFrame& frame = parts.all_points.frame(group, global_row);
    auto visible = [&](std::size_t, std::size_t j) {
      return !fragment_[j] && crack_.visible(x, parts.model.particle_position[j], frame);
    };
    bool nothing_visible = false;
    try {
      parts.all_points.rebuild_row(parts.model, group, global_row, visible);
    } catch (const Error&) {
      nothing_visible = true;  // nothing visible is left: the point is cut loose (the row changed all the same)
    }
    if constexpr (distributed)
      parts.points.copy_row(group, row, parts.all_points, global_row, parts.domain.layout().local_of);
    if (nothing_visible || parts.points.shape(group).shepard[row]) return Rebuild::cut_loose;  // no gradient: no strain
    const shell::SurfaceGradients current =
        parts.points.gather(group, row, parts.particles.position, parts.particles.director);
    parts.states.restart_strains(p, parts.assembler.strains_of(current, parts.points, p));
    parts.assembler.clear_slots(group, row, parts.points);
    // The edge-tied shear does not depend on the shape functions; it lets its
    // energy go only when a corner of the cell is hidden (docs/method.md §6).
    const double tied_energy =
        parts.assembler.scatter_point(group, row, current, parts.particles, parts.points, parts.states);
    dropped_tied_energy = parts.states.tied_shear_energy(p) - tied_energy;
    parts.states.tied_shear_energy(p) = tied_energy;
    return Rebuild::rebuilt;
  }

  Crack crack_;
  std::vector<unsigned char> fragment_;             // per particle: every stress point around it removed
  std::vector<unsigned char> stress_point_active_;  // per stress point, whole (distributed: read by the fragment rule)
  std::vector<std::vector<int>> particles_of_stress_point_, stress_points_of_particle_;
  std::array<std::vector<Vector3>, 2> local_eval_;  // per group: evaluation points of the local rows
  std::array<std::vector<long>, 2> local_row_of_;   // per group: global row → local row, or −1
  std::size_t damaged_stress_points_ = 0;
  std::size_t precrack_stress_points_ = 0;
  Sum released_energy_{};
};

}  // namespace sphshell::solver
