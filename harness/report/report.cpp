// Comparison reports from records alone: Markdown for terminals and CI logs, a self-contained HTML page, gnuplot SVG plots.
#include "report/report.h"

#include "registry.h"


#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <map>
#include <sstream>
#include <utility>

#include "compare.h"
#include "report/gnuplot.h"
#include "records.h"

namespace tippe {

namespace {

namespace fs = std::filesystem;
using nlohmann::json;

// ---- formatting -----------------------------------------------------------------------------

std::string fmt(double v, const char* spec = "%.4g") {
  if (!std::isfinite(v)) return "-";
  char buf[64];
  std::snprintf(buf, sizeof buf, spec, v);
  return buf;
}

bool has_number(const json& j, const char* key) { return j.contains(key) && j.at(key).is_number(); }
double num(const json& j, const char* key) {
  return has_number(j, key) ? j.at(key).get<double>() : std::nan("");
}
std::string str(const json& j, const char* key) {
  return j.contains(key) && j.at(key).is_string() ? j.at(key).get<std::string>() : std::string();
}

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
  return {text, grade_against(comparison, key + "_time_rel_error", rel_err, 0.01, 0.10)};
}

std::string status_text(const json& summary) {
  const std::string status = str(summary, "status");
  if (status == "ok") return status;
  return status + " at t=" + fmt(num(summary, "status_time"), "%.6g");
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
              "Jellett ball",   "Jellett stem",    "surface switches",  "wall s",          "real-time factor"};
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
                      cell("wall_seconds"),
                      cell("real_time_factor")});
  }
  return t;
}

std::string markdown_table(const Table& t) {
  auto md = [](std::string s) {
    // A pipe would split the cell.
    std::string out;
    for (char ch : s) out += ch == '|' ? std::string("\\|") : std::string(1, ch);
    return out;
  };
  std::string s = "|";
  for (const auto& h : t.header) s += " " + md(h) + " |";
  s += "\n|";
  for (size_t i = 0; i < t.header.size(); ++i) s += i == 0 ? "---|" : "---:|";
  s += "\n";
  for (const auto& row : t.rows) {
    s += "|";
    for (const auto& cell : row) s += " " + md(cell.text) + " |";
    s += "\n";
  }
  return s;
}

std::string html_table(const Table& t, const char* css_class) {
  std::string s = std::string("<table class=\"") + css_class + "\">\n<thead><tr>";
  for (const auto& h : t.header) s += "<th>" + html_escape(h) + "</th>";
  s += "</tr></thead>\n<tbody>\n";
  for (const auto& row : t.rows) {
    s += "<tr>";
    for (size_t i = 0; i < row.size(); ++i) {
      const char* cls = grade_class(row[i].grade);
      const std::string tag = i == 0 ? "th" : "td";
      s += "<" + tag + (*cls ? std::string(" class=\"") + cls + "\"" : std::string()) + ">" +
           html_escape(row[i].text) + "</" + tag + ">";
    }
    s += "</tr>\n";
  }
  return s + "</tbody>\n</table>\n";
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

std::string run_time_text(const json& s) { return fmt(num(s, "final_time"), "%.6g"); }

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

// ---- plots ----------------------------------------------------------------------------------

// Fixed per engine so that a colour means the same engine on every page.
std::string engine_colour(const std::string& engine, size_t index) {
  // Registered engines have their own (engines/registry.h); a name from an old record that is
  // no longer registered gets a spare one.
  if (const EngineInfo* e = find_engine(engine)) return e->colour;
  static const char* const spare[] = {"#8c564b", "#e377c2", "#17becf", "#bcbd22"};
  return spare[index % 4];
}

// Indices that keep the shape of a series in at most ~2 * buckets points: the first and last
// sample and the minimum and maximum of each bucket, so that spikes such as impacts survive
// (800 points draw a 900-pixel-wide plot faithfully and keep an SVG small).
std::vector<size_t> decimate_minmax(const std::vector<double>& y, size_t buckets) {
  std::vector<size_t> idx;
  const size_t n = y.size();
  if (n <= 2 * buckets) {
    for (size_t i = 0; i < n; ++i) idx.push_back(i);
    return idx;
  }
  const size_t per = (n + buckets - 1) / buckets;
  for (size_t b = 0; b < n; b += per) {
    const size_t e = std::min(n, b + per);
    size_t lo = b, hi = b;
    for (size_t i = b; i < e; ++i) {
      if (!std::isfinite(y[i])) continue;
      if (!std::isfinite(y[lo]) || y[i] < y[lo]) lo = i;
      if (!std::isfinite(y[hi]) || y[i] > y[hi]) hi = i;
    }
    if (b == 0) idx.push_back(0);
    idx.push_back(std::min(lo, hi));
    idx.push_back(std::max(lo, hi));
  }
  idx.push_back(n - 1);
  std::sort(idx.begin(), idx.end());
  idx.erase(std::unique(idx.begin(), idx.end()), idx.end());
  return idx;
}

struct Series {
  std::string name;  // reference or engine
  std::string title, colour;
  bool reference = false;
  std::string file;  // plot-N.dat: numbered, so that no name read from a record becomes a path
  std::map<std::string, int> block;  // quantity -> gnuplot index; absent: no finite point
};

// Writes one run's decimated series as gnuplot data blocks.
void write_plot_data(const fs::path& dir, Series& series, Trajectory tr, const json& summary, const json& scene) {
  // The sample that ends a run early may carry the blown-up state; it would flatten every axis.
  if (str(summary, "status") != "ok" && tr.size() > 1) {
    for (auto* col : {&tr.t, &tr.theta, &tr.energy, &tr.jellett, &tr.normal_force, &tr.x_C, &tr.y_C}) col->pop_back();
  }
  const double E0 = tr.size() ? tr.energy.front() : 1.0;
  const double J0 = tr.size() ? tr.jellett.front() : 1.0;
  const double Mg = num(scene.at("mass_properties"), "mass") * num(scene, "gravity");
  auto scaled = [](const std::vector<double>& v, double by) {
    std::vector<double> out(v);
    if (std::isfinite(by) && by != 0.0)
      for (double& x : out) x /= by;
    return out;
  };
  const std::vector<std::pair<std::string, std::pair<std::vector<double>, std::vector<double>>>> quantities = {
      {"theta", {tr.t, tr.theta}},
      {"energy", {tr.t, scaled(tr.energy, std::abs(E0) > 0 ? E0 : 1.0)}},
      {"path", {tr.x_C, tr.y_C}},
      {"jellett", {tr.t, scaled(tr.jellett, std::abs(J0) > 1e-300 ? J0 : 1.0)}},
      {"normal_force", {tr.t, scaled(tr.normal_force, Mg)}},
  };
  // Each block opens with its title, read by plots.gp as `title columnheader(1)`: the script
  // itself never holds a name read from a record.
  std::string text = "# decimated series for plots.gp, one block per quantity\n";
  int index = 0;
  for (const auto& [name, xy] : quantities) {
    const auto& [x, y] = xy;
    std::vector<size_t> idx;
    if (name == "path") {
      // A path has no single y to keep extremes of: evenly spaced samples.
      const size_t stride = std::max<size_t>(1, x.size() / 1000);
      for (size_t i = 0; i < x.size(); i += stride) idx.push_back(i);
      if (!x.empty() && idx.back() != x.size() - 1) idx.push_back(x.size() - 1);
    } else {
      idx = decimate_minmax(y, 400);
    }
    std::string block;
    for (size_t i : idx) {
      if (!std::isfinite(x[i]) || !std::isfinite(y[i])) continue;
      char line[96];
      std::snprintf(line, sizeof line, "%.9g %.9g\n", x[i], y[i]);
      block += line;
    }
    if (block.empty()) continue;
    text += "# " + name + "\n" + gp_column_header(series.title) + "\n" + block + "\n\n";
    series.block[name] = index++;
  }
  write_file_atomic((dir / series.file).string(), text);
}

struct PlotSpec {
  std::string file, quantity, title, xlabel, ylabel;
};

const std::vector<PlotSpec>& plot_specs() {
  static const std::vector<PlotSpec> specs = {
      {"theta.svg", "theta", "tilt θ(t)", "t", "θ (rad)"},
      {"energy.svg", "energy", "energy E(t)/E0", "t", "E / E0"},
      {"contact_path.svg", "path", "floor contact path", "x_C", "y_C"},
      {"jellett.svg", "jellett", "Jellett integral J(t)/J0", "t", "J / J0"},
      {"normal_force.svg", "normal_force", "normal force F_n(t)/(M g)", "t", "F_n / (M g)"},
  };
  return specs;
}

std::string gnuplot_script(const std::vector<Series>& series, const json& comparison) {
  const json& ref = comparison.at("reference").at("summary");
  std::string s =
      "# Plots of the comparison in this directory (written by tippe; regenerate with `tippe report DIR`).\n"
      "set encoding utf8\n"
      "set terminal svg size 960,540 dynamic noenhanced font 'Helvetica,13' background rgb 'white'\n"
      "set grid lc rgb '#dddddd'\n"
      "set key below horizontal\n"
      "set border lc rgb '#444444'\n";
  for (const PlotSpec& p : plot_specs()) {
    std::string plot;
    for (const Series& sr : series) {
      auto it = sr.block.find(p.quantity);
      if (it == sr.block.end()) continue;
      plot += plot.empty() ? "plot " : ", \\\n     ";
      plot += gp_literal(sr.file) + " index " + std::to_string(it->second) + " using 1:2 with lines lw " +
              (sr.reference ? "4" : "1.5") + " lc rgb " + gp_literal(sr.colour) + " title columnheader(1)";
    }
    if (plot.empty()) continue;
    // The page names the scene above every plot; the plot's own title is the program's.
    s += "\nset output " + gp_literal(p.file) + "\n";
    s += "set title " + gp_literal(p.title) + "\n";
    s += "set xlabel " + gp_literal(p.xlabel) + "\nset ylabel " + gp_literal(p.ylabel) + "\n";
    const bool marks = p.quantity != "path";
    if (p.quantity == "path") s += "set size ratio -1\n";
    if (marks && has_number(ref, "inversion_time"))
      s += "set arrow 1 from " + fmt(num(ref, "inversion_time"), "%.9g") +
           ", graph 0 to " + fmt(num(ref, "inversion_time"), "%.9g") +
           ", graph 1 nohead dashtype 2 lc rgb '#888888'\n";
    s += plot + "\n";
    s += "unset arrow\nset size noratio\nunset output\n";
  }
  return s;
}

}  // namespace

// ---- public ---------------------------------------------------------------------------------

std::string html_escape(const std::string& text) {
  std::string out;
  out.reserve(text.size());
  for (char ch : text) {
    switch (ch) {
      case '&': out += "&amp;"; break;
      case '<': out += "&lt;"; break;
      case '>': out += "&gt;"; break;
      case '"': out += "&quot;"; break;
      case '\'': out += "&#39;"; break;
      default: out += ch;
    }
  }
  return out;
}

std::string render_summary_table(const json& comparison) { return markdown_table(summary_table(comparison)); }

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
    if (gains > 0)
      out.push_back(engine + ": energy rose between samples " + std::to_string(gains) + " time" +
                    (gains == 1 ? "" : "s") + " by more than " + fmt(kEnergyGainTolerance, "%g") +
                    " E0 (largest rise " + fmt(num(m, "energy_max_gain"), "%.3g") +
                    " E0) although the contact law dissipates");
  }
  return out;
}

std::string render_summary_line(const json& c) {
  auto side = [](const json& s, const std::string& name, const std::string& rel) {
    std::string t = name + ": ";
    t += has_number(s, "inversion_time") ? "inverts at t = " + fmt(num(s, "inversion_time"), "%.6g") + rel
                                         : "no inversion to t = " + run_time_text(s);
    if (str(s, "status") != "ok") t += " (" + status_text(s) + ")";
    return t;
  };
  std::string line = side(c.at("reference").at("summary"), "reference", "");
  for (const json& e : c.at("engines")) {
    const double rel = num(e.at("metrics"), "inversion_time_rel_error");
    line += " | " + side(e.at("summary"), str(e, "engine"),
                         std::isfinite(rel) ? " (" + fmt(100 * rel, "%+.2g") + " %)" : std::string());
  }
  return line;
}

std::string render_markdown(const json& c) {
  const json& scene = c.at("scene");
  std::string s = "# Comparison: " + str(c, "scene_name") + "\n\n";
  const auto [check_headline, check_detail] = self_check_lines(c);
  if (!check_headline.empty()) s += "**" + check_headline + "**\n\n";
  if (!str(scene, "description").empty()) s += str(scene, "description") + "\n\n";
  const json& ref = c.at("reference").at("summary");
  s += "Reference: " + str(ref, "engine_version") + ", run to t = " + run_time_text(ref) +
       (c.at("reference").value("cached", false) ? " (from the cache)" : "") + ". " + check_detail + "\n\n";
  s += render_summary_table(c);
  s += "\nErrors are engine minus reference on the common sample grid; E0 is the reference's initial energy, R the "
       "ball radius.\n";
  s += "\n## Findings\n\n";
  const auto findings = report_findings(c);
  if (findings.empty()) s += "None: every run ended ok, every event is on both sides, no energy gain events.\n";
  for (const auto& f : findings) s += "- " + f + "\n";
  s += "\n## Provenance\n\n";
  std::istringstream lines(provenance_lines(c, "\n"));
  for (std::string line; std::getline(lines, line);) s += "- " + line + "\n";
  return s;
}

const std::vector<std::string>& plot_file_names() {
  static const std::vector<std::string> names = [] {
    std::vector<std::string> v;
    for (const auto& p : plot_specs()) v.push_back(p.file);
    return v;
  }();
  return names;
}

std::string plot_caption(const std::string& file) {
  static const std::map<std::string, std::string> captions = {
      {"theta.svg",
       "Tilt θ(t) of every engine over the reference (thick black); the dashed line marks the reference's inversion."},
      {"energy.svg", "Energy E(t) divided by each run's initial energy E0."},
      {"contact_path.svg", "Path of the geometric floor contact point (x_C, y_C), equal axes."},
      {"jellett.svg", "Jellett's integral J(t) divided by each run's initial J0 (conserved on one contact surface)."},
      {"normal_force.svg", "Normal force F_n(t) in units of the weight M g (decimated: extremes kept)."},
  };
  auto it = captions.find(file);
  return it != captions.end() ? it->second : file;
}

std::string render_html(const json& c, const std::vector<std::string>& plot_files, const std::string& plots_note) {
  const json& scene = c.at("scene");
  const std::string name = str(c, "scene_name");
  std::string h;
  h += "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n";
  h += "<meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">\n";
  h += "<title>" + html_escape("tippe compare: " + name) + "</title>\n";
  h += R"(<style>
body { font-family: system-ui, sans-serif; margin: 1.5em auto; max-width: 1280px; padding: 0 1em; color: #222; }
h1 { font-size: 1.5em; } h2 { font-size: 1.2em; margin-top: 1.6em; border-bottom: 1px solid #ccc; }
table { border-collapse: collapse; margin: 0.5em 0; font-size: 0.9em; }
th, td { border: 1px solid #ccc; padding: 0.25em 0.5em; text-align: right; }
thead th { background: #f0f0f0; text-align: center; }
tbody th { text-align: left; }
table.params td { text-align: left; }
td.good, th.good { background: #c8ecc8; } td.warn, th.warn { background: #fde5a6; } td.bad, th.bad { background: #f6b8b8; }
.wide { overflow-x: auto; }
figure { margin: 1em 0; } figure img { max-width: 100%; border: 1px solid #ddd; }
figcaption { font-size: 0.9em; color: #555; }
details { margin: 0.4em 0; } summary { cursor: pointer; font-weight: bold; }
footer { margin-top: 2em; font-size: 0.85em; color: #555; border-top: 1px solid #ccc; }
.note { color: #555; font-style: italic; }
.unconverged { background: #fde5a6; padding: 0.4em 0.6em; border-left: 4px solid #d9a400; }
</style>
</head>
<body>
)";
  h += "<h1>" + html_escape(name + ": engines against the analytic reference") + "</h1>\n";
  const auto [check_headline, check_detail] = self_check_lines(c);
  if (!check_headline.empty()) h += "<p class=\"unconverged\"><strong>" + html_escape(check_headline) + "</strong></p>\n";
  if (!str(scene, "description").empty()) h += "<p>" + html_escape(str(scene, "description")) + "</p>\n";
  // What the scene's maker approximated (an imported model's notes): first, before any number.
  if (scene.contains("notes") && scene.at("notes").is_array() && !scene.at("notes").empty()) {
    h += "<h2>Scene notes</h2>\n<ul>\n";
    for (const auto& n : scene.at("notes"))
      if (n.is_string()) h += "<li>" + html_escape(n.get<std::string>()) + "</li>\n";
    h += "</ul>\n";
  }

  h += "<h2>Scene</h2>\n<table class=\"params\">\n<tbody>\n";
  h += "<tr><th>gravity</th><td>" + html_escape(scalar_text(scene.value("gravity", json()))) + "</td></tr>\n";
  for (const char* section : {"body", "mass_properties", "contact", "initial", "run"}) {
    if (!scene.contains(section)) continue;
    std::string items;
    for (const auto& [k, v] : scene.at(section).items())
      items += (items.empty() ? "" : ", ") + k + " = " + scalar_text(v);
    h += "<tr><th>" + html_escape(section) + "</th><td>" + html_escape(items) + "</td></tr>\n";
  }
  h += "</tbody>\n</table>\n";

  const json& ref = c.at("reference").at("summary");
  h += "<h2>Summary</h2>\n";
  h += "<p>Reference: " + html_escape(str(ref, "engine_version")) + ", run to t = " + html_escape(run_time_text(ref)) +
       (c.at("reference").value("cached", false) ? " (from the cache)" : "") + ". " + html_escape(check_detail) +
       "</p>\n";
  h += "<div class=\"wide\">\n" + html_table(summary_table(c), "summary") + "</div>\n";
  h += "<p class=\"note\">Errors are engine minus reference on the common sample grid (to the end of the shorter "
       "run); E0 is the reference's initial energy, R the ball radius. Event errors: green below 1 %, amber below "
       "10 %, red above, and red for an event only one side has. Other cells are coloured only when the comparison "
       "carries tolerances.</p>\n";
  h += "<details><summary>More metrics</summary>\n<div class=\"wide\">\n" + html_table(detail_table(c), "detail") +
       "</div>\n</details>\n";

  h += "<h2>Findings</h2>\n";
  const auto findings = report_findings(c);
  if (findings.empty()) {
    h += "<p>None: every run ended ok, every event is on both sides, no energy gain events.</p>\n";
  } else {
    h += "<ul>\n";
    for (const auto& f : findings) h += "<li>" + html_escape(f) + "</li>\n";
    h += "</ul>\n";
  }

  h += "<h2>Plots</h2>\n";
  for (const auto& f : plot_files)
    h += "<figure><img src=\"" + html_escape(f) + "\" alt=\"" + html_escape(plot_caption(f)) + "\"><figcaption>" +
         html_escape(plot_caption(f)) + "</figcaption></figure>\n";
  if (!plots_note.empty()) h += "<p class=\"note\">" + html_escape(plots_note) + "</p>\n";

  h += "<h2>Engine settings</h2>\n";
  auto settings_block = [&](const json& s, bool open) {
    std::string b = std::string("<details") + (open ? " open" : "") + "><summary>" +
                    html_escape(str(s, "engine") + " (" + str(s, "engine_version") + ")") + "</summary>\n";
    b += "<table class=\"params\">\n<tbody>\n";
    const json settings = s.value("settings", json::object());
    for (const auto& [k, v] : settings.items())
      b += "<tr><th>" + html_escape(k) + "</th><td>" + html_escape(scalar_text(v)) + "</td></tr>\n";
    b += "</tbody>\n</table>\n</details>\n";
    return b;
  };
  h += settings_block(ref, false);
  for (const json& e : c.at("engines")) h += settings_block(e.at("summary"), false);

  h += "<h2>Notes</h2>\n<ul>\n";
  bool any_note = false;
  auto notes = [&](const json& s) {
    for (const auto& n : s.value("notes", json::array())) {
      h += "<li>" + html_escape(str(s, "engine") + ": " + n.get<std::string>()) + "</li>\n";
      any_note = true;
    }
  };
  notes(ref);
  for (const json& e : c.at("engines")) notes(e.at("summary"));
  if (!any_note) h += "<li>No engine reports an approximation.</li>\n";
  h += "</ul>\n";

  h += "<footer>\n<p>";
  std::istringstream lines(provenance_lines(c, "\n"));
  bool first = true;
  for (std::string line; std::getline(lines, line); first = false) h += (first ? "" : "<br>\n") + html_escape(line);
  h += "</p>\n</footer>\n</body>\n</html>\n";
  return h;
}

PlotSet render_plots(const std::string& out_dir, const json& c) {
  PlotSet result;
  std::string why;
  const std::string gnuplot = gnuplot_command(&why);
  if (gnuplot.empty()) {
    result.note = why;
    return result;
  }
  const fs::path dir(out_dir);
  std::vector<Series> series;
  std::vector<std::string> missing;
  auto add = [&](const std::string& name, const std::string& engine, const json& summary, bool reference,
                 size_t index) {
    const fs::path csv = dir / (name + ".csv");
    Series s;
    s.name = name;
    s.reference = reference;
    s.title = reference ? "reference (" + engine + ")" : engine;
    s.colour = reference ? "#000000" : engine_colour(engine, index);
    s.file = "plot-" + std::to_string(series.size() + missing.size()) + ".dat";
    try {
      write_plot_data(dir, s, Trajectory::from_csv(read_trajectory_csv(csv.string())), summary, c.at("scene"));
      series.push_back(s);
    } catch (const std::exception&) {
      missing.push_back(name + ".csv");
    }
  };
  const json& ref = c.at("reference").at("summary");
  add("reference", str(ref, "engine"), ref, true, 0);
  size_t i = 0;
  for (const json& e : c.at("engines")) add(str(e, "engine"), str(e, "engine"), e.at("summary"), false, i++);
  std::string missing_text;
  for (const auto& m : missing) missing_text += (missing_text.empty() ? "" : ", ") + m;
  if (series.empty()) {
    result.note = "plots skipped: no trajectory in " + out_dir + " (" + missing_text + ")";
    return result;
  }

  write_file_atomic((dir / "plots.gp").string(), gnuplot_script(series, c));
  const int code = run_gnuplot(gnuplot, dir, "plots.gp", "plots.log");
  if (code != 0) {
    result.note = code == 127 ? "plots skipped: gnuplot not found (" + gnuplot + ")"
                              : "plots failed: gnuplot exited with status " + std::to_string(code) + " (see plots.log)";
    return result;
  }
  std::error_code ec;
  fs::remove(dir / "plots.log", ec);
  std::string empty;
  for (const auto& f : plot_file_names()) {
    const fs::path p = dir / f;
    if (fs::exists(p, ec) && fs::file_size(p, ec) > 0)
      result.files.push_back(f);
    else
      empty += (empty.empty() ? "" : ", ") + f;
  }
  if (!empty.empty()) result.note = "plots missing: " + empty + " (no data, or gnuplot wrote nothing)";
  if (!missing.empty())
    result.note += (result.note.empty() ? "" : "; ") + std::string("not plotted (no trajectory): ") + missing_text;
  return result;
}

void write_report(const std::string& out_dir, const json& comparison, bool plots) {
  const PlotSet p = plots ? render_plots(out_dir, comparison) : PlotSet{{}, "plots skipped: disabled (--no-plots)"};
  std::string md = render_markdown(comparison);
  std::string plot_line = "\n## Plots\n\n";
  if (!p.files.empty()) {
    plot_line += "In index.html:";
    for (const auto& f : p.files) plot_line += " " + f;
    plot_line += "\n";
  }
  if (!p.note.empty()) plot_line += p.note + "\n";
  // Plots go before the provenance footer, which stays last.
  const size_t footer = md.find("\n## Provenance\n");
  md.insert(footer == std::string::npos ? md.size() : footer, plot_line);
  const fs::path dir(out_dir);
  write_file_atomic((dir / "report.md").string(), md);
  write_file_atomic((dir / "index.html").string(), render_html(comparison, p.files, p.note));
}

}  // namespace tippe
