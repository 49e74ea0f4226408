// The shipped scenes, sweeps and gates give the reference's settings in [engines.analytic] (no deprecation note on their runs); the older [run] spelling meets them with a clear refusal.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <string>
#include <vector>

#include "harness/gating/gate.h"
#include "engines/core/registry.h"
#include "harness/io/scene_io.h"
#include "harness/scene/resolve.h"
#include "harness/sweep/sweep.h"

namespace test_reference_settings_spelling {

namespace {

namespace fs = std::filesystem;
using namespace tippe;

const fs::path kHarness = fs::path(TIPPE_SOURCE_DIR) / "harness";
// The older spelling of the reference's settings (analytic/scene.h, RunSpec::alias_keys).
const std::vector<std::string> kOlderKeys = {"run.rtol", "run.atol", "run.method", "run.self_check"};

std::vector<fs::path> files_under(const fs::path& dir) {
  std::vector<fs::path> out;
  for (const auto& e : fs::recursive_directory_iterator(dir))
    if (e.is_regular_file() && e.path().extension() == ".toml") out.push_back(e.path());
  std::sort(out.begin(), out.end());
  return out;
}

// "run.rtol=1e-6" or "run.rtol" names an older key.
bool older_spelling(const std::string& key_or_override) {
  const std::string key = key_or_override.substr(0, key_or_override.find('='));
  return std::find(kOlderKeys.begin(), kOlderKeys.end(), key) != kOlderKeys.end();
}

TEST(ReferenceSettingsSpelling, ShippedScenesUseEnginesAnalytic) {
  const auto scenes = files_under(kHarness / "scenes");
  ASSERT_GE(scenes.size(), 20u);  // 12 top-level scenes, 1 scaled, 13 extremes
  for (const fs::path& p : scenes) {
    const Scene s = load_scene(p.string());
    EXPECT_TRUE(s.run.alias_keys.empty()) << p << " gives run." << s.run.alias_keys.front();
    EXPECT_TRUE(s.engines.count("analytic")) << p << " has no [engines.analytic]";
    EXPECT_TRUE(make_simulator("analytic", s)->notes().empty()) << p;
  }
}

TEST(ReferenceSettingsSpelling, ShippedSweepsAndGatesUseEnginesAnalytic) {
  const auto sweeps = files_under(kHarness / "sweeps");
  ASSERT_GE(sweeps.size(), 5u);
  for (const fs::path& p : sweeps) {
    const SweepPlan plan = load_sweep(p.string());
    for (const SweepSetup& u : plan.spec.setups) {
      EXPECT_FALSE(older_spelling(u.ladder_key)) << p << ": setup " << u.name << " ladders " << u.ladder_key;
      EXPECT_FALSE(older_spelling(u.grid_key)) << p << ": setup " << u.name << " grids " << u.grid_key;
      for (const std::string& o : u.set) EXPECT_FALSE(older_spelling(o)) << p << ": setup " << u.name << " sets " << o;
    }
  }
  const auto gates = files_under(kHarness / "gates");
  ASSERT_GE(gates.size(), 1u);
  for (const fs::path& p : gates) {
    const GateFile g = load_gate_file(p.string());
    for (const Check& c : g.checks) {
      for (const std::string& o : c.set) EXPECT_FALSE(older_spelling(o)) << p << ": check " << c.name << " sets " << o;
      EXPECT_TRUE(c.loaded.run.alias_keys.empty()) << p << ": check " << c.name;
    }
  }
}

// A shipped scene has rtol in [engines.analytic]: the override in the new spelling wins without
// a note, the older one is refused (one of the two would be silently unused) and the message
// says which spelling to use.
TEST(ReferenceSettingsSpelling, OverridesOnAShippedScene) {
  const std::string toy = (kHarness / "scenes" / "toy.toml").string();
  const Scene s = load_scene(toy, {"engines.analytic.rtol=1e-6", "engines.analytic.method=\"dopri5\""});
  EXPECT_EQ(s.run.rtol, 1e-6);
  EXPECT_EQ(s.run.method, "dopri5");
  EXPECT_TRUE(make_simulator("analytic", s)->notes().empty());
  try {
    load_scene(toy, {"run.rtol=1e-6"});
    FAIL() << "run.rtol accepted beside [engines.analytic] rtol";
  } catch (const SceneError& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("toy.toml: engines.analytic.rtol: also given as run.rtol"), std::string::npos) << m;
    EXPECT_NE(m.find("run.rtol was set with --set: set engines.analytic.rtol instead"), std::string::npos) << m;
  }
  // A key the scene does not give ([run] self_check) still reads in the older spelling, noted.
  const Scene old = load_scene(toy, {"run.self_check=false"});
  EXPECT_FALSE(old.run.self_check);
  const auto notes = make_simulator("analytic", old)->notes();
  ASSERT_EQ(notes.size(), 1u);
  EXPECT_NE(notes[0].find("run.self_check: older spelling"), std::string::npos) << notes[0];
}

}  // namespace

}  // namespace test_reference_settings_spelling
