// Boundary searches through the `tippe` command: a real search resumed, a gate on a boundary, and searches sharded, merged and over MPI ranks giving one run's records.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <map>
#include <set>
#include <string>
#include <vector>

#include "harness/sweep/sweep.h"
#include "harness/sweep/sweep_search.h"
#include "tests/support/files.h"
#include "tests/support/process.h"
#include "tests/support/records.h"
#include "harness/report/sweep_analysis.h"
#include "tests/support/fixtures.h"

namespace test_sweep_search_cli {

namespace fs = std::filesystem;
using namespace tippe;
using nlohmann::json;

namespace {

const std::string& kSource = fixtures::kSourceDir;
const std::string& kBinary = fixtures::kTippeBinary;
const std::string kScenes = kSource + "/harness/scenes/";

// Records by point id, timings left out (they differ between runs of the same point).
std::map<std::string, json> keyed(const std::vector<SweepRecord>& records) {
  std::map<std::string, json> m;
  for (const SweepRecord& r : records) EXPECT_TRUE(m.emplace(r.point_id, without_timings(to_json(r))).second) << r.point_id;
  return m;
}

// ---- one real search through `tippe sweep` --------------------------------------------------

std::map<std::string, json> records_of(const fs::path& dir) { return keyed(read_records((dir / "records.jsonl").string()).records); }

TEST(SweepSearchEndToEnd, RealSearchFindsOdesStepAndResumesToTheSameRecords) {
  TempDir dir;
  const std::string sweep = kSource + "/harness/sweeps/search-tiny.toml";
  const fs::path whole = dir.path() / "whole", err = dir.path() / "err.txt";
  ChildExit e = wait_process(
      spawn_process({kBinary, "sweep", sweep, "--out", whole.string(), "--jobs", "2", "--no-plots"}, "/dev/null", err));
  ASSERT_EQ(e.code, 0) << slurp(err);
  const std::vector<SweepRecord> records = read_records((whole / "records.jsonl").string()).records;
  const std::vector<SearchBoundary> b = search_boundaries(records);
  ASSERT_EQ(b.size(), 1u);
  ASSERT_EQ(b[0].status, "found") << render_sweep_markdown(records);
  EXPECT_LT(std::log10(*b[0].beyond / *b[0].boundary), 0.05);
  // 4 coarse values over 3 decades, then one decade bisected to 0.05: ceil(log2(20)) = 5.
  EXPECT_LE(records.size(), 4u + 5u);
  // The run at the boundary is safe (finished, classed ok, in the reference's regime); the one
  // beyond is not (it gains energy, leaves the regime, or inverts and then diverges).
  const SearchCriterion regime = parse_criterion("regime");
  for (const SweepRecord& r : records) {
    if (r.ladder_label == search_value_text(*b[0].boundary)) {
      EXPECT_TRUE(is_safe(regime, r)) << unsafe_reason(regime, r);
    }
    if (r.ladder_label == search_value_text(*b[0].beyond)) {
      EXPECT_FALSE(is_safe(regime, r));
    }
  }
  const std::string md = slurp(whole / "report.md");
  EXPECT_NE(md.find("| ode-regime | ode | max_safe_timestep | regime |"), std::string::npos) << md;

  // Interrupted: a directory holding the first records (a kill between two fsynced lines),
  // mid-bisection, then the same command again.
  const std::string text = slurp(whole / "records.jsonl");
  for (const size_t keep : {size_t{2}, size_t{5}, records.size() - 1}) {
    const fs::path cut = dir.path() / ("cut" + std::to_string(keep));
    fs::create_directories(cut);
    fs::copy_file(whole / "sweep.json", cut / "sweep.json");
    size_t pos = 0;
    for (size_t k = 0; k < keep; ++k) pos = text.find('\n', pos) + 1;
    spit(cut / "records.jsonl", text.substr(0, pos));
    e = wait_process(
        spawn_process({kBinary, "sweep", sweep, "--out", cut.string(), "--jobs", "1", "--no-plots"}, "/dev/null", err));
    ASSERT_EQ(e.code, 0) << slurp(err);
    EXPECT_EQ(records_of(cut), records_of(whole)) << "resumed after " << keep << " records";
  }
}

// ---- a gate on a boundary --------------------------------------------------------------------

TEST(SweepSearchGate, GateRunsTheSearchAndFailsWhenTheSafeStepShrinks) {
  // ODE's safe step on toy_viscous is 7.5e-4 (at 8.1e-4 and 1e-3 it gains energy, a net rise of
  // 1.5e-5 and 3.2e-5 E0 against a tolerance of 1.4e-5 E0): >= 5e-4 passes, >= 0.05 fails.
  TempDir dir;
  const std::string sweep = kSource + "/harness/sweeps/search-tiny.toml";
  const std::string gate = dir.write("gate.toml", "[[boundary]]\nname = \"ode-step\"\nsweep = \"" + sweep +
                                                      "\"\nsetup = \"ode-regime\"\nrequire = \"max_safe_timestep >= 5e-4\"\n"
                                                      "[[boundary]]\nname = \"ode-step-strict\"\nsweep = \"" + sweep +
                                                      "\"\nsetup = \"ode-regime\"\nscene = \"toy_viscous\"\n"
                                                      "require = \"max_safe_timestep >= 0.05\"\n");
  const fs::path out = dir.path() / "out.txt", err = dir.path() / "err.txt";
  const ChildExit e = wait_process(spawn_process(
      {kBinary, "gate", gate, "--boundary-out", (dir.path() / "runs").string(), "--json", (dir.path() / "g.json").string()},
      out, err));
  EXPECT_EQ(e.code, 1) << slurp(err);
  const json j = json::parse(slurp(dir.path() / "g.json"));
  ASSERT_EQ(j["results"].size(), 2u);
  EXPECT_TRUE(j["results"][0]["passed"].get<bool>()) << j.dump(2);
  EXPECT_FALSE(j["results"][1]["passed"].get<bool>()) << j.dump(2);
  EXPECT_NE(slurp(out).find("ode-step-strict: max_safe_timestep "), std::string::npos) << slurp(out);

  // Bad input: exit 2, the file, the key and the reason.
  const std::string bad = dir.write("bad.toml", "[[boundary]]\nname = \"x\"\nsweep = \"" + sweep +
                                                    "\"\nsetup = \"ode-regime\"\nrequire = \"min_safe_timestep >= 1\"\n");
  ChildExit b = wait_process(spawn_process({kBinary, "gate", bad}, out, err));
  EXPECT_EQ(b.code, 2);
  EXPECT_NE(slurp(err).find(bad + ": boundary[0].require: \"min_safe_timestep\" is not what setup \"ode-regime\" finds "
                                  "(expected max_safe_timestep"),
            std::string::npos)
      << slurp(err);
  const std::string empty = dir.write("empty.toml", "boundary = []\n");
  b = wait_process(spawn_process({kBinary, "gate", empty}, out, err));
  EXPECT_EQ(b.code, 2);
  EXPECT_NE(slurp(err).find(empty + ": boundary: no checks"), std::string::npos) << slurp(err);
  const std::string unknown = dir.write("unknown.toml", "[[boundary]]\nname = \"x\"\nsweep = \"" + sweep +
                                                            "\"\nsetup = \"nope\"\nrequire = \"max_safe_timestep >= 1\"\n");
  b = wait_process(spawn_process({kBinary, "gate", unknown}, out, err));
  EXPECT_EQ(b.code, 2);
  EXPECT_NE(slurp(err).find(unknown + ": boundary[0].setup: \"nope\" is not a setup of "), std::string::npos) << slurp(err);
}

// ---- shards, merge and MPI through the command ----------------------------------------------

std::string two_search_sweep() {
  return "description = \"two searches and a ladder\"\n"
         "scenes = [ { file = \"" + kScenes + "toy_viscous.toml\", duration = 4.6 }, { file = \"" + kScenes +
         "toy.toml\", duration = 1.0 } ]\n"
         "[[setup]]\nname = \"ode-regime\"\nengine = \"ode\"\n"
         "ladder.search = { key = \"engines.ode.timestep\", from = 1e-4, to = 1e-1, criterion = \"regime\" }\n"
         "[[setup]]\nname = \"bullet-regime\"\nengine = \"bullet\"\n"
         "ladder.search = { key = \"engines.bullet.timestep\", from = 1e-4, to = 1e-1, criterion = \"regime\" }\n"
         "[[setup]]\nname = \"ode-ladder\"\nengine = \"ode\"\n"
         "ladder = { key = \"engines.ode.timestep\", values = [1e-3, 1e-2] }\n";
}

int run_tippe(const std::vector<std::string>& args, const fs::path& log) {
  std::vector<std::string> argv = {kBinary};
  argv.insert(argv.end(), args.begin(), args.end());
  return wait_process(spawn_process(argv, log, log)).code;
}

TEST(SweepSearchDistributed, ShardsMergedAndMpiRanksGiveTheRecordsOfOneRun) {
  TempDir dir;
  const std::string sweep = dir.write("s.toml", two_search_sweep());
  const fs::path log = dir.path() / "log";
  const fs::path whole = dir.path() / "whole", merged = dir.path() / "merged";
  ASSERT_EQ(run_tippe({"sweep", sweep, "--out", whole.string(), "--jobs", "2", "--no-plots"}, log), 0) << slurp(log);
  const auto want = records_of(whole);
  // 2 scenes x 2 searches bisected, and the 4 ladder points.
  EXPECT_GT(want.size(), 2u * 2 * 4 + 4);
  std::vector<std::string> merge = {"sweep", "--merge"};
  for (int i = 0; i < 2; ++i) {
    const fs::path d = dir.path() / ("shard" + std::to_string(i));
    ASSERT_EQ(run_tippe({"sweep", sweep, "--shard", std::to_string(i) + "/2", "--out", d.string(), "--jobs", "1",
                         "--no-plots"},
                        log),
              0)
        << slurp(log);
    // Each search runs whole in one shard: its bisection needs its own records.
    std::set<std::string> units;
    for (const SweepRecord& r : read_records((d / "records.jsonl").string()).records)
      if (r.search) units.insert(r.scene + "/" + r.setup);
    EXPECT_GE(units.size(), 1u);
    merge.push_back(d.string());
  }
  merge.insert(merge.end(), {"--out", merged.string(), "--no-plots"});
  ASSERT_EQ(run_tippe(merge, log), 0) << slurp(log);
  EXPECT_EQ(records_of(merged), want);
  // The merged directory is finished: the same sweep on it runs nothing.
  ASSERT_EQ(run_tippe({"sweep", sweep, "--out", merged.string(), "--jobs", "1", "--no-plots"}, log), 0) << slurp(log);
  EXPECT_NE(slurp(log).find("0 run now"), std::string::npos) << slurp(log);
#ifdef TIPPE_HAVE_MPI
  // The coordinator plans each wave and every rank loads the same points.
  ::setenv("OMPI_ALLOW_RUN_AS_ROOT", "1", 1);
  ::setenv("OMPI_ALLOW_RUN_AS_ROOT_CONFIRM", "1", 1);
  const fs::path mpi = dir.path() / "mpi";
  const int code = wait_process(spawn_process({"mpirun", "--oversubscribe", "-np", "3", kBinary, "sweep", sweep, "--out",
                                               mpi.string(), "--no-plots"},
                                              log, log))
                       .code;
  ASSERT_EQ(code, 0) << slurp(log);
  EXPECT_EQ(records_of(mpi), want);
#endif
}

}  // namespace

}  // namespace test_sweep_search_cli
