// Tests of boundary searches in sweeps (harness/sweep/sweep_search.cpp): the bisection on synthetic criteria, the boundaries from records and in the report, bad input, and the shipped boundaries sweep (the plan's waves: test_sweep_search_plan.cpp).
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <functional>
#include <map>
#include <set>
#include <string>
#include <vector>

#include "harness/gating/gate.h"
#include "engines/core/simulator.h"
#include "harness/io/scene_io.h"
#include "harness/scene/resolve.h"
#include "harness/sweep/sweep.h"
#include "harness/sweep/sweep_search.h"
#include "tests/support/files.h"
#include "tests/support/process.h"
#include "harness/report/sweep_analysis.h"
#include "tests/support/fixtures.h"
#include "tests/support/sweep_searches.h"

namespace test_sweep_search {

namespace fs = std::filesystem;
using namespace tippe;
using nlohmann::json;

namespace {

const std::string& kSource = fixtures::kSourceDir;
const std::string& kBinary = fixtures::kTippeBinary;
const std::string kScenes = kSource + "/harness/scenes/";

using namespace tippe::fixtures;

// ---- the bisection on synthetic criteria ----------------------------------------------------

TEST(SweepSearch, CoarseGridIsOneValuePerDecadeWithExactEnds) {
  const std::vector<double> g = search_coarse_grid(search(1e-6, 1e-1, 0.05));
  ASSERT_EQ(g.size(), 6u);
  EXPECT_EQ(g.front(), 1e-6);
  EXPECT_EQ(g.back(), 1e-1);
  for (size_t k = 1; k < g.size(); ++k) EXPECT_NEAR(std::log10(g[k] / g[k - 1]), 1.0, 1e-6);
  SweepSearch s = search(1e-4, 2e-1, 0.05);
  s.per_decade = 3;
  const std::vector<double> h = search_coarse_grid(s);
  // log10(2e-1 / 1e-4) = 3.3 decades at 3 per decade: ceil(9.9) = 10 intervals.
  EXPECT_EQ(h.size(), 11u);
}

TEST(SweepSearch, FindsAKnownBoundaryToTheResolutionInLogarithmicRuns) {
  // The criterion holds up to B and fails above: a time step's safe region.
  for (const double boundary : {3.7e-3, 1.234e-5, 0.0999e-1, 2.0e-2}) {
    for (const double res : {0.2, 0.05, 0.01, 0.001}) {
      const SweepSearch s = search(1e-6, 1e-1, res);
      const Synthetic r = run_synthetic(s, [&](double v) { return v <= boundary; });
      ASSERT_EQ(r.replay.crossings.size(), 1u) << boundary;
      const SearchCrossing& c = r.replay.crossings[0];
      EXPECT_TRUE(c.lo_passes);
      EXPECT_TRUE(c.resolved);
      EXPECT_LE(c.lo, boundary);
      EXPECT_GT(c.hi, boundary);
      EXPECT_LT(std::log10(c.hi / c.lo), res) << "bracket " << c.lo << " .. " << c.hi;
      // 6 coarse runs, then one bisection of a decade: ceil(log2(1 / res)) halvings at most.
      const size_t bound = 6 + static_cast<size_t>(std::ceil(std::log2(1.0 / res)));
      EXPECT_LE(r.run.size(), bound) << "boundary " << boundary << " resolution " << res;
      // A dense ladder to the same resolution over the 5 decades has 5 / res + 1 values.
      EXPECT_GE((5.0 / res + 1) / static_cast<double>(r.run.size()), res <= 0.05 ? 5.0 : 1.0);
      // Waves: the coarse grid, then one per bisection step.
      EXPECT_EQ(r.waves, r.run.size() - 6 + 1);
    }
  }
}

TEST(SweepSearch, NoCrossingMeansAllSafeOrNoneSafe) {
  const Synthetic all = run_synthetic(search(1e-6, 1e-1, 0.05), [](double) { return true; });
  EXPECT_TRUE(all.replay.crossings.empty());
  EXPECT_EQ(all.run.size(), 6u);
  const Synthetic none = run_synthetic(search(1e-6, 1e-1, 0.05), [](double) { return false; });
  EXPECT_TRUE(none.replay.crossings.empty());
  EXPECT_EQ(none.run.size(), 6u);
}

TEST(SweepSearch, NonMonotonicCriterionHasEveryCrossingBisected) {
  // Safe below 3e-5, unsafe up to 2e-3, safe again to 4e-2 (a regime that comes and goes).
  const auto crit = [](double v) { return v < 3e-5 || (v > 2e-3 && v < 4e-2); };
  const Synthetic r = run_synthetic(search(1e-6, 1e-1, 0.05), crit);
  ASSERT_EQ(r.replay.crossings.size(), 3u);
  const double at[] = {3e-5, 2e-3, 4e-2};
  for (size_t k = 0; k < 3; ++k) {
    const SearchCrossing& c = r.replay.crossings[k];
    EXPECT_TRUE(c.resolved);
    EXPECT_LE(c.lo, at[k]);
    EXPECT_GE(c.hi, at[k]);
    EXPECT_EQ(c.lo_passes, k != 1);
  }
}

TEST(SweepSearch, IntegerSearchStaysOnWholeNumbersAndStopsAtNeighbours) {
  // An iteration count: the criterion holds from 37 up (fewer iterations are the softer side).
  SweepSearch s = search(1, 1000, 0.001);
  s.integer = true;
  const Synthetic r = run_synthetic(s, [](double v) { return v >= 37; });
  for (const auto& [text, ok] : r.run) {
    (void)ok;
    EXPECT_EQ(text.find_first_not_of("0123456789"), std::string::npos) << text;
  }
  ASSERT_EQ(r.replay.crossings.size(), 1u);
  EXPECT_EQ(r.replay.crossings[0].lo, 36);
  EXPECT_EQ(r.replay.crossings[0].hi, 37);
  EXPECT_TRUE(r.replay.crossings[0].resolved);
  // 4 coarse values, then 10..100 halved in log down to neighbours: a handful of runs.
  EXPECT_LE(r.run.size(), 4u + 7u);
  // A coarse grid finer than the integers runs each integer once.
  s = search(1, 3, 0.05);
  s.integer = true;
  s.per_decade = 20;
  EXPECT_EQ(search_coarse_grid(s), (std::vector<double>{1, 2, 3}));
}

TEST(SweepSearch, IntegerSearchOfAnIterationCountLoads) {
  TempDir dir;
  const SweepPlan plan = load_sweep(dir.write(
      "i.toml", "scenes = [\"" + kScenes + "toy.toml\"]\n[[setup]]\nname = \"ode-iterations\"\nengine = \"ode\"\n"
                "ladder.search = { key = \"engines.ode.iterations\", from = 2, to = 200, criterion = \"regime\" }\n"));
  const SweepSetup& u = plan.spec.setups[0];
  ASSERT_TRUE(u.search && u.search->integer);
  EXPECT_EQ(u.ladder_texts, (std::vector<std::string>{"2", "20", "200"}));
  EXPECT_EQ(boundary_quantity(u.ladder_key), "min_safe_iterations");
  // Written as floats, the same range is a search over real values.
  const SweepPlan f = load_sweep(dir.write(
      "f.toml", "scenes = [\"" + kScenes + "toy.toml\"]\n[[setup]]\nname = \"ode-step\"\nengine = \"ode\"\n"
                "ladder.search = { key = \"engines.ode.timestep\", from = 1e-3, to = 1e-1, criterion = \"regime\" }\n"));
  EXPECT_FALSE(f.spec.setups[0].search->integer);
}

// ---- records and the report's boundaries ----------------------------------------------------

TEST(SweepSearch, BoundariesFromRecordsGiveTheBracketRunsAndCost) {
  const SweepSearch s = search(1e-6, 1e-1, 0.05);
  std::vector<SweepRecord> records = synthetic_records(s, [](double v) { return v <= 3.7e-3; }, "toy_viscous", 0);
  const auto more = synthetic_records(s, [](double v) { return v < 3e-5 || (v > 2e-3 && v < 4e-2); }, "toy", 1);
  records.insert(records.end(), more.begin(), more.end());
  const std::vector<SearchBoundary> b = search_boundaries(records);
  ASSERT_EQ(b.size(), 2u);
  EXPECT_EQ(b[0].status, "found");
  EXPECT_TRUE(b[0].monotonic());
  EXPECT_EQ(b[0].quantity, "max_safe_timestep");
  ASSERT_TRUE(b[0].boundary && b[0].beyond);
  EXPECT_LE(*b[0].boundary, 3.7e-3);
  EXPECT_GT(*b[0].beyond, 3.7e-3);
  EXPECT_LT(std::log10(*b[0].beyond / *b[0].boundary), 0.05);
  EXPECT_EQ(b[0].runs, 11u);
  ASSERT_TRUE(b[0].cpu_seconds);
  EXPECT_DOUBLE_EQ(*b[0].cpu_seconds, 1e-4 / *b[0].boundary);
  // Not monotonic: reported so, with the conservative boundary (the first from the fine end).
  EXPECT_FALSE(b[1].monotonic());
  EXPECT_EQ(b[1].replay.crossings.size(), 3u);
  ASSERT_TRUE(b[1].boundary);
  EXPECT_LE(*b[1].boundary, 3e-5);
  EXPECT_GT(*b[1].beyond, 3e-5);

  const std::string md = render_sweep_markdown(records);
  EXPECT_NE(md.find("### Largest safe setting per engine"), std::string::npos) << md;
  EXPECT_NE(md.find("(not monotonic)"), std::string::npos) << md;
  EXPECT_NE(md.find("NOT MONOTONIC, 3 crossings"), std::string::npos) << md;
  // At the top of the report, before the setups' table.
  EXPECT_LT(md.find("## Boundaries"), md.find("| setup | engine | fixed settings"));
}

TEST(SweepSearch, RecordsCarryTheirSearchAndRefuseABadOne) {
  SweepRecord r;
  r.point_id = "0123456789abcdef";
  r.scene = "toy";
  r.setup = "ode-regime";
  r.engine = "ode";
  r.ladder_key = "engines.ode.timestep";
  r.ladder_value = 1e-3;
  r.ladder_label = "0.001";
  r.engine_version = r.git_commit = "x";
  r.search = search(1e-6, 1e-1, 0.05, "inversion_time_rel_error <= 0.01");
  r.search->per_decade = 2;
  const SweepRecord back = sweep_record_from_json(json::parse(to_jsonl(r)));
  ASSERT_TRUE(back.search);
  EXPECT_EQ(back.search->criterion, r.search->criterion);
  EXPECT_EQ(back.search->from, 1e-6);
  EXPECT_EQ(back.search->per_decade, 2);
  json j = to_json(r);
  j["search"]["criterion"] = "wall_seconds <= 1";
  try {
    sweep_record_from_json(j);
    FAIL() << "accepted a timing criterion";
  } catch (const SweepRecordError& e) {
    EXPECT_EQ(std::string(e.what()).rfind("search.criterion: ", 0), 0u) << e.what();
  }
  j = to_json(r);
  j["search"]["to"] = 1e-7;
  EXPECT_THROW(sweep_record_from_json(j), SweepRecordError);
}

// ---- bad input ------------------------------------------------------------------------------

TEST(SweepSearchInput, BadSearchNamesFileKeyAndReason) {
  const std::string head = "scenes = [\"" + kScenes + "toy.toml\"]\n[[setup]]\nname = \"s\"\nengine = \"ode\"\n";
  const std::string ok = "key = \"engines.ode.timestep\", from = 1e-4, to = 1e-1, criterion = \"regime\"";
  const struct {
    std::string ladder, key, reason;
  } cases[] = {
      {"ladder.search = { key = \"engines.ode.timestep\", from = 0, to = 1e-1, criterion = \"regime\" }",
       "setup[0].ladder.search.from", "0 is out of range (expected from > 0: the search is in log10)"},
      {"ladder.search = { key = \"engines.ode.timestep\", from = 1e-2, to = 1e-3, criterion = \"regime\" }",
       "setup[0].ladder.search.to", "0.001 is out of range (expected to > from = 0.01)"},
      {"ladder.search = { key = \"engines.ode.timestep\", from = 1e-4, criterion = \"regime\" }",
       "setup[0].ladder.search.to", "missing (required)"},
      {"ladder.search = { key = \"engines.ode.timestep\", from = 1e-4, to = 1e-1 }", "setup[0].ladder.search.criterion",
       "missing (required)"},
      {"ladder.search = { key = \"engines.ode.timestep\", from = 1e-4, to = 1e-1, criterion = \"tilt_rms_error\" }",
       "setup[0].ladder.search.criterion", "\"tilt_rms_error\" is not a bound"},
      {"ladder.search = { key = \"engines.ode.timestep\", from = 1e-4, to = 1e-1, criterion = \"wall_seconds <= 1\" }",
       "setup[0].ladder.search.criterion", "wall_seconds: timing is never gated"},
      {"ladder.search = { key = \"engines.ode.timestep\", from = 1e-4, to = 1e-1, criterion = \"tilt <= 1\" }",
       "setup[0].ladder.search.criterion", "tilt: unknown metric"},
      {"ladder.search = { key = \"engines.ode.timestep\", from = 1e-4, to = 1e-1, criterion = \"tilt_rms_error >= 1\" }",
       "setup[0].ladder.search.criterion", "a metric is bounded from above"},
      {"ladder.search = { key = \"engines.ode.timestep\", from = 1e-4, to = 1e-1, criterion = \"tilt_rms_error <= -1\" }",
       "setup[0].ladder.search.criterion", "-1 is out of range (expected tilt_rms_error >= 0"},
      {"ladder.search = { key = \"engines.ode.timestep\", from = 1e-4, to = 1e-1, criterion = \"tilt_rms_error <= x\" }",
       "setup[0].ladder.search.criterion", "\"x\" after <= is not a finite number"},
      {"ladder.search = { " + ok + ", resolution = 0 }", "setup[0].ladder.search.resolution",
       "0 is out of range (expected 0.001 <= resolution <= 1.0, in log10 units)"},
      {"ladder.search = { " + ok + ", per_decade = 1.5 }", "setup[0].ladder.search.per_decade",
       "expected an integer (1 <= per_decade <= 20)"},
      {"ladder.search = { " + ok + ", step = 2 }", "setup[0].ladder.search.step", "unknown key"},
      {"ladder.search = { key = \"engines.bullet.timestep\", from = 1e-4, to = 1e-1, criterion = \"regime\" }",
       "setup[0].ladder.search.key", "is not a setting of ode"},
      {"ladder = { search = { " + ok + " }, values = [1e-3] }", "setup[0].ladder.values",
       "unknown key (expected one of: search)"},
      {"ladder.search = 3", "setup[0].ladder.search", "expected a table"},
      {"ladder.search = { key = \"engines.ode.timestep\", from = 1e-30, to = 1e-1, criterion = \"regime\" }",
       "setup[0].ladder.search.to", "decades above from"},
      {"set = [\"engines.ode.timestep=1e-3\"]\nladder.search = { " + ok + " }", "setup[0].ladder.search.key",
       "engines.ode.timestep is also fixed in setup[0].set"},
      // The engine's own range (timestep <= 0.1) refuses the search's end.
      {"ladder.search = { key = \"engines.ode.timestep\", from = 1e-4, to = 1, criterion = \"regime\" }",
       "setup[0].ladder.search.to", "engines.ode.timestep: value 1 outside [1e-08, 0.1]"},
      {"ladder.search = { key = \"engines.ode.timestepx\", from = 1e-4, to = 1e-1, criterion = \"regime\" }",
       "setup[0].ladder.search.from", "timestepx"},
  };
  TempDir dir;
  for (const auto& c : cases) {
    const std::string file = dir.write("bad.toml", head + c.ladder + "\n");
    try {
      load_sweep(file);
      ADD_FAILURE() << "accepted: " << c.ladder;
    } catch (const SceneError& e) {
      const std::string prefix = file + ": " + c.key + ": ";
      const std::string what = e.what();
      EXPECT_EQ(what.rfind(prefix, 0), 0u) << what;
      EXPECT_NE(what.find(c.reason), std::string::npos) << what;
    }
  }
  // Through the command: exit 2, the message on stderr, nothing written.
  const std::string file = dir.write("bad.toml", head + cases[4].ladder + "\n");
  const fs::path out = dir.path() / "out", err = dir.path() / "err.txt";
  const ChildExit e = wait_process(spawn_process({kBinary, "sweep", file, "--out", out.string()}, "/dev/null", err));
  EXPECT_EQ(e.code, 2);
  EXPECT_NE(slurp(err).find(file + ": setup[0].ladder.search.criterion: "), std::string::npos) << slurp(err);
  EXPECT_FALSE(fs::exists(out));
}

TEST(SweepSearchInput, BoundTextIsTheGatesThreshold) {
  const Threshold t = parse_threshold_text("  inversion_time_rel_error<=0.01 ");
  EXPECT_EQ(t.metric, "inversion_time_rel_error");
  EXPECT_EQ(t.max, 0.01);
  const BoundText b = parse_bound_text("max_safe_timestep >= 1e-4");
  EXPECT_EQ(b.name, "max_safe_timestep");
  EXPECT_EQ(b.op, ">=");
  EXPECT_EQ(b.bound, 1e-4);
  EXPECT_THROW(parse_bound_text("a <= 1 >= 2"), std::invalid_argument);
  EXPECT_THROW(parse_bound_text("<= 1"), std::invalid_argument);
  EXPECT_THROW(parse_bound_text("a <= inf"), std::invalid_argument);
}

// ---- the shipped boundaries sweep ------------------------------------------------------------

TEST(SweepSearchShipped, BoundariesCoverEveryEngineAndEveryShippedScene) {
  const SweepPlan plan = load_sweep(kSource + "/harness/sweeps/boundaries.toml");
  std::set<std::string> scenes;
  for (const Scene& s : plan.scenes) scenes.insert(s.name);
  for (const auto& f : fs::directory_iterator(kSource + "/harness/scenes")) {
    if (f.path().extension() != ".toml") continue;
    EXPECT_TRUE(scenes.count(load_scene(f.path().string()).name)) << f.path() << " is not in boundaries.toml";
  }
  std::set<std::string> regime, inversion;
  for (const SweepSetup& u : plan.spec.setups) {
    ASSERT_TRUE(u.search) << u.name;
    EXPECT_EQ(u.search->resolution, 0.05);
    if (u.search->criterion == "regime") {
      EXPECT_TRUE(u.only_scenes.empty()) << u.name << ": the regime is asked on every scene";
      regime.insert(u.engine);
    } else {
      EXPECT_EQ(u.search->criterion, "inversion_time_rel_error <= 0.01");
      // Where the reference inverts (reports/<scene>/report.md): the others would be n/a.
      EXPECT_EQ(u.only_scenes, (std::vector<std::string>{"source_dimensionless", "toy_viscous", "rutstam_ball",
                                                          "rutstam_gliding_ball", "leine_glocker_coupled",
                                                          "leine_glocker_twin_coupled"}));
      inversion.insert(u.engine);
    }
  }
  for (const std::string& e : available_engines()) {
    if (e == "analytic") continue;
    EXPECT_TRUE(regime.count(e)) << e << " has no regime search";
    EXPECT_TRUE(inversion.count(e)) << e << " has no inversion-time search";
  }
  // Planned up front: the coarse grids (5 values over 4 decades) of 12 scenes x every engine's
  // regime search and 6 x every engine's inversion search.
  const size_t engines = engine_names().size();
  EXPECT_EQ(plan.planned, 5u * (12 * engines + 6 * engines));
}

TEST(SweepSearchInput, SetupScenesNameScenesOfTheSweep) {
  TempDir dir;
  std::string text = sweep_text();
  text.replace(text.find("name = \"ode-ladder\""), 19, "name = \"ode-ladder\"\nscenes = [\"toy_viscous\"]");
  const SweepPlan plan = load_sweep(dir.write("s.toml", text));
  size_t ladder_points = 0;
  for (const SweepPoint& p : plan.points)
    if (plan.spec.setups[p.setup_index].name == "ode-ladder") {
      ++ladder_points;
      EXPECT_EQ(p.scene.name, "toy_viscous");
    }
  EXPECT_EQ(ladder_points, 2u);
  text = sweep_text();
  text.replace(text.find("name = \"ode-ladder\""), 19, "name = \"ode-ladder\"\nscenes = [\"toy\", \"nope\"]");
  const std::string file = dir.write("bad.toml", text);
  try {
    load_sweep(file);
    FAIL() << "accepted an unknown scene";
  } catch (const SceneError& e) {
    EXPECT_EQ(std::string(e.what()), file + ": setup[2].scenes[1]: \"nope\" is not the name of a scene of this sweep "
                                            "(expected one of: toy, toy_viscous)");
  }
}

}  // namespace

}  // namespace test_sweep_search
