// The library's RunSummary (<tippe/tippe.h>) and the Python stub against the run record's field list: every field of the record is in both, under its key and type, and a summary carries the record's values.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "harness/library/summary.h"
#include "harness/records/fields.h"
#include "harness/records/records.h"
#include "tests/support/field_filler.h"
#include "tests/support/files.h"

namespace tippe::test_summary {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;
using ordered = nlohmann::ordered_json;

// A struct's schema (SchemaBuilder, from its `visit`) with only what says which key holds which
// JSON type: the record's docs, choices, bounds and required list are the record's own.
ordered shape(const ordered& s) {
  if (!s.is_object()) return s;
  ordered out = ordered::object();
  for (const auto& [k, v] : s.items())
    if (k == "properties") {
      out[k] = ordered::object();
      for (const auto& [name, p] : v.items()) out[k][name] = shape(p);
    } else if (k != "description" && k != "enum" && k != "minimum" && k != "required") {
      out[k] = shape(v);
    }
  return out;
}

// The record's keys the summary leaves to its `json` text: the scene as run is a JSON object of
// every scene field, which the installed header (the standard library only) has no type for.
const std::vector<std::string> kOnlyInJson = {"scene_spec"};

// A field added to RunRecord's `visit` fails here until RunSummary (and its `visit`) has it.
TEST(LibrarySummary, ListsEveryFieldOfTheRecordUnderItsKeyAndType) {
  ordered record = shape(SchemaBuilder::object<RunRecord>("object"));
  ordered summary = shape(SchemaBuilder::object<RunSummary>("object"));
  for (const std::string& k : kOnlyInJson) record["properties"].erase(k);
  // "format" is the summary's own field; the record's to_json writes it beside its list.
  ASSERT_TRUE(summary["properties"].contains("format"));
  summary["properties"].erase("format");
  for (const auto& [k, p] : record["properties"].items()) {
    ASSERT_TRUE(summary["properties"].contains(k))
        << "RunRecord's field " << k << " is not in the library's RunSummary (include/tippe/tippe.h)";
    EXPECT_EQ(summary["properties"][k], p) << k << ": the summary's type differs from the record's";
  }
  for (const auto& [k, p] : summary["properties"].items())
    EXPECT_TRUE(record["properties"].contains(k)) << "RunSummary's field " << k << " is no field of the record";
  EXPECT_EQ(summary.dump(), record.dump()) << "the same fields in the same order";
}

// Every value of a record with a distinct value per field arrives in the summary under its key.
TEST(LibrarySummary, CarriesEveryValueOfTheRecord) {
  const RunRecord r = filled<RunRecord>();
  const RunSummary s = to_summary(r);
  json want = to_json(r);
  EXPECT_EQ(s.json, want.dump(2) + "\n");
  for (const std::string& k : kOnlyInJson) want.erase(k);
  EXPECT_EQ(JsonWriter::write(s), want);
  EXPECT_EQ(s.format, kRunRecordFormat);
  EXPECT_EQ(s.scene, r.scene_name);
  EXPECT_EQ(s.normal_work, r.normal_work);
  EXPECT_EQ(s.numerical_energy_final, r.numerical_energy_final);
  EXPECT_EQ(s.ledger_not_available, r.ledger_not_available);
  ASSERT_TRUE(s.ledger_at_inversion.has_value());
  EXPECT_EQ(s.ledger_at_inversion->numerical_energy, r.ledger_at_inversion->numerical_energy);
  ASSERT_EQ(s.events.size(), r.events.size());
  EXPECT_EQ(s.events[1].value, r.events[1].value);
  EXPECT_EQ(s.settings.at("setting"), r.settings.at(0).second);
  EXPECT_EQ(s.provenance.hostname, r.provenance.hostname);
  EXPECT_EQ(s.work.solver_iterations, r.work.solver_iterations);
}

// A term the simulator cannot give (JSON null) is NaN, an absent part std::nullopt.
TEST(LibrarySummary, AbsentValuesAreNanAndNullopt) {
  const RunSummary s = to_summary(RunRecord{});
  EXPECT_TRUE(std::isnan(s.friction_work));
  EXPECT_TRUE(std::isnan(s.elastic_energy_max));
  EXPECT_FALSE(s.ledger_at_inversion.has_value());
  EXPECT_FALSE(s.inversion_time.has_value());
}

// ---- the Python stub ---------------------------------------------------------------------------

// The Python type of each field as the module gives it (python/tippe/_objects.py: a record's
// JSON with its keys as attributes, nested objects as Records, null as None).
class PythonTypes {
 public:
  std::vector<std::pair<std::string, std::string>> fields;
  void operator()(const Field& f, const std::string&) { add(f, f.is_empty_as_null() ? "str | None" : "str"); }
  void operator()(const Field& f, const double&) { add(f, "float | None"); }  // non-finite: null
  void operator()(const Field& f, const std::optional<double>&) { add(f, "float | None"); }
  void operator()(const Field& f, const long long&) { add(f, "int"); }
  void operator()(const Field& f, const std::optional<long long>&) { add(f, "int | None"); }
  void operator()(const Field& f, const bool&) { add(f, "bool"); }
  void operator()(const Field& f, const std::vector<std::string>&) { add(f, "list[str]"); }
  void operator()(const Field& f, const json&) { add(f, "dict[str, Any]"); }
  void operator()(const Field& f, const SettingsList&) { add(f, "dict[str, str]"); }
  template <class T, std::enable_if_t<has_visit<T>::value, int> = 0>
  void operator()(const Field& f, const T&) { add(f, "Record"); }
  template <class T>
  void operator()(const Field& f, const std::optional<T>&) { add(f, "Record | None"); }
  template <class T>
  void operator()(const Field& f, const std::vector<T>&) { add(f, "list[Record]"); }

 private:
  void add(const Field& f, const char* type) { fields.emplace_back(f.key(), type); }
};

// python/tippe/__init__.pyi types RunResult with every field of summary.json: the class's body
// is the one generated here from RunRecord's `visit`.
TEST(LibrarySummary, PythonStubTypesEveryFieldOfTheRecord) {
  PythonTypes types;
  types.fields.emplace_back("format", "str");
  const RunRecord r{};
  visit(r, types);
  std::string want = "class RunResult(Record):\n    trajectory: Trajectory\n";
  for (const auto& [key, type] : types.fields) want += "    " + key + ": " + type + "\n";
  const std::string stub = slurp(fs::path(TIPPE_SOURCE_DIR) / "python" / "tippe" / "__init__.pyi");
  const size_t at = stub.find("class RunResult(Record):\n");
  ASSERT_NE(at, std::string::npos);
  const size_t end = stub.find("\n\n", at);
  ASSERT_NE(end, std::string::npos);
  EXPECT_EQ(stub.substr(at, end + 1 - at), want) << "python/tippe/__init__.pyi's RunResult should read:\n" << want;
}

}  // namespace
}  // namespace tippe
