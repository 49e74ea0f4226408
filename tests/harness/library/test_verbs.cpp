// Tests of the verbs the command line and the Python module share (harness/library): columns kept as numbers, the registry as JSON, compare's input checks.
#include <gtest/gtest.h>

#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <sstream>

#include "harness/io/scene_io.h"
#include "harness/scene/resolve.h"
#include "harness/library/columns.h"
#include "harness/library/verbs.h"
#include "harness/measure/run.h"
#include "harness/records/trajectory.h"
#include "engines/core/registry.h"
#include "tests/support/fixtures.h"

namespace tippe::test_verbs {
namespace {

namespace fs = std::filesystem;
using fixtures::bit_equal;
using fixtures::kScenesDir;

// The columns the Python module hands over as arrays are the numbers trajectory.csv's text reads
// back to, bit for bit (17 significant digits round-trip a double), in the file's column order:
// one list of what a row holds (trajectory_row_values) for both. ODE reports its own contact
// point (the *_engine columns) only while touching, so NaN rows are compared too.
TEST(ColumnTrajectorySink, SameNumbersAsTheCsvText) {
  const Scene scene = load_scene(kScenesDir + "rutstam_ball.toml", {"run.duration=0.2"});
  ColumnTrajectorySink columns;
  CsvTrajectoryText text;
  TrajectorySink both({&columns, &text});
  const RunRecord r = run_scene(scene, "ode", &both);
  std::istringstream in(text.text);
  const CsvTrajectory csv = parse_trajectory_csv(in, "text");
  ASSERT_EQ(columns.columns.columns, csv.columns);
  ASSERT_EQ(columns.columns.surface.size(), static_cast<size_t>(r.samples));
  for (const std::string& c : csv.columns) {
    if (c == "surface") continue;
    const std::vector<double>& got = columns.columns.values.at(c);
    const std::vector<double>& want = csv.column(c);
    ASSERT_EQ(got.size(), want.size()) << c;
    for (size_t i = 0; i < got.size(); ++i)
      ASSERT_TRUE(bit_equal(got[i], want[i]) || (std::isnan(got[i]) && std::isnan(want[i])))
          << c << "[" << i << "]: " << got[i] << " vs " << want[i];
  }
  for (size_t i = 0; i < csv.rows(); ++i)
    ASSERT_EQ(columns.columns.surface[i], to_string(static_cast<Surface>(csv.surface[i]))) << i;
}

// engines_to_json lists the registry: every simulator with each of its settings, a number's
// default inside its bounds.
TEST(EnginesJson, EverySimulatorAndSetting) {
  const nlohmann::json j = engines_to_json();
  ASSERT_EQ(j.size(), engine_registry().size());
  size_t bounded = 0;
  for (size_t i = 0; i < j.size(); ++i) {
    const EngineInfo& e = engine_registry()[i];
    EXPECT_EQ(j[i].at("name"), e.name);
    EXPECT_EQ(j[i].at("version"), e.version);
    EXPECT_EQ(j[i].at("settings").size(), e.describe_settings ? e.describe_settings().size() : 0u) << e.name;
    for (const auto& s : j[i].at("settings")) {
      if (!s.contains("bounds")) continue;
      ++bounded;
      const double v = s.at("default").get<double>();
      EXPECT_LE(s.at("bounds")[0].get<double>(), v) << e.name << "." << s.at("key");
      EXPECT_LE(v, s.at("bounds")[1].get<double>()) << e.name << "." << s.at("key");
    }
  }
  EXPECT_GT(bounded, 0u);
}

// compare_scene refuses bad input with the command line's message before its directory exists.
TEST(CompareScene, RefusesBeforeWriting) {
  const Scene scene = load_scene(kScenesDir + "rutstam_ball.toml", {"run.duration=0.05"});
  const fs::path out = fs::temp_directory_path() / ("tippe-verbs-" + std::to_string(::getpid()));
  CompareRequest r;
  r.engines = {"ode", "ode"};
  r.out = out.string();
  r.progress = false;
  try {
    compare_scene(scene, r);
    FAIL() << "an engine listed twice was accepted";
  } catch (const InputError& e) {
    EXPECT_STREQ(e.what(), "engine \"ode\" listed twice");
  }
  EXPECT_FALSE(fs::exists(out));
}

}  // namespace
}  // namespace tippe
