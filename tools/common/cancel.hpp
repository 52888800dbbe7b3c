// Stopping a tool on SIGINT, SIGTERM or SIGHUP, shared by the command-line tools.
//
// install_cancel_handlers() blocks the three signals in every thread (call it first in main,
// before any thread exists: OpenMP workers inherit the mask) and waits for them in one watcher
// thread. A signal raises cancel_flag(), which the library polls (BakeOptions::cancel,
// ValidationOptions::cancel, ...); the tool then unwinds, removes its temporaries and returns
// cancel_exit_code(): 128 + the signal (130 SIGINT, 143 SIGTERM, 129 SIGHUP). If the tool is still
// running after the grace period (a computation that does not poll), the watcher removes this
// process's temporaries ("*.tmp-<pid>") from the registered directories and ends the process with
// the same code, so every tool stops within about a second of the signal.
//
// SIGXFSZ (a file-size limit, `ulimit -f`) is ignored, so exceeding the limit is a write error
// (EFBIG) reported as an I/O failure instead of a kill.
#pragma once

#include <signal.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

namespace hairlut_tools {

namespace detail {
inline std::atomic<bool> cancel{false};
inline std::atomic<int> signal_number{0};
inline std::mutex mutex;
inline std::vector<std::filesystem::path> temp_dirs;

// Removes "<anything>.tmp-<this pid>" in the registered directories.
inline void remove_own_temporaries() {
  const std::string suffix = ".tmp-" + std::to_string(::getpid());
  std::lock_guard<std::mutex> lock(mutex);
  for (const auto& dir : temp_dirs) {
    std::error_code ec;
    for (const auto& entry : std::filesystem::directory_iterator(dir, ec)) {
      const std::string n = entry.path().filename().string();
      if (n.size() > suffix.size() && n.compare(n.size() - suffix.size(), suffix.size(), suffix) == 0)
        std::filesystem::remove(entry.path(), ec);
    }
  }
}
}  // namespace detail

/// Raised once SIGINT, SIGTERM or SIGHUP arrived.
inline const std::atomic<bool>& cancel_flag() { return detail::cancel; }
inline std::atomic<bool>* cancel_pointer() { return &detail::cancel; }

/// 128 + the signal received (130 when none was: a cancellation by other means).
inline int cancel_exit_code() {
  const int s = detail::signal_number.load();
  return 128 + (s ? s : SIGINT);
}

/// Directory in which this process may leave "*.tmp-<pid>" files to remove if it must stop hard.
inline void register_temp_dir(const std::filesystem::path& dir) {
  std::lock_guard<std::mutex> lock(detail::mutex);
  detail::temp_dirs.push_back(dir.empty() ? std::filesystem::path(".") : dir);
}

/// See the file comment. `tool` names the program in the message printed on a hard stop.
inline void install_cancel_handlers(const char* tool, std::chrono::milliseconds grace = std::chrono::milliseconds(800)) {
  ::signal(SIGXFSZ, SIG_IGN);
  sigset_t set;
  sigemptyset(&set);
  sigaddset(&set, SIGINT);
  sigaddset(&set, SIGTERM);
  sigaddset(&set, SIGHUP);
  if (pthread_sigmask(SIG_BLOCK, &set, nullptr) != 0) return;  // keep the default actions
  std::thread([set, tool, grace] {
    int sig = 0;
    while (sigwait(&set, &sig) != 0) {
    }
    detail::signal_number.store(sig);
    detail::cancel.store(true);
    std::this_thread::sleep_for(grace);
    detail::remove_own_temporaries();
    std::fprintf(stderr, "\n%s: interrupted by signal %d; stopped\n", tool, sig);
    std::fflush(stderr);
    std::_Exit(128 + sig);
  }).detach();
}

}  // namespace hairlut_tools
