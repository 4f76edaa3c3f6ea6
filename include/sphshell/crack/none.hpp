#pragma once
// crack::None: no fracture. Every pair interacts and no stress point is ever
// removed; the solver's crack hooks compile away.

namespace sphshell::crack {

struct None {
  static constexpr bool enabled = false;
  static constexpr const char* name = "none";
};

}  // namespace sphshell::crack
