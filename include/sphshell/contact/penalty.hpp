#pragma once
// Penalty contact of shell particles against a rigid body.
//
// A particle is a point of the mid-surface; the shell's faces lie half the
// local thickness h to either side. The contact point of particle i is the
// face point facing the body, c = x + σ (h/2) d (d the unit director, σ = ±1
// chosen against the body's outward normal at x), and its gap is the body's
// signed distance of c: for a director along the normal, gap = distance − h/2.
// The mid-surface itself never touches. A negative gap (penetration
// δ = −gap) gives the particle
//   f_n = k δ n             (n the body's outward normal at c),
//   f_t                     Coulomb friction, |f_t| ≤ μ |f_n|,
//   f = f_n + f_t on its translation and M = (c − x) × f on its rotation,
// and the body the reaction −f at c (moment (c − x_body) × (−f) about its centre).
//
// Penalty stiffness (the stiffness-from-mass rule of LS-DYNA's soft constraint
// contact, SOFT = 1: k1 ∝ nodal mass / Δt², scaled by SOFSCL, default 0.1,
// LS-DYNA Keyword User's Manual, *CONTACT optional card A; its contact FAQ
// likens each contact to a spring-mass system whose Courant step matches the
// run's step. OpenRadioss /INTER/TYPE7 goes the other way: its reference
// manual notes that the time step is reduced for high impact speeds or small
// gaps, its interface stiffness bounding the step. Here the step is given and
// the stiffness follows from it):
//   k = s m / Δt².
// Why it keeps the step stable: the particle on its contact spring is an
// oscillator of angular frequency ω = √(k/m) = √s / Δt, so ω Δt = √s, and the
// central difference is stable for ω Δt < 2, i.e. s < 4. The spring adds to the
// shell's own stiffness, (ω Δt)² = (ω_shell Δt)² + s; with the solver's safety
// factor 0.8 the shell uses at most (0.8 · 2)² = 2.56 of the 4, so s < 1.44
// keeps the sum stable; the default s = 0.1 leaves margin. Against a free body
// of mass m_b, m is the pair's reduced mass m m_b / (m + m_b), so the pair's
// frequency is the same √s / Δt.
//
// Friction: an elastic-slip tangential spring (a regularised Coulomb law). The
// tangential force is history: each step it is turned into the new tangent
// plane, loaded by k_t times the tangential relative displacement of the
// contact point, and returned to the Coulomb cone |f_t| ≤ μ |f_n|; what is cut
// off is slip, which dissipates μ |f_n| × slip. Chosen over a velocity-based
// regularisation because it holds a body at rest under a tangential load below
// μ |f_n| without creeping and has no velocity scale to choose; the spring has
// the normal spring's stability (k_t ≤ k).
//
// Velocities given are those of the last half step (v^{n−½}): the relative
// displacement of the contact point over the last step is (v_c − v_body) Δt.
// The contact work of a step is the trapezoidal ½ (f^{n−1} + f^n) · Δu summed
// over the particles: over a frictionless bounce it sums to about zero; with
// friction it sums to minus the dissipation (and the spring energy held).

#include <sphshell/contact/contact.hpp>
#include <sphshell/contact/rigid_body.hpp>
#include <sphshell/core/error.hpp>

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace sphshell::contact {

// s of k = s m / Δt², after LS-DYNA's SOFSCL default.
inline constexpr double default_penalty_stiffness_scale = 0.1;
// The central difference is stable for ω Δt < 2; ω Δt = √s, so s < 4.
inline constexpr double central_difference_frequency_limit = 2.0;
inline constexpr double penalty_stiffness_scale_bound =
    central_difference_frequency_limit * central_difference_frequency_limit;

struct PenaltyOptions {
  double stiffness_scale = default_penalty_stiffness_scale;  // s in k = s m / Δt², 0 < s < 4
  double friction_coefficient = 0.0;                          // μ ≥ 0 (Coulomb)
  double tangential_stiffness_ratio = 1.0;                    // k_t / k, in (0, 1]
};

inline void validate(const PenaltyOptions& options) {
  sphshell::detail::require_open_interval("penalty stiffness_scale", options.stiffness_scale, 0.0,
                                          penalty_stiffness_scale_bound);
  sphshell::detail::require_nonnegative("friction_coefficient", options.friction_coefficient);
  sphshell::detail::require_half_open_interval("tangential_stiffness_ratio", options.tangential_stiffness_ratio,
                                               0.0, 1.0);
}

// k = s m / Δt²: the contact spring on mass m oscillates at ω Δt = √s.
inline double penalty_stiffness(double mass, double time_step, double stiffness_scale) {
  return stiffness_scale * mass / (time_step * time_step);
}

// The particles, structure of arrays (the solver's own arrays, not copied).
struct ContactParticles {
  const std::vector<Vector3>& position;
  const std::vector<Vector3>& director;          // unit
  const std::vector<Vector3>& velocity;          // at n − ½
  const std::vector<Vector3>& angular_velocity;  // at n − ½
  const std::vector<double>& mass;
  const std::vector<double>& thickness;
};

// Per particle: the contact force on its translation and moment on its rotation.
struct ParticleContactLoads {
  std::vector<Vector3> force;
  std::vector<Vector3> moment;
};

// What one contact evaluation did, summed over the particles.
struct ContactStepResult {
  Vector3 body_force = Vector3::Zero();   // reaction on the body (N)
  Vector3 body_moment = Vector3::Zero();  // its moment about the body's centre (N m)
  double work = 0.0;                  // contact work over the last step, ½ (f^{n−1} + f^n) · Δu (J)
  double friction_dissipation = 0.0;  // dissipated by slip this step (J)
  double spring_energy = 0.0;         // held by the normal and tangential springs (J)
  std::size_t contacts = 0;           // particles in contact
};

// One particle's share of a ContactStepResult, as compute_range adds it:
// what a contact evaluation sums over the particles, kept per particle so
// that the sum can be formed in one fixed order wherever the particles are
// (body_set.hpp: in index order within the chunks of
// ParticleEnergyTerms::sum_chunk particles, then chunk by chunk, however the
// particles are split between threads or processes). Only particles near
// enough to touch have a term: the others add nothing. Plain data (no Eigen
// members), so that terms can be gathered between processes as bytes.
struct ContactTerm {
  std::int64_t particle = 0;  // its index (the local one where computed; body_set.hpp renumbers)
  std::int64_t body = 0;      // the body's id in its run (body_set.hpp)
  double force[3] = {0.0, 0.0, 0.0};        // on the particle; the body takes −force
  double body_moment[3] = {0.0, 0.0, 0.0};  // (c − x_body) × (−force)
  double work = 0.0;                  // ½ (f^{n−1} + f^n) · Δu
  double friction_dissipation = 0.0;  // μ |f_n| × slip, when it slipped
  double spring_energy = 0.0;
  // The contact force's work on the particle over the halves of the step
  // (body_set.hpp, RigidBodySet::book_chunk), f^n · Δt_v v^{n∓½}/2.
  double work_first_half = 0.0, work_second_half = 0.0;
  std::int32_t in_contact = 0, slipped = 0;
};

class PenaltyContact {
 public:
  explicit PenaltyContact(const PenaltyOptions& options = {}) : options_(options) { validate(options_); }

  const PenaltyOptions& options() const { return options_; }

  // Checkpoints: the contact history (every particle's tangential spring
  // force and last contact force), sized to the particle count by prepare().
  template <class Writer>
  void save(Writer& out) const {
    out(tangential_force_, previous_force_);
  }
  template <class Reader>
  void load(Reader& in) {
    in.read_exact(tangential_force_, "rigid body contact history (tangential forces)");
    in.read_exact(previous_force_, "rigid body contact history (last contact forces)");
  }

  // The contact of every particle with the body at configuration n: prepare,
  // then compute_range over all particles.
  template <class Shape, class Motion>
  ContactStepResult compute(const ContactParticles& particles, const RigidBody<Shape, Motion>& body,
                            double time_step, ParticleContactLoads& loads) {
    prepare(particles, time_step, loads);
    return compute_range(particles, body, time_step, loads, 0, particles.position.size());
  }

  // Checks the particles (array sizes, masses and thicknesses finite and > 0)
  // and the time step, and sizes the contact history and loads (to the
  // particle count). Throws an Error naming the first bad value; once per step.
  void prepare(const ContactParticles& particles, double time_step, ParticleContactLoads& loads) {
    sphshell::detail::require_positive("time step", time_step);
    const std::size_t count = particles.position.size();
    check_sizes(particles, count);
    for (std::size_t i = 0; i < count; ++i) {
      if (!(particles.mass[i] > 0.0) || !std::isfinite(particles.mass[i]))
        sphshell::detail::invalid_parameter("mass of particle " + std::to_string(i), particles.mass[i],
                                            "must be finite and > 0");
      if (!(particles.thickness[i] > 0.0) || !std::isfinite(particles.thickness[i]))
        sphshell::detail::invalid_parameter("thickness of particle " + std::to_string(i), particles.thickness[i],
                                            "must be finite and > 0");
    }
    if (tangential_force_.size() != count) {
      tangential_force_.assign(count, Vector3::Zero());
      previous_force_.assign(count, Vector3::Zero());
    }
    loads.force.resize(count);
    loads.moment.resize(count);
  }

  // Particles [first, last) after prepare(): writes their loads (zero where
  // there is no contact) and their contact history, nothing else, and does
  // not throw, so that chunks of particles may run on several threads; their
  // results summed in chunk order with accumulate() give the same bits
  // whatever the thread count.
  template <class Shape, class Motion>
  ContactStepResult compute_range(const ContactParticles& particles, const RigidBody<Shape, Motion>& body,
                                  double time_step, ParticleContactLoads& loads, std::size_t first,
                                  std::size_t last) {
    ContactStepResult result;
    for_each_term(particles, body, time_step, loads, first, last, [&](const ContactTerm& term) { add(result, term); });
    return result;
  }
  // The same evaluation, its terms (in index order) appended to `terms`
  // instead of summed, for a sum formed elsewhere in a fixed order.
  template <class Shape, class Motion>
  void compute_terms(const ContactParticles& particles, const RigidBody<Shape, Motion>& body, double time_step,
                     ParticleContactLoads& loads, std::size_t first, std::size_t last,
                     std::vector<ContactTerm>& terms) {
    for_each_term(particles, body, time_step, loads, first, last,
                  [&](const ContactTerm& term) { terms.push_back(term); });
  }

  // A particle's term added to a sum, as compute_range adds it.
  static void add(ContactStepResult& result, const ContactTerm& term) {
    if (term.in_contact) {
      if (term.slipped) result.friction_dissipation += term.friction_dissipation;
      result.body_force -= Vector3(term.force[0], term.force[1], term.force[2]);
      result.body_moment += Vector3(term.body_moment[0], term.body_moment[1], term.body_moment[2]);
      result.spring_energy += term.spring_energy;
      ++result.contacts;
    }
    result.work += term.work;
  }

  static void accumulate(ContactStepResult& total, const ContactStepResult& part) {
    total.body_force += part.body_force;
    total.body_moment += part.body_moment;
    total.work += part.work;
    total.friction_dissipation += part.friction_dissipation;
    total.spring_energy += part.spring_energy;
    total.contacts += part.contacts;
  }

  // The tangential (friction) force each particle holds.
  const std::vector<Vector3>& tangential_forces() const { return tangential_force_; }

 private:
  // The contact of particles [first, last): their loads and history written,
  // each particle near enough to touch handed to `sink` as its term.
  template <class Shape, class Motion, class Sink>
  void for_each_term(const ContactParticles& particles, const RigidBody<Shape, Motion>& body, double time_step,
                     ParticleContactLoads& loads, std::size_t first, std::size_t last, Sink&& sink) {
    const double body_mass = body.inertial_mass();
    for (std::size_t i = first; i < last; ++i) {
      loads.force[i].setZero();
      loads.moment[i].setZero();
      const double half_thickness = 0.5 * particles.thickness[i];
      const Vector3& x = particles.position[i];
      const SurfaceProximity at_mid = body.proximity(x);
      // The signed distance changes by at most |c − x| = h/2 (it is 1-Lipschitz):
      // a particle farther than h/2 cannot touch.
      if (at_mid.gap > half_thickness && previous_force_[i].squaredNorm() == 0.0) {
        tangential_force_[i].setZero();
        continue;
      }
      ContactTerm term;
      term.particle = static_cast<std::int64_t>(i);
      const Vector3& d = particles.director[i];
      const double side = d.dot(at_mid.normal) > 0.0 ? -1.0 : 1.0;
      const Vector3 arm = side * half_thickness * d;
      const Vector3 contact_point = x + arm;
      const Vector3 relative_velocity =
          particles.velocity[i] + particles.angular_velocity[i].cross(arm) - body.velocity_at(contact_point);
      const Vector3 displacement = time_step * relative_velocity;
      const SurfaceProximity at_face = body.proximity(contact_point);
      Vector3 force = Vector3::Zero();
      if (at_face.gap < 0.0) {
        const double mass = particles.mass[i];
        const double spring_mass = std::isfinite(body_mass) ? mass * body_mass / (mass + body_mass) : mass;
        const double stiffness = penalty_stiffness(spring_mass, time_step, options_.stiffness_scale);
        const double tangential_stiffness = options_.tangential_stiffness_ratio * stiffness;
        const Vector3& n = at_face.normal;
        const double penetration = -at_face.gap;
        const double normal_force = stiffness * penetration;
        // The stored tangential force, turned into the new tangent plane.
        Vector3 tangential = tangential_force_[i] - tangential_force_[i].dot(n) * n;
        const double stored = tangential_force_[i].norm();
        const double projected = tangential.norm();
        if (projected > 0.0) tangential *= stored / projected;
        const Vector3 tangential_displacement = displacement - displacement.dot(n) * n;
        tangential -= tangential_stiffness * tangential_displacement;
        const double limit = options_.friction_coefficient * normal_force;
        const double trial = tangential.norm();
        if (trial > limit) {
          const double slip = (trial - limit) / tangential_stiffness;
          term.slipped = 1;
          term.friction_dissipation = limit * slip;
          tangential *= trial > 0.0 ? limit / trial : 0.0;
        }
        tangential_force_[i] = tangential;
        force = normal_force * n + tangential;
        loads.force[i] = force;
        loads.moment[i] = arm.cross(force);
        const Vector3 moment = (contact_point - body.position()).cross(-force);
        for (int k = 0; k < 3; ++k) {
          term.force[k] = force[k];
          term.body_moment[k] = moment[k];
        }
        term.spring_energy = 0.5 * normal_force * penetration + 0.5 * tangential.squaredNorm() / tangential_stiffness;
        term.in_contact = 1;
      } else {
        tangential_force_[i].setZero();
      }
      term.work = 0.5 * (previous_force_[i] + force).dot(displacement);
      previous_force_[i] = force;
      sink(term);
    }
  }

  static void check_sizes(const ContactParticles& particles, std::size_t count) {
    const std::size_t sizes[] = {particles.director.size(), particles.velocity.size(),
                                 particles.angular_velocity.size(), particles.mass.size(),
                                 particles.thickness.size()};
    const char* names[] = {"director", "velocity", "angular_velocity", "mass", "thickness"};
    for (int k = 0; k < 5; ++k)
      if (sizes[k] != count)
        sphshell::detail::invalid_parameter(std::string("contact particle ") + names[k] + " count", sizes[k],
                                            "must equal the position count " + std::to_string(count));
  }

  PenaltyOptions options_;
  std::vector<Vector3> tangential_force_;
  std::vector<Vector3> previous_force_;
};

}  // namespace sphshell::contact
