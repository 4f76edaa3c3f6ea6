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

}  // namespace sphshell::example
