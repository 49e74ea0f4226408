// Tests of a sweep plan growing by a search's waves (harness/sweep/sweep_search.cpp), with a fake runner: each search's boundary found, interrupted and resumed, split over shards, and point ids that hash the search.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <optional>
#include <set>
#include <string>
#include <tuple>
#include <vector>

#include "harness/sweep/sweep.h"
#include "harness/sweep/sweep_search.h"
#include "tests/support/files.h"
#include "tests/support/records.h"
#include "tests/support/sweep_searches.h"

namespace test_sweep_search_plan {

using namespace tippe;
using nlohmann::json;

namespace {

using namespace tippe::fixtures;

// The synthetic physics: each search's own boundary, a function of scene, setup and grid value.
double synthetic_boundary(const SweepPoint& p) {
  return 1e-4 * (1 + static_cast<double>(p.scene_index)) * (1 + 3 * static_cast<double>(p.setup_index)) *
         (1 + 0.5 * static_cast<double>(p.grid_index));
}

SweepRecord fake_record(const SweepPlan& plan, const SweepPoint& p) {
  const SweepSetup& s = plan.spec.setups[p.setup_index];
  SweepRecord r;
  r.point_id = p.id;
  r.scene = p.scene.name;
  r.scene_index = static_cast<long long>(p.scene_index);
  r.setup = s.name;
  r.engine = s.engine;
  r.set = s.set;
  r.ladder_key = s.ladder_key;
  r.ladder_value = p.ladder_value;
  r.ladder_label = p.ladder_label;
  r.setup_index = static_cast<long long>(p.setup_index);
  r.ladder_index = static_cast<long long>(p.ladder_index);
  if (s.has_grid()) {
    r.grid_key = s.grid_key;
    r.grid_value = s.grid_values[p.grid_index];
    r.grid_label = s.grid_labels[p.grid_index];
    r.grid_index = static_cast<long long>(p.grid_index);
  }
  r.search = s.search;
  r.reference_inversion_time = 4.33;
  const bool in = p.ladder_value <= synthetic_boundary(p);
  if (in) r.inversion_time = 4.33 * (1 + 1e-3);
  r.metrics.inversion_time_rel_error = in ? 1e-3 : 0.5;
  r.engine_version = r.git_commit = "fake";
  r.cpu_seconds = 1e-3 / p.ladder_value;
  return r;
}

// What run_search_sweep does, with fake runs: replay the records into the plan, then run the
// missing points of the share wave by wave. Stops (an interruption) after `budget` new records.
std::vector<SweepRecord> fake_sweep(SweepPlan plan, std::vector<SweepRecord> records, size_t budget = 1000000,
                                    const std::optional<SweepShard>& shard = std::nullopt, size_t* waves = nullptr) {
  extend_search_plan(plan, records);
  for (size_t wave = 0;; ++wave) {
    if (wave > 0) {
      const std::vector<SearchPoint> f = search_frontier(plan, records);
      if (f.empty()) break;
      // The wave reaches every rank as text.
      add_search_points(plan, decode_search_points(encode_search_points(f)));
    }
    std::set<std::string> done;
    for (const SweepRecord& r : records) done.insert(r.point_id);
    std::vector<size_t> share;
    if (shard) {
      share = shard_points(plan, *shard);
    } else {
      for (size_t i = 0; i < plan.points.size(); ++i) share.push_back(i);
    }
    for (size_t i : share) {
      if (done.count(plan.points[i].id)) continue;
      if (budget-- == 0) return records;
      records.push_back(fake_record(plan, plan.points[i]));
    }
    if (waves) *waves = wave + 1;
  }
  return records;
}

std::map<std::string, json> keyed(const std::vector<SweepRecord>& records) {
  std::map<std::string, json> m;
  for (const SweepRecord& r : records) EXPECT_TRUE(m.emplace(r.point_id, without_timings(to_json(r))).second) << r.point_id;
  return m;
}

TEST(SweepSearchPlan, WavesFindEachSearchsBoundaryAndKeepTheLadders) {
  TempDir dir;
  const SweepPlan plan = load_sweep(dir.write("s.toml", sweep_text()));
  // Planned up front: 2 scenes x (6 coarse + 2 x 4 coarse + 2 ladder values).
  EXPECT_EQ(plan.planned, 2u * (6 + 8 + 2));
  EXPECT_EQ(plan.points.size(), plan.planned);
  size_t waves = 0;
  const std::vector<SweepRecord> records = fake_sweep(plan, {}, 1000000, std::nullopt, &waves);
  const std::vector<SearchBoundary> b = search_boundaries(records);
  ASSERT_EQ(b.size(), 2u * (1 + 2));
  for (const SearchBoundary& x : b) {
    SweepPoint p;
    p.scene_index = static_cast<size_t>(x.scene_index);
    p.setup_index = static_cast<size_t>(x.setup_index);
    p.grid_index = static_cast<size_t>(x.grid_index);
    const double truth = synthetic_boundary(p);
    ASSERT_EQ(x.status, "found") << x.scene << " " << x.setup;
    EXPECT_LE(*x.boundary, truth);
    EXPECT_GT(*x.beyond, truth);
    EXPECT_LT(std::log10(*x.beyond / *x.boundary), x.search.resolution);
  }
  // Each search is independent; the waves are the longest bisection plus the coarse wave.
  EXPECT_LE(waves, 1u + 5u);
  // Every id distinct, every index below the sweep's bound.
  const auto m = keyed(records);
  EXPECT_EQ(m.size(), records.size());
  for (const SweepRecord& r : records) EXPECT_LT(r.ladder_index, static_cast<long long>(kMaxSweepPoints));
}

TEST(SweepSearchPlan, InterruptedAndResumedGivesTheRecordsOfAnUninterruptedSearch) {
  TempDir dir;
  const std::string file = dir.write("s.toml", sweep_text());
  const std::vector<SweepRecord> whole = fake_sweep(load_sweep(file), {});
  // Interrupted after every possible number of records: mid coarse grid, mid bisection, at the end.
  for (size_t cut = 0; cut <= whole.size(); cut += 3) {
    const std::vector<SweepRecord> part = fake_sweep(load_sweep(file), {}, cut);
    ASSERT_EQ(part.size(), std::min(cut, whole.size()));
    // A new process: the plan from the file, the records from the directory.
    const std::vector<SweepRecord> resumed = fake_sweep(load_sweep(file), part);
    EXPECT_EQ(keyed(resumed), keyed(whole)) << "interrupted after " << cut << " records";
  }
}

TEST(SweepSearchPlan, ShardsKeepEachSearchWholeAndTogetherGiveTheWholeSweep) {
  TempDir dir;
  const std::string file = dir.write("s.toml", sweep_text());
  const std::vector<SweepRecord> whole = fake_sweep(load_sweep(file), {});
  std::vector<SweepRecord> merged;
  std::map<std::tuple<long long, long long, long long>, int> owner;
  for (int i = 0; i < 3; ++i) {
    const std::vector<SweepRecord> part = fake_sweep(load_sweep(file), {}, 1000000, SweepShard{i, 3});
    for (const SweepRecord& r : part) {
      if (r.search) {
        const auto [it, fresh] = owner.emplace(std::make_tuple(r.scene_index, r.setup_index, r.grid_index), i);
        EXPECT_EQ(it->second, i) << "a search split over shards " << it->second << " and " << i;
        (void)fresh;
      }
      merged.push_back(r);
    }
  }
  EXPECT_EQ(keyed(merged), keyed(whole));
}

TEST(SweepSearchPlan, PointIdsHashTheSearch) {
  TempDir dir;
  const SweepPlan a = load_sweep(dir.write("a.toml", sweep_text()));
  std::string text = sweep_text();
  text.replace(text.find("criterion = \"regime\""), 20, "criterion = \"tilt_rms_error <= 0.1\"");
  const SweepPlan b = load_sweep(dir.write("b.toml", text));
  EXPECT_NE(a.points[0].id, b.points[0].id);
  EXPECT_NE(a.plan_hash, b.plan_hash);
  EXPECT_EQ(a.points[0].ladder_label, "1e-06");
}

}  // namespace

}  // namespace test_sweep_search_plan
