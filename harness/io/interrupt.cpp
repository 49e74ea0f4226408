// SIGINT, SIGTERM and SIGHUP end a command cleanly: work that leaves files behind stops at its next check and cleans up.
#include "harness/io/interrupt.h"

#include <signal.h>
#include <string.h>

#include <atomic>

namespace tippe {

namespace {

std::atomic<int> g_guards{0};

extern "C" void on_signal(int sig) {
  if (g_guards.load() == 0) {
    // Nothing to clean up: the default action, as if no handler were installed.
    ::signal(sig, SIG_DFL);
    ::raise(sig);
    return;
  }
  int none = 0;
  g_stop_request.compare_exchange_strong(none, sig);
}

}  // namespace

void install_interrupt_handlers() {
  struct sigaction sa {};
  sa.sa_handler = on_signal;
  sigemptyset(&sa.sa_mask);
  sa.sa_flags = SA_RESTART;
  for (int sig : {SIGINT, SIGTERM, SIGHUP}) ::sigaction(sig, &sa, nullptr);
}

InterruptGuard::InterruptGuard() { g_guards.fetch_add(1); }

InterruptGuard::~InterruptGuard() { g_guards.fetch_sub(1); }

void check_interrupted() { poll_stop(); }

}  // namespace tippe
