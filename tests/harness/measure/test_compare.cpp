// Tests of `tippe compare` end to end (harness/measure/compare.cpp): the reference against itself, bad engines refused before anything is written, and the command's files, reference cache and exit codes (the metrics: test_metrics.cpp; the report: tests/harness/report/test_compare_report.cpp).
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <cstdlib>
#include <filesystem>
#include <stdexcept>
#include <string>
#include <vector>

#include "harness/measure/compare.h"
#include "harness/records/records.h"
#include "harness/report/gnuplot.h"
#include "harness/report/report.h"
#include "harness/io/scene_io.h"
#include "harness/scene/resolve.h"
#include "tests/support/files.h"
#include "tests/support/html_check.h"

namespace test_compare {

namespace fs = std::filesystem;
using namespace tippe;
using nlohmann::json;

namespace {

using fixtures::check_html;

int run_tippe(const std::string& args, const fs::path& err_file) {
  const std::string cmd = std::string(TIPPE_BINARY_DIR) + "/tippe " + args + " >/dev/null 2>" + err_file.string();
  const int rc = std::system(cmd.c_str());
  return WIFEXITED(rc) ? WEXITSTATUS(rc) : -1;
}

const std::string kScene = std::string(TIPPE_SOURCE_DIR) + "/harness/scenes/source_dimensionless.toml";

}  // namespace

TEST(CompareCli, WritesEveryFileAndReusesTheReferenceCache) {
  ASSERT_TRUE(fs::exists(std::string(TIPPE_BINARY_DIR) + "/tippe")) << "build the tippe target first";
  TempDir dir{"tippe-compare"};
  const fs::path out = dir.path() / "out", cache = dir.path() / "cache", err = dir.path() / "err.txt";
  const std::string args = "compare " + kScene + " --set run.duration=0.5 --engines ode --jobs 2 --out " +
                           out.string() + " --cache " + cache.string();
  ASSERT_EQ(run_tippe(args, err), 0) << slurp(err);
  std::vector<std::string> files = {"comparison.json", "reference.csv", "ode.csv", "report.md", "index.html"};
  const bool plots = !gnuplot_command().empty();
  if (plots) files.insert(files.end(), plot_file_names().begin(), plot_file_names().end());
  for (const auto& f : files) {
    ASSERT_TRUE(fs::exists(out / f)) << f;
    EXPECT_GT(fs::file_size(out / f), 0u) << f;
  }
  const json j = json::parse(slurp(out / "comparison.json"));
  EXPECT_FALSE(j.at("reference").at("cached").get<bool>());
  ASSERT_EQ(j.at("engines").size(), 1u);
  EXPECT_EQ(j.at("engines")[0].at("engine"), "ode");
  EXPECT_EQ(j.at("scene").at("run").at("duration"), 0.5);
  EXPECT_TRUE(j.at("provenance").at("engine_versions").contains("ode"));
  const Comparison c = comparison_from_json(j);
  EXPECT_EQ(c.engines[0].run.samples, 51);
  EXPECT_NEAR(c.engines[0].metrics.compared_until, 0.5, 1e-12);
  EXPECT_LT(c.engines[0].metrics.tilt_rms_error, 0.1);
  std::vector<std::string> images;
  EXPECT_EQ(check_html(slurp(out / "index.html"), images), "");
  EXPECT_TRUE(fs::exists(cache / j.at("physics_hash").get<std::string>() / "summary.json"));

  // Second run: the reference comes from the cache, with the same numbers.
  ASSERT_EQ(run_tippe(args, err), 0) << slurp(err);
  const json j2 = json::parse(slurp(out / "comparison.json"));
  EXPECT_TRUE(j2.at("reference").at("cached").get<bool>());
  EXPECT_EQ(j2.at("engines")[0].at("metrics").at("tilt_rms_error"), j.at("engines")[0].at("metrics").at("tilt_rms_error"));
  EXPECT_EQ(slurp(out / "reference.csv").size(), fs::file_size(cache / j.at("physics_hash").get<std::string>() / "trajectory.csv"));

  // The report regenerates from the records alone.
  fs::remove(out / "index.html");
  fs::remove(out / "report.md");
  ASSERT_EQ(run_tippe("report " + out.string(), err), 0) << slurp(err);
  EXPECT_TRUE(fs::exists(out / "index.html"));
  EXPECT_TRUE(fs::exists(out / "report.md"));
}

TEST(CompareCli, InvalidInputExitsWithTwoAndWritesNothing) {
  TempDir dir{"tippe-compare"};
  const fs::path out = dir.path() / "out", cache = dir.path() / "cache", err = dir.path() / "err.txt";
  const std::string tail = " --out " + out.string() + " --cache " + cache.string();
  EXPECT_EQ(run_tippe("compare " + kScene + " --engines ode,nosuch" + tail, err), 2);
  EXPECT_NE(slurp(err).find("nosuch"), std::string::npos) << slurp(err);
  EXPECT_EQ(run_tippe("compare " + kScene + " --set engines.ode.nosuch=1" + tail, err), 2);
  EXPECT_NE(slurp(err).find("engines.ode.nosuch"), std::string::npos) << slurp(err);
  EXPECT_EQ(run_tippe("compare " + kScene + " --engines ode,ode" + tail, err), 2);
  EXPECT_EQ(run_tippe("compare " + (dir.path() / "missing.toml").string() + tail, err), 2);
  EXPECT_FALSE(fs::exists(out));
  EXPECT_FALSE(fs::exists(cache));
  EXPECT_EQ(run_tippe("report " + (dir.path() / "nothing").string(), err), 2);
}

TEST(RunComparison, UnknownEngineThrowsBeforeWriting) {
  TempDir dir{"tippe-compare"};
  const Scene scene = load_scene(kScene, {"run.duration=0.1"});
  CompareOptions o;
  o.engines = {"ode", "nosuch"};
  o.out_dir = (dir.path() / "out").string();
  o.cache_dir = (dir.path() / "cache").string();
  o.progress = false;
  EXPECT_THROW(run_comparison(scene, o), std::invalid_argument);
  o.engines = {"ode"};
  o.jobs = 0;
  EXPECT_THROW(run_comparison(scene, o), std::invalid_argument);
  EXPECT_FALSE(fs::exists(o.out_dir));
  EXPECT_FALSE(fs::exists(o.cache_dir));
}

TEST(RunComparison, TheReferenceAgainstItselfHasNoError) {
  const Scene scene = load_scene(kScene, {"run.duration=0.5"});
  CompareOptions o;
  o.engines = {"analytic", "ode"};
  o.jobs = 2;
  o.progress = false;
  const Comparison c = run_comparison(scene, o);  // no out_dir, no cache: nothing written
  ASSERT_EQ(c.engines.size(), 2u);
  const Metrics& m = c.engines[0].metrics;
  EXPECT_EQ(c.engines[0].run.engine, "analytic");
  EXPECT_EQ(m.tilt_max_error, 0.0);
  EXPECT_EQ(m.energy_max_error, 0.0);
  EXPECT_EQ(m.contact_path_max_error, 0.0);
  EXPECT_EQ(m.energy_gain_events, 0);
  EXPECT_EQ(m.inversion_event, "neither");
  EXPECT_NEAR(m.compared_until, 0.5, 1e-12);
  EXPECT_EQ(c.engines[1].run.engine, "ode");
  EXPECT_GT(c.engines[1].metrics.steps, 0);
  EXPECT_FALSE(c.reference_cached);
}

}  // namespace test_compare
