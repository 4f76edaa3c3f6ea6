#pragma once
// A rigid body: a shape (contact.hpp) placed in the world by the position of
// its centre and an orientation, moved by a motion policy:
//   Fixed                       it stays where it is;
//   Prescribed<Linear, Angular> its velocity and angular velocity are given
//                               functions of time (callables double → Vector3,
//                               template parameters, so no indirect call);
//   Free                        mass, principal rotational inertia (bounded
//                               shapes only), optional gravity; moved by the
//                               contact force and moment.
// advance() takes one central-difference step, as stepper::CentralDifference
// moves the particles: the velocities live at half steps, the first update
// spans Δt/2,
//   v^{n+½} = v^{n−½} + Δt_v (F/m + g),   x^{n+1} = x^n + Δt v^{n+½},
// and the orientation turns by Δt ω^{n+½} (Rodrigues, as a unit quaternion).
// The rotation follows Euler's equations in the body frame, I ω̇ + ω × I ω = M,
// with the gyroscopic term taken at ω^{n−½} (explicit; it vanishes for a
// sphere, I = const · 1).
//
// In a step, at configuration n: clear_contact_load(); the contact adds its
// reactions (add_contact_load); advance(at, Δt) with at.time = t0 + n Δt.

#include <sphshell/contact/contact.hpp>
#include <sphshell/contact/plane.hpp>
#include <sphshell/core/error.hpp>

#include <cmath>
#include <limits>
#include <string>
#include <utility>

namespace sphshell::contact {

// Where a body is and how it moves; velocities are those of the last half step.
struct RigidKinematics {
  Vector3 position = Vector3::Zero();                          // the centre (m)
  Eigen::Quaterniond orientation = Eigen::Quaterniond::Identity();  // body frame → world
  Vector3 velocity = Vector3::Zero();                          // of the centre (m/s)
  Vector3 angular_velocity = Vector3::Zero();                  // world frame (rad/s)
};

// The central difference's span of the velocity update of step n.
inline double rigid_velocity_step(long step, double time_step) { return step == 0 ? 0.5 * time_step : time_step; }

// The orientation turned by the rotation vector θ (world frame).
inline Eigen::Quaterniond rotated(const Eigen::Quaterniond& orientation, const Vector3& rotation_vector) {
  const double angle = rotation_vector.norm();
  if (!(angle > 0.0)) return orientation;
  return (Eigen::Quaterniond(Eigen::AngleAxisd(angle, rotation_vector / angle)) * orientation).normalized();
}

struct Fixed {
  static constexpr bool free = false;
  void advance(RigidKinematics& kinematics, const Vector3&, const Vector3&, const StepTime&, double, bool) const {
    kinematics.velocity.setZero();
    kinematics.angular_velocity.setZero();
  }
};

struct NoRotation {
  Vector3 operator()(double) const { return Vector3::Zero(); }
};

template <class LinearVelocity, class AngularVelocity = NoRotation>
struct Prescribed {
  static constexpr bool free = false;
  LinearVelocity linear;
  AngularVelocity angular{};

  void advance(RigidKinematics& kinematics, const Vector3&, const Vector3&, const StepTime& at, double time_step,
               bool) const {
    const double midstep = at.time + 0.5 * time_step;
    kinematics.velocity = linear(midstep);
    kinematics.angular_velocity = angular(midstep);
    kinematics.position += time_step * kinematics.velocity;
    kinematics.orientation = rotated(kinematics.orientation, time_step * kinematics.angular_velocity);
  }
};

template <class LinearVelocity>
Prescribed<LinearVelocity> prescribed(LinearVelocity linear) {
  return {std::move(linear), NoRotation{}};
}
template <class LinearVelocity, class AngularVelocity>
Prescribed<LinearVelocity, AngularVelocity> prescribed(LinearVelocity linear, AngularVelocity angular) {
  return {std::move(linear), std::move(angular)};
}

struct FreeMotionParameters {
  double mass = 0.0;                          // kg
  Vector3 principal_inertia = Vector3::Zero();  // body frame (kg m²); zero for an unbounded shape
  Vector3 gravity = Vector3::Zero();          // m/s²
};

class Free {
 public:
  static constexpr bool free = true;

  explicit Free(const FreeMotionParameters& parameters) : parameters_(parameters) {
    sphshell::detail::require_positive("rigid body mass", parameters.mass);
    for (int axis = 0; axis < 3; ++axis) {
      sphshell::detail::require_nonnegative("rigid body principal inertia " + std::to_string(axis),
                                            parameters.principal_inertia[axis]);
      sphshell::detail::require_finite("rigid body gravity " + std::to_string(axis), parameters.gravity[axis]);
    }
  }

  double mass() const { return parameters_.mass; }
  const Vector3& principal_inertia() const { return parameters_.principal_inertia; }
  const Vector3& gravity() const { return parameters_.gravity; }

  void advance(RigidKinematics& kinematics, const Vector3& force, const Vector3& moment, const StepTime& at,
               double time_step, bool rotates) const {
    const double span = rigid_velocity_step(at.step, time_step);
    kinematics.velocity += span * (force / parameters_.mass + parameters_.gravity);
    kinematics.position += time_step * kinematics.velocity;
    if (!rotates) return;
    const Matrix3 to_world = kinematics.orientation.toRotationMatrix();
    const Vector3 omega = to_world.transpose() * kinematics.angular_velocity;
    const Vector3 spin = parameters_.principal_inertia.cwiseProduct(omega);
    const Vector3 body_moment = to_world.transpose() * moment;
    const Vector3 body_omega = omega + span * (body_moment - omega.cross(spin)).cwiseQuotient(parameters_.principal_inertia);
    kinematics.angular_velocity = to_world * body_omega;
    kinematics.orientation = rotated(kinematics.orientation, time_step * kinematics.angular_velocity);
  }

 private:
  FreeMotionParameters parameters_;
};

template <class Shape, class Motion>
class RigidBody {
  static_assert(check_rigid_shape<Shape>(), "RigidBody needs a rigid shape (contact/contact.hpp)");

 public:
  using shape_type = Shape;
  using motion_type = Motion;
  // A free bounded body rotates; a plane has no finite inertia and only translates.
  static constexpr bool rotates = Motion::free && Shape::bounded;

  RigidBody(Shape shape, Motion motion, const RigidKinematics& initial = {})
      : shape_(std::move(shape)), motion_(std::move(motion)), kinematics_(initial) {
    if (!all_finite(initial.position, initial.velocity, initial.angular_velocity))
      sphshell::detail::invalid_parameter("rigid body initial state", "non-finite",
                                          "position, velocity and angular velocity must be finite");
    kinematics_.orientation.normalize();
    if constexpr (Motion::free) {
      if constexpr (Shape::bounded) {
        for (int axis = 0; axis < 3; ++axis)
          sphshell::detail::require_positive("rigid body principal inertia " + std::to_string(axis),
                                             motion_.principal_inertia()[axis]);
      } else {
        if (motion_.principal_inertia().squaredNorm() != 0.0 || initial.angular_velocity.squaredNorm() != 0.0)
          sphshell::detail::invalid_parameter("rigid body principal inertia", motion_.principal_inertia().norm(),
                                              "an unbounded shape (a plane) only translates: give no inertia and "
                                              "no angular velocity");
      }
    }
  }

  // Signed distance, outward normal and nearest point for a world point.
  SurfaceProximity proximity(const Vector3& point) const {
    const SurfaceProximity local = shape_.proximity(kinematics_.orientation.conjugate() * (point - kinematics_.position));
    return {local.gap, kinematics_.orientation * local.normal, kinematics_.position + kinematics_.orientation * local.nearest};
  }

  // Velocity of the body's material point at a world point.
  Vector3 velocity_at(const Vector3& point) const {
    return kinematics_.velocity + kinematics_.angular_velocity.cross(point - kinematics_.position);
  }

  // Mass that a particle's contact spring acts against: infinite unless free.
  double inertial_mass() const {
    if constexpr (Motion::free)
      return motion_.mass();
    else
      return std::numeric_limits<double>::infinity();
  }

  void clear_contact_load() {
    contact_force_.setZero();
    contact_moment_.setZero();
  }
  // A contact force on the body and its moment about the body's centre.
  void add_contact_load(const Vector3& force, const Vector3& moment_about_centre) {
    contact_force_ += force;
    contact_moment_ += moment_about_centre;
  }

  // One step from configuration n (at.step = n, at.time = t0 + n Δt) with the
  // contact load added since clear_contact_load(). The impulse it received is
  // the load times the velocity update's span.
  void advance(const StepTime& at, double time_step) {
    sphshell::detail::require_positive("time step", time_step);
    const double span = rigid_velocity_step(at.step, time_step);
    contact_impulse_ += span * contact_force_;
    motion_.advance(kinematics_, contact_force_, contact_moment_, at, time_step, rotates);
  }

  // Checkpoints (solver/checkpoint.hpp): where the body is, how it moves
  // and the contact load and impulse it received. Shape and motion are the
  // program's set-up, given again when the body is added before loading.
  template <class Writer>
  void save(Writer& out) const {
    const Eigen::Vector4d orientation = kinematics_.orientation.coeffs();
    out(kinematics_.position, orientation, kinematics_.velocity, kinematics_.angular_velocity, contact_force_,
        contact_moment_, contact_impulse_);
  }
  template <class Reader>
  void load(Reader& in) {
    Eigen::Vector4d orientation;
    in(kinematics_.position, orientation, kinematics_.velocity, kinematics_.angular_velocity, contact_force_,
       contact_moment_, contact_impulse_);
    kinematics_.orientation.coeffs() = orientation;
  }

  const Shape& shape() const { return shape_; }
  const Motion& motion() const { return motion_; }
  const RigidKinematics& kinematics() const { return kinematics_; }
  const Vector3& position() const { return kinematics_.position; }
  const Eigen::Quaterniond& orientation() const { return kinematics_.orientation; }
  const Vector3& velocity() const { return kinematics_.velocity; }
  const Vector3& angular_velocity() const { return kinematics_.angular_velocity; }
  const Vector3& contact_force() const { return contact_force_; }
  const Vector3& contact_moment() const { return contact_moment_; }
  const Vector3& contact_impulse() const { return contact_impulse_; }

 private:
  Shape shape_;
  Motion motion_;
  RigidKinematics kinematics_;
  Vector3 contact_force_ = Vector3::Zero();
  Vector3 contact_moment_ = Vector3::Zero();
  Vector3 contact_impulse_ = Vector3::Zero();
};

// A wall through `point` with the given outward normal, held fixed.
inline RigidBody<Plane, Fixed> fixed_wall(const Vector3& point, const Vector3& outward_normal) {
  RigidKinematics at;
  at.position = point;
  return RigidBody<Plane, Fixed>(Plane(outward_normal), Fixed{}, at);
}

}  // namespace sphshell::contact
