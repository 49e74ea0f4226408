// Sweep pages lead with the verdict per engine and recommend no setting the stability map classes unphysical or diverged.
#include <gtest/gtest.h>

#include <optional>
#include <string>
#include <vector>

#include "harness/report/gnuplot.h"
#include "harness/report/document.h"
#include "harness/report/report.h"
#include "harness/sweep/sweep.h"
#include "tests/support/files.h"
#include "harness/report/sweep_analysis.h"

namespace test_report_sweep {

using namespace tippe;

namespace {

// A point of engine `engine` on `scene` at time step dt; the reference inverts at 10 on
// "inverting", never on "rolling".
SweepRecord point(const std::string& scene, const std::string& engine, long long index, double dt, double cpu,
                  std::optional<double> inversion, const std::string& run_class = "ok") {
  SweepRecord r;
  r.scene = scene;
  r.scene_file = scene + ".toml";
  r.scene_index = scene == "inverting" ? 0 : 1;
  r.setup = engine;
  r.engine = engine;
  r.setup_index = engine == "ode" ? 0 : 1;
  r.ladder_key = "engines." + engine + ".timestep";
  r.ladder_value = dt;
  r.ladder_label = std::to_string(dt);
  r.ladder_index = index;
  r.point_id = scene + engine + std::to_string(index);
  r.duration = 20;
  r.cpu_seconds = cpu;
  r.steps = 100;
  r.run_class = run_class;
  r.inversion_time = inversion;
  if (scene == "inverting") {
    r.reference_inversion_time = 10.0;
    if (inversion) {
      r.metrics.inversion_event = "both";
      r.metrics.inversion_time_rel_error = (*inversion - 10.0) / 10.0;
    } else {
      r.metrics.inversion_event = "reference_only";
    }
  } else {
    r.metrics.inversion_event = inversion ? "engine_only" : "neither";
  }
  return r;
}

std::vector<SweepRecord> fixture() {
  return {
      point("inverting", "ode", 0, 1e-2, 0.1, 10.5),    // 5 % late
      point("inverting", "ode", 1, 1e-3, 1.0, 10.05),   // 0.5 %: the cheapest below 1 %
      point("inverting", "ode", 2, 1e-4, 10.0, 10.001),  // 0.01 %
      point("rolling", "ode", 0, 1e-2, 0.1, 3.0),        // inverts where the reference rolls
      point("rolling", "ode", 1, 1e-3, 1.0, std::nullopt),
      point("rolling", "ode", 2, 1e-4, 10.0, std::nullopt),
  };
}

std::string verdict_line(const std::string& md, const std::string& engine) {
  const size_t at = md.find("\n" + engine + ": safe in the reference's regime");
  if (at == std::string::npos) return "";
  return md.substr(at + 1, md.find('\n', at + 1) - at - 1);
}

}  // namespace

TEST(SweepVerdict, RegimeErrorAndTheSettingToUse) {
  const std::string md = render_sweep_markdown(fixture());
  const std::string v = verdict_line(md, "ode");
  EXPECT_EQ(v,
            "ode: safe in the reference's regime at 5 of 6 points (inverting 3/3, rolling 2/3); inversion-time error 0.01 % to 5 % where both invert; setting to use: on inverting ode "
            "timestep = 0.001 (the cheapest safe within 1 %: 0.5 %, 1 CPU s); on rolling ode timestep = 0.001 (the cheapest "
            "safe: in the reference's regime, 1 CPU s).")
      << md;
  // It opens the page: before the first table and the first section.
  EXPECT_LT(md.find(v), md.find("| "));
  EXPECT_LT(md.find(v), md.find("\n## "));
  EXPECT_EQ(md.rfind("[all reports](../index.html) · [records.jsonl](records.jsonl)", 0), 0u) << md.substr(0, 200);
}

// A second point safe within 1 % at a CPU time within 10 % of the cheapest's is named beside the
// answer, in the verdict and in the cheapest-setting table; the answer stays the cheapest.
TEST(SweepVerdict, ANearTieInCostIsNamedBesideTheAnswer) {
  std::vector<SweepRecord> recs = fixture();
  recs[2].cpu_seconds = 1.05;  // 0.01 %, 5 % dearer than the 0.5 % point
  const std::string md = render_sweep_markdown(recs);
  const std::string v = verdict_line(md, "ode");
  EXPECT_NE(v.find("on inverting ode timestep = 0.001 (the cheapest safe within 1 %: 0.5 %, 1 CPU s) (within 10 % of its "
                   "CPU time, not told apart: ode timestep = 0.0001 1.05 s)"),
            std::string::npos)
      << v;
  EXPECT_NE(md.find("| ode | 1 % | ode | engines.ode.timestep = 0.001 | 0.5 % | 1 | ode timestep = 0.0001: 1.05 s |"),
            std::string::npos)
      << md;
  // Without the tie, no such words.
  EXPECT_EQ(render_sweep_markdown(fixture()).find("not told apart:"), std::string::npos);
  // The index's cell of the sweep's matrix counts it, in words apart from the error's 10 % tier.
  const std::string index = render_document_markdown(index_document(IndexInput{{}, {{"sweep-x", "d", recs}}}, "report.md"));
  EXPECT_NE(index.find("timestep = 0.001 (0.5 %), 1 CPU s; 1 other within 10 % of its CPU time"), std::string::npos)
      << index;
  EXPECT_EQ(render_document_markdown(index_document(IndexInput{{}, {{"sweep-x", "d", fixture()}}}, "report.md"))
                .find("within 10 % of its CPU time"),
            std::string::npos);
}

TEST(SweepVerdict, AnUnphysicalOrDivergedPointIsNeverRecommended) {
  std::vector<SweepRecord> recs = fixture();
  recs[1].run_class = "unphysical";  // the cheapest below 1 %, but its conservation law broke
  recs[4].run_class = "diverged";    // the cheapest rolling point
  recs[4].status = "ok";
  const std::string md = render_sweep_markdown(recs);
  const std::string v = verdict_line(md, "ode");
  EXPECT_NE(v.find("on inverting ode timestep = 0.0001 (the cheapest safe within 1 %: 0.01 %, 10 CPU s)"), std::string::npos)
      << v;
  EXPECT_NE(v.find("on rolling ode timestep = 0.0001 (the cheapest safe: in the reference's regime, 10 CPU s)"),
            std::string::npos)
      << v;
  EXPECT_NE(v.find("at 3 of 6 points"), std::string::npos) << v;
  // The recommended-settings table: the 1 % row names 1e-4, not the unphysical 1e-3.
  EXPECT_NE(md.find("| ode | 1 % | ode | engines.ode.timestep = 0.0001 |"), std::string::npos) << md;
  EXPECT_EQ(md.find("| ode | 1 % | ode | engines.ode.timestep = 0.001 |"), std::string::npos) << md;
  EXPECT_NE(md.find("classed ok by the stability map"), std::string::npos);
  EXPECT_NE(md.find("unphysical or diverged never count, nor are they ever the setting to use"), std::string::npos);
}

TEST(SweepVerdict, EveryPointTableCarriesTheClass) {
  std::vector<SweepRecord> recs = fixture();
  recs[1].run_class = "unphysical";
  recs[1].class_time = 4.5;
  const std::string md = render_sweep_markdown(recs);
  EXPECT_NE(md.find("| setup | setting | status | class | inversion t |"), std::string::npos) << md;
  EXPECT_NE(md.find("| ode | timestep = 0.001 | ok | unphysical at 4.5 | 10.05 |"), std::string::npos) << md;
  // A finished run out of the reference's regime says so in its class cell.
  EXPECT_NE(md.find("| ode | timestep = 0.01 | ok | ok, regime differs | 3 |"), std::string::npos) << md;
}

TEST(SweepVerdict, HtmlPageColoursTheClassAndLinksTheRecords) {
  TempDir dir{"tippe-sweep-page"};
  std::vector<SweepRecord> recs = fixture();
  recs[2].run_class = "diverged";
  write_sweep_report(dir.path().string(), recs, false);
  const std::string html = slurp(dir.path() / "index.html");
  EXPECT_NE(html.find("<p class=\"verdict\">ode: safe in the reference"), std::string::npos);
  EXPECT_NE(html.find("<td class=\"c-diverged\">diverged</td>"), std::string::npos);
  EXPECT_NE(html.find("<a href=\"records.jsonl\">records.jsonl</a>"), std::string::npos);
  EXPECT_NE(html.find("<a href=\"../index.html\">all reports</a>"), std::string::npos);
  EXPECT_NE(html.find("<nav class=\"toc\">"), std::string::npos);
  EXPECT_EQ(html.find("<script"), std::string::npos);
}

TEST(SweepCharts, NamedByTheScenesPlaceAndStaleChartsGo) {
  if (gnuplot_command().empty()) GTEST_SKIP() << "gnuplot not installed";
  TempDir dir{"tippe-sweep-page"};
  spit(dir.path() / "wp-old_scene-tilt_rms_error.svg", "<svg>stale</svg>");
  spit(dir.path() / "regime-old_scene.svg", "<svg>stale</svg>");
  spit(dir.path() / "notes.svg", "<svg>not a chart</svg>");
  write_sweep_report(dir.path().string(), fixture(), true);
  EXPECT_FALSE(std::filesystem::exists(dir.path() / "wp-old_scene-tilt_rms_error.svg"));
  EXPECT_FALSE(std::filesystem::exists(dir.path() / "regime-old_scene.svg"));
  EXPECT_TRUE(std::filesystem::exists(dir.path() / "notes.svg")) << "only the report's own charts are removed";
  EXPECT_TRUE(std::filesystem::exists(dir.path() / "wp-s1-inversion_time_rel_error.svg"));
  EXPECT_TRUE(std::filesystem::exists(dir.path() / "regime-s2.svg")) << "the rolling scene's regime chart";
  // Neither a scene's name nor a setup's reaches the script; each axis says its unit.
  const std::string gp = slurp(dir.path() / "sweep-plots.gp");
  EXPECT_EQ(gp.find("inverting"), std::string::npos) << gp;
  EXPECT_EQ(gp.find("rolling"), std::string::npos) << gp;
  EXPECT_NE(gp.find("set xlabel 'CPU seconds of the run (s;"), std::string::npos);
  EXPECT_NE(gp.find("(dimensionless)'"), std::string::npos);
  EXPECT_NE(gp.find("(scene time unit;"), std::string::npos);
  const std::string html = slurp(dir.path() / "index.html");
  EXPECT_NE(html.find("<img src=\"wp-s1-inversion_time_rel_error.svg\""), std::string::npos);
}

}  // namespace test_report_sweep
