// The sweep record's one field list (`visit`, records/sweep_record.h): every field it lists is written, read back and described by the generated schema as its reader reads it, and every published record reads and writes back byte for byte.
#include <gtest/gtest.h>

#include <filesystem>
#include <functional>
#include <set>
#include <sstream>
#include <string>

#include <nlohmann/json.hpp>

#include "harness/records/record_schemas.h"
#include "harness/records/sweep_record.h"
#include "tests/support/field_filler.h"
#include "tests/support/files.h"

namespace tippe::test_sweep_record_fields {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

// Sets every field of a sweep record to a value no other field has and that its reader's checks
// accept (names, labels equal to their numbers, known statuses), so that a field written under
// another's key, or read into another, shows in a round trip.
class SweepFiller {
 public:
  std::set<std::string> keys;  // the dotted key of every field and group
  std::string prefix;

  void operator()(const SweepField& f, std::string& v) {
    add(f);
    switch (f.check()) {
      case SweepField::Check::label: v = json(f.value()).dump(); break;
      case SweepField::Check::status: v = "clamped"; break;
      case SweepField::Check::run_class: v = "unphysical"; break;
      case SweepField::Check::criterion: v = "regime"; break;
      case SweepField::Check::key: v = "engines.ode.key_" + std::to_string(n_++); break;
      default: v = "name_" + std::to_string(n_++);
    }
  }
  void operator()(const SweepField& f, double& v) { add(f), v = 0.5 + n_++; }
  void operator()(const SweepField& f, std::optional<double>& v) { add(f), v = 0.25 + n_++; }
  void operator()(const SweepField& f, long long& v) { add(f), v = f.hi() > 1000 ? n_++ : 2; }
  void operator()(const SweepField& f, int& v) { add(f), v = 3; }
  void operator()(const SweepField& f, bool& v) { add(f), v = true; }
  void operator()(const SweepField& f, std::vector<std::string>& v) { add(f), v = {"set " + std::to_string(n_++)}; }
  void operator()(const SweepField& f, std::vector<double>& v) { add(f), v = {0.125 + n_++, 0.125 + n_++}; }
  void operator()(const SweepField& f, json& v) { add(f), v = {{"setting", std::to_string(n_++)}}; }
  void operator()(const SweepField& f, Metrics& m) { add(f), m = filled<Metrics>(); }
  template <class T>
  void operator()(const SweepField& f, std::optional<T>& part) {
    add(f);
    part = T{};
    SweepFiller inner;
    inner.prefix = prefix + f.key() + ".";
    inner.n_ = n_;
    visit(*part, inner);
    n_ = inner.n_;
    keys.insert(inner.keys.begin(), inner.keys.end());
  }
  template <class Fields>
  void group(const SweepField& f, Fields&& fields) {
    add(f);
    const std::string outer = prefix;
    prefix += std::string(f.key()) + ".";
    fields(*this);
    prefix = outer;
  }

 private:
  void add(const SweepField& f) { EXPECT_TRUE(keys.insert(prefix + f.key()).second) << prefix + f.key() << " listed twice"; }
  int n_ = 1;
};

// The dotted keys of a record's JSON, the metrics as one key (their own list is checked in
// test_record_fields).
void keys_of(const json& j, const std::string& prefix, std::set<std::string>& out) {
  for (const auto& [k, v] : j.items()) {
    out.insert(prefix + k);
    if (v.is_object() && k != "metrics" && k != "settings") keys_of(v, prefix + k + ".", out);
  }
}

// A record filled so; `keys` receives the dotted keys its `visit` lists.
SweepRecord filled_sweep_record(std::set<std::string>* keys = nullptr) {
  SweepRecord r;
  SweepFiller f;
  visit(r, f);
  if (keys) *keys = f.keys;
  // What a search's range must be as a whole: a resolution of at most a decade, whole numbers
  // for an integer search (the filler's are not).
  r.search->resolution = 0.25;
  r.search->integer = false;
  r.grid_value = 7.0;  // the grid's label is the text of its number
  r.grid_label = "7";
  return r;
}

TEST(SweepRecordFields, WritesExactlyItsVisitedFieldsAndReadsEveryOneBack) {
  std::set<std::string> want;
  const SweepRecord r = filled_sweep_record(&want);
  const json j = to_json(r);
  std::set<std::string> written;
  keys_of(j, "", written);
  want.insert("format");
  EXPECT_EQ(written, want);
  const std::string line = to_jsonl(r);
  EXPECT_EQ(to_jsonl(sweep_record_from_json(json::parse(line))), line);
  const SweepRecord back = sweep_record_from_json(j);
  EXPECT_EQ(back.solver_iterations, r.solver_iterations);
  EXPECT_EQ(back.cpu_seconds_repeats, r.cpu_seconds_repeats);
  ASSERT_TRUE(back.search.has_value());
  EXPECT_EQ(back.search->to, r.search->to);
  EXPECT_EQ(back.class_reason, r.class_reason);
  EXPECT_EQ(back.grid_index, r.grid_index);
}

// What a record written before a group or part existed reads as: no grid, the class its status
// implies, no reference, no search, the label the number's text.
TEST(SweepRecordFields, GroupsAndPartsAbsentInOlderRecordsReadAsTheirDefaults) {
  SweepRecord r = filled_sweep_record();
  r.grid_key.clear();
  json j = to_json(r);
  EXPECT_TRUE(j.at("grid").is_null());
  for (const char* k : {"grid", "class", "reference", "search", "ladder_label"}) j.erase(k);
  const SweepRecord back = sweep_record_from_json(j);
  EXPECT_TRUE(back.grid_key.empty());
  EXPECT_EQ(back.run_class, "clamped");  // the status's class
  EXPECT_FALSE(back.reference.has_value());
  EXPECT_FALSE(back.search.has_value());
  EXPECT_EQ(back.ladder_label, json(r.ladder_value).dump());
}

// The committed schema (schemas/sweep-record.schema.json, generated from the list) describes
// every field of the list and no other.
void schema_keys(const json& properties, const std::string& prefix, std::set<std::string>& out) {
  for (const auto& [k, p] : properties.items()) {
    out.insert(prefix + k);
    if (k == "metrics" || k == "settings") continue;
    if (p.contains("properties")) schema_keys(p.at("properties"), prefix + k + ".", out);
    if (p.contains("oneOf"))
      for (const json& alternative : p.at("oneOf"))
        if (alternative.contains("properties")) schema_keys(alternative.at("properties"), prefix + k + ".", out);
  }
}
TEST(SweepRecordFields, TheCommittedSchemaDescribesEveryListedField) {
  std::set<std::string> listed;
  filled_sweep_record(&listed);
  listed.insert("format");
  const json schema = json::parse(slurp(fs::path(TIPPE_SOURCE_DIR) / "schemas" / "sweep-record.schema.json"));
  std::set<std::string> described;
  schema_keys(schema.at("properties"), "", described);
  EXPECT_EQ(described, listed);
}

// The schema and the reader agree on every field: required exactly where a record without it is
// refused, null allowed exactly where the reader takes null. (A field absent or null is the one
// fault of each record tried: the filled record is valid.)
bool reads(const json& j) {
  try {
    sweep_record_from_json(j);
    return true;
  } catch (const SweepRecordError&) {
    return false;
  }
}
TEST(SweepRecordFields, TheSchemaRequiresAndAllowsNullExactlyWhereTheReaderDoes) {
  const json record = to_json(filled_sweep_record());
  ASSERT_TRUE(reads(record));
  const json schema = json::parse(record_schema_text("sweep-record"));
  size_t fields = 0;
  std::function<void(const json&, const json::json_pointer&)> walk = [&](const json& object, const json::json_pointer& at) {
    const json& required = object.at("required");
    for (const auto& [key, p] : object.at("properties").items()) {
      const json::json_pointer field = at / key;
      const std::string name = field.to_string();
      ++fields;
      json without = record;
      without.at(at).erase(key);
      const bool is_required = std::find(required.begin(), required.end(), key) != required.end();
      EXPECT_EQ(reads(without), !is_required) << name << (is_required ? " is required but reads when absent"
                                                                        : " is not required but is refused when absent");
      json nulled = record;
      nulled[field] = nullptr;
      // A value null is "not a number": its label must then be a name (the one rule across fields).
      if (name == "/ladder_value") nulled["ladder_label"] = "a_name";
      if (name == "/grid/value") nulled["grid"]["label"] = "a_name";
      const json type = p.value("type", json());
      const bool may_be_null = type == "null" || (type.is_array() && std::find(type.begin(), type.end(), "null") != type.end());
      EXPECT_EQ(reads(nulled), may_be_null) << name << (may_be_null ? " may be null but is refused null"
                                                                    : " may not be null but reads null");
      if (p.contains("properties")) walk(p, field);
    }
  };
  walk(schema, json::json_pointer());
  EXPECT_GT(fields, 50u);
}

// The published records (reports/sweep-*/records.jsonl) read back, and write back every field
// they hold with the same value: the only difference a JSON diff finds is a field added since
// they were written (the ledger's metrics), and what is written reads back to the same bytes.
TEST(SweepRecordFields, PublishedRecordsWriteBackEveryFieldTheyHold) {
  size_t files = 0, lines = 0;
  for (const auto& d : fs::directory_iterator(fs::path(TIPPE_SOURCE_DIR) / "reports")) {
    const fs::path p = d.path() / "records.jsonl";
    if (d.path().filename().string().rfind("sweep-", 0) != 0 || !fs::exists(p)) continue;
    ++files;
    std::istringstream in(slurp(p));
    std::string line;
    for (size_t n = 1; std::getline(in, line); ++n) {
      if (line.empty()) continue;
      ++lines;
      const json published = json::parse(line);
      const std::string written = to_jsonl(sweep_record_from_json(published));
      for (const json& op : json::diff(published, json::parse(written)))
        ASSERT_EQ(op.at("op"), "add") << p << ":" << n << ": " << op.dump();
      ASSERT_EQ(to_jsonl(sweep_record_from_json(json::parse(written))), written) << p << ":" << n;
    }
  }
  EXPECT_GT(files, 0u);
  EXPECT_GT(lines, 0u);
}

}  // namespace
}  // namespace tippe
