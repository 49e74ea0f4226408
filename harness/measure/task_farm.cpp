// Tasks on threads of one process: the local TaskFarm, and the thread pool under it.
#include "harness/measure/task_farm.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <exception>
#include <mutex>
#include <thread>

namespace tippe {

void parallel_for(size_t n, int jobs, const std::function<void(size_t)>& fn, const std::function<void()>& idle) {
  std::atomic<size_t> next{0}, finished{0};
  std::exception_ptr error;
  std::mutex error_m;
  std::atomic<bool> stop{false};
  auto worker = [&] {
    for (size_t k; !stop.load() && (k = next.fetch_add(1)) < n;) {
      try {
        fn(k);
      } catch (...) {
        std::lock_guard<std::mutex> lock(error_m);
        if (!error) error = std::current_exception();
        stop.store(true);
      }
      finished.fetch_add(1);
    }
  };
  const size_t threads = std::min(static_cast<size_t>(std::max(jobs, 1)), std::max<size_t>(n, 1));
  std::vector<std::thread> pool;
  for (size_t i = 0; i < threads; ++i) pool.emplace_back(worker);
  if (idle) {
    // Five redraws a second; the short naps end the wait soon after the last task.
    auto last = std::chrono::steady_clock::now() - std::chrono::seconds(1);
    while (finished.load() < n && !stop.load()) {
      if (std::chrono::steady_clock::now() - last >= std::chrono::milliseconds(200)) {
        idle();
        last = std::chrono::steady_clock::now();
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
  }
  for (auto& t : pool) t.join();
  if (error) std::rethrow_exception(error);
}

namespace {

class ThreadFarm : public TaskFarm {
 public:
  explicit ThreadFarm(int jobs) : jobs_(std::max(jobs, 1)) {}
  bool coordinator() const override { return true; }
  int workers() const override { return jobs_; }
  bool distributed() const override { return false; }
  void broadcast(std::string&) override {}
  std::vector<std::string> gather(const std::string& token) override { return {token}; }
  void run(size_t n, const Task& task, const Done& done, const Started& started, const Idle& idle) override {
    std::mutex m;
    // Local callers keep their own exception types (a SweepInputError stays one).
    parallel_for(
        n, jobs_,
        [&](size_t k) {
          if (started) {
            std::lock_guard<std::mutex> lock(m);
            started(k);
          }
          std::string result = task(k);
          std::lock_guard<std::mutex> lock(m);
          done(k, std::move(result));
        },
        idle);
  }

 private:
  int jobs_;
};

}  // namespace

std::string first_error(TaskFarm& farm, const std::string& error) {
  std::string verdict;
  if (!farm.distributed()) return error;
  const std::vector<std::string> all = farm.gather(error);
  for (size_t r = 0; r < all.size() && verdict.empty(); ++r)
    if (!all[r].empty()) verdict = r == 0 ? all[r] : "rank " + std::to_string(r) + ": " + all[r];
  farm.broadcast(verdict);
  return verdict;
}

std::unique_ptr<TaskFarm> make_thread_farm(int jobs) { return std::make_unique<ThreadFarm>(jobs); }

}  // namespace tippe
