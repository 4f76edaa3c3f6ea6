#pragma once
// What a model will cost in memory before the large allocations are made, and
// what the machine offers, so that a model too large is refused up front with
// both figures instead of failing with std::bad_alloc after seconds of work.

#include <sphshell/core/error.hpp>

#include <sys/resource.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <fstream>
#include <limits>
#include <sstream>
#include <string>

namespace sphshell::approx {

// Bytes one shape-function slot (one row × neighbour pair) costs: the
// neighbour index and Φ, ∇Φ (ShapeFunctions), the gathered index while
// building, and the solver's force entry (its point, tied corner and slot,
// in the particles' order: solver/integration_points.hpp).
inline constexpr double bytes_per_slot = sizeof(int) + 3 * sizeof(double) + sizeof(int) + 3 * sizeof(std::uint32_t);

// Mean number of particles within a support of the given radius: the particle
// density (count over the area they cover) times π r².
inline double expected_row_size(std::size_t particles, double covered_area, double support_radius) {
  constexpr double pi = 3.14159265358979323846;
  if (!(covered_area > 0.0)) return static_cast<double>(particles);
  return std::min(static_cast<double>(particles),
                  static_cast<double>(particles) / covered_area * pi * support_radius * support_radius);
}

namespace detail {
// A number from a file such as /proc/meminfo ("MemAvailable:  1234 kB") or a
// cgroup file ("max" or a byte count); infinity when absent or unlimited.
inline double read_meminfo_bytes(const char* key) {
  std::ifstream in("/proc/meminfo");
  std::string name;
  double value = 0.0;
  std::string unit;
  while (in >> name >> value >> unit)
    if (name == key) return value * 1024.0;
  return std::numeric_limits<double>::infinity();
}
inline double read_cgroup_bytes(const char* path) {
  std::ifstream in(path);
  std::string text;
  if (!(in >> text) || text == "max") return std::numeric_limits<double>::infinity();
  try {
    return std::stod(text);
  } catch (...) {
    return std::numeric_limits<double>::infinity();
  }
}
// Bytes of address space the process uses now (/proc/self/statm, in pages).
inline double address_space_in_use() {
  std::ifstream in("/proc/self/statm");
  double pages = 0.0;
  if (!(in >> pages)) return 0.0;
  const long page = sysconf(_SC_PAGESIZE);
  return pages * static_cast<double>(page > 0 ? page : 4096);
}
}  // namespace detail

// Memory the process may still take, in bytes: the least of the system's
// available memory (MemAvailable), the cgroup's limit less its usage, and the
// address-space limit (ulimit -v) less the address space in use. Infinity
// where none of them is known.
inline double available_memory() {
  double available = detail::read_meminfo_bytes("MemAvailable:");
  const double cgroup_limit = detail::read_cgroup_bytes("/sys/fs/cgroup/memory.max");
  if (std::isfinite(cgroup_limit))
    available = std::min(available, cgroup_limit - detail::read_cgroup_bytes("/sys/fs/cgroup/memory.current"));
  rlimit limit{};
  if (getrlimit(RLIMIT_AS, &limit) == 0 && limit.rlim_cur != RLIM_INFINITY)
    available = std::min(available, static_cast<double>(limit.rlim_cur) - detail::address_space_in_use());
  return std::max(available, 0.0);
}

// "1.5 GiB" for a message.
inline std::string format_bytes(double bytes) {
  std::ostringstream text;
  text.precision(3);
  if (bytes >= 1024.0 * 1024.0 * 1024.0)
    text << bytes / (1024.0 * 1024.0 * 1024.0) << " GiB";
  else
    text << bytes / (1024.0 * 1024.0) << " MiB";
  return text.str();
}

}  // namespace sphshell::approx
