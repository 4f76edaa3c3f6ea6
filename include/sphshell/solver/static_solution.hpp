#pragma once
// Solver::solve_static's parameters and results under the solver's names; the
// load stepping, Newton's method and the dynamic relaxation are the static
// family's (statics/static_solve.hpp, on its tangent assembly statics/coupling.hpp).
// StaticSolution hands them the solver's state and puts the solver back as
// solve_static promises (solver.hpp).

#include <sphshell/core/error.hpp>
#include <sphshell/statics/static_solve.hpp>

#include <cmath>
#include <cstddef>
#include <limits>

namespace sphshell::solver {

using statics::automatic_relaxation_steps;
using statics::StaticDamping;
using statics::StaticIteration;
using statics::StaticMass;
using statics::StaticNotConverged;
using statics::StaticParameters;
using statics::StaticResult;

// The static solve of a Solver (a friend of it): the loads at the load time
// scaled by the load factor, the internal forces at the quasi-static limit,
// the material states kept at the last converged point; afterwards the
// solver at rest at the result, or as it was before the call when the solve
// fails other than by its budget.
template <class Solver>
class StaticSolution {
 public:
  template <class Observer>
  static StaticResult solve(Solver& s, const StaticParameters& parameters, Observer& observer) {
    s.domain_.collectively([&] {
      statics::validate(parameters);
      if (Solver::distributed && parameters.mass == StaticMass::tangent)
        throw Error("sphshell: solve_static: StaticMass::tangent (Newton steps on the assembled tangent) runs on "
                    "one process only; a distributed run relaxes: StaticMass::particle_bound (the default)");
    });
    const double load_time = std::isnan(parameters.load_time) ? s.time_ : parameters.load_time;
    const auto start = s.particles_;
    const auto start_states = *s.states_;
    auto converged = *s.states_;
    auto evaluate = [&](double load_factor) {
      s.apply_loads_now({s.steps_, load_time});
      for (std::size_t i = 0; i < s.particles_.size(); ++i) {
        s.forces_.external[i] *= load_factor;
        s.forces_.external_moment[i] *= load_factor;
      }
      // Equilibrium is quasi-static: no strain rate (rate-dependent laws at their static limit).
      s.assembler_->set_time_step(std::numeric_limits<double>::infinity());
      s.assembler_->compute(s.now(), s.particles_, *s.points_, *s.states_, s.forces_);
    };
    auto save = [&] { converged = *s.states_; };
    auto restore = [&] { *s.states_ = converged; };
    statics::StaticSystem<typename Solver::domain_type, typename Solver::approximation_type, decltype(evaluate),
                          decltype(save), decltype(restore)>
        system{s.domain_, s.model_, s.particles_, s.forces_, s.constraints_, *s.points_,
               evaluate,  save,     restore,      s.options_.progress_stream};
    // The solve leaves its result (or a failed load step's best state) with
    // its material state and internal forces; the books restart at rest there.
    auto at_rest = [&] {
      s.forces_current_ = true;
      s.ledger_->restart_at_rest(s.domain_, s.energy().elastic);
    };
    try {
      const StaticResult result = statics::solve_static(system, parameters, observer);
      at_rest();
      return result;
    } catch (const StaticNotConverged&) {
      at_rest();
      throw;
    } catch (...) {
      s.particles_ = start;
      *s.states_ = start_states;
      s.compute_internal_forces();
      throw;
    }
  }
};

}  // namespace sphshell::solver
