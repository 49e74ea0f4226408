// `tippe advise` end to end on a scene written for the tests (advice found, nothing in range, the written gate), and the one criterion of "safe" read the same by the search, the page's sentence, a gate and advise.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <set>
#include <string>
#include <vector>

#include "harness/advise/advise.h"
#include "harness/advise/advice_record.h"
#include "harness/gating/gate_boundary.h"
#include "engines/core/registry.h"
#include "harness/report/sweep_analysis.h"
#include "tests/support/files.h"
#include "tests/support/fixtures.h"
#include "tests/support/process.h"
#include "harness/sweep/sweep_search.h"

namespace test_advise {

namespace fs = std::filesystem;
using namespace tippe;
using nlohmann::json;

namespace {

const std::string& kSource = fixtures::kSourceDir;
const std::string& kBinary = fixtures::kTippeBinary;
const std::string kScene = kSource + "/tests/data/advise_flip.toml";

ChildExit run(const std::vector<std::string>& argv, const fs::path& out, const fs::path& err) {
  return wait_process(spawn_process(argv, out, err));
}

// ODE in one configuration (dWorldStep, finite rotation) on the test scene, the inversion within
// 10 %: the scene's own step (1e-3) gains energy and inverts 28 % early, 1e-4 inverts 4 % early
// and gains none, coarser steps leave the regime and diverge.
std::vector<std::string> advise_ode(const fs::path& dir, const std::string& from, const std::string& to) {
  return {kBinary, "advise", kScene, "--engines", "ode", "--axis", "ode.stepper=\"step\"", "--axis",
          "ode.finite_rotation=true", "--from", from, "--to", to, "--tolerance", "10%", "--jobs", "2", "--no-plots", "--quiet",
          "--out", dir.string()};
}

TEST(Advise, FindsTheBoundaryInLogRunsAndWritesAGateThatHolds) {
  TempDir dir;
  const fs::path out = dir.path() / "advice", log = dir.path() / "out.txt", err = dir.path() / "err.txt";
  ChildExit e = run(advise_ode(out, "1e-4", "1e-1"), log, err);
  ASSERT_EQ(e.code, 0) << slurp(err);
  const std::string text = slurp(log);
  EXPECT_NE(text.find("ode: stepper = step, finite_rotation = true, timestep "), std::string::npos) << text;
  ASSERT_TRUE(fs::exists(out / "advice.toml")) << text;
  ASSERT_TRUE(fs::exists(out / "index.html"));
  const std::string md = slurp(out / "index.md");
  EXPECT_EQ(md.find("ode: stepper = step"), md.find("ode: ")) << "the page opens with the engine's sentence\n" << md;
  // The page states its one "safe" once, with the energy the gain rule counts (the scene's default).
  EXPECT_NE(md.find("counting E plus the elastic energy the contact stores where the engine's contact law gives it "
                    "(energy_gain_rule = stored)"),
            std::string::npos)
      << md;

  const std::vector<SweepRecord> records = read_records((out / "sweep" / "records.jsonl").string()).records;
  const std::vector<SearchBoundary> b = search_boundaries(records);
  ASSERT_EQ(b.size(), 1u);
  ASSERT_EQ(b[0].status, "found");
  ASSERT_TRUE(b[0].boundary && b[0].beyond);
  EXPECT_LT(std::log10(*b[0].beyond / *b[0].boundary), 0.05) << "the bracket is within the resolution";
  // O(log) runs: 4 coarse values over 3 decades, then one decade bisected to 0.05 (5 steps).
  EXPECT_LE(records.size(), 4u + 5u);

  // The confirming run at the boundary / 2 is safe under the one criterion.
  const std::vector<SweepRecord> confirm = read_records((out / "confirm" / "records.jsonl").string()).records;
  ASSERT_EQ(confirm.size(), 1u);
  const SearchCriterion c = parse_criterion("regime and inversion within 10%");
  EXPECT_TRUE(is_safe(c, confirm[0])) << unsafe_reason(c, confirm[0]);
  EXPECT_EQ(confirm[0].ladder_value, search_round(*b[0].boundary / kAdviceMargin));
  // Its cost, which chooses among configurations, is the least of its three runs (the default
  // --repeats), not one run's: the searches' points run once.
  EXPECT_EQ(confirm[0].repeats, 3);
  ASSERT_EQ(confirm[0].cpu_seconds_repeats.size(), 3u);
  EXPECT_EQ(confirm[0].cpu_seconds,
            *std::min_element(confirm[0].cpu_seconds_repeats.begin(), confirm[0].cpu_seconds_repeats.end()));
  for (const SweepRecord& r : records) EXPECT_EQ(r.repeats, 1) << r.point_id;
  EXPECT_NE(md.find(" CPU s (the least of 3 runs)"), std::string::npos) << md;

  // The record says what the page and the gate say.
  const json advice = json::parse(slurp(out / "advice.json"));
  EXPECT_EQ(advice.at("format"), kAdviceFormat);
  ASSERT_EQ(advice.at("engines").size(), 1u);
  const json& ode = advice.at("engines").at(0);
  EXPECT_EQ(ode.at("engine"), "ode");
  EXPECT_EQ(ode.at("advised_step").get<double>(), confirm[0].ladder_value);
  EXPECT_EQ(ode.at("largest_safe_step").get<double>(), *b[0].boundary);
  EXPECT_EQ(ode.at("settings").back(), "engines.ode.timestep=" + search_value_text(confirm[0].ladder_value));
  EXPECT_EQ(ode.at("confirm_point"), confirm[0].point_id);
  EXPECT_EQ(ode.at("cpu_seconds").get<double>(), confirm[0].cpu_seconds);
  EXPECT_EQ(advice.at("repeats"), 3);
  // 4 coarse values and the bisection (the points above), each once, and the confirming point 3 times.
  EXPECT_EQ(advice.at("runs").get<size_t>(), records.size() + 3);
  EXPECT_TRUE(ode.at("reason").is_null());
  EXPECT_TRUE(advice.at("gate_written").get<bool>());
  // Every configuration searched, with what its search found (the page's table).
  ASSERT_EQ(ode.at("searched").size(), 1u);
  const json& searched = ode.at("searched").at(0);
  EXPECT_EQ(searched.at("status"), "found");
  EXPECT_EQ(searched.at("largest_safe_step").get<double>(), *b[0].boundary);
  EXPECT_EQ(searched.at("first_unsafe_step").get<double>(), *b[0].beyond);
  EXPECT_EQ(searched.at("runs").get<size_t>(), records.size());
  EXPECT_EQ(ode.at("not_searched"), json::array());

  // The gate passes as written ...
  const fs::path gate = out / "advice.toml";
  e = run({kBinary, "gate", gate.string(), "--quiet", "--boundary-out", (dir.path() / "g1").string()}, log, err);
  EXPECT_EQ(e.code, 0) << slurp(log) << slurp(err);
  // ... and fails with its step raised past the boundary (to the first unsafe value).
  const std::string g = slurp(gate);
  const std::string step = search_value_text(confirm[0].ladder_value);
  const std::string pinned = "engines.ode.timestep=" + step;
  ASSERT_NE(g.find(pinned), std::string::npos) << g;
  std::string raised = g;
  raised.replace(raised.find(pinned), pinned.size(), "engines.ode.timestep=" + search_value_text(*b[0].beyond));
  spit(gate, raised);
  e = run({kBinary, "gate", gate.string(), "--quiet", "--boundary-out", (dir.path() / "g2").string()}, log, err);
  EXPECT_EQ(e.code, 1) << slurp(log) << slurp(err);
  EXPECT_NE(slurp(log).find("ode-advised"), std::string::npos) << slurp(log);
}

TEST(Advise, NothingSafeInRangeSaysSoAndPinsNoGate) {
  TempDir dir;
  const fs::path out = dir.path() / "advice", log = dir.path() / "out.txt", err = dir.path() / "err.txt";
  // Every step from 0.03 to 0.1 leaves the regime and diverges (the boundary is near 2.5e-4).
  ChildExit e = run(advise_ode(out, "0.03", "0.1"), log, err);
  ASSERT_EQ(e.code, 0) << slurp(err);
  const std::string text = slurp(log);
  EXPECT_NE(text.find("ode: no advice: no configuration is safe at any timestep in the searched range"), std::string::npos)
      << text;
  EXPECT_NE(text.find("gate: none"), std::string::npos) << text;
  EXPECT_FALSE(fs::exists(out / "advice.toml"));
  EXPECT_NE(slurp(out / "index.md").find("no advice"), std::string::npos);
}

// --repeats outside 1..kMaxRepeats is a usage error before anything runs or is written.
TEST(Advise, RepeatsOutOfRangeIsAnErrorAndWritesNothing) {
  TempDir dir;
  const fs::path log = dir.path() / "out.txt", err = dir.path() / "err.txt";
  for (const std::string bad : {"0", "101", "x"}) {
    const fs::path out = dir.path() / ("advice-" + bad);
    std::vector<std::string> argv = advise_ode(out, "1e-4", "1e-1");
    argv.insert(argv.begin() + 2, {"--repeats", bad});
    const ChildExit e = run(argv, log, err);
    EXPECT_EQ(e.code, 2) << bad << ": " << slurp(err);
    EXPECT_NE(slurp(err).find("--repeats"), std::string::npos) << slurp(err);
    EXPECT_FALSE(fs::exists(out)) << bad;
  }
}

TEST(Advise, ConfigurationsComeFromTheRegistry) {
  // Every combination of the axes each engine declares, the engine's defaults first.
  for (const std::string& n : engine_names()) {
    const EngineInfo& e = engine_info(n);
    size_t combos = 1;
    for (const SettingAxis& a : e.advice_axes) combos *= a.values.size();
    const std::vector<AdviceConfig> c = advice_configs(n, {});
    EXPECT_EQ(c.size(), combos) << n;
    EXPECT_FALSE(e.cost_knob.empty()) << n << " declares no cost knob";
    std::set<std::string> setups;
    for (const AdviceConfig& x : c) EXPECT_TRUE(setups.insert(x.setup).second) << x.setup;
  }
  const std::vector<AdviceConfig> m = advice_configs("mujoco", {"mujoco.integrator=\"Euler\"", "ode.stepper=\"step\""});
  ASSERT_EQ(m.size(), 4u) << "the integrator fixed, the cone and noslip free; another engine's axis ignored";
  EXPECT_EQ(m.front().text(), "integrator = Euler, cone = elliptic, noslip_iterations = 0");
  EXPECT_EQ(m.front().set().front(), "engines.mujoco.integrator=\"Euler\"");
  EXPECT_THROW(advice_configs("mujoco", {"mujoco.nope=1"}), std::invalid_argument);
  EXPECT_THROW(advice_configs("mujoco", {"mujoco.cone="}), std::invalid_argument);
}

// ---- one criterion: the same records give the same answer everywhere -------------------------

SweepRecord rec(double dt, double cpu, const std::string& run_class, std::optional<double> inversion_error) {
  SweepRecord r;
  r.point_id = "p" + std::to_string(dt);
  r.scene = "s";
  r.engine = r.setup = "mujoco";
  r.ladder_key = "engines.mujoco.timestep";
  r.ladder_value = dt;
  r.ladder_label = search_value_text(dt);
  r.cpu_seconds = cpu;
  r.steps = static_cast<long long>(1 / dt);
  r.run_class = run_class;
  r.reference_inversion_time = 10.0;
  if (inversion_error) {
    r.inversion_time = 10.0 * (1 + *inversion_error);
    r.metrics.inversion_event = "both";
    r.metrics.inversion_time_rel_error = inversion_error;
  } else {
    r.metrics.inversion_event = "reference_only";
  }
  SweepSearch s;
  s.criterion = "regime and inversion within 1%";
  s.from = 1e-5;
  s.to = 1e-1;
  s.resolution = 0.6;
  r.search = s;
  return r;
}

TEST(OneCriterion, SearchSentenceAndAdviceAgreeOnTheSameRecords) {
  // The contradiction: a status-only search said 1e-2 was safe while the page's sentence,
  // reading the stability map, chose 1e-5. Here 1e-3 and coarser are classed unphysical (an
  // energy gain) though they invert within 1 %, and 1e-1 leaves the regime.
  const std::vector<SweepRecord> rs = {rec(1e-5, 9.0, "ok", 0.001), rec(1e-4, 1.0, "ok", 0.002),
                                       rec(1e-3, 0.1, "unphysical", 0.003), rec(1e-2, 0.01, "unphysical", 0.005),
                                       rec(1e-1, 0.001, "ok", std::nullopt),
                                       // the bisection points of the crossing 1e-4 .. 1e-3 at resolution 0.6 (one halves it to 0.5)
                                       rec(search_round(std::pow(10.0, -3.5)), 0.3, "unphysical", 0.002)};
  const std::vector<SearchBoundary> b = search_boundaries(rs);
  ASSERT_EQ(b.size(), 1u);
  ASSERT_EQ(b[0].status, "found");
  EXPECT_DOUBLE_EQ(*b[0].boundary, 1e-4) << "the search's boundary";

  // The page's "setting to use" picks the same point, by the same predicate.
  const long long i = cheapest_safe(rs, setting_criterion(true, 0.01));
  ASSERT_GE(i, 0);
  EXPECT_DOUBLE_EQ(rs[static_cast<size_t>(i)].ladder_value, 1e-4);
  const std::string md = render_sweep_markdown(rs);
  EXPECT_NE(md.find("timestep = 0.0001 (the cheapest safe within 1 %"), std::string::npos) << md;

  // A gate on the boundary: >= 1e-4 passes, >= 1e-3 fails.
  BoundaryCheck gc;
  gc.name = "g";
  gc.setup = "mujoco";
  gc.scene = "s";
  gc.require = parse_bound_text("max_safe_timestep >= 1e-4");
  EXPECT_TRUE(evaluate_boundary(gc, rs).passed);
  gc.require = parse_bound_text("max_safe_timestep >= 1e-3");
  EXPECT_FALSE(evaluate_boundary(gc, rs).passed);

  // advise's choice on the same records: the configuration's boundary 1e-4, confirmed at 5e-5.
  AdviceEngine e;
  e.engine = "mujoco";
  e.knob = "timestep";
  AdviceConfig cfg;
  cfg.engine = "mujoco";
  cfg.setup = "mujoco";
  e.configs = {cfg};
  e.boundaries = b;
  SweepRecord confirm = rec(5e-5, 2.0, "ok", 0.0015);
  choose_advice(e, parse_criterion("regime and inversion within 1%"), {confirm});
  ASSERT_TRUE(e.chosen);
  EXPECT_DOUBLE_EQ(e.boundary, 1e-4);
  // And a confirming run the class rejects gives no advice.
  confirm.run_class = "unphysical";
  choose_advice(e, parse_criterion("regime and inversion within 1%"), {confirm});
  EXPECT_FALSE(e.chosen);
}

// The advice is the cheapest confirmed configuration; those confirmed safe within 10 % of its
// CPU time are named beside it (as the sweep page names its ties), cheapest first; one 20 % dearer
// and one whose confirming run is not safe are not.
TEST(OneCriterion, AdviceNamesTheConfigurationsItDoesNotTellApart) {
  AdviceEngine e;
  e.engine = "mujoco";
  e.knob = "timestep";
  std::vector<SweepRecord> confirm;
  const std::vector<std::pair<double, std::string>> runs = {{1.0, "ok"}, {1.2, "ok"}, {1.08, "ok"}, {1.02, "unphysical"}, {1.05, "ok"}};
  for (size_t i = 0; i < runs.size(); ++i) {
    AdviceConfig cfg;
    cfg.engine = "mujoco";
    cfg.setup = "mujoco-" + std::to_string(i);
    cfg.keys = {"cone"};
    cfg.values = {"\"c" + std::to_string(i) + "\""};
    e.configs.push_back(cfg);
    SearchBoundary b;
    b.status = "found";
    b.boundary = 1e-3;
    e.boundaries.push_back(b);
    SweepRecord r = rec(5e-4, runs[i].first, runs[i].second, 0.001);
    r.setup = cfg.setup;
    confirm.push_back(r);
  }
  choose_advice(e, parse_criterion("regime and inversion within 1%"), confirm);
  ASSERT_TRUE(e.chosen);
  EXPECT_EQ(*e.chosen, 0u);
  ASSERT_EQ(e.ties.size(), 2u);
  EXPECT_EQ(e.ties[0].config, 4u);
  EXPECT_EQ(e.ties[1].config, 2u);
  EXPECT_EQ(advice_ties_text(e), (std::vector<std::string>{"cone = c4, timestep 0.0005 (1.05 CPU s)",
                                                           "cone = c2, timestep 0.0005 (1.08 CPU s)"}));
  EXPECT_EQ(advice_record(AdviceResult{"s", "c", true, 10.0, 1.0, {e}, 5, false}).engines.at(0).near_ties,
            advice_ties_text(e));
}

TEST(OneCriterion, ParsesAndPrintsItsTerms) {
  const SearchCriterion c = parse_criterion("regime and inversion within 1% and tilt_rms_error <= 0.05");
  EXPECT_TRUE(c.regime);
  ASSERT_TRUE(c.inversion);
  EXPECT_DOUBLE_EQ(*c.inversion, 0.01);
  ASSERT_EQ(c.bounds.size(), 1u);
  EXPECT_EQ(criterion_text(c), "regime and inversion within 1% and tilt_rms_error <= 0.05");
  EXPECT_TRUE(parse_criterion("regime").regime);
  EXPECT_FALSE(parse_criterion("tilt_rms_error <= 0.1").regime);
  EXPECT_THROW(parse_criterion("regime and"), std::invalid_argument);
  EXPECT_THROW(parse_criterion("inversion within -1%"), std::invalid_argument);
  EXPECT_THROW(parse_criterion("nonsense <= 1"), std::invalid_argument);
}

}  // namespace

// advice.json writes exactly the fields of its two lists (advice_record.h), an engine without
// advice with nulls where the advice would be and its reason.
TEST(AdviceRecord, WritesExactlyItsListedFields) {
  AdviceResult r;
  r.scene_name = "toy";
  r.criterion = "regime";
  r.duration = 5;
  r.runs = 12;
  r.gate_written = true;
  AdviceEngine chosen;
  chosen.engine = "mujoco";
  chosen.knob = "timestep";
  chosen.configs.push_back({"mujoco", "mujoco-0", {"integrator"}, {"\"RK4\""}});
  chosen.chosen = 0;
  chosen.step = 2e-4;
  chosen.boundary = 4e-4;
  chosen.beyond = 0;  // safe to the end of the range
  chosen.cpu_seconds = 0.5;
  chosen.confirm_point = "p1";
  chosen.configs.push_back({"mujoco", "mujoco-1", {"integrator"}, {"\"Euler\""}});
  chosen.unsearched.push_back({"mujoco", "mujoco-2", {"integrator"}, {"\"implicit\""}});
  SearchBoundary found;
  found.status = "found";
  found.boundary = 4e-4;
  found.runs = 9;
  chosen.boundaries = {found};  // the second configuration's search has no records yet
  AdviceEngine none;
  none.engine = "ode";
  none.knob = "timestep";
  none.reason = "no configuration is safe in the searched range";
  r.engines = {chosen, none};

  const json j = to_json(advice_record(r));
  std::set<std::string> keys, listed = {"format"};
  for (const auto& [k, v] : j.items()) keys.insert(k);
  for (const FieldInfo& f : field_list<AdviceRecord>()) listed.insert(f.key);
  EXPECT_EQ(keys, listed);
  std::set<std::string> engine_keys, engine_listed;
  for (const auto& [k, v] : j.at("engines").at(0).items()) engine_keys.insert(k);
  for (const FieldInfo& f : field_list<EngineAdvice>()) engine_listed.insert(f.key);
  EXPECT_EQ(engine_keys, engine_listed);
  std::set<std::string> searched_keys, searched_listed;
  for (const auto& [k, v] : j.at("engines").at(0).at("searched").at(0).items()) searched_keys.insert(k);
  for (const FieldInfo& f : field_list<SearchedConfiguration>()) searched_listed.insert(f.key);
  EXPECT_EQ(searched_keys, searched_listed);

  const json& m = j.at("engines").at(0);
  EXPECT_EQ(m.at("configuration"), "integrator = RK4");
  EXPECT_EQ(m.at("settings"), json({"engines.mujoco.integrator=\"RK4\"", "engines.mujoco.timestep=0.0002"}));
  EXPECT_EQ(m.at("advised_step"), 2e-4);
  EXPECT_TRUE(m.at("first_unsafe_step").is_null());
  EXPECT_TRUE(m.at("reason").is_null());
  // Each searched configuration with its search's outcome (none yet for the second), then the
  // ones the budget left out.
  ASSERT_EQ(m.at("searched").size(), 2u);
  EXPECT_EQ(m.at("searched").at(0).at("configuration"), "integrator = RK4");
  EXPECT_EQ(m.at("searched").at(0).at("status"), "found");
  EXPECT_EQ(m.at("searched").at(0).at("largest_safe_step"), 4e-4);
  EXPECT_TRUE(m.at("searched").at(0).at("first_unsafe_step").is_null());
  EXPECT_EQ(m.at("searched").at(0).at("runs"), 9);
  EXPECT_EQ(m.at("searched").at(1).at("settings"), json({"engines.mujoco.integrator=\"Euler\""}));
  EXPECT_TRUE(m.at("searched").at(1).at("status").is_null());
  EXPECT_TRUE(m.at("searched").at(1).at("largest_safe_step").is_null());
  EXPECT_EQ(m.at("not_searched"), json({"integrator = implicit"}));
  const json& o = j.at("engines").at(1);
  EXPECT_TRUE(o.at("configuration").is_null());
  EXPECT_TRUE(o.at("advised_step").is_null());
  EXPECT_EQ(o.at("reason"), none.reason);
  EXPECT_TRUE(j.at("reference_inversion_time").is_null());
}

}  // namespace test_advise
