// The reference's self-check in sweeps: points compared only as far as the reference is converged, and a cached reference lacking its check given the check alone.
#include <gtest/gtest.h>

#include <filesystem>
#include <string>

#include "harness/io/files.h"
#include "harness/io/scene_io.h"
#include "harness/scene/resolve.h"
#include "harness/measure/compare.h"
#include "harness/report/sweep_analysis.h"
#include "harness/sweep/sweep.h"
#include "tests/support/fixtures.h"
#include "tests/support/records.h"
#include "tests/support/sweep_runs.h"

namespace test_sweep_self_check {

namespace fs = std::filesystem;
using namespace tippe;
using namespace tippe::fixtures;

namespace {

// The toy top to 2 s at the reference tolerance `rtol` (atol 100 times smaller, as shipped), and
// a sweep of one ODE point on it.
struct ToySweep {
  TempDir dir{"tippe-sweep-self-check"};
  std::string scene_path, sweep_path;
  explicit ToySweep(const std::string& rtol, const std::string& atol, bool self_check = true) {
    std::string text = slurp(kScenesDir + "toy.toml");
    text = edit(text, "rtol = 1e-10", "rtol = " + rtol);
    text = edit(text, "atol = 1e-12", "atol = " + atol + (self_check ? "" : "\nself_check = false"));
    scene_path = dir.write("toy.toml", text);
    sweep_path = dir.write("s.toml", R"(description = "one ODE point on the toy"
scenes = [{ file = "toy.toml", duration = 2.0 }]
[[setup]]
name = "ode"
engine = "ode"
ladder = { key = "engines.ode.timestep", values = [1e-3] }
)");
  }
  std::vector<SweepRecord> run() const {
    run_outcome();
    return records();
  }
  // restart: the earlier records set aside, so that every point runs again against what
  // OUT/reference/ holds.
  SweepOutcome run_outcome(bool restart = false) const {
    SweepOptions o;
    o.out_dir = (dir.path() / "out").string();
    o.progress = false;
    o.restart = restart;
    return run_sweep(load_sweep(sweep_path), o);
  }
  std::vector<SweepRecord> records() const {
    return read_records((dir.path() / "out" / "records.jsonl").string()).records;
  }
};

// The comparison's own self-check on the same scene, to which the sweep's must agree.
std::optional<double> comparison_converged_until(const std::string& scene_path) {
  CompareOptions o;
  o.engines = {"ode"};
  o.progress = false;
  const Comparison c = run_comparison(load_scene(scene_path, {"run.duration=2"}), o);
  EXPECT_TRUE(c.self_check);
  return c.self_check ? c.self_check->converged_until : std::nullopt;
}

// rtol 1e-3 on the toy: the two reference methods part within 0.1 s (SelfCheck.CatchesALoose-
// ToleranceOnTheToy), so the point's metrics stop where the comparison's do.
TEST(SweepSelfCheck, CutsThePointsMetricsWhereTheReferenceIsNotConverged) {
  const ToySweep s("1e-3", "1e-5");
  const std::vector<SweepRecord> records = s.run();
  ASSERT_EQ(records.size(), 1u);
  const Metrics& m = records[0].metrics;
  ASSERT_TRUE(m.reference_converged_until);
  EXPECT_LT(*m.reference_converged_until, 0.1);
  EXPECT_LE(m.compared_until, *m.reference_converged_until);
  const std::optional<double> c = comparison_converged_until(s.scene_path);
  ASSERT_TRUE(c);
  EXPECT_EQ(*m.reference_converged_until, *c);  // the same two runs, the same rule: the same time
  // The report says from when on the reference is not trusted.
  EXPECT_NE(render_sweep_markdown(records).find("parts from it at t ="), std::string::npos);
  // The self-check is cached beside the reference and a rerun reads it from there.
  EXPECT_TRUE(fs::exists(s.dir.path() / "out" / "reference" / records[0].physics_hash / "self_check.json"));
}

TEST(SweepSelfCheck, AConvergedReferenceLeavesTheMetricsWhole) {
  const ToySweep s("1e-10", "1e-12");
  const std::vector<SweepRecord> records = s.run();
  ASSERT_EQ(records.size(), 1u);
  EXPECT_FALSE(records[0].metrics.reference_converged_until);
  EXPECT_NEAR(records[0].metrics.compared_until, 2.0, 1e-9);
  EXPECT_EQ(render_sweep_markdown(records).find("parts from it at t ="), std::string::npos);
}

TEST(SweepSelfCheck, TurnedOffInTheSceneComparesTheWholeRun) {
  const ToySweep s("1e-3", "1e-5", /*self_check=*/false);
  const std::vector<SweepRecord> records = s.run();
  ASSERT_EQ(records.size(), 1u);
  EXPECT_FALSE(records[0].metrics.reference_converged_until);
  EXPECT_FALSE(fs::exists(s.dir.path() / "out" / "reference" / records[0].physics_hash / "self_check.json"));
}

// What OUT/reference/<hash>/ holds after a sweep: the reference's files as they were written, and
// its self-check without the second run's CPU time (the one part two runs of it do not share).
struct CacheEntry {
  fs::path dir;
  std::string summary;
  fs::file_time_type summary_written, trajectory_written;
  explicit CacheEntry(fs::path d)
      : dir(std::move(d)),
        summary(slurp(dir / "summary.json")),
        summary_written(fs::last_write_time(dir / "summary.json")),
        trajectory_written(fs::last_write_time(dir / "trajectory.csv")) {}
  nlohmann::json check() const {
    nlohmann::json j = nlohmann::json::parse(slurp(dir / "self_check.json"));
    j.at("self_check").erase("cpu_seconds");
    return j;
  }
  // The reference was not run again: a new run replaces both files (write_file_atomic renames a
  // new file over each) and its summary carries its own CPU time and date.
  void expect_untouched(const std::string& what) const {
    EXPECT_TRUE(slurp(dir / "summary.json") == summary) << what << ": summary.json rewritten";
    EXPECT_EQ(fs::last_write_time(dir / "summary.json"), summary_written) << what;
    EXPECT_EQ(fs::last_write_time(dir / "trajectory.csv"), trajectory_written) << what;
  }
};

// A cache entry written before the self-check existed (or whose check was lost): the sweep runs
// the second method alone against the cached reference, stores the check beside it and records
// what a sweep from a cold OUT records. rtol 1e-3, where the two references part before 0.1 s, so
// that a converged_until carries over and cuts the metrics.
TEST(SweepSelfCheck, ACachedReferenceWithoutItHasOnlyItsCheckRun) {
  const ToySweep s("1e-3", "1e-5");
  const SweepOutcome cold = s.run_outcome();
  EXPECT_EQ(cold.references_computed, 1u);
  EXPECT_EQ(cold.self_checks_computed, 0u);
  const std::vector<SweepRecord> cold_records = s.records();
  ASSERT_EQ(cold_records.size(), 1u);
  ASSERT_TRUE(cold_records[0].metrics.reference_converged_until);
  const CacheEntry entry(s.dir.path() / "out" / "reference" / cold_records[0].physics_hash);
  const nlohmann::json cold_check = entry.check();

  fs::remove(entry.dir / "self_check.json");
  const SweepOutcome warm = s.run_outcome(/*restart=*/true);
  EXPECT_EQ(warm.references_cached, 1u);
  EXPECT_EQ(warm.references_computed, 0u);
  EXPECT_EQ(warm.self_checks_computed, 1u);
  entry.expect_untouched("after the self-check alone");
  ASSERT_TRUE(fs::exists(entry.dir / "self_check.json"));
  EXPECT_EQ(entry.check(), cold_check);
  const std::vector<SweepRecord> warm_records = s.records();
  ASSERT_EQ(warm_records.size(), 1u);
  EXPECT_EQ(warm_records[0].metrics.reference_converged_until, cold_records[0].metrics.reference_converged_until);
  EXPECT_EQ(warm_records[0].metrics.compared_until, cold_records[0].metrics.compared_until);
  EXPECT_EQ(without_timings(to_json(warm_records[0])), without_timings(to_json(cold_records[0])));

  // The check stored is found by the next run: nothing is computed.
  const SweepOutcome again = s.run_outcome(/*restart=*/true);
  EXPECT_EQ(again.references_computed + again.self_checks_computed, 0u);
  entry.expect_untouched("after a run from the whole cache");
}

// A self_check.json read back is input: one cut short, mistyped, or made for another reference,
// method or check is taken as missing (the cache's rule for its entries): the check runs again
// against the cached reference and replaces it, and the records stay the cold run's.
TEST(SweepSelfCheck, ADamagedOrForeignCheckBesideACachedReferenceIsRunAgain) {
  const ToySweep s("1e-3", "1e-5");
  const std::vector<SweepRecord> cold_records = s.run();
  ASSERT_EQ(cold_records.size(), 1u);
  const CacheEntry entry(s.dir.path() / "out" / "reference" / cold_records[0].physics_hash);
  const nlohmann::json cold_check = entry.check();
  const std::string good = slurp(entry.dir / "self_check.json");
  const nlohmann::json j = nlohmann::json::parse(good);
  auto edited = [&](const nlohmann::json::json_pointer& at, const nlohmann::json& value) {
    nlohmann::json e = j;
    e[at] = value;
    return e.dump(2);
  };
  using ptr = nlohmann::json::json_pointer;
  const std::vector<std::pair<std::string, std::string>> damaged = {
      {"cut short", good.substr(0, good.size() / 2)},
      {"not JSON", "\x01 self-check"},
      {"another format", edited(ptr("/format"), "tippe-self-check-0")},
      {"another reference's", edited(ptr("/key/reference_date"), "2000-01-01T00:00:00Z")},
      {"another method's", edited(ptr("/key/method"), "bulirsch_stoer")},
      {"a check other than its key names", edited(ptr("/self_check/rtol"), 1e-4)},
      {"a negative converged_until", edited(ptr("/self_check/converged_until"), -1.0)},
      {"a converged_until that is text", edited(ptr("/self_check/converged_until"), "soon")},
  };
  for (const auto& [what, text] : damaged) {
    write_file_atomic((entry.dir / "self_check.json").string(), text);
    const SweepOutcome r = s.run_outcome(/*restart=*/true);
    EXPECT_EQ(r.references_computed, 0u) << what;
    EXPECT_EQ(r.self_checks_computed, 1u) << what;
    entry.expect_untouched(what);
    EXPECT_EQ(entry.check(), cold_check) << what;
    const std::vector<SweepRecord> records = s.records();
    ASSERT_EQ(records.size(), 1u) << what;
    EXPECT_EQ(without_timings(to_json(records[0])), without_timings(to_json(cold_records[0]))) << what;
  }
}

#ifdef TIPPE_HAVE_MPI

// The same over MPI ranks: one worker runs the check alone, the coordinator stores it beside the
// untouched reference and every rank gets it, so the point (run on a worker) stops its metrics
// where the local run from a cold cache did.
TEST(SweepSelfCheck, UnderMpiACachedReferenceWithoutItHasTheCheckAloneRunAndShared) {
  REQUIRE_MPIRUN();
  const ToySweep s("1e-3", "1e-5");
  const std::vector<SweepRecord> cold_records = s.run();
  ASSERT_EQ(cold_records.size(), 1u);
  ASSERT_TRUE(cold_records[0].metrics.reference_converged_until);
  const fs::path local = s.dir.path() / "out", log = s.dir.path() / "log";
  for (int np : {2, 3}) {
    const fs::path out = s.dir.path() / ("np" + std::to_string(np));
    fs::create_directories(out);
    // The sweep's reference cache with the marker that makes the directory a sweep's: a
    // directory holding a bare reference/ is one tippe did not write, and is refused.
    fs::copy(local / "reference", out / "reference", fs::copy_options::recursive);
    fs::copy_file(local / ".tippe-output", out / ".tippe-output");
    const CacheEntry entry(out / "reference" / cold_records[0].physics_hash);
    ASSERT_TRUE(fs::remove(entry.dir / "self_check.json"));
    ASSERT_EQ(sweep_runs::run(sweep_runs::mpirun_sweep(np, {s.sweep_path, "--out", out.string()}), log), 0)
        << slurp(log);
    const std::string text = slurp(log);
    EXPECT_NE(text.find("[sweep] checking 1 cached reference(s): their self-check only"), std::string::npos) << text;
    EXPECT_EQ(text.find("[sweep] computing"), std::string::npos) << text;
    entry.expect_untouched(std::to_string(np) + " ranks");
    EXPECT_TRUE(fs::exists(entry.dir / "self_check.json"));
    sweep_runs::expect_same_records(local, out);
  }
}

#endif

}  // namespace

}  // namespace test_sweep_self_check
