#pragma once
// A folder taken by one writer: the lock file ".sphshell.lock" in it holds
// "pid <pid> host <host>" of the process whose solver writes there. It is
// created exclusively (O_EXCL), so of two solvers starting at once one wins;
// the other gets an Error naming the folder and the holder. A lock whose
// process is gone (same host, the pid no longer alive: a crash or a kill) is
// stale and taken over. A lock from another host cannot be judged from here
// and is refused like a live one. The lock is removed when its holder is
// destroyed.

#include <sphshell/core/error.hpp>

#include <cerrno>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <system_error>

#if defined(__unix__) || defined(__APPLE__)
#include <fcntl.h>
#include <signal.h>
#include <unistd.h>
#endif

namespace sphshell::io {

class DirectoryLock {
 public:
  static constexpr const char* file_name = ".sphshell.lock";

  // Takes `directory` (which must exist); `noun` names it in messages ("output_directory").
  DirectoryLock(const std::string& directory, const std::string& noun)
      : path_((std::filesystem::path(directory) / file_name).string()) {
    // Two tries: the second after removing a stale lock.
    for (int attempt = 0; attempt < 2; ++attempt) {
      if (try_create()) return;
      const Holder holder = read_holder();
      if (attempt == 0 && holder.is_gone()) {
        std::error_code ignored;
        std::filesystem::remove(path_, ignored);
        continue;
      }
      throw Error("sphshell: " + noun + " '" + directory + "' is in use by another solver (" + holder.text +
                  ", lock file '" + path_ + "'); give each run a folder of its own, or remove the lock file if "
                  "that process is no longer running");
    }
    throw Error("sphshell: cannot take " + noun + " '" + directory + "': its lock file '" + path_ +
                "' came back after a stale one was removed (another run is starting there)");
  }
  DirectoryLock(const DirectoryLock&) = delete;
  DirectoryLock& operator=(const DirectoryLock&) = delete;
  ~DirectoryLock() {
    std::error_code ignored;
    std::filesystem::remove(path_, ignored);
  }

  const std::string& path() const { return path_; }

  static std::string this_host() {
#if defined(__unix__) || defined(__APPLE__)
    char name[256] = {};
    if (::gethostname(name, sizeof name - 1) == 0) return name;
#endif
    return "unknown";
  }
  static long this_process() {
#if defined(__unix__) || defined(__APPLE__)
    return static_cast<long>(::getpid());
#else
    return 0;
#endif
  }

 private:
  struct Holder {
    long pid = -1;
    std::string host;
    std::string text;  // as the message shows it
    // Same host and the pid names no process (kill(pid, 0) fails with ESRCH).
    bool is_gone() const {
#if defined(__unix__) || defined(__APPLE__)
      if (pid <= 0 || host != this_host()) return false;
      return ::kill(static_cast<pid_t>(pid), 0) != 0 && errno == ESRCH;
#else
      return false;
#endif
    }
  };

  bool try_create() const {
    const std::string content = "pid " + std::to_string(this_process()) + " host " + this_host() + "\n";
#if defined(__unix__) || defined(__APPLE__)
    const int descriptor = ::open(path_.c_str(), O_WRONLY | O_CREAT | O_EXCL, 0644);
    if (descriptor < 0) {
      if (errno == EEXIST) return false;
      throw Error("sphshell: cannot create the lock file '" + path_ + "' (" +
                  std::generic_category().message(errno) + ")");
    }
    const ssize_t written = ::write(descriptor, content.data(), content.size());
    ::close(descriptor);
    if (written != static_cast<ssize_t>(content.size()))
      throw Error("sphshell: cannot write the lock file '" + path_ + "'");
    return true;
#else
    if (std::filesystem::exists(path_)) return false;
    std::ofstream(path_) << content;
    return true;
#endif
  }

  Holder read_holder() const {
    Holder holder;
    std::ifstream in(path_);
    std::string pid_word, host_word;
    if (in >> pid_word >> holder.pid >> host_word >> holder.host && pid_word == "pid" && host_word == "host") {
      holder.text = "pid " + std::to_string(holder.pid) + " on host " + holder.host;
    } else {
      holder.pid = -1;
      holder.text = "a holder the lock file does not name";
    }
    return holder;
  }

  std::string path_;
};

}  // namespace sphshell::io
