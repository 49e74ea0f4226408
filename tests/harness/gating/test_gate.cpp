// Tests of `tippe gate`: the metric table, evaluation on fixture records, table/JUnit/JSON output, gate-file validation and the command end to end.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <memory>
#include <regex>
#include <set>
#include <sstream>

#include "harness/measure/compare.h"
#include "harness/gating/gate.h"
#include "engines/core/registry.h"
#include "harness/records/records.h"
#include "harness/io/scene_io.h"
#include "tests/support/files.h"

namespace fs = std::filesystem;
using namespace tippe;
using nlohmann::json;

namespace {

const std::string kSource = TIPPE_SOURCE_DIR;
const std::string kBinary = std::string(TIPPE_BINARY_DIR) + "/tippe";
const std::string kScene = kSource + "/harness/scenes/source_dimensionless.toml";

struct Exit {
  int code = -1;
  std::string out, err;
};

// Runs the built binary with stdout and stderr captured separately (the table goes to stdout,
// errors and progress to stderr).
Exit run_tippe(const std::string& args, const fs::path& dir) {
  const fs::path out = dir / "stdout.txt", err = dir / "stderr.txt";
  const std::string cmd = kBinary + " " + args + " >" + out.string() + " 2>" + err.string();
  const int rc = std::system(cmd.c_str());
  Exit e;
  e.code = WIFEXITED(rc) ? WEXITSTATUS(rc) : -1;
  e.out = slurp(out);
  e.err = slurp(err);
  return e;
}

// ---- a small XML reader, so that the JUnit output is parsed, not pattern-matched -------------

struct XmlElement {
  std::string name;
  std::map<std::string, std::string> attrs;
  std::vector<std::unique_ptr<XmlElement>> children;
  std::string text;
  std::vector<const XmlElement*> all(const std::string& n) const {
    std::vector<const XmlElement*> out;
    if (name == n) out.push_back(this);
    for (const auto& c : children)
      for (const XmlElement* e : c->all(n)) out.push_back(e);
    return out;
  }
};

// Throws std::runtime_error on anything that is not well-formed (unbalanced tags, a raw '<' or a
// stray '&' in text or attributes, an unknown entity, control characters).
class XmlReader {
 public:
  explicit XmlReader(std::string s) : s_(std::move(s)) {}
  std::unique_ptr<XmlElement> document() {
    skip_space();
    if (s_.compare(i_, 5, "<?xml") == 0) {
      const size_t end = s_.find("?>", i_);
      if (end == std::string::npos) fail("unterminated prolog");
      i_ = end + 2;
    }
    skip_space();
    auto root = element();
    skip_space();
    if (i_ != s_.size()) fail("content after the root element");
    return root;
  }

 private:
  [[noreturn]] void fail(const std::string& why) const {
    throw std::runtime_error("XML at " + std::to_string(i_) + ": " + why);
  }
  void skip_space() {
    while (i_ < s_.size() && std::isspace(static_cast<unsigned char>(s_[i_]))) ++i_;
  }
  std::string name() {
    const size_t b = i_;
    while (i_ < s_.size() && (std::isalnum(static_cast<unsigned char>(s_[i_])) || s_[i_] == '_' || s_[i_] == '-' ||
                              s_[i_] == ':' || s_[i_] == '.'))
      ++i_;
    if (b == i_) fail("expected a name");
    return s_.substr(b, i_ - b);
  }
  // Character data up to `stop`, entities decoded.
  std::string chars(char stop) {
    std::string out;
    while (i_ < s_.size() && s_[i_] != stop) {
      const char c = s_[i_];
      if (c == '<') fail("raw '<' in character data");
      if (static_cast<unsigned char>(c) < 0x20 && c != '\n' && c != '\t' && c != '\r') fail("control character");
      if (c == '&') {
        const size_t semi = s_.find(';', i_);
        if (semi == std::string::npos) fail("stray '&'");
        const std::string ent = s_.substr(i_ + 1, semi - i_ - 1);
        static const std::map<std::string, std::string> named = {
            {"amp", "&"}, {"lt", "<"}, {"gt", ">"}, {"quot", "\""}, {"apos", "'"}};
        if (auto it = named.find(ent); it != named.end())
          out += it->second;
        else if (ent.size() > 1 && ent[0] == '#')
          out += static_cast<char>(ent[1] == 'x' ? std::stoi(ent.substr(2), nullptr, 16) : std::stoi(ent.substr(1)));
        else
          fail("unknown entity &" + ent + ";");
        i_ = semi + 1;
        continue;
      }
      out += c;
      ++i_;
    }
    return out;
  }
  std::unique_ptr<XmlElement> element() {
    if (i_ >= s_.size() || s_[i_] != '<') fail("expected '<'");
    ++i_;
    auto e = std::make_unique<XmlElement>();
    e->name = name();
    for (;;) {
      skip_space();
      if (s_.compare(i_, 2, "/>") == 0) {
        i_ += 2;
        return e;
      }
      if (i_ < s_.size() && s_[i_] == '>') {
        ++i_;
        break;
      }
      const std::string key = name();
      skip_space();
      if (i_ >= s_.size() || s_[i_] != '=') fail("expected '='");
      ++i_;
      skip_space();
      if (i_ >= s_.size() || s_[i_] != '"') fail("expected '\"'");
      ++i_;
      const std::string value = chars('"');
      if (i_ >= s_.size()) fail("unterminated attribute");
      ++i_;
      if (!e->attrs.emplace(key, value).second) fail("repeated attribute " + key);
    }
    for (;;) {
      e->text += chars('<');
      if (i_ >= s_.size()) fail("unterminated element " + e->name);
      if (s_.compare(i_, 2, "</") == 0) {
        i_ += 2;
        if (name() != e->name) fail("mismatched end tag for " + e->name);
        skip_space();
        if (i_ >= s_.size() || s_[i_] != '>') fail("expected '>'");
        ++i_;
        return e;
      }
      e->children.push_back(element());
    }
  }
  std::string s_;
  size_t i_ = 0;
};

std::unique_ptr<XmlElement> parse_xml(const std::string& text) { return XmlReader(text).document(); }

// ---- fixtures ---------------------------------------------------------------------------------

Check fixture_check() {
  Check c;
  c.name = "ode-fixture";
  c.scene = "../scenes/fixture.toml";
  c.engine = "ode";
  c.require_same_events = false;
  c.max = {{"inversion_time_rel_error", 0.01}, {"tilt_rms_error", 0.05}, {"energy_gain_events", 0}};
  return c;
}

RunRecord fixture_record(const std::string& engine, std::optional<double> inversion) {
  RunRecord r;
  r.engine = engine;
  r.status = "ok";
  r.inversion_time = inversion;
  r.work.wall_seconds = 0.25;
  return r;
}

Metrics fixture_metrics() {
  Metrics m;
  m.inversion_event = "both";
  m.stem_contact_event = "neither";
  m.inversion_time_abs_error = 0.017;
  m.inversion_time_rel_error = 0.001;
  m.tilt_rms_error = 0.02;
  m.tilt_max_error = 0.04;
  m.compared_until = 18.0;
  m.steps = 180000;
  return m;
}

const GateRow* row(const CheckResult& r, const std::string& metric) {
  for (const GateRow& g : r.rows)
    if (g.metric == metric) return &g;
  return nullptr;
}

}  // namespace

// ---- the metric table -----------------------------------------------------------------------------

TEST(GateMetrics, AreTheNumericMetricsButWallClock) {
  // to_json(Metrics) lists every field: the gate table must follow it when a metric is added.
  std::set<std::string> expected;
  const json all = to_json(Metrics{});
  for (const auto& [k, v] : all.items())
    if (!v.is_string() && k != "wall_seconds" && k != "cpu_seconds" && k != "real_time_factor" &&
        k != "reference_converged_until" &&  // the reference's, not the engine's: it marks rows instead
        // The event alignment: its counts of events on each side and of matches describe the
        // sequences (missing and extra judge them), the first wrong event is a text gated by
        // require_no_wrong_event, the dwell is a setting of the bench.
        k != "events_reference" && k != "events_engine" && k != "events_matched" && k != "first_wrong_event" &&
        k != "first_wrong_event_index" && k != "event_min_dwell" && k != "event_alignment" && k != "event_alignment_rows")
      expected.insert(k);
  std::set<std::string> names;
  for (const GateMetric& g : gate_metrics()) EXPECT_TRUE(names.insert(g.name).second) << g.name << " listed twice";
  EXPECT_EQ(names, expected);
  for (const char* timing : {"wall_seconds", "cpu_seconds", "real_time_factor"})
    EXPECT_EQ(find_gate_metric(timing), nullptr) << timing;
}

TEST(GateMetrics, EachAccessorReadsItsOwnField) {
  json j = to_json(Metrics{});
  double v = 1.0;
  for (auto& [k, x] : j.items())
    if (k == "first_wrong_event") x = "reference: inversion at t=1, engine: none";
    else if (x.is_array()) continue;  // the aligned rows, no gate metric
    else if (!x.is_string())
      x = (k == "steps" || k == "energy_gain_events" || k.rfind("events_", 0) == 0 || k == "first_wrong_event_index" ||
               k == "event_alignment_rows")
              ? json(static_cast<long long>(v++))
              : json(v++ + 0.5);
  const Metrics m = metrics_from_json(j);
  for (const GateMetric& g : gate_metrics()) {
    const auto got = g.get(m);
    ASSERT_TRUE(got.has_value()) << g.name;
    EXPECT_EQ(*got, j.at(g.name).get<double>()) << g.name;
  }
}

// ---- evaluation (pure) ------------------------------------------------------------------------------

TEST(GateEvaluate, PassesWithinEveryThreshold) {
  const CheckResult r = evaluate_check(fixture_check(), fixture_record("analytic", 17.25),
                                       fixture_record("ode", 17.27), fixture_metrics());
  EXPECT_TRUE(r.passed);
  ASSERT_EQ(r.rows.size(), 4u);  // status + three thresholds, no event rows
  EXPECT_EQ(r.rows[0].metric, "status");
  EXPECT_EQ(r.name, "ode-fixture");
  EXPECT_EQ(r.engine, "ode");
  EXPECT_DOUBLE_EQ(r.seconds, 0.25);
  for (const GateRow& g : r.rows) EXPECT_TRUE(g.passed && g.message.empty()) << g.metric << ": " << g.message;
  EXPECT_EQ(row(r, "tilt_rms_error")->measured, "0.02");
  EXPECT_EQ(row(r, "tilt_rms_error")->required, "0.05");
}

TEST(GateEvaluate, ThresholdFailsAboveAndPassesAtEquality) {
  Metrics m = fixture_metrics();
  m.tilt_rms_error = 0.0812;
  m.energy_gain_events = 0;
  CheckResult r = evaluate_check(fixture_check(), fixture_record("analytic", 17.25), fixture_record("ode", 17.27), m);
  EXPECT_FALSE(r.passed);
  const GateRow* t = row(r, "tilt_rms_error");
  ASSERT_NE(t, nullptr);
  EXPECT_FALSE(t->passed);
  EXPECT_EQ(*t->value, 0.0812);
  EXPECT_EQ(*t->limit, 0.05);
  EXPECT_EQ(t->message, "tilt_rms_error 0.0812 > 0.05");
  EXPECT_TRUE(row(r, "inversion_time_rel_error")->passed);

  m.tilt_rms_error = 0.05;  // the threshold is the largest accepted value
  r = evaluate_check(fixture_check(), fixture_record("analytic", 17.25), fixture_record("ode", 17.27), m);
  EXPECT_TRUE(r.passed);
}

TEST(GateEvaluate, ComparesAbsoluteValues) {
  Metrics m = fixture_metrics();
  m.inversion_time_rel_error = -0.009;  // engine early, within 1 %
  CheckResult r = evaluate_check(fixture_check(), fixture_record("analytic", 17.25), fixture_record("ode", 17.1), m);
  EXPECT_TRUE(r.passed);
  m.inversion_time_rel_error = -0.02;
  r = evaluate_check(fixture_check(), fixture_record("analytic", 17.25), fixture_record("ode", 16.9), m);
  EXPECT_FALSE(r.passed);
  EXPECT_EQ(row(r, "inversion_time_rel_error")->message, "inversion_time_rel_error |-0.02| > 0.01");
}

TEST(GateEvaluate, AbsentEventErrorFailsWithTheReason) {
  Metrics m = fixture_metrics();
  m.inversion_event = "engine_only";
  m.inversion_time_abs_error.reset();
  m.inversion_time_rel_error.reset();
  CheckResult r = evaluate_check(fixture_check(), fixture_record("analytic", std::nullopt), fixture_record("ode", 17.3), m);
  EXPECT_FALSE(r.passed);
  const GateRow* g = row(r, "inversion_time_rel_error");
  EXPECT_FALSE(g->passed);
  EXPECT_FALSE(g->value.has_value());
  EXPECT_EQ(g->measured, "absent");
  EXPECT_EQ(g->message, "inversion_time_rel_error: absent (engine_only: the engine inverts, the reference does not)");

  m.inversion_event = "reference_only";
  r = evaluate_check(fixture_check(), fixture_record("analytic", 17.25), fixture_record("ode", std::nullopt), m);
  EXPECT_EQ(row(r, "inversion_time_rel_error")->message,
            "inversion_time_rel_error: absent (reference_only: the reference inverts, the engine does not)");
  // Neither side inverting leaves nothing to bound either: the threshold cannot be met.
  m.inversion_event = "neither";
  r = evaluate_check(fixture_check(), fixture_record("analytic", std::nullopt), fixture_record("ode", std::nullopt), m);
  EXPECT_FALSE(r.passed);
  EXPECT_EQ(row(r, "inversion_time_rel_error")->message,
            "inversion_time_rel_error: absent (neither: neither the engine nor the reference inverts)");

  Check c = fixture_check();
  c.max = {{"stem_contact_time_abs_error", 1.0}, {"jellett_drift_stem", 1.0}};
  m.stem_contact_event = "reference_only";
  r = evaluate_check(c, fixture_record("analytic", 17.25), fixture_record("ode", 17.3), m);
  EXPECT_EQ(row(r, "stem_contact_time_abs_error")->message,
            "stem_contact_time_abs_error: absent (reference_only: the reference reaches stem contact, the engine does "
            "not)");
  EXPECT_EQ(row(r, "jellett_drift_stem")->message, "jellett_drift_stem: absent (the engine never rolled on the stem)");
}

TEST(GateEvaluate, NotANumberFails) {
  Metrics m = fixture_metrics();
  m.tilt_rms_error = std::numeric_limits<double>::quiet_NaN();
  m.compared_until = std::numeric_limits<double>::quiet_NaN();
  const CheckResult r = evaluate_check(fixture_check(), fixture_record("analytic", 17.25), fixture_record("ode", 17.3), m);
  EXPECT_FALSE(r.passed);
  EXPECT_EQ(row(r, "tilt_rms_error")->measured, "nan");
  EXPECT_EQ(row(r, "tilt_rms_error")->message, "tilt_rms_error: no samples in common with the reference");
}

TEST(GateEvaluate, RequireSameEvents) {
  Check c = fixture_check();
  c.max.clear();
  c.require_same_events = true;
  Metrics m = fixture_metrics();  // inversion both, stem contact neither: both acceptable
  CheckResult r = evaluate_check(c, fixture_record("analytic", 17.25), fixture_record("ode", 17.3), m);
  EXPECT_TRUE(r.passed);
  ASSERT_NE(row(r, "inversion_event"), nullptr);
  EXPECT_EQ(row(r, "stem_contact_event")->measured, "neither");

  m.stem_contact_event = "engine_only";
  r = evaluate_check(c, fixture_record("analytic", 17.25), fixture_record("ode", 17.3), m);
  EXPECT_FALSE(r.passed);
  EXPECT_FALSE(row(r, "stem_contact_event")->passed);
  EXPECT_EQ(row(r, "stem_contact_event")->message,
            "stem_contact_event engine_only (the engine reaches stem contact, the reference does not; required on "
            "both sides or neither)");
}

TEST(GateEvaluate, RunStatus) {
  Check c = fixture_check();
  c.max.clear();
  RunRecord eng = fixture_record("ode", std::nullopt);
  eng.status = "diverged";
  eng.status_time = 3.5;
  eng.status_detail = "|omega| > 1e6";
  CheckResult r = evaluate_check(c, fixture_record("analytic", 17.25), eng, fixture_metrics());
  EXPECT_FALSE(r.passed);
  EXPECT_EQ(r.rows[0].measured, "diverged");
  EXPECT_EQ(r.rows[0].message, "status diverged at t = 3.5 (|omega| > 1e6), required ok");
  // A gate may require a status, e.g. that a setting far outside the stable range is caught.
  c.status = "diverged";
  r = evaluate_check(c, fixture_record("analytic", 17.25), eng, fixture_metrics());
  EXPECT_TRUE(r.passed);
}

TEST(GateEvaluate, ErrorResultFails) {
  const CheckResult r = error_result(fixture_check(), "reference run failed: boom");
  EXPECT_FALSE(r.passed);
  ASSERT_EQ(r.rows.size(), 1u);
  EXPECT_EQ(r.rows[0].kind, GateRowKind::Error);
  EXPECT_EQ(r.rows[0].message, "run: reference run failed: boom");
}

// ---- renderings -----------------------------------------------------------------------------

namespace {

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
// and the committed schema (schemas/gate-result.schema.json, written by hand) describes each of
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

// ---- gate files -------------------------------------------------------------------------------

namespace {

// A gate directory beside a copy of the scene, so that relative scene paths are exercised.
struct GateDir {
  TempDir tmp{"tippe-gate"};
  fs::path gate;
  GateDir() {
    fs::create_directories(tmp.path() / "scenes");
    fs::copy_file(kScene, tmp.path() / "scenes" / "source.toml");
    gate = tmp.path() / "gates" / "g.toml";
  }
  std::string write(const std::string& text) {
    spit(gate, text);
    return gate.string();
  }
};

}  // namespace

TEST(GateFile, DefaultsMergeUnderEachCheck) {
  GateDir d;
  const GateFile g = load_gate_file(d.write(R"(# fixture
[defaults]
scene = "../scenes/source.toml"
duration = 2.0
set = ["contact.k=2.0"]
require_same_events = true
[defaults.max]
tilt_rms_error = 0.1
energy_max_error = 0.5

[[check]]
name = "a"
engine = "ode"
set = ["engines.ode.timestep=2e-4"]
[check.max]
energy_max_error = 0.05
steps = 20000

[[check]]
name = "b"
engine = "mujoco"
duration = 1.0
status = "diverged"
require_same_events = false
# an event error without require_same_events is allowed (it fails when the event is missing)
max.inversion_time_rel_error = 0.1
)"));
  ASSERT_EQ(g.checks.size(), 2u);
  const Check& a = g.checks[0];
  EXPECT_EQ(a.scene, "../scenes/source.toml");
  EXPECT_EQ(a.scene_path, (d.tmp.path() / "scenes" / "source.toml").lexically_normal().string());
  EXPECT_EQ(a.overrides, (std::vector<std::string>{"run.duration=2.0", "contact.k=2.0", "engines.ode.timestep=2e-4"}));
  EXPECT_EQ(a.status, "ok");
  EXPECT_TRUE(a.require_same_events);
  EXPECT_DOUBLE_EQ(a.loaded.run.duration, 2.0);
  EXPECT_DOUBLE_EQ(a.loaded.contact.k, 2.0);
  ASSERT_EQ(a.max.size(), 3u);  // in the metric table's order, the check's own value winning
  EXPECT_EQ(a.max[0].metric, "tilt_rms_error");
  EXPECT_EQ(a.max[1].metric, "energy_max_error");
  EXPECT_EQ(a.max[1].max, 0.05);
  EXPECT_EQ(a.max[2].metric, "steps");
  const Check& b = g.checks[1];
  EXPECT_EQ(b.engine, "mujoco");
  EXPECT_EQ(b.status, "diverged");
  EXPECT_FALSE(b.require_same_events);
  EXPECT_EQ(b.overrides.front(), "run.duration=1.0");
  EXPECT_DOUBLE_EQ(b.loaded.run.duration, 1.0);
  EXPECT_EQ(b.max.front().metric, "inversion_time_rel_error");
}

TEST(GateFile, ShippedGateFilesLoad) {
  for (const char* f : {"harness/gates/default.toml", "harness/gates/examples/failing.toml"}) {
    GateFile g;
    ASSERT_NO_THROW(g = load_gate_file(kSource + "/" + f)) << f;
    EXPECT_FALSE(g.checks.empty()) << f;
  }
}

// Every malformed gate file exits 2 with "FILE: KEY: reason" on stderr and writes nothing.
TEST(GateCommand, MalformedGateFilesExit2WithFileAndKey) {
  struct Case {
    const char* what;
    std::string text;
    std::string key;     // as it must follow "FILE: "
    std::string reason;  // a fragment of what follows the key
  };
  const std::string head = "[[check]]\nname = \"a\"\nscene = \"../scenes/source.toml\"\nengine = \"ode\"\n";
  const std::vector<Case> cases = {
      {"empty file", "# nothing\n", "check", "no checks"},
      {"empty check array", "check = []\n", "check", "no checks"},
      {"check not tables", "check = 3\n", "check", "expected [[check]] tables, got an integer"},
      {"unknown top-level key", head + "[thresholds]\nx = 1\n", "thresholds", "unknown key"},
      {"unknown check key", head + "engnie = \"ode\"\n", "check[0].engnie", "unknown key"},
      {"unknown defaults key", "[defaults]\nname = \"x\"\n" + head, "defaults.name", "unknown key"},
      {"wrong type", "[[check]]\nname = 3\n", "check[0].name", "expected a string, got an integer"},
      {"missing name", "[[check]]\nscene = \"../scenes/source.toml\"\nengine = \"ode\"\n", "check[0].name", "missing"},
      {"missing scene", "[[check]]\nname = \"a\"\nengine = \"ode\"\n", "check[0].scene", "missing"},
      {"missing engine", "[[check]]\nname = \"a\"\nscene = \"../scenes/source.toml\"\n", "check[0].engine", "missing"},
      {"unknown engine", "[[check]]\nname = \"a\"\nscene = \"../scenes/source.toml\"\nengine = \"physx\"\n",
       "check[0].engine", "unknown engine \"physx\""},
      {"reference is no engine", "[[check]]\nname = \"a\"\nscene = \"../scenes/source.toml\"\nengine = \"analytic\"\n",
       "check[0].engine", "unknown engine"},
      {"duplicate names", head + head, "check[1].name", "already the name of check[0]"},
      {"negative threshold", head + "[check.max]\ntilt_rms_error = -0.1\n", "check[0].max.tilt_rms_error",
       "-0.1 is out of range (expected tilt_rms_error >= 0"},
      {"nan threshold", head + "[check.max]\ntilt_rms_error = nan\n", "check[0].max.tilt_rms_error", "nan"},
      {"infinite threshold", head + "[check.max]\ntilt_rms_error = inf\n", "check[0].max.tilt_rms_error", "finite"},
      {"threshold not a number", head + "[check.max]\ntilt_rms_error = \"0.1\"\n", "check[0].max.tilt_rms_error",
       "expected a number, got a string"},
      {"unknown metric", head + "[check.max]\ntilt_error = 0.1\n", "check[0].max.tilt_error", "unknown metric"},
      {"wall clock", head + "[check.max]\nwall_seconds = 10\n", "check[0].max.wall_seconds", "never gated"},
      {"max not a table", head + "max = 0.1\n", "check[0].max", "expected a table"},
      {"threshold in defaults", "[defaults.max]\nsteps = -1\n" + head, "defaults.max.steps", "-1 is out of range (expected steps >= 0"},
      {"bad status", head + "status = \"fine\"\n", "check[0].status", "unknown run status \"fine\""},
      {"bad boolean", head + "require_same_events = \"yes\"\n", "check[0].require_same_events",
       "expected true or false"},
      {"scene file missing", "[[check]]\nname = \"a\"\nscene = \"../scenes/nope.toml\"\nengine = \"ode\"\n",
       "check[0].scene", "cannot read"},
      {"scene invalid", "[[check]]\nname = \"a\"\nscene = \"../scenes/bad.toml\"\nengine = \"ode\"\n", "check[0].scene",
       "colour: unknown key"},
      {"invalid override value", head + "set = [\"engines.ode.timestep=-1\"]\n", "check[0].set[0]",
       "engines.ode.timestep"},
      {"invalid override key", head + "set = [\"contact.nosuch=1\"]\n", "check[0].set[0]", "contact.nosuch"},
      {"malformed override", head + "set = [\"nonsense\"]\n", "check[0].set[0]", "malformed override"},
      {"another engine's setting", head + "set = [\"engines.mujoco.timestep=1e-4\"]\n", "check[0].set[0]",
       "is a setting of mujoco"},
      {"override twice", head + "set = [\"contact.k=1\", \"contact.k=2\"]\n", "check[0].set[1]", "set twice"},
      {"default override breaks the scene", "[defaults]\nset = [\"body.sphere_radius=-1\"]\n" + head,
       "defaults.set[0]", "body.sphere_radius"},
      {"duration not positive", "[defaults]\nduration = 0\n" + head, "defaults.duration", "0 is out of range (expected duration > 0)"},
      {"duration below the sample interval", head + "duration = 0.001\n", "check[0].duration", "sample_interval"},
      {"bad name", "[[check]]\nname = \"a b\"\n", "check[0].name", "not a usable name"},
  };
  GateDir d;
  spit(d.tmp.path() / "scenes" / "bad.toml", "colour = \"red\"\n" + slurp(kScene));
  const fs::path junit = d.tmp.path() / "out" / "junit.xml", json_out = d.tmp.path() / "out" / "gate.json";
  for (const Case& c : cases) {
    SCOPED_TRACE(c.what);
    const std::string file = d.write(c.text);
    // The direct call and the command agree on the message.
    try {
      load_gate_file(file);
      ADD_FAILURE() << "no error for: " << c.text;
    } catch (const SceneError& e) {
      EXPECT_EQ(std::string(e.what()).rfind(file + ": " + c.key + ": ", 0), 0u) << e.what();
      EXPECT_NE(std::string(e.what()).find(c.reason), std::string::npos) << e.what();
    }
    const Exit e = run_tippe("gate " + file + " --junit " + junit.string() + " --json " + json_out.string() +
                                 " --cache " + (d.tmp.path() / "cache").string(),
                             d.tmp.path());
    EXPECT_EQ(e.code, 2) << e.err;
    EXPECT_NE(e.err.find(file + ": " + c.key + ": "), std::string::npos) << e.err;
    EXPECT_NE(e.err.find(c.reason), std::string::npos) << e.err;
    EXPECT_TRUE(e.out.empty()) << e.out;
    EXPECT_FALSE(fs::exists(junit));
    EXPECT_FALSE(fs::exists(json_out));
    EXPECT_FALSE(fs::exists(d.tmp.path() / "out"));
    EXPECT_FALSE(fs::exists(d.tmp.path() / "cache"));
  }
}

TEST(GateCommand, OtherInputErrorsExit2) {
  GateDir d;
  const Exit missing = run_tippe("gate " + (d.tmp.path() / "missing.toml").string(), d.tmp.path());
  EXPECT_EQ(missing.code, 2);
  EXPECT_NE(missing.err.find("missing.toml: cannot read"), std::string::npos) << missing.err;

  const std::string file = d.write("[[check]]\nname = \"a\"\nscene = \"../scenes/source.toml\"\nengine = \"ode\"\n[check\n");
  const Exit syntax = run_tippe("gate " + file, d.tmp.path());
  EXPECT_EQ(syntax.code, 2);
  EXPECT_NE(syntax.err.find(file + ":5:"), std::string::npos) << syntax.err;

  const std::string good = d.write("[[check]]\nname = \"a\"\nscene = \"../scenes/source.toml\"\nengine = \"ode\"\n");
  const Exit dir = run_tippe("gate " + good + " --junit " + d.tmp.path().string(), d.tmp.path());
  EXPECT_EQ(dir.code, 2);
  EXPECT_NE(dir.err.find("--junit"), std::string::npos) << dir.err;
  const Exit same = run_tippe("gate " + good + " --junit x.out --json x.out", d.tmp.path());
  EXPECT_EQ(same.code, 2);
  EXPECT_NE(same.err.find("same file"), std::string::npos) << same.err;
}

// ---- end to end (runs the engines) ------------------------------------------------------------

namespace {

// Counts in the JUnit file, checked against the JSON results and the table on stdout.
void expect_consistent_reports(const fs::path& junit, const fs::path& json_path, const std::string& table) {
  std::unique_ptr<XmlElement> root;
  ASSERT_NO_THROW(root = parse_xml(slurp(junit))) << slurp(junit);
  const json j = json::parse(slurp(json_path));
  const auto cases = root->all("testcase");
  ASSERT_EQ(cases.size(), j.at("results").size());
  size_t failed = 0, failed_rows = 0;
  for (size_t i = 0; i < cases.size(); ++i) {
    const json& r = j.at("results").at(i);
    EXPECT_EQ(cases[i]->attrs.at("name"), r.at("name").get<std::string>());
    const bool has_failure = !cases[i]->all("failure").empty() || !cases[i]->all("error").empty();
    EXPECT_EQ(has_failure, !r.at("passed").get<bool>()) << r.at("name");
    failed += has_failure;
    for (const json& row : r.at("rows")) failed_rows += !row.at("passed").get<bool>();
  }
  EXPECT_EQ(root->all("testsuite").at(0)->attrs.at("failures"), std::to_string(failed));
  EXPECT_EQ(j.at("failed").get<size_t>(), failed);
  size_t fail_lines = 0;
  std::istringstream in(table);
  for (std::string line; std::getline(in, line);)
    fail_lines += line.size() >= 6 && line.compare(line.size() - 6, 6, "  FAIL") == 0;
  EXPECT_EQ(fail_lines, failed_rows) << table;
}

}  // namespace

TEST(GateCommand, PassingGateExits0) {
  GateDir d;
  // Two checks share the scene and overrides (one comparison, ODE run once); a third has its own
  // duration (a second comparison).
  const std::string file = d.write(R"(
[defaults]
scene = "../scenes/source.toml"
engine = "ode"
duration = 18.0
require_same_events = true
[[check]]
name = "ode-inversion"
max.inversion_time_rel_error = 0.01   # ODE's default: 1.4e-3
[[check]]
name = "ode-energy"
max.energy_max_error = 0.01           # 1.3e-3
max.energy_gain_events = 0
[[check]]
name = "ode-short"
duration = 2.0
max.tilt_rms_error = 0.01
)");
  const fs::path junit = d.tmp.path() / "reports" / "junit.xml", json_out = d.tmp.path() / "reports" / "gate.json";
  const Exit e = run_tippe("gate " + file + " --jobs 2 --junit " + junit.string() + " --json " + json_out.string() +
                               " --cache " + (d.tmp.path() / "cache").string(),
                           d.tmp.path());
  ASSERT_EQ(e.code, 0) << e.out << e.err;
  EXPECT_NE(e.err.find("3 check(s) in 2 comparison(s)"), std::string::npos) << e.err;
  EXPECT_NE(e.out.find("gate: 3 of 3 checks passed"), std::string::npos) << e.out;
  EXPECT_EQ(e.out.find("FAIL"), std::string::npos) << e.out;
  expect_consistent_reports(junit, json_out, e.out);
  const json j = json::parse(slurp(json_out));
  EXPECT_TRUE(j.at("passed").get<bool>());
  EXPECT_EQ(j.at("gate_file"), file);
  // The reference was cached by physics hash: the rerun reads it instead of integrating again.
  EXPECT_FALSE(fs::is_empty(d.tmp.path() / "cache"));
  const Exit again = run_tippe("gate " + file + " --cache " + (d.tmp.path() / "cache").string(), d.tmp.path());
  EXPECT_EQ(again.code, 0) << again.err;
  EXPECT_NE(again.err.find("analytic cached"), std::string::npos) << again.err;
}

TEST(GateCommand, TightThresholdExits1AndNamesTheMetric) {
  TempDir tmp{"tippe-gate"};
  const fs::path junit = tmp.path() / "junit.xml", json_out = tmp.path() / "gate.json";
  const std::string gate = kSource + "/harness/gates/examples/failing.toml";
  const Exit e = run_tippe("gate " + gate + " --junit " + junit.string() + " --json " + json_out.string() +
                               " --cache " + (tmp.path() / "cache").string(),
                           tmp.path());
  ASSERT_EQ(e.code, 1) << e.out << e.err;
  EXPECT_TRUE(std::regex_search(e.out, std::regex("ode-inversion-tight +ode +inversion_time_rel_error +\\S+ +0\\.0001 +FAIL")))
      << e.out;
  EXPECT_NE(e.out.find("ode-inversion-tight: inversion_time_rel_error "), std::string::npos) << e.out;
  EXPECT_NE(e.out.find("gate: 1 of 2 checks passed"), std::string::npos) << e.out;
  expect_consistent_reports(junit, json_out, e.out);
  const auto root = parse_xml(slurp(junit));
  const auto failures = root->all("failure");
  ASSERT_EQ(failures.size(), 1u);
  EXPECT_EQ(failures[0]->attrs.at("message").rfind("inversion_time_rel_error ", 0), 0u);
  EXPECT_NE(failures[0]->attrs.at("message").find(" > 0.0001"), std::string::npos);
  EXPECT_EQ(root->all("testcase").at(0)->attrs.at("classname"), gate);
}

TEST(GateCommand, ShippedDefaultGatesPass) {
  TempDir tmp{"tippe-gate"};
  const Exit e = run_tippe("gate " + kSource + "/harness/gates/default.toml --jobs 2 --cache " +
                               (tmp.path() / "cache").string(),
                           tmp.path());
  EXPECT_EQ(e.code, 0) << e.out << e.err;
  // Two checks (ball, stem) per registered engine.
  const std::string n = std::to_string(2 * engine_names().size());
  EXPECT_NE(e.out.find("gate: " + n + " of " + n + " checks passed"), std::string::npos) << e.out;
}

// ---- the reference's self-check ---------------------------------------------------------------

TEST(GateEvaluate, AWindowPastTheConvergedReferenceFailsUnlessAllowed) {
  Check c = fixture_check();
  c.loaded.run.duration = 23.0;
  c.require_same_events = true;
  Metrics m = fixture_metrics();
  m.reference_converged_until = 21.37;
  m.compared_until = 21.37;
  m.stem_contact_event = "unconverged";
  CheckResult r = evaluate_check(c, fixture_record("analytic", 17.25), fixture_record("ode", 17.27), m);
  EXPECT_FALSE(r.passed);
  const GateRow* tilt = row(r, "tilt_rms_error");
  ASSERT_NE(tilt, nullptr);
  EXPECT_FALSE(tilt->passed);
  EXPECT_NE(tilt->measured.find("compared to t = 21.37 (reference converged)"), std::string::npos) << tilt->measured;
  EXPECT_NE(tilt->message.find("reference not converged after t = 21.37"), std::string::npos) << tilt->message;
  // The inversion (t = 17.25) is inside the window: judged as usual.
  EXPECT_TRUE(row(r, "inversion_time_rel_error")->passed);
  EXPECT_TRUE(row(r, "inversion_event")->passed);
  EXPECT_FALSE(row(r, "stem_contact_event")->passed);
  EXPECT_NE(row(r, "stem_contact_event")->message.find("reference not converged after t = 21.37"), std::string::npos);
  EXPECT_TRUE(row(r, "energy_gain_events")->passed);  // the engine's own: the whole run
  const std::string junit = render_junit({r}, "suite");
  EXPECT_NE(junit.find("reference not converged after t = 21.37"), std::string::npos);
  EXPECT_NE(render_table({r}).find("compared to t = 21.37 (reference converged)"), std::string::npos);

  c.allow_unconverged = true;
  r = evaluate_check(c, fixture_record("analytic", 17.25), fixture_record("ode", 17.27), m);
  EXPECT_TRUE(r.passed) << render_table({r});
  EXPECT_NE(row(r, "tilt_rms_error")->measured.find("compared to t = 21.37"), std::string::npos);
  EXPECT_EQ(row(r, "stem_contact_event")->measured, "unconverged");

  // A window that reaches the check's end, or no self-check at all: nothing is marked.
  c.allow_unconverged = false;
  c.loaded.run.duration = 21.0;
  m.stem_contact_event = "both";
  r = evaluate_check(c, fixture_record("analytic", 17.25), fixture_record("ode", 17.27), m);
  EXPECT_EQ(row(r, "tilt_rms_error")->measured.find("compared to"), std::string::npos);
  m.reference_converged_until.reset();
  r = evaluate_check(c, fixture_record("analytic", 17.25), fixture_record("ode", 17.27), m);
  EXPECT_TRUE(row(r, "tilt_rms_error")->passed);
}

TEST(GateFile, AllowUnconvergedIsABooleanMergedFromDefaults) {
  TempDir d{"tippe-gate"};
  d.write("fixture.toml", slurp(kSource + "/harness/scenes/toy.toml"));
  const GateFile g = load_gate_file(d.write("g.toml", R"(
[defaults]
scene = "fixture.toml"
engine = "ode"
allow_unconverged = true
[[check]]
name = "a"
[[check]]
name = "b"
allow_unconverged = false
)"));
  ASSERT_EQ(g.checks.size(), 2u);
  EXPECT_TRUE(g.checks[0].allow_unconverged);
  EXPECT_FALSE(g.checks[1].allow_unconverged);
  try {
    load_gate_file(d.write("bad.toml", "[[check]]\nname = \"a\"\nscene = \"fixture.toml\"\nengine = \"ode\"\nallow_unconverged = 1\n"));
    FAIL() << "a number for allow_unconverged loaded";
  } catch (const SceneError& e) {
    EXPECT_NE(std::string(e.what()).find("check[0].allow_unconverged: expected true or false"), std::string::npos) << e.what();
  }
}

// ---- the aligned event sequences (measure/event_alignment.h) --------------------------------------

TEST(GateEvaluate, EventTimeBoundPassesAndFails) {
  Check c = fixture_check();
  c.max = {{"event_time_max_error", 0.05}};
  Metrics m = fixture_metrics();
  m.events_reference = 2, m.events_engine = 2, m.events_matched = 2, m.events_missing = 0, m.events_extra = 0;
  m.event_time_max_error = 0.04;
  CheckResult r = evaluate_check(c, fixture_record("analytic", 17.25), fixture_record("ode", 17.29), m);
  EXPECT_TRUE(r.passed) << row(r, "event_time_max_error")->message;
  m.event_time_max_error = 0.06;
  r = evaluate_check(c, fixture_record("analytic", 17.25), fixture_record("ode", 17.31), m);
  EXPECT_FALSE(r.passed);
  EXPECT_EQ(row(r, "event_time_max_error")->message, "event_time_max_error 0.06 > 0.05");
  // A record without the alignment fails the bound with the reason, never passes it.
  m.event_time_max_error.reset();
  r = evaluate_check(c, fixture_record("analytic", 17.25), fixture_record("ode", 17.31), m);
  EXPECT_FALSE(r.passed);
  EXPECT_NE(row(r, "event_time_max_error")->message.find("before the event sequences were aligned"), std::string::npos);
}

TEST(GateEvaluate, RequireNoWrongEvent) {
  Check c = fixture_check();
  c.max.clear();
  c.require_no_wrong_event = true;
  Metrics m = fixture_metrics();
  m.events_reference = 2, m.events_engine = 2, m.events_matched = 2, m.events_missing = 0, m.events_extra = 0;
  m.event_time_max_error = 0.01;
  CheckResult r = evaluate_check(c, fixture_record("analytic", 17.25), fixture_record("ode", 17.3), m);
  EXPECT_TRUE(r.passed);
  ASSERT_NE(row(r, "first_wrong_event"), nullptr);
  EXPECT_EQ(row(r, "first_wrong_event")->measured, "none");

  m.events_matched = 1, m.events_missing = 1, m.events_extra = 1;
  m.first_wrong_event_index = 1;
  m.first_wrong_event = "reference: stem_contact at t=1.23, engine: inversion at t=1.1";
  r = evaluate_check(c, fixture_record("analytic", 17.25), fixture_record("ode", 17.3), m);
  EXPECT_FALSE(r.passed);
  EXPECT_EQ(row(r, "first_wrong_event")->message,
            "first_wrong_event at aligned event 1: reference: stem_contact at t=1.23, engine: inversion at t=1.1 "
            "(1 missing, 1 extra)");
  // Not aligned (an older record): nothing was compared, so it fails.
  r = evaluate_check(c, fixture_record("analytic", 17.25), fixture_record("ode", 17.3), fixture_metrics());
  EXPECT_FALSE(r.passed);
  EXPECT_EQ(row(r, "first_wrong_event")->measured, "absent");
}

TEST(GateFile, EventKeysParsedWithClearErrors) {
  TempDir d{"tippe-gate"};
  d.write("fixture.toml", slurp(kSource + "/harness/scenes/toy.toml"));
  const GateFile g = load_gate_file(d.write("g.toml", R"(
[defaults]
scene = "fixture.toml"
engine = "ode"
require_no_wrong_event = true
[[check]]
name = "a"
[check.max]
event_time_max_error = 0.01
events_missing = 0
[[check]]
name = "b"
require_no_wrong_event = false
)"));
  ASSERT_EQ(g.checks.size(), 2u);
  EXPECT_TRUE(g.checks[0].require_no_wrong_event);
  EXPECT_FALSE(g.checks[1].require_no_wrong_event);
  ASSERT_EQ(g.checks[0].max.size(), 2u);
  const std::string head = "[[check]]\nname = \"a\"\nscene = \"fixture.toml\"\nengine = \"ode\"\n";
  const std::vector<std::pair<std::string, std::string>> bad = {
      {head + "require_no_wrong_event = \"yes\"\n", "check[0].require_no_wrong_event: expected true or false"},
      {head + "[check.max]\nevent_time_max_error = -1\n", "check[0].max.event_time_max_error"},
      {head + "[check.max]\nfirst_wrong_event = 0\n", "check[0].max.first_wrong_event: not a number: require"},
  };
  for (const auto& [text, expected] : bad) {
    try {
      load_gate_file(d.write("bad.toml", text));
      ADD_FAILURE() << "loaded: " << text;
    } catch (const SceneError& e) {
      EXPECT_NE(std::string(e.what()).find(expected), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find("bad.toml"), std::string::npos) << e.what();
    }
  }
}

TEST(GateCommand, BadEventBoundExits2) {
  TempDir d{"tippe-gate"};
  d.write("fixture.toml", slurp(kSource + "/harness/scenes/toy.toml"));
  const std::string gate = d.write("g.toml", "[[check]]\nname = \"a\"\nscene = \"fixture.toml\"\nengine = \"ode\"\n"
                                             "[check.max]\nevent_time_max_error = \"small\"\n");
  const Exit e = run_tippe("gate " + gate, d.path());
  EXPECT_EQ(e.code, 2) << e.err;
  EXPECT_NE(e.err.find("check[0].max.event_time_max_error"), std::string::npos) << e.err;
}
