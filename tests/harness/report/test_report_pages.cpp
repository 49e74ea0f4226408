// Comparison pages lead with the verdict: one sentence per engine, engine-minus-reference plots on a log axis, contact paths broken at surface switches, plots kept when they cannot be remade.
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "harness/measure/compare.h"
#include "harness/records/fields.h"
#include "harness/records/records.h"
#include "harness/report/document.h"
#include "harness/report/gnuplot.h"
#include "harness/report/report.h"
#include "harness/io/scene_io.h"
#include "tests/support/files.h"

namespace test_report_pages {

namespace fs = std::filesystem;
using namespace tippe;
using nlohmann::json;

namespace {

Scene page_scene() {
  Scene s;
  s.name = "fixture";
  s.description = "a synthetic comparison";
  s.source_file = "fixture.toml";
  s.content_hash = "0123456789abcdef";
  s.gravity = 9.81;
  s.body.sphere_radius = 2.0;
  s.body.stem_radius = 0.5;
  s.body.stem_length = 2.4;
  s.body.truncation_height = 1.8;
  s.body.mass_model = MassModel::Given;
  s.mass = {1.0, 0.6, 1.6, 1.8};
  s.contact.friction = FrictionLaw::Viscous;
  s.contact.k = 1.0;
  s.initial.tilt = 0.1;
  s.initial.spin = 5.0;
  s.run.duration = 2.0;
  s.run.sample_interval = 0.01;
  return s;
}

RunRecord record(const std::string& engine, std::optional<double> inversion) {
  RunRecord r;
  r.scene_name = "fixture";
  r.scene_file = "fixture.toml";
  r.scene_hash = "0123456789abcdef";
  r.scene_spec = scene_to_json(page_scene());
  r.engine = engine;
  r.engine_version = engine + " 1.0";
  r.inversion_time = inversion;
  if (inversion) r.events.push_back({"inversion", *inversion, "theta crosses 90 deg", 0.0});
  r.work.steps = 100;
  r.work.cpu_seconds = 1.0;
  r.work.wall_seconds = 1.0;
  r.samples = 201;
  r.final_time = 2.0;
  r.energy_initial = 10.0;
  r.energy_final = 9.0;
  r.jellett_initial = -1.5;
  r.provenance = current_provenance();
  return r;
}

// theta(t) rising through pi/2 at t_inv (never when t_inv is empty); the contact on the ball
// until t_stem, then on the stem (its contact point a stem's length away).
Trajectory write_run(const fs::path& csv_path, std::optional<double> t_inv, double offset, double t_stem = 99) {
  CsvTrajectoryWriter csv(csv_path.string());
  TrajectorySink sink({&csv});
  for (int k = 0; k < 201; ++k) {
    const double t = 0.01 * k;
    Observation o;
    o.state.t = t;
    o.state.p_WG = Vec3(0, 0, 1);
    o.theta = t_inv ? 0.1 + (M_PI / 2 - 0.1) * t / *t_inv : 0.1 + 0.01 * t;
    o.theta += offset * t;
    o.surface = t < t_stem ? Surface::Ball : Surface::Stem;
    o.p_WC = t < t_stem ? Vec3(std::cos(t), std::sin(t), 0) : Vec3(std::cos(t) + 3, std::sin(t) + 3, 0);
    o.normal_force = 9.81;
    o.energy = 10 - t + offset * t;
    o.jellett = -1.5;
    o.contact_latitude = 0.1;
    sink.write(o);
  }
  csv.commit();
  return sink.trajectory;
}

// The reference inverts at 1.0; "late" inverts at 1.05; "rolling" never does.
json make_comparison(const fs::path& dir, double t_stem = 99) {
  const Scene scene = page_scene();
  const Trajectory ref_t = write_run(dir / "reference.csv", 1.0, 0.0, t_stem);
  const Trajectory late_t = write_run(dir / "ode.csv", 1.05, 1e-3, t_stem);
  const Trajectory roll_t = write_run(dir / "bullet.csv", std::nullopt, 0.0, t_stem);
  Comparison c;
  c.scene = scene_to_json(scene);
  c.provenance = current_provenance();
  c.reference = record("analytic", 1.0);
  const RunRecord late = record("ode", 1.05), rolling = record("bullet", std::nullopt);
  c.engines.push_back({late, compare_runs(c.reference, ref_t, late, late_t, scene)});
  c.engines.push_back({rolling, compare_runs(c.reference, ref_t, rolling, roll_t, scene)});
  json j = to_json(c);
  write_file_atomic((dir / "comparison.json").string(), j.dump(2));
  return j;
}

bool has_gnuplot() { return !gnuplot_command().empty(); }

}  // namespace

TEST(ReportVerdict, OneSentencePerEngineFromTheRecords) {
  TempDir dir{"tippe-pages"};
  const json c = make_comparison(dir.path());
  const auto v = verdict_sentences(c);
  ASSERT_EQ(v.size(), 2u);
  // A late-inverting engine: its regime and its error, signed in words.
  EXPECT_EQ(v[0], "ode: inverts like the reference, 5 % late (t = 1.05 against the reference's 1).") << v[0];
  // A rolling engine where the reference inverts: the wrong regime, no time to compare.
  EXPECT_EQ(v[1],
            "bullet: does not invert by the end of its run (t = 2) while the reference inverts at t = 1: the wrong "
            "regime, no inversion time to compare.")
      << v[1];
}

TEST(ReportVerdict, RollingLikeTheReferenceAndEndedEarly) {
  TempDir dir{"tippe-pages"};
  json c = make_comparison(dir.path());
  // The reference keeps rolling: a rolling engine is in its regime, an inverting one is not.
  c["reference"]["summary"]["inversion_time"] = nullptr;
  c["engines"][0]["metrics"]["inversion_time_rel_error"] = nullptr;
  auto v = verdict_sentences(c);
  EXPECT_EQ(v[0].rfind("ode: inverts at t = 1.05 while the reference does not invert to t = 2: the wrong regime", 0), 0u)
      << v[0];
  EXPECT_EQ(v[1].rfind("bullet: does not invert to t = 2, like the reference (the reference's regime)", 0), 0u) << v[1];
  c["engines"][1]["summary"]["status"] = "diverged";
  c["engines"][1]["summary"]["status_time"] = 0.5;
  v = verdict_sentences(c);
  EXPECT_NE(v[1].find("its run ended early (diverged at t = 0.5) without inverting"), std::string::npos) << v[1];
}

TEST(ReportVerdict, AnInversionPastTheReferencesConvergedWindowSaysSo) {
  TempDir dir{"tippe-pages"};
  json c = make_comparison(dir.path());
  // The reference's self-check parts at t = 1.02: ode's inversion at 1.05 rests on an unconverged
  // reference, and its sentence says so; an event inside the window carries no such caveat.
  c["engines"][0]["metrics"]["reference_converged_until"] = 1.02;
  auto v = verdict_sentences(c);
  EXPECT_NE(v[0].find("5 % late (t = 1.05 against the reference's 1); it inverts after t = 1.02, where the "
                      "reference's self-check says the reference is no longer converged"),
            std::string::npos)
      << v[0];
  c["engines"][0]["metrics"]["reference_converged_until"] = 1.5;
  v = verdict_sentences(c);
  EXPECT_EQ(v[0], "ode: inverts like the reference, 5 % late (t = 1.05 against the reference's 1).") << v[0];
}

TEST(ReportPage, OpensWithTheVerdictAndLinksTheDataAndTheIndex) {
  TempDir dir{"tippe-pages"};
  const json c = make_comparison(dir.path());
  {
    const char* old = std::getenv("TIPPE_GNUPLOT");
    const std::string saved = old ? old : "";
    ::setenv("TIPPE_GNUPLOT", "none", 1);
    write_report(dir.path().string(), c, true);
    if (old) ::setenv("TIPPE_GNUPLOT", saved.c_str(), 1);
    else ::unsetenv("TIPPE_GNUPLOT");
  }
  const std::string html = slurp(dir.path() / "index.html");
  const size_t verdict = html.find("<p class=\"verdict\">ode: inverts like the reference");
  ASSERT_NE(verdict, std::string::npos) << html;
  // Before any table, heading but the title, or the scene's description.
  EXPECT_LT(verdict, html.find("<table"));
  EXPECT_LT(verdict, html.find("<h2"));
  EXPECT_LT(verdict, html.find("a synthetic comparison"));
  EXPECT_NE(html.find("<a href=\"../index.html\">all reports</a>"), std::string::npos);
  EXPECT_NE(html.find("<a href=\"comparison.json\">"), std::string::npos);
  for (const char* csv : {"reference.csv", "ode.csv", "bullet.csv"})
    EXPECT_NE(html.find("<a href=\"" + std::string(csv) + "\">"), std::string::npos) << csv;
  // A long page has a table of contents linking its sections.
  EXPECT_NE(html.find("<nav class=\"toc\">"), std::string::npos);
  EXPECT_NE(html.find("<a href=\"#sec-"), std::string::npos);
  EXPECT_EQ(html.find("<script"), std::string::npos);
  const std::string md = slurp(dir.path() / "report.md");
  EXPECT_EQ(md.rfind("[all reports](../index.html)", 0), 0u) << md.substr(0, 200);
  EXPECT_LT(md.find("ode: inverts like the reference, 5 % late"), md.find("| engine |"));
  EXPECT_NE(md.find("- [Findings](#findings)"), std::string::npos) << md;
  // Without the trajectories (a published report), no link to them.
  fs::remove(dir.path() / "ode.csv");
  const std::string again = render_html(c, {}, "", {"reference.csv"});
  EXPECT_EQ(again.find("ode.csv"), std::string::npos);
}

TEST(ReportPlots, DifferencesOnALogAxisAndUnitsOnEveryAxis) {
  if (!has_gnuplot()) GTEST_SKIP() << "gnuplot not installed";
  TempDir dir{"tippe-pages"};
  const json c = make_comparison(dir.path());
  write_report(dir.path().string(), c, true);
  const std::string gp = slurp(dir.path() / "plots.gp");
  for (const char* f : {"theta_error.svg", "energy_error.svg"}) {
    const size_t at = gp.find(std::string("set output '") + f + "'");
    ASSERT_NE(at, std::string::npos) << f << "\n" << gp;
    const std::string figure = gp.substr(at, gp.find("unset output", at) - at);
    EXPECT_NE(figure.find("set logscale y"), std::string::npos) << figure;
    EXPECT_NE(figure.find("|"), std::string::npos) << figure;
    EXPECT_GT(fs::file_size(dir.path() / f), 1000u) << f;
  }
  // Every axis label carries a unit: SI seconds for this scene, ratios said dimensionless.
  size_t labels = 0;
  for (size_t at = gp.find("set xlabel"); at != std::string::npos; at = gp.find("set xlabel", at + 1)) {
    const std::string x = gp.substr(at, gp.find('\n', at) - at);
    const size_t y_at = gp.find("set ylabel", at);
    const std::string y = gp.substr(y_at, gp.find('\n', y_at) - y_at);
    EXPECT_TRUE(x.find("(s)") != std::string::npos || x.find("dimensionless") != std::string::npos) << x;
    EXPECT_TRUE(y.find("(rad)") != std::string::npos || y.find("dimensionless") != std::string::npos) << y;
    ++labels;
  }
  EXPECT_EQ(labels, plot_file_names().size());
  const std::string html = slurp(dir.path() / "index.html");
  EXPECT_NE(html.find("interpolated"), std::string::npos) << "the caption says how the difference is taken";
  // Engines are told apart by markers as well as colours.
  EXPECT_NE(gp.find("pt " + std::to_string(engine_point_type("ode"))), std::string::npos);
  EXPECT_NE(gp.find("pt " + std::to_string(engine_point_type("bullet"))), std::string::npos);
  EXPECT_NE(engine_point_type("ode"), engine_point_type("bullet"));
}

TEST(ReportPlots, TheContactPathBreaksAtASurfaceSwitch) {
  if (!has_gnuplot()) GTEST_SKIP() << "gnuplot not installed";
  TempDir dir{"tippe-pages"};
  const json c = make_comparison(dir.path(), /*t_stem=*/1.5);
  write_report(dir.path().string(), c, true);
  // The reference's data file: the path block holds one blank line, at the switch, between a
  // point on the ball (x ~ cos t) and one on the stem (x ~ cos t + 3).
  const std::string dat = slurp(dir.path() / "plot-0.dat");
  const size_t begin = dat.find("# path\n");
  ASSERT_NE(begin, std::string::npos) << dat.substr(0, 300);
  const std::string block = dat.substr(begin, dat.find("\n\n\n", begin) - begin);
  const size_t gap = block.find("\n\n");
  ASSERT_NE(gap, std::string::npos) << block;
  EXPECT_EQ(block.find("\n\n", gap + 2), std::string::npos) << "one break only";
  const std::string before = block.substr(block.rfind('\n', gap - 1) + 1, gap - block.rfind('\n', gap - 1) - 1);
  const std::string after = block.substr(gap + 2, block.find('\n', gap + 2) - gap - 2);
  const double x_before = std::stod(before), x_after = std::stod(after);
  EXPECT_NEAR(x_before, std::cos(1.49) / 2.0, 1e-6) << before;  // over R = 2
  EXPECT_NEAR(x_after, (std::cos(1.5) + 3) / 2.0, 1e-6) << after;
  // Without a switch, no break.
  TempDir plain{"tippe-pages"};
  write_report(plain.path().string(), make_comparison(plain.path()), true);
  const std::string d2 = slurp(plain.path() / "plot-0.dat");
  const size_t b2 = d2.find("# path\n");
  const std::string block2 = d2.substr(b2, d2.find("\n\n\n", b2) - b2);
  EXPECT_EQ(block2.find("\n\n"), std::string::npos);
}

TEST(ReportPlots, ReportKeepsPlotsItCannotRemake) {
  if (!has_gnuplot()) GTEST_SKIP() << "gnuplot not installed";
  TempDir dir{"tippe-pages"};
  const json c = make_comparison(dir.path());
  write_report(dir.path().string(), c, true);
  ASSERT_TRUE(fs::exists(dir.path() / "theta.svg"));
  const std::string svg = slurp(dir.path() / "theta.svg");
  // A published report: the records and the SVGs, no trajectories.
  for (const char* csv : {"reference.csv", "ode.csv", "bullet.csv"}) fs::remove(dir.path() / csv);
  const std::string tippe = std::string(TIPPE_BINARY_DIR) + "/tippe";
  const std::string cmd = tippe + " report " + dir.path().string() + " >/dev/null 2>&1";
  ASSERT_EQ(std::system(cmd.c_str()), 0);
  EXPECT_EQ(slurp(dir.path() / "theta.svg"), svg) << "the plot stays as it was";
  const std::string html = slurp(dir.path() / "index.html");
  EXPECT_NE(html.find("<img src=\"theta.svg\""), std::string::npos) << "and is still shown";
  EXPECT_NE(html.find("kept from an earlier run"), std::string::npos);
  // --no-plots keeps them too.
  ASSERT_EQ(std::system((tippe + " report " + dir.path().string() + " --no-plots >/dev/null 2>&1").c_str()), 0);
  EXPECT_TRUE(fs::exists(dir.path() / "theta.svg"));
  EXPECT_NE(slurp(dir.path() / "index.html").find("<img src=\"theta.svg\""), std::string::npos);
}

TEST(ReportIndex, OneSentencePerEngineOverEveryScene) {
  TempDir dir{"tippe-pages"};
  json a = make_comparison(dir.path());
  json b = a;
  b["scene_name"] = "second";
  b["engines"][0]["metrics"]["inversion_time_rel_error"] = 0.01;
  const auto v = index_verdicts({a, b});
  ASSERT_EQ(v.size(), 2u);
  EXPECT_EQ(v[0],
            "ode: the reference's regime on 2 of 2 scenes; inversion-time error 1 % to 5 % where both invert (2 scenes, "
            "largest on fixture).")
      << v[0];
  EXPECT_EQ(v[1], "bullet: the reference's regime on 0 of 2 scenes, the wrong regime on 2; no scene where both invert.")
      << v[1];
}

// Each kind of matrix cell from a record: the error's size where both invert, neither inverting,
// the wrong regime either way, and a run that ended early.
TEST(ReportIndex, EveryVerdictKindOfTheMatrix) {
  TempDir dir{"tippe-pages"};
  json c = make_comparison(dir.path());
  json& ode = c["engines"][0];
  const json& bullet = c["engines"][1];
  EXPECT_EQ(verdict_cell(c, ode).kind, "10pct") << "5 % late";
  ode["metrics"]["inversion_time_rel_error"] = 0.05;
  EXPECT_EQ(verdict_cell(c, ode).kind, "10pct");
  EXPECT_EQ(verdict_cell(c, ode).text, "+5 %");
  ode["metrics"]["inversion_time_rel_error"] = -0.002;
  EXPECT_EQ(verdict_cell(c, ode).kind, "1pct");
  EXPECT_EQ(verdict_cell(c, ode).text, "-0.2 %");
  ode["metrics"]["inversion_time_rel_error"] = 0.3;
  EXPECT_EQ(verdict_cell(c, ode).kind, "beyond");
  const VerdictCell rolls = verdict_cell(c, bullet);
  EXPECT_EQ(rolls.kind, "wrong");
  EXPECT_EQ(rolls.text.rfind("rolls; the reference inverts at ", 0), 0u) << rolls.text;
  json ended = bullet;
  ended["summary"]["status"] = "diverged";
  ended["summary"]["status_time"] = 0.5;
  EXPECT_EQ(verdict_cell(c, ended).kind, "failed");
  EXPECT_EQ(verdict_cell(c, ended).text.rfind("diverged at ", 0), 0u) << verdict_cell(c, ended).text;
  // The reference rolls: a rolling engine is in its regime, an inverting one is not.
  c["reference"]["summary"]["inversion_time"] = nullptr;
  EXPECT_EQ(verdict_cell(c, bullet).kind, "regime");
  EXPECT_EQ(verdict_cell(c, c["engines"][0]).kind, "wrong");
  EXPECT_NE(verdict_cell(c, c["engines"][0]).text.find("; the reference rolls"), std::string::npos);
  // Six kinds, each with its words and colour.
  EXPECT_EQ(verdict_kinds().size(), 6u);
  for (const auto& k : verdict_kinds()) EXPECT_NE(verdict_kind_text(k), k);
}

TEST(ReportDocument, OneModelRenderedToMarkdownAndHtml) {
  Document d;
  d.title = "t <1>";
  d.top_links = {{"all reports", "../index.html"}};
  d.heading(1, "Title & more");
  d.para("verdict <b>", "verdict");
  for (int i = 0; i < 4; ++i) d.heading(2, "Part " + std::to_string(i));
  DocTable t;
  t.header = {"a", "b|c"};
  t.rows = {{DocCell("x"), DocCell("1", "bad")}};
  d.table(t);
  d.figure("p.svg", "a \"caption\"");
  d.footer = {"commit abc"};
  const std::string html = render_document_html(d);
  EXPECT_NE(html.find("<title>t &lt;1&gt;</title>"), std::string::npos);
  EXPECT_NE(html.find("<p class=\"verdict\">verdict &lt;b&gt;</p>"), std::string::npos);
  EXPECT_NE(html.find("<td class=\"bad\">1</td>"), std::string::npos);
  EXPECT_NE(html.find("<nav class=\"toc\">"), std::string::npos);
  EXPECT_LT(html.find("verdict &lt;b&gt;"), html.find("<nav class=\"toc\">")) << "the verdict before the contents";
  EXPECT_NE(html.find("<h2 id=\"sec-2\">Part 0</h2>"), std::string::npos);
  EXPECT_NE(html.find("<a href=\"#sec-2\">Part 0</a>"), std::string::npos);
  EXPECT_NE(html.find("alt=\"a &quot;caption&quot;\""), std::string::npos);
  EXPECT_EQ(html.find("<script"), std::string::npos);
  const std::string md = render_document_markdown(d);
  EXPECT_NE(md.find("| a | b\\|c |"), std::string::npos) << md;
  EXPECT_NE(md.find("- [Part 0](#part-0)"), std::string::npos) << md;
  EXPECT_NE(md.find("![a \"caption\"](p.svg)"), std::string::npos) << md;
  EXPECT_NE(md.find("## Provenance\n\n- commit abc"), std::string::npos) << md;
  d.toc_from = 5;
  EXPECT_EQ(render_document_html(d).find("<nav class=\"toc\">"), std::string::npos) << "a short page has none";
}

TEST(ReportIndex, TheCommandReadsEverySceneDirectory) {
  TempDir dir{"tippe-pages"};
  fs::create_directories(dir.path() / "fixture");
  fs::create_directories(dir.path() / "sweep-x");  // no comparison.json: not a scene page
  make_comparison(dir.path() / "fixture");
  const std::string tippe = std::string(TIPPE_BINARY_DIR) + "/tippe";
  const fs::path out = dir.path() / "out.txt";
  ASSERT_EQ(std::system((tippe + " report " + dir.path().string() + " --index-verdict >" + out.string()).c_str()), 0);
  const std::string text = slurp(out);
  EXPECT_EQ(text,
            "ode: the reference's regime on 1 of 1 scenes; inversion-time error 5 % where both invert (1 scene, largest "
            "on fixture).\n"
            "bullet: the reference's regime on 0 of 1 scenes, the wrong regime on 1; no scene where both invert.\n");
  // --index writes the index page and its Markdown from the records: the matrix, linked cells.
  ASSERT_EQ(std::system((tippe + " report " + dir.path().string() + " --index >/dev/null").c_str()), 0);
  const std::string html = slurp(dir.path() / "index.html"), md = slurp(dir.path() / "README.md");
  EXPECT_NE(html.find("<table class=\"matrix num\">"), std::string::npos) << html;
  EXPECT_NE(html.find("<thead><tr><th>scene</th><th>ode</th><th>bullet</th></tr></thead>"), std::string::npos) << html;
  EXPECT_NE(html.find("<td class=\"v-wrong\"><a href=\"fixture/index.html\">rolls; the reference inverts at"), std::string::npos) << html;
  EXPECT_NE(md.find("| [fixture](fixture/report.md) |"), std::string::npos) << md;
  // A directory with no comparison in it is bad input, exit 2.
  const int rc = std::system((tippe + " report " + (dir.path() / "sweep-x").string() + " --index-verdict 2>/dev/null").c_str());
  EXPECT_EQ(WEXITSTATUS(rc), 2);
}

// The page shows every number of Metrics' list (its `visit`): changing one changes the page, so
// a metric added to the list is on the page or named here with the reason it is not.
TEST(ReportPage, EveryMetricOfTheListIsOnThePage) {
  TempDir dir{"tippe-pages"};
  json c = make_comparison(dir.path());
  // Both sides touch down on the stem, so the page has a stem-contact time to compare.
  c["reference"]["summary"]["stem_contact_time"] = 1.2;
  c["engines"][0]["summary"]["stem_contact_time"] = 1.25;
  c["engines"][0]["metrics"]["stem_contact_event"] = "both";
  c["engines"][0]["metrics"]["stem_contact_time_abs_error"] = 0.05;
  c["engines"][0]["metrics"]["stem_contact_time_rel_error"] = 0.05 / 1.2;
  // Shown from elsewhere in the record, the same number: the energy ledger's section reads each
  // run's own ledger (its summary), of which these metrics are copies scaled by |E0|; the CPU
  // column reads the run's summary; the first wrong event is shown by its text, the index only
  // places it in the alignment's table.
  const std::set<std::string> elsewhere = {"numerical_energy_max", "numerical_energy_final", "friction_work",
                                           "normal_work",          "drilling_work",          "impact_energy",
                                           "elastic_energy_max",   "cpu_seconds",            "first_wrong_event_index"};
  const std::string base = render_markdown(c);
  std::vector<std::string> missing, shown_after_all;
  for (const FieldInfo& f : field_list<Metrics>()) {
    if (!f.number) continue;
    json changed = c;
    json& m = changed["engines"][0]["metrics"];
    m[f.key] = m[f.key].is_number_integer() ? json(987654) : json(987.654);
    const bool shown = render_markdown(changed) != base;
    if (!shown && !elsewhere.count(f.key)) missing.push_back(f.key);
    if (shown && elsewhere.count(f.key)) shown_after_all.push_back(f.key);
  }
  EXPECT_TRUE(missing.empty()) << "metrics the page does not show: " << ::testing::PrintToString(missing);
  EXPECT_TRUE(shown_after_all.empty()) << "excused but shown: " << ::testing::PrintToString(shown_after_all);
}

}  // namespace test_report_pages
