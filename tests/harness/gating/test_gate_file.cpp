// Tests of reading gate files (harness/gating/gate_file.cpp): defaults merged under each check, the shipped files, and the booleans and event bounds a check may carry.
#include <gtest/gtest.h>

#include <string>
#include <utility>
#include <vector>

#include "harness/gating/gate.h"
#include "harness/io/scene_io.h"
#include "tests/support/files.h"
#include "tests/support/gate_fixtures.h"

namespace test_gate_file {

using namespace tippe;

namespace {

using namespace tippe::fixtures;

const std::string kSource = TIPPE_SOURCE_DIR;

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

}  // namespace test_gate_file
