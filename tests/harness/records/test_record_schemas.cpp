// The generated schemas (library/schemas.h): which files of schemas/ they are, and that the sweep record's and the gate result's say what their readers and writers do.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <iterator>
#include <regex>
#include <set>
#include <stdexcept>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "harness/gating/gate.h"
#include "harness/io/names.h"
#include "harness/library/schemas.h"
#include "harness/measure/classify.h"
#include "harness/records/fields.h"
#include "harness/records/record_schemas.h"
#include "harness/records/records.h"
#include "harness/records/sweep_record.h"
#include "tests/support/files.h"

namespace test_record_schemas {

namespace {

using namespace tippe;
using nlohmann::json;
namespace fs = std::filesystem;

std::set<std::string> keys_of(const json& object) {
  std::set<std::string> k;
  for (const auto& [key, v] : object.items()) k.insert(key);
  return k;
}

bool is_required(const json& object_schema, const std::string& key) {
  const json& r = object_schema.at("required");
  return std::find(r.begin(), r.end(), key) != r.end();
}

// Every schema of schemas/ is generated from a field list but that of sweep.json (a sweep's plan,
// written from the sweep file, which has no list): a schema added by hand fails here, and so
// does a generated one without its committed file.
TEST(RecordSchemas, EverySchemaFileButTheSweepPlansIsGenerated) {
  std::set<std::string> files;
  for (const auto& e : fs::directory_iterator(fs::path(TIPPE_SOURCE_DIR) / "schemas")) {
    const std::string name = e.path().filename().string();
    const std::string suffix = ".schema.json";
    if (name.size() > suffix.size() && name.compare(name.size() - suffix.size(), suffix.size(), suffix) == 0)
      files.insert(name.substr(0, name.size() - suffix.size()));
  }
  const std::vector<std::string>& names = generated_schema_names();
  const std::set<std::string> generated(names.begin(), names.end());
  EXPECT_EQ(generated.size(), names.size()) << "a name listed twice";
  EXPECT_EQ(generated, (std::set<std::string>{"run-summary", "comparison", "sweep-record", "gate-result", "advice"}));
  std::set<std::string> by_hand;
  std::set_difference(files.begin(), files.end(), generated.begin(), generated.end(),
                      std::inserter(by_hand, by_hand.end()));
  EXPECT_EQ(by_hand, std::set<std::string>{"sweep"});
  for (const std::string& n : names) EXPECT_TRUE(files.count(n)) << n << " has no committed file";
  for (const std::string& n : names) EXPECT_EQ(json::parse(generated_schema_text(n)).at("$id"), n + ".schema.json");
}

TEST(RecordSchemas, AnUnknownNameIsRefusedWithTheGeneratedNames) {
  try {
    generated_schema_text("sweep");
    FAIL() << "no throw";
  } catch (const std::invalid_argument& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("\"sweep\""), std::string::npos) << m;
    for (const std::string& n : generated_schema_names()) EXPECT_NE(m.find(n), std::string::npos) << m;
  }
  EXPECT_THROW(record_schema_text("gate-result"), std::invalid_argument);  // the records know no gates
}

// The pattern the schemas give names is the rule is_valid_name checks (std::regex's ECMAScript
// grammar is the one JSON Schema patterns use).
TEST(RecordSchemas, TheNamePatternIsTheRuleOfNames) {
  const std::regex pattern(kNamePattern);
  const std::vector<std::string> samples = {"", ".", "..", "...", "....", "a", "A9", ".a", "a.", "..a", "a..", "-",
                                            "_", "toy_viscous", "engines.ode.timestep", "1e-06", "a b", "a/b",
                                            "a\\b", "a\n", "\na", "a\"", "caf\xc3\xa9", "a+b", "a:b", "a,b", "*", "a\t"};
  for (const std::string& s : samples)
    EXPECT_EQ(std::regex_search(s, pattern), is_valid_name(s)) << json(s).dump(-1, ' ', false, json::error_handler_t::replace);
}

// The classes a sweep record may name are the stability map's, in RunClassKind's order.
TEST(RecordSchemas, RunClassNamesAreTheClassifiersClasses) {
  std::vector<std::string> classes;
  for (RunClassKind k : {RunClassKind::Ok, RunClassKind::Diverged, RunClassKind::Unphysical, RunClassKind::Clamped,
                         RunClassKind::Failed, RunClassKind::ContactLost})
    classes.emplace_back(to_string(k));
  EXPECT_EQ(run_class_names(), classes);
}

// What the sweep record's schema says of the fields whose checks it carries over: the readers'
// names, bounds and patterns, and the parts and groups older records lack.
TEST(RecordSchemas, TheSweepRecordSchemaCarriesTheReadersChecks) {
  const json s = json::parse(generated_schema_text("sweep-record"));
  const json& p = s.at("properties");
  EXPECT_EQ(p.at("format").at("const"), "tippe-sweep-record-1");
  EXPECT_TRUE(is_required(s, "format"));
  for (const char* k : {"scene", "setup", "engine", "ladder_key"}) EXPECT_EQ(p.at(k).at("pattern"), kNamePattern) << k;
  EXPECT_EQ(p.at("grid").at("properties").at("key").at("pattern"), kNamePattern);
  EXPECT_EQ(p.at("status").at("enum"), json(run_status_names()));
  EXPECT_EQ(p.at("reference").at("properties").at("status").at("enum"), json(run_status_names()));
  EXPECT_EQ(p.at("class").at("properties").at("name").at("enum"), json(run_class_names()));
  EXPECT_EQ(p.at("reference").at("properties").at("class").at("enum"), json(run_class_names()));
  EXPECT_EQ(p.at("repeats"), json({{"type", "integer"}, {"minimum", 1}, {"maximum", kMaxRepeats},
                                   {"description", "runs of the point; its times are their minima"}}));
  EXPECT_EQ(p.at("scene_index").at("maximum"), kMaxSweepIndex);
  EXPECT_FALSE(p.at("work").at("properties").at("steps").contains("maximum"));  // long long's own bound
  EXPECT_EQ(p.at("work").at("properties").at("steps").at("minimum"), 0);
  EXPECT_EQ(p.at("work").at("properties").at("cpu_seconds_repeats").at("maxItems"), kMaxRepeats);
  EXPECT_EQ(p.at("duration").at("minimum"), 0);
  EXPECT_EQ(p.at("metrics").at("$ref"), "comparison.schema.json#/$defs/metrics");
  EXPECT_TRUE(p.at("ladder_label").contains("pattern"));
  EXPECT_NE(p.at("ladder_label").at("description").get<std::string>().find("ladder_value"), std::string::npos);
  // A search has a range: never null, from above 0, per_decade bounded both ways.
  const json& q = p.at("search");
  EXPECT_EQ(q.at("type"), json({"object", "null"}));
  EXPECT_EQ(q.at("properties").at("from").at("type"), "number");
  EXPECT_GT(q.at("properties").at("from").at("minimum").get<double>(), 0.0);
  EXPECT_EQ(q.at("properties").at("resolution").at("minimum"), kMinSearchResolution);
  EXPECT_EQ(q.at("properties").at("per_decade").at("maximum"), kMaxSearchPerDecade);
  EXPECT_FALSE(is_required(q, "integer"));
  // Absent in older records: not required; null where the reader takes null.
  for (const char* k : {"class", "reference", "search", "ladder_label", "grid"}) EXPECT_FALSE(is_required(s, k)) << k;
  EXPECT_EQ(p.at("reference").at("type"), json({"object", "null"}));
  EXPECT_EQ(p.at("grid").at("type"), json({"object", "null"}));
  EXPECT_EQ(p.at("class").at("type"), "object");
  // The descriptions are the field list's docs.
  EXPECT_EQ(p.at("point_id").at("description"), "the point's identity in the plan");
  EXPECT_EQ(p.at("set").at("description"), "KEY=VALUE overrides of the setup");
}

// The gate result's schema describes every key `tippe gate --json` writes, each required, with
// the results from the field lists.
TEST(RecordSchemas, TheGateResultSchemaDescribesEveryKeyWritten) {
  CheckResult c;
  c.name = "check";
  c.rows.emplace_back();
  json written = to_json(std::vector<CheckResult>{c});
  written["gate_file"] = "gates.toml";  // what the command line and the Python module add
  const json s = json::parse(generated_schema_text("gate-result"));
  EXPECT_EQ(keys_of(s.at("properties")), keys_of(written));
  for (const auto& [k, v] : written.items()) EXPECT_TRUE(is_required(s, k)) << k;
  EXPECT_EQ(s.at("properties").at("format").at("const"), written.at("format"));
  const json& result = s.at("properties").at("results").at("items");
  EXPECT_EQ(keys_of(result.at("properties")), keys_of(written.at("results").at(0)));
  const json& row = result.at("properties").at("rows").at("items");
  EXPECT_EQ(keys_of(row.at("properties")), keys_of(written.at("results").at(0).at("rows").at(0)));
  EXPECT_EQ(row.at("properties").at("kind").at("enum"), json(gate_row_kind_names()));
  EXPECT_EQ(s.at("properties").at("checks").at("minimum"), 0);
  EXPECT_EQ(s.at("properties").at("failed").at("minimum"), 0);
}

}  // namespace

}  // namespace test_record_schemas
