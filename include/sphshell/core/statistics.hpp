#pragma once
// Small statistics of per-point values shared by the model checks, the
// support radii, the searches and the energy books.

#include <algorithm>
#include <array>
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

// The sum of the values, as eight partial sums over every eighth value added
// up in a fixed order: a single running sum waits for each addition before
// the next (about 4 cycles per value), these overlap. The order depends only
// on the count, never on the thread count.
inline double interleaved_sum(const std::vector<double>& values) {
  constexpr std::size_t partial_sums = 8;
  std::array<double, partial_sums> sums{};
  const std::size_t count = values.size(), whole = count - count % partial_sums;
  for (std::size_t p = 0; p < whole; p += partial_sums)
    for (std::size_t k = 0; k < partial_sums; ++k) sums[k] += values[p + k];
  for (std::size_t p = whole; p < count; ++p) sums[p - whole] += values[p];
  double sum = 0.0;
  for (double partial : sums) sum += partial;
  return sum;
}

}  // namespace sphshell::detail
