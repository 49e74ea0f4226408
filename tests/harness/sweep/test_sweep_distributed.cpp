// Sweeps beyond one process: the task farm's contract, shards and their merge, and MPI runs (mpirun -np 2 and 3, killed and resumed) giving a local run's records.
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdlib>
#include <fstream>
#include <map>
#include <mutex>
#include <set>
#include <thread>

#include "harness/sweep/mpi_farm.h"
#include "harness/sweep/sweep.h"
#include "harness/measure/task_farm.h"
#include "tests/support/files.h"
#include "tests/support/process.h"
#include "tests/support/records.h"
#include "tests/support/sweep_runs.h"
#include "harness/report/sweep_analysis.h"
#include "tests/support/fixtures.h"

namespace fs = std::filesystem;
using namespace tippe;
using nlohmann::json;
using namespace tippe::sweep_runs;

namespace {

const std::string& kSource = fixtures::kSourceDir;
const std::string kSmoke = kSource + "/harness/sweeps/smoke.toml";

// One local run of the smoke sweep, shared by the tests that compare against it.
const fs::path& local_smoke() {
  static TempDir dir("tippe-dist-local");
  static bool done = false;
  if (!done) {
    const fs::path out = dir.path() / "local";
    EXPECT_EQ(run(tippe_sweep({kSmoke, "--out", out.string(), "--jobs", "1"}), dir.path() / "log"), 0)
        << slurp(dir.path() / "log");
    done = true;
  }
  static const fs::path out = dir.path() / "local";
  return out;
}

// ---- the task farm ----------------------------------------------------------------------------

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

// A sweep whose second scene's reference fails on its first step: the stiff scene on an explicit
// method (Bulirsch-Stoer at k = 1e4).
std::string failing_reference_sweep(const TempDir& dir) {
  std::string scene = slurp(kSource + "/harness/scenes/extremes/k_high.toml");
  const std::string from = "method = \"rosenbrock4\"";
  scene.replace(scene.find(from), from.size(), "method = \"bulirsch_stoer\"");
  dir.write("stiff_explicit.toml", scene);
  return dir.write("fails.toml", "description = \"a reference that fails\"\nscenes = [\"" + kSource +
                                     "/harness/scenes/toy.toml\", \"stiff_explicit.toml\"]\n"
                                     "[[setup]]\nname = \"ode\"\nengine = \"ode\"\n"
                                     "ladder.key = \"engines.ode.timestep\"\nladder.values = [1e-3, 2e-3]\n");
}

// A failing reference is a result: its scene's points are recorded failed with its reason, the
// other scene's points run, the report lists the reference as failed, and the sweep exits 0.
void expect_failed_reference_recorded(const fs::path& out, const std::string& log) {
  std::map<std::string, size_t> by_scene, failed;
  for (const json& r : lines_of(out / "records.jsonl")) {
    const std::string scene = r.at("scene");
    ++by_scene[scene];
    if (r.at("status") == "failed") {
      ++failed[scene];
      EXPECT_EQ(r.at("status_detail").get<std::string>().rfind("not run: the reference run of k_high failed at t = ", 0), 0u)
          << r.dump();
      EXPECT_EQ(r.at("class").at("name"), "failed");
      EXPECT_EQ(r.at("reference").at("status"), "failed");
    }
  }
  EXPECT_EQ(by_scene["toy"], 2u) << log;
  EXPECT_EQ(failed["toy"], 0u) << log;
  EXPECT_EQ(by_scene["k_high"], 2u) << log;
  EXPECT_EQ(failed["k_high"], 2u) << log;
  EXPECT_NE(log.find("tippe: warning: the reference run of k_high failed"), std::string::npos) << log;
  const std::string report = slurp(out / "report.md");
  EXPECT_NE(report.find("k_high"), std::string::npos) << report;
  EXPECT_NE(report.find("| failed |"), std::string::npos) << report;
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

// ---- MPI --------------------------------------------------------------------------------------

// A grid and a categorical ladder: every point is an ordinary point, so shards, merges, resumed
// runs and MPI ranks give the records of one local run.
std::string grid_sweep(const TempDir& dir) {
  return dir.write("grid.toml", "description = \"a grid\"\nduration = 0.3\nscenes = [\"" + kSource +
                                    "/harness/scenes/toy.toml\"]\n"
                                    "[[setup]]\nname = \"ode\"\nengine = \"ode\"\n"
                                    "ladder = { key = \"engines.ode.timestep\", values = [1e-3, 2e-3] }\n"
                                    "grid = { key = \"engines.ode.friction_model\", values = [\"approx1\", \"box\"] }\n"
                                    "[[setup]]\nname = \"mujoco\"\nengine = \"mujoco\"\n"
                                    "ladder = { key = \"engines.mujoco.body_frame\", values = [\"com\", \"ball_centre\"] }\n");
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

#ifdef TIPPE_HAVE_MPI

TEST(SweepMpi, TwoAndThreeRanksGiveTheRecordsOfOneJob) {
  REQUIRE_MPIRUN();
  TempDir dir("tippe-mpi");
  const fs::path log = dir.path() / "log";
  for (int np : {2, 3}) {
    const fs::path out = dir.path() / ("np" + std::to_string(np));
    ASSERT_EQ(run(mpirun_sweep(np, {kSmoke, "--out", out.string()}), log), 0) << slurp(log);
    EXPECT_NE(slurp(log).find(std::to_string(np - 1) + " worker rank(s) (MPI, " + std::to_string(np) + " ranks)"),
              std::string::npos)
        << slurp(log);
    expect_same_records(local_smoke(), out);
    // The references were computed once each (one cache entry per scene) and the report written.
    size_t refs = 0;
    for (const auto& e : fs::directory_iterator(out / "reference")) refs += fs::exists(e.path() / "summary.json");
    EXPECT_EQ(refs, 2u);
    EXPECT_TRUE(fs::exists(out / "index.html"));
    const json a = json::parse(slurp(local_smoke() / "sweep.json")), b = json::parse(slurp(out / "sweep.json"));
    EXPECT_EQ(a["plan_hash"], b["plan_hash"]);
  }
}

TEST(SweepMpi, GridAndCategoricalLaddersRunUnderMpiAsOneLocalRun) {
  REQUIRE_MPIRUN();
  TempDir dir("tippe-grid-mpi");
  const std::string sweep = grid_sweep(dir);
  const fs::path log = dir.path() / "log", local = dir.path() / "local", np2 = dir.path() / "np2";
  ASSERT_EQ(run(tippe_sweep({sweep, "--out", local.string(), "--jobs", "1"}), log), 0) << slurp(log);
  ASSERT_EQ(run(mpirun_sweep(2, {sweep, "--out", np2.string()}), log), 0) << slurp(log);
  expect_same_records(local, np2);
}

TEST(SweepMpi, ShardsRunUnderMpiToo) {
  REQUIRE_MPIRUN();
  TempDir dir("tippe-mpi-shard");
  const fs::path log = dir.path() / "log";
  std::vector<std::string> merge = {"--merge"};
  for (int i = 0; i < 2; ++i) {
    const std::string d = (dir.path() / ("s" + std::to_string(i))).string();
    ASSERT_EQ(run(mpirun_sweep(2, {kSmoke, "--shard", std::to_string(i) + "/2", "--out", d}), log), 0) << slurp(log);
    merge.push_back(d);
  }
  merge.insert(merge.end(), {"--out", (dir.path() / "merged").string()});
  ASSERT_EQ(run(tippe_sweep(merge), log), 0) << slurp(log);
  expect_same_records(local_smoke(), dir.path() / "merged");
}

// The pids of the processes whose parent is `parent` (mpirun's ranks).
std::vector<pid_t> children_of(pid_t parent) {
  std::vector<pid_t> out;
  for (const auto& e : fs::directory_iterator("/proc")) {
    const std::string name = e.path().filename();
    if (name.find_first_not_of("0123456789") != std::string::npos) continue;
    std::ifstream stat(e.path() / "stat");
    std::string line;
    std::getline(stat, line);
    const size_t close = line.rfind(')');
    if (close == std::string::npos) continue;
    std::istringstream rest(line.substr(close + 2));
    char state = 0;
    pid_t ppid = 0;
    rest >> state >> ppid;
    if (ppid == parent) out.push_back(static_cast<pid_t>(std::stol(name)));
  }
  return out;
}

TEST(SweepMpi, AJobKilledMidwayCompletesWhenStartedAgainWithNothingLostOrTwice) {
  REQUIRE_MPIRUN();
  TempDir dir("tippe-mpi-kill");
  // Twelve ODE points of ~0.2 s each: long enough to kill the job between two of them.
  std::string values;
  for (int i = 0; i < 12; ++i) values += (i ? ", " : "") + std::to_string(1.0e-5 + i * 1.0e-6);
  const std::string sweep = dir.write("kill.toml", "description = \"killed midway\"\nscenes = [ { file = \"" + kSource +
                                                       "/harness/scenes/toy.toml\", duration = 2.0 } ]\n"
                                                       "[[setup]]\nname = \"ode\"\nengine = \"ode\"\n"
                                                       "ladder.key = \"engines.ode.timestep\"\nladder.values = [" +
                                                       values + "]\n");
  const fs::path out = dir.path() / "out", log = dir.path() / "log";
  const pid_t job = spawn_process(mpirun_sweep(3, {sweep, "--out", out.string()}), log, log);
  // Kill every rank (a node lost, a job cancelled) once some but not all points are in.
  size_t seen = 0;
  for (int i = 0; i < 12000 && seen < 3; ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
    seen = lines_of(out / "records.jsonl").size();
  }
  ASSERT_GE(seen, 3u) << "the job never got going: " << slurp(log);
  const std::vector<pid_t> ranks = children_of(job);
  EXPECT_EQ(ranks.size(), 3u);
  for (pid_t r : ranks) ::kill(r, SIGKILL);
  EXPECT_NE(wait_process(job).code, 0) << "mpirun should report its killed ranks";
  const size_t after_kill = lines_of(out / "records.jsonl").size();
  ASSERT_LT(after_kill, 12u) << "the job finished before it was killed; the test proves nothing";

  ASSERT_EQ(run(mpirun_sweep(3, {sweep, "--out", out.string()}), log), 0) << slurp(log);
  EXPECT_NE(slurp(log).find("(" + std::to_string(after_kill) + " from an earlier run, " +
                            std::to_string(12 - after_kill) + " run now)"),
            std::string::npos)
      << slurp(log);
  const auto resumed = records_by_id(out);  // a point written twice fails here
  EXPECT_EQ(resumed.size(), 12u);
  EXPECT_EQ(lines_of(out / "records.jsonl").size(), 12u);

  // And they are the records of an uninterrupted local run.
  const fs::path local = dir.path() / "local";
  ASSERT_EQ(run(tippe_sweep({sweep, "--out", local.string(), "--jobs", "2"}), log), 0) << slurp(log);
  expect_same_records(local, out);
}

TEST(SweepMpi, BadInputStopsEveryRankWithTheMessageOnce) {
  REQUIRE_MPIRUN();
  TempDir dir("tippe-mpi-bad");
  const fs::path log = dir.path() / "log";
  // --jobs is for one process.
  EXPECT_EQ(run(mpirun_sweep(2, {kSmoke, "--out", (dir.path() / "a").string(), "--jobs", "2"}), log), 2);
  EXPECT_NE(slurp(log).find("--jobs is for a run in one process"), std::string::npos) << slurp(log);
  // A malformed sweep file: every rank stops, the message is printed once (by rank 0).
  const std::string bad = dir.write("bad.toml", "description = \"x\"\nrepeats = 0\n");
  EXPECT_EQ(run(mpirun_sweep(3, {bad, "--out", (dir.path() / "b").string()}), log), 2);
  const std::string text = slurp(log);
  const size_t first = text.find("tippe: error: ");
  ASSERT_NE(first, std::string::npos) << text;
  EXPECT_EQ(text.find("tippe: error: ", first + 1), std::string::npos) << "printed more than once:\n" << text;
  EXPECT_NE(text.find("repeats"), std::string::npos) << text;
  EXPECT_FALSE(fs::exists(dir.path() / "b"));
  // An output directory of another sweep: refused by rank 0 before anything is written.
  const fs::path other = dir.path() / "other";
  fs::create_directories(other);
  spit(other / "sweep.json", "{\"sweep_hash\": \"0000000000000000\", \"plan_hash\": \"0\"}\n");
  EXPECT_EQ(run(mpirun_sweep(2, {kSmoke, "--out", other.string()}), log), 2);
  EXPECT_NE(slurp(log).find("was started with another sweep file"), std::string::npos) << slurp(log);
  EXPECT_FALSE(fs::exists(other / "records.jsonl"));
}

TEST(SweepMpi, AReferenceFailingOnAWorkerIsRecordedAsALocalRunRecordsIt) {
  REQUIRE_MPIRUN();
  TempDir dir("tippe-mpi-fail");
  const std::string sweep = failing_reference_sweep(dir);
  const fs::path log = dir.path() / "log";
  const fs::path local = dir.path() / "local";
  ASSERT_EQ(run(tippe_sweep({sweep, "--out", local.string(), "--jobs", "2"}), log), 0) << slurp(log);
  for (int np : {2, 3}) {
    const fs::path out = dir.path() / ("np" + std::to_string(np));
    const ChildExit e = wait_process_within(spawn_process(mpirun_sweep(np, {sweep, "--out", out.string()}), log, log), 120);
    ASSERT_FALSE(e.timed_out) << "the job hung:\n" << slurp(log);
    EXPECT_EQ(e.code, 0) << slurp(log);
    const std::string text = slurp(log);
    EXPECT_EQ(text.find("tippe: warning: "), text.rfind("tippe: warning: ")) << "printed more than once:\n" << text;
    expect_failed_reference_recorded(out, text);
    expect_same_records(local, out);
  }
}

TEST(SweepMpi, OneRankRunsAsALocalSweep) {
  REQUIRE_MPIRUN();
  TempDir dir("tippe-mpi-one");
  const fs::path out = dir.path() / "out", log = dir.path() / "log";
  ASSERT_EQ(run(mpirun_sweep(1, {kSmoke, "--out", out.string(), "--jobs", "1"}), log), 0) << slurp(log);
  EXPECT_NE(slurp(log).find("with 1 job(s)"), std::string::npos) << slurp(log);
  expect_same_records(local_smoke(), out);
}

#else

TEST(SweepMpi, ABuildWithoutMpiRefusesToRunAsOneOfManyRanks) {
  TempDir dir("tippe-nompi");
  ::setenv("OMPI_COMM_WORLD_SIZE", "2", 1);
  const fs::path log = dir.path() / "log";
  const int rc = run(tippe_sweep({kSmoke, "--out", (dir.path() / "out").string()}), log);
  ::unsetenv("OMPI_COMM_WORLD_SIZE");
  EXPECT_EQ(rc, 2);
  EXPECT_NE(slurp(log).find("built without MPI"), std::string::npos) << slurp(log);
  EXPECT_FALSE(fs::exists(dir.path() / "out"));
  EXPECT_EQ(mpi_library_version(), "");
}

#endif

}  // namespace
