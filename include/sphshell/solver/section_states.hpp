#pragma once
// The state of every integration point's section: the thickness rule's and
// material law's state (Section<Rule, Law>::State), the strains it was last
// updated to, its resultants and transverse shear force, and whether it still
// takes part in the integration (a failed point is removed by the fracture
// manager). One Section per distinct wall thickness; each point refers to its
// own.
//
// Quantities reported per integral point through the thickness (probes, VTU
// frames, the Solver's accessors) are listed once in integral_point_quantities:
// a new one needs a member of the law and of Section, an enumerator and a row
// of that table.
//
// The law states are stored as the grouped assembler reads them: where its
// SectionGroup runs across points, in lanes, a SectionGroup::Block per G
// consecutive points of a point group (the stress points' blocks first, the
// particles' starting at a block of their own, so that block b of a group
// holds its rows b·G … b·G + G − 1 and a run of rows starting at a multiple of
// G never shares a block with another run); otherwise point by point. The
// per-point readers, the checkpoints and subset() see each point's
// Section::State either way, and a checkpoint holds them point by point, so
// its bytes do not depend on the layout.

#include <sphshell/core/types.hpp>
#include <sphshell/shell/kinematics.hpp>
#include <sphshell/shell/model.hpp>
#include <sphshell/thickness/section_group.hpp>
#include <sphshell/thickness/section.hpp>

#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

namespace sphshell::solver {

enum class IntegralPointQuantity { equivalent_stress, equivalent_plastic_strain, damage };

struct IntegralPointQuantityInfo {
  IntegralPointQuantity quantity;
  const char* name;         // array name in the frames; probe columns add _k
  const char* unit;         // probe column unit suffix, "" for dimensionless
  bool needs_damage_law;    // written to frames only when the law has damage
};

inline constexpr std::array<IntegralPointQuantityInfo, 3> integral_point_quantities{{
    {IntegralPointQuantity::equivalent_stress, "equivalent_stress", " [Pa]", false},
    {IntegralPointQuantity::equivalent_plastic_strain, "equivalent_plastic_strain", "", false},
    {IntegralPointQuantity::damage, "damage", "", true},
}};

template <class Rule, class Law>
class SectionStates {
 public:
  using Section = thickness::Section<Rule, Law>;
  using State = typename Section::State;
  using Group = thickness::SectionGroup<Rule, Law>;
  // Whether the law states are stored in lanes, by blocks of G points.
  static constexpr bool in_lanes = Group::across_points;
  using Block = typename Group::Block;
  static constexpr std::size_t block_points = std::size_t(Group::group_size);

  // Points in the IntegrationPoints numbering: the model's stress points, then
  // particle_points particles.
  SectionStates(const ShellModel& model, const Law& law, std::size_t particle_points) {
    const std::size_t stress_points = model.stress_point_count();
    const std::size_t total = stress_points + particle_points;
    section_index_.resize(total);
    for (std::size_t p = 0; p < stress_points; ++p) section_index_[p] = section_for(law, model.stress_point_thickness(p));
    for (std::size_t i = 0; i < particle_points; ++i)
      section_index_[stress_points + i] = section_for(law, model.particle_thickness(i));
    stress_points_ = stress_points;
    assign_states(std::vector<State>(total, sections_.front().initial_state()));
    membrane_strain_.assign(total, StrainVoigt::Zero());
    curvature_.assign(total, StrainVoigt::Zero());
    shear_.assign(total, Vector2::Zero());
    shear_force_.assign(total, Vector2::Zero());
    tied_shear_energy_.assign(total, 0.0);
    membrane_.assign(total, StressVoigt::Zero());
    moment_.assign(total, StressVoigt::Zero());
    active_.assign(total, 1);
  }

  // The states of the given points (ascending indices), in that order: the
  // points one rank of a distributed run computes (include/sphshell/mpi/).
  SectionStates subset(const std::vector<std::size_t>& points) const {
    SectionStates part(*this);
    auto pick = [&](auto& to, const auto& from) {
      to.clear();
      for (std::size_t p : points) to.push_back(from.at(p));
    };
    pick(part.section_index_, section_index_);
    part.stress_points_ = std::size_t(
        std::count_if(points.begin(), points.end(), [&](std::size_t p) { return p < stress_points_; }));
    std::vector<State> states;
    pick(states, point_states());
    part.assign_states(std::move(states));
    pick(part.membrane_strain_, membrane_strain_);
    pick(part.curvature_, curvature_);
    pick(part.shear_, shear_);
    pick(part.shear_force_, shear_force_);
    pick(part.tied_shear_energy_, tied_shear_energy_);
    pick(part.membrane_, membrane_);
    pick(part.moment_, moment_);
    pick(part.active_, active_);
    return part;
  }

  std::size_t size() const { return section_index_.size(); }
  const Section& section(std::size_t p) const { return sections_[section_index_[p]]; }

  // Material state (a copy, in either layout) and the strains and resultants
  // of the last update. The resultants are per unit length (not yet
  // weighted); the shear force is weighted (shear_weight × γ, updated
  // incrementally).
  State state(std::size_t p) const {
    if constexpr (in_lanes)
      return Group::state_in(blocks_[block_of(p)], lane_of(p));
    else
      return state_[p];
  }
  void set_state(std::size_t p, const State& state) {
    if constexpr (in_lanes)
      Group::set_state_in(blocks_[block_of(p)], lane_of(p), state);
    else
      state_[p] = state;
  }
  // Point by point: the stored state itself, for the assembler to update in place.
  State& stored_state(std::size_t p) {
    static_assert(!in_lanes, "SectionStates::stored_state: states in lanes are reached through block()");
    return state_[p];
  }
  // In lanes: the block holding point p, and p's place in it.
  Block& block(std::size_t p) {
    static_assert(in_lanes, "SectionStates::block: states point by point are reached through stored_state()");
    return blocks_[block_of(p)];
  }
  int lane_of(std::size_t p) const { return int(slot_of(p) % block_points); }
  StrainVoigt& membrane_strain(std::size_t p) { return membrane_strain_[p]; }
  StrainVoigt& curvature(std::size_t p) { return curvature_[p]; }
  Vector2& shear_strain(std::size_t p) { return shear_[p]; }
  StressVoigt& membrane_force(std::size_t p) { return membrane_[p]; }
  const StressVoigt& membrane_force(std::size_t p) const { return membrane_[p]; }
  StressVoigt& bending_moment(std::size_t p) { return moment_[p]; }
  const StressVoigt& bending_moment(std::size_t p) const { return moment_[p]; }
  Vector2& shear_force(std::size_t p) { return shear_force_[p]; }
  const Vector2& shear_force(std::size_t p) const { return shear_force_[p]; }
  // Elastic energy of a stress point's edge-tied shear at its last update
  // (shell/cell_shear.hpp; 0 for points whose shear is not tied).
  double& tied_shear_energy(std::size_t p) { return tied_shear_energy_[p]; }
  double tied_shear_energy(std::size_t p) const { return tied_shear_energy_[p]; }

  // Restarts the strain bookkeeping of a point from new strains (after its
  // shape functions changed, so the change itself creates no strain).
  void restart_strains(std::size_t p, const shell::Strains& strains) {
    membrane_strain_[p] = strains.membrane;
    curvature_[p] = strains.curvature;
    shear_[p] = strains.shear;
  }

  bool active(std::size_t p) const { return active_[p] != 0; }
  bool all_failed(std::size_t p) const { return section(p).all_failed(state(p)); }
  void deactivate(std::size_t p) { active_[p] = 0; }

  // Elastic energy held by one point (membrane, bending, shear), given its weights.
  double stored_energy(std::size_t p, double membrane_bending_weight, double shear_weight) const {
    const double shear = shear_weight > 0.0 ? 0.5 * shear_force_[p].squaredNorm() / shear_weight : 0.0;
    return membrane_bending_weight * section(p).elastic_energy(state(p)) + shear + tied_shear_energy_[p];
  }

  double quantity(IntegralPointQuantity q, std::size_t p, int k) const {
    switch (q) {
      case IntegralPointQuantity::equivalent_stress: return section(p).equivalent_stress(state(p), k);
      case IntegralPointQuantity::equivalent_plastic_strain:
        return section(p).equivalent_plastic_strain(state(p), k);
      case IntegralPointQuantity::damage: return section(p).damage(state(p), k);
    }
    return 0.0;
  }

  // Checkpoints (solver/checkpoint.hpp): every point's material state (each
  // law's State, for_each_field; Section<Rule, Law>::State per rule), the
  // strains of its last update, its resultants, the energy of its edge-tied
  // shear and whether it is active. The states are written point by point
  // whatever their layout here.
  // The sections themselves follow from the model and the law.
  template <class Writer>
  void save(Writer& out) const {
    out(point_states(), membrane_strain_, curvature_, shear_, shear_force_, membrane_, moment_, tied_shear_energy_, active_);
  }
  template <class Reader>
  void load(Reader& in) {
    std::vector<State> states(size());
    in.read_exact(states, "integration point states");
    assign_states(std::move(states));
    in.read_exact(membrane_strain_, "membrane strains");
    in.read_exact(curvature_, "curvatures");
    in.read_exact(shear_, "transverse shear strains");
    in.read_exact(shear_force_, "transverse shear forces");
    in.read_exact(membrane_, "membrane forces");
    in.read_exact(moment_, "bending moments");
    in.read_exact(tied_shear_energy_, "edge-tied shear energies");
    in.read_exact(active_, "active flags");
  }

  // Distinct sections (one per wall thickness).
  const std::vector<Section>& sections() const { return sections_; }

 private:
  std::uint32_t section_for(const Law& law, double d) {
    for (std::size_t k = 0; k < sections_.size(); ++k)
      if (sections_[k].thickness() == d) return static_cast<std::uint32_t>(k);
    sections_.emplace_back(law, d);
    return static_cast<std::uint32_t>(sections_.size() - 1);
  }

  // Point p's place in the blocks: the stress points from 0, the particles
  // from the first block after theirs.
  std::size_t slot_of(std::size_t p) const {
    if (p < stress_points_) return p;
    const std::size_t first_particle_slot = (stress_points_ + block_points - 1) / block_points * block_points;
    return first_particle_slot + (p - stress_points_);
  }
  std::size_t block_of(std::size_t p) const { return slot_of(p) / block_points; }

  // Every point's state, point by point, and the same stored in this layout
  // (size() states; in lanes, the blocks' lanes of no point hold the first
  // point's state).
  std::vector<State> point_states() const {
    if constexpr (in_lanes) {
      std::vector<State> states;
      states.reserve(size());
      for (std::size_t p = 0; p < size(); ++p) states.push_back(state(p));
      return states;
    } else {
      return state_;
    }
  }
  void assign_states(std::vector<State> states) {
    if constexpr (in_lanes) {
      const std::size_t slots = states.empty() ? 0 : slot_of(states.size() - 1) + 1;
      blocks_.assign((slots + block_points - 1) / block_points, Block{});
      if (!states.empty())
        for (Block& block : blocks_)
          for (int g = 0; g < int(block_points); ++g) Group::set_state_in(block, g, states.front());
      for (std::size_t p = 0; p < states.size(); ++p) set_state(p, states[p]);
    } else {
      state_ = std::move(states);
    }
  }

  std::vector<Section> sections_;
  std::vector<std::uint32_t> section_index_;  // 4 bytes a point: a model has far fewer thicknesses
  std::size_t stress_points_ = 0;
  std::vector<State> state_;   // point by point (not in_lanes)
  std::vector<Block> blocks_;  // in lanes
  std::vector<StrainVoigt> membrane_strain_, curvature_;
  std::vector<Vector2> shear_, shear_force_;
  std::vector<double> tied_shear_energy_;
  std::vector<StressVoigt> membrane_, moment_;
  std::vector<unsigned char> active_;
};

}  // namespace sphshell::solver
