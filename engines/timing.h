// Wall-clock and per-thread CPU clocks for work counters (CPU time stays fair under load).
#pragma once

#include <chrono>
#include <ctime>

namespace tippe {

inline double thread_cpu_seconds() {
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

// Adds the wall and CPU time of its lifetime to two accumulators.
class WorkTimer {
 public:
  WorkTimer(double& wall, double& cpu)
      : wall_(wall), cpu_(cpu), w0_(std::chrono::steady_clock::now()), c0_(thread_cpu_seconds()) {}
  ~WorkTimer() {
    wall_ += std::chrono::duration<double>(std::chrono::steady_clock::now() - w0_).count();
    cpu_ += thread_cpu_seconds() - c0_;
  }
  WorkTimer(const WorkTimer&) = delete;
  WorkTimer& operator=(const WorkTimer&) = delete;

 private:
  double& wall_;
  double& cpu_;
  std::chrono::steady_clock::time_point w0_;
  double c0_;
};

}  // namespace tippe
