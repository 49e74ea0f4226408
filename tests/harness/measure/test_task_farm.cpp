// Tests of the task farm's contract (harness/measure/task_farm.cpp): every task run once, results handed over one at a time, and the first error rethrown after the tasks running.
#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <mutex>
#include <set>
#include <stdexcept>
#include <string>
#include <vector>

#include "harness/measure/task_farm.h"

namespace test_task_farm {

using namespace tippe;

TEST(TaskFarm, ThreadFarmRunsEveryTaskOnceAndHandsResultsOverOneAtATime) {
  auto farm = make_thread_farm(4);
  EXPECT_TRUE(farm->coordinator());
  EXPECT_FALSE(farm->distributed());
  EXPECT_EQ(farm->workers(), 4);
  std::vector<int> runs(200, 0), done(200, 0);
  std::atomic<int> inside{0};
  int max_inside = 0;
  std::mutex m;
  std::set<size_t> started;
  farm->run(
      200,
      [&](size_t k) {
        std::lock_guard<std::mutex> lock(m);
        ++runs[k];
        return std::to_string(k * k);
      },
      [&](size_t k, std::string&& r) {
        // `done` is never entered twice at once: no lock of its own is needed.
        max_inside = std::max(max_inside, ++inside);
        EXPECT_EQ(r, std::to_string(k * k));
        ++done[k];
        --inside;
      },
      [&](size_t k) { started.insert(k); });
  for (int k = 0; k < 200; ++k) {
    EXPECT_EQ(runs[k], 1) << k;
    EXPECT_EQ(done[k], 1) << k;
  }
  EXPECT_EQ(started.size(), 200u);
  EXPECT_EQ(max_inside, 1);
}

TEST(TaskFarm, ThreadFarmRethrowsTheFirstErrorAfterTheTasksRunning) {
  auto farm = make_thread_farm(2);
  std::atomic<int> finished{0};
  EXPECT_THROW(farm->run(
                   1000,
                   [&](size_t k) -> std::string {
                     if (k == 3) throw std::invalid_argument("task 3 failed");
                     return "";
                   },
                   [&](size_t, std::string&&) { ++finished; }),
               std::invalid_argument);
  // Handing out stopped: far from every task ran.
  EXPECT_LT(finished.load(), 1000);
  EXPECT_EQ(first_error(*farm, ""), "");
  EXPECT_EQ(first_error(*farm, "mine"), "mine");
}

}  // namespace test_task_farm
