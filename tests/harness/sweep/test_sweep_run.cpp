// Tests of running `tippe sweep` (harness/sweep/sweep_run.cpp): a killed sweep resumed to the same records, a changed sweep file or records counted by another energy-gain rule refused unless restarted, and invalid input exiting 2 with nothing written (the analysis: tests/harness/report/test_sweep_analysis.cpp).
#include <gtest/gtest.h>
#include <signal.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <map>
#include <string>
#include <thread>
#include <vector>

#include "harness/sweep/sweep.h"
#include "tests/support/files.h"
#include "tests/support/fixtures.h"
#include "tests/support/process.h"
#include "tests/support/records.h"
#include "tests/support/sweep_files.h"

namespace test_sweep_run {

namespace fs = std::filesystem;
using namespace tippe;
using nlohmann::json;

namespace {

using namespace tippe::fixtures;

const std::string& kSource = fixtures::kSourceDir;
const std::string& kBinary = fixtures::kTippeBinary;
const std::string kSmoke = kSource + "/harness/sweeps/smoke.toml";

// Starts `tippe ARGS` with stderr to err_file, stdout to /dev/null.
pid_t start_tippe(const std::vector<std::string>& args, const fs::path& err_file) {
  std::vector<std::string> argv = {kBinary};
  argv.insert(argv.end(), args.begin(), args.end());
  return spawn_process(argv, "/dev/null", err_file);
}

ChildExit run_tippe(const std::vector<std::string>& args, const fs::path& err_file) {
  return wait_process(start_tippe(args, err_file));
}

size_t count_lines(const fs::path& p) {
  const std::string t = slurp(p);
  return static_cast<size_t>(std::count(t.begin(), t.end(), '\n'));
}

std::map<std::string, json> by_id(const std::vector<SweepRecord>& records, size_t& duplicates) {
  std::map<std::string, json> m;
  duplicates = 0;
  for (const SweepRecord& r : records) duplicates += !m.emplace(r.point_id, without_timings(to_json(r))).second;
  return m;
}

}  // namespace

TEST(SweepCli, KilledSweepResumesToTheSameRecords) {
  ASSERT_TRUE(fs::exists(kBinary)) << "build the tippe target first";
  TempDir dir{"tippe-sweep"};
  const fs::path whole = dir.path() / "whole", killed = dir.path() / "killed", err = dir.path() / "err.txt";
  const size_t n_points = load_sweep(kSmoke).points.size();

  // Uninterrupted.
  ChildExit e = run_tippe({"sweep", kSmoke, "--out", whole.string(), "--jobs", "2", "--no-plots"}, err);
  ASSERT_EQ(e.code, 0) << slurp(err);
  size_t dup = 0;
  const auto reference = by_id(read_records((whole / "records.jsonl").string()).records, dup);
  ASSERT_EQ(reference.size(), n_points);
  ASSERT_EQ(dup, 0u);

  // Killed as soon as the first point is on disk, then a crash mid-write simulated by a partial line.
  const std::vector<std::string> args = {"sweep", kSmoke, "--out", killed.string(), "--jobs", "1", "--no-plots"};
  const pid_t pid = start_tippe(args, err);
  const fs::path records = killed / "records.jsonl";
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(120);
  while (count_lines(records) < 1 && std::chrono::steady_clock::now() < deadline)
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  ::kill(pid, SIGKILL);
  e = wait_process(pid);
  ASSERT_EQ(e.signal, SIGKILL) << "the sweep finished before it could be killed: " << slurp(err);
  const size_t before = count_lines(records);
  ASSERT_GE(before, 1u);
  ASSERT_LT(before, n_points) << "killed midway";
  {
    std::ofstream out(records, std::ios::app | std::ios::binary);
    out << to_jsonl(read_records(records.string()).records.front()).substr(0, 80);
  }

  // Restarted with the same command: completes, drops the partial line, loses and repeats nothing.
  e = run_tippe(args, err);
  ASSERT_EQ(e.code, 0) << slurp(err);
  EXPECT_NE(slurp(err).find("partial last line"), std::string::npos) << slurp(err);
  const std::string text = slurp(records);
  ASSERT_FALSE(text.empty());
  EXPECT_EQ(text.back(), '\n');
  const auto resumed = by_id(read_records(records.string()).records, dup);
  EXPECT_EQ(dup, 0u);
  ASSERT_EQ(resumed.size(), n_points);
  for (const auto& [id, j] : reference) {
    ASSERT_TRUE(resumed.count(id)) << id;
    EXPECT_EQ(resumed.at(id), j) << id;
  }

  // A third run has nothing left to do and leaves the records alone.
  e = run_tippe(args, err);
  ASSERT_EQ(e.code, 0) << slurp(err);
  EXPECT_EQ(slurp(records), text);

  // The report is a function of the records: rebuilt from them, it is the same page.
  const std::string md = slurp(killed / "report.md");
  fs::remove(killed / "report.md");
  fs::remove(killed / "index.html");
  e = run_tippe({"sweep", "--report", killed.string(), "--no-plots"}, err);
  ASSERT_EQ(e.code, 0) << slurp(err);
  EXPECT_EQ(slurp(killed / "report.md"), md);
  EXPECT_TRUE(fs::exists(killed / "index.html"));
  EXPECT_NE(md.find("Cheapest setting of each engine"), std::string::npos);
  EXPECT_NE(md.find("Regime: does it still roll?"), std::string::npos) << "the smoke sweep's toy scene rolls";
}

TEST(SweepCli, ChangedSweepFileIsRefusedUnlessRestarted) {
  TempDir dir{"tippe-sweep"};
  const fs::path out = dir.path() / "out", err = dir.path() / "err.txt";
  const std::string body = kGoodHead + kGoodSetup;
  const fs::path sweep = write_sweep(dir.path(), body);
  ChildExit e = run_tippe({"sweep", sweep.string(), "--out", out.string(), "--jobs", "2", "--no-plots"}, err);
  ASSERT_EQ(e.code, 0) << slurp(err);
  ASSERT_EQ(count_lines(out / "records.jsonl"), 2u);
  EXPECT_TRUE(fs::exists(out / "sweep.json"));
  EXPECT_EQ(fs::directory_iterator(out / "reference") != fs::directory_iterator(), true) << "reference cached";

  write_sweep(dir.path(), body + "# edited\n");
  e = run_tippe({"sweep", sweep.string(), "--out", out.string(), "--no-plots"}, err);
  EXPECT_EQ(e.code, 2);
  EXPECT_NE(slurp(err).find("sweep.json: sweep_hash:"), std::string::npos) << slurp(err);
  EXPECT_EQ(count_lines(out / "records.jsonl"), 2u);

  e = run_tippe({"sweep", sweep.string(), "--out", out.string(), "--restart", "--no-plots"}, err);
  ASSERT_EQ(e.code, 0) << slurp(err);
  EXPECT_EQ(count_lines(out / "records.jsonl"), 2u);
  EXPECT_TRUE(fs::exists(out / "records.jsonl.old")) << "earlier records are kept aside";

  // A second restart keeps the first set aside too, under the next free name.
  const std::string first_old = slurp(out / "records.jsonl.old");
  e = run_tippe({"sweep", sweep.string(), "--out", out.string(), "--restart", "--no-plots"}, err);
  ASSERT_EQ(e.code, 0) << slurp(err);
  EXPECT_EQ(slurp(out / "records.jsonl.old"), first_old) << "--restart keeps every earlier record file";
  EXPECT_EQ(count_lines(out / "records.jsonl.old.2"), 2u);
}

TEST(SweepCli, RecordsCountedByAnotherEnergyGainRuleAreRefusedUnlessRestarted) {
  // Records left by a build whose default rule counted gains another way (the rule before
  // "stored" was "total"): resuming would put two meanings of "unphysical" on one page.
  TempDir dir{"tippe-sweep"};
  const fs::path out = dir.path() / "out", err = dir.path() / "err.txt";
  const fs::path sweep = write_sweep(dir.path(), kGoodHead + kGoodSetup);
  ChildExit e = run_tippe({"sweep", sweep.string(), "--out", out.string(), "--no-plots"}, err);
  ASSERT_EQ(e.code, 0) << slurp(err);
  std::string edited;
  {
    std::ifstream in(out / "records.jsonl");
    for (std::string line; std::getline(in, line);) {
      json r = json::parse(line);
      ASSERT_EQ(r.at("metrics").at("energy_gain_rule"), "stored") << "the default rule is named in each record";
      r["metrics"]["energy_gain_rule"] = "total";
      edited += r.dump() + "\n";
    }
  }
  std::ofstream(out / "records.jsonl", std::ios::trunc) << edited;
  e = run_tippe({"sweep", sweep.string(), "--out", out.string(), "--no-plots"}, err);
  EXPECT_EQ(e.code, 2);
  EXPECT_NE(slurp(err).find("records.jsonl:1: metrics.energy_gain_rule: \"total\" is not point"), std::string::npos)
      << slurp(err);
  EXPECT_EQ(slurp(out / "records.jsonl"), edited) << "nothing written";
  e = run_tippe({"sweep", sweep.string(), "--out", out.string(), "--restart", "--no-plots"}, err);
  ASSERT_EQ(e.code, 0) << slurp(err);
  EXPECT_EQ(slurp(out / "records.jsonl.old"), edited) << "the refused records are kept aside";
}

TEST(SweepCli, InvalidSweepExitsWithTwoAndWritesNothing) {
  TempDir dir{"tippe-sweep"};
  const fs::path out = dir.path() / "out", err = dir.path() / "err.txt";
  const fs::path bad =
      write_sweep(dir.path(), kGoodHead +
                                  "[[setup]]\nname = \"mj\"\nengine = \"mujoco\"\n"
                                  "ladder.key = \"engines.mujoco.timestep\"\nladder.values = [1e-3, 2.0]\n");
  ChildExit e = run_tippe({"sweep", bad.string(), "--out", out.string()}, err);
  EXPECT_EQ(e.code, 2);
  EXPECT_NE(slurp(err).find(bad.string() + ": setup[0].ladder.values[1]: engines.mujoco.timestep"), std::string::npos)
      << slurp(err);
  EXPECT_FALSE(fs::exists(out));

  const fs::path missing = write_sweep(dir.path(), "scenes = [\"gone.toml\"]\n" + kGoodSetup, "missing.toml");
  e = run_tippe({"sweep", missing.string(), "--out", out.string()}, err);
  EXPECT_EQ(e.code, 2);
  EXPECT_NE(slurp(err).find(missing.string() + ": scenes[0]:"), std::string::npos) << slurp(err);
  EXPECT_FALSE(fs::exists(out));

  e = run_tippe({"sweep", (dir.path() / "nosuch.toml").string(), "--out", out.string()}, err);
  EXPECT_EQ(e.code, 2);
  EXPECT_FALSE(fs::exists(out));
  e = run_tippe({"sweep", "--report", (dir.path() / "nothing").string()}, err);
  EXPECT_EQ(e.code, 2);
  e = run_tippe({"sweep", "--jobs", "0", kSmoke, "--out", out.string()}, err);
  EXPECT_EQ(e.code, 2);
  EXPECT_FALSE(fs::exists(out));
}

}  // namespace test_sweep_run
