// The sweep's progress line: points done, what runs, elapsed time and an estimate of the time left.
#pragma once

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <map>
#include <mutex>
#include <string>
#include <utility>
#include <vector>

#include "harness/io/progress.h"
#include "harness/sweep/sweep_detail.h"

namespace tippe::sweep_detail {

inline std::string clock_text(double seconds) {
  const long long s = static_cast<long long>(std::llround(std::max(0.0, seconds)));
  char buf[32];
  if (s >= 3600)
    std::snprintf(buf, sizeof buf, "%lld:%02lld:%02lld", s / 3600, s / 60 % 60, s % 60);
  else
    std::snprintf(buf, sizeof buf, "%lld:%02lld", s / 60, s % 60);
  return buf;
}

// The one progress line: points done, what runs, elapsed and an estimate of the time left. Its
// unit of work is one run of a point (a point runs `repeats` times, interleaved: repeat_schedule).
// Each setup's wall time of a run is fitted as a + b * weight over its finished runs: a is the
// per-run overhead (a MuJoCo model compile, the comparison), which would make a plain ratio taken
// on a short point overestimate every long one.
class SweepProgress {
 public:
  // todo: the points to run (indices into plan.points), tasks: their runs in the order handed out
  // (indices into todo); total: the points of this run's share (the whole plan, or a shard's);
  // lines: one full line every 10 s instead of redrawing one (stderr passed on by an MPI launcher).
  SweepProgress(const SweepPlan& plan, std::vector<size_t> todo, std::vector<SweepTask> tasks, int repeats,
                size_t total, size_t skipped, int jobs, bool lines)
      : plan_(plan),
        todo_(std::move(todo)),
        tasks_(std::move(tasks)),
        repeats_(std::max(repeats, 1)),
        total_(total),
        skipped_(skipped),
        jobs_(jobs),
        lines_(lines),
        start_(now()),
        started_(tasks_.size(), -1.0),
        finished_(tasks_.size(), false) {}

  void begin(size_t task) {
    std::lock_guard<std::mutex> lock(m_);
    started_[task] = now() - start_;
  }
  void end(size_t task, double wall) {
    std::lock_guard<std::mutex> lock(m_);
    finished_[task] = true;
    const SweepPoint& p = point(task);
    samples_[p.setup_index].emplace_back(weight(p), wall);
  }
  // A point's last run came in and its record is written.
  void point_done() {
    std::lock_guard<std::mutex> lock(m_);
    ++done_;
  }

  void print(bool final_line) {
    std::lock_guard<std::mutex> lock(m_);
    const double elapsed = now() - start_;
    if (lines_ && !final_line && elapsed - last_line_ < kProgressLineSeconds) return;
    last_line_ = elapsed;
    char buf[160];
    std::snprintf(buf, sizeof buf, "[sweep] %zu/%zu points", done_ + skipped_, total_);
    std::string line = buf;
    if (skipped_) line += " (" + std::to_string(skipped_) + " from an earlier run)";
    size_t running = 0, next = tasks_.size();
    for (size_t k = 0; k < tasks_.size(); ++k) {
      running += started_[k] >= 0 && !finished_[k];
      if (started_[k] < 0 && next == tasks_.size()) next = k;
    }
    if (!final_line) line += " | " + std::to_string(running) + " running";
    // Which repeat is being handed out (the block's round), when a point runs more than once.
    if (!final_line && repeats_ > 1 && next < tasks_.size())
      line += " | repeat " + std::to_string(tasks_[next].round + 1) + "/" + std::to_string(repeats_);
    line += " | " + clock_text(elapsed) + " elapsed";
    if (!final_line) {
      const double left = estimate_left(elapsed);
      line += std::isfinite(left) ? " | ~" + clock_text(left) + " left" : " | estimating";
    }
    out_.write(std::move(line), final_line);
  }

 private:
  const SweepPoint& point(size_t task) const { return plan_.points[todo_[tasks_[task].point]]; }
  // One run's share of the point's a priori weight (which counts every repeat).
  double weight(const SweepPoint& p) const { return point_weight(plan_, p) / repeats_; }
  static double now() {
    return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
  }
  // Expected wall seconds of a run of weight w of this setup; NaN before any run finished.
  double expect(size_t setup, double w) const {
    auto it = samples_.find(setup);
    double sw = 0, st = 0;
    if (it == samples_.end()) {
      // No point of this setup yet: the ratio over every finished point.
      for (const auto& [s, v] : samples_)
        for (const auto& [x, t] : v) {
          sw += x;
          st += t;
        }
      return sw > 0 ? st / sw * w : std::nan("");
    }
    const auto& v = it->second;
    double sww = 0, swt = 0;
    for (const auto& [x, t] : v) {
      sw += x;
      st += t;
      sww += x * x;
      swt += x * t;
    }
    const double n = static_cast<double>(v.size()), det = n * sww - sw * sw;
    if (v.size() >= 2 && det > 1e-12 * sww * n) {
      const double b = (n * swt - sw * st) / det, a = (st - b * sw) / n;
      if (b > 0 && a >= 0) return a + b * w;
    }
    return sw > 0 ? st / sw * w : std::nan("");
  }
  double estimate_left(double elapsed) const {
    if (samples_.empty()) return std::nan("");
    double left = 0;
    for (size_t k = 0; k < tasks_.size(); ++k) {
      if (finished_[k]) continue;
      const SweepPoint& p = point(k);
      const double expect = this->expect(p.setup_index, weight(p));
      left += started_[k] >= 0 ? std::max(0.0, expect - (elapsed - started_[k])) : expect;
    }
    return left / jobs_;
  }

  const SweepPlan& plan_;
  std::vector<size_t> todo_;
  std::vector<SweepTask> tasks_;
  int repeats_;
  size_t total_, skipped_;
  int jobs_;
  bool lines_;
  double last_line_ = -1e9;
  double start_;
  std::mutex m_;
  std::vector<double> started_;
  std::vector<bool> finished_;
  size_t done_ = 0;
  std::map<size_t, std::vector<std::pair<double, double>>> samples_;  // setup -> (weight, wall)
  ProgressLine out_{lines_};
};


}  // namespace tippe::sweep_detail
