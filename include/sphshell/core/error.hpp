#pragma once
// The one exception type of the library, and the checks that raise it.

#include <cmath>
#include <sstream>
#include <stdexcept>
#include <string>

namespace sphshell {

// Thrown for invalid input and for runs that go unstable; the message names the
// offending parameter (or step, time and point) and its value.
class Error : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// Where a run is: the step count and the simulated time. Parts of the solver
// that can detect an instability are handed it, so their error names both.
struct StepTime {
  long step = 0;
  double time = 0.0;
};

namespace detail {

// A run that went unstable stops with an Error naming the step, the time and
// what failed (a particle or a point).
[[noreturn]] inline void fail_unstable(const StepTime& at, const std::string& what) {
  std::ostringstream message;
  message.precision(6);
  message << "sphshell: simulation unstable at step " << at.step << ", t = " << at.time << " s: " << what;
  throw Error(message.str());
}

template <class Value>
[[noreturn]] inline void invalid_parameter(const std::string& name, const Value& value,
                                           const std::string& requirement) {
  std::ostringstream message;
  message.precision(17);
  message << "sphshell: invalid parameter " << name << " = " << value << " (" << requirement
          << ")";
  throw Error(message.str());
}

inline void require_finite(const std::string& name, double value) {
  if (!std::isfinite(value)) invalid_parameter(name, value, "must be finite");
}

inline void require_positive(const std::string& name, double value) {
  if (!(value > 0.0) || !std::isfinite(value))
    invalid_parameter(name, value, "must be finite and > 0");
}

inline void require_nonnegative(const std::string& name, double value) {
  if (!(value >= 0.0) || !std::isfinite(value))
    invalid_parameter(name, value, "must be finite and >= 0");
}

// lower < value < upper; NaN fails every comparison and is rejected.
inline void require_open_interval(const std::string& name, double value, double lower,
                                  double upper) {
  if (!(value > lower && value < upper)) {
    std::ostringstream requirement;
    requirement << "must lie in (" << lower << ", " << upper << ")";
    invalid_parameter(name, value, requirement.str());
  }
}

// lower < value <= upper.
inline void require_half_open_interval(const std::string& name, double value, double lower,
                                       double upper) {
  if (!(value > lower && value <= upper)) {
    std::ostringstream requirement;
    requirement << "must lie in (" << lower << ", " << upper << "]";
    invalid_parameter(name, value, requirement.str());
  }
}

}  // namespace detail
}  // namespace sphshell
