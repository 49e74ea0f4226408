// Tests of `tippe sweep`: records, sweep-file checks, ladders, and a killed sweep resumed (the analysis: tests/harness/report/test_sweep_analysis.cpp).
#include <gtest/gtest.h>
#include <signal.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <sstream>
#include <thread>

#include "harness/io/scene_io.h"
#include "harness/sweep/sweep.h"
#include "tests/support/files.h"
#include "tests/support/process.h"
#include "tests/support/records.h"
#include "harness/report/sweep_analysis.h"
#include "tests/support/fixtures.h"
#include "tests/support/sweep_points.h"

namespace fs = std::filesystem;
using namespace tippe;
using nlohmann::json;

namespace {

const std::string& kSource = fixtures::kSourceDir;
const std::string& kBinary = fixtures::kTippeBinary;
const std::string kSmoke = kSource + "/harness/sweeps/smoke.toml";
const std::string kScene = kSource + "/harness/scenes/source_dimensionless.toml";

using fixtures::point;

SweepRecord sample_record() {
  SweepRecord r;
  r.point_id = "0123456789abcdef";
  r.scene = "source_dimensionless";
  r.scene_file = "../scenes/source_dimensionless.toml";
  r.physics_hash = "fedcba9876543210";
  r.scene_index = 1;
  r.setup = "mujoco-rk4";
  r.engine = "mujoco";
  r.set = {"engines.mujoco.integrator=\"RK4\""};
  r.ladder_key = "engines.mujoco.timestep";
  r.ladder_value = 3e-5;
  r.setup_index = 2;
  r.ladder_index = 4;
  r.repeats = 3;
  r.duration = 25.0;
  r.status = "diverged";
  r.status_time = 12.345678901234567;
  r.status_detail = "|omega| > 1e6 \"quoted\"\nsecond line";
  r.inversion_time = std::nullopt;
  r.stem_contact_time = 0.1 + 0.2;
  r.reference_inversion_time = 17.251740062499294;
  r.reference_stem_contact_time = std::nullopt;
  r.metrics.inversion_event = "reference_only";
  r.metrics.stem_contact_event = "engine_only";
  r.metrics.tilt_rms_error = 1.0 / 3.0;
  r.metrics.tilt_max_error = std::nan("");  // written as null, read back as NaN
  r.metrics.energy_max_error = 2.5e-7;
  r.metrics.contact_path_rms_error = 4e-3;
  r.metrics.jellett_drift_ball = 1e-9;
  r.metrics.steps = 123456;
  r.cpu_seconds = 0.25;
  r.cpu_seconds_repeats = {0.3, 0.25, 0.27};
  r.wall_seconds = 0.26;
  r.steps = 123456;
  r.rhs_evaluations = 123456;
  r.solver_iterations = 98765;
  r.engine_version = "mujoco 2.2.2";
  r.git_commit = "abcdef012345";
  r.settings = {{"timestep", "3.0000000000000001e-05"}, {"integrator", "RK4"}};
  return r;
}


}  // namespace

// ---- records ----------------------------------------------------------------------------------

TEST(SweepRecords, JsonLineRoundTrip) {
  const SweepRecord r = sample_record();
  const std::string line = to_jsonl(r);
  ASSERT_EQ(line.back(), '\n');
  EXPECT_EQ(line.find('\n'), line.size() - 1) << "one record, one line";
  const SweepRecord back = sweep_record_from_json(json::parse(line));
  EXPECT_EQ(to_jsonl(back), line);
  EXPECT_EQ(back.point_id, r.point_id);
  EXPECT_EQ(back.set, r.set);
  EXPECT_EQ(back.ladder_value, 3e-5);
  EXPECT_FALSE(back.inversion_time);
  EXPECT_EQ(*back.stem_contact_time, 0.1 + 0.2);
  EXPECT_TRUE(std::isnan(back.metrics.tilt_max_error));
  EXPECT_EQ(back.metrics.tilt_rms_error, 1.0 / 3.0);
  EXPECT_EQ(back.cpu_seconds_repeats, r.cpu_seconds_repeats);
  EXPECT_EQ(back.status_detail, r.status_detail);
  EXPECT_EQ(back.settings, r.settings);
}

TEST(SweepRecords, MissingFieldOrOtherFormatThrows) {
  json j = to_json(sample_record());
  j.erase("point_id");
  EXPECT_THROW(sweep_record_from_json(j), SweepRecordError);
  json k = to_json(sample_record());
  k["format"] = "tippe-sweep-record-0";
  EXPECT_THROW(sweep_record_from_json(k), SweepRecordError);
}

TEST(SweepRecords, PartialLastLineIsDetectedAndDropped) {
  EXPECT_EQ(complete_lines_length(""), 0u);
  EXPECT_EQ(complete_lines_length("{\"a\""), 0u);
  EXPECT_EQ(complete_lines_length("one\ntwo\n"), 8u);
  EXPECT_EQ(complete_lines_length("one\ntwo\nthr"), 8u);

  TempDir dir{"tippe-sweep"};
  const fs::path file = dir.path() / "records.jsonl";
  EXPECT_TRUE(read_records(file.string()).records.empty()) << "a missing file is empty";
  SweepRecord a = sample_record(), b = sample_record();
  b.point_id = "1111111111111111";
  const std::string whole = to_jsonl(a) + to_jsonl(b);
  const std::string cut = to_jsonl(a).substr(0, 57);
  spit(file, whole + cut);

  const RecordsFile seen = read_records(file.string());
  ASSERT_EQ(seen.records.size(), 2u);
  EXPECT_EQ(seen.complete_bytes, whole.size());
  EXPECT_EQ(seen.partial_bytes, cut.size());
  EXPECT_EQ(fs::file_size(file), whole.size() + cut.size()) << "reading leaves the file alone";

  const RecordsFile fixed = recover_records(file.string());
  EXPECT_EQ(fixed.records.size(), 2u);
  EXPECT_EQ(fixed.partial_bytes, cut.size());
  EXPECT_EQ(slurp(file), whole) << "truncated to the last complete line";
  EXPECT_EQ(recover_records(file.string()).partial_bytes, 0u);
}

// Records read back are input: a count beyond long long, an index out of range, a float where
// an integer belongs, are refused by key, never converted with undefined behaviour.
TEST(SweepRecords, FieldsReadBackAreCheckedByKey) {
  auto message = [](const json& j) -> std::string {
    try {
      sweep_record_from_json(j);
    } catch (const SweepRecordError& e) {
      return e.what();
    }
    return "accepted";
  };
  json j = to_json(sample_record());
  j["work"]["steps"] = 1e300;
  EXPECT_EQ(message(j).rfind("work.steps: 1e+300 is not an integer", 0), 0u) << message(j);
  j = to_json(sample_record());
  j["work"]["rhs_evaluations"] = json::parse("18446744073709551615");
  EXPECT_EQ(message(j).rfind("work.rhs_evaluations: 18446744073709551615 is out of range", 0), 0u) << message(j);
  j = to_json(sample_record());
  j["scene_index"] = -1;
  EXPECT_EQ(message(j).rfind("scene_index: -1 is out of range (expected 0 <= scene_index <= 99999)", 0), 0u) << message(j);
  j = to_json(sample_record());
  j["repeats"] = 0;
  EXPECT_EQ(message(j).rfind("repeats: 0 is out of range", 0), 0u) << message(j);
  j = to_json(sample_record());
  j["class"]["name"] = "fine";
  EXPECT_EQ(message(j).rfind("class.name: \"fine\" is not one of ok, ", 0), 0u) << message(j);
  j = to_json(sample_record());
  j["metrics"]["steps"] = "many";
  EXPECT_EQ(message(j).rfind("metrics: ", 0), 0u) << message(j);
  j = to_json(sample_record());
  j["duration"] = "long";
  EXPECT_EQ(message(j), "duration: expected a number or null, got string");
  EXPECT_EQ(message(json::array()).rfind("record: expected an object", 0), 0u);

  TempDir dir{"tippe-sweep"};
  const fs::path file = dir.path() / "records.jsonl";
  j = to_json(sample_record());
  j["work"]["steps"] = 1e300;
  spit(file, to_jsonl(sample_record()) + j.dump() + "\n");
  try {
    read_records(file.string());
    FAIL() << "no exception";
  } catch (const SweepRecordError& e) {
    EXPECT_EQ(std::string(e.what()).rfind(file.string() + ":2: work.steps: 1e+300 is not an integer", 0), 0u) << e.what();
  }
}

TEST(SweepRecords, SweepJsonReadBackIsChecked) {
  auto message = [](const std::string& text) -> std::string {
    try {
      parse_sweep_meta(text, "D/sweep.json");
    } catch (const SweepRecordError& e) {
      return e.what();
    }
    return "accepted";
  };
  const std::string head = R"({"sweep_hash": "a", "plan_hash": "b", "points": 4, "shard": )";
  EXPECT_EQ(message(head + R"({"index": 1, "count": 2, "point_ids": ["x", "y"]}})"), "accepted");
  EXPECT_EQ(message(head + R"({"index": 2, "count": 2, "point_ids": []}})"),
            "D/sweep.json: shard.index: 2 is out of range (expected 0 <= index <= 1)");
  EXPECT_EQ(message(head + R"({"index": 1e300, "count": 2, "point_ids": []}})"),
            "D/sweep.json: shard.index: 1e+300 is not an integer (expected 0 <= index <= 1)");
  EXPECT_EQ(message(head + R"({"index": 0, "count": 0, "point_ids": []}})"),
            "D/sweep.json: shard.count: 0 is out of range (expected 1 <= count <= 1000000)");
  EXPECT_EQ(message(head + R"({"index": 0, "count": 1, "point_ids": ["a", "b", "c", "d", "e"]}})"),
            "D/sweep.json: shard.point_ids: 5 ids, more than the sweep's 4 points");
  EXPECT_EQ(message(R"({"sweep_hash": 7, "plan_hash": "b"})"), "D/sweep.json: sweep_hash: expected a string, got number");
  EXPECT_EQ(message("{"), "D/sweep.json: sweep.json: not JSON");
}

TEST(SweepRecords, ACorruptCompleteLineNamesFileAndLine) {
  TempDir dir{"tippe-sweep"};
  const fs::path file = dir.path() / "records.jsonl";
  spit(file, to_jsonl(sample_record()) + "{\"format\": \"tippe-sweep-record-1\"}\n");
  try {
    read_records(file.string());
    FAIL() << "no exception";
  } catch (const SweepInputError& e) {
    EXPECT_NE(std::string(e.what()).find(file.string() + ":2:"), std::string::npos) << e.what();
  }
}

// ---- sweep files ------------------------------------------------------------------------------

namespace {

// Writes a sweep file whose scene is the shipped source_dimensionless (absolute path).
fs::path write_sweep(const fs::path& dir, const std::string& body, const std::string& name = "s.toml") {
  const fs::path p = dir / name;
  spit(p, body);
  return p;
}

const std::string kGoodHead = "repeats = 1\nduration = 0.5\nscenes = [\"" + kScene + "\"]\n";
const std::string kGoodSetup =
    "[[setup]]\nname = \"ode\"\nengine = \"ode\"\nladder.key = \"engines.ode.timestep\"\n"
    "ladder.values = [1e-3, 5e-4]\n";

std::string load_error(const fs::path& p) {
  try {
    load_sweep(p.string());
  } catch (const SceneError& e) {
    return e.what();
  }
  return "";
}

}  // namespace

TEST(SweepFiles, ShippedSweepsLoad) {
  const SweepPlan smoke = load_sweep(kSmoke);
  EXPECT_GE(smoke.points.size(), 6u);
  const SweepPlan def = load_sweep(kSource + "/harness/sweeps/default.toml");
  std::set<std::string> engines, scenes;
  size_t most_steps = 0;
  bool analytic_ladder = false;
  for (const SweepSetup& s : def.spec.setups) {
    engines.insert(s.engine);
    if (s.ladder_key.find("timestep") != std::string::npos) most_steps = std::max(most_steps, s.ladder_values.size());
    analytic_ladder = analytic_ladder || (s.engine == "analytic" && s.ladder_key == "engines.analytic.rtol");
  }
  for (const Scene& s : def.scenes) scenes.insert(s.name);
  EXPECT_GE(engines.size(), 4u) << "three engines and the analytic model";
  EXPECT_GE(most_steps, 6u);
  EXPECT_TRUE(analytic_ladder);
  EXPECT_TRUE(scenes.count("source_dimensionless") && scenes.count("toy_viscous"));
  EXPECT_GE(def.spec.repeats, 1);
  // Point ids are unique and stable.
  std::set<std::string> ids;
  for (const SweepPoint& p : def.points) ids.insert(p.id);
  EXPECT_EQ(ids.size(), def.points.size());
  EXPECT_EQ(load_sweep(kSource + "/harness/sweeps/default.toml").plan_hash, def.plan_hash);
}

TEST(SweepFiles, PointsCarryTheirOverrides) {
  TempDir dir{"tippe-sweep"};
  const fs::path p =
      write_sweep(dir.path(), kGoodHead +
                                  "[[setup]]\nname = \"mj\"\nengine = \"mujoco\"\n"
                                  "set = [\"engines.mujoco.integrator=\\\"RK4\\\"\"]\n"
                                  "ladder.key = \"engines.mujoco.iterations\"\nladder.values = [5, 50]\n");
  const SweepPlan plan = load_sweep(p.string());
  ASSERT_EQ(plan.points.size(), 2u);
  const Scene& s = plan.points[1].scene;
  EXPECT_EQ(s.run.duration, 0.5);
  EXPECT_EQ(std::get<std::string>(s.engines.at("mujoco").at("integrator")), "RK4");
  EXPECT_EQ(std::get<long long>(s.engines.at("mujoco").at("iterations")), 50) << "integers stay integers";
  EXPECT_NE(plan.points[0].id, plan.points[1].id);
}

TEST(SweepFiles, InvalidFilesNameFileAndKey) {
  TempDir dir{"tippe-sweep"};
  struct Case {
    std::string body, key;
  };
  const std::vector<Case> cases = {
      {kGoodHead + "repeat = 3\n" + kGoodSetup, ": repeat: unknown key"},
      {"repeats = 0\nscenes = [\"" + kScene + "\"]\n" + kGoodSetup, ": repeats: 0 is out of range (expected 1 <= repeats <= 100)"},
      {"repeats = 2.5\nscenes = [\"" + kScene + "\"]\n" + kGoodSetup, ": repeats: expected an integer"},
      {"duration = -1\nscenes = [\"" + kScene + "\"]\n" + kGoodSetup, ": duration: -1 is out of range (expected duration > 0)"},
      {"scenes = [\"nosuch.toml\"]\n" + kGoodSetup, ": scenes[0]: cannot read"},
      {"scenes = []\n" + kGoodSetup, ": scenes: must list at least one scene"},
      {kGoodHead, ": setup: missing"},
      {kGoodHead + "[[setup]]\nname = \"x\"\nengine = \"havok\"\nladder.key = \"k\"\nladder.values = [1]\n",
       ": setup[0].engine: unknown engine \"havok\""},
      {kGoodHead + kGoodSetup + kGoodSetup, ": setup[1].name: \"ode\" is already the name of setup[0]"},
      {kGoodHead + "[[setup]]\nname = \"x\"\nengine = \"ode\"\nladder.key = \"engines.ode.timestep\"\n"
                   "ladder.values = [1e-3, 0.5]\n",
       ": setup[0].ladder.values[1]: engines.ode.timestep: value 0.5 outside"},
      {kGoodHead + "[[setup]]\nname = \"x\"\nengine = \"ode\"\nladder.key = \"engines.ode.timestep\"\n"
                   "ladder.values = [\"fine\"]\n",
       ": setup[0].ladder.values[0]: engines.ode.timestep: expected a number"},
      {kGoodHead + "[[setup]]\nname = \"x\"\nengine = \"ode\"\nset = [\"engines.ode.nosuch=1\"]\n"
                   "ladder.key = \"engines.ode.timestep\"\nladder.values = [1e-3]\n",
       ": setup[0].set[0]: engines.ode.nosuch: unknown setting"},
      {kGoodHead + "[[setup]]\nname = \"x\"\nengine = \"ode\"\nset = [\"contact.k=2\"]\n"
                   "ladder.key = \"engines.ode.timestep\"\nladder.values = [1e-3]\n",
       ": setup[0].set[0]: \"contact.k\" is not a setting of ode"},
      {kGoodHead +
           "[[setup]]\nname = \"x\"\nengine = \"analytic\"\nladder.key = \"run.duration\"\nladder.values = [1]\n",
       ": setup[0].ladder.key: \"run.duration\" is not a setting of the analytic model"},
      {kGoodHead + "[[setup]]\nname = \"x\"\nengine = \"ode\"\nladder.key = \"engines.ode.timestep\"\n"
                   "ladder.values = [1e-3, 1e-3]\n",
       ": setup[0].ladder.values[1]: 0.001 repeats setup[0].ladder.values[0]"},
      {kGoodHead +
           "[[setup]]\nname = \"x\"\nengine = \"ode\"\nladder = { key = \"engines.ode.timestep\", values = [1e-3], "
           "step = 2 }\n",
       ": setup[0].ladder.step: unknown key"},
  };
  for (size_t i = 0; i < cases.size(); ++i) {
    const fs::path p = write_sweep(dir.path(), cases[i].body, "case" + std::to_string(i) + ".toml");
    const std::string msg = load_error(p);
    EXPECT_EQ(msg.rfind(p.string() + ":", 0), 0u) << "case " << i << ": " << msg;
    EXPECT_NE(msg.find(cases[i].key), std::string::npos) << "case " << i << ": " << msg;
  }
  const fs::path syntax = write_sweep(dir.path(), "repeats = = 3\n", "syntax.toml");
  EXPECT_EQ(load_error(syntax).rfind(syntax.string() + ":1:", 0), 0u) << load_error(syntax);
}

// ---- the command ------------------------------------------------------------------------------

namespace {

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

// ---- ladders: categorical values and grids ----------------------------------------------------

// Published sweep directories resume only while a one-axis point keeps its id: the value below
// was computed by the build before grids and categorical ladders existed.
TEST(SweepLadders, OneAxisPointIdsAreThoseOfEarlierBuilds) {
  SweepSetup u;
  u.name = "ode";
  u.engine = "ode";
  u.set = {"engines.ode.iterations=50"};
  u.ladder_key = "engines.ode.timestep";
  EXPECT_EQ(sweep_point_id("fedcba9876543210", u, "0.001", 3), "c8db2ce8901bf92f");
}


namespace {

const std::string kMujocoFrameGrid =
    "[[setup]]\nname = \"mj\"\nengine = \"mujoco\"\n"
    "ladder = { key = \"engines.mujoco.timestep\", values = [1e-3, 5e-4, 2.5e-4] }\n"
    "grid = { key = \"engines.mujoco.body_frame\", values = [\"com\", \"ball_centre\"] }\n";

// A grid point of the Modelling-choices fixtures: scene s, the setup's choice at `dt`.
SweepRecord choice_point(const std::string& setup, long long grid_index, const std::string& choice, long long ladder_index,
                         double dt, std::optional<double> inversion) {
  SweepRecord r = point("mujoco", setup, dt, 1e-3 / dt, std::nullopt);
  r.scene = "s";
  r.point_id = setup + choice + std::to_string(ladder_index);
  r.ladder_index = ladder_index;
  r.grid_key = "engines.mujoco." + setup;
  r.grid_label = choice;
  r.grid_index = grid_index;
  r.inversion_time = inversion;
  if (inversion) {
    r.metrics.inversion_event = "both";
    r.metrics.inversion_time_rel_error = *inversion / 10.0 - 1;
  }
  return r;
}

}  // namespace

TEST(SweepLadders, OneAxisPlanIdsAreTheOneAxisFormula) {
  TempDir dir{"tippe-sweep"};
  const SweepPlan plan = load_sweep(write_sweep(dir.path(), kGoodHead + kGoodSetup).string());
  ASSERT_EQ(plan.points.size(), 2u);
  const SweepSetup& u = plan.spec.setups[0];
  EXPECT_FALSE(u.has_grid());
  for (size_t k = 0; k < 2; ++k) {
    EXPECT_EQ(plan.points[k].grid_index, 0u);
    EXPECT_EQ(plan.points[k].id, sweep_point_id(plan.physics_hashes[0], u, u.ladder_texts[k], 1));
  }
  EXPECT_EQ(u.ladder_labels, (std::vector<std::string>{"0.001", "0.0005"}));
}

TEST(SweepLadders, CategoricalLadderPlansOnePointPerValue) {
  TempDir dir{"tippe-sweep"};
  const fs::path p = write_sweep(dir.path(), kGoodHead +
                                                 "[[setup]]\nname = \"mj\"\nengine = \"mujoco\"\n"
                                                 "ladder.key = \"engines.mujoco.body_frame\"\n"
                                                 "ladder.values = [\"com\", \"ball_centre\"]\n"
                                                 "[[setup]]\nname = \"bt\"\nengine = \"bullet\"\n"
                                                 "ladder.key = \"engines.bullet.velocity_friction_direction\"\n"
                                                 "ladder.values = [true, false]\n");
  const SweepPlan plan = load_sweep(p.string());
  ASSERT_EQ(plan.points.size(), 4u);
  const SweepSetup& u = plan.spec.setups[0];
  EXPECT_EQ(u.ladder_texts, (std::vector<std::string>{"\"com\"", "\"ball_centre\""}));
  EXPECT_EQ(u.ladder_labels, (std::vector<std::string>{"com", "ball_centre"}));
  EXPECT_TRUE(std::isnan(u.ladder_values[0]) && std::isnan(u.ladder_values[1]));
  EXPECT_EQ(std::get<std::string>(plan.points[1].scene.engines.at("mujoco").at("body_frame")), "ball_centre");
  EXPECT_EQ(std::get<bool>(plan.points[3].scene.engines.at("bullet").at("velocity_friction_direction")), false);
  EXPECT_EQ(plan.spec.setups[1].ladder_labels, (std::vector<std::string>{"true", "false"}));
  std::set<std::string> ids;
  for (const SweepPoint& q : plan.points) ids.insert(q.id);
  EXPECT_EQ(ids.size(), 4u);
  EXPECT_EQ(plan.points[0].id, sweep_point_id(plan.physics_hashes[0], u, "\"com\"", 1));
  EXPECT_EQ(load_sweep(p.string()).plan_hash, plan.plan_hash) << "ids are stable";
}

TEST(SweepLadders, GridPlansEveryPairGridThenLadder) {
  TempDir dir{"tippe-sweep"};
  const fs::path p = write_sweep(dir.path(), kGoodHead + kMujocoFrameGrid + kGoodSetup);
  const SweepPlan plan = load_sweep(p.string());
  ASSERT_EQ(plan.points.size(), 6u + 2u);
  const SweepSetup& u = plan.spec.setups[0];
  ASSERT_TRUE(u.has_grid());
  EXPECT_EQ(u.point_count(), 6u);
  EXPECT_EQ(u.grid_labels, (std::vector<std::string>{"com", "ball_centre"}));
  const std::vector<std::pair<size_t, size_t>> order = {{0, 0}, {0, 1}, {0, 2}, {1, 0}, {1, 1}, {1, 2}};
  std::set<std::string> ids;
  for (size_t i = 0; i < 6; ++i) {
    const SweepPoint& q = plan.points[i];
    EXPECT_EQ(q.grid_index, order[i].first) << i;
    EXPECT_EQ(q.ladder_index, order[i].second) << i;
    const auto& mj = q.scene.engines.at("mujoco");
    EXPECT_EQ(std::get<std::string>(mj.at("body_frame")), u.grid_labels[q.grid_index]) << i;
    EXPECT_EQ(std::get<double>(mj.at("timestep")), u.ladder_values[q.ladder_index]) << i;
    EXPECT_EQ(q.id, sweep_point_id(plan.physics_hashes[0], u, u.ladder_texts[q.ladder_index], 1,
                                   u.grid_texts[q.grid_index]));
    ids.insert(q.id);
  }
  EXPECT_EQ(ids.size(), 6u);
  // The grid's points are not the one-axis points of the same ladder, and the one-axis setup
  // beside it keeps its ids.
  EXPECT_FALSE(ids.count(sweep_point_id(plan.physics_hashes[0], u, u.ladder_texts[0], 1)));
  const SweepPlan alone = load_sweep(write_sweep(dir.path(), kGoodHead + kGoodSetup, "alone.toml").string());
  EXPECT_EQ(plan.points[6].id, alone.points[0].id);
  EXPECT_EQ(plan.points[7].id, alone.points[1].id);
  EXPECT_EQ(load_sweep(p.string()).plan_hash, plan.plan_hash);
  // The shipped modelling sweep is a grid on every setup.
  const SweepPlan modelling = load_sweep(kSource + "/harness/sweeps/modelling.toml");
  for (const SweepSetup& s : modelling.spec.setups) EXPECT_TRUE(s.has_grid()) << s.name;
  EXPECT_GE(modelling.points.size(), 2u * 6 * 2);
}

TEST(SweepLadders, GridRecordsRoundTripAndOldRecordsReadBack) {
  SweepRecord r = sample_record();
  r.ladder_key = "engines.mujoco.body_frame";
  r.ladder_value = std::nan("");
  r.ladder_label = "ball_centre";
  r.grid_key = "engines.mujoco.noslip_iterations";
  r.grid_value = 10;
  r.grid_label = "10";
  r.grid_index = 1;
  const std::string line = to_jsonl(r);
  const SweepRecord back = sweep_record_from_json(json::parse(line));
  EXPECT_EQ(to_jsonl(back), line);
  EXPECT_TRUE(std::isnan(back.ladder_value));
  EXPECT_EQ(back.ladder_label, "ball_centre");
  EXPECT_EQ(back.grid_key, r.grid_key);
  EXPECT_EQ(back.grid_value, 10);
  EXPECT_EQ(back.grid_label, "10");
  EXPECT_EQ(back.grid_index, 1);
  EXPECT_EQ(ladder_text(back), "ball_centre");
  EXPECT_EQ(grid_text(back), "10");

  // A record from before grids and categorical ladders: no ladder_label, no grid.
  json old = to_json(sample_record());
  old.erase("ladder_label");
  old.erase("grid");
  const SweepRecord o = sweep_record_from_json(old);
  EXPECT_EQ(o.ladder_value, 3e-5);
  EXPECT_EQ(o.ladder_label, "3e-05");
  EXPECT_TRUE(o.grid_key.empty());
  EXPECT_EQ(o.grid_index, 0);
  EXPECT_EQ(json::parse(to_jsonl(sample_record()))["grid"], nullptr);
}

// Keys and labels read back become report labels and gnuplot column headers: names or numbers,
// and a label says the number beside it.
TEST(SweepLadders, GridFieldsReadBackAreCheckedByKey) {
  auto message = [](const json& j) -> std::string {
    try {
      sweep_record_from_json(j);
    } catch (const SweepRecordError& e) {
      return e.what();
    }
    return "accepted";
  };
  SweepRecord g = sample_record();
  g.grid_key = "engines.mujoco.cone";
  g.grid_label = "pyramidal";
  g.grid_index = 1;
  const json good = to_json(g);
  EXPECT_EQ(message(good), "accepted");
  json j = good;
  j["grid"]["label"] = "a'b\"; system";
  EXPECT_EQ(message(j).rfind("grid.label: \"a'b\"; system\" is neither a number nor a usable name", 0), 0u) << message(j);
  j = good;
  j["grid"]["key"] = "engines mujoco";
  EXPECT_EQ(message(j).rfind("grid.key: \"engines mujoco\" is not a usable key", 0), 0u) << message(j);
  j = good;
  j["grid"]["index"] = -1;
  EXPECT_EQ(message(j).rfind("grid.index: -1 is out of range", 0), 0u) << message(j);
  j = good;
  j["grid"]["value"] = "x";
  EXPECT_EQ(message(j), "grid.value: expected a number or null, got string");
  j = good;
  j["grid"]["label"] = "5";
  EXPECT_EQ(message(j), "grid.label: \"5\" is a number, but grid.value is null");
  j = good;
  j["grid"] = 3;
  EXPECT_EQ(message(j).rfind("grid: expected an object", 0), 0u) << message(j);
  j = good;
  j["ladder_label"] = "0.002";
  EXPECT_EQ(message(j), "ladder_label: \"0.002\" is not ladder_value 3e-05");
  j = good;
  j["ladder_value"] = nullptr;
  j.erase("ladder_label");
  EXPECT_EQ(message(j), "ladder_label: missing (required when ladder_value is null)");
  j = good;
  j["ladder_key"] = "$(rm -rf x)";
  EXPECT_EQ(message(j).rfind("ladder_key: \"$(rm -rf x)\" is not a usable key", 0), 0u) << message(j);

  TempDir dir{"tippe-sweep"};
  const fs::path file = dir.path() / "records.jsonl";
  j = good;
  j["grid"]["label"] = "a b";
  spit(file, to_jsonl(g) + j.dump() + "\n");
  try {
    read_records(file.string());
    FAIL() << "no exception";
  } catch (const SweepRecordError& e) {
    EXPECT_EQ(std::string(e.what()).rfind(file.string() + ":2: grid.label: \"a b\" is neither", 0), 0u) << e.what();
  }
}

TEST(SweepLadders, ModellingChoicesFindWhatMovesTheVerdict) {
  std::vector<SweepRecord> recs;
  long long setup_index = 0;
  const std::vector<double> steps = {1e-3, 5e-4};
  // body_frame: at the coarse step ball_centre does not invert (the regime moves); cone:
  // pyramidal inverts 5 % later; noslip_iterations: 0.5 % apart, within the 1 % threshold.
  const struct {
    std::string setup, a, b;
    std::vector<std::optional<double>> ta, tb;
  } fixtures[] = {
      {"body_frame", "com", "ball_centre", {4.0, 4.0}, {std::nullopt, 4.01}},
      {"cone", "elliptic", "pyramidal", {4.0, 4.0}, {4.1, 4.2}},
      {"noslip_iterations", "0", "10", {4.0, 4.0}, {4.01, 4.02}},
  };
  for (const auto& f : fixtures) {
    for (long long k = 0; k < 2; ++k) {
      SweepRecord a = choice_point(f.setup, 0, f.a, k, steps[k], f.ta[k]);
      SweepRecord b = choice_point(f.setup, 1, f.b, k, steps[k], f.tb[k]);
      if (f.setup == "noslip_iterations") a.grid_value = 0, b.grid_value = 10;
      a.setup_index = b.setup_index = setup_index;
      recs.push_back(a);
      recs.push_back(b);
    }
    ++setup_index;
  }
  const std::vector<ChoiceEffect> effects = modelling_choices(recs);
  ASSERT_EQ(effects.size(), 3u);
  const ChoiceEffect& frame = effects[0];
  EXPECT_EQ(frame.key, "engines.mujoco.body_frame");
  EXPECT_EQ(frame.values, (std::vector<std::string>{"com", "ball_centre"}));
  EXPECT_EQ(frame.steps, 2u);
  EXPECT_TRUE(frame.regime_moves);
  EXPECT_EQ(frame.regime_at, "timestep = 0.001");
  EXPECT_EQ(frame.regime_steps, 1u);
  EXPECT_EQ(frame.regime_outcomes,
            (std::vector<std::string>{"com: inverts at 4 (the reference's regime)", "ball_centre: does not invert"}));
  EXPECT_TRUE(frame.moves());
  const ChoiceEffect& cone = effects[1];
  EXPECT_FALSE(cone.regime_moves);
  ASSERT_TRUE(cone.largest_spread);
  EXPECT_NEAR(*cone.largest_spread, 0.05, 1e-12);
  EXPECT_EQ(cone.spread_at, "timestep = 0.0005");
  EXPECT_TRUE(cone.time_moves());
  const ChoiceEffect& noslip = effects[2];
  EXPECT_FALSE(noslip.regime_moves);
  ASSERT_TRUE(noslip.largest_spread);
  EXPECT_NEAR(*noslip.largest_spread, 0.005, 1e-12);
  EXPECT_FALSE(noslip.moves());

  const std::string md = render_sweep_markdown(recs);
  EXPECT_NE(md.find("## Modelling choices"), std::string::npos) << md;
  EXPECT_NE(md.find("mujoco: body_frame moves it (s (body_frame): the regime at timestep = 0.001 (1 of 2 steps)). cone moves it (s "
                    "(cone): the inversion time by 5 % at timestep = 0.0005). noslip_iterations does not move the "
                    "verdict (s (noslip_iterations): within 0.5 %)."),
            std::string::npos)
      << md;
  EXPECT_NE(md.find("| mujoco | s | inverts at 10 | body_frame | engines.mujoco.body_frame | com, ball_centre | moves the regime | at "
                    "timestep = 0.001 (1 of 2 steps): com: inverts at 4 (the reference's regime); ball_centre: does not invert;"),
            std::string::npos)
      << md;
  EXPECT_NE(md.find("| moves the inversion time by 5 % | largest: inversion times 5 % apart at timestep = 0.0005 "
                    "(elliptic 4, pyramidal 4.2) |"),
            std::string::npos)
      << md;
  EXPECT_NE(md.find("| noslip_iterations | engines.mujoco.noslip_iterations | 0, 10 | does not move the verdict |"),
            std::string::npos)
      << md;
  // One line per grid value wherever the report walks a ladder.
  EXPECT_NE(md.find("| cone cone=pyramidal | mujoco |"), std::string::npos) << md;
  EXPECT_NE(md.find("| s, cone=pyramidal |"), std::string::npos) << md;
  // A sweep without choices has no such section.
  std::vector<SweepRecord> plain = {point("ode", "ode", 1e-3, 1, 0.01)};
  plain[0].scene = "s";
  EXPECT_EQ(render_sweep_markdown(plain).find("Modelling choices"), std::string::npos);
}

TEST(SweepLadders, BadCategoricalValuesAreRefusedAtLoad) {
  TempDir dir{"tippe-sweep"};
  const std::string mj = "[[setup]]\nname = \"mj\"\nengine = \"mujoco\"\n";
  const std::string steps = "ladder = { key = \"engines.mujoco.timestep\", values = [1e-3, 5e-4] }\n";
  struct Case {
    std::string body, expected;
  };
  const std::vector<Case> cases = {
      {mj + steps + "grid = { key = \"engines.mujoco.cone\", values = [\"elliptic\", \"pyramid\"] }\n",
       ": setup[0].grid.values[1]: engines.mujoco.cone: value \"pyramid\" is not one of: elliptic, pyramidal"},
      {mj + "ladder = { key = \"engines.mujoco.body_frame\", values = [\"com\", \"middle\"] }\n",
       ": setup[0].ladder.values[1]: engines.mujoco.body_frame: value \"middle\" is not one of: com, ball_centre"},
      {mj + steps + "grid = { key = \"engines.mujoco.noslip_iterations\", values = [\"many\"] }\n",
       ": setup[0].grid.values[0]: engines.mujoco.noslip_iterations: expected an integer"},
      {mj + steps + "grid = { key = \"engines.mujoco.body_frame\", values = [\"com\", 1] }\n",
       ": setup[0].grid.values[1]: expected a string like setup[0].grid.values[0], got an integer 1 (an axis' values are all "
       "numbers, all strings or all booleans)"},
      {mj + steps + "grid = { key = \"engines.mujoco.body_frame\", values = [\"com\", \"com\"] }\n",
       ": setup[0].grid.values[1]: com repeats setup[0].grid.values[0]"},
      {mj + steps + "grid = { key = \"engines.mujoco.body_frame\", values = [\"a b\"] }\n",
       ": setup[0].grid.values[0]: \"a b\" is not a usable value"},
      {mj + steps + "grid = { key = \"engines.mujoco.timestep\", values = [1e-4] }\n",
       ": setup[0].grid.key: engines.mujoco.timestep is also setup[0]'s ladder key"},
      {mj + "set = [\"engines.mujoco.cone=\\\"pyramidal\\\"\"]\n" + steps +
           "grid = { key = \"engines.mujoco.cone\", values = [\"elliptic\"] }\n",
       ": setup[0].grid.key: engines.mujoco.cone is also fixed in setup[0].set"},
      {mj + steps + "grid = { key = \"contact.mu\", values = [0.1, 0.2] }\n",
       ": setup[0].grid.key: \"contact.mu\" is not a setting of mujoco"},
      {mj + steps + "grid = { key = \"engines.mujoco.cone\", values = [] }\n",
       ": setup[0].grid.values: must list at least one value"},
      {mj + steps + "grid = { key = \"engines.mujoco.cone\", values = [\"elliptic\"], by = 2 }\n",
       ": setup[0].grid.by: unknown key (expected one of: key, values)"},
      {mj + steps + "grid = { key = \"engines.mujoco.cone\", values = [{ a = 1 }] }\n",
       ": setup[0].grid.values[0]: expected a number, a string or a boolean, got"},
  };
  for (size_t i = 0; i < cases.size(); ++i) {
    const fs::path p = write_sweep(dir.path(), kGoodHead + cases[i].body, "bad" + std::to_string(i) + ".toml");
    const std::string msg = load_error(p);
    EXPECT_EQ(msg.rfind(p.string() + cases[i].expected, 0), 0u) << "case " << i << ": " << msg;
  }
}
