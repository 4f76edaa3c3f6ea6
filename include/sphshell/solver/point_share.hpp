#pragma once
// The integration points of one process's share (solver.hpp), a base part
// of the Solver that owns them: the rows and section states of the points
// this process computes (serially all of them; distributed, every point
// whose row reaches a particle it owns, mpi/layout.hpp), and the stress
// queries by global stress point: the owner's values on every process.
//
// Set-up builds the whole model's points and states on every process (the
// stable step is taken from them, so it is the serial value everywhere), then
// keeps the share's: one process moves them in whole; a distributed run
// keeps its subset, and with cracks the whole model's rows too (a crack
// rebuilds a row from the whole model's, solver/fracture.hpp).

#include <sphshell/core/error.hpp>
#include <sphshell/core/parallel.hpp>
#include <sphshell/core/types.hpp>
#include <sphshell/shell/model.hpp>
#include <sphshell/solver/integration_points.hpp>
#include <sphshell/solver/particle_share.hpp>
#include <sphshell/solver/section_states.hpp>
#include <sphshell/thickness/section.hpp>

#include <array>
#include <cstddef>
#include <optional>
#include <utility>
#include <vector>

namespace sphshell::solver {

template <class Approx, class Rule, class Material, class Domain>
class PointShare : public ParticleShare<Domain> {
  using Base = ParticleShare<Domain>;

 public:
  using Points = IntegrationPoints<Approx>;
  using States = SectionStates<Rule, Material>;
  // Per stress point, the thickness output points k (integral points; one for Global).
  static constexpr int output_points = thickness::Section<Rule, Material>::output_points;

  // Per stress point and thickness output point k (integral point; one for
  // Global), the owner's values on every process (collective).
  std::size_t stress_point_count() const { return stress_point_count_; }
  double integral_point_quantity(IntegralPointQuantity quantity, int stress_point, int k) const {
    check_output_point(stress_point, k);
    return owner_values(stress_point, [&](std::size_t p) {
      return std::array<double, 3>{states_->quantity(quantity, p, k), 0.0, 0.0};
    })[0];
  }
  double equivalent_stress(int stress_point, int k) const {
    return integral_point_quantity(IntegralPointQuantity::equivalent_stress, stress_point, k);
  }
  double equivalent_plastic_strain(int stress_point, int k) const {
    return integral_point_quantity(IntegralPointQuantity::equivalent_plastic_strain, stress_point, k);
  }
  double damage(int stress_point, int k) const {
    return integral_point_quantity(IntegralPointQuantity::damage, stress_point, k);
  }
  // Membrane forces (N/m) and moments (N·m/m) at a stress point, Voigt (xx, yy, xy)
  // in its reference tangent frame.
  StressVoigt membrane_force(int stress_point) const {
    check_output_point(stress_point, 0);
    const auto n = owner_values(stress_point, [&](std::size_t p) { return voigt(states_->membrane_force(p)); });
    return StressVoigt(n[0], n[1], n[2]);
  }
  StressVoigt bending_moment(int stress_point) const {
    check_output_point(stress_point, 0);
    const auto m = owner_values(stress_point, [&](std::size_t p) { return voigt(states_->bending_moment(p)); });
    return StressVoigt(m[0], m[1], m[2]);
  }
  // Whether a stress point has left the integration (damaged or on a pre-crack).
  bool is_removed(int stress_point) const {
    check_output_point(stress_point, 0);
    return owner_values(stress_point, [&](std::size_t p) {
             return std::array<double, 3>{states_->active(p) ? 0.0 : 1.0, 0.0, 0.0};
           })[0] != 0.0;
  }
  // Current stress point positions, interpolated from the particles (collective).
  std::vector<Vector3> stress_point_positions() const {
    const std::vector<std::size_t> rows = this->domain_.owned_stress_rows();
    std::vector<std::pair<std::size_t, Vector3>> mine(rows.size());
    parallel::for_each(std::size_t{0}, rows.size(), [&](std::size_t n) noexcept {
      mine[n] = {this->domain_.global_stress_point(rows[n]), stress_point_position(rows[n])};
    });
    return this->domain_.assembled(stress_point_count_, mine);
  }

 protected:
  using Base::Base;

  // Keeps the share's points and states of the whole model's (after the
  // domain's decomposition); distributed, the whole model's rows too when
  // keep_whole_rows (a crack rebuilds rows from them).
  void share_points(const ShellModel& model, Points&& all_points, States&& all_states, bool keep_whole_rows) {
    stress_point_count_ = model.stress_point_count();
    model_point_count_ = all_points.size();
    model_slot_count_ = all_points.slot_count();
    if constexpr (Domain::is_distributed) {
      const auto& layout = this->domain_.layout();
      for (PointGroup group : point_groups) {
        const std::size_t g = index_of(group);
        for (std::size_t k = 0; k < layout.computed[g].size(); ++k) {
          global_point_.push_back(all_points.point(group, layout.computed[g][k]));
          point_owned_.push_back(layout.computed_is_owned[g][k]);
        }
      }
      states_.emplace(this->domain_.local_states(all_states, all_points));
      points_.emplace(this->domain_.local_rows(all_points));
      if (keep_whole_rows) all_points_.emplace(std::move(all_points));
    } else {
      states_.emplace(std::move(all_states));
      points_.emplace(std::move(all_points));
    }
  }
  // The whole model's rows again, in place of rows a crack rebuilt (a checkpoint's load).
  void reset_rows(Points&& fresh) {
    if constexpr (Domain::is_distributed) {
      points_.emplace(this->domain_.local_rows(fresh));
      if (all_points_) all_points_.emplace(std::move(fresh));
    } else {
      points_.emplace(std::move(fresh));
    }
  }
  bool any_rebuilt() const { return points_->any_rebuilt() || (all_points_ && all_points_->any_rebuilt()); }

  void check_stress_point(int stress_point) const {
    if (stress_point < 0 || static_cast<std::size_t>(stress_point) >= stress_point_count_)
      detail::invalid_parameter("stress point index", stress_point, "out of range");
  }
  void check_output_point(int stress_point, int k) const {
    this->domain_.collectively([&] {
      check_stress_point(stress_point);
      if (k < 0 || k >= output_points) detail::invalid_parameter("thickness output point", k, "out of range");
    });
  }
  static std::array<double, 3> voigt(const StressVoigt& value) { return {value[0], value[1], value[2]}; }
  // value(local point) of the process that owns the stress point, on every process.
  template <class Value>
  std::array<double, 3> owner_values(int stress_point, Value&& value) const {
    const long row = this->domain_.owned_stress_row(static_cast<std::size_t>(stress_point));
    std::optional<std::array<double, 3>> mine;
    if (row >= 0) mine = value(points_->point(PointGroup::stress_points, static_cast<std::size_t>(row)));
    return this->domain_.from_owner(mine);
  }
  // The current position of local stress-point row k, interpolated from the
  // particles (owned and ghosts: current after every step's exchange).
  Vector3 stress_point_position(std::size_t k) const {
    const approx::ShapeFunctions& shape = points_->shape(PointGroup::stress_points);
    Vector3 position = Vector3::Zero();
    for (std::size_t s = shape.row_begin[k]; s < shape.row_begin[k] + shape.row_size[k]; ++s)
      position += shape.value[s].phi * this->particles_.position[static_cast<std::size_t>(shape.neighbour[s])];
    return position;
  }

  std::optional<Points> all_points_;  // distributed with cracks: the whole model's rows
  std::optional<Points> points_;
  std::optional<States> states_;
  std::vector<char> point_owned_;          // distributed, per local point: owned here (books its work)
  std::vector<std::size_t> global_point_;  // distributed, per local point: its index in the whole model's
  std::size_t stress_point_count_ = 0;
  std::size_t model_point_count_ = 0, model_slot_count_ = 0;  // the whole model's (checkpoint identity)
};

}  // namespace sphshell::solver
