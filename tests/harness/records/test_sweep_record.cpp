// Tests of the sweep record and sweep.json read back (harness/records/sweep_record.cpp): a record's JSON line round trip, partial and corrupt lines, every field checked by key, and the grid's fields.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <string>

#include "harness/records/sweep_record.h"
#include "tests/support/files.h"

namespace test_sweep_record {

namespace fs = std::filesystem;
using namespace tippe;
using nlohmann::json;

namespace {

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

// ---- grids and categorical ladders ------------------------------------------------------------

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

}  // namespace test_sweep_record
