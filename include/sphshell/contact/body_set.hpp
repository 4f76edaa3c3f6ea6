#pragma once
// The rigid bodies of a run and their penalty contact with the shell, as the
// Solver steps them (Solver::add_rigid_body).
//
// Each body is kept with its own PenaltyContact behind one small interface,
// so bodies of any shape and motion (a prescribed motion's callables are
// template parameters) sit side by side. The interface is called once per
// body per chunk of particles; the loop over a chunk's particles is the
// concrete PenaltyContact::compute_range of that body's type, with no
// indirect call per particle.
//
// In a step, at configuration n (solver/particle_pass.hpp):
//   prepare()     before the particle pass;
//   load_chunk()  in the pass, after the loads and before the stepper's
//                 velocity update: every body's contact with the chunk's
//                 particles, added to their external forces and moments,
//                 and each particle's share of the sums (reaction on the
//                 body, spring energy, friction dissipation: a ContactTerm,
//                 penalty.hpp) kept in the chunk's list;
//   book_chunk()  in the pass, after the energy books' chunk: the work of the
//                 contact forces on the chunk's particles over the step, as
//                 the books count external work, f · Δt_v (v^{n−½} + v^{n+½})/2
//                 (and the moments' with ω), per particle;
//   finish_step() after the pass: the terms of every process (the particles
//                 are split between them in a distributed run) summed in one
//                 fixed order, that of one process's chunks (the same bits
//                 for any thread and process count), the reaction put on
//                 each body, the body advanced (RigidBody::advance) and the
//                 energy terms booked.
//
// The spring energy is reported at n+½, where the books' kinetic energies
// are: the springs' ½ k δ² at n less the contact's work over the step's second
// half, f^n · Δt_v (v^{n+½} − v_body^{n+½})/2 summed over the contacts.
//
// Energy (EnergyReport): the contact forces on the particles are external
// loads of the shell, so the shell's books count their work W_cs as external
// work. The whole system — shell, bodies and contact springs — balances
//   shell balance + W_cs + K_b + E_spring + D_friction − W_b = 0,
// K_b the bodies' kinetic energy, E_spring the energy the contact springs
// hold (the shell's self contact's too, when enabled: shell_contact.hpp, whose
// forces on the shell are part of W_cs and which puts no work into a body), D_friction what slip dissipated, and W_b the work put into the bodies
// from outside the contact: their initial kinetic energy, gravity's work
// (free bodies, m g · Δt_v v̄) and, for a fixed or prescribed body, the work
// of what drives it (its kinetic energy change less the contact's work on it).
// The contact work of the pair, W_cs + the contact's work on the bodies,
// equals −ΔE_spring − D_friction: the books' force-at-n times mean-velocity
// sums and the spring's trapezoidal sums differ only by their end term, the
// second half above.

#include <sphshell/contact/cylinder.hpp>
#include <sphshell/contact/penalty.hpp>
#include <sphshell/contact/plane.hpp>
#include <sphshell/contact/rigid_body.hpp>
#include <sphshell/contact/shell_contact.hpp>
#include <sphshell/contact/sphere.hpp>
#include <sphshell/contact/surface_mesh.hpp>
#include <sphshell/contact/triangle_surface.hpp>
#include <sphshell/core/error.hpp>
#include <sphshell/core/types.hpp>
#include <sphshell/io/binary_stream.hpp>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <memory>
#include <optional>
#include <string>
#include <type_traits>
#include <typeinfo>
#include <utility>
#include <vector>

namespace sphshell::contact {

// A body's index in its run, in the order added.
using RigidBodyId = std::size_t;

// What a run reports of one body after a step: position and orientation at
// the new configuration n+1, velocities at n+½ (the central difference's
// half step), the contact load it received in the step (at configuration n)
// and the impulse received since the start.
struct RigidBodyState {
  RigidKinematics kinematics;
  Vector3 contact_force = Vector3::Zero();
  Vector3 contact_moment = Vector3::Zero();  // about the body's centre
  Vector3 contact_impulse = Vector3::Zero();
  std::size_t contacts = 0;    // particles in contact in the step
  double kinetic_energy = 0.0;  // ½ m |v|² + ½ ω · I ω (free bodies; 0 for others)
};

// The bodies' and contacts' energy terms (see the header comment).
struct ContactEnergy {
  double body_kinetic = 0.0;           // K_b
  double spring = 0.0;                 // E_spring, at configuration n of the last step
  double friction_dissipation = 0.0;   // D_friction, summed over the steps
  double shell_contact_work = 0.0;     // W_cs, summed over the steps (part of the shell's external work)
  double body_work = 0.0;              // W_b, summed over the steps
};

// What a checkpoint checks a body against (the body added before loading
// must be the one saved): its shape's kind, its motion's kind and, for a free
// body, its mass (0 for the others).
struct RigidBodyDescription {
  std::string shape;
  std::string motion;
  double mass = 0.0;
};

namespace detail {

template <class Shape>
std::string shape_kind() {
  if constexpr (std::is_same_v<Shape, Sphere>)
    return "sphere";
  else if constexpr (std::is_same_v<Shape, Cylinder>)
    return "cylinder";
  else if constexpr (std::is_same_v<Shape, Plane>)
    return "plane";
  else if constexpr (std::is_same_v<Shape, TriangleSurface>)
    return "triangle surface";
  else
    return std::string("shape ") + typeid(Shape).name();
}

template <class Motion>
std::string motion_kind() {
  if constexpr (Motion::free)
    return "free";
  else if constexpr (std::is_same_v<Motion, Fixed>)
    return "fixed";
  else
    return "prescribed";
}

// One body with its contact; the solver's interface to it.
class BodyContact {
 public:
  virtual ~BodyContact() = default;
  virtual void prepare(std::size_t chunk_count) = 0;
  // Particles [first, last) of chunk `chunk`: their loads into loads(), their
  // terms (penalty.hpp, ContactTerm) into the chunk's list.
  virtual void compute_range(const ContactParticles& particles, double time_step, std::size_t chunk,
                             std::size_t first, std::size_t last) = 0;
  // The body moved by the step's sums `total` (RigidBodySet::finish_step
  // forms them from every process's terms): returns the work put into the
  // body from outside the contact and the contact's work on it over the
  // step's second half.
  virtual void finish_step(const ContactStepResult& total, const StepTime& at, double time_step,
                           double velocity_step, double& body_work, double& contact_second_half) = 0;
  virtual RigidBodyState state() const = 0;
  // The body's surface where it is now, for the frames (surface_mesh.hpp).
  virtual SurfaceMesh surface(const ModelExtent& model, const SurfaceMeshResolution& resolution) const = 0;
  // Checkpoints (RigidBodySet::save): what the body is, and its state.
  virtual RigidBodyDescription description() const = 0;
  virtual void save(io::BinaryWriter& out) const = 0;
  virtual void load(io::BinaryReader& in) = 0;
  const ParticleContactLoads& loads() const { return loads_; }
  // The terms of chunk `chunk` of the last evaluation, in index order.
  std::vector<ContactTerm>& terms(std::size_t chunk) { return chunk_terms_[chunk]; }
  const std::vector<std::vector<ContactTerm>>& chunk_terms() const { return chunk_terms_; }

 protected:
  ParticleContactLoads loads_;
  std::vector<std::vector<ContactTerm>> chunk_terms_;  // per chunk; cleared, not freed, each step
};

template <class Shape, class Motion>
class BodyContactOf final : public BodyContact {
 public:
  BodyContactOf(RigidBody<Shape, Motion> body, const PenaltyOptions& options, const ContactParticles& particles,
                double time_step)
      : body_(std::move(body)), contact_(options) {
    contact_.prepare(particles, time_step, loads_);
  }

  void prepare(std::size_t chunk_count) override {
    chunk_terms_.resize(chunk_count);
    for (std::vector<ContactTerm>& terms : chunk_terms_) terms.clear();
  }

  void compute_range(const ContactParticles& particles, double time_step, std::size_t chunk, std::size_t first,
                     std::size_t last) override {
    chunk_terms_[chunk].clear();
    contact_.compute_terms(particles, body_, time_step, loads_, first, last, chunk_terms_[chunk]);
  }

  void finish_step(const ContactStepResult& total, const StepTime& at, double time_step, double velocity_step,
                   double& body_work, double& contact_second_half) override {
    const Vector3 old_velocity = body_.velocity();
    const Vector3 old_angular_velocity = body_.angular_velocity();
    const double old_kinetic = kinetic_energy();
    body_.clear_contact_load();
    body_.add_contact_load(total.body_force, total.body_moment);
    body_.advance(at, time_step);
    contacts_ = total.contacts;
    // The contact's work on the body over the step, as the books count a particle's.
    contact_second_half =
        0.5 * velocity_step * (total.body_force.dot(body_.velocity()) + total.body_moment.dot(body_.angular_velocity()));
    const double contact_work =
        0.5 * velocity_step * (total.body_force.dot(old_velocity) + total.body_moment.dot(old_angular_velocity)) +
        contact_second_half;
    if constexpr (Motion::free) {
      body_work = velocity_step * body_.motion().mass() *
                  body_.motion().gravity().dot(0.5 * (old_velocity + body_.velocity()));
    } else {
      body_work = kinetic_energy() - old_kinetic - contact_work;
    }
  }

  RigidBodyState state() const override {
    RigidBodyState state;
    state.kinematics = body_.kinematics();
    state.contact_force = body_.contact_force();
    state.contact_moment = body_.contact_moment();
    state.contact_impulse = body_.contact_impulse();
    state.contacts = contacts_;
    state.kinetic_energy = kinetic_energy();
    return state;
  }

  SurfaceMesh surface(const ModelExtent& model, const SurfaceMeshResolution& resolution) const override {
    return place_surface_mesh(body_, model, resolution);
  }

  RigidBodyDescription description() const override {
    RigidBodyDescription description{shape_kind<Shape>(), motion_kind<Motion>(), 0.0};
    if constexpr (Motion::free) description.mass = body_.motion().mass();
    return description;
  }
  // The body's state, its contact history and the particles it touched in
  // the last step; the chunks' terms are rewritten by every step before use.
  void save(io::BinaryWriter& out) const override {
    body_.save(out);
    contact_.save(out);
    out(static_cast<std::uint64_t>(contacts_));
  }
  void load(io::BinaryReader& in) override {
    body_.load(in);
    contact_.load(in);
    std::uint64_t contacts = 0;
    in(contacts);
    contacts_ = static_cast<std::size_t>(contacts);
  }

  // ½ m |v|² + ½ Σ I_k ω_k² (body frame); a body that is not free has no mass here.
  double kinetic_energy() const {
    if constexpr (Motion::free) {
      double energy = 0.5 * body_.motion().mass() * body_.velocity().squaredNorm();
      if constexpr (RigidBody<Shape, Motion>::rotates) {
        const Vector3 omega = body_.orientation().conjugate() * body_.angular_velocity();
        energy += 0.5 * body_.motion().principal_inertia().dot(omega.cwiseProduct(omega));
      }
      return energy;
    } else {
      return 0.0;
    }
  }

  const RigidBody<Shape, Motion>& body() const { return body_; }

 private:
  RigidBody<Shape, Motion> body_;
  PenaltyContact contact_;
  std::size_t contacts_ = 0;
};

}  // namespace detail

class RigidBodySet {
 public:
  bool empty() const { return bodies_.empty(); }
  std::size_t size() const { return bodies_.size(); }
  // Whether a step has contact to evaluate: bodies, or the shell's self contact.
  bool active() const { return !bodies_.empty() || shell_contact_ != nullptr; }

  // The shell's contact with itself (shell_contact.hpp), stepped with the
  // bodies: computed by compute_shell_contact() after prepare(), its loads go
  // to the particles in load_chunk(), its work and spring energy into the
  // same books. Once per run.
  void enable_shell_contact(const ShellModel& model, const ShellContactOptions& options,
                            double rotary_inertia_scale = 1.0) {
    if (shell_contact_)
      sphshell::detail::invalid_parameter("enable_shell_contact", "a second call", "the shell contact is enabled once");
    shell_contact_ = std::make_unique<ShellContact>(model, options, rotary_inertia_scale);
    old_velocity_.resize(model.particle_count());
    old_angular_velocity_.resize(model.particle_count());
  }
  // Null unless enabled.
  const ShellContact* shell_contact() const { return shell_contact_.get(); }
  // The shell contact's loads of the last step, per particle (local numbering).
  const ParticleContactLoads& shell_contact_loads() const { return shell_loads_; }

  // Where a body would start inside the shell: the particle (its global id)
  // and the body's signed distance there.
  struct StartInside {
    long particle = 0;
    double gap = 0.0;
    double half_thickness = 0.0;
  };
  // The particle of lowest global id among this process's [0, owned) where
  // `body` lies deeper in the shell than the particle's half thickness (the
  // contact would throw the particle out at once), if any.
  template <class Shape, class Motion, class GlobalOf>
  static std::optional<StartInside> start_inside(const RigidBody<Shape, Motion>& body,
                                                 const ContactParticles& particles, std::size_t owned,
                                                 GlobalOf&& global_of) {
    std::optional<StartInside> found;
    for (std::size_t i = 0; i < owned; ++i) {
      const double gap = body.proximity(particles.position[i]).gap;
      const double half_thickness = 0.5 * particles.thickness[i];
      const long particle = static_cast<long>(global_of(i));
      if (gap < -half_thickness && (!found || particle < found->particle))
        found = StartInside{particle, gap, half_thickness};
    }
    return found;
  }
  // The Error of a body that starts inside the shell (the next body's id).
  [[noreturn]] void refuse_start_inside(const StartInside& inside) const {
    sphshell::detail::invalid_parameter("rigid body " + std::to_string(bodies_.size()) + " initial gap at particle " +
                                            std::to_string(inside.particle),
                                        inside.gap,
                                        "must be at least minus half the thickness (" +
                                            std::to_string(-inside.half_thickness) +
                                            " m): the body starts inside the shell");
  }

  // A body in contact with the particles (local numbering: a process's owned
  // particles, then its ghosts). The caller has refused a body that starts
  // inside the shell (start_inside).
  template <class Shape, class Motion>
  RigidBodyId add(RigidBody<Shape, Motion> body, const PenaltyOptions& options, const ContactParticles& particles,
                  double time_step) {
    validate(options);
    auto pair = std::make_unique<detail::BodyContactOf<Shape, Motion>>(std::move(body), options, particles, time_step);
    energy_.body_work += pair->kinetic_energy();  // the initial kinetic energy is put in from outside
    energy_.body_kinetic += pair->kinetic_energy();
    bodies_.push_back(std::move(pair));
    old_velocity_.resize(particles.position.size());
    old_angular_velocity_.resize(particles.position.size());
    return bodies_.size() - 1;
  }

  // Before the particle pass: the particles (the solver's arrays), where the
  // contact loads go, and the pass's chunk count.
  void prepare(const ContactParticles& particles, std::vector<Vector3>& external_force,
               std::vector<Vector3>& external_moment, double time_step, std::size_t chunk_count) {
    particles_ = std::make_unique<ContactParticles>(particles);
    external_force_ = &external_force;
    external_moment_ = &external_moment;
    time_step_ = time_step;
    for (auto& body : bodies_) body->prepare(chunk_count);
    shell_chunk_terms_.resize(chunk_count);
    for (std::vector<ContactTerm>& terms : shell_chunk_terms_) terms.clear();
  }

  // After prepare(), with the shell contact enabled: its loads at
  // configuration n. `whole` is every particle of the model, numbered
  // globally (one process's own arrays; a distributed run's gathered
  // positions and directors: the contact reads positions, directors, masses
  // and thicknesses, and a fold's far side is no ghost of a process), so
  // every process computes what one process would; the loads of its `local`
  // particles (global_of numbers them) are kept.
  template <class GlobalOf>
  void compute_shell_contact(const ContactParticles& whole, double time_step, std::size_t local,
                             GlobalOf&& global_of) {
    shell_result_ = shell_contact_->compute(whole, time_step, shell_whole_loads_);
    shell_loads_.force.resize(local);
    shell_loads_.moment.resize(local);
    for (std::size_t i = 0; i < local; ++i) {
      const auto g = static_cast<std::size_t>(global_of(i));
      shell_loads_.force[i] = shell_whole_loads_.force[g];
      shell_loads_.moment[i] = shell_whole_loads_.moment[g];
    }
  }

  // In the pass, after the chunk's loads: the bodies' contact loads added to them.
  void load_chunk(std::size_t chunk, std::size_t first, std::size_t last) noexcept {
    const ContactParticles& particles = *particles_;
    for (std::size_t i = first; i < last; ++i) {
      old_velocity_[i] = particles.velocity[i];
      old_angular_velocity_[i] = particles.angular_velocity[i];
    }
    for (auto& body : bodies_) {
      body->compute_range(particles, time_step_, chunk, first, last);
      const ParticleContactLoads& loads = body->loads();
      for (std::size_t i = first; i < last; ++i) {
        (*external_force_)[i] += loads.force[i];
        (*external_moment_)[i] += loads.moment[i];
      }
    }
    if (shell_contact_)
      for (std::size_t i = first; i < last; ++i) {
        (*external_force_)[i] += shell_loads_.force[i];
        (*external_moment_)[i] += shell_loads_.moment[i];
      }
  }

  // In the pass, after the velocities are final (kinematic conditions imposed):
  // the contact forces' work on the chunk's particles over the step, per
  // particle (a particle without a body's term has no load from it).
  void book_chunk(std::size_t chunk, std::size_t first, std::size_t last, double velocity_step) noexcept {
    const ContactParticles& particles = *particles_;
    const auto first_half = [&](const ParticleContactLoads& loads, std::size_t i) {
      return 0.5 * velocity_step *
             (loads.force[i].dot(old_velocity_[i]) + loads.moment[i].dot(old_angular_velocity_[i]));
    };
    const auto second_half = [&](const ParticleContactLoads& loads, std::size_t i) {
      return 0.5 * velocity_step *
             (loads.force[i].dot(particles.velocity[i]) + loads.moment[i].dot(particles.angular_velocity[i]));
    };
    for (const auto& body : bodies_)
      for (ContactTerm& term : body->terms(chunk)) {
        const auto i = static_cast<std::size_t>(term.particle);
        term.work_first_half = first_half(body->loads(), i);
        term.work_second_half = second_half(body->loads(), i);
      }
    if (shell_contact_)
      for (std::size_t i = first; i < last; ++i)
        if ((shell_loads_.force[i].array() != 0.0).any() || (shell_loads_.moment[i].array() != 0.0).any()) {
          ContactTerm term;
          term.particle = static_cast<std::int64_t>(i);
          term.work_first_half = first_half(shell_loads_, i);
          term.work_second_half = second_half(shell_loads_, i);
          shell_chunk_terms_[chunk].push_back(term);
        }
  }

  // After the pass (which did not fail): the bodies move, the books add the
  // step. Every process passes the terms of the particles it owns, and
  // `gather` (std::vector<ContactTerm> → std::vector<ContactTerm>) returns
  // those of all processes; `global_of` numbers a local particle globally.
  // The sums are then formed from the terms in one fixed order, the order of
  // one process's particle pass: within the chunks of `particles_per_chunk`
  // particles (ParticleEnergyTerms::sum_chunk) in index order, body by body
  // (the shell contact's work last, as if it were one more body), then chunk
  // by chunk. So every process moves the bodies alike, by the same bits as
  // one process would, whatever the split of the particles between
  // processes and threads. A particle without a term adds ±0 to a sum that
  // is never −0: nothing.
  template <class GlobalOf, class Gather>
  void finish_step(const StepTime& at, double time_step, double velocity_step, std::size_t particles_per_chunk,
                   GlobalOf&& global_of, Gather&& gather) {
    std::size_t term_count = 0;
    for (const auto& body : bodies_)
      for (const std::vector<ContactTerm>& chunk : body->chunk_terms()) term_count += chunk.size();
    for (const std::vector<ContactTerm>& chunk : shell_chunk_terms_) term_count += chunk.size();
    std::vector<ContactTerm> mine;
    mine.reserve(term_count);
    for (std::size_t b = 0; b < bodies_.size(); ++b)
      for (const std::vector<ContactTerm>& chunk : bodies_[b]->chunk_terms())
        for (ContactTerm term : chunk) {
          term.particle = static_cast<std::int64_t>(global_of(static_cast<std::size_t>(term.particle)));
          term.body = static_cast<std::int64_t>(b);
          mine.push_back(term);
        }
    const auto shell = static_cast<std::int64_t>(bodies_.size());
    for (const std::vector<ContactTerm>& chunk : shell_chunk_terms_)
      for (ContactTerm term : chunk) {
        term.particle = static_cast<std::int64_t>(global_of(static_cast<std::size_t>(term.particle)));
        term.body = shell;
        mine.push_back(term);
      }
    std::vector<ContactTerm> terms = gather(std::move(mine));
    const auto chunk_of = [&](const ContactTerm& term) {
      return static_cast<std::size_t>(term.particle) / particles_per_chunk;
    };
    // Each body's sums: a sum per chunk in index order, the chunks' sums in
    // chunk order (PenaltyContact::accumulate). A chunk without terms adds
    // nothing (its sums are +0, and none of these sums is −0).
    // (body, particle) is unique, so a sort gives the one order whatever the
    // input's; one process's terms arrive in it already, and the check alone runs.
    const auto sorted_by = [&terms](auto&& before) {
      if (!std::is_sorted(terms.begin(), terms.end(), before)) std::sort(terms.begin(), terms.end(), before);
    };
    sorted_by([](const ContactTerm& a, const ContactTerm& b) {
      return a.body != b.body ? a.body < b.body : a.particle < b.particle;
    });
    std::vector<ContactStepResult> totals(bodies_.size());
    for (std::size_t k = 0; k < terms.size() && terms[k].body != shell;) {
      ContactStepResult chunk_sum;
      const std::int64_t body = terms[k].body;
      const std::size_t chunk = chunk_of(terms[k]);
      for (; k < terms.size() && terms[k].body == body && chunk_of(terms[k]) == chunk; ++k)
        PenaltyContact::add(chunk_sum, terms[k]);
      PenaltyContact::accumulate(totals[static_cast<std::size_t>(body)], chunk_sum);
    }
    double spring = 0.0, kinetic = 0.0, second_half = 0.0;
    for (std::size_t b = 0; b < bodies_.size(); ++b) {
      double body_work = 0.0, body_second_half = 0.0;
      const ContactStepResult& result = totals[b];
      bodies_[b]->finish_step(result, at, time_step, velocity_step, body_work, body_second_half);
      spring += result.spring_energy;
      second_half += body_second_half;
      energy_.friction_dissipation += result.friction_dissipation;
      energy_.body_work += body_work;
      kinetic += bodies_[b]->state().kinetic_energy;
    }
    if (shell_contact_) spring += shell_result_.spring_energy;
    // The contact forces' work on the particles: a sum per chunk (the bodies'
    // terms in body and index order, then the shell contact's), the chunks'
    // sums in chunk order.
    sorted_by([&](const ContactTerm& a, const ContactTerm& b) {
      const std::size_t chunk_a = chunk_of(a), chunk_b = chunk_of(b);
      if (chunk_a != chunk_b) return chunk_a < chunk_b;
      return a.body != b.body ? a.body < b.body : a.particle < b.particle;
    });
    for (std::size_t k = 0; k < terms.size();) {
      HalfStepWork work;
      const std::size_t chunk = chunk_of(terms[k]);
      for (; k < terms.size() && chunk_of(terms[k]) == chunk; ++k) {
        work.first_half += terms[k].work_first_half;
        work.second_half += terms[k].work_second_half;
      }
      energy_.shell_contact_work += work.first_half + work.second_half;
      second_half += work.second_half;
    }
    // The springs' energy at n+½, where the books' kinetic energies are: the
    // energy at n less the contact's work over the step's second half.
    energy_.spring = spring - second_half;
    energy_.body_kinetic = kinetic;
  }

  const ContactEnergy& energy() const { return energy_; }

  // Checkpoints (solver/checkpoint_io.hpp). First what the bodies are, which
  // a loading solver checks before it changes anything: the count, then each
  // body's description, in the order added.
  void save_descriptions(io::BinaryWriter& out) const {
    out.write_size(bodies_.size());
    for (const auto& body : bodies_) {
      const RigidBodyDescription d = body->description();
      out(d.shape, d.motion, d.mass);
    }
  }
  // An Error naming the checkpoint and the first difference, if its bodies
  // are not this run's.
  void check_descriptions(io::BinaryReader& in, const std::string& path) const {
    const std::string lead = "sphshell: checkpoint '" + path + "' ";
    const std::string fix = ": add the checkpoint's bodies, in the order it had them, before loading it";
    std::uint64_t count = 0;
    in(count);
    if (count != bodies_.size())
      throw Error(lead + "has " + std::to_string(count) + " rigid bodies and this solver " +
                  std::to_string(bodies_.size()) + fix);
    for (std::size_t id = 0; id < bodies_.size(); ++id) {
      RigidBodyDescription file;
      in(file.shape, file.motion, file.mass);
      const RigidBodyDescription here = bodies_[id]->description();
      const std::string body = "rigid body " + std::to_string(id);
      if (file.shape != here.shape || file.motion != here.motion)
        throw Error(lead + "has a " + file.motion + " " + file.shape + " as " + body + " and this solver a " +
                    here.motion + " " + here.shape + fix);
      if (std::memcmp(&file.mass, &here.mass, sizeof(double)) != 0)
        throw Error(lead + "has " + body + " of mass " + std::to_string(file.mass) + " kg and this solver of " +
                    std::to_string(here.mass) + " kg" + fix);
    }
  }
  // Then their state: every body's, and the energy terms of bodies and contact.
  void save(io::BinaryWriter& out) const {
    for (const auto& body : bodies_) body->save(out);
    out(energy_.body_kinetic, energy_.spring, energy_.friction_dissipation, energy_.shell_contact_work,
        energy_.body_work);
    // The shell contact's pair history (a run without it writes nothing more).
    if (shell_contact_) shell_contact_->save(out);
  }
  void load(io::BinaryReader& in) {
    for (auto& body : bodies_) body->load(in);
    in(energy_.body_kinetic, energy_.spring, energy_.friction_dissipation, energy_.shell_contact_work,
       energy_.body_work);
    // The history is there exactly when the saving run had the shell contact
    // (a file of a library from before the history was kept has none either).
    if (shell_contact_ && in.at_end())
      in.fail("it holds no shell contact pair history (the side of each pair), which this solver's shell contact "
              "needs: it was written by a run without enable_shell_contact(), or by a library that did not save "
              "the pairs' sides; restart without the shell contact or from a checkpoint written with it");
    if (!shell_contact_ && !in.at_end())
      in.fail("it holds a shell contact pair history and this solver has no shell contact: call "
              "enable_shell_contact() before loading it");
    if (shell_contact_) shell_contact_->load(in);
  }

  RigidBodyState state(RigidBodyId id) const {
    check(id);
    return bodies_[id]->state();
  }

  // Body `id`'s surface where it is now (world frame): a plane's patch sized
  // to the model, whose extent is that of `positions` (the shell's particles).
  SurfaceMesh surface(RigidBodyId id, const std::vector<Vector3>& positions,
                      const SurfaceMeshResolution& resolution = {}) const {
    check(id);
    ModelExtent model;
    if (!positions.empty()) model.lower = model.upper = positions.front();
    for (const Vector3& x : positions) {
      model.lower = model.lower.cwiseMin(x);
      model.upper = model.upper.cwiseMax(x);
    }
    return bodies_[id]->surface(model, resolution);
  }

  // An Error unless `id` is a body of this run.
  void check(RigidBodyId id) const {
    if (id >= bodies_.size())
      sphshell::detail::invalid_parameter("rigid body id", id,
                                          "must be below the number of bodies added (" +
                                              std::to_string(bodies_.size()) + ")");
  }

 private:
  std::vector<std::unique_ptr<detail::BodyContact>> bodies_;
  std::unique_ptr<ShellContact> shell_contact_;  // null: no self contact
  ParticleContactLoads shell_loads_;        // local numbering
  ParticleContactLoads shell_whole_loads_;  // every particle of the model
  std::vector<std::vector<ContactTerm>> shell_chunk_terms_;  // its work, per chunk of the pass
  ContactStepResult shell_result_;
  std::unique_ptr<ContactParticles> particles_;  // the solver's arrays, this step
  std::vector<Vector3>* external_force_ = nullptr;
  std::vector<Vector3>* external_moment_ = nullptr;
  double time_step_ = 0.0;
  std::vector<Vector3> old_velocity_, old_angular_velocity_;
  // The contact forces' work on particles over the halves of the step,
  // f^n · Δt_v v^{n−½}/2 and f^n · Δt_v v^{n+½}/2.
  struct HalfStepWork {
    double first_half = 0.0, second_half = 0.0;
  };

  ContactEnergy energy_;
};

}  // namespace sphshell::contact
