// The event-sequence section of the comparison report: the alignment's counts per engine and the aligned sequences.
#include "harness/report/compare_events.h"

#include <string>

#include "harness/report/report_text.h"

namespace tippe {

namespace {

using nlohmann::json;
using namespace report_text;

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

  for (const json& e : c.at("engines")) {
    const json& m = e.at("metrics");
    if (!has_number(m, "events_matched")) continue;
    DocTable rows;
    rows.header = {"#", "reference", "engine", "alignment", "time error"};
    rows.css = "detail";
    auto side = [](const json& r, const char* kind, const char* time) {
      if (!r.contains(kind) || !r.at(kind).is_string()) return std::string("none");
      return r.at(kind).get<std::string>() + " at t=" + fmt(num(r, time));
    };
    size_t k = 0;
    if (m.contains("event_alignment") && m.at("event_alignment").is_array())
      for (const json& r : m.at("event_alignment")) {
        const std::string op = str(r, "op");
        const bool ok = op == "match";
        rows.rows.push_back({DocCell(std::to_string(k++)), DocCell(side(r, "reference", "t_reference")),
                             DocCell(side(r, "engine", "t_engine")), DocCell(op, ok ? "" : "bad"),
                             DocCell(ok ? fmt(num(r, "t_engine") - num(r, "t_reference")) : "")});
      }
    const std::string total = count_text(m, "event_alignment_rows");
    std::string summary = str(e, "engine") + ": " + total + " aligned events";
    if (has_number(m, "event_alignment_rows") && num(m, "event_alignment_rows") > static_cast<double>(k))
      summary += " (the first " + std::to_string(k) + " kept in the record)";
    const std::string left_out = str(m, "events_not_compared");
    if (!left_out.empty()) summary += "; not compared: " + left_out;
    if (rows.rows.empty()) rows.rows.push_back({"-", "none", "none", "", ""});
    d.table(rows, summary, true);
  }
}

}  // namespace tippe
