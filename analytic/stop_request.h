// A request to stop (a deferred SIGINT, SIGTERM or SIGHUP): set by the harness's signal handler, polled by every stepping loop so that no run outlives a signal by more than a moment.
#pragma once

#include <atomic>
#include <cstring>
#include <exception>
#include <string>

namespace tippe {

// The pending signal's number, 0 for none. Written from a signal handler: a lock-free atomic,
// constant-initialised.
inline std::atomic<int> g_stop_request{0};
static_assert(std::atomic<int>::is_always_lock_free, "a signal handler may only touch lock-free atomics");

// Thrown where a loop sees the request: unwinding removes staging directories and temporary
// files; the command exits with 128 + the signal's number (harness/io/interrupt.h).
class Interrupted : public std::exception {
 public:
  explicit Interrupted(int signal)
      : signal_(signal),
        what_(std::string("interrupted by ") + (sigabbrev_np(signal) ? std::string("SIG") + sigabbrev_np(signal)
                                                                      : "signal " + std::to_string(signal))) {}
  const char* what() const noexcept override { return what_.c_str(); }
  int signal() const { return signal_; }

 private:
  int signal_;
  std::string what_;
};

// Throws Interrupted when a stop was requested. Cheap: one relaxed atomic load.
inline void poll_stop() {
  if (const int sig = g_stop_request.load(std::memory_order_relaxed)) throw Interrupted(sig);
}

// Steps between two polls in a stepping loop: an engine step or a reference step costs at most
// ~100 us on the shipped scenes, so 256 of them stay well under the second a signal may wait.
inline constexpr long long kStepsPerStopPoll = 256;

}  // namespace tippe
