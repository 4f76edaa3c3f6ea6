#pragma once
// Penalty contact of a shell with itself: two shells of one model, or two far
// parts of one shell (the folds of a crushed tube), pushed apart when their
// faces meet. The Solver plugs it in with enable_shell_contact(); the rigid
// body set (body_set.hpp) adds its loads in the particle pass and books its
// work and spring energy with the rigid contacts'.
//
// Geometry (docs/method.md §12). A particle a is a point of the mid-surface;
// the shell it stands for is the tangent plane through it (normal d_a, the
// unit director) out to a patch radius R_a = patch_spacings · Δ_a (Δ_a its
// local spacing, shell/local_spacing.hpp), with faces h_a/2 to either side.
// With r = x_a − x_b, g = r · d_b (a's distance from b's mid-plane),
// ρ² = |r|² − g² (a's lateral offset from b) and c = (h_a + h_b)/2, a meets
// b's patch when ρ < R_b and, on its side s = ±1 of b, s g < 2c; penetration
// δ = max(0, c − s g). The side is history: the sign of g when a first
// weighed b, kept while it does (a deeply pressed pair is pushed back, never
// through), or, for a new pair, the side a had of a patch of b's sheet it
// weighed in the last step (a material neighbour b' of b within 60° of
// parallel; s times the sign of d_b · d_b') unless that puts a beyond b's
// far face (s g < −c), else the sign of g now.
// A particle a meets the surface as a weighted mean of the patches it lies
// over (node against surface, as a penalty contact's slave node against its
// master segments), so that its force changes continuously as it slides from
// patch to patch. Patch b's weight is
//   w_b = σ(ρ²) ν(s g),  σ = (1 − ρ²/R_b²)²,  ν = 1 for s g ≤ c,
//   (1 − ((s g − c)/c)²)² up to 2c, 0 beyond,
// so a patch enters and leaves with weight 0 both sideways and along its
// normal; pair ab carries the share φ_b = w_b / S_a of a's spring, with
// S_a = max(Σ w, W_sheet) and W_sheet = 4 (1 − 1/(2 patch_spacings²))², the
// smallest Σ w over a regular square sheet (at a cell's centre): inside a
// sheet the shares sum to 1, at its edge they fade to 0 instead of a lone
// patch of tiny weight taking the whole spring. Every particle plays both
// parts (a symmetric contact): on two matching sheets a pair is met twice.
// Every patch a particle lies over counts, however many: the search keeps
// up to initial_patch_slots patches per particle to start with (a sheet's
// patches of radius 0.75 Δ overlap at most four deep, two sheets' eight) and,
// whenever a step finds a particle over more, raises that limit for every
// particle to the most that one particle met and searches the step again;
// ShellContactStatistics::most_patches reports the most of the last step,
// patch_slots() the limit. The pair store holds only the pairs found, one
// particle's after the other's (no room kept free per particle), so that a
// step reads and writes little more than the pairs it has.
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
// Forces. The pair's spring k_ab = s m_ab / Δt² (penalty.hpp's rule) with the
// pair's effective mass at the contact point, 1/m_ab = 1/m_a + 1/m_b + ρ²/I_b
// (I_b = s_I m_b h_b²/12, the solver's rotary inertia, docs/method.md §1;
// b's rotation moves the patch under a by ρ θ), so the pair oscillates at
// ω Δt = √s whatever arm it acts on. The contact is a potential: the spring
// energy E = Σ_a E_a, E_a = Σ_b ½ k_ab φ_b δ_b², a function of the positions
// and directors alone, and the loads are its exact negative gradient:
// f_a = −∂E_a/∂x_a, f_b = −∂E_a/∂x_b = −f_a, and on b's rotation
// M_b = −d_b × ∂E_a/∂d_b (turning d_b by θ changes it by θ × d_b), through
// δ_b, the weights (as a slides over a patch or off a sheet's edge its
// share changes, and that change is pushed against) and k_ab(ρ²). So the
// contact neither makes nor loses energy (the books close to the central
// difference's error), the forces are exactly opposite (momentum to
// round-off), and E_a is unchanged by a rigid rotation, so the moments
// balance the forces' moment (angular momentum). With only the normal
// force k φ δ n, a patch's share rising as a slid under it put ½ k φ δ² in
// with no work done: enough, where a fold's edge slid in sideways, to blow a
// thin crushed tube apart. A particle carries the shares of its own spring
// (summing to at most 1) and of the springs of the particles that meet its
// patch: with the default s = 0.1 a few leave (ω Δt)² well below the 4 the
// central difference allows beside the shell's 2.56 (penalty.hpp). No
// friction: the contact is frictionless.
//
// Search: a cell list (approx/neighbour_search.hpp) rebuilt from the current
// positions every step, with cells as wide as the farthest a patch can weigh
// from, √((2 h_max)² + (patch_spacings Δ_max)²): each particle visits the 27 cells
// around it, so a step costs O(N). candidate_pairs() counts the pairs within
// that reach (each ordered pair once), the work the search does per step.
// What every candidate is tested with (position, director, patch radius) is
// read in the cell list's order, the order the queries visit the particles
// in, so that a large model's search reads its memory nearly in sequence.
//
// Energy: the spring energy E at configuration n; its work on the shell is
// the shell's external work, booked by the body set like the rigid contacts'.
// The sides are state: a checkpoint holds every particle's pairs (save/load).

#include <sphshell/approx/neighbour_search.hpp>
#include <sphshell/contact/penalty.hpp>
#include <sphshell/core/error.hpp>
#include <sphshell/core/parallel.hpp>
#include <sphshell/core/types.hpp>
#include <sphshell/shell/cell.hpp>
#include <sphshell/shell/model.hpp>
#include <sphshell/shell/local_spacing.hpp>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstddef>
#include <cstdint>
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
// Patches a particle's pairs may hold in a search, to start with; the limit
// grows when a particle meets more (see the header comment).
inline constexpr std::size_t initial_patch_slots = 8;
// Particles per block of the pair store, the unit the parallel search hands
// out: a few kilobytes of pairs, read in one stretch, and enough blocks in a
// model of a thousand particles for the threads to share (parallel.hpp runs a
// loop of fewer than 16 indices serially).
inline constexpr std::size_t pair_block_particles = 64;
// A new pair takes its side over from a remembered patch of the same sheet
// only when the two directors are within 60° of parallel (cos 60°): across a
// tighter bend the sheet's sides are not told apart by the directors.
inline constexpr double side_transfer_alignment = 0.5;
// A square grid's cell centre lies Δ/√2 from its four corners: a patch of
// radius patch_spacings · Δ must reach beyond it to cover a regular sheet.
inline constexpr double half_cell_diagonal_spacings = 0.70710678118654752440;

// Σ w over a regular square sheet at its thinnest, the cell centre: four
// patches at ρ = Δ/√2, each of weight (1 − ρ²/r²)² (method.md §12, eq. 12.2).
inline double regular_sheet_weight(double patch_spacings) {
  const double inside = 1.0 - 0.5 / (patch_spacings * patch_spacings);
  return 4.0 * inside * inside;
}

struct ShellContactOptions {
  double stiffness_scale = default_penalty_stiffness_scale;  // s in k = s m_ab / Δt², 0 < s < 4
  double patch_spacings = default_patch_spacings;            // patch radius / local spacing, > 0
  double exclusion_spacings = default_exclusion_spacings;    // material neighbour reach / local spacing, > patch_spacings
};

inline void validate(const ShellContactOptions& options) {
  sphshell::detail::require_open_interval("shell contact stiffness_scale", options.stiffness_scale, 0.0,
                                          penalty_stiffness_scale_bound);
  sphshell::detail::require_positive("shell contact patch_spacings", options.patch_spacings);
  if (!(options.patch_spacings > half_cell_diagonal_spacings))
    sphshell::detail::invalid_parameter("shell contact patch_spacings", options.patch_spacings,
                                        "must exceed 1/√2 ≈ 0.7071: smaller patches leave holes at a regular sheet's "
                                        "cell centres");
  sphshell::detail::require_positive("shell contact exclusion_spacings", options.exclusion_spacings);
  if (!(options.exclusion_spacings > options.patch_spacings))
    sphshell::detail::invalid_parameter("shell contact exclusion_spacings", options.exclusion_spacings,
                                        "must exceed patch_spacings (" + std::to_string(options.patch_spacings) +
                                            "): a particle would meet its own sheet's patches");
}

// One particle's contact with a patch it meets.
struct ShellContactPair {
  int partner = -1;             // b, whose patch a meets
  int side = 0;                 // s = ±1: a is on the side s d_b of b's mid-surface, kept from the pair's onset
  double stiffness = 0.0;       // w k, the share of a's spring this pair carries (N/m)
  double penetration = 0.0;     // δ = (h_a + h_b)/2 − s g (m), 0 where the patch only weighs
  Vector3 force = Vector3::Zero();  // on a; −force on b
  Vector3 partner_moment = Vector3::Zero();  // on b's rotation
};

// What the last evaluation found.
struct ShellContactStatistics {
  std::size_t contacts = 0;         // particles meeting a patch
  std::size_t candidate_pairs = 0;  // ordered pairs within the search reach
  double largest_penetration = 0.0; // max δ (m)
  double spring_energy = 0.0;       // Σ ½ k δ² (J)
  std::size_t most_patches = 0;     // the most patches one particle lay over (all of them count)
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
    spacing_ = local_spacing(model).particle;
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
    patch_squared_.resize(reference_.size());
    for (std::size_t i = 0; i < reference_.size(); ++i) {
      const double patch = options_.patch_spacings * spacing_[i];
      patch_squared_[i] = patch * patch;
    }
    sheet_weight_ = regular_sheet_weight(options_.patch_spacings);
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
    // The last step's pairs are the history that keeps each pair's side.
    previous_blocks_.swap(blocks_);
    const approx::CellList cells(particles.position, reach_);
    // The candidates' directors and patch radii in the cell list's order, the
    // order the searches visit them in: read side by side, not gathered from
    // all over the particle arrays for every candidate.
    patch_in_cell_.resize(count);
    parallel::for_each(std::size_t{0}, count, [&](std::size_t slot) noexcept {
      const auto b = static_cast<std::size_t>(cells.point_at(slot));
      patch_in_cell_[slot] = {particles.director[b], patch_squared_[b]};
    });
    const std::size_t block_count = (count + pair_block_particles - 1) / pair_block_particles;
    blocks_.resize(block_count);
    std::size_t most_patches = 0;
    for (;;) {
      // A particle that meets more patches than there are slots counts them
      // all but keeps none; the slots then grow to the most met and the step
      // is searched again, so that none is left out.
      std::atomic<bool> out_of_memory{false};
      parallel::for_each_range(std::size_t{0}, block_count, [&](std::size_t first, std::size_t last) noexcept {
        try {
          std::vector<PatchTerm> terms(slots_);
          for (std::size_t block = first; block < last; ++block) {
            PairBlock& pairs = blocks_[block];
            pairs.pair_end.clear();
            pairs.sides.clear();
            pairs.loads.clear();
            pairs.candidates = 0;
            pairs.most_patches = 0;
            const std::size_t end = std::min(count, (block + 1) * pair_block_particles);
            for (std::size_t a = block * pair_block_particles; a < end; ++a)
              find_pairs(particles, cells, time_step, a, terms.data(), pairs);
          }
        } catch (...) {
          out_of_memory.store(true);
        }
      });
      if (out_of_memory.load())
        throw Error("sphshell: shell contact: no memory for the pairs of " + std::to_string(slots_) +
                    " patches per particle");
      most_patches = 0;
      for (const PairBlock& pairs : blocks_) most_patches = std::max(most_patches, pairs.most_patches);
      if (most_patches <= slots_) break;
      slots_ = most_patches;
    }
    loads.force.assign(count, Vector3::Zero());
    loads.moment.assign(count, Vector3::Zero());
    ContactStepResult result;
    statistics_ = ShellContactStatistics{};
    statistics_.most_patches = most_patches;
    for (std::size_t block = 0; block < block_count; ++block) {
      const PairBlock& pairs = blocks_[block];
      statistics_.candidate_pairs += pairs.candidates;
      const std::size_t first_particle = block * pair_block_particles;
      std::size_t begin = 0;
      for (std::size_t local = 0; local < pairs.pair_end.size(); ++local) {
        const std::size_t a = first_particle + local, end = pairs.pair_end[local];
        bool touches = false;
        for (std::size_t k = begin; k < end; ++k) {
          const PairLoad& pair = pairs.loads[k];
          if (!(pair.penetration > 0.0)) continue;
          result.spring_energy += 0.5 * pair.stiffness * pair.penetration * pair.penetration;
          statistics_.largest_penetration = std::max(statistics_.largest_penetration, pair.penetration);
          touches = true;
        }
        // Where a touches, every patch it weighs carries a load (the shares'
        // change is part of the force); where it does not, none does.
        if (touches) {
          for (std::size_t k = begin; k < end; ++k) {
            const PairLoad& pair = pairs.loads[k];
            const auto b = static_cast<std::size_t>(pairs.sides[k].partner);
            loads.force[a] += pair.force;
            loads.force[b] -= pair.force;
            loads.moment[b] += pair.partner_moment;
          }
          ++result.contacts;
        }
        begin = end;
      }
    }
    statistics_.contacts = result.contacts;
    statistics_.spring_energy = result.spring_energy;
    return result;
  }

  const ShellContactStatistics& statistics() const { return statistics_; }
  // Patches a particle's pairs may hold in a search: initial_patch_slots, or
  // the most patches one particle has met since (no patch is ever dropped).
  std::size_t patch_slots() const { return slots_; }
  // Particle a's pairs of the last compute(): the patches it weighs (those
  // with penetration 0 carry no force).
  std::vector<ShellContactPair> pairs_of(std::size_t a) const {
    if (a >= reference_.size())
      sphshell::detail::invalid_parameter("shell contact pairs_of: particle", a,
                                          "must be below the model's particle count " +
                                              std::to_string(reference_.size()));
    std::vector<ShellContactPair> result;
    if (blocks_.empty()) return result;
    const PairBlock& pairs = blocks_[a / pair_block_particles];
    const PairRange range = pairs.of(a % pair_block_particles);
    for (std::size_t k = range.begin; k < range.end; ++k) {
      ShellContactPair pair;
      pair.partner = pairs.sides[k].partner;
      pair.side = pairs.sides[k].side;
      if (k < pairs.loads.size()) {
        pair.stiffness = pairs.loads[k].stiffness;
        pair.penetration = pairs.loads[k].penetration;
        pair.force = pairs.loads[k].force;
        pair.partner_moment = pairs.loads[k].partner_moment;
      }
      result.push_back(pair);
    }
    return result;
  }

  // Checkpoints: the history, every particle's pairs of the last compute()
  // (partner and side; the rest is recomputed from the configuration).
  template <class Writer>
  void save(Writer& out) const {
    std::vector<std::size_t> counts;
    std::vector<std::int32_t> partners, sides;
    for (const PairBlock& pairs : blocks_) {
      std::size_t begin = 0;
      for (const std::size_t end : pairs.pair_end) {
        counts.push_back(end - begin);
        begin = end;
      }
      for (const PairSide& pair : pairs.sides) {
        partners.push_back(pair.partner);
        sides.push_back(pair.side);
      }
    }
    out(counts, partners, sides);
  }
  template <class Reader>
  void load(Reader& in) {
    std::vector<std::size_t> counts;
    std::vector<std::int32_t> partners, sides;
    in(counts, partners, sides);
    const std::size_t count = reference_.size();
    if (!counts.empty() && counts.size() != count)
      sphshell::detail::invalid_parameter("checkpoint's shell contact history: particle count", counts.size(),
                                          "must be the model's " + std::to_string(count));
    std::size_t total = 0, most = 0;
    for (std::size_t c : counts) {
      if (c > count)
        sphshell::detail::invalid_parameter("checkpoint's shell contact history: pairs of a particle", c,
                                            "must not exceed the model's particle count " + std::to_string(count));
      total += c;
      most = std::max(most, c);
    }
    if (partners.size() != total || sides.size() != total)
      sphshell::detail::invalid_parameter("checkpoint's shell contact history: pair count", partners.size(),
                                          "must be the sum of the particles' counts " + std::to_string(total));
    for (std::size_t next = 0; next < total; ++next)
      if (partners[next] < 0 || static_cast<std::size_t>(partners[next]) >= count ||
          (sides[next] != 1 && sides[next] != -1))
        sphshell::detail::invalid_parameter("checkpoint's shell contact history: pair " + std::to_string(next),
                                            partners[next], "must name a particle with a side of ±1");
    // The history's blocks: partners and sides only (their loads are the
    // next compute()'s).
    std::vector<PairBlock> blocks((counts.size() + pair_block_particles - 1) / pair_block_particles);
    std::size_t next = 0;
    for (std::size_t a = 0; a < counts.size(); ++a) {
      PairBlock& pairs = blocks[a / pair_block_particles];
      for (std::size_t k = 0; k < counts[a]; ++k, ++next)
        pairs.sides.push_back({partners[next], sides[next]});
      pairs.pair_end.push_back(pairs.sides.size());
    }
    slots_ = std::max(slots_, most);
    blocks_ = std::move(blocks);
  }

 private:
  // One patch that a weighs, while its share is being formed.
  struct PatchTerm {
    Vector3 arm = Vector3::Zero();  // r = x_a − x_b
    Vector3 director = Vector3::Zero();  // d_b
    double gap = 0.0;               // g = r · d_b
    double lateral_squared = 0.0;   // ρ²
    double sideways = 0.0, sideways_slope = 0.0;  // σ(ρ²) and dσ/dρ²
    double along = 0.0, along_slope = 0.0;        // ν(s g) and dν/d(s g)
    double stiffness = 0.0, stiffness_slope = 0.0;  // k(ρ²) and dk/dρ²
    double penetration = 0.0;       // δ
    std::int32_t partner = -1;      // b
    std::int32_t side = 0;          // s
  };

  // A candidate's patch as the search reads it (in the cell list's order).
  struct PatchInCell {
    Vector3 director;      // d_b
    double patch_squared;  // R_b²
  };
  // A pair's history: whose patch, and on which side of it.
  struct PairSide {
    std::int32_t partner;
    std::int32_t side;
  };
  // What a pair puts on a and b in this step (its partner is in sides).
  struct PairLoad {
    double stiffness;  // w k, the share of a's spring (N/m)
    double penetration;  // δ (m)
    Vector3 force;  // on a; −force on b
    Vector3 partner_moment;  // on b's rotation
  };
  struct PairRange {
    std::size_t begin, end;
  };
  // The pairs of pair_block_particles consecutive particles, in particle and
  // patch order, side by side with no room left between particles: a step
  // writes and the next one reads only the pairs found. The blocks are fixed
  // by the particle count, not by the threads, so the loads summed from
  // them are the same for any thread count.
  struct PairBlock {
    std::vector<std::size_t> pair_end;  // per particle of the block: one past its last pair
    std::vector<PairSide> sides;        // the next step's history and the checkpoint
    std::vector<PairLoad> loads;        // this step's forces
    std::size_t candidates = 0;         // candidate pairs of the block's particles
    std::size_t most_patches = 0;       // the most patches one of them met
    // The pairs of the block's local-th particle: [begin, end) in sides and loads.
    PairRange of(std::size_t local) const { return {local == 0 ? 0 : pair_end[local - 1], pair_end[local]}; }
  };

  // The side of b's mid-surface a lies on: remembered from the last step if
  // a weighed b then; else taken over from a patch b' of the same sheet (a
  // material neighbour of b, nearly parallel) that a weighed then, unless
  // that side puts a beyond b's far face (s g < −c: the pair would start
  // deeper than both thicknesses, at full weight, where it weighed nothing a
  // step before); else the side a is on now (method.md §12, eq. 12.5).
  int side_of(const ContactParticles& particles, std::size_t a, int b, double gap,
              double contact_distance) const noexcept {
    const std::size_t block = a / pair_block_particles, local = a % pair_block_particles;
    if (block < previous_blocks_.size()) {
      const PairBlock& history = previous_blocks_[block];
      const PairRange range = history.of(local);
      const PairSide* first = history.sides.data() + range.begin;
      const PairSide* last = history.sides.data() + range.end;
      for (const PairSide* previous = first; previous != last; ++previous)
        if (previous->partner == b) return previous->side;
      const Vector3& db = particles.director[static_cast<std::size_t>(b)];
      for (const PairSide* previous = first; previous != last; ++previous) {
        const int other = previous->partner;
        if (!is_material_neighbour(static_cast<std::size_t>(b), other)) continue;
        const double alignment = db.dot(particles.director[static_cast<std::size_t>(other)]);
        if (std::abs(alignment) < side_transfer_alignment) continue;
        const int side = alignment > 0.0 ? previous->side : -previous->side;
        if (side * gap < -contact_distance) break;
        return side;
      }
    }
    return gap >= 0.0 ? 1 : -1;
  }

  // Particle a's pairs appended to its block (terms: slots_ of scratch); a
  // particle meeting more patches than slots_ has them counted, none kept,
  // and compute() searches again. Throws only when out of memory.
  void find_pairs(const ContactParticles& particles, const approx::CellList& cells, double time_step,
                  std::size_t a, PatchTerm* terms, PairBlock& pairs) {
    const Vector3& xa = particles.position[a];
    const double half_a = 0.5 * particles.thickness[a];
    std::size_t found = 0, candidates = 0;
    double weight_sum = 0.0;
    cells.for_each_slot_within(xa, reach_, [&](std::size_t slot, double distance_squared) {
      const int j = cells.point_at(slot);
      const auto b = static_cast<std::size_t>(j);
      if (b == a) return;
      ++candidates;
      const PatchInCell& patch_b = patch_in_cell_[slot];
      const Vector3& db = patch_b.director;
      const Vector3 arm = xa - cells.position_at(slot);
      const double gap = arm.dot(db);
      const double lateral_squared = std::max(0.0, distance_squared - gap * gap);
      const double patch_squared = patch_b.patch_squared;
      if (!(lateral_squared < patch_squared) || is_material_neighbour(a, j)) return;
      const double contact_distance = half_a + 0.5 * particles.thickness[b];
      const int side = side_of(particles, a, j, gap, contact_distance);
      const double signed_gap = side * gap;  // > 0 on a's side of b, < 0 once past b's mid-surface
      if (!(signed_gap < 2.0 * contact_distance)) return;
      if (found >= slots_) {
        ++found;
        return;
      }
      PatchTerm& term = terms[found];
      term.arm = arm;
      term.director = db;
      term.gap = gap;
      term.lateral_squared = lateral_squared;
      const double inside = 1.0 - lateral_squared / patch_squared;
      term.sideways = inside * inside;
      term.sideways_slope = -2.0 * inside / patch_squared;
      term.along = 1.0;
      term.along_slope = 0.0;
      if (signed_gap > contact_distance) {
        const double beyond = (signed_gap - contact_distance) / contact_distance;
        const double fade = 1.0 - beyond * beyond;
        term.along = fade * fade;
        term.along_slope = -4.0 * beyond * fade / contact_distance;
      }
      const double mass_b = particles.mass[b], thickness_b = particles.thickness[b];
      const double rotary_inertia_b = rotary_inertia_scale_ * mass_b * thickness_b * thickness_b / 12.0;
      const double compliance = 1.0 / particles.mass[a] + 1.0 / mass_b + lateral_squared / rotary_inertia_b;
      term.stiffness = penalty_stiffness(1.0 / compliance, time_step, options_.stiffness_scale);
      term.stiffness_slope = -term.stiffness / (compliance * rotary_inertia_b);
      term.partner = j;
      term.side = side;
      term.penetration = std::max(0.0, contact_distance - signed_gap);
      weight_sum += term.sideways * term.along;
      ++found;
    });
    pairs.candidates += candidates;
    pairs.most_patches = std::max(pairs.most_patches, found);
    if (found > slots_) {  // compute() grows the slots and searches again
      pairs.pair_end.push_back(pairs.sides.size());
      return;
    }
    // Shares φ_b = w_b / S, S = max(Σ w, W_sheet) (method.md §12, eq. 12.2),
    // and a's spring energy E_a = Σ ½ k_b φ_b δ_b².
    const double share_sum = std::max(weight_sum, sheet_weight_);
    const bool normalised = weight_sum > sheet_weight_;
    const std::size_t first = pairs.loads.size();
    pairs.loads.resize(first + found);
    PairLoad* loads = pairs.loads.data() + first;
    double energy = 0.0;
    for (std::size_t k = 0; k < found; ++k) {
      PairLoad& pair = loads[k];
      const PatchTerm& term = terms[k];
      const double share = share_sum > 0.0 ? term.sideways * term.along / share_sum : 0.0;
      pair.stiffness = share * term.stiffness;
      pair.penetration = term.penetration;
      energy += 0.5 * pair.stiffness * pair.penetration * pair.penetration;
      pairs.sides.push_back({term.partner, term.side});
    }
    pairs.pair_end.push_back(pairs.sides.size());
    // The loads are −∂E_a/∂(x_a, x_b, θ_b) (eq. 12.4): through δ_b, through
    // the weights (the shares' change as a slides over and off the patches)
    // and through k_b(ρ²).
    for (std::size_t k = 0; k < found; ++k) {
      PairLoad& pair = loads[k];
      const PatchTerm& term = terms[k];
      const double delta = pair.penetration;
      const double share = pair.stiffness > 0.0 ? pair.stiffness / term.stiffness : 0.0;
      // ∂E_a/∂w_b.
      const double per_weight =
          share_sum > 0.0 ? (0.5 * term.stiffness * delta * delta - (normalised ? energy : 0.0)) / share_sum : 0.0;
      // ∂E_a/∂ρ_b² and ∂E_a/∂(s g_b).
      const double per_lateral = per_weight * term.sideways_slope * term.along +
                                 0.5 * share * delta * delta * term.stiffness_slope;
      const double per_gap = per_weight * term.sideways * term.along_slope - pair.stiffness * delta;
      const double side = term.side;
      // ρ² = |r|² − g², g = r · d: ∂ρ²/∂r = 2 (r − g d), ∂ρ²/∂d = −2 g r; ∂(s g)/∂r = s d, ∂(s g)/∂d = s r.
      const Vector3 by_arm =
          (2.0 * per_lateral) * (term.arm - term.gap * term.director) + (per_gap * side) * term.director;
      const Vector3 by_director = (-2.0 * per_lateral * term.gap + per_gap * side) * term.arm;
      pair.force = -by_arm;
      // A turn θ of b's director changes it by θ × d_b: the moment is −d_b × ∂E_a/∂d_b.
      pair.partner_moment = -term.director.cross(by_director);
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
  std::vector<double> patch_squared_;  // R² per particle, (patch_spacings Δ)²
  std::vector<PatchInCell> patch_in_cell_;  // the step's candidates' patches, in the cell list's order
  double reach_ = 0.0;
  double sheet_weight_ = 0.0;  // W_sheet, regular_sheet_weight
  std::size_t slots_ = initial_patch_slots;  // the most patches a particle's pairs may hold in a search
  std::vector<PairBlock> blocks_;  // this step's pairs
  std::vector<PairBlock> previous_blocks_;  // the last step's: each pair's side
  ShellContactStatistics statistics_;
};

}  // namespace sphshell::contact
