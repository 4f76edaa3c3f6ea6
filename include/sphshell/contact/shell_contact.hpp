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
// Each particle a takes, of the patches it meets, the nearest one (smallest
// |r|, then the lowest index) — node against surface, as a penalty contact's
// slave node against its master segment — and every particle plays both
// parts (a symmetric contact): on two matching sheets a pair is met twice.
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
// gives f = k δ n on a and −f on b, exactly opposite, so the pair's forces sum
// to zero in floating point (momentum is conserved to round-off). Each acts at
// its particle's face towards the other (offset h/2 along ±d, as the rigid
// contact's), so it also has a moment (c − x) × f on the rotation. A
// particle meeting several patches (and met by several particles) carries
// several springs: with the default s = 0.1 four of them leave (ω Δt)² = 0.4
// of the 4 the central difference allows beside the shell's 2.56
// (penalty.hpp). No friction: the contact is frictionless.
//
// Search: a cell list (approx/neighbour_search.hpp) rebuilt from the current
// positions every step, with cells as wide as the farthest a patch can be met
// from, √(h_max² + (patch_spacings Δ_max)²): each particle visits the 27 cells
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

// One particle's contact with the patch it meets (none: partner < 0).
struct ShellContactPair {
  int partner = -1;             // b, whose patch a meets
  double stiffness = 0.0;       // k (N/m)
  double penetration = 0.0;     // δ (m)
  Vector3 force = Vector3::Zero();        // on a; −force on b
  Vector3 moment = Vector3::Zero();       // on a's rotation
  Vector3 partner_moment = Vector3::Zero();  // on b's rotation
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
  ShellContact(const ShellModel& model, const ShellContactOptions& options) : options_(options) {
    validate(options_);
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
    reach_ = std::hypot(largest_thickness, options_.patch_spacings * largest_spacing);
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
    pairs_.assign(count, ShellContactPair{});
    candidates_.assign(count, 0);
    const approx::CellList cells(particles.position, reach_);
    parallel::for_each_range(std::size_t{0}, count, [&](std::size_t first, std::size_t last) noexcept {
      for (std::size_t a = first; a < last; ++a) pairs_[a] = find_pair(particles, cells, time_step, a);
    });
    loads.force.assign(count, Vector3::Zero());
    loads.moment.assign(count, Vector3::Zero());
    ContactStepResult result;
    statistics_ = ShellContactStatistics{};
    for (std::size_t a = 0; a < count; ++a) {
      statistics_.candidate_pairs += candidates_[a];
      const ShellContactPair& pair = pairs_[a];
      if (pair.partner < 0) continue;
      const auto b = static_cast<std::size_t>(pair.partner);
      loads.force[a] += pair.force;
      loads.force[b] -= pair.force;
      loads.moment[a] += pair.moment;
      loads.moment[b] += pair.partner_moment;
      const double energy = 0.5 * pair.stiffness * pair.penetration * pair.penetration;
      result.spring_energy += energy;
      ++result.contacts;
      statistics_.largest_penetration = std::max(statistics_.largest_penetration, pair.penetration);
    }
    statistics_.contacts = result.contacts;
    statistics_.spring_energy = result.spring_energy;
    return result;
  }

  const ShellContactStatistics& statistics() const { return statistics_; }
  // Each particle's pair of the last compute() (partner < 0: none).
  const std::vector<ShellContactPair>& pairs() const { return pairs_; }

 private:
  ShellContactPair find_pair(const ContactParticles& particles, const approx::CellList& cells, double time_step,
                             std::size_t a) noexcept {
    const Vector3& xa = particles.position[a];
    const double half_a = 0.5 * particles.thickness[a];
    int best = -1;
    double best_distance_squared = std::numeric_limits<double>::infinity();
    double best_gap = 0.0;
    std::size_t candidates = 0;
    cells.for_each_within(xa, reach_, [&](int j, double distance_squared) {
      const auto b = static_cast<std::size_t>(j);
      if (b == a) return;
      ++candidates;
      if (is_material_neighbour(a, j)) return;
      const Vector3 r = xa - particles.position[b];
      const double gap = r.dot(particles.director[b]);
      const double lateral_squared = std::max(0.0, distance_squared - gap * gap);
      const double patch = options_.patch_spacings * spacing_[b];
      if (lateral_squared > patch * patch) return;
      if (!(std::abs(gap) < half_a + 0.5 * particles.thickness[b])) return;
      if (distance_squared < best_distance_squared || (distance_squared == best_distance_squared && j < best)) {
        best = j;
        best_distance_squared = distance_squared;
        best_gap = gap;
      }
    });
    candidates_[a] = candidates;
    ShellContactPair pair;
    if (best < 0) return pair;
    const auto b = static_cast<std::size_t>(best);
    const double half_b = 0.5 * particles.thickness[b];
    const Vector3& db = particles.director[b];
    const Vector3 n = best_gap >= 0.0 ? Vector3(db) : Vector3(-db);
    const double mass_a = particles.mass[a], mass_b = particles.mass[b];
    pair.partner = best;
    pair.stiffness = penalty_stiffness(mass_a * mass_b / (mass_a + mass_b), time_step, options_.stiffness_scale);
    pair.penetration = half_a + half_b - std::abs(best_gap);
    pair.force = pair.stiffness * pair.penetration * n;
    // a's face towards b lies along −n, b's towards a along +n.
    const Vector3& da = particles.director[a];
    const Vector3 arm_a = (da.dot(n) > 0.0 ? -half_a : half_a) * da;
    const Vector3 arm_b = (db.dot(n) > 0.0 ? half_b : -half_b) * db;
    pair.moment = arm_a.cross(pair.force);
    pair.partner_moment = arm_b.cross(Vector3(-pair.force));
    return pair;
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
  std::vector<Vector3> reference_;
  std::vector<std::size_t> neighbour_begin_;
  std::vector<int> neighbours_;
  std::vector<double> spacing_;
  double reach_ = 0.0;
  std::vector<ShellContactPair> pairs_;
  std::vector<std::size_t> candidates_;
  ShellContactStatistics statistics_;
};

}  // namespace sphshell::contact
