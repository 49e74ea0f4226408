// Tests of `tippe compare`: the metrics on synthetic trajectories, the report on fixture records, and the command end to end.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <regex>
#include <set>
#include <sstream>

#include "harness/measure/compare.h"
#include "harness/report/gnuplot.h"
#include "harness/records/records.h"
#include "harness/report/report.h"
#include "harness/io/scene_io.h"
#include "harness/scene/resolve.h"
#include "tests/support/files.h"

namespace fs = std::filesystem;
using namespace tippe;
using nlohmann::json;

namespace {

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

// A scene built in code: R = 2 so that path errors divided by R are told apart from raw ones.
Scene test_scene() {
  Scene s;
  s.name = "fixture";
  s.description = "fixture <scene> & \"quotes\"";
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

// Samples t_k = k dt, k = 0..n-1, with every column from one function of t.
struct Columns {
  std::function<double(double)> theta = [](double) { return 0.1; };
  std::function<double(double)> energy = [](double) { return 10.0; };
  std::function<double(double)> jellett = [](double) { return -1.5; };
  std::function<double(double)> normal_force = [](double) { return 9.81; };
  std::function<double(double)> x_C = [](double) { return 0.0; };
  std::function<double(double)> y_C = [](double) { return 0.0; };
  std::function<double(double)> x_G = [](double) { return 0.0; };
  std::function<double(double)> y_G = [](double) { return 0.0; };
  std::function<double(double)> latitude = [](double) { return 0.1; };
};

Observation observation_at(double t, const Columns& c) {
  Observation o;
  o.state.t = t;
  o.state.p_WG = Vec3(c.x_G(t), c.y_G(t), 1.0);
  o.theta = c.theta(t);
  o.surface = Surface::Ball;
  o.p_WC = Vec3(c.x_C(t), c.y_C(t), 0.0);
  o.normal_force = c.normal_force(t);
  o.energy = c.energy(t);
  o.jellett = c.jellett(t);
  o.contact_latitude = c.latitude(t);
  return o;
}

Trajectory make_traj(size_t n, double dt, const Columns& c, double t0 = 0.0) {
  Trajectory tr;
  for (size_t k = 0; k < n; ++k) tr.append(observation_at(t0 + static_cast<double>(k) * dt, c));
  return tr;
}

RunRecord make_record(const std::string& engine, std::optional<double> inversion, std::optional<double> stem,
                      double cpu = 1.0) {
  RunRecord r;
  r.scene_name = "fixture";
  r.scene_file = "fixture.toml";
  r.scene_hash = "0123456789abcdef";
  r.scene_spec = scene_to_json(test_scene());
  r.engine = engine;
  r.engine_version = engine + " 1.0";
  r.inversion_time = inversion;
  r.stem_contact_time = stem;
  if (inversion) r.events.push_back({"inversion", *inversion, "theta crosses 90 deg", 0.0});
  if (stem) r.events.push_back({"stem_contact", *stem, "first stem contact", 0.0});
  r.settings = {{"timestep", "0.0001"}, {"note<&>", "value with <tags> & ampersands"}};
  r.work.steps = 1000;
  r.work.cpu_seconds = cpu;
  r.work.wall_seconds = cpu;
  r.samples = 201;
  r.final_time = 2.0;
  r.energy_initial = 10.0;
  r.energy_final = 9.0;
  r.jellett_initial = -1.5;
  r.jellett_max_relative_drift = 1e-6;
  r.jellett_drift_ball = 1e-6;
  r.provenance = current_provenance();
  return r;
}

// ---- metrics --------------------------------------------------------------------------------

TEST(Metrics, ShiftedCopyGivesKnownTiltAndEventErrors) {
  const Scene scene = test_scene();
  Columns ref_c, eng_c;
  ref_c.theta = [](double t) { return 0.3 + 0.8 * t; };
  eng_c.theta = [](double t) { return 0.3 + 0.8 * (t - 0.05); };  // the same motion 0.05 later
  const Trajectory ref = make_traj(201, 0.01, ref_c), eng = make_traj(201, 0.01, eng_c);
  const Metrics m = compare_runs(make_record("analytic", 1.5, 1.8), ref, make_record("ode", 1.55, 1.71), eng, scene);
  EXPECT_NEAR(m.tilt_max_error, 0.04, 1e-12);
  EXPECT_NEAR(m.tilt_rms_error, 0.04, 1e-12);
  EXPECT_EQ(m.inversion_event, "both");
  ASSERT_TRUE(m.inversion_time_abs_error && m.inversion_time_rel_error);
  EXPECT_NEAR(*m.inversion_time_abs_error, 0.05, 1e-12);
  EXPECT_NEAR(*m.inversion_time_rel_error, 0.05 / 1.5, 1e-12);
  ASSERT_TRUE(m.stem_contact_time_abs_error);
  EXPECT_NEAR(*m.stem_contact_time_abs_error, -0.09, 1e-12);  // signed: the engine is early
  EXPECT_NEAR(*m.stem_contact_time_rel_error, -0.05, 1e-12);
  EXPECT_NEAR(m.compared_until, 2.0, 1e-12);
  EXPECT_EQ(m.energy_gain_events, 0);
  EXPECT_DOUBLE_EQ(m.energy_max_error, 0.0);
}

TEST(Metrics, ScaledEnergiesGiveKnownEnergyErrors) {
  const Scene scene = test_scene();
  Columns ref_c, eng_c;
  ref_c.energy = [](double t) { return 10.0 * (1 - 0.1 * t); };
  eng_c.energy = [](double t) { return 0.9 * 10.0 * (1 - 0.1 * t); };
  const Metrics m = compare_runs(make_record("analytic", {}, {}), make_traj(201, 0.01, ref_c),
                                 make_record("ode", {}, {}), make_traj(201, 0.01, eng_c), scene);
  // |E - E_ref| / E0 = 0.1 (1 - 0.1 t): largest at t = 0.
  EXPECT_NEAR(m.energy_max_error, 0.1, 1e-12);
  // The engine's own E_final / E0: 1 - 0.1 * 2.
  EXPECT_NEAR(m.energy_final_ratio, 0.8, 1e-12);
  EXPECT_EQ(m.energy_gain_events, 0);
  EXPECT_EQ(m.inversion_event, "neither");
  EXPECT_FALSE(m.inversion_time_abs_error);
}

TEST(Metrics, KnownPathsGiveKnownDistancesOverR) {
  const Scene scene = test_scene();  // R = 2
  Columns ref_c, eng_c;
  ref_c.x_C = [](double t) { return std::cos(t); };
  ref_c.y_C = [](double t) { return std::sin(t); };
  eng_c.x_C = [](double t) { return std::cos(t) + 0.03; };
  eng_c.y_C = [](double t) { return std::sin(t) + 0.04; };  // 0.05 away everywhere
  ref_c.x_G = [](double t) { return 0.5 * t; };
  eng_c.x_G = [](double t) { return 0.5 * t + (t < 1.0 ? 0.0 : 0.2); };  // 0.2 away on the second half
  ref_c.latitude = [](double) { return 0.2; };
  eng_c.latitude = [](double) { return 0.25; };
  const Metrics m = compare_runs(make_record("analytic", {}, {}), make_traj(201, 0.01, ref_c),
                                 make_record("ode", {}, {}), make_traj(201, 0.01, eng_c), scene);
  EXPECT_NEAR(m.contact_path_rms_error, 0.025, 1e-12);
  EXPECT_NEAR(m.contact_path_max_error, 0.025, 1e-12);
  EXPECT_NEAR(m.com_path_max_error, 0.1, 1e-12);
  // 101 of 201 samples (t = 1.00 .. 2.00) are 0.1 away.
  EXPECT_NEAR(m.com_path_rms_error, std::sqrt(101.0 / 201.0) * 0.1, 1e-9);
  EXPECT_NEAR(m.latitude_rms_error, 0.05, 1e-12);
}

TEST(Metrics, EnergyRisesAreCountedOnlyInDissipativeScenes) {
  Scene scene = test_scene();
  Columns ref_c, eng_c;
  ref_c.energy = [](double t) { return 10.0 - t; };
  // Decreasing, with net rises of 2e-3 and 1e-3 E0 (counted), and 1e-4 E0, below the tolerance:
  // 1e-6 E0 plus the energy of 1e-4 R of contact depth, M g 1e-4 R = 1.96e-3 = 1.96e-4 E0 here.
  ASSERT_NEAR(contact_energy_allowance(scene), 1.962e-3, 1e-9);
  eng_c.energy = [](double t) {
    const int k = static_cast<int>(std::lround(t / 0.01));
    double e = 10.0 - 1e-3 * k;
    if (k == 50) e += 1e-3 + 2e-2;
    if (k == 120) e += 1e-3 + 1e-2;
    if (k == 150) e += 1e-3 + 1e-3;
    return e;
  };
  const RunRecord ref = make_record("analytic", {}, {}), eng = make_record("ode", {}, {});
  const Trajectory rt = make_traj(201, 0.01, ref_c), et = make_traj(201, 0.01, eng_c);
  Metrics m = compare_runs(ref, rt, eng, et, scene);
  EXPECT_EQ(m.energy_gain_events, 2);
  EXPECT_NEAR(m.energy_max_gain, 2e-3, 1e-12);

  scene.contact.friction = FrictionLaw::None;
  scene.contact.k = 0;
  EXPECT_FALSE(energy_must_not_rise(scene));
  m = compare_runs(ref, rt, eng, et, scene);
  EXPECT_EQ(m.energy_gain_events, 0);
  EXPECT_DOUBLE_EQ(m.energy_max_gain, 0.0);
}

TEST(Metrics, DissipativeLaws) {
  Scene s = test_scene();
  EXPECT_TRUE(energy_must_not_rise(s));  // viscous k = 1
  s.contact.friction = FrictionLaw::Coulomb;
  s.contact.k = 0;
  s.contact.mu = 0.3;
  EXPECT_TRUE(energy_must_not_rise(s));
  s.contact.mu = 0;
  EXPECT_FALSE(energy_must_not_rise(s));
  s.contact.friction = FrictionLaw::Gliding;  // F_t = -mu F_n v_C removes energy when mu > 0
  EXPECT_FALSE(energy_must_not_rise(s));
  s.contact.mu = 0.3;
  EXPECT_TRUE(energy_must_not_rise(s));
  s.contact.mu = 0;
  s.contact.friction = FrictionLaw::Rolling;
  EXPECT_FALSE(energy_must_not_rise(s));
  s.contact.drilling = 0.01;
  EXPECT_TRUE(energy_must_not_rise(s));
}

TEST(Metrics, EventOnOneSideOnlyIsAFindingWithoutErrors) {
  const Scene scene = test_scene();
  const Trajectory tr = make_traj(201, 0.01, {});
  const Metrics m = compare_runs(make_record("analytic", 1.5, {}), tr, make_record("ode", {}, 1.9), tr, scene);
  EXPECT_EQ(m.inversion_event, "reference_only");
  EXPECT_EQ(m.stem_contact_event, "engine_only");
  EXPECT_FALSE(m.inversion_time_abs_error);
  EXPECT_FALSE(m.inversion_time_rel_error);
  EXPECT_FALSE(m.stem_contact_time_abs_error);
  const json j = to_json(m);
  EXPECT_TRUE(j.at("inversion_time_abs_error").is_null());
  EXPECT_TRUE(j.at("stem_contact_time_rel_error").is_null());

  Comparison c;
  c.scene = scene_to_json(scene);
  c.provenance = current_provenance();
  c.reference = make_record("analytic", 1.5, {});
  c.engines.push_back({make_record("ode", {}, 1.9), m});
  const auto findings = report_findings(to_json(c));
  ASSERT_EQ(findings.size(), 2u);
  EXPECT_NE(findings[0].find("ode: no inversion"), std::string::npos) << findings[0];
  EXPECT_NE(findings[0].find("1.5"), std::string::npos) << findings[0];
  EXPECT_NE(findings[1].find("ode: stem contact at t = 1.9; the reference has none"), std::string::npos)
      << findings[1];
}

TEST(Metrics, DifferentGridsAreInterpolatedOntoTheReference) {
  const Scene scene = test_scene();
  Columns c;
  c.theta = [](double t) { return 0.2 + 0.5 * t; };
  c.x_C = [](double t) { return t * t; };
  const Trajectory ref = make_traj(201, 0.01, c);
  // Sampled at 0.007 + k 0.01: 0.007 off the reference grid, more than half an interval.
  const Trajectory eng = make_traj(150, 0.01, c, 0.007);
  const Metrics m = compare_runs(make_record("analytic", {}, {}), ref, make_record("ode", {}, {}), eng, scene);
  // Linear columns interpolate exactly; t^2 is off by at most dt^2 / 4 / R.
  EXPECT_NEAR(m.tilt_max_error, 0.0, 1e-12);
  EXPECT_LE(m.contact_path_max_error, 0.01 * 0.01 / 4 / 2 + 1e-12);
  EXPECT_GT(m.contact_path_max_error, 0.0);
  // Reference times inside the engine's span [0.007, 1.497]: 0.01 .. 1.49.
  EXPECT_NEAR(m.compared_until, 1.49, 1e-12);
}

TEST(Metrics, ShorterRunEndsTheCommonGrid) {
  const Scene scene = test_scene();
  Columns ref_c, eng_c;
  eng_c.theta = [](double) { return 0.3; };  // 0.2 off the reference
  const Trajectory ref = make_traj(201, 0.01, ref_c);
  // An engine that stopped at t = 0.5 (index-aligned with the reference up to there).
  const Trajectory eng = make_traj(51, 0.01, eng_c);
  RunRecord er = make_record("ode", {}, {});
  er.status = "diverged";
  const Metrics m = compare_runs(make_record("analytic", {}, {}), ref, er, eng, scene);
  EXPECT_NEAR(m.compared_until, 0.5, 1e-12);
  EXPECT_NEAR(m.tilt_rms_error, 0.2, 1e-12);

  // No common sample at all: errors are unknown, not zero.
  const Metrics none = compare_runs(make_record("analytic", {}, {}), ref, er, Trajectory{}, scene);
  EXPECT_TRUE(std::isnan(none.tilt_rms_error));
  EXPECT_TRUE(to_json(none).at("tilt_rms_error").is_null());
}

TEST(Metrics, CostRatioGuardsAZeroReference) {
  const Scene scene = test_scene();
  const Trajectory tr = make_traj(11, 0.01, {});
  EXPECT_NEAR(compare_runs(make_record("analytic", {}, {}, 0.5), tr, make_record("ode", {}, {}, 2.0), tr, scene)
                  .cost_ratio,
              4.0, 1e-12);
  EXPECT_EQ(compare_runs(make_record("analytic", {}, {}, 0.0), tr, make_record("ode", {}, {}, 2.0), tr, scene)
                .cost_ratio,
            0.0);
}

TEST(Metrics, JsonRoundTrip) {
  const Scene scene = test_scene();
  Columns ref_c, eng_c;
  eng_c.theta = [](double t) { return 0.1 + 0.01 * t; };
  const Metrics m = compare_runs(make_record("analytic", 1.5, 1.8), make_traj(201, 0.01, ref_c),
                                 make_record("ode", 1.6, {}), make_traj(201, 0.01, eng_c), scene);
  const json j = to_json(m);
  const Metrics back = metrics_from_json(json::parse(j.dump()));
  EXPECT_EQ(to_json(back), j);
  EXPECT_EQ(back.stem_contact_event, "reference_only");
  EXPECT_THROW(metrics_from_json(json::object()), json::exception);
}

TEST(Metrics, PhysicsHashIgnoresNamesAndEngineSettings) {
  Scene a = test_scene();
  const std::string h = physics_hash(a);
  EXPECT_TRUE(std::regex_match(h, std::regex("[0-9a-f]{16}"))) << h;
  Scene b = a;
  b.name = "other";
  b.description = "other";
  b.source_file = "elsewhere.toml";
  b.content_hash = "ffffffffffffffff";
  b.engines["ode"]["timestep"] = 1e-5;
  b.run.energy_gain_rule = "ledger";  // how a gain is counted moves no run: the cached reference serves both
  EXPECT_EQ(physics_hash(b), h);
  EXPECT_EQ(scene_to_json(b).at("run").at("energy_gain_rule"), "ledger") << "named in the record when not the default";
  EXPECT_FALSE(scene_to_json(a).at("run").contains("energy_gain_rule")) << "the default keeps every record as it was";
  b.contact.k = 1.5;
  EXPECT_NE(physics_hash(b), h);
  Scene c = a;
  c.run.rtol = 1e-9;  // the reference's tolerance is part of what is cached
  EXPECT_NE(physics_hash(c), h);
}

TEST(Trajectories, SinkKeepsSamplesAndForwardsThem) {
  TempDir dir{"tippe-compare"};
  const std::string path = (dir.path() / "t.csv").string();
  CsvTrajectoryWriter csv(path);
  TrajectorySink sink({&csv});
  Columns c;
  c.theta = [](double t) { return 0.1 + t; };
  c.x_G = [](double t) { return -t; };
  for (int k = 0; k < 5; ++k) sink.write(observation_at(0.1 * k, c));
  csv.commit();
  ASSERT_EQ(sink.trajectory.size(), 5u);
  const Trajectory back = Trajectory::from_csv(read_trajectory_csv(path));
  ASSERT_EQ(back.size(), 5u);
  for (size_t k = 0; k < 5; ++k) {
    EXPECT_EQ(back.t[k], sink.trajectory.t[k]);
    EXPECT_EQ(back.theta[k], sink.trajectory.theta[k]);
    EXPECT_EQ(back.x_G[k], sink.trajectory.x_G[k]);
    EXPECT_EQ(back.surface[k], static_cast<int>(Surface::Ball));
  }
}

TEST(Trajectories, FromCsvNamesAMissingColumn) {
  CsvTrajectory csv;
  csv.columns = {"t", "surface"};
  csv.values["t"] = {0.0};
  csv.surface = {1};
  EXPECT_THROW(Trajectory::from_csv(csv), std::out_of_range);
}

// ---- report -------------------------------------------------------------------------------

// Checks the subset of HTML the report uses: balanced tags (void elements excepted), quoted
// attributes, no raw '<' or stray '&' in text. Returns "" or the first problem; collects
// every <img src>.
std::string check_html(const std::string& h, std::vector<std::string>& images) {
  static const std::set<std::string> void_tags = {"meta", "img", "br", "hr", "link", "input"};
  std::vector<std::string> stack;
  size_t i = 0;
  auto line_of = [&](size_t pos) { return "line " + std::to_string(std::count(h.begin(), h.begin() + pos, '\n') + 1); };
  while (i < h.size()) {
    const char ch = h[i];
    if (ch == '&') {
      static const std::regex entity("&(#[0-9]+|[a-z]+);");
      std::smatch mt;
      const std::string rest = h.substr(i, 12);
      if (!std::regex_search(rest, mt, entity, std::regex_constants::match_continuous))
        return "stray '&' at " + line_of(i);
      i += mt.length(0);
      continue;
    }
    if (ch == '>') return "stray '>' at " + line_of(i);
    if (ch != '<') {
      ++i;
      continue;
    }
    if (h.compare(i, 4, "<!--") == 0) {
      const size_t e = h.find("-->", i);
      if (e == std::string::npos) return "unterminated comment";
      i = e + 3;
      continue;
    }
    if (h.compare(i, 2, "<!") == 0) {
      i = h.find('>', i) + 1;
      continue;
    }
    const bool closing = h.compare(i, 2, "</") == 0;
    size_t p = i + (closing ? 2 : 1);
    size_t q = p;
    while (q < h.size() && std::isalnum(static_cast<unsigned char>(h[q]))) ++q;
    const std::string name = h.substr(p, q - p);
    if (name.empty()) return "raw '<' at " + line_of(i);
    // Attributes: name="value" pairs, no '<' or '>' inside values.
    std::string attrs;
    size_t e = q;
    bool in_quote = false;
    for (; e < h.size(); ++e) {
      if (h[e] == '"') in_quote = !in_quote;
      if (in_quote && (h[e] == '<' || h[e] == '>')) return "'<' or '>' in an attribute at " + line_of(e);
      if (!in_quote && h[e] == '>') break;
    }
    if (e == h.size()) return "unterminated tag <" + name;
    attrs = h.substr(q, e - q);
    i = e + 1;
    if (closing) {
      if (stack.empty() || stack.back() != name)
        return "</" + name + "> closes <" + (stack.empty() ? std::string("nothing") : stack.back()) + "> at " +
               line_of(e);
      stack.pop_back();
      continue;
    }
    if (name == "img") {
      std::smatch mt;
      if (std::regex_search(attrs, mt, std::regex("src=\"([^\"]*)\""))) images.push_back(mt[1]);
    }
    if (void_tags.count(name) || (!attrs.empty() && attrs.back() == '/')) continue;
    stack.push_back(name);
    if (name == "style") {
      // CSS is raw text up to </style>.
      const size_t s = h.find("</style>", i);
      if (s == std::string::npos) return "unterminated <style>";
      i = s;
    }
  }
  if (!stack.empty()) return "unclosed <" + stack.back() + ">";
  return "";
}

TEST(HtmlChecker, CatchesTheUsualMistakes) {
  std::vector<std::string> img;
  EXPECT_EQ(check_html("<html><body><p>a &amp; b</p><img src=\"x.svg\"></body></html>", img), "");
  EXPECT_EQ(img, std::vector<std::string>{"x.svg"});
  EXPECT_NE(check_html("<p><b>x</p></b>", img), "");
  EXPECT_NE(check_html("<p>a < b</p>", img), "");
  EXPECT_NE(check_html("<p>a & b</p>", img), "");
  EXPECT_NE(check_html("<p>x", img), "");
}

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

// ---- end to end ---------------------------------------------------------------------------

int run_tippe(const std::string& args, const fs::path& err_file) {
  const std::string cmd = std::string(TIPPE_BINARY_DIR) + "/tippe " + args + " >/dev/null 2>" + err_file.string();
  const int rc = std::system(cmd.c_str());
  return WIFEXITED(rc) ? WEXITSTATUS(rc) : -1;
}

const std::string kScene = std::string(TIPPE_SOURCE_DIR) + "/harness/scenes/source_dimensionless.toml";

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

}  // namespace
