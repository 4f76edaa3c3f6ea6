#pragma once
// Dynamic relaxation run period by period until a checked quantity has
// settled: the tests that relax a model to its static state with the solver's
// own damped explicit steps stop once the quantity moves by less than
// `tolerance` of itself over one period, and after `max_periods` at most.

#include <cmath>

namespace sphshell::test_support {

struct Settled {
  double value;        // the quantity where the relaxation stopped
  double last_change;  // its relative change over the last period run
};

// solver.run_until(k · period) for k = 1, 2, …, max_periods, reading
// quantity() after each; stops once |q_k − q_{k−1}| < tolerance |q_k|.
template <class Solver, class Quantity>
Settled relax_until_settled(Solver& solver, double period, int max_periods, double tolerance, Quantity&& quantity) {
  double before = 0.0, value = 0.0, change = 1.0;
  for (int k = 1; k <= max_periods && !(change < tolerance); ++k) {
    solver.run_until(k * period);
    value = quantity();
    change = std::abs(value - before) / std::abs(value);
    before = value;
  }
  return {value, change};
}

}  // namespace sphshell::test_support
