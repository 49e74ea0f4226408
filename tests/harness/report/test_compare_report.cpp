// Tests of a comparison's report (harness/report/compare_report.cpp) on fixture records: well-formed HTML with plots and footer, graded errors and coloured metrics, the page without gnuplot, and comparison.json read back.
#include <gtest/gtest.h>
#include <stdlib.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "harness/io/text.h"
#include "harness/measure/compare.h"
#include "harness/records/records.h"
#include "harness/report/gnuplot.h"
#include "harness/report/report.h"
#include "harness/io/scene_io.h"
#include "tests/support/compare_fixtures.h"
#include "tests/support/files.h"
#include "tests/support/html_check.h"

namespace test_compare_report {

namespace fs = std::filesystem;
using namespace tippe;
using nlohmann::json;

namespace {

using namespace tippe::fixtures;

// Sets an environment variable for one scope.
class EnvGuard {
 public:
  EnvGuard(const char* name, const char* value) : name_(name) {
    if (const char* old = std::getenv(name)) old_ = old;
    if (value)
      ::setenv(name, value, 1);
    else
      ::unsetenv(name);
  }
  ~EnvGuard() {
    if (old_)
      ::setenv(name_.c_str(), old_->c_str(), 1);
    else
      ::unsetenv(name_.c_str());
  }

 private:
  std::string name_;
  std::optional<std::string> old_;
};

// A comparison of two engines on synthetic runs, with trajectories written where the report looks.
struct Fixture {
  json comparison;
  explicit Fixture(const fs::path& dir) {
    const Scene scene = test_scene();
    Columns ref_c;
    ref_c.theta = [](double t) { return 0.1 + 1.5 * t; };
    ref_c.energy = [](double t) { return 10.0 - t; };
    ref_c.x_C = [](double t) { return std::cos(3 * t); };
    ref_c.y_C = [](double t) { return std::sin(3 * t); };
    ref_c.normal_force = [](double t) { return 9.81 * (1 + 0.1 * std::sin(10 * t)); };
    Columns ode_c = ref_c;
    ode_c.theta = [](double t) { return 0.1 + 1.5 * (t - 0.02); };
    Columns bullet_c = ref_c;
    bullet_c.theta = [](double t) { return 0.1 + 1.0 * t; };  // never reaches 90 deg by t = 1
    bullet_c.energy = [](double t) { return 10.0 - t + (t > 0.505 ? 0.05 : 0.0); };  // one rise of 0.04

    auto write = [&](const std::string& name, const Columns& c, size_t n) {
      CsvTrajectoryWriter csv((dir / (name + ".csv")).string());
      TrajectorySink sink({&csv});
      for (size_t k = 0; k < n; ++k) sink.write(observation_at(0.01 * static_cast<double>(k), c));
      csv.commit();
      return sink.trajectory;
    };
    const Trajectory ref_t = write("reference", ref_c, 201);
    const Trajectory ode_t = write("ode", ode_c, 201);
    const Trajectory bullet_t = write("bullet", bullet_c, 101);

    Comparison c;
    c.scene = scene_to_json(scene);
    c.provenance = current_provenance();
    c.reference = make_record("analytic", 0.98, 1.5, 0.25);
    RunRecord ode = make_record("ode", 1.0, 1.52, 2.0);
    ode.notes = {"viscous friction applied by the bench"};
    RunRecord bullet = make_record("bullet", {}, {}, 1.0);
    bullet.status = "diverged";
    bullet.status_time = 1.0;
    bullet.status_detail = "|w| > 1e6 <rad/s>";
    c.engines.push_back({ode, compare_runs(c.reference, ref_t, ode, ode_t, scene)});
    c.engines.push_back({bullet, compare_runs(c.reference, ref_t, bullet, bullet_t, scene)});
    comparison = to_json(c);
    write_file_atomic((dir / "comparison.json").string(), comparison.dump(2));
  }
};

}  // namespace

TEST(HtmlChecker, CatchesTheUsualMistakes) {
  std::vector<std::string> img;
  EXPECT_EQ(check_html("<html><body><p>a &amp; b</p><img src=\"x.svg\"></body></html>", img), "");
  EXPECT_EQ(img, std::vector<std::string>{"x.svg"});
  EXPECT_NE(check_html("<p><b>x</p></b>", img), "");
  EXPECT_NE(check_html("<p>a < b</p>", img), "");
  EXPECT_NE(check_html("<p>a & b</p>", img), "");
  EXPECT_NE(check_html("<p>x", img), "");
}

TEST(Report, HtmlIsWellFormedWithPlotsAndFooter) {
  std::string why;
  if (gnuplot_command(&why).empty()) GTEST_SKIP() << why;
  TempDir dir{"tippe-compare"};
  const Fixture f(dir.path());
  write_report(dir.path().string(), f.comparison, true);
  const std::string html = slurp(dir.path() / "index.html");
  std::vector<std::string> images;
  EXPECT_EQ(check_html(html, images), "");
  EXPECT_EQ(images.size(), plot_file_names().size()) << html;
  for (const auto& img : images) {
    const fs::path p = dir.path() / img;
    ASSERT_TRUE(fs::exists(p)) << img;
    EXPECT_GT(fs::file_size(p), 1000u) << img;
    EXPECT_NE(slurp(p).find("<svg"), std::string::npos) << img;
  }
  EXPECT_EQ(html.find("plots skipped"), std::string::npos);
  // The footer: compiler, engine versions, commit, machine, date, scene hash.
  const size_t footer = html.find("<footer>");
  ASSERT_NE(footer, std::string::npos);
  const std::string foot = html.substr(footer);
  const Provenance p = current_provenance();
  for (const std::string& s : {p.compiler, p.git_commit, p.hostname, std::string("0123456789abcdef"),
                               std::string("ode: ode 1.0"), std::string("analytic: analytic 1.0")})
    EXPECT_NE(foot.find(markup_escape(s)), std::string::npos) << s;
  // Escaped text, colours and findings.
  EXPECT_NE(html.find("fixture &lt;scene&gt; &amp; &quot;quotes&quot;"), std::string::npos);
  EXPECT_NE(html.find("&lt;rad/s&gt;"), std::string::npos);
  EXPECT_NE(html.find("<td class=\"bad\">missing</td>"), std::string::npos);  // bullet lacks the inversion
  EXPECT_NE(html.find("diverged at t=1"), std::string::npos);
  EXPECT_NE(html.find("<details"), std::string::npos);
  EXPECT_NE(html.find("viscous friction applied by the bench"), std::string::npos);
  EXPECT_EQ(html.find("<script"), std::string::npos);
  EXPECT_EQ(html.find("http"), std::string::npos);  // no network resources

  const std::string md = slurp(dir.path() / "report.md");
  EXPECT_NE(md.find("| engine | status | inversion t |"), std::string::npos);
  EXPECT_NE(md.find("bullet: status diverged at t = 1"), std::string::npos) << md;
  EXPECT_NE(md.find("bullet: no inversion"), std::string::npos) << md;
  EXPECT_NE(md.find("bullet: energy rose above its lowest earlier value 1 time"), std::string::npos) << md;
  EXPECT_NE(md.find("## Provenance"), std::string::npos);
}

TEST(Report, EventErrorsAreGradedAndTolerancesColourMetrics) {
  TempDir dir{"tippe-compare"};
  Fixture f(dir.path());
  // ode inverts 0.02 after the reference at 0.98: 2 % -> amber.
  std::string html = render_html(f.comparison, {});
  EXPECT_NE(html.find("<td class=\"warn\">+0.02 (+2 %)</td>"), std::string::npos) << html;
  // Stem contact 1.52 vs 1.5: 1.3 % -> amber too; tilt RMS not graded without tolerances.
  f.comparison["tolerances"] = {{"tilt_rms_error", {{"green", 1e-3}, {"amber", 0.1}}},
                                {"inversion_time_rel_error", {{"green", 0.05}, {"amber", 0.1}}}};
  html = render_html(f.comparison, {});
  EXPECT_NE(html.find("<td class=\"good\">+0.02 (+2 %)</td>"), std::string::npos) << html;
  EXPECT_NE(html.find("<td class=\"warn\">0.03</td>"), std::string::npos) << html;  // ode tilt RMS = 1.5 * 0.02
}

TEST(Report, WithoutGnuplotThePageSaysPlotsSkipped) {
  TempDir dir{"tippe-compare"};
  const Fixture f(dir.path());
  {
    EnvGuard env("TIPPE_GNUPLOT", "none");
    write_report(dir.path().string(), f.comparison, true);
  }
  std::string html = slurp(dir.path() / "index.html");
  std::vector<std::string> images;
  EXPECT_EQ(check_html(html, images), "");
  EXPECT_TRUE(images.empty());
  EXPECT_EQ(html.find("<img"), std::string::npos);
  EXPECT_NE(html.find("plots skipped"), std::string::npos);
  EXPECT_NE(slurp(dir.path() / "report.md").find("plots skipped"), std::string::npos);
  EXPECT_NE(html.find("<table class=\"summary num\">"), std::string::npos);

  {
    EnvGuard env("TIPPE_GNUPLOT", (dir.path() / "no-such-gnuplot").c_str());
    write_report(dir.path().string(), f.comparison, true);
  }
  html = slurp(dir.path() / "index.html");
  EXPECT_NE(html.find("plots skipped: gnuplot not found"), std::string::npos);
  EXPECT_EQ(html.find("<img"), std::string::npos);

  {
    EnvGuard env("TIPPE_GNUPLOT", nullptr);
    EnvGuard path("PATH", dir.path().c_str());
    write_report(dir.path().string(), f.comparison, true);
  }
  EXPECT_NE(slurp(dir.path() / "index.html").find("plots skipped: gnuplot not found"), std::string::npos);

  write_report(dir.path().string(), f.comparison, false);
  EXPECT_NE(slurp(dir.path() / "index.html").find("plots skipped: disabled"), std::string::npos);
}

TEST(Report, ComparisonJsonRoundTrip) {
  TempDir dir{"tippe-compare"};
  const Fixture f(dir.path());
  const Comparison c = comparison_from_json(f.comparison);
  EXPECT_EQ(to_json(c), f.comparison);
  ASSERT_EQ(c.engines.size(), 2u);
  EXPECT_EQ(c.engines[1].run.status, "diverged");
  EXPECT_EQ(c.engines[1].metrics.inversion_event, "reference_only");
  EXPECT_EQ(f.comparison.at("physics_hash"), physics_hash(test_scene()));
}

TEST(Report, ChatteringSwitchEventsAreCountedNotListed) {
  const Scene scene = test_scene();
  Comparison c;
  c.scene = scene_to_json(scene);
  c.provenance = current_provenance();
  c.reference = make_record("analytic", {}, {});
  RunRecord eng = make_record("mujoco", 1.0, {});
  for (int k = 0; k < 150; ++k) eng.events.push_back({"switch", 0.01 * k, "ball -> stem", 0.0});
  const Trajectory tr = make_traj(11, 0.01, {});
  c.engines.push_back({eng, compare_runs(c.reference, tr, eng, tr, scene)});
  const json j = to_json(c);
  const json& events = j["engines"][0]["summary"]["events"];
  EXPECT_EQ(events.size(), static_cast<size_t>(kMaxSwitchEventsKept) + 1);  // the inversion stays
  EXPECT_EQ(events[0]["name"], "inversion");
  EXPECT_EQ(j["engines"][0]["summary"]["events_omitted"]["switch"], 150 - kMaxSwitchEventsKept);
  EXPECT_EQ(comparison_from_json(j).engines[0].run.inversion_time, 1.0);
  EXPECT_NE(render_html(j, {}).find("<td>150</td>"), std::string::npos);
}

}  // namespace test_compare_report
