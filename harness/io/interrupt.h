// SIGINT, SIGTERM and SIGHUP end a command cleanly: work that leaves files behind stops at its next check and cleans up.
#pragma once

#include "analytic/stop_request.h"  // Interrupted, and the request the stepping loops poll

namespace tippe {

// Installs the handlers (main, once). While no InterruptGuard lives, a signal has its default
// effect at once (a sweep's points are fsynced records and resume after any kill); while one
// lives, the signal is remembered for check_interrupted().
void install_interrupt_handlers();

// Defers SIGINT, SIGTERM and SIGHUP while something must be cleaned up if they come.
class InterruptGuard {
 public:
  InterruptGuard();
  ~InterruptGuard();
  InterruptGuard(const InterruptGuard&) = delete;
  InterruptGuard& operator=(const InterruptGuard&) = delete;
};

// Throws Interrupted when a deferred signal has arrived. Cheap: one atomic load.
void check_interrupted();

}  // namespace tippe
