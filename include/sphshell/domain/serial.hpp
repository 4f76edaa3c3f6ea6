#pragma once
// domain::Serial: one process owns the whole shell (domain/domain.hpp).
// Nothing to exchange or agree on: an exception leaves as it was thrown, and
// a checkpoint is one file at its path.

#include <sphshell/core/error.hpp>
#include <sphshell/domain/domain.hpp>

#include <optional>
#include <string>
#include <utility>

namespace sphshell::domain {

class Serial {
 public:
  static constexpr bool is_distributed = false;
  int rank() const { return 0; }
  int size() const { return 1; }
  bool is_root() const { return true; }
  void agree(const std::optional<Failure>& failure) const {
    if (failure) throw Error(failure->message);
  }
  template <class Body>
  void collectively(Body&& body) const {
    std::forward<Body>(body)();
  }
  bool first_process_decides(bool value) const { return value; }
  std::string checkpoint_file(const std::string& path) const { return path; }
};

static_assert(check_domain<Serial>());

}  // namespace sphshell::domain
