// Tests of the event-sequence alignment: the canonical vocabulary, the edit-distance alignment, the metrics' record round trip, and a real comparison's fields.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>

#include "harness/measure/event_alignment.h"
#include "harness/records/comparison.h"
#include "tests/support/files.h"

namespace test_event_alignment {

namespace fs = std::filesystem;
using namespace tippe;
using nlohmann::json;

namespace {

std::vector<CanonicalEvent> seq(std::initializer_list<std::pair<const char*, double>> events) {
  std::vector<CanonicalEvent> out;
  for (const auto& [kind, t] : events) out.push_back({kind, t});
  return out;
}

}  // namespace

// ---- the alignment (pure) ---------------------------------------------------------------------

TEST(EventAlignment, IdenticalSequencesMatchWithZeroError) {
  const auto s = seq({{"inversion", 1.0}, {"stem_contact", 2.0}, {"surface:stem", 2.0}});
  const EventAlignment a = align_events(s, s);
  EXPECT_EQ(a.matched, 3);
  EXPECT_EQ(a.missing, 0);
  EXPECT_EQ(a.extra, 0);
  EXPECT_EQ(a.time_max_error, 0.0);
  EXPECT_FALSE(a.first_wrong.has_value());
  EXPECT_EQ(a.first_wrong_text, "");
}

TEST(EventAlignment, OneMissing) {
  const EventAlignment a = align_events(seq({{"inversion", 1.0}, {"stem_contact", 2.0}, {"surface:stem", 2.1}}),
                                        seq({{"inversion", 1.0}, {"surface:stem", 2.1}}));
  EXPECT_EQ(a.matched, 2);
  EXPECT_EQ(a.missing, 1);
  EXPECT_EQ(a.extra, 0);
  ASSERT_TRUE(a.first_wrong.has_value());
  EXPECT_EQ(*a.first_wrong, 1u);
  EXPECT_EQ(a.pairs[1].op, AlignOp::Missing);
  EXPECT_EQ(a.first_wrong_text, "reference: stem_contact at t=2, engine: none");
}

TEST(EventAlignment, OneExtra) {
  const EventAlignment a = align_events(seq({{"inversion", 1.0}}), seq({{"surface:none", 0.5}, {"inversion", 1.0}}));
  EXPECT_EQ(a.matched, 1);
  EXPECT_EQ(a.missing, 0);
  EXPECT_EQ(a.extra, 1);
  ASSERT_TRUE(a.first_wrong.has_value());
  EXPECT_EQ(*a.first_wrong, 0u);
  EXPECT_EQ(a.first_wrong_text, "reference: none, engine: surface:none at t=0.5");
}

TEST(EventAlignment, SubstitutionCountsOneMissingAndOneExtra) {
  const EventAlignment a = align_events(seq({{"inversion", 1.0}, {"stem_contact", 1.23}}),
                                        seq({{"inversion", 1.0}, {"surface:both", 1.1}}));
  EXPECT_EQ(a.matched, 1);
  EXPECT_EQ(a.substituted, 1);
  EXPECT_EQ(a.missing, 1);  // matched + missing = the reference's count
  EXPECT_EQ(a.extra, 1);    // matched + extra = the engine's
  ASSERT_EQ(a.pairs.size(), 2u);
  EXPECT_EQ(a.pairs[1].op, AlignOp::Substitution);
  EXPECT_EQ(a.first_wrong_text, "reference: stem_contact at t=1.23, engine: surface:both at t=1.1");
}

TEST(EventAlignment, TimeErrorsOfMatchedEventsAndTheirTieBreak) {
  // Both engine "surface:ball" events could pair with the reference's by kind alone: the
  // alignment pairs the nearer one, the first (ties in edit count are broken by the matched time
  // errors; the trace back alone would take the last).
  const EventAlignment a = align_events(seq({{"surface:both", 2.0}, {"surface:ball", 3.0}}),
                                        seq({{"surface:both", 2.25}, {"surface:ball", 2.95}, {"surface:ball", 3.5}}));
  EXPECT_EQ(a.matched, 2);
  EXPECT_EQ(a.extra, 1);
  EXPECT_DOUBLE_EQ(a.time_max_error, 0.25);
  ASSERT_EQ(a.pairs.size(), 3u);
  EXPECT_EQ(a.pairs[1].op, AlignOp::Match);
  EXPECT_EQ(*a.pairs[1].engine, 1u);
  EXPECT_EQ(a.pairs[2].op, AlignOp::Extra);
}

TEST(EventAlignment, EmptySides) {
  const EventAlignment none = align_events({}, {});
  EXPECT_EQ(none.matched + none.missing + none.extra, 0);
  EXPECT_TRUE(none.pairs.empty());
  EXPECT_FALSE(none.first_wrong.has_value());
  const EventAlignment ref_only = align_events(seq({{"inversion", 1.0}}), {});
  EXPECT_EQ(ref_only.missing, 1);
  EXPECT_EQ(ref_only.first_wrong_text, "reference: inversion at t=1, engine: none");
  const EventAlignment eng_only = align_events({}, seq({{"inversion", 1.0}, {"stem_contact", 2.0}}));
  EXPECT_EQ(eng_only.extra, 2);
  EXPECT_EQ(eng_only.time_max_error, 0.0);  // nothing matched: nothing off
}

// ---- the canonical vocabulary ---------------------------------------------------------------------

TEST(EventAlignment, CanonicalVocabularyMapsBothSidesAndCountsWhatIsLeftOut) {
  // A reference's sequence: contact-law events are left out, counted; the second inversion too.
  const std::vector<Event> ref = {{"stick", 0.02, "slip vanishes on the ball", 0},
                                  {"inversion", 1.0, "", 0},
                                  {"reversion", 1.1, "", 0},
                                  {"inversion", 1.2, "", 0},
                                  {"impact", 2.0, "stem touches down", 0},
                                  {"stem_contact", 2.0, "first stem touchdown", 0},
                                  {"switch", 2.0, "ball -> stem", 0},
                                  {"failed", 3.0, "step size underflow", 0}};
  const CanonicalSequence r = canonical_events(ref, 0.0);
  ASSERT_EQ(r.events.size(), 4u);
  EXPECT_EQ(r.events[0].kind, "inversion");
  EXPECT_EQ(r.events[0].time, 1.0);
  EXPECT_EQ(r.events[1].kind, "stem_contact");
  EXPECT_EQ(r.events[2].kind, "surface:stem");
  EXPECT_EQ(r.events[3].kind, "status:failed");
  EXPECT_EQ(r.not_compared.at("stick"), 1);
  EXPECT_EQ(r.not_compared.at("impact"), 1);
  EXPECT_EQ(r.not_compared.at("reversion"), 1);
  EXPECT_EQ(r.not_compared.at("inversion (after the first)"), 1);
  // The window leaves later events out, counted.
  const CanonicalSequence w = canonical_events(ref, 0.0, 1.5);
  EXPECT_EQ(w.events.size(), 1u);
  EXPECT_EQ(w.not_compared.at("after the window"), 3);
}

TEST(EventAlignment, ShortSurfacePhasesMergeOnEitherSide) {
  // Soft-contact chatter: ball -> none -> ball within one step, then a real change to both.
  const std::vector<Event> chatter = {{"switch", 0.100, "ball -> none", 0}, {"switch", 0.101, "none -> ball", 0},
                                      {"switch", 0.200, "ball -> none", 0}, {"switch", 0.2005, "none -> ball", 0},
                                      {"switch", 1.000, "ball -> both", 0}, {"switch", 1.5, "both -> ball", 0}};
  const CanonicalSequence c = canonical_events(chatter, 0.01);
  ASSERT_EQ(c.events.size(), 2u);
  EXPECT_EQ(c.events[0].kind, "surface:both");
  EXPECT_EQ(c.events[0].time, 1.0);
  EXPECT_EQ(c.events[1].kind, "surface:ball");
  EXPECT_EQ(c.not_compared.at("surface (phase < dwell)"), 4);
  // Without a dwell, every change counts.
  EXPECT_EQ(canonical_events(chatter, 0.0).events.size(), 6u);
}

// ---- the metrics record -----------------------------------------------------------------------------

TEST(EventAlignment, MetricsRoundTripAndOldRecordsLoad) {
  Metrics m;
  m.inversion_event = "both";
  m.stem_contact_event = "neither";
  m.events_reference = 4, m.events_engine = 5, m.events_matched = 3, m.events_missing = 1, m.events_extra = 2;
  m.event_time_max_error = 0.125;
  m.first_wrong_event_index = 2;
  m.first_wrong_event = "reference: surface:stem at t=4.638, engine: none";
  m.events_not_compared = "stick 1 (reference)";
  m.event_min_dwell = 0.0039;
  m.event_alignment = {{"match", "inversion", "inversion", 4.328, 4.2},
                       {"missing", "surface:stem", "", 4.638, std::nullopt},
                       {"extra", "", "surface:none", std::nullopt, 4.7}};
  m.event_alignment_rows = 3;
  const json j = to_json(m);
  const Metrics back = metrics_from_json(json::parse(j.dump()));
  EXPECT_EQ(to_json(back), j);
  EXPECT_EQ(back.first_wrong_event, m.first_wrong_event);
  EXPECT_EQ(*back.events_matched, 3);
  ASSERT_EQ(back.event_alignment.size(), 3u);
  EXPECT_EQ(back.event_alignment[1].reference_kind, "surface:stem");
  EXPECT_FALSE(back.event_alignment[1].engine_time.has_value());

  // A record written before the alignment: the fields are absent and read as absent.
  json old = j;
  for (const char* k : {"events_reference", "events_engine", "events_matched", "events_missing", "events_extra",
                        "event_time_max_error", "first_wrong_event_index", "first_wrong_event", "events_not_compared",
                        "event_min_dwell", "event_alignment", "event_alignment_rows"})
    old.erase(k);
  const Metrics o = metrics_from_json(old);
  EXPECT_FALSE(o.events_matched.has_value());
  EXPECT_FALSE(o.event_time_max_error.has_value());
  EXPECT_EQ(o.first_wrong_event, "");

  // Present, they are checked, with the key named.
  json bad = j;
  bad["events_missing"] = -1;
  try {
    metrics_from_json(bad);
    FAIL() << "a negative count loaded";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("metrics.events_missing"), std::string::npos) << e.what();
  }
  bad = j;
  bad["event_alignment"][0]["op"] = "swap";
  EXPECT_THROW(metrics_from_json(bad), std::invalid_argument);
  bad = j;
  bad["first_wrong_event_index"] = nullptr;
  EXPECT_THROW(metrics_from_json(bad), std::invalid_argument);
}

// ---- end to end: a shipped scene's comparison ---------------------------------------------------------

TEST(EventAlignment, ShippedSceneComparisonCarriesConsistentFields) {
  TempDir d{"tippe-events"};
  const fs::path out = d.path() / "out";
  // toy_viscous to 5 s: the reference inverts, touches down on the stem and bounces before its
  // converged window ends (4.79 s). The four engines that run it in well under a second each
  // (Simbody and Siconos take seconds; the fields are the same code for every engine).
  const std::string cmd = std::string(TIPPE_BINARY_DIR) + "/tippe compare " + TIPPE_SOURCE_DIR +
                          "/harness/scenes/toy_viscous.toml --set run.duration=5 --engines bullet,ode,mujoco,dart --out " + out.string() +
                          " --no-plots >" + (d.path() / "log.txt").string() + " 2>&1";
  ASSERT_EQ(std::system(cmd.c_str()), 0) << slurp(d.path() / "log.txt");
  const json c = json::parse(slurp(out / "comparison.json"));
  ASSERT_FALSE(c.at("engines").empty());
  for (const json& e : c.at("engines")) {
    const json& m = e.at("metrics");
    const std::string name = e.at("engine").get<std::string>();
    for (const char* k : {"events_reference", "events_engine", "events_matched", "events_missing", "events_extra"})
      ASSERT_TRUE(m.at(k).is_number_integer()) << name << " " << k;
    const long long ref = m.at("events_reference"), eng = m.at("events_engine"), matched = m.at("events_matched"),
                    missing = m.at("events_missing"), extra = m.at("events_extra");
    EXPECT_GT(ref, 0) << name << ": the reference inverts within the window";
    EXPECT_EQ(matched + missing, ref) << name;
    EXPECT_EQ(matched + extra, eng) << name;
    ASSERT_TRUE(m.at("event_time_max_error").is_number()) << name;
    EXPECT_GE(m.at("event_time_max_error").get<double>(), 0.0) << name;
    const bool wrong = !m.at("first_wrong_event").is_null();
    EXPECT_EQ(wrong, missing + extra > 0) << name;
    EXPECT_EQ(wrong, m.at("first_wrong_event_index").is_number_integer()) << name;
    if (wrong) {
      EXPECT_EQ(m.at("first_wrong_event").get<std::string>().rfind("reference: ", 0), 0u) << name;
    }
    // The rows the record keeps agree with the counts and the first wrong event.
    const json& rows = m.at("event_alignment");
    EXPECT_EQ(static_cast<long long>(rows.size()), std::min<long long>(m.at("event_alignment_rows").get<long long>(), 20)) << name;
    if (wrong && m.at("first_wrong_event_index").get<long long>() < static_cast<long long>(rows.size())) {
      EXPECT_NE(rows.at(m.at("first_wrong_event_index").get<size_t>()).at("op"), "match") << name;
    }
    // The reference's contact-law events are said to be left out, not counted as missing.
    EXPECT_NE(m.at("events_not_compared").get<std::string>().find("impact"), std::string::npos) << name;
    // The engine's inversion, when inside the window, is the reference's first canonical event
    // matched (every engine inverts on this scene; Bullet's comes after the window).
    const json& inv = e.at("summary").at("inversion_time");
    const double t_inv = inv.is_number() ? inv.get<double>() : -1.0;
    const double window = m.at("reference_converged_until").is_number() ? m.at("reference_converged_until").get<double>() : 1e300;
    if (t_inv >= 0 && t_inv <= window) {
      EXPECT_GE(matched, 1) << name;
    }
  }
  const std::string report = slurp(out / "report.md");
  EXPECT_NE(report.find("## Event sequences"), std::string::npos);
  EXPECT_NE(report.find("| engine | reference | engine events | matched | missing | extra |"), std::string::npos);
}

}  // namespace test_event_alignment
