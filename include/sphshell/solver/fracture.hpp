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
#include <cstddef>
#include <cstdint>
#include <sstream>
#include <type_traits>
#include <utility>
#include <vector>

namespace sphshell::solver {

// The parts a crack changes, handed to the manager by the solver.
template <class Approx, class Rule, class Law>
struct FractureParts {
  const ShellModel& model;
  const ParticleState& particles;
  IntegrationPoints<Approx>& points;
  SectionStates<Rule, Law>& states;
  InternalForceAssembler& assembler;
  ParticleForces& forces;
};

template <class Crack, bool = Crack::enabled>
class FractureManager {
 public:
  // Nothing to track without cracks.
  template <class Approx>
  void initialize(const ShellModel&, const IntegrationPoints<Approx>&) {}
  template <class Parts>
  void update(const Parts&) {}
  const Crack& crack() const { return crack_; }
  std::size_t damaged_stress_point_count() const { return 0; }
  std::size_t precrack_stress_point_count() const { return 0; }
  double released_energy() const { return 0.0; }
  bool is_fragment(std::size_t) const { return false; }
  std::size_t fragment_count() const { return 0; }
  // Checkpoints: nothing to store.
  template <class Writer>
  void save(Writer&) const {}
  template <class Reader>
  void load(Reader&) {}

 private:
  Crack crack_;
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
// spacing, ShellModel::stress_point_spacing) and the inverse; shared with
// mpi::DistributedFracture, which needs the same maps on every rank.
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

}  // namespace fracture_detail

template <class Crack>
class FractureManager<Crack, true> {
 public:
  template <class Approx>
  void initialize(const ShellModel& model, const IntegrationPoints<Approx>& points) {
    // The crack policy bounds its searches by the largest row support: every
    // row's own support lies within it (rows_near then keeps a fragment's
    // rebuilds to the rows whose own support reaches it).
    crack_.initialize(model.stress_point_position, model.stress_point_normal, model.maximum_spacing(),
                      points.largest_support_radius());
    fragment_.assign(model.particle_count(), 0);
    fracture_detail::StressPointNeighbourhoods maps = fracture_detail::stress_point_neighbourhoods(model);
    particles_of_stress_point_ = std::move(maps.particles_of_stress_point);
    stress_points_of_particle_ = std::move(maps.stress_points_of_particle);
  }

  // Per step: the failed points leave, the new crack segments and fragments
  // cut their neighbourhoods.
  template <class Parts>
  void update(const Parts& parts) {
    const std::vector<char> failed = failed_points(parts);
    std::vector<int> newly_damaged;
    for (std::size_t p = 0; p < parts.model.stress_point_count(); ++p)
      if (failed[p]) newly_damaged.push_back(static_cast<int>(p));
    bool removed_particle_point = false;
    for (std::size_t p = parts.model.stress_point_count(); p < failed.size(); ++p)
      if (failed[p]) {
        deactivate(p, parts);
        removed_particle_point = true;
      }
    if (newly_damaged.empty()) {
      if (removed_particle_point) parts.assembler.sum_particle_forces(parts.points, parts.forces);
      return;
    }
    for (int p : newly_damaged) deactivate(static_cast<std::size_t>(p), parts);
    damaged_stress_points_ += newly_damaged.size();
    const auto segments = crack_.add_damaged_stress_points(newly_damaged);
    std::vector<int> new_fragments;
    for (int p : newly_damaged) take_fragments_around(p, parts, new_fragments);
    rebuild_near(segments, new_fragments, parts);
  }

  // A pre-crack (see Solver::add_precrack): the stress points on it become its
  // crack points and leave the integration.
  template <class Parts>
  void add_precrack(const std::vector<Vector3>& polyline, const Parts& parts) {
    fracture_detail::reject_particles_on(crack_, polyline, parts.model);
    const std::vector<int> absorbed = crack_.add_precrack(polyline);
    std::vector<int> new_fragments;
    for (int p : absorbed) {
      if (parts.states.active(static_cast<std::size_t>(p))) deactivate(static_cast<std::size_t>(p), parts);
      take_fragments_around(p, parts, new_fragments);
    }
    precrack_stress_points_ += absorbed.size();
    rebuild_near(crack_.segments(), new_fragments, parts);
  }

  const Crack& crack() const { return crack_; }
  std::size_t damaged_stress_point_count() const { return damaged_stress_points_; }
  std::size_t precrack_stress_point_count() const { return precrack_stress_points_; }
  // Elastic energy the removed points held when they left (part of the plastic dissipation).
  double released_energy() const { return released_energy_; }
  bool is_fragment(std::size_t particle) const { return fragment_[particle] != 0; }
  std::size_t fragment_count() const {
    return static_cast<std::size_t>(std::count(fragment_.begin(), fragment_.end(), 1));
  }

  // Checkpoints (solver/checkpoint.hpp): the crack policy's topology, the
  // fragments and the counters. The maps between stress points and particles
  // follow from the model.
  template <class Writer>
  void save(Writer& out) const {
    static_assert(fracture_detail::has_checkpoint_members<Crack, Writer>::value,
                  "save_checkpoint: the crack policy cannot be checkpointed; add `template <class Writer> void "
                  "save(Writer&) const` and `template <class Reader> void load(Reader&)` (crack/crack.hpp)");
    crack_.save(out);
    out(fragment_, static_cast<std::uint64_t>(damaged_stress_points_), static_cast<std::uint64_t>(precrack_stress_points_),
        released_energy_);
  }
  template <class Reader>
  void load(Reader& in) {
    crack_.load(in);
    std::uint64_t damaged = 0, precrack = 0;
    in.read_exact(fragment_, "fragment flags");
    in(damaged, precrack, released_energy_);
    damaged_stress_points_ = static_cast<std::size_t>(damaged);
    precrack_stress_points_ = static_cast<std::size_t>(precrack);
  }

 private:
  // Active points whose integral points have all failed, flagged per point.
  template <class Parts>
  std::vector<char> failed_points(const Parts& parts) const {
    std::vector<char> failed(parts.points.size(), 0);
    parallel::for_each(std::size_t{0}, failed.size(), [&](std::size_t p) noexcept {
      failed[p] = parts.states.active(p) && parts.states.all_failed(p);
    });
    return failed;
  }

  // Removes an integration point from the force integration, keeping its
  // stored elastic energy in the books as released.
  template <class Parts>
  void deactivate(std::size_t p, const Parts& parts) {
    released_energy_ += stored_energy(p, parts);
    parts.states.deactivate(p);
    parts.assembler.clear_slots(parts.points.group_of(p), parts.points.row_of(p), parts.points);
  }
  template <class Parts>
  static double stored_energy(std::size_t p, const Parts& parts) {
    return parts.states.stored_energy(p, parts.points.membrane_bending_weight(p), parts.points.shear_weight(p));
  }

  // Particles around a removed stress point that are left with every stress
  // point around them removed become fragments; their own integration points
  // leave too.
  template <class Parts>
  void take_fragments_around(int removed_stress_point, const Parts& parts, std::vector<int>& new_fragments) {
    const std::size_t particle_points = parts.points.count(PointGroup::particles);
    for (int corner : particles_of_stress_point_[removed_stress_point])
      if (!fragment_[corner] && all_removed_around(corner, parts)) {
        fragment_[corner] = 1;
        new_fragments.push_back(corner);
        const std::size_t own_point = parts.points.point(PointGroup::particles, static_cast<std::size_t>(corner));
        if (particle_points > 0 && parts.states.active(own_point)) deactivate(own_point, parts);
      }
  }
  template <class Parts>
  bool all_removed_around(int particle, const Parts& parts) const {
    const std::vector<int>& around = stress_points_of_particle_[particle];
    return !around.empty() && std::all_of(around.begin(), around.end(), [&](int q) {
             return !parts.states.active(static_cast<std::size_t>(q));
           });
  }

  // How a point's rebuild ended.
  enum class Rebuild : char { skipped, rebuilt, cut_loose };

  // Rebuilds the shape functions of every evaluation point within the support
  // of a new crack segment or of a new fragment, hiding the pairs the cracks
  // cut and the fragments. The strain bookkeeping restarts from the new
  // approximation so the change of functions itself creates no strain.
  template <class Segments, class Parts>
  void rebuild_near(const Segments& segments, const std::vector<int>& new_fragments, const Parts& parts) {
    for (PointGroup group : point_groups) {
      if (parts.points.count(group) == 0) continue;
      const std::vector<std::size_t> rows = rows_near(group, segments, new_fragments, parts);
      std::vector<Rebuild> outcome(rows.size(), Rebuild::skipped);
      std::vector<double> dropped(rows.size(), 0.0);  // tied shear energy a hidden cell corner lets go
      parallel::for_each(std::size_t{0}, rows.size(),
                         [&](std::size_t k) { outcome[k] = rebuild_row(group, rows[k], parts, dropped[k]); });
      // Released energies are booked in row order, whatever the thread count.
      for (std::size_t k = 0; k < rows.size(); ++k) {
        released_energy_ += dropped[k];
        if (outcome[k] == Rebuild::cut_loose) {
          const std::size_t p = parts.points.point(group, rows[k]);
          released_energy_ += stored_energy(p, parts);
          parts.states.deactivate(p);
          parts.assembler.clear_slots(group, rows[k], parts.points);
        }
      }
    }
    parts.points.build_slot_transpose(parts.model.particle_count());
    parts.assembler.sum_particle_forces(parts.points, parts.forces);
  }

  template <class Segments, class Parts>
  std::vector<std::size_t> rows_near(PointGroup group, const Segments& segments,
                                     const std::vector<int>& new_fragments, const Parts& parts) const {
    const std::vector<Vector3>& eval = parts.points.positions(parts.model, group);
    std::vector<std::size_t> rows = crack_.affected_points(eval, segments);
    if (!new_fragments.empty()) {
      std::vector<char> near(eval.size(), 0);
      parallel::for_each(std::size_t{0}, eval.size(), [&](std::size_t row) noexcept {
        const double support_radius = parts.points.support_radius(group, row);
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

  template <class Parts>
  Rebuild rebuild_row(PointGroup group, std::size_t row, const Parts& parts, double& dropped_tied_energy) const {
    const std::size_t p = parts.points.point(group, row);
    if (!parts.states.active(p)) return Rebuild::skipped;
    const Vector3& x = parts.points.positions(parts.model, group)[row];
    const TangentFrame& frame = parts.points.frame(group, row);
    auto visible = [&](std::size_t, std::size_t j) {
      return !fragment_[j] && crack_.visible(x, parts.model.particle_position[j], frame);
    };
    try {
      parts.points.rebuild_row(parts.model, group, row, visible);
    } catch (const Error&) {
      return Rebuild::cut_loose;  // nothing visible is left: the point is cut loose
    }
    if (parts.points.shape(group).shepard[row]) return Rebuild::cut_loose;  // no gradient: no strain
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
  std::vector<unsigned char> fragment_;  // per particle: every stress point around it removed
  std::vector<std::vector<int>> particles_of_stress_point_, stress_points_of_particle_;
  std::size_t damaged_stress_points_ = 0;
  std::size_t precrack_stress_points_ = 0;
  double released_energy_ = 0.0;
};

}  // namespace sphshell::solver
