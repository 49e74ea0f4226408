// The event-sequence section of the comparison report: the alignment's counts per engine and the aligned sequences.
#include "report/compare_events.h"

#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "measure/event_alignment.h"
#include "report/report_text.h"

namespace tippe {

namespace {

using nlohmann::json;
using namespace report_text;

// The rows of an aligned sequence shown per engine: the first wrong event is always among them
// when it comes early; a long chatter is summarised by the counts above rather than listed.
constexpr size_t kMaxRowsShown = 40;

std::vector<Event> events_of(const json& summary) {
  std::vector<Event> out;
  if (!summary.contains("events") || !summary.at("events").is_array()) return out;
  for (const json& e : summary.at("events")) {
    if (!e.is_object()) continue;
    out.push_back({str(e, "name"), num(e, "time"), str(e, "detail"), 0.0});
  }
  return out;
}

std::string count_text(const json& m, const char* key) {
  return has_number(m, key) ? std::to_string(m.at(key).get<long long>()) : "-";
}

}  // namespace

void add_event_sequences(Document& d, const json& c) {
  bool any = false;
  for (const json& e : c.at("engines")) any = any || has_number(e.at("metrics"), "events_matched");
  if (!any) return;
  const SceneUnits units = scene_units(c.at("scene"));
  d.heading(2, "Event sequences");
  d.para("Each run's events in the vocabulary both sides can report (first inversion, first stem contact, the contact "
         "surface entered, a failure status), aligned by edit distance; the reference's contact-law events (stick, "
         "slip, impacts, ...) are not compared (docs/events.md). Surface phases shorter than the dwell are merged on "
         "both sides. Times in " + units.time + ".",
         "note");
  DocTable t;
  t.header = {"engine", "reference", "engine events", "matched", "missing", "extra", "max time error", "dwell",
              "first wrong event"};
  t.row_headers = true;
  t.css = "detail";
  for (const json& e : c.at("engines")) {
    const json& m = e.at("metrics");
    if (!has_number(m, "events_matched")) {
      t.rows.push_back({DocCell(str(e, "engine")), "-", "-", "-", "-", "-", "-", "-", "not in this record"});
      continue;
    }
    const std::string wrong = str(m, "first_wrong_event");
    const bool clean = wrong.empty();
    t.rows.push_back({DocCell(str(e, "engine")), DocCell(count_text(m, "events_reference")),
                      DocCell(count_text(m, "events_engine")), DocCell(count_text(m, "events_matched")),
                      DocCell(count_text(m, "events_missing"), num(m, "events_missing") > 0 ? "bad" : "good"),
                      DocCell(count_text(m, "events_extra"), num(m, "events_extra") > 0 ? "bad" : "good"),
                      DocCell(fmt(num(m, "event_time_max_error"))), DocCell(fmt(num(m, "event_min_dwell"))),
                      DocCell(clean ? "none" : "#" + count_text(m, "first_wrong_event_index") + ": " + wrong,
                              clean ? "good" : "bad")});
  }
  d.table(t);

  const json& ref_summary = c.at("reference").at("summary");
  for (const json& e : c.at("engines")) {
    const json& m = e.at("metrics");
    if (!has_number(m, "events_matched")) continue;
    const double dwell = has_number(m, "event_min_dwell") ? num(m, "event_min_dwell") : 0.0;
    const double until = has_number(m, "reference_converged_until") ? num(m, "reference_converged_until")
                                                                     : std::numeric_limits<double>::infinity();
    const CanonicalSequence rs = canonical_events(events_of(ref_summary), dwell, until);
    const CanonicalSequence es = canonical_events(events_of(e.at("summary")), dwell, until);
    const EventAlignment a = align_events(rs.events, es.events);
    DocTable rows;
    rows.header = {"#", "reference", "engine", "alignment", "time error"};
    rows.css = "detail";
    for (size_t k = 0; k < a.pairs.size() && k < kMaxRowsShown; ++k) {
      const AlignedPair& p = a.pairs[k];
      const bool ok = p.op == AlignOp::Match;
      rows.rows.push_back({DocCell(std::to_string(k)), DocCell(event_text(a.reference, p.reference)),
                           DocCell(event_text(a.engine, p.engine)), DocCell(to_string(p.op), ok ? "" : "bad"),
                           DocCell(ok ? fmt(a.engine[*p.engine].time - a.reference[*p.reference].time) : "")});
    }
    std::string summary = str(e, "engine") + ": " + std::to_string(a.pairs.size()) + " aligned events";
    if (a.pairs.size() > kMaxRowsShown) summary += " (the first " + std::to_string(kMaxRowsShown) + " shown)";
    // comparison.json keeps the first switch events of a chattering run only (kMaxSwitchEventsKept):
    // the rows then stop where the record does, while the counts above are of the whole run.
    if (e.at("summary").contains("events_omitted") || ref_summary.contains("events_omitted"))
      summary += "; the record keeps only the first switch events, so rows past them are not shown";
    const std::string left_out = str(m, "events_not_compared");
    if (!left_out.empty()) summary += "; not compared: " + left_out;
    if (rows.rows.empty()) rows.rows.push_back({"-", "none", "none", "", ""});
    d.table(rows, summary, true);
  }
}

}  // namespace tippe
