#pragma once
// The internal-force assembler: the one hot loop of a step. For every active
// integration point: gather a1, a2, n, n1, n2 from its neighbours → strains
// (Green or linear, shell/kinematics.hpp) → material update through the
// thickness (Section) → resultants → the point's five conjugate forces (and
// the corner forces of its edge-tied shear) kept per point; then each particle
// sums, over the shape-function slots that refer to it and in a fixed order
// (IntegrationPoints::force_entries), the slot's share of its point's forces
// (the deterministic sum: no atomics, identical results for any thread
// count). The per-slot forces are formed where they are added, so no array of
// them is written and read back. The work of each point over the step is kept
// for the energy ledger.

#include <sphshell/core/error.hpp>
#include <sphshell/core/parallel.hpp>
#include <sphshell/core/types.hpp>
#include <sphshell/shell/cell_shear.hpp>
#include <sphshell/shell/kinematics.hpp>
#include <sphshell/solver/integration_points.hpp>
#include <sphshell/solver/particles.hpp>
#include <sphshell/solver/section_states.hpp>

#include <algorithm>
#include <array>
#include <cstddef>
#include <string>
#include <vector>

namespace sphshell::solver {

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
    prepare(points);
    packed_.resize(particles.size());
    parallel::for_each(std::size_t{0}, particles.size(), [&](std::size_t i) noexcept {
      packed_[i] = PackedKinematics{particles.position[i], particles.director[i]};
    });
    for (PointGroup group : point_groups)
      parallel::for_each(
          std::size_t{0}, points.count(group),
          [&](std::size_t row) { integrate_point(group, row, points, states); },
          [&](std::size_t row, const std::exception_ptr& error) {
            failed_point_ = points.point(group, row);
            detail::fail_unstable(at, std::string(name_of(group)) + " " +
                                          std::to_string(points.global_row(group, row)) + ": " +
                                          parallel::what(error));
          });
    sum_particle_forces(points, forces);
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
  template <class Approx>
  void sum_particle_forces(const IntegrationPoints<Approx>& points, ParticleForces& forces) const {
    const std::vector<std::size_t>& begin = points.particle_slot_begin();
    const auto* const entries = points.force_entries().data();
    const shell::ConjugateForces* const conjugate = conjugate_.data();
    const Vector3 *const tied_force = tied_force_.data(), *const tied_director_force = tied_director_force_.data();
    const std::size_t untied = points.untied_corner();
    // Each group's Φ, ∂Φ/∂X1, ∂Φ/∂X2, picked by whether the entry's point is a
    // particle point (those follow the stress points).
    const approx::ShapeValue* const value_of[2] = {points.shape(PointGroup::stress_points).value.data(),
                                                   points.shape(PointGroup::particles).value.data()};
    const std::size_t first_particle_point = points.point(PointGroup::particles, 0);
    parallel::for_each(std::size_t{0}, forces.internal.size(), [&](std::size_t i) noexcept {
      Vector3 force = Vector3::Zero(), director_force = Vector3::Zero();
      for (std::size_t k = begin[i]; k < begin[i + 1]; ++k) {
        const auto& entry = entries[k];
        const shell::ConjugateForces& f = conjugate[entry.point];
        const std::size_t g = entry.point >= first_particle_point ? 1 : 0;
        const approx::ShapeValue& value = value_of[g][entry.slot];
        const double phi = value.phi, dphi_d1 = value.dphi_d1, dphi_d2 = value.dphi_d2;
        Vector3 slot_force = dphi_d1 * f.a1 + dphi_d2 * f.a2;
        Vector3 slot_director_force = phi * f.n + dphi_d1 * f.n1 + dphi_d2 * f.n2;
        if (entry.tied_corner != untied) {
          slot_force += tied_force[entry.tied_corner];
          slot_director_force += tied_director_force[entry.tied_corner];
        }
        force += slot_force;
        director_force += slot_director_force;
      }
      forces.internal[i] = force;
      forces.internal_director[i] = director_force;
    });
  }

  // The point whose failure stopped the last compute() (the lowest failing
  // index of its group).
  std::size_t failed_point() const { return failed_point_; }

  // Work of the generalized stresses over the last update, per point (zero
  // for inactive points), for the energy ledger.
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
    work_increment_.assign(points.size(), 0.0);
  }

  // The tied corner forces of a stress point whose cell's shear is left out.
  void clear_tied_corners(std::size_t row) {
    for (std::size_t k = 0; k < std::size_t(shell::max_cell_corners); ++k) {
      tied_force_[row * shell::max_cell_corners + k] = Vector3::Zero();
      tied_director_force_[row * shell::max_cell_corners + k] = Vector3::Zero();
    }
  }

  template <class Approx, class Rule, class Law>
  void integrate_point(PointGroup group, std::size_t row, const IntegrationPoints<Approx>& points,
                       SectionStates<Rule, Law>& states) {
    const std::size_t p = points.point(group, row);
    if (!states.active(p)) return;
    const shell::SurfaceGradients current = points.gather(group, row, packed_);
    const shell::Strains strains = strains_of(current, points, p);
    const StrainVoigt d_membrane = strains.membrane - states.membrane_strain(p);
    const StrainVoigt d_curvature = strains.curvature - states.curvature(p);
    const Vector2 d_shear = strains.shear - states.shear_strain(p);
    const thickness::Resultants resultants = states.section(p).update(states.state(p), d_membrane, d_curvature);
    // The elastic transverse shear force (weighted: the shear weight holds
    // κs G d A) is updated incrementally like the other resultants, so a
    // change of shape functions (after a crack) leaves it continuous.
    const Vector2 shear_force = states.shear_force(p) + points.shear_weight(p) * d_shear;
    const double w = points.membrane_bending_weight(p);
    // Trapezoidal work of the generalized stresses over the strain increment.
    work_increment_[p] = w * (0.5 * (states.membrane_force(p) + resultants.membrane).dot(d_membrane) +
                              0.5 * (states.bending_moment(p) + resultants.moment).dot(d_curvature)) +
                         0.5 * (states.shear_force(p) + shear_force).dot(d_shear);
    states.restart_strains(p, strains);
    states.membrane_force(p) = resultants.membrane;
    states.bending_moment(p) = resultants.moment;
    states.shear_force(p) = shear_force;
    // The tied shear reads the corners from this step's packed kinematics
    // (the same numbers as the particle state's).
    const double tied_energy =
        scatter(group, row, current, points, states,
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
    return shell::corner_shear_forces(
        tying, points.shear_edges(row), [&](int k) -> const Vector3& { return position(tying.particle[std::size_t(k)]); },
        [&](int k) -> const Vector3& { return director(tying.particle[std::size_t(k)]); }, nonlinear_,
        &tied_force_[first], &tied_director_force_[first]);
  }

  bool nonlinear_;
  std::size_t failed_point_ = 0;
  // Per point: its conjugate forces (zero for a removed point). Per stress
  // point corner (row × max_cell_corners + corner): the tied shear's forces
  // on the corner particle and its director (zero where no tied shear acts).
  std::vector<shell::ConjugateForces> conjugate_;
  std::vector<Vector3> tied_force_, tied_director_force_;
  std::vector<double> work_increment_;
  std::vector<PackedKinematics> packed_;  // this step's positions and directors
};

}  // namespace sphshell::solver
