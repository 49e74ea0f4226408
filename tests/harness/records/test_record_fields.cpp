// Each record's one field list (`visit`, records/fields.h): every field it lists is written, read back, described by the committed schema and, for a comparison's numbers, in the metric table.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <optional>
#include <type_traits>
#include <vector>
#include <set>
#include <string>

#include <nlohmann/json.hpp>

#include "harness/library/schemas.h"
#include "harness/records/comparison.h"
#include "harness/records/fields.h"
#include "harness/records/metric_bounds.h"
#include "harness/records/record_schemas.h"
#include "harness/records/records.h"
#include "tests/support/field_filler.h"
#include "tests/support/files.h"

namespace test_record_fields {

namespace {

using namespace tippe;
using nlohmann::json;
namespace fs = std::filesystem;

std::set<std::string> keys_of(const json& j) {
  std::set<std::string> k;
  for (const auto& [key, v] : j.items()) k.insert(key);
  return k;
}

template <class T>
std::set<std::string> visited_keys() {
  std::set<std::string> k;
  for (const FieldInfo& f : field_list<T>()) EXPECT_TRUE(k.insert(f.key).second) << f.key << " listed twice";
  return k;
}

json committed_schema(const std::string& name) {
  return json::parse(slurp(fs::path(TIPPE_SOURCE_DIR) / "schemas" / (name + ".schema.json")));
}

// ---- the run summary ------------------------------------------------------------------------------

TEST(RecordFields, RunSummaryWritesExactlyItsVisitedFieldsAndReadsEveryOneBack) {
  const RunRecord r = filled<RunRecord>();
  const json j = to_json(r);
  std::set<std::string> expected = visited_keys<RunRecord>();
  expected.insert("format");
  EXPECT_EQ(keys_of(j), expected);
  // Distinct values: a field read into another, or not read, changes the JSON written again.
  EXPECT_EQ(to_json(from_json(json::parse(j.dump()))), j);
  EXPECT_EQ(from_json(j).samples, r.samples);
  EXPECT_EQ(from_json(j).ledger_at_inversion->numerical_energy, r.ledger_at_inversion->numerical_energy);
}

TEST(RecordFields, RunSummaryFieldsSinceAFormatChangeReadAsTheirDefaultWhenAbsent) {
  json j = to_json(filled<RunRecord>());
  const RunRecord defaults{};
  const json written_defaults = to_json(defaults);
  for (const FieldInfo& f : field_list<RunRecord>()) {
    json without = j;
    without.erase(f.key);
    bool since = false;
    try {
      const json back = to_json(from_json(without));
      since = true;
      EXPECT_EQ(back.at(f.key), written_defaults.at(f.key)) << f.key << " absent does not read as its default";
    } catch (const json::exception&) {
    }
    const json schema = committed_schema("run-summary").at("$defs").at("summary");
    const auto& req = schema.at("required");
    EXPECT_EQ(std::find(req.begin(), req.end(), f.key) == req.end(), since)
        << f.key << ": the schema's required list and the reader disagree";
  }
}

// ---- the comparison's metrics ---------------------------------------------------------------------

TEST(RecordFields, MetricsWriteExactlyTheirVisitedFieldsAndReadEveryOneBack) {
  const Metrics m = filled<Metrics>();
  const json j = to_json(m);
  EXPECT_EQ(keys_of(j), visited_keys<Metrics>());
  EXPECT_EQ(to_json(metrics_from_json(json::parse(j.dump()))), j);
}

// A number added to Metrics' `visit` is in the metric table, in the visit's order (a gate's rows
// follow it), unless the visit says why not, which a bound naming it is told.
TEST(RecordFields, EveryBoundedNumberOfMetricsIsInTheMetricTable) {
  const Metrics m = filled<Metrics>();
  const json j = to_json(m);
  size_t bounded = 0;
  for (const FieldInfo& f : field_list<Metrics>()) {
    const GateMetric* g = find_gate_metric(f.key);
    if (!f.bounded) {
      EXPECT_EQ(g, nullptr) << f.key;
      if (f.number) {
        const std::string why = gate_metric_problem(f.key);
        EXPECT_FALSE(why.empty() || why.rfind("unknown metric", 0) == 0) << f.key << ": " << why;
      }
      continue;
    }
    ASSERT_NE(g, nullptr) << f.key << " is a bounded number of Metrics but not in the metric table";
    ASSERT_LT(bounded, gate_metrics().size());
    EXPECT_EQ(gate_metrics()[bounded].name, f.key) << "the metric table is in the order of Metrics' visit";
    ++bounded;
    ASSERT_TRUE(g->get(m).has_value()) << f.key;
    EXPECT_EQ(*g->get(m), j.at(f.key).get<double>()) << f.key;
    EXPECT_EQ(gate_metric_problem(f.key), "") << f.key;
  }
  EXPECT_EQ(gate_metrics().size(), bounded);
}

// ---- the reader holds every field to its rules ---------------------------------------------------

// What a `visit` says a reader must refuse: a number below the field's minimum, a name outside its
// choices, for every field of the list, whether it came with a format change (`since`) or not.
// Each value a rule refuses, with the error the reader must give (what it names).
template <class T, class Read>
void expect_every_rule_held(const json& written, Read read) {
  size_t rules = 0;
  for (const FieldInfo& r : field_list<T>()) {
    if (!r.min && !r.choices) continue;
    ++rules;
    json bad = written;
    if (r.min) bad[r.key] = *r.min - 1;
    else if (r.list) bad[r.key] = json::array({"no_such_name"});
    else bad[r.key] = "no_such_name";
    try {
      read(bad);
      ADD_FAILURE() << r.key << " = " << bad[r.key].dump() << " was read back";
    } catch (const std::exception& e) {
      EXPECT_NE(std::string(e.what()).find(r.key), std::string::npos) << r.key << ": " << e.what();
    }
  }
  EXPECT_GT(rules, 0u);
}

TEST(RecordFields, TheReaderHoldsEveryFieldToItsMinimumAndChoices) {
  expect_every_rule_held<RunRecord>(to_json(filled<RunRecord>()), [](const json& j) { return from_json(j); });
  expect_every_rule_held<Metrics>(to_json(filled<Metrics>()), [](const json& j) { return metrics_from_json(j); });
  expect_every_rule_held<SelfCheck>(to_json(filled<SelfCheck>()), [](const json& j) { return self_check_from_json(j); });
  // The rules above include fields of the first format (no `since`): a run's sample count and
  // status, a list of names.
  std::set<std::string> keys;
  for (const FieldInfo& r : field_list<RunRecord>())
    if (r.min || r.choices) keys.insert(r.key);
  EXPECT_TRUE(keys.count("samples") && keys.count("status") && keys.count("ledger_not_available"));
}

TEST(RecordFields, SelfCheckWritesExactlyItsVisitedFieldsAndReadsEveryOneBack) {
  const json j = to_json(filled<SelfCheck>());
  EXPECT_EQ(keys_of(j), visited_keys<SelfCheck>());
  EXPECT_EQ(to_json(self_check_from_json(json::parse(j.dump()))), j);
  json old = j;
  old.erase("atol");  // records written before the absolute tolerance was a setting
  EXPECT_EQ(self_check_from_json(old).atol, 0.0);
}

// ---- the schemas ------------------------------------------------------------------------------------

// Every generated schema, the records' and the gate result's (library/schemas.h).
TEST(RecordFields, CommittedSchemasAreTheGeneratedOnes) {
  for (const std::string& name : generated_schema_names()) {
    const fs::path file = fs::path(TIPPE_SOURCE_DIR) / "schemas" / (name + ".schema.json");
    EXPECT_EQ(slurp(file), generated_schema_text(name))
        << file << " differs from the record's field list; regenerate it:\n"
        << "  ./build/tippe info --schema " << name << " > schemas/" << name << ".schema.json";
  }
}

// What the comparison above rests on: every visited field is a property of the schema, with the
// type its C++ type gives, so a field added to a `visit` is in the committed schema.
TEST(RecordFields, EveryVisitedFieldIsAPropertyOfItsSchema) {
  const json summary = json::parse(record_schema_text("run-summary")).at("$defs").at("summary").at("properties");
  for (const FieldInfo& f : field_list<RunRecord>()) EXPECT_TRUE(summary.contains(f.key)) << f.key;
  const json metrics = json::parse(record_schema_text("comparison")).at("$defs").at("metrics").at("properties");
  for (const FieldInfo& f : field_list<Metrics>()) {
    ASSERT_TRUE(metrics.contains(f.key)) << f.key;
    const std::string type = metrics.at(f.key).value("type", json()).dump();
    if (f.number) {
      EXPECT_TRUE(type.find("number") != std::string::npos || type.find("integer") != std::string::npos) << f.key;
    }
  }
  EXPECT_EQ(summary.at("samples").at("type"), "integer");
  EXPECT_EQ(summary.at("ledger_at_inversion").at("type"), json({"object", "null"}));
  EXPECT_EQ(metrics.at("events_missing").at("minimum"), 0);
}

}  // namespace

}  // namespace test_record_fields
