// Tests of classify_run on synthetic records and trajectories with known answers, and on one real engine run.
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "harness/measure/classify.h"
#include "harness/measure/compare.h"
#include "harness/records/records.h"
#include "harness/measure/run.h"
#include "harness/io/scene_io.h"
#include "harness/scene/resolve.h"
#include "tests/support/classify_fixtures.h"

namespace tippe::test_classify {
namespace {

// Samples at t = 0, 0.1, ...: E falls slowly from 10, J = -2, tilt grows, on the ball.
struct Samples {
  std::vector<double> t, energy, jellett;
  std::vector<Surface> surface;
  explicit Samples(int n) {
    for (int k = 0; k < n; ++k) {
      t.push_back(0.1 * k);
      energy.push_back(10.0 - 0.01 * k);
      jellett.push_back(-2.0);
      surface.push_back(Surface::Ball);
    }
  }
  Trajectory trajectory() const {
    Trajectory tr;
    for (size_t k = 0; k < t.size(); ++k) {
      Observation o;
      o.state.t = t[k];
      o.theta = 0.1 * static_cast<double>(k);
      o.energy = energy[k];
      o.jellett = jellett[k];
      o.surface = surface[k];
      o.normal_force = 1.0;
      tr.append(o);
    }
    return tr;
  }
};

// The record a run of these samples leaves: its summary numbers (Jellett drift per surface)
// come from SampleSummary, told about the switch events between samples as run_simulator does.
RunRecord summarized(const Samples& x, const std::vector<Event>& events = {}) {
  SampleSummary summary;
  for (size_t k = 0; k < x.t.size(); ++k) {
    bool switched = false;
    for (const auto& e : events) switched = switched || (e.name == "switch" && k > 0 && e.time > x.t[k - 1] && e.time <= x.t[k]);
    Observation o;
    o.state.t = x.t[k];
    o.energy = x.energy[k];
    o.jellett = x.jellett[k];
    o.surface = x.surface[k];
    summary.add(o, switched);
  }
  RunRecord r = ok_run();
  summary.fill(r);
  r.events = events;
  return r;
}

RunClass classify(const Scene& s, const RunRecord& r, const Samples& x, const Metrics* m = nullptr) {
  return classify_run(s, r, m, x.trajectory());
}

TEST(Classify, CleanDissipativeRunIsOk) {
  const Samples x(11);
  expect_ok(classify(viscous_scene(), summarized(x), x));
}

TEST(Classify, SmallNoiseStaysOk) {
  Samples x(11);
  x.energy[5] = x.energy[4] + 0.9e-6 * 10.0;  // a rise just below kEnergyGainTolerance * E0
  x.jellett[6] = -2.0 * (1 + 0.9e-3);         // a drift just below kJellettDriftTolerance
  expect_ok(classify(viscous_scene(), summarized(x), x));
}

TEST(Classify, EnergyRiseInDissipativeSceneIsUnphysicalAtTheFirstRise) {
  Samples x(11);
  x.energy[7] = x.energy[6] + 2e-6 * 10.0;
  x.energy[9] = x.energy[8] + 1e-3 * 10.0;  // a later, larger rise does not move the time
  const RunClass c = classify(viscous_scene(), ok_run(), x);
  EXPECT_EQ(c.kind, RunClassKind::Unphysical);
  EXPECT_DOUBLE_EQ(c.time, x.t[7]);
  EXPECT_NE(c.reason.find("energy rose"), std::string::npos) << c.reason;
}

// A trajectory of n samples every dt with the energy e(t), on the ball, J constant.
Trajectory energy_trajectory(int n, double dt, double (*e)(double)) {
  Trajectory tr;
  for (int k = 0; k < n; ++k) {
    Observation o;
    o.state.t = dt * k;
    o.energy = e(o.state.t);
    o.jellett = -2.0;
    o.surface = Surface::Ball;
    o.normal_force = 1.0;
    tr.append(o);
  }
  return tr;
}

TEST(Classify, SmallRisesThatAddUpAreAGain) {
  // Rises of 0.5e-6 E0 between samples, each below the tolerance: the rule on neighbouring
  // samples never saw them; their net rise passes 1e-6 E0 at the third.
  Samples x(11);
  for (int k = 0; k < 11; ++k) x.energy[static_cast<size_t>(k)] = 10.0 * (1 + 0.5e-6 * k);
  const RunClass c = classify(viscous_scene(), ok_run(), x);
  EXPECT_EQ(c.kind, RunClassKind::Unphysical) << c.reason;
  EXPECT_DOUBLE_EQ(c.time, x.t[3]);
  EXPECT_NE(c.reason.find("net rise"), std::string::npos) << c.reason;
}

TEST(Classify, TheEnergyRuleDoesNotDependOnTheSampleInterval) {
  // A steady injection of 1e-4 E0 per unit time, sampled every 0.1 and every 0.001: between two
  // samples 1e-5 E0 (above the tolerance) and 1e-7 E0 (below it). Both are the same run, and
  // both are unphysical, dated where the net rise passes 1e-6 E0 (t = 0.01) to within a sample.
  const auto drift = [](double t) { return 10.0 * (1 + 1e-4 * t); };
  const Trajectory coarse = energy_trajectory(11, 0.1, drift), fine = energy_trajectory(1001, 0.001, drift);
  const EnergyGains gc = energy_gains(coarse), gf = energy_gains(fine);
  EXPECT_EQ(gc.events, 1);
  EXPECT_EQ(gf.events, 1);
  EXPECT_NEAR(gc.max_rise, 1e-4, 1e-12);
  EXPECT_NEAR(gf.max_rise, 1e-4, 1e-12) << "the same net rise whatever the sampling";
  EXPECT_NEAR(gf.time, 0.01, 0.001 + 1e-12);
  EXPECT_NEAR(gc.time, 0.1, 1e-12) << "the coarse samples date it at their first";
  for (const Trajectory* tr : {&coarse, &fine})
    EXPECT_EQ(classify_run(viscous_scene(), ok_run(), nullptr, *tr).kind, RunClassKind::Unphysical);
}

TEST(Classify, JitterBelowTheToleranceNeverAddsUp) {
  // 10000 samples of a falling energy with +-0.4e-6 E0 of jitter: many rises between samples,
  // none a net rise above the tolerance, however long the run.
  const auto jitter = [](double t) {
    const long k = std::lround(t / 0.001);
    return 10.0 * (1 - 1e-9 * static_cast<double>(k) + (k % 2 ? 0.4e-6 : -0.4e-6));
  };
  const Trajectory tr = energy_trajectory(10000, 0.001, jitter);
  const EnergyGains g = energy_gains(tr);
  EXPECT_EQ(g.events, 0);
  EXPECT_LT(g.max_rise, kEnergyGainTolerance);
  expect_ok(classify_run(viscous_scene(), ok_run(), nullptr, tr));
}

TEST(Classify, EnergyRiseWhereEnergyMayRiseIsOk) {
  Samples x(11);
  x.energy[7] = x.energy[6] + 1e-3 * 10.0;
  Scene rolling = viscous_scene();
  rolling.contact.friction = FrictionLaw::Rolling;  // conservative: rises are not injected energy
  rolling.contact.k = 0;
  expect_ok(classify(rolling, ok_run(), x));
  Scene slippery = viscous_scene();
  slippery.contact.k = 0;  // viscous with k = 0 removes nothing
  expect_ok(classify(slippery, ok_run(), x));
}

TEST(Classify, JellettDriftIsUnphysicalAtTheFirstSampleBeyondTolerance) {
  Samples x(11);
  for (int k = 3; k <= 10; ++k) x.jellett[k] = -2.0 * (1 + 4e-4 * (k - 2));  // 1.2e-3 at k = 5
  const RunClass c = classify(viscous_scene(), summarized(x), x);
  EXPECT_EQ(c.kind, RunClassKind::Unphysical);
  EXPECT_DOUBLE_EQ(c.time, x.t[5]);
  EXPECT_NE(c.reason.find("Jellett"), std::string::npos) << c.reason;
  EXPECT_NE(c.reason.find("ball"), std::string::npos) << c.reason;
}

TEST(Classify, JellettDriftOnTheStem) {
  Samples x(11);
  for (int k = 4; k <= 10; ++k) x.surface[k] = Surface::Stem;
  for (int k = 4; k <= 10; ++k) x.jellett[k] = 5.0;  // a new stretch: the jump from -2 is not drift
  x.jellett[8] = 5.0 * (1 - 2e-3);
  const RunClass c = classify(viscous_scene(), summarized(x), x);
  EXPECT_EQ(c.kind, RunClassKind::Unphysical);
  EXPECT_DOUBLE_EQ(c.time, x.t[8]);
  EXPECT_NE(c.reason.find("stem"), std::string::npos) << c.reason;
}

TEST(Classify, JumpsOfJBetweenStretchesAreNotDrift) {
  Samples x(11);
  x.surface[3] = Surface::Both;  // ends the ball stretch
  for (int k = 4; k <= 10; ++k) x.jellett[k] = -1.0;
  x.surface[6] = Surface::None;  // in flight: ends it again
  for (int k = 7; k <= 10; ++k) x.jellett[k] = -3.0;
  expect_ok(classify(viscous_scene(), summarized(x), x));

  // A contact switch between two ball samples (chatter faster than the sampling) ends the stretch.
  Samples y(11);
  for (int k = 5; k <= 10; ++k) y.jellett[k] = -2.5;
  const std::vector<Event> chatter = {{"switch", 0.43, "ball -> stem", 0.0}, {"switch", 0.47, "stem -> ball", 0.0}};
  expect_ok(classify(viscous_scene(), summarized(y, chatter), y));
  // Without the events the same samples are a drift at t = 0.5.
  const RunClass c = classify(viscous_scene(), summarized(y), y);
  EXPECT_EQ(c.kind, RunClassKind::Unphysical);
  EXPECT_DOUBLE_EQ(c.time, y.t[5]);
}

TEST(Classify, TheRecordDecidesWhetherJDriftedTheSamplesWhen) {
  // A record read back from comparison.json keeps only the first 100 switch events: the record's
  // own drift (computed with all of them) says no drift, although the samples, without the
  // dropped events, seem to show one.
  Samples x(11);
  for (int k = 5; k <= 10; ++k) x.jellett[k] = -2.5;
  RunRecord complete = summarized(x, {{"switch", 0.43, "ball -> stem", 0.0}, {"switch", 0.47, "stem -> ball", 0.0}});
  complete.events.clear();  // dropped when the record was written
  expect_ok(classify(viscous_scene(), complete, x));

  // A drift in the record that the samples do not show is still a finding, undated.
  RunRecord drifted = summarized(Samples(11));
  drifted.jellett_drift_stem = 5e-3;
  RunClass c = classify(viscous_scene(), drifted, Samples(11));
  EXPECT_EQ(c.kind, RunClassKind::Unphysical);
  EXPECT_TRUE(std::isnan(c.time));
  EXPECT_NE(c.reason.find("on the stem"), std::string::npos) << c.reason;
  // ... and an energy rise the samples do date comes first.
  Samples y(11);
  y.energy[3] = y.energy[2] + 1e-3;
  c = classify(viscous_scene(), drifted, y);
  EXPECT_DOUBLE_EQ(c.time, y.t[3]);
  EXPECT_NE(c.reason.find("energy rose"), std::string::npos) << c.reason;
}

TEST(Classify, DrillingFrictionMayChangeJ) {
  Samples x(11);
  for (int k = 1; k <= 10; ++k) x.jellett[k] = -2.0 * (1 - 0.05 * k);
  Scene s = viscous_scene();
  s.contact.drilling = 1e-3;
  EXPECT_FALSE(jellett_must_hold(s));
  EXPECT_TRUE(jellett_must_hold(viscous_scene()));
  expect_ok(classify(s, summarized(x), x));
}

TEST(Classify, TheEarlierOfTwoFindingsWins) {
  Samples x(11);
  x.energy[6] = x.energy[5] + 1e-4 * 10.0;        // at t = 0.6
  for (int k = 3; k <= 10; ++k) x.jellett[k] = -2.1;  // at t = 0.3
  const RunClass c = classify(viscous_scene(), summarized(x), x);
  EXPECT_EQ(c.kind, RunClassKind::Unphysical);
  EXPECT_DOUBLE_EQ(c.time, x.t[3]);
  EXPECT_NE(c.reason.find("Jellett"), std::string::npos) << c.reason;
}

TEST(Classify, EngineVerdictsKeepTheirTimeAndDetail) {
  const struct {
    const char* status;
    RunClassKind kind;
  } cases[] = {{"diverged", RunClassKind::Diverged},
               {"clamped", RunClassKind::Clamped},
               {"failed", RunClassKind::Failed},
               {"contact_lost", RunClassKind::ContactLost},
               {"unphysical", RunClassKind::Unphysical}};
  for (const auto& k : cases) {
    RunRecord r = ok_run();
    r.status = k.status;
    r.status_time = 0.4321;
    r.status_detail = std::string("detail of ") + k.status;
    const RunClass c = classify(viscous_scene(), r, Samples(5));
    EXPECT_EQ(c.kind, k.kind) << k.status;
    EXPECT_EQ(c.time, 0.4321) << k.status;
    EXPECT_EQ(c.reason, r.status_detail) << k.status;
    EXPECT_STREQ(to_string(c.kind), k.status);
  }
  RunRecord r = ok_run();
  r.status = "exploded";
  r.status_time = 0.25;
  const RunClass c = classify(viscous_scene(), r, Samples(3));
  EXPECT_EQ(c.kind, RunClassKind::Failed);
  EXPECT_EQ(c.time, 0.25);
  EXPECT_NE(c.reason.find("unknown run status \"exploded\""), std::string::npos) << c.reason;
}

TEST(Classify, EngineVerdictMentionsAnEarlierSign) {
  Samples x(11);
  x.energy[4] = x.energy[3] + 1e-2 * 10.0;
  RunRecord r = ok_run();
  r.status = "diverged";
  r.status_time = 0.95;
  r.status_detail = "speed blow-up";
  const RunClass c = classify(viscous_scene(), r, x);
  EXPECT_EQ(c.kind, RunClassKind::Diverged);
  EXPECT_EQ(c.time, 0.95);
  EXPECT_EQ(c.reason.rfind("speed blow-up; earlier, at t = 0.4: energy rose", 0), 0u) << c.reason;
}

TEST(Classify, NonFiniteSampleIsDiverged) {
  Samples x(11);
  x.energy[6] = std::nan("");
  const RunClass c = classify(viscous_scene(), ok_run(), x);
  EXPECT_EQ(c.kind, RunClassKind::Diverged);
  EXPECT_DOUBLE_EQ(c.time, x.t[6]);

  Samples y(11);
  y.jellett[2] = INFINITY;
  EXPECT_DOUBLE_EQ(classify(viscous_scene(), ok_run(), y).time, y.t[2]);
}

TEST(Classify, EnergyAboveTheEnginesFactorIsDivergedEvenWhereEnergyMayRise) {
  Samples x(11);
  for (int k = 8; k <= 10; ++k) x.energy[k] = 25.0;  // above 2 E0 = 20 from t = 0.8
  Scene s = viscous_scene();
  s.contact.friction = FrictionLaw::None;
  s.contact.k = 0;
  const RunClass c = classify(s, ok_run(), x);
  EXPECT_EQ(c.kind, RunClassKind::Diverged);
  EXPECT_DOUBLE_EQ(c.time, x.t[8]);
  EXPECT_NE(c.reason.find("above 2 E0"), std::string::npos) << c.reason;
  // A divergence outranks an earlier energy rise in a dissipative scene.
  Samples y = x;
  y.energy[2] = y.energy[1] + 1e-3;
  EXPECT_EQ(classify(viscous_scene(), ok_run(), y).kind, RunClassKind::Diverged);
}

TEST(Classify, WithoutTrajectoryTheSummariesDecide) {
  const Trajectory none;
  expect_ok(classify_run(viscous_scene(), ok_run(), nullptr, none));

  Metrics m;
  m.energy_gain_events = 3;
  m.energy_max_gain = 2e-5;
  RunClass c = classify_run(viscous_scene(), ok_run(), &m, none);
  EXPECT_EQ(c.kind, RunClassKind::Unphysical);
  EXPECT_TRUE(std::isnan(c.time));
  EXPECT_NE(c.reason.find("3 net energy rises"), std::string::npos) << c.reason;

  RunRecord r = ok_run();
  r.jellett_drift_ball = 5e-4;
  r.jellett_drift_stem = 5e-3;
  c = classify_run(viscous_scene(), r, nullptr, none);
  EXPECT_EQ(c.kind, RunClassKind::Unphysical);
  EXPECT_TRUE(std::isnan(c.time));
  EXPECT_NE(c.reason.find("on the stem"), std::string::npos) << c.reason;
  Scene drilling = viscous_scene();
  drilling.contact.drilling = 1e-3;
  expect_ok(classify_run(drilling, r, nullptr, none));

  r.jellett_drift_stem = 5e-4;
  const Metrics clean;
  expect_ok(classify_run(viscous_scene(), r, &clean, none));
}

// A real run: ODE at its default step on the source's dimensionless top stays ok, and its
// record's Jellett drift agrees with what classify_run measures on the same trajectory.
TEST(Classify, RealEngineRunIsOk) {
  const Scene scene = load_scene(std::string(TIPPE_SOURCE_DIR) + "/harness/scenes/source_dimensionless.toml",
                                 {"run.duration=5"});
  TrajectorySink sink;
  const RunRecord run = run_scene(scene, "ode", &sink);
  ASSERT_EQ(run.status, "ok") << run.status_detail;
  const RunClass c = classify_run(scene, run, nullptr, sink.trajectory);
  EXPECT_EQ(c.kind, RunClassKind::Ok) << c.reason;
  ASSERT_TRUE(run.jellett_drift_ball.has_value());
  EXPECT_LT(*run.jellett_drift_ball, kJellettDriftTolerance);
}

}  // namespace
}  // namespace tippe
