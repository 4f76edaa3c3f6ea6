#pragma once
// Kinematic conditions on particles: fixed or prescribed translation
// components, fixed rotation components (clamped, simply supported, symmetry
// planes), and prescribed motions.
//
// Each constrained particle keeps the projectors onto its free translation and
// rotation subspaces; the solver projects velocities onto them and adds the
// prescribed part. Constraint directions are fixed in space.

#include <sphshell/core/error.hpp>
#include <sphshell/core/parallel.hpp>
#include <sphshell/core/types.hpp>

#include <algorithm>
#include <cstddef>
#include <exception>
#include <memory>
#include <string>
#include <unordered_map>
#include <vector>

namespace sphshell::detail {

// Prescribed motion of a particle: the velocity to impose on its fixed
// translation subspace over the step from t to t + dt, given its reference
// position.
class PrescribedMotion {
 public:
  virtual ~PrescribedMotion() = default;
  // Returns the imposed velocity (a full vector; only its component in the
  // constrained subspace is used).
  virtual Vector3 velocity(int particle, const Vector3& reference_position, double t,
                           double dt) const = 0;
};

template <class DisplacementFunction>
class PrescribedDisplacement final : public PrescribedMotion {
 public:
  explicit PrescribedDisplacement(DisplacementFunction displacement)
      : displacement_(std::move(displacement)) {}
  // Central difference: the velocity that carries u(t) to u(t + dt) exactly.
  Vector3 velocity(int, const Vector3& x, double t, double dt) const override {
    return (displacement_(x, t + dt) - displacement_(x, t)) / dt;
  }

 private:
  DisplacementFunction displacement_;
};

template <class VelocityFunction>
class PrescribedVelocity final : public PrescribedMotion {
 public:
  explicit PrescribedVelocity(VelocityFunction velocity) : velocity_(std::move(velocity)) {}
  Vector3 velocity(int, const Vector3& x, double t, double dt) const override {
    return velocity_(x, t + 0.5 * dt);
  }

 private:
  VelocityFunction velocity_;
};

struct ParticleConstraint {
  Matrix3 free_translation = Matrix3::Identity();
  Matrix3 free_rotation = Matrix3::Identity();
  std::vector<const PrescribedMotion*> motions;  // summed, then projected on the fixed subspace
};

class Constraints {
 public:
  // A free rotation subspace whose drilling component (along the director) is
  // this small in squared length has none to remove.
  static constexpr double negligible_drilling_squared = 1e-24;
  // A constraint direction whose part in the free subspace is this short
  // (relative) is already fixed.
  static constexpr double already_fixed_length = 1e-8;

  // On every particle of a set (indices already checked).
  void clamp(const std::vector<int>& set) {
    require_no_motion(set);
    for (int i : set) {
      fix_all_translations(i);
      fix_all_rotations(i);
    }
  }
  void simply_support(const std::vector<int>& set) {
    require_no_motion(set);
    for (int i : set) fix_all_translations(i);
  }
  // Translations fixed and no rotation about n × t (the director does not tilt along the edge).
  void simply_support_hard(const std::vector<int>& set, const std::vector<Vector3>& normal,
                           const Vector3& edge_tangent) {
    require_no_motion(set);
    require_rotation_axes(set, normal, edge_tangent, "edge_tangent", "along the particle's normal");
    for (int i : set) {
      fix_all_translations(i);
      fix_rotation(i, normal[i].cross(edge_tangent));
    }
  }
  // No translation across the plane and no rotation tilting the director out of it.
  void symmetry_plane(const std::vector<int>& set, const std::vector<Vector3>& normal, const Vector3& plane_normal) {
    require_no_motion(set);
    require_rotation_axes(set, normal, plane_normal, "plane_normal",
                          "along the particle's normal (the plane must contain the normal)");
    for (int i : set) {
      fix_translation(i, plane_normal);
      fix_rotation(i, normal[i].cross(plane_normal));
    }
  }
  void fix_translation(const std::vector<int>& set, const Vector3& direction) {
    require_no_motion(set);
    for (int i : set) fix_translation(i, direction);
  }
  void fix_rotation(const std::vector<int>& set, const Vector3& axis) {
    for (int i : set) fix_rotation(i, axis);
  }
  // A prescribed motion on all three translations of a set; its velocity
  // over the coming step must be finite at every particle.
  template <class Motion>
  void add_motion(const std::vector<int>& set, std::unique_ptr<Motion> motion,
                  const std::vector<Vector3>& reference_position, double time, double time_step) {
    for (int i : set) {
      const Vector3 v = motion->velocity(i, reference_position[i], time, time_step);
      if (!v.allFinite())
        invalid_parameter("prescribed motion at particle " + std::to_string(i), v.transpose(), "must be finite");
    }
    // A prescribed motion sets all three translations: a particle that has a
    // translation condition already (or another motion) would get two
    // conflicting ones, so that is an Error naming the particle. Rotation
    // conditions combine with it (a moving clamped grip: prescribe the motion,
    // then fix the rotations).
    for (int i : set) {
      const auto found = index_.find(i);
      if (found == index_.end()) continue;
      const ParticleConstraint& existing = entries_[found->second];
      if (!existing.motions.empty())
        invalid_parameter("prescribed motion at particle " + std::to_string(i), "(a second one)",
                          "the particle has a prescribed motion already; give one motion per particle");
      if (!existing.free_translation.isIdentity(0.0))
        invalid_parameter("prescribed motion at particle " + std::to_string(i), "(on a fixed translation)",
                          "conflicts with the clamp, support, symmetry plane or fixed translation already on the "
                          "particle: a prescribed motion sets all three translations; combine it with rotation "
                          "conditions only");
    }
    const PrescribedMotion* owned = own(std::move(motion));
    for (int i : set) {
      entry(i).free_translation.setZero();
      add_motion(i, owned);
    }
  }

  void fix_translation(int particle, const Vector3& direction) {
    restrict(translation_of(particle), direction, "translation direction");
  }
  void fix_rotation(int particle, const Vector3& axis) {
    restrict(entry(particle).free_rotation, axis, "rotation axis");
  }
  void fix_all_translations(int particle) { translation_of(particle).setZero(); }
  void fix_all_rotations(int particle) { entry(particle).free_rotation.setZero(); }
  void add_motion(int particle, const PrescribedMotion* motion) {
    entry(particle).motions.push_back(motion);
  }
  template <class Motion>
  const PrescribedMotion* own(std::unique_ptr<Motion> motion) {
    owned_.push_back(std::move(motion));
    return owned_.back().get();
  }

  // Imposes the conditions on velocities just updated without them: the
  // translation is projected onto its free subspace plus the prescribed part,
  // the angular velocity onto the free rotations normal to the director.
  // The position update always spans time_step (also on the half-step
  // start-up of the velocities), so the imposed velocity does too.
  // Only the conditions of particles [first, last), for the particle pass
  // that steps them in chunks (solver/particle_pass.hpp): call prepare()
  // once after the last condition was added and before such passes. A
  // failing condition k (its place in the order they were added: a
  // prescribed motion that is not finite, or whose function throws) is
  // handed to failed(k, error) and the others are imposed; failed must not
  // throw.
  void prepare() {
    if (by_particle_.size() == entries_.size()) return;
    by_particle_.resize(entries_.size());
    for (std::size_t k = 0; k < entries_.size(); ++k) by_particle_[k] = k;
    std::sort(by_particle_.begin(), by_particle_.end(),
              [&](std::size_t a, std::size_t b) { return particles_[a] < particles_[b]; });
  }
  template <class Failed>
  void impose(const StepTime& at, const std::vector<Vector3>& reference_position, double time_step,
              const std::vector<Vector3>& director, std::vector<Vector3>& velocity,
              std::vector<Vector3>& angular_velocity, std::size_t first, std::size_t last, Failed&& failed) const
      noexcept {
    const auto start = std::lower_bound(by_particle_.begin(), by_particle_.end(), first,
                                        [&](std::size_t k, std::size_t i) { return std::size_t(particles_[k]) < i; });
    for (auto it = start; it != by_particle_.end() && std::size_t(particles_[*it]) < last; ++it) {
      try {
        impose_one(*it, at, reference_position, time_step, director, velocity, angular_velocity);
      } catch (...) {
        failed(*it, std::current_exception());
      }
    }
  }

  bool empty() const { return particles_.empty(); }
  const std::vector<int>& particles() const { return particles_; }
  // The ids its step messages name the particles by (a distributed run's
  // global ids of its local particles); the indices themselves by default.
  void name_particles_by(std::vector<int> ids) { particle_ids_ = std::move(ids); }
  const ParticleConstraint& at(std::size_t k) const { return entries_[k]; }

 private:
  void impose_one(std::size_t k, const StepTime& at, const std::vector<Vector3>& reference_position, double time_step,
                  const std::vector<Vector3>& director, std::vector<Vector3>& velocity,
                  std::vector<Vector3>& angular_velocity) const {
    const int i = particles_[k];
    const ParticleConstraint& constraint = entries_[k];
    Vector3 prescribed = Vector3::Zero();
    for (const PrescribedMotion* motion : constraint.motions)
      prescribed += motion->velocity(i, reference_position[i], at.time, time_step);
    if (!prescribed.allFinite())
      fail_unstable(at, "prescribed motion of particle " +
                            std::to_string(particle_ids_.empty() ? i : particle_ids_[static_cast<std::size_t>(i)]) +
                            " is not finite");
    velocity[i] = constraint.free_translation * velocity[i] +
                  (Matrix3::Identity() - constraint.free_translation) * prescribed;
    // Project onto the free rotations and the plane normal to the director at
    // once: projecting one after the other would let the drilling removal
    // reintroduce a fixed component when the director is tilted.
    Matrix3 free = constraint.free_rotation;
    const Vector3 drilling = free * director[i];
    if (drilling.squaredNorm() > negligible_drilling_squared)
      free -= drilling * drilling.transpose() / drilling.squaredNorm();
    angular_velocity[i] = free * angular_velocity[i];
  }

  ParticleConstraint& entry(int particle) {
    auto found = index_.find(particle);
    if (found != index_.end()) return entries_[found->second];
    index_[particle] = entries_.size();
    particles_.push_back(particle);
    entries_.emplace_back();
    return entries_.back();
  }
  // Checked for a whole set before any of it changes.
  // Checked for the whole set before any particle changes, under the name the
  // caller used: `vector` must be finite, non-zero and, at every particle,
  // not along its normal (the rotation axis n × vector would vanish).
  static void require_rotation_axes(const std::vector<int>& set, const std::vector<Vector3>& normal,
                                    const Vector3& vector, const char* name, const char* parallel) {
    if (!vector.allFinite() || vector.norm() == 0.0)
      invalid_parameter(name, vector.transpose(), "must be finite and non-zero");
    for (int i : set)
      if (normal[std::size_t(i)].cross(vector).norm() == 0.0)
        invalid_parameter(name, vector.transpose(), std::string("must not lie ") + parallel + " at particle " +
                                                        std::to_string(i));
  }
  void require_no_motion(const std::vector<int>& set) {
    for (int i : set) {
      const auto found = index_.find(i);
      if (found != index_.end() && !entries_[found->second].motions.empty()) translation_of(i);
    }
  }
  // The free translations of a particle about to get a translation condition;
  // one under a prescribed motion has none left to fix (that is an Error).
  Matrix3& translation_of(int particle) {
    ParticleConstraint& constraint = entry(particle);
    if (!constraint.motions.empty())
      invalid_parameter("translation condition at particle " + std::to_string(particle), "(on a prescribed motion)",
                        "conflicts with the prescribed motion already on the particle, which sets all three "
                        "translations; fix only rotations there");
    return constraint.free_translation;
  }
  // Removes `direction` from the free subspace P: P ← P − (P c)(P c)ᵀ/|P c|².
  static void restrict(Matrix3& free, const Vector3& direction, const char* name) {
    if (!direction.allFinite() || direction.norm() == 0.0)
      invalid_parameter(name, direction.transpose(), "must be finite and non-zero");
    const Vector3 projected = free * direction.normalized();
    const double length = projected.norm();
    if (length < already_fixed_length) return;
    const Vector3 c = projected / length;
    free -= c * c.transpose();
  }

  std::vector<int> particles_;
  std::vector<ParticleConstraint> entries_;
  std::vector<std::size_t> by_particle_;  // entries_' indices by particle (prepare())
  std::unordered_map<int, std::size_t> index_;
  std::vector<int> particle_ids_;
  std::vector<std::unique_ptr<PrescribedMotion>> owned_;
};

}  // namespace sphshell::detail
