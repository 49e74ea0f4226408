// Tests of a gate's verdicts rendered (harness/gating/gate_check.cpp): the table, JUnit XML parsed back, and JSON against its field lists and the committed schema.
#include <gtest/gtest.h>

#include <filesystem>
#include <memory>
#include <regex>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "harness/gating/gate.h"
#include "harness/io/names.h"
#include "tests/support/files.h"
#include "tests/support/gate_fixtures.h"
#include "tests/support/xml_reader.h"

namespace test_gate_render {

namespace fs = std::filesystem;
using namespace tippe;
using nlohmann::json;

namespace {

using namespace tippe::fixtures;

std::vector<CheckResult> mixed_results() {
  std::vector<CheckResult> out;
  out.push_back(evaluate_check(fixture_check(), fixture_record("analytic", 17.25), fixture_record("ode", 17.27),
                               fixture_metrics()));
  Check tight = fixture_check();
  tight.name = "ode-tight";
  tight.set = {"engines.ode.timestep=1e-3", "description=<a & b>"};
  tight.max = {{"inversion_time_rel_error", 1e-4}, {"tilt_rms_error", 1e-3}};
  out.push_back(
      evaluate_check(tight, fixture_record("analytic", 17.25), fixture_record("ode", 17.27), fixture_metrics()));
  Check errored = fixture_check();
  errored.name = "ode-errored";
  out.push_back(error_result(errored, "reference \"failed\" <badly> & \x01oddly"));
  return out;
}

}  // namespace

TEST(GateRender, TableHasOneRowPerLineAndNamesFailures) {
  const auto results = mixed_results();
  const std::string t = render_table(results);
  size_t rows = 0, fails = 0;
  for (const auto& r : results) {
    rows += r.rows.size();
    for (const auto& g : r.rows) fails += !g.passed;
  }
  std::istringstream in(t);
  size_t seen = 0, seen_fail = 0;
  for (std::string line; std::getline(in, line);) {
    if (std::regex_search(line, std::regex("^ode-\\S+ +ode +\\S+"))) {
      ++seen;
      seen_fail += line.size() >= 4 && line.compare(line.size() - 4, 4, "FAIL") == 0;
    }
  }
  EXPECT_EQ(seen, rows) << t;
  EXPECT_EQ(seen_fail, fails) << t;
  EXPECT_NE(t.find("gate: 1 of 3 checks passed"), std::string::npos) << t;
  EXPECT_NE(t.find("ode-tight: inversion_time_rel_error 0.001 > 0.0001"), std::string::npos) << t;
  EXPECT_NE(t.find("ode-tight: tilt_rms_error 0.02 > 0.001"), std::string::npos) << t;
}

// Bytes that are not UTF-8 (a path, an engine's status detail) would make the document, which
// declares UTF-8, malformed: they are replaced by U+FFFD.
TEST(GateRender, JunitStaysUtf8WhateverTheBytesOfItsNames) {
  auto results = mixed_results();
  results[1].rows.back().message = "detail \xff\xfe bytes";
  results[1].rows.back().passed = false;
  const std::string xml = render_junit(results, "gates/\xff.toml");
  EXPECT_TRUE(is_valid_utf8(xml)) << xml;
  EXPECT_NE(xml.find("gates/\xEF\xBF\xBD.toml"), std::string::npos) << xml;
  EXPECT_EQ(utf8_replaced("a\xff\xc3\xa9"), "a\xEF\xBF\xBD\xc3\xa9");
  EXPECT_EQ(utf8_replaced("\xe2\x82"), "\xEF\xBF\xBD\xEF\xBF\xBD");
}

TEST(GateRender, JunitParsesBackWithMatchingCounts) {
  const auto results = mixed_results();
  const std::string suite = "gates/a&b <\"x\">.toml";
  const std::string xml = render_junit(results, suite);
  std::unique_ptr<XmlElement> root;
  ASSERT_NO_THROW(root = parse_xml(xml)) << xml;
  EXPECT_EQ(root->name, "testsuites");
  const auto suites = root->all("testsuite");
  ASSERT_EQ(suites.size(), 1u);
  const XmlElement& s = *suites[0];
  EXPECT_EQ(s.attrs.at("name"), suite);
  EXPECT_EQ(s.attrs.at("tests"), "3");
  EXPECT_EQ(s.attrs.at("failures"), "1");
  EXPECT_EQ(s.attrs.at("errors"), "1");
  EXPECT_TRUE(s.attrs.count("time"));
  EXPECT_EQ(root->attrs.at("tests"), "3");
  const auto cases = root->all("testcase");
  ASSERT_EQ(cases.size(), results.size());
  for (size_t i = 0; i < cases.size(); ++i) {
    EXPECT_EQ(cases[i]->attrs.at("classname"), suite);
    EXPECT_EQ(cases[i]->attrs.at("name"), results[i].name);
  }
  EXPECT_TRUE(cases[0]->children.empty());
  const auto failures = root->all("failure");
  ASSERT_EQ(failures.size(), 1u);
  EXPECT_EQ(failures[0]->attrs.at("type"), "threshold");
  EXPECT_EQ(failures[0]->attrs.at("message"),
            "inversion_time_rel_error 0.001 > 0.0001; tilt_rms_error 0.02 > 0.001");
  EXPECT_NE(failures[0]->text.find("description=<a & b>"), std::string::npos) << failures[0]->text;
  EXPECT_NE(failures[0]->text.find("pass status = ok"), std::string::npos) << failures[0]->text;
  const auto errors = root->all("error");
  ASSERT_EQ(errors.size(), 1u);
  // The control character cannot be carried by XML 1.0 and is replaced; the rest is kept.
  EXPECT_EQ(errors[0]->attrs.at("message"), "run: reference \"failed\" <badly> & ?oddly");
}

TEST(GateRender, JsonCounts) {
  const auto results = mixed_results();
  const json j = to_json(results);
  EXPECT_EQ(j.at("format"), "tippe-gate-1");
  EXPECT_EQ(j.at("passed"), false);
  EXPECT_EQ(j.at("checks"), 3);
  EXPECT_EQ(j.at("failed"), 2);
  ASSERT_EQ(j.at("results").size(), 3u);
  const json& tight = j.at("results").at(1);
  EXPECT_EQ(tight.at("name"), "ode-tight");
  EXPECT_EQ(tight.at("passed"), false);
  const json& rows = tight.at("rows");
  ASSERT_EQ(rows.size(), 3u);
  EXPECT_EQ(rows.at(1).at("metric"), "inversion_time_rel_error");
  EXPECT_EQ(rows.at(1).at("value"), 0.001);
  EXPECT_EQ(rows.at(1).at("threshold"), 1e-4);
  EXPECT_EQ(rows.at(1).at("kind"), "threshold");
  EXPECT_TRUE(rows.at(0).at("value").is_null());  // the status row has no number
  EXPECT_TRUE(to_json(std::vector<CheckResult>{}).at("passed").get<bool>());
}

// The JSON result writes exactly the fields of CheckResult's and GateRow's field lists (gate.h),
// and the committed schema (schemas/gate-result.schema.json, generated from those lists) describes each of
// them and no other: a field added to a list fails here until the schema has it.
TEST(GateRender, JsonResultIsTheFieldListsAndTheSchemaDescribesThem) {
  const auto keys = [](const std::vector<FieldInfo>& fields) {
    std::set<std::string> k;
    for (const FieldInfo& f : fields) k.insert(f.key);
    return k;
  };
  const auto keys_of = [](const json& object) {
    std::set<std::string> k;
    for (const auto& [key, v] : object.items()) k.insert(key);
    return k;
  };
  const std::set<std::string> result_keys = keys(field_list<CheckResult>()), row_keys = keys(field_list<GateRow>());
  const json j = to_json(mixed_results());
  size_t rows = 0;
  for (const json& r : j.at("results")) {
    EXPECT_EQ(keys_of(r), result_keys);
    for (const json& row : r.at("rows")) {
      EXPECT_EQ(keys_of(row), row_keys);
      ++rows;
    }
  }
  EXPECT_GT(rows, 3u);
  const json schema = json::parse(slurp(fs::path(TIPPE_SOURCE_DIR) / "schemas" / "gate-result.schema.json"));
  const json& result = schema.at("properties").at("results").at("items");
  EXPECT_EQ(keys_of(result.at("properties")), result_keys);
  const json& row = result.at("properties").at("rows").at("items");
  EXPECT_EQ(keys_of(row.at("properties")), row_keys);
  EXPECT_EQ(row.at("properties").at("kind").at("enum"), json(gate_row_kind_names()));
}

}  // namespace test_gate_render
