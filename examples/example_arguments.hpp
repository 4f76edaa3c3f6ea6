#pragma once
// Command-line numbers for the examples: a malformed value ("abc", "1e-3x",
// "nan") is an Error naming the option, never a silently truncated number.

#include <sphshell/core/error.hpp>

#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

namespace sphshell::example {

inline double parse_number(const std::string& option, const std::string& text) {
  std::size_t used = 0;
  double value = 0.0;
  try {
    value = std::stod(text, &used);
  } catch (const std::exception&) {
    used = 0;
  }
  if (used == 0 || used != text.size() || !std::isfinite(value))
    throw Error(option + " = '" + text + "' is not a finite number");
  return value;
}

inline int parse_integer(const std::string& option, const std::string& text) {
  std::size_t used = 0;
  long value = 0;
  try {
    value = std::stol(text, &used);
  } catch (const std::exception&) {
    used = 0;
  }
  if (used == 0 || used != text.size() || value < std::numeric_limits<int>::min() ||
      value > std::numeric_limits<int>::max())
    throw Error(option + " = '" + text + "' is not an integer");
  return static_cast<int>(value);
}

// SolverOptions::particle_integration_share from the command line, checked
// here so that the error names the option rather than the solver field.
inline double parse_particle_share(const std::string& option, const std::string& text) {
  const double share = parse_number(option, text);
  if (!(share >= 0.0 && share < 1.0)) detail::invalid_parameter(option, share, "must lie in [0, 1)");
  return share;
}

}  // namespace sphshell::example
