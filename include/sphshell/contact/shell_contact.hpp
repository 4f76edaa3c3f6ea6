#pragma once
// Penalty contact of a shell with itself: two shells of one model, or two far
// parts of one shell (the folds of a crushed tube), pushed apart when their
// faces meet. The Solver plugs it in with enable_shell_contact(); the rigid
// body set (body_set.hpp) adds its loads in the particle pass and books its
// work and spring energy with the rigid contacts'.
//
// Geometry. A particle a is a point of the mid-surface; the shell it stands
// for is the tangent plane through it (normal d_a, the unit director) out to
// a patch radius r_a = patch_spacings · Δ_a (Δ_a its local spacing,
// solver/local_spacing.hpp), with faces h_a/2 to either side. A particle a
// meets particle b's patch when, with r = x_a − x_b and g = r · d_b its
// distance from b's mid-plane,
//   |r − g d_b| ≤ r_b       (a lies over b's patch) and
//   |g| < (h_a + h_b)/2     (the mid-surfaces are closer than the two half thicknesses):
// penetration δ = (h_a + h_b)/2 − |g|, normal n = sign(g) d_b (from b towards a).
// A particle a meets the surface as a weighted mean of the patches it lies
// over (node against surface, as a penalty contact's slave node against its
// master segments), so that its force changes continuously as it slides from
// patch to patch (taking the nearest patch alone made the penetration jump by
// the surface's sag over a spacing, κ Δ²/8, at each change: energy put in at
// every switch, enough to blow a folding tube apart). Patch b's weight is
//   w_b = (1 − ρ²/r_b²)² · w_n(|g|),  w_n = 1 for |g| ≤ c, (1 − ((|g| − c)/c)²)²
//   up to 2c, 0 beyond  (ρ = |r − g d_b|, c = (h_a + h_b)/2),
// so a patch enters and leaves with weight 0 both sideways and along its normal;
// pair ab carries the share w_b / Σ w of a's spring. Every particle plays both
// parts (a symmetric contact): on two matching sheets a pair is met twice.
// At most max_patches_per_particle patches count per particle (the first in
// the search's order): a sheet's patches of radius 0.75 Δ overlap at most four
// deep, two sheets' eight.
//
// Material neighbours never touch: particle a's neighbours are the particles
// connected to it through the model's cells (corners of a common cell, step
// by step) without leaving the reference ball of radius exclusion_spacings ·
// max(Δ_a, Δ_b) about it. So the particles of one sheet next to each other
// (mid-surfaces 0 apart) exert nothing on each other, while the far side of a
// fold, beyond that reach along the shell, does, and so does another shell of
// the model however close it starts (it shares no cell). A model without
// cells (the general constructor) has no connectivity: there every particle
// within the reference ball is a neighbour. exclusion_spacings must exceed
// patch_spacings: then a particle of a flat sheet lies over no patch of its
// own sheet that is not excluded.
//
// Forces. The pair's spring k = s m_ab / Δt² (penalty.hpp's rule, with the
// reduced mass m_ab = m_a m_b / (m_a + m_b): the pair oscillates at ω Δt = √s)
// and share w gives f = w k δ n on a, −f on b and, on b's rotation, the
// moment M_b = (x_a − x_b) × (−f): the force on b acts where a meets b's
// patch, not at x_b. That moment is what makes the pair's spring conservative:
// δ depends on b's director through g = r · d_b, and turning d_b by θ changes
// ½ k δ² by −θ · M_b (without it, the folds of a crushed tube gained energy
// from the springs until the run blew up). The forces are exactly opposite,
// so they sum to zero in floating point (momentum is conserved to
// round-off), and with M_b the pair conserves angular momentum too. The
// spring's mass is the pair's effective mass at the contact point,
// 1/m_ab = 1/m_a + 1/m_b + ρ²/I_b (I_b = s_I m_b h_b²/12, the solver's rotary
// inertia, docs/method.md §1; ρ the lateral offset, b's rotation moving the
// patch under a by ρ θ), so the pair oscillates at ω Δt = √s whatever arm it
// acts on. The thickness offsets are in the gap. A particle carries the
// shares of its own spring (summing to 1) and of the springs of the particles
// that meet its patch: with the default s = 0.1 a few leave (ω Δt)² well
// below the 4 the central difference allows beside the shell's 2.56
// (penalty.hpp). No friction: the contact is frictionless.
//
// Search: a cell list (approx/neighbour_search.hpp) rebuilt from the current
// positions every step, with cells as wide as the farthest a patch can weigh
// from, √((2 h_max)² + (patch_spacings Δ_max)²): each particle visits the 27 cells
// around it, so a step costs O(N). candidate_pairs() counts the pairs within
// that reach (each ordered pair once), the work the search does per step.
//
// Energy: the spring energy Σ ½ k δ² at configuration n; its work on the
// shell is the shell's external work, booked by the body set like the rigid
// contacts'.

#include <sphshell/approx/neighbour_search.hpp>
#include <sphshell/contact/penalty.hpp>
#include <sphshell/core/error.hpp>
#include <sphshell/core/parallel.hpp>
#include <sphshell/core/types.hpp>
#include <sphshell/shell/cell.hpp>
#include <sphshell/shell/model.hpp>
#include <sphshell/solver/local_spacing.hpp>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <iterator>
#include <limits>
#include <string>
#include <vector>

namespace sphshell::contact {

// A patch reaches 0.75 spacings from its particle: beyond the 1/√2 ≈ 0.71 of
// a square grid's cell centre, so a particle over any point of a regular sheet
// meets a patch, and not much beyond a sheet's edge.
inline constexpr double default_patch_spacings = 0.75;
// Material neighbours: within 3 spacings in the reference configuration,
// beyond the solver's default support radius (2 spacings,
// SolverOptions::support_radius_factor).
inline constexpr double default_exclusion_spacings = 3.0;
// Patches that count per particle (see the header comment).
inline constexpr std::size_t max_patches_per_particle = 8;

struct ShellContactOptions {
  double stiffness_scale = default_penalty_stiffness_scale;  // s in k = s m_ab / Δt², 0 < s < 4
  double patch_spacings = default_patch_spacings;            // patch radius / local spacing, > 0
  double exclusion_spacings = default_exclusion_spacings;    // material neighbour reach / local spacing, > patch_spacings
};

inline void validate(const ShellContactOptions& options) {
  sphshell::detail::require_open_interval("shell contact stiffness_scale", options.stiffness_scale, 0.0,
                                          penalty_stiffness_scale_bound);
  sphshell::detail::require_positive("shell contact patch_spacings", options.patch_spacings);
  sphshell::detail::require_positive("shell contact exclusion_spacings", options.exclusion_spacings);
  if (!(options.exclusion_spacings > options.patch_spacings))
    sphshell::detail::invalid_parameter("shell contact exclusion_spacings", options.exclusion_spacings,
                                        "must exceed patch_spacings (" + std::to_string(options.patch_spacings) +
                                            "): a particle would meet its own sheet's patches");
}

// One particle's contact with a patch it meets.
struct ShellContactPair {
  int partner = -1;             // b, whose patch a meets
  double stiffness = 0.0;       // w k, the share of a's spring this pair carries (N/m)
  double penetration = 0.0;     // δ = (h_a + h_b)/2 − |g| (m), 0 where the patch only weighs
  Vector3 force = Vector3::Zero();  // on a; −force on b
  Vector3 partner_moment = Vector3::Zero();  // on b's rotation, (x_a − x_b) × (−force)
};

// What the last evaluation found.
struct ShellContactStatistics {
  std::size_t contacts = 0;         // particles meeting a patch
  std::size_t candidate_pairs = 0;  // ordered pairs within the search reach
  double largest_penetration = 0.0; // max δ (m)
  double spring_energy = 0.0;       // Σ ½ k δ² (J)
};

class ShellContact {
 public:
  // The model's reference positions, local spacings and thicknesses; the
  // particles' current state comes with every compute().
  // rotary_inertia_scale: the solver's s_I (SolverOptions::rotary_inertia_scale).
  ShellContact(const ShellModel& model, const ShellContactOptions& options, double rotary_inertia_scale = 1.0)
      : options_(options), rotary_inertia_scale_(rotary_inertia_scale) {
    validate(options_);
    if (!(rotary_inertia_scale >= 1.0) || !std::isfinite(rotary_inertia_scale))
      sphshell::detail::invalid_parameter("shell contact rotary_inertia_scale", rotary_inertia_scale,
                                          "must be finite and >= 1");
    reference_ = model.particle_position;
    spacing_ = solver::local_spacing(model).particle;
    const std::vector<double>& thickness = model.particle_thicknesses();
    double largest_thickness = 0.0, largest_spacing = 0.0;
    for (std::size_t i = 0; i < reference_.size(); ++i) {
      if (!(thickness[i] > 0.0) || !std::isfinite(thickness[i]))
        sphshell::detail::invalid_parameter("shell contact: thickness of particle " + std::to_string(i),
                                            thickness[i], "must be finite and > 0 (the faces are h/2 from the mid-surface)");
      largest_thickness = std::max(largest_thickness, thickness[i]);
      largest_spacing = std::max(largest_spacing, spacing_[i]);
    }
    reach_ = std::hypot(2.0 * largest_thickness, options_.patch_spacings * largest_spacing);
    find_material_neighbours(model);
  }

  const ShellContactOptions& options() const { return options_; }
  // How far a particle's search reaches (the cell width), m.
  double search_reach() const { return reach_; }

  // The contact at configuration n: every particle's loads (zero where there
  // is none) and the step's sums. Loads are summed in particle order, the same
  // bits for any thread count.
  ContactStepResult compute(const ContactParticles& particles, double time_step, ParticleContactLoads& loads) {
    sphshell::detail::require_positive("time step", time_step);
    const std::size_t count = particles.position.size();
    if (count != reference_.size())
      sphshell::detail::invalid_parameter("shell contact particle count", count,
                                          "must equal the model's " + std::to_string(reference_.size()));
    pairs_.assign(count * max_patches_per_particle, ShellContactPair{});
    pair_count_.assign(count, 0);
    candidates_.assign(count, 0);
    const approx::CellList cells(particles.position, reach_);
    parallel::for_each_range(std::size_t{0}, count, [&](std::size_t first, std::size_t last) noexcept {
      for (std::size_t a = first; a < last; ++a) find_pairs(particles, cells, time_step, a);
    });
    loads.force.assign(count, Vector3::Zero());
    loads.moment.assign(count, Vector3::Zero());
    ContactStepResult result;
    statistics_ = ShellContactStatistics{};
    for (std::size_t a = 0; a < count; ++a) {
      statistics_.candidate_pairs += candidates_[a];
      bool touches = false;
      for (std::size_t k = 0; k < pair_count_[a]; ++k) {
        const ShellContactPair& pair = pairs_[a * max_patches_per_particle + k];
        if (!(pair.penetration > 0.0)) continue;
        const auto b = static_cast<std::size_t>(pair.partner);
        loads.force[a] += pair.force;
        loads.force[b] -= pair.force;
        loads.moment[b] += pair.partner_moment;
        result.spring_energy += 0.5 * pair.stiffness * pair.penetration * pair.penetration;
        statistics_.largest_penetration = std::max(statistics_.largest_penetration, pair.penetration);
        touches = true;
      }
      if (touches) ++result.contacts;
    }
    statistics_.contacts = result.contacts;
    statistics_.spring_energy = result.spring_energy;
    return result;
  }

  const ShellContactStatistics& statistics() const { return statistics_; }
  // Particle a's pairs of the last compute(): the patches it weighs (those
  // with penetration 0 carry no force).
  std::vector<ShellContactPair> pairs_of(std::size_t a) const {
    const auto first = pairs_.begin() + static_cast<std::ptrdiff_t>(a * max_patches_per_particle);
    return {first, first + static_cast<std::ptrdiff_t>(pair_count_.at(a))};
  }

 private:
  void find_pairs(const ContactParticles& particles, const approx::CellList& cells, double time_step,
                  std::size_t a) noexcept {
    const Vector3& xa = particles.position[a];
    const double half_a = 0.5 * particles.thickness[a];
    ShellContactPair* pairs = &pairs_[a * max_patches_per_particle];
    double weights[max_patches_per_particle];
    std::size_t found = 0, candidates = 0;
    double weight_sum = 0.0;
    cells.for_each_within(xa, reach_, [&](int j, double distance_squared) {
      const auto b = static_cast<std::size_t>(j);
      if (b == a) return;
      ++candidates;
      if (found == max_patches_per_particle || is_material_neighbour(a, j)) return;
      const Vector3& db = particles.director[b];
      const double gap = (xa - particles.position[b]).dot(db);
      const double lateral_squared = std::max(0.0, distance_squared - gap * gap);
      const double patch = options_.patch_spacings * spacing_[b];
      if (!(lateral_squared < patch * patch)) return;
      const double contact_distance = half_a + 0.5 * particles.thickness[b];
      const double distance = std::abs(gap);
      if (!(distance < 2.0 * contact_distance)) return;
      const double sideways = 1.0 - lateral_squared / (patch * patch);
      double along = 1.0;
      if (distance > contact_distance) {
        const double beyond = (distance - contact_distance) / contact_distance;
        along = (1.0 - beyond * beyond) * (1.0 - beyond * beyond);
      }
      const double weight = sideways * sideways * along;
      ShellContactPair& pair = pairs[found];
      pair.partner = j;
      pair.penetration = std::max(0.0, contact_distance - distance);
      const double mass_b = particles.mass[b], thickness_b = particles.thickness[b];
      const double rotary_inertia_b = rotary_inertia_scale_ * mass_b * thickness_b * thickness_b / 12.0;
      const double compliance = 1.0 / particles.mass[a] + 1.0 / mass_b + lateral_squared / rotary_inertia_b;
      pair.stiffness = penalty_stiffness(1.0 / compliance, time_step, options_.stiffness_scale);
      // The normal from b towards a; the arm of b's moment, x_a − x_b.
      pair.force = gap >= 0.0 ? Vector3(db) : Vector3(-db);
      pair.partner_moment = xa - particles.position[b];
      weights[found] = weight;
      weight_sum += weight;
      ++found;
    });
    candidates_[a] = candidates;
    pair_count_[a] = found;
    for (std::size_t k = 0; k < found; ++k) {
      ShellContactPair& pair = pairs[k];
      pair.stiffness *= weight_sum > 0.0 ? weights[k] / weight_sum : 0.0;
      pair.force *= pair.stiffness * pair.penetration;
      pair.partner_moment = pair.partner_moment.cross(Vector3(-pair.force));
    }
  }

  // Whether a and b (a ≠ b) lie within the reference ball of either's reach.
  bool within_exclusion(std::size_t a, std::size_t b) const {
    const double exclusion = options_.exclusion_spacings * std::max(spacing_[a], spacing_[b]);
    return (reference_[a] - reference_[b]).squaredNorm() < exclusion * exclusion;
  }

  // Each particle's material neighbours (see the header comment), sorted, as
  // offsets into one array; a walk over the cells from each particle, kept
  // inside its reference ball. Once, at set-up: O(N) times the ball's size.
  void find_material_neighbours(const ShellModel& model) {
    const std::size_t count = reference_.size();
    neighbour_begin_.assign(count + 1, 0);
    neighbours_.clear();
    if (model.cells().empty()) {
      const double largest = *std::max_element(spacing_.begin(), spacing_.end());
      const approx::CellList cells(reference_, options_.exclusion_spacings * largest);
      for (std::size_t a = 0; a < count; ++a) {
        const std::size_t first = neighbours_.size();
        cells.for_each_within(reference_[a], options_.exclusion_spacings * largest, [&](int j, double) {
          if (static_cast<std::size_t>(j) != a && within_exclusion(a, static_cast<std::size_t>(j)))
            neighbours_.push_back(j);
        });
        std::sort(neighbours_.begin() + static_cast<std::ptrdiff_t>(first), neighbours_.end());
        neighbour_begin_[a + 1] = neighbours_.size();
      }
      return;
    }
    // Particles sharing a cell, per particle.
    std::vector<std::vector<int>> adjacent(count);
    for (const Cell& cell : model.cells())
      for (int i : cell)
        for (int j : cell)
          if (i != j) adjacent[static_cast<std::size_t>(i)].push_back(j);
    std::vector<char> reached(count, 0);
    std::vector<int> front;
    for (std::size_t a = 0; a < count; ++a) {
      const std::size_t first = neighbours_.size();
      front.assign(1, static_cast<int>(a));
      reached[a] = 1;
      for (std::size_t k = 0; k < front.size(); ++k)
        for (int j : adjacent[static_cast<std::size_t>(front[k])]) {
          const auto b = static_cast<std::size_t>(j);
          if (reached[b] || !within_exclusion(a, b)) continue;
          reached[b] = 1;
          front.push_back(j);
          neighbours_.push_back(j);
        }
      for (int j : front) reached[static_cast<std::size_t>(j)] = 0;
      std::sort(neighbours_.begin() + static_cast<std::ptrdiff_t>(first), neighbours_.end());
      neighbour_begin_[a + 1] = neighbours_.size();
    }
  }
  bool is_material_neighbour(std::size_t a, int b) const {
    const auto first = neighbours_.begin() + static_cast<std::ptrdiff_t>(neighbour_begin_[a]);
    const auto last = neighbours_.begin() + static_cast<std::ptrdiff_t>(neighbour_begin_[a + 1]);
    return std::binary_search(first, last, b);
  }

  ShellContactOptions options_;
  double rotary_inertia_scale_ = 1.0;
  std::vector<Vector3> reference_;
  std::vector<std::size_t> neighbour_begin_;
  std::vector<int> neighbours_;
  std::vector<double> spacing_;
  double reach_ = 0.0;
  std::vector<ShellContactPair> pairs_;  // max_patches_per_particle slots per particle
  std::vector<std::size_t> pair_count_;
  std::vector<std::size_t> candidates_;
  ShellContactStatistics statistics_;
};

}  // namespace sphshell::contact
