// Tests of sweeps in shards and their merge (harness/sweep/sweep_merge.cpp, the split in sweep_run.cpp): shards partition the plan, merged they give the whole run's records and resume as it, and what is not one whole split of one sweep is refused.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <map>
#include <set>
#include <stdexcept>
#include <string>
#include <vector>

#include "harness/report/sweep_analysis.h"
#include "harness/sweep/sweep.h"
#include "tests/support/files.h"
#include "tests/support/fixtures.h"
#include "tests/support/process.h"
#include "tests/support/sweep_runs.h"

namespace test_sweep_merge {

namespace fs = std::filesystem;
using namespace tippe;
using nlohmann::json;
using namespace tippe::sweep_runs;

namespace {

const std::string& kSource = fixtures::kSourceDir;

// ---- shards -----------------------------------------------------------------------------------

TEST(SweepShards, ShardsPartitionThePlanAndBalanceItsWeight) {
  const SweepPlan plan = load_sweep(kSmoke);
  for (int n : {1, 2, 3, 7, 25}) {
    std::vector<int> owner(plan.points.size(), -1);
    for (int i = 0; i < n; ++i) {
      const std::vector<size_t> share = shard_points(plan, {i, n});
      EXPECT_TRUE(std::is_sorted(share.begin(), share.end()));
      EXPECT_EQ(share, shard_points(plan, {i, n})) << "not a pure function of the plan";
      for (size_t p : share) {
        EXPECT_EQ(owner[p], -1) << "point " << p << " in shards " << owner[p] << " and " << i << " of " << n;
        owner[p] = i;
      }
    }
    for (size_t p = 0; p < owner.size(); ++p) EXPECT_NE(owner[p], -1) << "point " << p << " in no shard of " << n;
  }
  EXPECT_EQ(shard_points(plan, {0, 1}).size(), plan.points.size());
  // More shards than points: the extra shards are empty, none is given a point twice.
  size_t total = 0;
  for (int i = 0; i < 25; ++i) total += shard_points(plan, {i, 25}).size();
  EXPECT_EQ(total, plan.points.size());
}

// Records from ranks or merged shards arrive in another order than a local run's: the report must
// not depend on it.
TEST(SweepShards, TheReportDoesNotDependOnTheOrderOfTheRecords) {
  std::vector<SweepRecord> records = read_records((local_smoke() / "records.jsonl").string()).records;
  ASSERT_EQ(records.size(), load_sweep(kSmoke).points.size());
  const std::string expected = render_sweep_markdown(records);
  std::reverse(records.begin(), records.end());
  EXPECT_EQ(render_sweep_markdown(records), expected);
  std::rotate(records.begin(), records.begin() + 7, records.end());
  EXPECT_EQ(render_sweep_markdown(records), expected);
}

TEST(SweepShards, ParseShardTakesIOverNAndNamesWhatIsWrong) {
  EXPECT_EQ(parse_shard("0/1").index, 0);
  EXPECT_EQ(parse_shard("2/3").count, 3);
  for (const char* bad : {"", "3", "3/3", "-1/3", "1/0", "a/3", "1/3/4", "1 /3", "1/1000001"}) {
    try {
      parse_shard(bad);
      ADD_FAILURE() << "accepted \"" << bad << "\"";
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find(std::string("\"") + bad + "\""), std::string::npos) << e.what();
    }
  }
}

TEST(SweepShards, ThreeShardsMergedEqualTheWholeRunAndResumeAsIt) {
  TempDir dir("tippe-shards");
  const fs::path log = dir.path() / "log";
  std::vector<std::string> merge = {"--merge"};
  for (int i = 0; i < 3; ++i) {
    const std::string d = (dir.path() / ("shard" + std::to_string(i))).string();
    ASSERT_EQ(run(tippe_sweep({kSmoke, "--shard", std::to_string(i) + "/3", "--out", d, "--jobs", "1"}), log), 0)
        << slurp(log);
    merge.push_back(d);
  }
  const fs::path merged = dir.path() / "merged";
  merge.insert(merge.end(), {"--out", merged.string()});
  ASSERT_EQ(run(tippe_sweep(merge), log), 0) << slurp(log);
  const std::string n = std::to_string(load_sweep(kSmoke).points.size());
  EXPECT_NE(slurp(log).find("merged: 3 shards, " + n + " points"), std::string::npos) << slurp(log);
  expect_same_records(local_smoke(), merged);

  // The merged directory is the whole sweep's: same hashes, no shard, the report, and a run of the
  // sweep into it finds every point done and every reference cached.
  const json a = json::parse(slurp(local_smoke() / "sweep.json")), b = json::parse(slurp(merged / "sweep.json"));
  EXPECT_EQ(a["sweep_hash"], b["sweep_hash"]);
  EXPECT_EQ(a["plan_hash"], b["plan_hash"]);
  EXPECT_TRUE(b["shard"].is_null());
  EXPECT_EQ(b["merged_from"].size(), 3u);
  EXPECT_TRUE(fs::exists(merged / "report.md"));
  ASSERT_EQ(run(tippe_sweep({kSmoke, "--out", merged.string(), "--jobs", "1"}), log), 0) << slurp(log);
  EXPECT_NE(slurp(log).find("(" + n + " from an earlier run, 0 run now)"), std::string::npos) << slurp(log);

  // Merging again into the merge's own directory replaces it with the same records.
  ASSERT_EQ(run(tippe_sweep(merge), log), 0) << slurp(log);
  expect_same_records(local_smoke(), merged);
}

// Runs a shard of `sweep` into DIR/name; the directory.
std::string make_shard(const TempDir& dir, const std::string& sweep, const std::string& shard, const std::string& name) {
  const std::string d = (dir.path() / name).string();
  const fs::path log = dir.path() / "shard.log";
  EXPECT_EQ(run(tippe_sweep({sweep, "--shard", shard, "--out", d, "--jobs", "1"}), log), 0) << slurp(log);
  return d;
}

// `tippe sweep --merge DIRS --out OUT` exits 2 with a message that contains `needle`, and OUT is
// left as it was (absent here).
void expect_merge_refused(const TempDir& dir, const std::vector<std::string>& dirs, const std::string& needle,
                          const std::string& what) {
  const fs::path out = dir.path() / "refused", log = dir.path() / "merge.log";
  std::vector<std::string> args = {"--merge"};
  args.insert(args.end(), dirs.begin(), dirs.end());
  args.insert(args.end(), {"--out", out.string()});
  EXPECT_EQ(run(tippe_sweep(args), log), 2) << what << ": " << slurp(log);
  EXPECT_NE(slurp(log).find(needle), std::string::npos) << what << ": " << slurp(log);
  EXPECT_FALSE(fs::exists(out)) << what << ": the refused merge wrote " << out;
}

TEST(SweepShards, MergeRefusesWhatIsNotOneWholeSplitOfOneSweep) {
  TempDir dir("tippe-merge-bad");
  const std::string s0 = make_shard(dir, kSmoke, "0/3", "s0"), s1 = make_shard(dir, kSmoke, "1/3", "s1"),
                    s2 = make_shard(dir, kSmoke, "2/3", "s2");
  // The same sweep file with another description: another file, whose shards must not mix.
  std::string other_text = slurp(kSmoke);
  other_text.replace(other_text.find("description = \""), 15, "description = \"Other: ");
  const std::string other = dir.write("sweeps/other.toml", other_text);
  fs::copy(kSource + "/harness/scenes", dir.path() / "scenes", fs::copy_options::recursive);
  const std::string o2 = make_shard(dir, other, "2/3", "o2");
  const std::string h1 = make_shard(dir, kSmoke, "1/2", "h1");

  expect_merge_refused(dir, {s0, s1}, "shard(s) 2/3 missing", "a missing shard");
  expect_merge_refused(dir, {s0, s1, o2}, "sweep_hash: a shard of another sweep file", "another sweep file");
  expect_merge_refused(dir, {s0, s1, s2, h1}, "is of another split", "another shard count");
  expect_merge_refused(dir, {s0, s1, s1, s2}, "given twice", "a shard twice");
  expect_merge_refused(dir, {s0, s1, s2, local_smoke().string()}, "not a shard", "a whole run");
  expect_merge_refused(dir, {s0, s1, (dir.path() / "nothing").string()}, "no sweep.json", "not a directory of a sweep");

  // An unfinished shard: its last record dropped, then cut mid-line.
  const fs::path rec = fs::path(s2) / "records.jsonl";
  const std::string full = slurp(rec);
  const size_t last = full.rfind('\n', full.size() - 2);
  spit(rec, full.substr(0, last + 1));
  const size_t own = json::parse(slurp(fs::path(s2) / "sweep.json"))["shard"]["point_ids"].size();
  expect_merge_refused(dir, {s0, s1, s2}, "1 of " + std::to_string(own) + " points of shard 2/3 unfinished",
                       "an unfinished shard");
  spit(rec, full.substr(0, last + 10));
  expect_merge_refused(dir, {s0, s1, s2}, "ends in a partial line", "a shard cut short");
  // A record of another shard in this one.
  spit(rec, full + lines_of(fs::path(s0) / "records.jsonl").front().dump() + "\n");
  expect_merge_refused(dir, {s0, s1, s2}, "is not of shard 2/3", "a foreign point");
  spit(rec, full);

  // The output directory: one of the shards, or a run of its own.
  const fs::path log = dir.path() / "merge.log";
  EXPECT_EQ(run(tippe_sweep({"--merge", s0, s1, s2, "--out", s1}), log), 2);
  EXPECT_NE(slurp(log).find("is the --out directory"), std::string::npos) << slurp(log);
  const fs::path whole = dir.path() / "whole";
  fs::create_directories(whole);
  fs::copy_file(local_smoke() / "sweep.json", whole / "sweep.json");
  EXPECT_EQ(run(tippe_sweep({"--merge", s0, s1, s2, "--out", whole.string()}), log), 2);
  EXPECT_NE(slurp(log).find("holds another sweep or a run of its own"), std::string::npos) << slurp(log);
  EXPECT_FALSE(fs::exists(whole / "records.jsonl"));
  // And the good merge still goes through.
  EXPECT_EQ(run(tippe_sweep({"--merge", s2, s0, s1, "--out", (dir.path() / "good").string()}), log), 0) << slurp(log);
}

TEST(SweepShards, AShardDirectoryTakesOnlyItsOwnShard) {
  TempDir dir("tippe-shard-dir");
  const std::string s0 = make_shard(dir, kSmoke, "0/3", "s0");
  const fs::path log = dir.path() / "log";
  EXPECT_EQ(run(tippe_sweep({kSmoke, "--shard", "1/3", "--out", s0, "--jobs", "1"}), log), 2);
  EXPECT_NE(slurp(log).find("holds shard 0/3, this run is shard 1/3"), std::string::npos) << slurp(log);
  EXPECT_EQ(run(tippe_sweep({kSmoke, "--out", s0, "--jobs", "1"}), log), 2);
  EXPECT_NE(slurp(log).find("holds shard 0/3, this run is the whole sweep"), std::string::npos) << slurp(log);
  EXPECT_EQ(run(tippe_sweep({kSmoke, "--shard", "0/3", "--out", s0, "--jobs", "1"}), log), 0) << slurp(log);
  EXPECT_NE(slurp(log).find("0 run now"), std::string::npos) << slurp(log);
  EXPECT_EQ(run(tippe_sweep({kSmoke, "--shard", "3/3", "--out", (dir.path() / "x").string()}), log), 2);
  EXPECT_FALSE(fs::exists(dir.path() / "x"));
}

TEST(SweepShards, AFailingReferenceIsRecordedForItsSceneAndTheOtherScenesRun) {
  TempDir dir("tippe-local-fail");
  const std::string sweep = failing_reference_sweep(dir);
  const fs::path log = dir.path() / "log";
  const ChildExit e = wait_process_within(
      spawn_process(tippe_sweep({sweep, "--out", (dir.path() / "out").string(), "--jobs", "2"}), log, log), 120);
  EXPECT_FALSE(e.timed_out) << "the sweep hung:\n" << slurp(log);
  EXPECT_EQ(e.code, 0) << slurp(log);
  expect_failed_reference_recorded(dir.path() / "out", slurp(log));
  // Resumed, every point is done: the failed ones are results, not holes.
  ASSERT_EQ(run(tippe_sweep({sweep, "--out", (dir.path() / "out").string(), "--jobs", "2"}), log), 0) << slurp(log);
  EXPECT_NE(slurp(log).find("(4 from an earlier run, 0 run now)"), std::string::npos) << slurp(log);
}

TEST(SweepShards, GridAndCategoricalLaddersShardMergeAndResumeAsOneRun) {
  TempDir dir("tippe-grid");
  const std::string sweep = grid_sweep(dir);
  const fs::path log = dir.path() / "log", local = dir.path() / "local";
  ASSERT_EQ(run(tippe_sweep({sweep, "--out", local.string(), "--jobs", "2"}), log), 0) << slurp(log);
  const std::vector<json> lines = lines_of(local / "records.jsonl");
  ASSERT_EQ(lines.size(), 6u);
  std::set<std::string> cells;
  for (const json& r : lines)
    if (r.at("setup") == "ode")
      cells.insert(r.at("ladder_label").get<std::string>() + "/" + r.at("grid").at("label").get<std::string>());
    else
      cells.insert(r.at("ladder_label").get<std::string>() + (r.at("grid").is_null() ? "" : "?"));
  EXPECT_EQ(cells, (std::set<std::string>{"0.001/approx1", "0.001/box", "0.002/approx1", "0.002/box", "com",
                                          "ball_centre"}));
  EXPECT_NE(slurp(local / "report.md").find("## Modelling choices"), std::string::npos);

  std::vector<std::string> merge = {"--merge"};
  for (int i = 0; i < 2; ++i) {
    const std::string d = (dir.path() / ("shard" + std::to_string(i))).string();
    ASSERT_EQ(run(tippe_sweep({sweep, "--shard", std::to_string(i) + "/2", "--out", d, "--jobs", "1"}), log), 0)
        << slurp(log);
    merge.push_back(d);
  }
  const fs::path merged = dir.path() / "merged";
  merge.insert(merge.end(), {"--out", merged.string()});
  ASSERT_EQ(run(tippe_sweep(merge), log), 0) << slurp(log);
  expect_same_records(local, merged);
  // The merge writes plan order: grid, then ladder, within a setup.
  const std::vector<json> m = lines_of(merged / "records.jsonl");
  ASSERT_EQ(m.size(), 6u);
  EXPECT_EQ(m[1].at("grid").at("label"), "approx1");
  EXPECT_EQ(m[1].at("ladder_label"), "0.002");
  EXPECT_EQ(m[2].at("grid").at("label"), "box");
  ASSERT_EQ(run(tippe_sweep({sweep, "--out", merged.string(), "--jobs", "1"}), log), 0) << slurp(log);
  EXPECT_NE(slurp(log).find("(6 from an earlier run, 0 run now)"), std::string::npos) << slurp(log);
}

}  // namespace

}  // namespace test_sweep_merge
