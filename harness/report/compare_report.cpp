// The comparison report: the verdict, tables, findings and the page as one document, from comparison.json alone.
#include "harness/report/report.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <map>
#include <sstream>
#include <utility>

#include "harness/measure/compare.h"
#include "harness/records/records.h"
#include "harness/report/compare_events.h"
#include "harness/report/compare_ledger.h"
#include "harness/report/ledger_chart.h"
#include "harness/report/report_text.h"

namespace tippe {

namespace {

namespace fs = std::filesystem;
using nlohmann::json;

using namespace report_text;

std::string scalar_text(const json& v) {
  if (v.is_string()) {
    // Settings are stored with round-trip precision (0.20000000000000001); a page wants 0.2.
    const std::string s = v.get<std::string>();
    char* end = nullptr;
    const double x = std::strtod(s.c_str(), &end);
    if (!s.empty() && end && *end == '\0' && std::isfinite(x)) return fmt(x, "%.12g");
    return s;
  }
  if (v.is_number_float()) return fmt(v.get<double>(), "%.10g");
  return v.dump();
}

// A cell of the summary table: its text and how it fares against the tolerances.
enum class Grade { None, Good, Warn, Bad };
struct Cell {
  std::string text;
  Grade grade = Grade::None;
};

const char* grade_class(Grade g) {
  switch (g) {
    case Grade::Good: return "good";
    case Grade::Warn: return "warn";
    case Grade::Bad: return "bad";
    case Grade::None: break;
  }
  return "";
}

Grade grade_against(const json& comparison, const std::string& metric, double value, double green = NAN,
                    double amber = NAN) {
  if (comparison.contains("tolerances") && comparison["tolerances"].contains(metric)) {
    const json& t = comparison["tolerances"][metric];
    green = num(t, "green");
    amber = num(t, "amber");
  }
  if (!std::isfinite(value) || !std::isfinite(green)) return Grade::None;
  const double a = std::abs(value);
  if (a < green) return Grade::Good;
  if (std::isfinite(amber) && a < amber) return Grade::Warn;
  return Grade::Bad;
}

std::string event_name(const std::string& key) { return key == "inversion" ? "inversion" : "stem contact"; }

// The error cell of one event: signed error and relative error, or which side lacks it.
Cell event_error_cell(const json& comparison, const json& metrics, const std::string& key) {
  const std::string which = str(metrics, (key + "_event").c_str());
  if (which == "reference_only") return {"missing", Grade::Bad};
  if (which == "engine_only") return {"extra", Grade::Bad};
  if (which == "unconverged") return {"unconverged", Grade::Warn};
  if (which != "both") return {"-", Grade::None};
  const double abs_err = num(metrics, (key + "_time_abs_error").c_str());
  const double rel_err = num(metrics, (key + "_time_rel_error").c_str());
  std::string text = fmt(abs_err, "%+.3g");
  if (std::isfinite(rel_err)) text += " (" + fmt(100 * rel_err, "%+.2g") + " %)";
  return {text, grade_against(comparison, key + "_time_rel_error", rel_err, kEventTimeGreenBand, kEventTimeAmberBand)};
}

std::string cpu_text(const json& summary, bool cached) {
  std::string s = fmt(num(summary.at("work"), "cpu_seconds"), "%.3g");
  return cached ? s + " (cached)" : s;
}

struct Table {
  std::vector<std::string> header;
  std::vector<std::vector<Cell>> rows;
};

Table summary_table(const json& c) {
  Table t;
  t.header = {"engine", "status", "inversion t", "inversion error", "stem contact t", "stem contact error",
              "tilt RMS (rad)", "energy max error (/E0)", "contact path RMS (/R)", "Jellett drift", "steps",
              "CPU s", "cost ratio"};
  const json& ref = c.at("reference").at("summary");
  const bool cached = c.at("reference").value("cached", false);
  const std::string ok = "ok";
  t.rows.push_back({{"reference (" + str(ref, "engine") + ")"},
                    {status_text(ref), str(ref, "status") == ok ? Grade::Good : Grade::Bad},
                    {fmt(num(ref, "inversion_time"), "%.6g")},
                    {"-"},
                    {fmt(num(ref, "stem_contact_time"), "%.6g")},
                    {"-"},
                    {"-"},
                    {"-"},
                    {"-"},
                    {fmt(num(ref, "jellett_max_relative_drift"), "%.2g")},
                    {std::to_string(ref.at("work").value("steps", 0LL))},
                    {cpu_text(ref, cached)},
                    {"1"}});
  for (const json& e : c.at("engines")) {
    const json& s = e.at("summary");
    const json& m = e.at("metrics");
    t.rows.push_back({
        {str(e, "engine")},
        {status_text(s), str(s, "status") == ok ? Grade::Good : Grade::Bad},
        {fmt(num(s, "inversion_time"), "%.6g")},
        event_error_cell(c, m, "inversion"),
        {fmt(num(s, "stem_contact_time"), "%.6g")},
        event_error_cell(c, m, "stem_contact"),
        {fmt(num(m, "tilt_rms_error"), "%.3g"), grade_against(c, "tilt_rms_error", num(m, "tilt_rms_error"))},
        {fmt(num(m, "energy_max_error"), "%.3g"), grade_against(c, "energy_max_error", num(m, "energy_max_error"))},
        {fmt(num(m, "contact_path_rms_error"), "%.3g"),
         grade_against(c, "contact_path_rms_error", num(m, "contact_path_rms_error"))},
        {fmt(num(m, "jellett_max_relative_drift"), "%.2g"),
         grade_against(c, "jellett_max_relative_drift", num(m, "jellett_max_relative_drift"))},
        {std::to_string(m.value("steps", 0LL))},
        {cpu_text(s, false)},
        {fmt(num(m, "cost_ratio"), "%.3g"), grade_against(c, "cost_ratio", num(m, "cost_ratio"))},
    });
  }
  return t;
}

// Contact-surface changes the run reported, including those comparison.json only counts.
long long switch_count(const json& summary) {
  long long n = 0;
  for (const json& e : summary.value("events", json::array())) n += str(e, "name") == "switch";
  if (summary.contains("events_omitted")) n += summary["events_omitted"].value("switch", 0LL);
  return n;
}

// Everything in Metrics that the summary leaves out.
Table detail_table(const json& c) {
  Table t;
  t.header = {"engine",         "compared to t",   "reference converged to t", "tilt max (rad)",    "E final/E0",      "E gain events",
              "max gain (/E0)", "contact path max (/R)", "G path RMS (/R)", "G path max (/R)", "latitude RMS (rad)",
              "Jellett ball",   "Jellett stem",    "surface switches",  "friction work while the reference sticks (/E0)",
              "wall s",         "real-time factor"};
  for (const json& e : c.at("engines")) {
    const json& m = e.at("metrics");
    auto cell = [&](const char* key, const char* spec = "%.3g") {
      return Cell{fmt(num(m, key), spec), grade_against(c, key, num(m, key))};
    };
    const long long gains = m.value("energy_gain_events", 0LL);
    t.rows.push_back({{str(e, "engine")},
                      cell("compared_until", "%.6g"),
                      {m.contains("reference_converged_until")
                           ? (has_number(m, "reference_converged_until") ? fmt(num(m, "reference_converged_until"), "%.6g")
                                                                         : std::string("whole run"))
                           : std::string("unchecked"),
                       has_number(m, "reference_converged_until") ? Grade::Warn : Grade::None},
                      cell("tilt_max_error"),
                      cell("energy_final_ratio", "%.6g"),
                      {std::to_string(gains), gains > 0 ? Grade::Bad : Grade::None},
                      cell("energy_max_gain"),
                      cell("contact_path_max_error"),
                      cell("com_path_rms_error"),
                      cell("com_path_max_error"),
                      cell("latitude_rms_error"),
                      cell("jellett_drift_ball", "%.2g"),
                      cell("jellett_drift_stem", "%.2g"),
                      {std::to_string(switch_count(e.at("summary")))},
                      {has_number(m, "friction_work_reference_sticks") ? fmt(num(m, "friction_work_reference_sticks"), "%.3g")
                                                                       : std::string("-")},
                      cell("wall_seconds"),
                      cell("real_time_factor")});
  }
  return t;
}

DocTable doc_table(const Table& t, const char* css) {
  DocTable d;
  d.header = t.header;
  d.row_headers = true;
  d.css = css;
  for (const auto& row : t.rows) {
    std::vector<DocCell> cells;
    for (const Cell& c : row) cells.push_back({c.text, grade_class(c.grade)});
    d.rows.push_back(cells);
  }
  return d;
}

std::string provenance_lines(const json& c, const char* sep) {
  const json& p = c.at("provenance");
  std::string versions;
  const json engine_versions = p.value("engine_versions", json::object());
  for (const auto& [engine, v] : engine_versions.items())
    versions += (versions.empty() ? "" : "; ") + engine + ": " + v.get<std::string>();
  const json& ref = c.at("reference").at("summary");
  std::string s;
  s += "scene file: " + str(c, "scene_file") + " (content hash " + str(c, "scene_hash") + ", physics hash " +
       str(c, "physics_hash") + ")" + sep;
  s += "engine versions: " + versions + sep;
  s += "git commit: " + str(p, "git_commit") + sep;
  std::string flags = str(p, "cxx_flags");
  flags.erase(0, flags.find_first_not_of(' '));
  s += "compiler: " + str(p, "compiler") + ", flags: " + flags + sep;
  s += "machine: " + str(p, "hostname") + ", date: " + str(p, "date") + sep;
  if (c.at("reference").value("cached", false)) {
    const json& rp = ref.at("provenance");
    s += "reference from the cache: run " + str(rp, "date") + " on " + str(rp, "hostname") + ", commit " +
         str(rp, "git_commit") + sep;
  }
  return s;
}

// What the reference's self-check found: {headline, detail}. The headline is said at the top of
// the report when the reference is converged over less than the whole run; the detail line
// (which methods, the cost) is said with the reference in every case.
std::pair<std::string, std::string> self_check_lines(const json& c) {
  const json& r = c.at("reference");
  if (!r.contains("self_check") || !r.at("self_check").is_object())
    return {"", "Reference self-check: not run (run.self_check = false or --no-self-check, or a record from before it)."};
  const json& sc = r.at("self_check");
  const std::string a = str(c.at("scene").value("run", json::object()), "method");
  const std::string b = str(sc, "method") == a ? str(sc, "method") + " at rtol " + fmt(num(sc, "rtol"), "%g")
                                               : str(sc, "method");
  const std::string cost = "CPU " + fmt(num(sc, "cpu_seconds"), "%.3g") + " s" + (sc.value("cached", false) ? ", cached" : "");
  if (!has_number(sc, "converged_until"))
    return {"", "Reference self-check: " + a + " and " + b + " agree over the whole run (" + cost + ")."};
  const std::string x = fmt(num(sc, "converged_until"), "%.6g");
  return {"The reference is converged to t = " + x + " (methods " + a + " and " + b + " part: " + str(sc, "reason") +
              "); metrics are compared up to it.",
          "Reference self-check: " + a + " against " + b + ", converged to t = " + x + " of " +
              run_time_text(r.at("summary")) + " (" + cost + ")."};
}

}  // namespace

// ---- public ---------------------------------------------------------------------------------

std::string render_summary_table(const json& comparison) {
  Document d;
  d.table(doc_table(summary_table(comparison), "summary"));
  return render_document_markdown(d);
}

std::vector<std::string> report_findings(const json& c) {
  std::vector<std::string> out;
  const json& ref = c.at("reference").at("summary");
  if (const std::string unconverged = self_check_lines(c).first; !unconverged.empty()) out.push_back(unconverged);
  if (str(ref, "status") != "ok")
    out.push_back("reference: status " + str(ref, "status") + " at t = " + fmt(num(ref, "status_time"), "%.6g") +
                  ": " + str(ref, "status_detail"));
  for (const json& e : c.at("engines")) {
    const std::string engine = str(e, "engine");
    const json& s = e.at("summary");
    const json& m = e.at("metrics");
    if (str(s, "status") != "ok")
      out.push_back(engine + ": status " + str(s, "status") + " at t = " + fmt(num(s, "status_time"), "%.6g") + ": " +
                    str(s, "status_detail"));
    for (const std::string key : {"inversion", "stem_contact"}) {
      const std::string which = str(m, (key + "_event").c_str());
      const std::string time_key = key + "_time";
      const std::string what = event_name(key);
      if (which == "engine_only")
        out.push_back(engine + ": " + what + " at t = " + fmt(num(s, time_key.c_str()), "%.6g") +
                      "; the reference has none (its run ends at t = " + run_time_text(ref) + ")");
      else if (which == "reference_only")
        out.push_back(engine + ": no " + what + " (its run ends at t = " + run_time_text(s) +
                      "); the reference has one at t = " + fmt(num(ref, time_key.c_str()), "%.6g"));
    }
    const long long gains = m.value("energy_gain_events", 0LL);
    const std::string ledger = to_string(EnergyGainRule::Ledger), stored = to_string(EnergyGainRule::Stored);
    const std::string rule = str(m, "energy_gain_rule");
    // Under the stored rule an engine whose contact stores no energy it reports counts E alone.
    const bool with_store = rule == stored && m.contains("elastic_energy_max") && m["elastic_energy_max"].is_number();
    if (gains > 0)
      out.push_back(engine + ": energy " +
                    (rule == ledger       ? "created (energy_gain_rule = " + ledger + ") "
                     : with_store ? "with its contact's stored elastic energy (energy_gain_rule = " + stored + ") "
                                  : std::string()) +
                    "rose above its lowest earlier value " + std::to_string(gains) + " time" +
                    (gains == 1 ? "" : "s") + " by more than " + fmt(kEnergyGainTolerance, "%g") +
                    " E0 and the energy of 1e-4 R of contact depth (largest net rise " + fmt(num(m, "energy_max_gain"), "%.3g") +
                    " E0) although the contact law dissipates");
  }
  return out;
}

Document comparison_document(const json& c, const std::vector<std::string>& plot_files, const std::string& plots_note,
                             const std::vector<std::string>& data_files) {
  const json& scene = c.at("scene");
  const std::string name = str(c, "scene_name");
  const SceneUnits units = scene_units(scene);
  Document d;
  d.title = "tippe compare: " + name;
  d.top_links = {{"all reports", "../index.html"}, {"comparison.json", "comparison.json"}};
  for (const auto& f : data_files) d.top_links.push_back({f, f});
  d.heading(1, name + ": engines against the analytic reference");
  const auto [check_headline, check_detail] = self_check_lines(c);
  if (!check_headline.empty()) d.para(check_headline, "unconverged", true);
  for (const auto& v : verdict_sentences(c)) d.para(v, "verdict");
  d.para("Time is in " + units.time + "; inversion-time errors are engine minus reference relative to the "
         "reference's time. Verdicts hold up to each run's end, t = " + run_time_text(c.at("reference").at("summary")) +
         " for the reference.", "note");
  if (!str(scene, "description").empty()) d.para(str(scene, "description"));
  // What the scene's maker approximated (an imported model's notes): before any number.
  if (scene.contains("notes") && scene.at("notes").is_array() && !scene.at("notes").empty()) {
    std::vector<std::string> notes;
    for (const auto& n : scene.at("notes"))
      if (n.is_string()) notes.push_back(n.get<std::string>());
    d.heading(2, "Scene notes");
    d.list(notes);
  }

  const json& ref = c.at("reference").at("summary");
  d.heading(2, "Summary");
  d.para("Reference: " + str(ref, "engine_version") + ", run to t = " + run_time_text(ref) +
         (c.at("reference").value("cached", false) ? " (from the cache)" : "") + ". " + check_detail);
  d.table(doc_table(summary_table(c), "summary"));
  d.para("Errors are engine minus reference on the common sample grid (to the end of the shorter run); times in " +
             units.time + "; E0 is the reference's initial energy, R the ball radius. Event errors: green below 1 %, "
             "amber below 10 %, red above, and red for an event only one side has. Other cells are coloured only when "
             "the comparison carries tolerances.",
         "note");
  d.table(doc_table(detail_table(c), "detail"), "More metrics", true);
  add_event_sequences(d, c);
  const bool ledger_chart = std::find(plot_files.begin(), plot_files.end(), kLedgerChartFile) != plot_files.end();
  add_energy_ledger(d, c, ledger_chart);

  d.heading(2, "Findings");
  const auto findings = report_findings(c);
  if (findings.empty()) d.para("None: every run ended ok, every event is on both sides, no energy gain events.");
  else d.list(findings);

  d.heading(2, "Plots");
  for (const auto& f : plot_files)
    if (f != kLedgerChartFile) d.figure(f, plot_caption(f));  // the ledger chart is in its section
  if (!plots_note.empty()) d.para(plots_note, "note");

  d.heading(2, "Scene");
  DocTable params;
  params.css = "params";
  params.rows.push_back({DocCell("gravity"), DocCell(scalar_text(scene.value("gravity", json())))});
  for (const char* section : {"body", "mass_properties", "contact", "initial", "run"}) {
    if (!scene.contains(section)) continue;
    std::string items;
    for (const auto& [k, v] : scene.at(section).items()) items += (items.empty() ? "" : ", ") + k + " = " + scalar_text(v);
    params.rows.push_back({DocCell(section), DocCell(items)});
  }
  params.header = {"section", "values (" + units.length + ", " + units.time + ")"};
  d.table(params);

  d.heading(2, "Engine settings");
  auto settings_block = [&](const json& s) {
    DocTable t;
    t.css = "params";
    t.header = {"setting", "value"};
    const json settings = s.value("settings", json::object());
    for (const auto& [k, v] : settings.items())
      t.rows.push_back({DocCell(k), DocCell(scalar_text(v))});
    d.table(t, str(s, "engine") + " (" + str(s, "engine_version") + ")", true);
  };
  settings_block(ref);
  for (const json& e : c.at("engines")) settings_block(e.at("summary"));

  d.heading(2, "Notes");
  std::vector<std::string> notes;
  auto add_notes = [&](const json& s) {
    const json list = s.value("notes", json::array());
    for (const auto& n : list)
      if (n.is_string()) notes.push_back(str(s, "engine") + ": " + n.get<std::string>());
  };
  add_notes(ref);
  for (const json& e : c.at("engines")) add_notes(e.at("summary"));
  if (notes.empty()) notes.push_back("No engine reports an approximation.");
  d.list(notes);

  std::istringstream lines(provenance_lines(c, "\n"));
  for (std::string line; std::getline(lines, line);) d.footer.push_back(line);
  return d;
}

std::string render_markdown(const json& c, const std::vector<std::string>& plot_files, const std::string& plots_note) {
  return render_document_markdown(comparison_document(c, plot_files, plots_note));
}

std::string render_html(const json& c, const std::vector<std::string>& plot_files, const std::string& plots_note,
                        const std::vector<std::string>& data_files) {
  return render_document_html(comparison_document(c, plot_files, plots_note, data_files));
}

void write_report(const std::string& out_dir, const json& comparison, bool plots) {
  const fs::path dir(out_dir);
  std::error_code ec;
  PlotSet p;
  if (plots) {
    p = render_plots(out_dir, comparison);
  } else {
    p.note = "plots skipped: disabled (--no-plots)";
    for (const auto& f : plot_file_names())
      if (fs::exists(dir / f, ec) && fs::file_size(dir / f, ec) > 0) p.files.push_back(f);
    if (!p.files.empty()) p.note += "; the plots shown are kept from an earlier run";
  }
  // The ledger chart needs the record only (no trajectory, no gnuplot): drawn whenever plots are,
  // kept from an earlier run like them when they are not.
  const fs::path chart = dir / kLedgerChartFile;
  if (plots) {
    const std::string svg = ledger_chart_svg(comparison);
    if (svg.empty()) fs::remove(chart, ec);
    else write_file_atomic(chart.string(), svg);
  }
  if (fs::exists(chart, ec) && fs::file_size(chart, ec) > 0) p.files.push_back(kLedgerChartFile);
  // The trajectories, when they are here (published reports do not keep them).
  std::vector<std::string> data;
  std::vector<std::string> names = {"reference"};
  for (const json& e : comparison.at("engines")) names.push_back(str(e, "engine"));
  for (const auto& n : names)
    if (fs::exists(dir / (n + ".csv"), ec)) data.push_back(n + ".csv");
  const Document d = comparison_document(comparison, p.files, p.note, data);
  write_file_atomic((dir / "report.md").string(), render_document_markdown(d));
  write_file_atomic((dir / "index.html").string(), render_document_html(d));
}

}  // namespace tippe
