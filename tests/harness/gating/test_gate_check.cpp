// Tests of judging a gate's check (harness/gating/gate_check.cpp): the metric table a check bounds, and the rows of a check evaluated on fixture records and metrics.
#include <gtest/gtest.h>

#include <limits>
#include <set>
#include <string>

#include "harness/gating/gate.h"
#include "tests/support/gate_fixtures.h"

namespace test_gate_check {

using namespace tippe;
using nlohmann::json;

namespace {

using namespace tippe::fixtures;

}  // namespace

// ---- the metric table -----------------------------------------------------------------------------

TEST(GateMetrics, AreTheNumericMetricsButWallClock) {
  // to_json(Metrics) lists every field: the gate table must follow it when a metric is added.
  std::set<std::string> expected;
  const json all = to_json(Metrics{});
  for (const auto& [k, v] : all.items())
    if (!v.is_string() && k != "wall_seconds" && k != "cpu_seconds" && k != "real_time_factor" &&
        k != "reference_converged_until" &&  // the reference's, not the engine's: it marks rows instead
        // The event alignment: its counts of events on each side and of matches describe the
        // sequences (missing and extra judge them), the first wrong event is a text gated by
        // require_no_wrong_event, the dwell is a setting of the bench.
        k != "events_reference" && k != "events_engine" && k != "events_matched" && k != "first_wrong_event" &&
        k != "first_wrong_event_index" && k != "event_min_dwell" && k != "event_alignment" && k != "event_alignment_rows")
      expected.insert(k);
  std::set<std::string> names;
  for (const GateMetric& g : gate_metrics()) EXPECT_TRUE(names.insert(g.name).second) << g.name << " listed twice";
  EXPECT_EQ(names, expected);
  for (const char* timing : {"wall_seconds", "cpu_seconds", "real_time_factor"})
    EXPECT_EQ(find_gate_metric(timing), nullptr) << timing;
}

TEST(GateMetrics, EachAccessorReadsItsOwnField) {
  json j = to_json(Metrics{});
  double v = 1.0;
  for (auto& [k, x] : j.items())
    if (k == "first_wrong_event") x = "reference: inversion at t=1, engine: none";
    else if (x.is_array()) continue;  // the aligned rows, no gate metric
    else if (!x.is_string())
      x = (k == "steps" || k == "energy_gain_events" || k.rfind("events_", 0) == 0 || k == "first_wrong_event_index" ||
               k == "event_alignment_rows")
              ? json(static_cast<long long>(v++))
              : json(v++ + 0.5);
  const Metrics m = metrics_from_json(j);
  for (const GateMetric& g : gate_metrics()) {
    const auto got = g.get(m);
    ASSERT_TRUE(got.has_value()) << g.name;
    EXPECT_EQ(*got, j.at(g.name).get<double>()) << g.name;
  }
}

// ---- evaluation (pure) ------------------------------------------------------------------------------

TEST(GateEvaluate, PassesWithinEveryThreshold) {
  const CheckResult r = evaluate_check(fixture_check(), fixture_record("analytic", 17.25),
                                       fixture_record("ode", 17.27), fixture_metrics());
  EXPECT_TRUE(r.passed);
  ASSERT_EQ(r.rows.size(), 4u);  // status + three thresholds, no event rows
  EXPECT_EQ(r.rows[0].metric, "status");
  EXPECT_EQ(r.name, "ode-fixture");
  EXPECT_EQ(r.engine, "ode");
  EXPECT_DOUBLE_EQ(r.seconds, 0.25);
  for (const GateRow& g : r.rows) EXPECT_TRUE(g.passed && g.message.empty()) << g.metric << ": " << g.message;
  EXPECT_EQ(row(r, "tilt_rms_error")->measured, "0.02");
  EXPECT_EQ(row(r, "tilt_rms_error")->required, "0.05");
}

TEST(GateEvaluate, ThresholdFailsAboveAndPassesAtEquality) {
  Metrics m = fixture_metrics();
  m.tilt_rms_error = 0.0812;
  m.energy_gain_events = 0;
  CheckResult r = evaluate_check(fixture_check(), fixture_record("analytic", 17.25), fixture_record("ode", 17.27), m);
  EXPECT_FALSE(r.passed);
  const GateRow* t = row(r, "tilt_rms_error");
  ASSERT_NE(t, nullptr);
  EXPECT_FALSE(t->passed);
  EXPECT_EQ(*t->value, 0.0812);
  EXPECT_EQ(*t->limit, 0.05);
  EXPECT_EQ(t->message, "tilt_rms_error 0.0812 > 0.05");
  EXPECT_TRUE(row(r, "inversion_time_rel_error")->passed);

  m.tilt_rms_error = 0.05;  // the threshold is the largest accepted value
  r = evaluate_check(fixture_check(), fixture_record("analytic", 17.25), fixture_record("ode", 17.27), m);
  EXPECT_TRUE(r.passed);
}

TEST(GateEvaluate, ComparesAbsoluteValues) {
  Metrics m = fixture_metrics();
  m.inversion_time_rel_error = -0.009;  // engine early, within 1 %
  CheckResult r = evaluate_check(fixture_check(), fixture_record("analytic", 17.25), fixture_record("ode", 17.1), m);
  EXPECT_TRUE(r.passed);
  m.inversion_time_rel_error = -0.02;
  r = evaluate_check(fixture_check(), fixture_record("analytic", 17.25), fixture_record("ode", 16.9), m);
  EXPECT_FALSE(r.passed);
  EXPECT_EQ(row(r, "inversion_time_rel_error")->message, "inversion_time_rel_error |-0.02| > 0.01");
}

TEST(GateEvaluate, AbsentEventErrorFailsWithTheReason) {
  Metrics m = fixture_metrics();
  m.inversion_event = "engine_only";
  m.inversion_time_abs_error.reset();
  m.inversion_time_rel_error.reset();
  CheckResult r = evaluate_check(fixture_check(), fixture_record("analytic", std::nullopt), fixture_record("ode", 17.3), m);
  EXPECT_FALSE(r.passed);
  const GateRow* g = row(r, "inversion_time_rel_error");
  EXPECT_FALSE(g->passed);
  EXPECT_FALSE(g->value.has_value());
  EXPECT_EQ(g->measured, "absent");
  EXPECT_EQ(g->message, "inversion_time_rel_error: absent (engine_only: the engine inverts, the reference does not)");

  m.inversion_event = "reference_only";
  r = evaluate_check(fixture_check(), fixture_record("analytic", 17.25), fixture_record("ode", std::nullopt), m);
  EXPECT_EQ(row(r, "inversion_time_rel_error")->message,
            "inversion_time_rel_error: absent (reference_only: the reference inverts, the engine does not)");
  // Neither side inverting leaves nothing to bound either: the threshold cannot be met.
  m.inversion_event = "neither";
  r = evaluate_check(fixture_check(), fixture_record("analytic", std::nullopt), fixture_record("ode", std::nullopt), m);
  EXPECT_FALSE(r.passed);
  EXPECT_EQ(row(r, "inversion_time_rel_error")->message,
            "inversion_time_rel_error: absent (neither: neither the engine nor the reference inverts)");

  Check c = fixture_check();
  c.max = {{"stem_contact_time_abs_error", 1.0}, {"jellett_drift_stem", 1.0}};
  m.stem_contact_event = "reference_only";
  r = evaluate_check(c, fixture_record("analytic", 17.25), fixture_record("ode", 17.3), m);
  EXPECT_EQ(row(r, "stem_contact_time_abs_error")->message,
            "stem_contact_time_abs_error: absent (reference_only: the reference reaches stem contact, the engine does "
            "not)");
  EXPECT_EQ(row(r, "jellett_drift_stem")->message, "jellett_drift_stem: absent (the engine never rolled on the stem)");
}

TEST(GateEvaluate, NotANumberFails) {
  Metrics m = fixture_metrics();
  m.tilt_rms_error = std::numeric_limits<double>::quiet_NaN();
  m.compared_until = std::numeric_limits<double>::quiet_NaN();
  const CheckResult r = evaluate_check(fixture_check(), fixture_record("analytic", 17.25), fixture_record("ode", 17.3), m);
  EXPECT_FALSE(r.passed);
  EXPECT_EQ(row(r, "tilt_rms_error")->measured, "nan");
  EXPECT_EQ(row(r, "tilt_rms_error")->message, "tilt_rms_error: no samples in common with the reference");
}

TEST(GateEvaluate, RequireSameEvents) {
  Check c = fixture_check();
  c.max.clear();
  c.require_same_events = true;
  Metrics m = fixture_metrics();  // inversion both, stem contact neither: both acceptable
  CheckResult r = evaluate_check(c, fixture_record("analytic", 17.25), fixture_record("ode", 17.3), m);
  EXPECT_TRUE(r.passed);
  ASSERT_NE(row(r, "inversion_event"), nullptr);
  EXPECT_EQ(row(r, "stem_contact_event")->measured, "neither");

  m.stem_contact_event = "engine_only";
  r = evaluate_check(c, fixture_record("analytic", 17.25), fixture_record("ode", 17.3), m);
  EXPECT_FALSE(r.passed);
  EXPECT_FALSE(row(r, "stem_contact_event")->passed);
  EXPECT_EQ(row(r, "stem_contact_event")->message,
            "stem_contact_event engine_only (the engine reaches stem contact, the reference does not; required on "
            "both sides or neither)");
}

TEST(GateEvaluate, RunStatus) {
  Check c = fixture_check();
  c.max.clear();
  RunRecord eng = fixture_record("ode", std::nullopt);
  eng.status = "diverged";
  eng.status_time = 3.5;
  eng.status_detail = "|omega| > 1e6";
  CheckResult r = evaluate_check(c, fixture_record("analytic", 17.25), eng, fixture_metrics());
  EXPECT_FALSE(r.passed);
  EXPECT_EQ(r.rows[0].measured, "diverged");
  EXPECT_EQ(r.rows[0].message, "status diverged at t = 3.5 (|omega| > 1e6), required ok");
  // A gate may require a status, e.g. that a setting far outside the stable range is caught.
  c.status = "diverged";
  r = evaluate_check(c, fixture_record("analytic", 17.25), eng, fixture_metrics());
  EXPECT_TRUE(r.passed);
}

TEST(GateEvaluate, ErrorResultFails) {
  const CheckResult r = error_result(fixture_check(), "reference run failed: boom");
  EXPECT_FALSE(r.passed);
  ASSERT_EQ(r.rows.size(), 1u);
  EXPECT_EQ(r.rows[0].kind, GateRowKind::Error);
  EXPECT_EQ(r.rows[0].message, "run: reference run failed: boom");
}

// ---- the reference's self-check ---------------------------------------------------------------

TEST(GateEvaluate, AWindowPastTheConvergedReferenceFailsUnlessAllowed) {
  Check c = fixture_check();
  c.loaded.run.duration = 23.0;
  c.require_same_events = true;
  Metrics m = fixture_metrics();
  m.reference_converged_until = 21.37;
  m.compared_until = 21.37;
  m.stem_contact_event = "unconverged";
  CheckResult r = evaluate_check(c, fixture_record("analytic", 17.25), fixture_record("ode", 17.27), m);
  EXPECT_FALSE(r.passed);
  const GateRow* tilt = row(r, "tilt_rms_error");
  ASSERT_NE(tilt, nullptr);
  EXPECT_FALSE(tilt->passed);
  EXPECT_NE(tilt->measured.find("compared to t = 21.37 (reference converged)"), std::string::npos) << tilt->measured;
  EXPECT_NE(tilt->message.find("reference not converged after t = 21.37"), std::string::npos) << tilt->message;
  // The inversion (t = 17.25) is inside the window: judged as usual.
  EXPECT_TRUE(row(r, "inversion_time_rel_error")->passed);
  EXPECT_TRUE(row(r, "inversion_event")->passed);
  EXPECT_FALSE(row(r, "stem_contact_event")->passed);
  EXPECT_NE(row(r, "stem_contact_event")->message.find("reference not converged after t = 21.37"), std::string::npos);
  EXPECT_TRUE(row(r, "energy_gain_events")->passed);  // the engine's own: the whole run
  const std::string junit = render_junit({r}, "suite");
  EXPECT_NE(junit.find("reference not converged after t = 21.37"), std::string::npos);
  EXPECT_NE(render_table({r}).find("compared to t = 21.37 (reference converged)"), std::string::npos);

  c.allow_unconverged = true;
  r = evaluate_check(c, fixture_record("analytic", 17.25), fixture_record("ode", 17.27), m);
  EXPECT_TRUE(r.passed) << render_table({r});
  EXPECT_NE(row(r, "tilt_rms_error")->measured.find("compared to t = 21.37"), std::string::npos);
  EXPECT_EQ(row(r, "stem_contact_event")->measured, "unconverged");

  // A window that reaches the check's end, or no self-check at all: nothing is marked.
  c.allow_unconverged = false;
  c.loaded.run.duration = 21.0;
  m.stem_contact_event = "both";
  r = evaluate_check(c, fixture_record("analytic", 17.25), fixture_record("ode", 17.27), m);
  EXPECT_EQ(row(r, "tilt_rms_error")->measured.find("compared to"), std::string::npos);
  m.reference_converged_until.reset();
  r = evaluate_check(c, fixture_record("analytic", 17.25), fixture_record("ode", 17.27), m);
  EXPECT_TRUE(row(r, "tilt_rms_error")->passed);
}

// ---- the aligned event sequences (measure/event_alignment.h) --------------------------------------

TEST(GateEvaluate, EventTimeBoundPassesAndFails) {
  Check c = fixture_check();
  c.max = {{"event_time_max_error", 0.05}};
  Metrics m = fixture_metrics();
  m.events_reference = 2, m.events_engine = 2, m.events_matched = 2, m.events_missing = 0, m.events_extra = 0;
  m.event_time_max_error = 0.04;
  CheckResult r = evaluate_check(c, fixture_record("analytic", 17.25), fixture_record("ode", 17.29), m);
  EXPECT_TRUE(r.passed) << row(r, "event_time_max_error")->message;
  m.event_time_max_error = 0.06;
  r = evaluate_check(c, fixture_record("analytic", 17.25), fixture_record("ode", 17.31), m);
  EXPECT_FALSE(r.passed);
  EXPECT_EQ(row(r, "event_time_max_error")->message, "event_time_max_error 0.06 > 0.05");
  // A record without the alignment fails the bound with the reason, never passes it.
  m.event_time_max_error.reset();
  r = evaluate_check(c, fixture_record("analytic", 17.25), fixture_record("ode", 17.31), m);
  EXPECT_FALSE(r.passed);
  EXPECT_NE(row(r, "event_time_max_error")->message.find("before the event sequences were aligned"), std::string::npos);
}

TEST(GateEvaluate, RequireNoWrongEvent) {
  Check c = fixture_check();
  c.max.clear();
  c.require_no_wrong_event = true;
  Metrics m = fixture_metrics();
  m.events_reference = 2, m.events_engine = 2, m.events_matched = 2, m.events_missing = 0, m.events_extra = 0;
  m.event_time_max_error = 0.01;
  CheckResult r = evaluate_check(c, fixture_record("analytic", 17.25), fixture_record("ode", 17.3), m);
  EXPECT_TRUE(r.passed);
  ASSERT_NE(row(r, "first_wrong_event"), nullptr);
  EXPECT_EQ(row(r, "first_wrong_event")->measured, "none");

  m.events_matched = 1, m.events_missing = 1, m.events_extra = 1;
  m.first_wrong_event_index = 1;
  m.first_wrong_event = "reference: stem_contact at t=1.23, engine: inversion at t=1.1";
  r = evaluate_check(c, fixture_record("analytic", 17.25), fixture_record("ode", 17.3), m);
  EXPECT_FALSE(r.passed);
  EXPECT_EQ(row(r, "first_wrong_event")->message,
            "first_wrong_event at aligned event 1: reference: stem_contact at t=1.23, engine: inversion at t=1.1 "
            "(1 missing, 1 extra)");
  // Not aligned (an older record): nothing was compared, so it fails.
  r = evaluate_check(c, fixture_record("analytic", 17.25), fixture_record("ode", 17.3), fixture_metrics());
  EXPECT_FALSE(r.passed);
  EXPECT_EQ(row(r, "first_wrong_event")->measured, "absent");
}

}  // namespace test_gate_check
