// Tests of `tippe gate` end to end (harness/cli/cli_gate.cpp): malformed gate files and other input errors exit 2, passing and failing gates exit 0 and 1 with consistent table, JUnit and JSON.
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <cstdlib>
#include <filesystem>
#include <memory>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

#include "engines/core/registry.h"
#include "harness/gating/gate.h"
#include "harness/io/scene_io.h"
#include "tests/support/files.h"
#include "tests/support/gate_fixtures.h"
#include "tests/support/xml_reader.h"

namespace test_cli_gate {

namespace fs = std::filesystem;
using namespace tippe;
using nlohmann::json;

namespace {

using namespace tippe::fixtures;

const std::string kSource = TIPPE_SOURCE_DIR;
const std::string kBinary = std::string(TIPPE_BINARY_DIR) + "/tippe";
const std::string& kScene = kGateScene;

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

TEST(GateCommand, BadEventBoundExits2) {
  TempDir d{"tippe-gate"};
  d.write("fixture.toml", slurp(kSource + "/harness/scenes/toy.toml"));
  const std::string gate = d.write("g.toml", "[[check]]\nname = \"a\"\nscene = \"fixture.toml\"\nengine = \"ode\"\n"
                                             "[check.max]\nevent_time_max_error = \"small\"\n");
  const Exit e = run_tippe("gate " + gate, d.path());
  EXPECT_EQ(e.code, 2) << e.err;
  EXPECT_NE(e.err.find("check[0].max.event_time_max_error"), std::string::npos) << e.err;
}

// ---- end to end (runs the engines) ------------------------------------------------------------

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

}  // namespace test_cli_gate
