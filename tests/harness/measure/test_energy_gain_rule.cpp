// The energy-gain rule's three ways of counting energy (harness/measure/metrics.h, EnergyGainRule) on synthetic ledgers with known answers, and the default on a real soft contact: Simbody's Hertz store.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "harness/measure/classify.h"
#include "harness/measure/metrics.h"
#include "harness/measure/run.h"
#include "harness/io/scene_io.h"
#include "harness/records/trajectory.h"
#include "harness/scene/resolve.h"
#include "tests/support/classify_fixtures.h"

namespace tippe::test_energy_gain_rule {
namespace {

// A run whose E rises by 1e-3 E0 over t = 0.5 .. 1.0 while its ledger books `booked` of it
// (normal work with the contact's elastic energy falling by as much, or nothing).
Trajectory ledger_trajectory(bool with_store, double booked) {
  Trajectory tr;
  for (int k = 0; k <= 10; ++k) {
    Observation o;
    o.state.t = 0.1 * k;
    const double rise = k > 5 ? 1e-3 * 10.0 * (k - 5) / 5.0 : 0.0;
    o.energy = 10.0 + rise;
    o.surface = Surface::Ball;
    o.normal_work = booked * rise;
    o.friction_work = 0.0;
    o.elastic_energy = with_store ? 0.02 - booked * rise : std::nan("");
    o.numerical_energy = o.energy - 10.0 - o.normal_work;
    tr.append(o);
  }
  return tr;
}

TEST(Classify, LedgerRuleDoesNotCountEnergyReleasedFromTheContactsStore) {
  // The rise is the soft contact giving back what it stored (normal work = -dU): energy moved,
  // none created. Under the ledger rule no gain; under the total rule the same run gains.
  const Trajectory tr = ledger_trajectory(true, 1.0);
  EXPECT_EQ(energy_gains(tr, 0.0, EnergyGainRule::Ledger).events, 0);
  EXPECT_EQ(energy_gains(tr, 0.0, EnergyGainRule::Total).events, 1);
}

TEST(Classify, LedgerRuleCountsEnergyTheLedgerCannotExplain) {
  // The same rise with nothing booked: numerical energy, created by the integrator; a gain under
  // both rules, and the class says which rule counted it.
  const Trajectory tr = ledger_trajectory(true, 0.0);
  EXPECT_EQ(energy_gains(tr, 0.0, EnergyGainRule::Ledger).events, 1);
  EXPECT_NEAR(energy_gains(tr, 0.0, EnergyGainRule::Ledger).max_rise, 1e-3, 1e-12);
  const RunClass c = classify_run(viscous_scene(), ok_run(), nullptr, tr);
  EXPECT_EQ(c.kind, RunClassKind::Unphysical);
  EXPECT_NE(c.reason.find(std::string("energy_gain_rule = ") + to_string(kDefaultEnergyGainRule)), std::string::npos)
      << c.reason;
}

TEST(Classify, TheScenesRunTableChoosesTheRule) {
  // run.energy_gain_rule picks the rule the class counts with: the store's release is no gain
  // under "stored" (the default, kDefaultEnergyGainRule) and "ledger", and a gain under "total";
  // the reason names the rule that counted it.
  const Trajectory tr = ledger_trajectory(true, 1.0);
  Scene stored = viscous_scene();
  EXPECT_EQ(stored.run.energy_gain_rule, to_string(kDefaultEnergyGainRule)) << "the scene's default is the constant";
  EXPECT_EQ(energy_gain_rule(stored), EnergyGainRule::Stored);
  expect_ok(classify_run(stored, ok_run(), nullptr, tr));
  Scene total = viscous_scene();
  total.run.energy_gain_rule = "total";
  const RunClass c = classify_run(total, ok_run(), nullptr, tr);
  EXPECT_EQ(c.kind, RunClassKind::Unphysical);
  EXPECT_NE(c.reason.find("energy_gain_rule = total"), std::string::npos) << c.reason;
  Scene ledger = viscous_scene();
  ledger.run.energy_gain_rule = "ledger";
  EXPECT_EQ(energy_gain_rule(ledger), EnergyGainRule::Ledger);
  expect_ok(classify_run(ledger, ok_run(), nullptr, tr));
  // Energy neither the store nor the ledger explains is a gain under each, named as the rule's.
  const RunClass created = classify_run(ledger, ok_run(), nullptr, ledger_trajectory(true, 0.0));
  EXPECT_EQ(created.kind, RunClassKind::Unphysical);
  EXPECT_NE(created.reason.find("energy_gain_rule = ledger"), std::string::npos) << created.reason;
  const RunClass rose = classify_run(stored, ok_run(), nullptr, ledger_trajectory(true, 0.0));
  EXPECT_EQ(rose.kind, RunClassKind::Unphysical);
  EXPECT_NE(rose.reason.find("with the contact's stored elastic energy"), std::string::npos) << rose.reason;
  EXPECT_NE(rose.reason.find("energy_gain_rule = stored"), std::string::npos) << rose.reason;
}

TEST(Classify, StoredRuleCountsTheTopsEnergyWithTheContactsStore) {
  // E rises by 1e-3 E0 while the contact's elastic energy falls by as much: a release, no gain.
  EXPECT_EQ(energy_gains(ledger_trajectory(true, 1.0), 0.0, EnergyGainRule::Stored).events, 0);
  // Half of it released, half created: the created half is the net rise counted.
  const EnergyGains half = energy_gains(ledger_trajectory(true, 0.5), 0.0, EnergyGainRule::Stored);
  EXPECT_EQ(half.events, 1);
  EXPECT_NEAR(half.max_rise, 0.5e-3, 1e-12);
  // The store itself rising with E (the integrator putting energy into both) is counted whole.
  Trajectory both = ledger_trajectory(true, -1.0);
  EXPECT_NEAR(energy_gains(both, 0.0, EnergyGainRule::Stored).max_rise, 2e-3, 1e-12);
  // The rule needs no ledger: the work columns play no part (a store alone, as a record read
  // back with only elastic_energy would give).
  Trajectory no_work = ledger_trajectory(true, 1.0);
  no_work.normal_work.assign(no_work.size(), std::nan(""));
  no_work.numerical_energy.assign(no_work.size(), std::nan(""));
  EXPECT_EQ(energy_gains(no_work, 0.0, EnergyGainRule::Stored).events, 0);
}

TEST(Classify, StoredRuleWithoutAStoreCountsE) {
  // Where the engine's contact law gives no elastic energy (n/a from the first sample), E is
  // counted, as under the total rule: the same rise is a gain under both.
  const Trajectory tr = ledger_trajectory(false, 1.0);
  const EnergyGains stored = energy_gains(tr, 0.0, EnergyGainRule::Stored), total = energy_gains(tr, 0.0, EnergyGainRule::Total);
  EXPECT_EQ(stored.events, 1);
  EXPECT_EQ(stored.max_rise, total.max_rise);
  // A store that ends (a sample without it, as at a divergence) counts E there, not E - U0.
  Trajectory ends = ledger_trajectory(true, 1.0);
  ends.elastic_energy.back() = std::nan("");
  const std::vector<double> c = energy_counted(ends, EnergyGainRule::Stored);
  EXPECT_EQ(c.back(), ends.energy.back());
  EXPECT_EQ(c.front(), ends.energy.front()) << "the first sample is E0 under every rule";
}

TEST(EnergyGainRule, AStoreIsUFiniteAtTheFirstSampleWithOneUPerSample) {
  // The one predicate the counted energy and the class's wording share.
  EXPECT_TRUE(has_elastic_store(ledger_trajectory(true, 1.0)));
  EXPECT_FALSE(has_elastic_store(ledger_trajectory(false, 1.0))) << "n/a from the first sample";
  Trajectory later = ledger_trajectory(true, 1.0);
  later.elastic_energy.back() = std::nan("");
  EXPECT_TRUE(has_elastic_store(later)) << "a store that ends later is still the run's";
  Trajectory first = ledger_trajectory(true, 1.0);
  first.elastic_energy.front() = std::nan("");
  EXPECT_FALSE(has_elastic_store(first));
  Trajectory short_u = ledger_trajectory(true, 1.0);
  short_u.elastic_energy.pop_back();
  EXPECT_FALSE(has_elastic_store(short_u)) << "U not given for every sample";
  EXPECT_FALSE(has_elastic_store(Trajectory{})) << "no sample";
}

TEST(Classify, LedgerRuleWithoutTheElasticEnergyCountsNormalWorkAsExchange) {
  // Where the engine's contact law gives no elastic energy (n/a), the normal force's work is
  // counted as an exchange with the contact's store: the rise it explains is not a gain.
  const Trajectory tr = ledger_trajectory(false, 1.0);
  EXPECT_EQ(energy_gains(tr, 0.0, EnergyGainRule::Ledger).events, 0);
  EXPECT_EQ(energy_gains(tr, 0.0, EnergyGainRule::Total).events, 1);
}

// The default on a real soft contact: Simbody's Hertz contact takes the tutorial top's weight in
// its first milliseconds and gives part of the stored energy back, so E rises by 1.3e-5 E0 at
// t = 0.002 .. 0.003 s (measured; the tolerance there is 5.1e-6 E0) while E + U falls. The
// total rule calls that a gain, the default (stored) does not: the release moved energy.
TEST(EnergyGainRule, SimbodysHertzStoreGivingBackIsNoGainByDefault) {
  const Scene scene = load_scene(std::string(TIPPE_SOURCE_DIR) + "/harness/scenes/mujoco_tutorial.toml",
                                 {"run.duration=0.05"});
  ASSERT_EQ(energy_gain_rule(scene), EnergyGainRule::Stored) << "the scene file names no rule: the default";
  TrajectorySink sink;
  const RunRecord run = run_scene(scene, "simbody", &sink);
  ASSERT_EQ(run.status, "ok") << run.status_detail;
  const Trajectory& tr = sink.trajectory;
  ASSERT_EQ(tr.elastic_energy.size(), tr.size());
  ASSERT_TRUE(std::isfinite(tr.elastic_energy[0])) << "Simbody's Hertz law gives its store";
  const double allowance = contact_energy_allowance(scene);
  const EnergyGains total = energy_gains(tr, allowance, EnergyGainRule::Total);
  EXPECT_GE(total.events, 1) << "E alone rises as the store gives back";
  EXPECT_GT(total.max_rise, total.tolerance);
  const EnergyGains stored = energy_gains(tr, allowance, EnergyGainRule::Stored);
  EXPECT_EQ(stored.events, 0) << "largest net rise of E + U: " << stored.max_rise << " E0";
  expect_ok(classify_run(scene, run, nullptr, tr));
  // The store is what made the difference: E + U - U0 is E plus a store of the rise's size.
  double u_max = 0;
  for (double u : tr.elastic_energy) u_max = std::max(u_max, u);
  EXPECT_GT(u_max / std::abs(tr.energy[0]), total.max_rise);
}

}  // namespace
}  // namespace tippe
