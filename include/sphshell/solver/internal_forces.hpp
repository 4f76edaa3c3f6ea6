#pragma once
// The internal-force assembler: the one hot loop of a step. For every active
// integration point: gather a1, a2, n, n1, n2 from its neighbours → strains
// (Green or linear, shell/kinematics.hpp) → material update through the
// thickness (Section) → resultants → the conjugate forces scattered to the
// point's shape-function slots; then each particle sums the slots that refer to
// it, in a fixed order (the deterministic sum: no atomics, identical results
// for any thread count). The work of each point over the step is kept for the
// energy ledger.

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
    for (PointGroup group : point_groups)
      parallel::for_each(
          std::size_t{0}, points.count(group),
          [&](std::size_t row) { integrate_point(group, row, particles, points, states); },
          [&](std::size_t row, const std::exception_ptr& error) {
            failed_point_ = points.point(group, row);
            detail::fail_unstable(at, std::string(name_of(group)) + " " +
                                          std::to_string(points.global_row(group, row)) + ": " +
                                          parallel::what(error));
          });
    sum_particle_forces(points, forces);
  }

  // Forces of one point's stored resultants on the slots of its row (no
  // material update), from the current surface gradients, plus the forces of
  // its edge-tied shear from the particles' configuration. Returns the tied
  // shear's elastic energy (0 for a point whose shear is not tied).
  template <class Approx, class Rule, class Law>
  double scatter_point(PointGroup group, std::size_t row, const shell::SurfaceGradients& current,
                       const ParticleState& particles, const IntegrationPoints<Approx>& points,
                       const SectionStates<Rule, Law>& states) {
    const std::size_t p = points.point(group, row);
    const double w = points.membrane_bending_weight(p);
    const shell::WeightedStresses weighted{w * states.membrane_force(p), w * states.bending_moment(p),
                                           states.shear_force(p)};
    const shell::ConjugateForces f = shell::conjugate_forces(nonlinear_ ? current : points.reference(p), weighted);
    const approx::ShapeFunctions& shape = points.shape(group);
    const std::size_t end = shape.row_begin[row] + shape.row_size[row];
    for (std::size_t s = shape.row_begin[row]; s < end; ++s) {
      const std::size_t slot = points.slot(group, s);
      slot_force_[slot] = shape.dphi_d1[s] * f.a1 + shape.dphi_d2[s] * f.a2;
      slot_director_force_[slot] = shape.phi[s] * f.n + shape.dphi_d1[s] * f.n1 + shape.dphi_d2[s] * f.n2;
    }
    return points.shear_tied(group, row) ? scatter_tied_shear(row, particles, points) : 0.0;
  }

  // Zeroes the forces a point left on the slots of its row (a removed point).
  template <class Approx>
  void clear_slots(PointGroup group, std::size_t row, const IntegrationPoints<Approx>& points) {
    const approx::ShapeFunctions& shape = points.shape(group);
    for (std::size_t s = shape.row_begin[row]; s < shape.row_begin[row + 1]; ++s) {
      slot_force_[points.slot(group, s)].setZero();
      slot_director_force_[points.slot(group, s)].setZero();
    }
  }

  // Deterministic per-particle sums of the slot forces.
  template <class Approx>
  void sum_particle_forces(const IntegrationPoints<Approx>& points, ParticleForces& forces) const {
    const std::vector<std::size_t>& begin = points.particle_slot_begin();
    const std::vector<std::size_t>& slots = points.particle_slots();
    parallel::for_each(std::size_t{0}, forces.internal.size(), [&](std::size_t i) noexcept {
      Vector3 force = Vector3::Zero(), director_force = Vector3::Zero();
      for (std::size_t k = begin[i]; k < begin[i + 1]; ++k) {
        force += slot_force_[slots[k]];
        director_force += slot_director_force_[slots[k]];
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

  // Strains of a point's current gradients against its reference.
  shell::Strains strains_of(const shell::SurfaceGradients& current, const shell::SurfaceGradients& reference) const {
    return nonlinear_ ? shell::green_strains(current, reference) : shell::linear_strains(current, reference);
  }

 private:
  // Slot arrays are sized once (rows keep their capacity when cracks shrink
  // them); the work is zero for points that do not integrate.
  template <class Approx>
  void prepare(const IntegrationPoints<Approx>& points) {
    if (slot_force_.size() != points.slot_count()) {
      slot_force_.assign(points.slot_count(), Vector3::Zero());
      slot_director_force_.assign(points.slot_count(), Vector3::Zero());
    }
    work_increment_.assign(points.size(), 0.0);
  }

  template <class Approx, class Rule, class Law>
  void integrate_point(PointGroup group, std::size_t row, const ParticleState& particles,
                       const IntegrationPoints<Approx>& points, SectionStates<Rule, Law>& states) {
    const std::size_t p = points.point(group, row);
    if (!states.active(p)) return;
    const shell::SurfaceGradients current = points.gather(group, row, particles.position, particles.director);
    const shell::Strains strains = strains_of(current, points.reference(p));
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
    const double tied_energy = scatter_point(group, row, current, particles, points, states);
    // The tied shear is elastic and quadratic: its work over the step is
    // exactly the change of its energy.
    work_increment_[p] += tied_energy - states.tied_shear_energy(p);
    states.tied_shear_energy(p) = tied_energy;
  }

  // Adds the forces of a stress point's edge-tied shear (shell/cell_shear.hpp)
  // to the slots of its cell's corners in its row; returns its energy. A corner
  // hidden from the point by a crack leaves the cell's shear out (energy 0).
  template <class Approx>
  double scatter_tied_shear(std::size_t row, const ParticleState& particles, const IntegrationPoints<Approx>& points) {
    const shell::CellShearTying& tying = points.shear_tying(row);
    const approx::ShapeFunctions& shape = points.shape(PointGroup::stress_points);
    const std::size_t begin = shape.row_begin[row], end = begin + shape.row_size[row];
    std::array<std::size_t, shell::max_cell_corners> corner_slot{};
    for (int k = 0; k < tying.corners; ++k) {
      std::size_t s = begin;
      while (s < end && shape.neighbour[s] != tying.particle[k]) ++s;
      if (s == end) return 0.0;
      corner_slot[k] = points.slot(PointGroup::stress_points, s);
    }
    const shell::CellShearForces f = shell::cell_shear_forces(tying, particles.position, particles.director, nonlinear_);
    for (int k = 0; k < tying.corners; ++k) {
      slot_force_[corner_slot[k]] += f.force[k];
      slot_director_force_[corner_slot[k]] += f.director_force[k];
    }
    return f.energy;
  }

  bool nonlinear_;
  std::size_t failed_point_ = 0;
  std::vector<Vector3> slot_force_, slot_director_force_;
  std::vector<double> work_increment_;
};

}  // namespace sphshell::solver
