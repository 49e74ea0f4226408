// The reference's self-check: a second reference run with another method, the time up to which
// the two agree, the metrics and the report cut there, the cache, and records without it.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <string>

#include "harness/measure/compare.h"
#include "harness/records/records.h"
#include "harness/report/report.h"
#include "harness/io/scene_io.h"
#include "harness/scene/resolve.h"
#include "tests/support/files.h"

namespace test_self_check {

namespace fs = std::filesystem;
using namespace tippe;
using nlohmann::json;

namespace {

const std::string kScenes = std::string(TIPPE_SOURCE_DIR) + "/harness/scenes/";

CompareOptions quiet(const std::vector<std::string>& engines) {
  CompareOptions o;
  o.engines = engines;
  o.jobs = 2;
  o.progress = false;
  return o;
}

double first_event(const RunRecord& r, const std::string& name) {
  for (const Event& e : r.events)
    if (e.name == name) return e.time;
  return NAN;
}

// ---- the second method --------------------------------------------------------------------------

TEST(SelfCheck, SecondMethodIsTheOtherFamilyOrATighterRosenbrock) {
  RunSpec r;
  r.rtol = 1e-10;
  r.atol = 1e-12;
  r.method = "bulirsch_stoer";
  EXPECT_EQ(self_check_method(r).method, "dopri5");
  EXPECT_EQ(self_check_method(r).rtol, 1e-10);
  EXPECT_EQ(self_check_method(r).atol, 1e-12);
  r.method = "dopri5";
  EXPECT_EQ(self_check_method(r).method, "bulirsch_stoer");
  r.method = "rosenbrock4";
  EXPECT_EQ(self_check_method(r).method, "rosenbrock4");
  EXPECT_DOUBLE_EQ(self_check_method(r).rtol, 1e-11);
  EXPECT_DOUBLE_EQ(self_check_method(r).atol, 1e-13);
  r.rtol = 1e-15;
  EXPECT_EQ(self_check_method(r).rtol, 1e-15);  // the scene reader's floor
}

TEST(SelfCheck, EventToleranceFollowsRtolWithinItsBounds) {
  Scene s = load_scene(kScenes + "source_dimensionless.toml");
  s.run.duration = 25;
  s.run.rtol = 1e-10;
  EXPECT_DOUBLE_EQ(self_check_event_tolerance(s), 2.5e-6);
  s.run.rtol = 1e-14;
  EXPECT_DOUBLE_EQ(self_check_event_tolerance(s), 2.5e-8);
  s.run.rtol = 1e-3;
  EXPECT_DOUBLE_EQ(self_check_event_tolerance(s), 2.5e-4);
}

// ---- the pure comparison -----------------------------------------------------------------------

Trajectory line(size_t n, double dt, double theta_slope, double E0 = 10.0) {
  Trajectory tr;
  for (size_t k = 0; k < n; ++k) {
    Observation o;
    o.state.t = static_cast<double>(k) * dt;
    o.theta = 0.1 + theta_slope * o.state.t;
    o.energy = E0;
    tr.append(o);
  }
  return tr;
}

TEST(SelfCheck, PartsAtTheFirstDifferingEventOrState) {
  Scene s = load_scene(kScenes + "toy.toml", {"run.duration=1", "run.sample_interval=0.1"});
  RunRecord a, b;
  a.events = {{"inversion", 0.3, "theta crosses 90 deg downward", 0}, {"impact", 0.6, "stem touches down", 0}};
  b.events = a.events;
  const Trajectory tr = line(11, 0.1, 0.0);
  SelfCheck sc = compare_reference_runs(a, tr, b, tr, s);
  EXPECT_FALSE(sc.converged_until) << sc.reason;
  EXPECT_EQ(sc.reason, "");
  EXPECT_EQ(sc.method, "dopri5");

  b.events[1].time += 2 * self_check_event_tolerance(s);
  sc = compare_reference_runs(a, tr, b, tr, s);
  ASSERT_TRUE(sc.converged_until);
  EXPECT_DOUBLE_EQ(*sc.converged_until, 0.6);
  EXPECT_NE(sc.reason.find("event 1 (impact)"), std::string::npos) << sc.reason;

  b.events[1] = {"lift", 0.55, "the stem leaves the floor", 0};
  sc = compare_reference_runs(a, tr, b, tr, s);
  EXPECT_DOUBLE_EQ(*sc.converged_until, 0.55);
  EXPECT_NE(sc.reason.find("dopri5 has lift"), std::string::npos) << sc.reason;

  b.events.pop_back();
  sc = compare_reference_runs(a, tr, b, tr, s);
  EXPECT_DOUBLE_EQ(*sc.converged_until, 0.6);
  EXPECT_NE(sc.reason.find("bulirsch_stoer has 1 more event(s) from impact"), std::string::npos) << sc.reason;

  // The reference's own `unresolved` ends the window even when both runs agree on it.
  b.events = a.events;
  a.events.push_back({"unresolved", 0.45, "the stem returns from an excursion below 1e-06 R", 0});
  b.events.push_back(a.events.back());
  sc = compare_reference_runs(a, tr, b, tr, s);
  EXPECT_DOUBLE_EQ(*sc.converged_until, 0.45);
  EXPECT_EQ(sc.reason.rfind("unresolved at t = 0.45", 0), 0u) << sc.reason;

  // The state: converged until the last sample within the threshold.
  a.events.pop_back();
  b.events.pop_back();
  const Trajectory drift = line(11, 0.1, 8e-6);  // 8e-7 apart at t = 0.1, 1.6e-6 at t = 0.2
  sc = compare_reference_runs(a, tr, b, drift, s);
  ASSERT_TRUE(sc.converged_until);
  EXPECT_NEAR(*sc.converged_until, 0.1, 1e-12);
  EXPECT_NE(sc.reason.find("the tilt differs by"), std::string::npos) << sc.reason;

  b.status = "failed";
  b.status_time = 0.05;
  sc = compare_reference_runs(a, tr, b, tr, s);
  EXPECT_DOUBLE_EQ(*sc.converged_until, 0.05);
}

TEST(SelfCheck, JsonChecksConvergedUntil) {
  SelfCheck sc;
  sc.method = "dopri5";
  sc.rtol = 1e-10;
  sc.atol = 1e-12;
  sc.converged_until = 21.37;
  sc.reason = "why";
  sc.cpu_seconds = 0.02;
  json j = to_json(sc);
  EXPECT_EQ(self_check_from_json(j).converged_until, 21.37);
  j["converged_until"] = nullptr;
  EXPECT_FALSE(self_check_from_json(j).converged_until);
  j["converged_until"] = -1.0;
  EXPECT_THROW(self_check_from_json(j), std::invalid_argument);
  j["converged_until"] = "soon";
  EXPECT_THROW(self_check_from_json(j), json::exception);
}

// ---- end to end --------------------------------------------------------------------------------

TEST(SelfCheck, ConvergedSceneAgreesOverTheWholeRun) {
  // source_dimensionless to 18 (past the inversion at 17.25) at rtol 1e-10.
  const Scene scene = load_scene(kScenes + "source_dimensionless.toml", {"run.duration=18"});
  const Comparison c = run_comparison(scene, quiet({"analytic"}));
  ASSERT_TRUE(c.self_check);
  EXPECT_EQ(c.self_check->method, "dopri5");
  EXPECT_FALSE(c.self_check->converged_until) << c.self_check->reason;
  EXPECT_GT(c.self_check->cpu_seconds, 0);
  const Metrics& m = c.engines.at(0).metrics;
  EXPECT_FALSE(m.reference_converged_until);
  EXPECT_NEAR(m.compared_until, 18.0, 1e-9);
  EXPECT_EQ(m.inversion_event, "both");
  const json j = to_json(c);
  EXPECT_TRUE(j.at("reference").at("self_check").at("converged_until").is_null());
  EXPECT_EQ(render_markdown(j).find("The reference is converged to t ="), std::string::npos);
  EXPECT_NE(render_markdown(j).find("dopri5 agree over the whole run"), std::string::npos);
}

TEST(SelfCheck, CatchesAReferenceNotConvergedAndCutsTheMetricsAndTheReport) {
  // source_dimensionless to 23 at rtol 1e-8: after the graze ends (t ~ 21.37) the stem's hops
  // are not fixed by the motion, and at this tolerance the two methods part before that.
  TempDir dir{"tippe-self-check"};
  const Scene scene =
      load_scene(kScenes + "source_dimensionless.toml", {"run.duration=23", "engines.analytic.rtol=1e-8", "engines.analytic.atol=1e-10"});
  CompareOptions o = quiet({"analytic", "ode"});
  o.out_dir = (dir.path() / "out").string();
  const Comparison c = run_comparison(scene, o);
  write_report(o.out_dir, to_json(c), /*plots=*/false);  // as `tippe compare` does after the run
  ASSERT_TRUE(c.self_check);
  ASSERT_TRUE(c.self_check->converged_until);
  const double cu = *c.self_check->converged_until;
  std::printf("converged until %.6g: %s\n", cu, c.self_check->reason.c_str());
  EXPECT_LT(cu, 21.38);
  EXPECT_GT(cu, first_event(c.reference, "inversion"));
  EXPECT_FALSE(c.self_check->reason.empty());
  for (const EngineResult& e : c.engines) {
    ASSERT_TRUE(e.metrics.reference_converged_until) << e.run.engine;
    EXPECT_EQ(*e.metrics.reference_converged_until, cu);
    EXPECT_LE(e.metrics.compared_until, cu) << e.run.engine;
    EXPECT_GT(e.metrics.compared_until, cu - 2 * scene.run.sample_interval) << e.run.engine;
  }
  EXPECT_EQ(c.engines.at(0).metrics.inversion_event, "both");

  // comparison.json says it, reads back, and the report leads with it.
  const json j = json::parse(slurp(dir.path() / "out" / "comparison.json"));
  EXPECT_EQ(j.at("reference").at("self_check").at("converged_until").get<double>(), cu);
  EXPECT_EQ(j.at("reference").at("self_check").at("method"), "dopri5");
  EXPECT_EQ(j.at("engines")[1].at("metrics").at("reference_converged_until").get<double>(), cu);
  const Comparison back = comparison_from_json(j);
  ASSERT_TRUE(back.self_check);
  EXPECT_EQ(back.self_check->converged_until, cu);
  EXPECT_EQ(back.engines[1].metrics.reference_converged_until, cu);
  EXPECT_EQ(to_json(back), j);
  for (const char* page : {"report.md", "index.html"}) {
    const std::string text = slurp(dir.path() / "out" / page);
    const size_t at = text.find("The reference is converged to t = ");
    ASSERT_NE(at, std::string::npos) << page;
    EXPECT_LT(at, text.find("Summary") == std::string::npos ? text.size() : text.find("Summary")) << page;
    EXPECT_NE(text.find("methods bulirsch_stoer and dopri5 part: "), std::string::npos) << page;
    EXPECT_NE(text.find("metrics are compared up to it."), std::string::npos) << page;
  }
}

TEST(SelfCheck, CatchesALooseToleranceOnTheToy) {
  const Scene scene = load_scene(kScenes + "toy.toml", {"run.duration=2", "engines.analytic.rtol=1e-3", "engines.analytic.atol=1e-5"});
  const Comparison c = run_comparison(scene, quiet({"analytic"}));
  ASSERT_TRUE(c.self_check);
  ASSERT_TRUE(c.self_check->converged_until);
  EXPECT_LT(*c.self_check->converged_until, 0.1) << c.self_check->reason;
  EXPECT_LE(c.engines.at(0).metrics.compared_until, *c.self_check->converged_until);
}

TEST(SelfCheck, TurnedOffRecordsNone) {
  const Scene scene = load_scene(kScenes + "source_dimensionless.toml", {"run.duration=1", "engines.analytic.self_check=false"});
  EXPECT_FALSE(scene.run.self_check);
  const Comparison c = run_comparison(scene, quiet({"analytic"}));
  EXPECT_FALSE(c.self_check);
  EXPECT_FALSE(c.engines.at(0).metrics.reference_converged_until);
  const json j = to_json(c);
  EXPECT_FALSE(j.at("reference").contains("self_check"));
  EXPECT_EQ(j.at("scene").at("run").at("self_check"), false);
  EXPECT_NE(render_markdown(j).find("Reference self-check: not run"), std::string::npos);
  // Not physics: the same reference (and cache entry) serves both.
  EXPECT_EQ(physics_hash(scene), physics_hash(load_scene(kScenes + "source_dimensionless.toml", {"run.duration=1"})));
}

TEST(SelfCheck, SceneKeyIsABoolean) {
  EXPECT_TRUE(load_scene(kScenes + "toy.toml").run.self_check);
  try {
    load_scene(kScenes + "toy.toml", {"run.self_check=1"});
    FAIL() << "a number for run.self_check loaded";
  } catch (const SceneError& e) {
    EXPECT_NE(std::string(e.what()).find("run.self_check"), std::string::npos) << e.what();
  }
}

TEST(SelfCheck, IsCachedWithTheReferenceAndNeverAssumed) {
  TempDir dir{"tippe-self-check"};
  const Scene scene = load_scene(kScenes + "toy_viscous.toml", {"run.duration=5.5"});
  CompareOptions o = quiet({"analytic"});
  o.cache_dir = (dir.path() / "cache").string();
  const Comparison first = run_comparison(scene, o);
  ASSERT_TRUE(first.self_check);
  EXPECT_FALSE(first.reference_cached);
  EXPECT_FALSE(first.self_check_cached);
  // toy_viscous: an excursion of the stem below the resolution at t ~ 4.79.
  ASSERT_TRUE(first.self_check->converged_until);
  const fs::path entry = dir.path() / "cache" / physics_hash(scene);
  ASSERT_TRUE(fs::exists(entry / "self_check.json"));

  const Comparison second = run_comparison(scene, o);
  EXPECT_TRUE(second.reference_cached);
  EXPECT_TRUE(second.self_check_cached);
  EXPECT_EQ(to_json(*second.self_check), to_json(*first.self_check));
  EXPECT_EQ(second.engines[0].metrics.reference_converged_until, first.self_check->converged_until);

  // A cached reference without its self-check (an entry from before it, or one whose check was
  // lost) has the check run again, not assumed, and only the check: the reference's summary (its
  // own CPU time and date) stays as it was.
  const std::string summary = slurp(entry / "summary.json");
  fs::remove(entry / "self_check.json");
  const Comparison third = run_comparison(scene, o);
  EXPECT_TRUE(third.reference_cached);
  EXPECT_TRUE(slurp(entry / "summary.json") == summary) << "the cached reference was run again";
  ASSERT_TRUE(third.self_check);
  EXPECT_FALSE(third.self_check_cached);
  EXPECT_EQ(third.self_check->converged_until, first.self_check->converged_until);
  EXPECT_TRUE(fs::exists(entry / "self_check.json"));

  // A check made with another method does not match.
  json j = json::parse(slurp(entry / "self_check.json"));
  j["key"]["method"] = "bulirsch_stoer";
  write_file_atomic((entry / "self_check.json").string(), j.dump());
  EXPECT_FALSE(run_comparison(scene, o).self_check_cached);
}

TEST(SelfCheck, RecordsWithoutItStillRead) {
  // The published comparison.json files may predate the self-check; strip it from a new one too.
  for (const auto& entry : fs::directory_iterator(std::string(TIPPE_SOURCE_DIR) + "/reports")) {
    const fs::path f = entry.path() / "comparison.json";
    if (!fs::exists(f)) continue;
    EXPECT_NO_THROW(comparison_from_json(json::parse(slurp(f)))) << f;
  }
  const Scene scene = load_scene(kScenes + "source_dimensionless.toml", {"run.duration=0.5"});
  json j = to_json(run_comparison(scene, quiet({"analytic"})));
  j["reference"].erase("self_check");
  j["engines"][0]["metrics"].erase("reference_converged_until");
  const Comparison c = comparison_from_json(j);
  EXPECT_FALSE(c.self_check);
  EXPECT_FALSE(c.engines[0].metrics.reference_converged_until);
  EXPECT_NE(render_markdown(j).find("Reference self-check: not run"), std::string::npos);
  j["engines"][0]["metrics"]["reference_converged_until"] = -2.0;
  EXPECT_THROW(comparison_from_json(j), std::invalid_argument);
  j["engines"][0]["metrics"]["reference_converged_until"] = "later";
  EXPECT_THROW(comparison_from_json(j), json::exception);
}

}  // namespace

}  // namespace test_self_check
