// Tests of a sweep point's runs (harness/sweep/sweep_point.cpp): the repeats interleaved with other points' runs, their times folded into the record, the texts a worker sends back.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "harness/sweep/sweep_detail.h"
#include "tests/support/files.h"
#include "tests/support/records.h"
#include "tests/support/sweep_files.h"

namespace test_sweep_point {

using namespace tippe;
using namespace tippe::sweep_detail;

namespace {

// Each (point, round) once; a point's rounds in order; between two repeats of a point every other
// point of its block runs exactly once; blocks in order, each finished before the next begins.
void expect_interleaved(const std::vector<SweepTask>& tasks, size_t points, int repeats, size_t block) {
  ASSERT_EQ(tasks.size(), points * static_cast<size_t>(repeats));
  std::set<std::pair<size_t, int>> seen;
  std::map<size_t, std::vector<size_t>> at;  // point -> the positions of its runs
  for (size_t k = 0; k < tasks.size(); ++k) {
    ASSERT_LT(tasks[k].point, points);
    EXPECT_TRUE(seen.insert({tasks[k].point, tasks[k].round}).second) << "point " << tasks[k].point << " round " << tasks[k].round << " twice";
    EXPECT_EQ(tasks[k].round, static_cast<int>(at[tasks[k].point].size())) << "point " << tasks[k].point << " out of order";
    at[tasks[k].point].push_back(k);
  }
  for (const auto& [p, pos] : at) {
    const size_t b0 = p / block * block, b1 = std::min(points, b0 + block);
    for (size_t r = 1; r < pos.size(); ++r) {
      std::multiset<size_t> between;
      for (size_t k = pos[r - 1] + 1; k < pos[r]; ++k) between.insert(tasks[k].point);
      for (size_t q = b0; q < b1; ++q)
        EXPECT_EQ(between.count(q), q == p ? 0u : 1u) << "point " << q << " between repeats " << r - 1 << " and " << r
                                                      << " of point " << p;
      EXPECT_EQ(between.size(), b1 - b0 - 1) << "point " << p << ": a point of another block between its repeats";
    }
  }
}

}  // namespace

// The order a sweep hands its runs out in: rounds over blocks of points, never a point's repeats
// back to back (where one slow spell of the machine lasted through all three: BENCHMARKS.md,
// Simbody on toy_viscous).
TEST(SweepRepeats, ScheduleInterleavesEachPointsRepeatsWithItsBlock) {
  expect_interleaved(repeat_schedule(5, 3, 2), 5, 3, 2);
  expect_interleaved(repeat_schedule(70, 3, 32), 70, 3, 32);
  expect_interleaved(repeat_schedule(3, 4, 32), 3, 4, 32);
  const std::vector<SweepTask> t = repeat_schedule(5, 3, 2);
  const std::vector<std::pair<size_t, int>> want = {{0, 0}, {1, 0}, {0, 1}, {1, 1}, {0, 2}, {1, 2}, {2, 0}, {3, 0},
                                                    {2, 1}, {3, 1}, {2, 2}, {3, 2}, {4, 0}, {4, 1}, {4, 2}};
  ASSERT_EQ(t.size(), want.size());
  for (size_t k = 0; k < t.size(); ++k) {
    EXPECT_EQ(t[k].point, want[k].first) << k;
    EXPECT_EQ(t[k].round, want[k].second) << k;
  }
}

// One repeat: each point once, in the order given (as a sweep ran before repeats were interleaved).
TEST(SweepRepeats, OneRepeatIsEachPointOnceInOrder) {
  const std::vector<SweepTask> t = repeat_schedule(40, 1, 32);
  ASSERT_EQ(t.size(), 40u);
  for (size_t k = 0; k < t.size(); ++k) {
    EXPECT_EQ(t[k].point, k);
    EXPECT_EQ(t[k].round, 0);
  }
  EXPECT_TRUE(repeat_schedule(0, 3, 32).empty());
}

// The record's times are the repeats' minima, the list in the order they ran, and the ratios
// follow from the minima.
TEST(SweepRepeats, TimesFoldIntoTheRecord) {
  FirstRun f;
  f.final_time = 2.0;
  f.reference_cpu = 0.5;
  set_repeat_times(f, {{0.30, 0.40}, {0.20, 0.50}, {0.25, 0.25}});
  const SweepRecord& r = f.record;
  EXPECT_EQ(r.cpu_seconds_repeats, (std::vector<double>{0.30, 0.20, 0.25}));
  EXPECT_EQ(r.cpu_seconds, 0.20);
  EXPECT_EQ(r.wall_seconds, 0.25);
  EXPECT_EQ(r.metrics.cpu_seconds, 0.20);
  EXPECT_EQ(r.metrics.wall_seconds, 0.25);
  EXPECT_DOUBLE_EQ(r.metrics.cost_ratio, 0.4);
  EXPECT_DOUBLE_EQ(r.metrics.real_time_factor, 8.0);
  // A point whose scene's reference failed ran nothing: its record keeps what it says.
  FirstRun untimed;
  untimed.timed = false;
  untimed.record.cpu_seconds_repeats = {0.0};
  untimed.record.metrics.cost_ratio = std::nan("");
  set_repeat_times(untimed, {{1.0, 1.0}});
  EXPECT_EQ(untimed.record.cpu_seconds_repeats, std::vector<double>{0.0});
  EXPECT_TRUE(std::isnan(untimed.record.metrics.cost_ratio));
}

// What a worker on another rank sends back reads to the same numbers.
TEST(SweepRepeats, TaskTextsReadBackExactly) {
  const RepeatTime t{0.1 + 1e-17 * 3, 1.0 / 3.0};
  const std::optional<RepeatTime> back = read_repeat_time_text(repeat_time_text(t));
  ASSERT_TRUE(back);
  EXPECT_EQ(back->cpu, t.cpu);
  EXPECT_EQ(back->wall, t.wall);
  EXPECT_FALSE(read_repeat_time_text(repeat_time_text(std::nullopt)));
}

// End to end: a sweep of three repeats writes each point's record from its first run (every field
// but the times as with one repeat), with three times whose minimum is the point's.
TEST(SweepRepeats, ThreeRepeatsGiveOneRunsRecordWithThreeTimes) {
  TempDir dir{"tippe-sweep-repeats"};
  const std::string setup = fixtures::kGoodSetup;
  auto run = [&](int repeats, const std::string& name) {
    std::string head = fixtures::kGoodHead;
    head.replace(head.find("repeats = 1"), 11, "repeats = " + std::to_string(repeats));
    const SweepPlan plan = load_sweep(fixtures::write_sweep(dir.path(), head + setup, name + ".toml").string());
    SweepOptions o;
    o.out_dir = (dir.path() / name).string();
    o.jobs = 2;
    o.progress = false;
    run_sweep(plan, o);
    return read_records((dir.path() / name / "records.jsonl").string()).records;
  };
  const std::vector<SweepRecord> one = run(1, "one"), three = run(3, "three");
  ASSERT_EQ(one.size(), 2u);
  ASSERT_EQ(three.size(), 2u);
  std::map<long long, nlohmann::json> by_ladder;
  for (const SweepRecord& r : one) {
    nlohmann::json j = without_timings(to_json(r));
    j.erase("point_id");
    j.erase("repeats");
    by_ladder[r.ladder_index] = j;
  }
  for (const SweepRecord& r : three) {
    SCOPED_TRACE(r.ladder_label);
    ASSERT_EQ(r.cpu_seconds_repeats.size(), 3u);
    EXPECT_EQ(r.repeats, 3);
    EXPECT_EQ(r.cpu_seconds, *std::min_element(r.cpu_seconds_repeats.begin(), r.cpu_seconds_repeats.end()));
    EXPECT_EQ(r.metrics.cpu_seconds, r.cpu_seconds);
    nlohmann::json j = without_timings(to_json(r));
    j.erase("point_id");
    j.erase("repeats");
    EXPECT_EQ(j, by_ladder.at(r.ladder_index));
  }
}

}  // namespace test_sweep_point
