// Tests of the metrics of a run against the reference (harness/measure/metrics.cpp) on synthetic trajectories, with their JSON and the physics hash, and of the trajectories they read (harness/records/trajectory.cpp).
#include <gtest/gtest.h>

#include <cmath>
#include <initializer_list>
#include <limits>
#include <utility>
#include <vector>
#include <regex>
#include <string>

#include "harness/measure/compare.h"
#include "harness/measure/metrics.h"
#include "harness/records/records.h"
#include "harness/report/report.h"
#include "harness/io/scene_io.h"
#include "tests/support/compare_fixtures.h"
#include "tests/support/files.h"

namespace test_metrics {

using namespace tippe;
using nlohmann::json;

namespace {

using namespace tippe::fixtures;

}  // namespace

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

// An engine whose friction works at a steady rate, -0.1 a unit of time, sampled every 0.01.
Trajectory steady_friction_work() {
  Trajectory tr = make_traj(201, 0.01, Columns{});
  tr.friction_work.clear();
  for (const double t : tr.t) tr.friction_work.push_back(-0.1 * t);
  return tr;
}

std::vector<Event> reference_events(std::initializer_list<std::pair<const char*, double>> list) {
  std::vector<Event> events;
  for (const auto& [name, time] : list) events.push_back({name, time, "", 0.0});
  return events;
}

TEST(Metrics, FrictionWorkWhileTheReferenceSticks) {
  const Trajectory eng = steady_friction_work();
  const double inf = std::numeric_limits<double>::infinity();
  // Sticking over [0.5, 1.0] and from 1.5 on (to the engine's end, 2.0): 0.5 + 0.5 of time. The
  // work is a sum of 100 differences of numbers below 0.2: a few ulps of 0.1.
  const auto both = friction_work_where_reference_sticks(
      reference_events({{"inversion", 0.2}, {"stick", 0.5}, {"slip", 1.0}, {"stick", 1.5}}), eng, inf);
  ASSERT_TRUE(both.has_value());
  EXPECT_NEAR(*both, -0.1, 1e-12);
  // Cut at the reference's converged window.
  const auto cut = friction_work_where_reference_sticks(
      reference_events({{"stick", 0.5}, {"slip", 1.0}, {"stick", 1.5}}), eng, 1.75);
  ASSERT_TRUE(cut.has_value());
  EXPECT_NEAR(*cut, -0.075, 1e-12);
  // A change of contact ends a stick as a slip does; events out of order are put in order.
  const auto touch = friction_work_where_reference_sticks(
      reference_events({{"two_contact", 0.7}, {"stick", 0.5}}), eng, inf);
  ASSERT_TRUE(touch.has_value());
  EXPECT_NEAR(*touch, -0.02, 1e-12);
  // No stick in the window, or no friction work in the engine's trajectory: no value.
  EXPECT_FALSE(friction_work_where_reference_sticks(reference_events({{"slip", 0.5}}), eng, inf).has_value());
  EXPECT_FALSE(friction_work_where_reference_sticks(reference_events({{"stick", 1.9}}), eng, 1.5).has_value());
  Trajectory no_ledger = eng;
  no_ledger.friction_work.clear();
  EXPECT_FALSE(friction_work_where_reference_sticks(reference_events({{"stick", 0.5}}), no_ledger, inf).has_value());
}

TEST(Metrics, FrictionWorkWhileTheReferenceSticksIsOverTheEnginesInitialEnergy) {
  const Scene scene = test_scene();
  const Trajectory ref = make_traj(201, 0.01, Columns{});
  RunRecord reference = make_record("analytic", std::nullopt, std::nullopt);
  reference.events = reference_events({{"stick", 1.0}});
  RunRecord engine = make_record("ode", std::nullopt, std::nullopt);
  engine.energy_initial = -4.0;  // the scale is |E0|
  const Metrics m = compare_runs(reference, ref, engine, steady_friction_work(), scene);
  ASSERT_TRUE(m.friction_work_reference_sticks.has_value());
  EXPECT_NEAR(*m.friction_work_reference_sticks, -0.1 / 4.0, 1e-12);
  // The reference never sticks: null.
  reference.events.clear();
  EXPECT_FALSE(compare_runs(reference, ref, engine, steady_friction_work(), scene).friction_work_reference_sticks);
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
  EXPECT_EQ(scene_to_json(b).at("run").at("energy_gain_rule"), "ledger") << "every rule but total is named in the record";
  EXPECT_EQ(scene_to_json(a).at("run").at("energy_gain_rule"), "stored") << "the default too: absent meant total";
  Scene t = a;
  t.run.energy_gain_rule = "total";
  EXPECT_FALSE(scene_to_json(t).at("run").contains("energy_gain_rule"))
      << "total keeps the JSON of the records written before the key existed";
  EXPECT_EQ(physics_hash(t), h);
  b.contact.k = 1.5;
  EXPECT_NE(physics_hash(b), h);
  Scene c = a;
  c.run.rtol = 1e-9;  // the reference's tolerance is part of what is cached
  EXPECT_NE(physics_hash(c), h);
}

// ---- trajectories ------------------------------------------------------------------------

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

}  // namespace test_metrics
