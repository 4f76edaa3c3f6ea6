#pragma once
// Small statistics of per-point values shared by the model checks, the
// support radii and the searches.

#include <algorithm>
#include <cstddef>
#include <vector>

namespace sphshell::detail {

// The middle value (the upper one of an even count; 0 for none): also the
// cell width of a search whose radii vary from point to point.
inline double median(std::vector<double> values) {
  if (values.empty()) return 0.0;
  const auto middle = values.begin() + static_cast<std::ptrdiff_t>(values.size() / 2);
  std::nth_element(values.begin(), middle, values.end());
  return *middle;
}

}  // namespace sphshell::detail
