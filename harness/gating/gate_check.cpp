// CI gates: judging one engine's run against its check's bounds, and the verdicts as a table, JUnit XML and JSON.
#include "harness/gating/gate.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <set>
#include <sstream>

#include "harness/io/scene_io.h"
#include "harness/io/text.h"
#include "harness/records/records.h"
#include "engines/core/registry.h"

namespace tippe {

using nlohmann::json;

// ---- evaluation -----------------------------------------------------------------------------

namespace {

// "the engine inverts, the reference does not" and the like, for an event pairing.
std::string event_story(const std::string& which, const char* verb, const char* noun) {
  if (which == "engine_only") return std::string("the engine ") + verb + ", the reference does not";
  if (which == "reference_only") return std::string("the reference ") + verb + ", the engine does not";
  if (which == "neither") return std::string("neither the engine nor the reference ") + verb;
  if (which == "both") return std::string("both have the ") + noun + "; the reference's is at t = 0, so no relative error";
  if (which == "unconverged")
    return std::string("not judged: the reference is not converged where the ") + noun + " is (or would be)";
  return "no event comparison";
}

// Why a metric has no value in this comparison.
std::string absent_reason(const std::string& metric, const Metrics& m) {
  if (metric.rfind("inversion_", 0) == 0)
    return m.inversion_event + ": " + event_story(m.inversion_event, "inverts", "inversion");
  if (metric.rfind("stem_contact_", 0) == 0)
    return m.stem_contact_event + ": " + event_story(m.stem_contact_event, "reaches stem contact", "stem contact");
  if (metric == "event_time_max_error" || metric == "events_missing" || metric == "events_extra")
    return "a record written before the event sequences were aligned";
  if (metric == "jellett_drift_ball") return "the engine never rolled on the ball";
  if (metric == "jellett_drift_stem") return "the engine never rolled on the stem";
  if (metric == "numerical_energy_max" || metric == "numerical_energy_final" || metric == "friction_work" ||
      metric == "normal_work" || metric == "elastic_energy_max")
    return "the energy ledger: not available for this engine, or a record written before the ledger";
  if (metric == "friction_work_reference_sticks")
    return "the reference's contact never sticks in the compared window, the engine has no ledger, or a record "
           "written before this metric";
  return "not computed";
}

std::string nan_reason(const std::string& metric, const Metrics& m) {
  if (metric == "energy_final_ratio") return "the engine produced no samples";
  if (!std::isfinite(m.compared_until) && metric != "compared_until" && metric != "steps" && metric != "cost_ratio")
    return "no samples in common with the reference";
  return "not a number";
}

// "0.0812" or "|-0.0812|": the message says what was compared.
std::string compared(double v) { return v < 0 ? "|" + short_value(v) + "|" : short_value(v); }

GateRow status_row(const Check& c, const RunRecord& engine) {
  GateRow r;
  r.kind = GateRowKind::Status;
  r.metric = "status";
  r.measured = engine.status;
  r.required = c.status;
  r.passed = engine.status == c.status;
  if (!r.passed) {
    r.message = "status " + engine.status;
    if (engine.status != "ok") {
      r.message += " at t = " + short_value(engine.status_time);
      if (!engine.status_detail.empty()) r.message += " (" + engine.status_detail + ")";
    }
    r.message += ", required " + c.status;
  }
  return r;
}

GateRow event_row(const std::string& metric, const std::string& which, const char* verb, const char* noun) {
  GateRow r;
  r.kind = GateRowKind::Events;
  r.metric = metric;
  r.measured = which.empty() ? "?" : which;
  r.required = "both|neither";
  r.passed = which == "both" || which == "neither";
  if (!r.passed)
    r.message = metric + " " + r.measured + " (" + event_story(which, verb, noun) + "; required on both sides or neither)";
  return r;
}

// require_no_wrong_event: the aligned event sequences (measure/event_alignment.h) have no first
// wrong event. A record without the alignment fails: nothing was compared.
GateRow wrong_event_row(const Metrics& m) {
  GateRow r;
  r.kind = GateRowKind::Events;
  r.metric = "first_wrong_event";
  r.required = "none";
  if (!m.events_matched) {
    r.measured = "absent";
    r.message = "first_wrong_event: absent (the event sequences were not aligned)";
    return r;
  }
  r.measured = m.first_wrong_event.empty() ? "none" : m.first_wrong_event;
  r.passed = m.first_wrong_event.empty();
  if (!r.passed)
    r.message = "first_wrong_event at aligned event " + std::to_string(m.first_wrong_event_index.value_or(-1)) + ": " +
                m.first_wrong_event + " (" + std::to_string(m.events_missing.value_or(0)) + " missing, " +
                std::to_string(m.events_extra.value_or(0)) + " extra)";
  return r;
}

}  // namespace

GateRow threshold_row(const Threshold& t, const Metrics& m) {
  GateRow r;
  r.kind = GateRowKind::Threshold;
  r.metric = t.metric;
  r.limit = t.max;
  r.required = short_value(t.max);
  const GateMetric* g = find_gate_metric(t.metric);
  r.value = g ? g->get(m) : std::nullopt;
  if (!g) {
    r.measured = "unknown";
    r.message = t.metric + ": not a gate metric";
  } else if (!r.value) {
    r.measured = "absent";
    r.message = t.metric + ": absent (" + absent_reason(t.metric, m) + ")";
  } else if (std::isnan(*r.value)) {
    r.measured = "nan";
    r.message = t.metric + ": " + nan_reason(t.metric, m);
  } else {
    r.measured = short_value(*r.value);
    r.passed = std::abs(*r.value) <= t.max;
    if (!r.passed) r.message = t.metric + " " + compared(*r.value) + " > " + short_value(t.max);
  }
  return r;
}

namespace {

// Metrics computed over the samples the reference and the engine have in common: cut at the end
// of the reference's converged window.
bool windowed_metric(const std::string& metric) {
  static const std::set<std::string> names = {"tilt_max_error",         "tilt_rms_error",         "energy_max_error",
                                              "contact_path_rms_error", "contact_path_max_error", "com_path_rms_error",
                                              "com_path_max_error",     "latitude_rms_error",     "compared_until",
                                              // the event alignment leaves out events after the window
                                              "event_time_max_error",   "events_missing",         "events_extra",
                                              "first_wrong_event",
                                              // from the reference's stick events inside the window
                                              "friction_work_reference_sticks"};
  return names.count(metric) > 0;
}

bool event_metric(const std::string& metric, std::string* which, const Metrics& m) {
  if (metric.rfind("inversion_", 0) == 0) {
    *which = m.inversion_event;
    return true;
  }
  if (metric.rfind("stem_contact_", 0) == 0) {
    *which = m.stem_contact_event;
    return true;
  }
  return false;
}

// The rows of a check that runs past the end of the reference's converged window, marked and
// (unless the check allows it) failed.
void mark_unconverged(std::vector<GateRow>& rows, const Check& check, const Metrics& m) {
  if (!m.reference_converged_until || !(*m.reference_converged_until < check.loaded.run.duration)) return;
  const std::string x = short_value(*m.reference_converged_until);
  const std::string why = "reference not converged after t = " + x + " (the check runs to t = " +
                          short_value(check.loaded.run.duration) + ")";
  for (GateRow& row : rows) {
    std::string which;
    // The aligned sequences are windowed like the sample metrics, not an event pairing.
    const bool aligned = row.metric == "first_wrong_event";
    const bool event = (row.kind == GateRowKind::Events && !aligned) ||
                       (row.kind == GateRowKind::Threshold && event_metric(row.metric, &which, m));
    if (row.kind == GateRowKind::Events) which = row.measured;
    if (event) {
      if (which != "unconverged") continue;  // the pairing was judged inside the window
      row.measured = "unconverged";
      row.passed = check.allow_unconverged;
      row.message = row.passed ? "" : row.metric + ": " + why + "; the event is not judged";
      continue;
    }
    if ((row.kind != GateRowKind::Threshold && !aligned) || !windowed_metric(row.metric)) continue;
    row.measured += " compared to t = " + x + " (reference converged)";
    if (check.allow_unconverged) continue;  // judged on the window, and marked
    row.passed = false;
    row.message = row.metric + ": " + why + "; compared to t = " + x + " only";
  }
}

bool rows_pass(const std::vector<GateRow>& rows) {
  return std::all_of(rows.begin(), rows.end(), [](const GateRow& r) { return r.passed; });
}

CheckResult result_head(const Check& c) {
  CheckResult r;
  r.name = c.name;
  r.engine = c.engine;
  r.scene = c.scene;
  r.set = c.set;
  return r;
}

const char* kind_name(GateRowKind k) {
  switch (k) {
    case GateRowKind::Status: return "status";
    case GateRowKind::Events: return "events";
    case GateRowKind::Threshold: return "threshold";
    case GateRowKind::Error: return "error";
  }
  return "?";
}

// Text and attribute values: the five XML specials, and control characters XML 1.0 cannot
// carry at all (an engine's status detail could hold any byte).

std::string seconds_text(double s) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.3f", std::isfinite(s) && s > 0 ? s : 0.0);
  return buf;
}

std::vector<std::string> failure_messages(const CheckResult& r) {
  std::vector<std::string> out;
  for (const GateRow& row : r.rows)
    if (!row.passed) out.push_back(row.message);
  return out;
}

}  // namespace

CheckResult evaluate_check(const Check& check, const RunRecord& reference, const RunRecord& engine,
                           const Metrics& metrics) {
  (void)reference;  // the metrics already hold everything compared against it
  CheckResult r = result_head(check);
  r.seconds = engine.work.wall_seconds;
  r.rows.push_back(status_row(check, engine));
  if (check.require_same_events) {
    r.rows.push_back(event_row("inversion_event", metrics.inversion_event, "inverts", "inversion"));
    r.rows.push_back(event_row("stem_contact_event", metrics.stem_contact_event, "reaches stem contact", "stem contact"));
  }
  if (check.require_no_wrong_event) r.rows.push_back(wrong_event_row(metrics));
  for (const Threshold& t : check.max) r.rows.push_back(threshold_row(t, metrics));
  mark_unconverged(r.rows, check, metrics);
  r.passed = rows_pass(r.rows);
  return r;
}

CheckResult error_result(const Check& check, const std::string& why) {
  CheckResult r = result_head(check);
  GateRow row;
  row.kind = GateRowKind::Error;
  row.metric = "run";
  row.measured = "error";
  row.required = "ok";
  row.message = "run: " + why;
  r.rows.push_back(row);
  r.passed = false;
  return r;
}

bool all_passed(const std::vector<CheckResult>& results) {
  return std::all_of(results.begin(), results.end(), [](const CheckResult& r) { return r.passed; });
}

std::string render_table(const std::vector<CheckResult>& results) {
  std::vector<std::array<std::string, 6>> lines;
  lines.push_back({"check", "engine", "metric", "measured", "threshold", "verdict"});
  for (const CheckResult& r : results)
    for (const GateRow& row : r.rows)
      lines.push_back({r.name, r.engine, row.metric, row.measured, row.required, row.passed ? "pass" : "FAIL"});
  std::array<size_t, 6> width{};
  for (const auto& l : lines)
    for (size_t k = 0; k < l.size(); ++k) width[k] = std::max(width[k], l[k].size());

  std::string out;
  for (size_t i = 0; i < lines.size(); ++i) {
    std::string line;
    for (size_t k = 0; k < 6; ++k) {
      std::string cell = lines[i][k];
      // Numbers line up on the right, names on the left.
      const bool right = k == 3 || k == 4;
      const std::string pad(width[k] - cell.size(), ' ');
      line += right ? pad + cell : (k + 1 < 6 ? cell + pad : cell);
      if (k + 1 < 6) line += "  ";
    }
    out += line + "\n";
    if (i == 0) {
      size_t total = 0;
      for (size_t k = 0; k < 6; ++k) total += width[k] + (k + 1 < 6 ? 2 : 0);
      out += std::string(total, '-') + "\n";
    }
  }
  size_t passed = 0;
  for (const CheckResult& r : results) passed += r.passed;
  out += "\ngate: " + std::to_string(passed) + " of " + std::to_string(results.size()) +
         " checks passed (a threshold bounds |measured|)";
  out += passed == results.size() ? "\n" : "; failing:\n";
  for (const CheckResult& r : results)
    for (const std::string& m : failure_messages(r)) out += "  " + r.name + ": " + m + "\n";
  return out;
}

std::string render_junit(const std::vector<CheckResult>& results, const std::string& suite_name) {
  size_t failures = 0, errors = 0;
  double total = 0;
  for (const CheckResult& r : results) {
    const bool errored = std::any_of(r.rows.begin(), r.rows.end(),
                                     [](const GateRow& row) { return row.kind == GateRowKind::Error; });
    if (errored)
      ++errors;
    else if (!r.passed)
      ++failures;
    if (std::isfinite(r.seconds) && r.seconds > 0) total += r.seconds;
  }
  const std::string suite = markup_escape(suite_name, true);
  const std::string counts = " tests=\"" + std::to_string(results.size()) + "\" failures=\"" +
                             std::to_string(failures) + "\" errors=\"" + std::to_string(errors) + "\"";
  std::string x = "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n";
  x += "<testsuites name=\"" + suite + "\"" + counts + " time=\"" + seconds_text(total) + "\">\n";
  x += "  <testsuite name=\"" + suite + "\"" + counts + " skipped=\"0\" time=\"" + seconds_text(total) + "\">\n";
  for (const CheckResult& r : results) {
    x += "    <testcase classname=\"" + suite + "\" name=\"" + markup_escape(r.name, true) + "\" time=\"" +
         seconds_text(r.seconds) + "\"";
    if (r.passed) {
      x += "/>\n";
      continue;
    }
    x += ">\n";
    // The details repeat every line of the check, so the CI page shows what passed beside what did not.
    std::string details = "engine " + r.engine + ", scene " + r.scene;
    if (!r.set.empty()) details += ", set " + join(r.set, " ");
    details += "\n";
    GateRowKind first_kind = GateRowKind::Threshold;
    bool first = true;
    for (const GateRow& row : r.rows) {
      details += (row.passed ? "pass " : "FAIL ") + row.metric + " = " + row.measured + " (required " +
                 (row.kind == GateRowKind::Threshold ? "|value| <= " : "") + row.required + ")";
      if (!row.passed) details += ": " + row.message;
      details += "\n";
      if (!row.passed && first) {
        first_kind = row.kind;
        first = false;
      }
    }
    const std::string tag = first_kind == GateRowKind::Error ? "error" : "failure";
    x += "      <" + tag + " message=\"" + markup_escape(join(failure_messages(r), "; "), true) + "\" type=\"" +
         kind_name(first_kind) + "\">" + markup_escape(details, false) + "</" + tag + ">\n";
    x += "    </testcase>\n";
  }
  x += "  </testsuite>\n</testsuites>\n";
  return x;
}

const std::vector<std::string>& gate_row_kind_names() {
  static const std::vector<std::string> names = [] {
    std::vector<std::string> n;
    for (GateRowKind k : {GateRowKind::Status, GateRowKind::Events, GateRowKind::Threshold, GateRowKind::Error})
      n.emplace_back(kind_name(k));
    return n;
  }();
  return names;
}

json to_json(const std::vector<CheckResult>& results) {
  json list = json::array();
  size_t failed = 0;
  for (const CheckResult& r : results) {
    failed += !r.passed;
    list.push_back(JsonWriter::write(r));
  }
  return json{{"format", kGateResultFormat},
              {"passed", failed == 0},
              {"checks", results.size()},
              {"failed", failed},
              {"results", list}};
}

}  // namespace tippe
