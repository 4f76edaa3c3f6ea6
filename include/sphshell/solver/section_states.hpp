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

#include <sphshell/core/types.hpp>
#include <sphshell/shell/kinematics.hpp>
#include <sphshell/shell/model.hpp>
#include <sphshell/thickness/section.hpp>

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

  // Points in the IntegrationPoints numbering: the model's stress points, then
  // particle_points particles.
  SectionStates(const ShellModel& model, const Law& law, std::size_t particle_points) {
    const std::size_t stress_points = model.stress_point_count();
    const std::size_t total = stress_points + particle_points;
    section_index_.resize(total);
    for (std::size_t p = 0; p < stress_points; ++p) section_index_[p] = section_for(law, model.stress_point_thickness(p));
    for (std::size_t i = 0; i < particle_points; ++i)
      section_index_[stress_points + i] = section_for(law, model.particle_thickness(i));
    state_.assign(total, sections_.front().initial_state());
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
    pick(part.state_, state_);
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

  std::size_t size() const { return state_.size(); }
  const Section& section(std::size_t p) const { return sections_[section_index_[p]]; }

  // Material state and the strains and resultants of the last update. The
  // resultants are per unit length (not yet weighted); the shear force is
  // weighted (shear_weight × γ, updated incrementally).
  State& state(std::size_t p) { return state_[p]; }
  const State& state(std::size_t p) const { return state_[p]; }
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
  bool all_failed(std::size_t p) const { return section(p).all_failed(state_[p]); }
  void deactivate(std::size_t p) { active_[p] = 0; }

  // Elastic energy held by one point (membrane, bending, shear), given its weights.
  double stored_energy(std::size_t p, double membrane_bending_weight, double shear_weight) const {
    const double shear = shear_weight > 0.0 ? 0.5 * shear_force_[p].squaredNorm() / shear_weight : 0.0;
    return membrane_bending_weight * section(p).elastic_energy(state_[p]) + shear + tied_shear_energy_[p];
  }

  double quantity(IntegralPointQuantity q, std::size_t p, int k) const {
    switch (q) {
      case IntegralPointQuantity::equivalent_stress: return section(p).equivalent_stress(state_[p], k);
      case IntegralPointQuantity::equivalent_plastic_strain:
        return section(p).equivalent_plastic_strain(state_[p], k);
      case IntegralPointQuantity::damage: return section(p).damage(state_[p], k);
    }
    return 0.0;
  }

  // Checkpoints (solver/checkpoint.hpp): every point's material state (each
  // law's State, for_each_field; Section<Rule, Law>::State per rule), the
  // strains of its last update, its resultants, the energy of its edge-tied
  // shear and whether it is active.
  // The sections themselves follow from the model and the law.
  template <class Writer>
  void save(Writer& out) const {
    out(state_, membrane_strain_, curvature_, shear_, shear_force_, membrane_, moment_, tied_shear_energy_, active_);
  }
  template <class Reader>
  void load(Reader& in) {
    in.read_exact(state_, "integration point states");
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

  std::vector<Section> sections_;
  std::vector<std::uint32_t> section_index_;  // 4 bytes a point: a model has far fewer thicknesses
  std::vector<State> state_;
  std::vector<StrainVoigt> membrane_strain_, curvature_;
  std::vector<Vector2> shear_, shear_force_;
  std::vector<double> tied_shear_energy_;
  std::vector<StressVoigt> membrane_, moment_;
  std::vector<unsigned char> active_;
};

}  // namespace sphshell::solver
