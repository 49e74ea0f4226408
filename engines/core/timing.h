// Wall-clock and per-thread CPU clocks for work counters, read at a run's two ends only.
#pragma once

#include <chrono>
#include <ctime>

namespace tippe {

// A thread CPU clock read is a system call (the vDSO serves only the wall clocks): ~0.5-2 us,
// which per sample would cost more than sampling itself. Read it per run, not per step.
inline double thread_cpu_seconds() {
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

// The wall and CPU (calling thread) time from its construction to stop(): each clock read once
// at either end, so a run of any number of samples costs four clock reads.
class SpanTimer {
 public:
  SpanTimer() : w0_(std::chrono::steady_clock::now()), c0_(thread_cpu_seconds()) {}
  // Writes the span's wall and CPU seconds so far.
  void stop(double& wall, double& cpu) const {
    cpu = thread_cpu_seconds() - c0_;
    wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - w0_).count();
  }

 private:
  std::chrono::steady_clock::time_point w0_;
  double c0_;
};

}  // namespace tippe
