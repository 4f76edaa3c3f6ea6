#pragma once
// The failure latch of a Solver's step, on one process or many. A step that
// stops part-way (an instability Error, or running out of memory) leaves a
// half-updated state: the latch keeps the error, and every later step
// refuses with it instead of going on from that state. Checkpoints keep the
// message, so a restart from a file written after a failure refuses too.

#include <sphshell/core/error.hpp>

#include <new>
#include <string>
#include <utility>

namespace sphshell::solver {

class StepLatch {
 public:
  // Throws the error that stopped an earlier step (nothing while open).
  void check() const {
    if (closed()) throw Error(message_);
  }

  // Runs advance(), one step; `steps` is the solver's step count, read after
  // a failure to name the step. An Error or a std::bad_alloc from advance()
  // closes the latch and leaves as an Error.
  template <class Count, class Advance>
  void run(const Count& steps, Advance&& advance) {
    check();
    try {
      std::forward<Advance>(advance)();
    } catch (const Error& error) {
      message_ = "sphshell: the solver stopped at step " + std::to_string(steps) +
                 " and cannot go on from its half-updated state; the error was: " + error.what();
      throw;
    } catch (const std::bad_alloc&) {
      message_ = "sphshell: out of memory (std::bad_alloc) in step " + std::to_string(steps);
      throw Error(message_);
    }
  }

  // Closes the latch with a message of the caller's (a checkpoint that failed
  // to load part-way).
  void close(std::string message) { message_ = std::move(message); }

  bool closed() const { return !message_.empty(); }
  // The message (empty while open), as checkpoints store it.
  std::string& message() { return message_; }
  const std::string& message() const { return message_; }

 private:
  std::string message_;
};

}  // namespace sphshell::solver
