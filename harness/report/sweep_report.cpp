// The sweep report: the verdict per engine, boundaries, stability map, per-scene tables and charts, as one document made from records.jsonl alone.

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <functional>
#include <limits>
#include <map>
#include <set>
#include <sstream>
#include <optional>
#include <string>
#include <tuple>
#include <vector>

#include "engines/core/registry.h"
#include "harness/report/gnuplot.h"
#include "harness/records/records.h"
#include "harness/report/report.h"
#include "harness/sweep/sweep.h"
#include "harness/report/document.h"
#include "harness/report/sweep_groups.h"
#include "harness/sweep/sweep_search.h"
#include "harness/report/sweep_analysis.h"
#include "harness/report/sweep_choices.h"

namespace tippe {

namespace {

namespace fs = std::filesystem;
using namespace sweep_report_detail;


// The regime table's last column: the verdict and the inversion times it rests on.
std::string trend_text(const RegimeTrend& tr) {
  if (tr.verdict == "-" || tr.verdict == "none") return tr.verdict;
  std::string times;
  for (const auto& [dt, t] : tr.inversion_by_step)
    times += (times.empty() ? "" : ", ") + fmt("%.3g", t) + " at " + fmt("%.3g", dt);
  std::string text = tr.verdict;
  if (tr.in_regime_from) text += " (in the regime from dt = " + fmt("%.3g", *tr.in_regime_from) + " down)";
  return text + "; inverts at " + times;
}

// A table of text cells, with an optional CSS class per cell (same shape as rows; "" for none).
struct SweepTable {
  std::vector<std::string> header;
  std::vector<std::vector<std::string>> rows;
  std::vector<std::vector<std::string>> css = {};
};
DocTable to_doc(const SweepTable& t) {
  DocTable d;
  d.header = t.header;
  for (size_t i = 0; i < t.rows.size(); ++i) {
    std::vector<DocCell> row;
    for (size_t j = 0; j < t.rows[i].size(); ++j)
      row.push_back({t.rows[i][j], i < t.css.size() && j < t.css[i].size() ? t.css[i][j] : std::string()});
    d.rows.push_back(row);
  }
  return d;
}

std::string class_cell(const SweepRecord& r) {
  std::string text = r.run_class;
  if (std::isfinite(r.class_time)) text += " at " + fmt("%.4g", r.class_time);
  if (r.run_class == "ok" && !agrees_with_reference_regime(r)) text += ", regime differs";
  return text;
}
std::string class_css(const SweepRecord& r) {
  if (r.run_class == "ok") return agrees_with_reference_regime(r) ? "c-ok" : "c-regime";
  return "c-" + r.run_class;
}


std::string points_text(const std::vector<double>& values, const std::vector<size_t>& used) {
  std::string t;
  for (size_t i : used) t += (t.empty() ? "" : ", ") + fmt("%g", values[i]);
  return t;
}

void scene_section(const SceneGroup& s, size_t scene, const std::vector<std::string>& images, Document& doc) {
  doc.heading(2, "Scene " + s.name);
  std::string ref = "Scene file " + s.file + " (as the sweep file names it), run to t = " + fmt("%g", s.duration) +
                    ". The reference ";
  ref += s.reference_inversion ? "inverts at t = " + fmt("%.10g", *s.reference_inversion)
                               : "does not invert (it settles into rolling): errors in the inversion time mean "
                                 "nothing here, so the regime of every point is what counts";
  ref += s.reference_stem_contact ? "; its stem first touches at t = " + fmt("%.10g", *s.reference_stem_contact) + "."
                                  : "; its stem never touches.";
  // The reference's self-check (records' metrics.reference_converged_until): the same for every
  // point of the scene, since all are compared with the one reference.
  std::optional<double> converged_until;
  for (const SetupGroup& u : s.setups)
    for (const SweepRecord& r : u.points)
      if (r.metrics.reference_converged_until) converged_until = r.metrics.reference_converged_until;
  if (converged_until)
    ref += " Its self-check (a second reference by an independent method) parts from it at t = " +
           fmt("%.6g", *converged_until) + ": every metric against the reference below stops there, and an "
           "event after it is not judged (\"unconverged\").";
  doc.para(ref);

  std::vector<SweepRecord> all, analytic;
  std::vector<std::string> engines;
  for (const SetupGroup& u : s.setups) {
    all.insert(all.end(), u.points.begin(), u.points.end());
    if (u.engine == reference_engine().name)
      for (const SweepRecord& r : u.points)
        if (r.run_class != "unphysical" && r.run_class != "diverged") analytic.push_back(r);
    if (std::find(engines.begin(), engines.end(), u.engine) == engines.end()) engines.push_back(u.engine);
  }

  if (s.reference_inversion) {
    doc.heading(3, "Cheapest setting of each engine by inversion-time error");
    doc.para("For each engine (over all its setups) the point with the least CPU time that is safe with the "
             "inversion within the bound (the one criterion of the page's opening: finished, classed ok by the "
             "stability map, |relative inversion-time error| <= the bound). \"Analytic at least as "
             "accurate\": the cheapest point of the analytic model's own ladders with an error no larger than "
             "this point's; the ratio is this point's CPU time over that one's. \"Not told apart\": the "
             "engine's other points safe within the same bound at a CPU time within " + pct(kCostResolution) +
             " of this one's, a difference the machine's noise could reverse.");
    SweepTable t{{"engine", "error below", "setup", "setting", "inversion error", "CPU s", "not told apart", "steps",
             "analytic at least as accurate", "cost ratio"},
            {}};
    for (const std::string& e : engines) {
      std::vector<SweepRecord> mine;
      for (const SweepRecord& r : all)
        if (r.engine == e) mine.push_back(r);
      for (double bound : {0.1, 0.01, 0.001}) {
        const long long i = cheapest_below(mine, bound);
        if (i < 0) {
          t.rows.push_back({e, pct(bound), "none reaches it", "", "", "", "", "", "", ""});
          continue;
        }
        const SweepRecord& r = mine[static_cast<size_t>(i)];
        const double err = std::abs(*r.metrics.inversion_time_rel_error);
        const long long a = cheapest_at_least_as_accurate(analytic, err);
        std::string a_text = "none", ratio = "-";
        if (a >= 0) {
          const SweepRecord& ar = analytic[static_cast<size_t>(a)];
          a_text = ar.setup + " " + short_setting(ar) + ": " + g3(ar.cpu_seconds) + " s (error " +
                   pct(std::abs(*ar.metrics.inversion_time_rel_error)) + ")";
          if (ar.cpu_seconds > 0) ratio = g3(r.cpu_seconds / ar.cpu_seconds);
        }
        std::vector<std::string> ties;
        for (size_t k : cost_ties(mine, i, setting_criterion(true, bound)))
          ties.push_back(mine[k].setup + " " + short_setting(mine[k]) + ": " + g3(mine[k].cpu_seconds) + " s");
        t.rows.push_back({e, pct(bound), r.setup, setting_text(r), pct(*r.metrics.inversion_time_rel_error),
                          g3(r.cpu_seconds), ties.empty() ? "-" : join_list(ties, "; "), std::to_string(r.steps),
                          a_text, ratio});
      }
    }
    doc.table(to_doc(t));
  }

  // Convergence in the time step: only ladders over a time step have one.
  SweepTable conv{{"setup", "engine", "ladder", "order (inversion time)", "points in the asymptotic range",
              "order (tilt RMS)", "points in the asymptotic range"},
             {}};
  for (const SetupGroup& u : s.setups)
    for (const Line& l : lines_of(u)) {
      const std::string last = u.key.substr(u.key.rfind('.') + 1);
      if (last != "timestep") continue;
      std::vector<double> h, e_inv, e_tilt;
      for (const SweepRecord& r : l.points) {
        const bool ok = r.status == "ok";
        h.push_back(r.ladder_value);
        e_inv.push_back(ok && r.metrics.inversion_time_rel_error ? std::abs(*r.metrics.inversion_time_rel_error)
                                                                 : std::nan(""));
        e_tilt.push_back(ok ? r.metrics.tilt_rms_error : std::nan(""));
      }
      std::vector<std::string> row = {l.title, u.engine, u.key};
      for (const auto* e : {&e_inv, &e_tilt}) {
        if (e == &e_inv && !s.reference_inversion) {
          row.insert(row.end(), {"-", "the reference does not invert"});
          continue;
        }
        const ConvergenceFit f = convergence_order(h, *e);
        row.push_back(f.ok ? fmt("%.2f", f.order) : "-");
        row.push_back(f.ok ? "dt = " + points_text(h, f.used) + (f.note.empty() ? "" : " (" + f.note + ")") : f.note);
      }
      conv.rows.push_back(row);
    }
  if (!conv.rows.empty()) {
    doc.heading(3, "Empirical order of convergence in the time step");
    doc.para("Least-squares slope of log(error) against log(dt) over the asymptotic range: the longest run of "
                   "consecutive time steps whose local slopes are all at least 0.5 (points where the error no longer "
                   "falls, at a floor or saturated, are left out) and agree with the fitted slope within "
                   "max(0.25, 15 %). Only runs that finished (status ok) count.");
    doc.table(to_doc(conv));
  }

  doc.heading(3, s.reference_inversion ? "Regime: does it still invert?" : "Regime: does it still roll?");
  doc.para(std::string("The reference ") + (s.reference_inversion ? "inverts" : "does not invert") +
                     ". For each setup, the softest setting (largest time step or tolerance, fewest iterations) "
                     "reached from the finest one before the first point that is not safe in the reference's "
                     "regime (the page's one criterion: its regime differs" +
                     (s.reference_inversion ? " (no inversion)" : " (it inverts, or the run ends early)") +
                     ", or the stability map classes it other than ok)" +
                     ". Every verdict here holds up to the runs' horizon, t = " + fmt("%.4g", s.duration) +
                     (s.reference_inversion
                          ? "."
                          : "; for a time-step ladder, the last column says whether leaving the reference's regime "
                            "goes away as the step shrinks (the finest runs roll), only moves later (every finished "
                            "run inverts, later at a smaller step), or converges (the two finest runs invert within "
                            "1 % of each other: the engine's model, not its step)."));
  SweepTable reg{{"setup", "engine", "softest safe setting in the reference's regime", "points not safe",
             "as the step shrinks"},
            {}};
  for (const SetupGroup& u : s.setups)
    for (const Line& l : lines_of(u)) {
      const long long k = softest_agreeing(l.points);
      const bool choices = std::any_of(l.points.begin(), l.points.end(),
                                       [](const SweepRecord& r) { return !std::isfinite(r.ladder_value); });
      std::string out;
      const SearchCriterion regime = setting_criterion(false, 0);
      for (const SweepRecord& r : l.points)
        if (!is_safe(regime, r)) {
          std::string what = r.inversion_time
                                 ? "inverts at " + fmt("%.4g", *r.inversion_time)
                                 : (r.status == "ok" ? "no inversion" : r.status + " at " + fmt("%.4g", r.status_time));
          if (r.status == "ok" && r.run_class != "ok") what += ", classed " + r.run_class;
          out += (out.empty() ? "" : "; ") + ladder_text(r) + ": " + what;
        }
      reg.rows.push_back({l.title, u.engine,
                          choices ? "- (a ladder of choices)"
                          : k >= 0 ? setting_text(l.points[static_cast<size_t>(k)])
                                   : "none (even the finest disagrees)",
                          out.empty() ? "none" : out, trend_text(regime_trend(l.points))});
    }
  doc.table(to_doc(reg));

  if (!images.empty()) {
    doc.heading(3, "Charts");
    for (const ChartFile& c : chart_files(s, scene))
      if (std::find(images.begin(), images.end(), c.file) != images.end()) doc.figure(c.file, c.caption);
  }

  doc.heading(3, "Every point");
  SweepTable all_t{{"setup", "setting", "status", "class", "inversion t", "inversion error", "stem contact error", "tilt RMS (rad)",
               "energy max (/E0)", "contact path RMS (/R)", "CPU s (min)", "steps", "rhs evals", "solver iters"},
              {}};
  for (const SetupGroup& u : s.setups)
    for (const SweepRecord& r : u.points) {
      const std::string status = r.status == "ok" ? "ok" : r.status + " at " + fmt("%.4g", r.status_time);
      all_t.rows.push_back(
          {r.setup, short_setting(r), status, class_cell(r), time_text(r.inversion_time),
           r.metrics.inversion_event == "both" ? pct(r.metrics.inversion_time_rel_error) : r.metrics.inversion_event,
           r.metrics.stem_contact_event == "both" ? pct(r.metrics.stem_contact_time_rel_error)
                                                  : r.metrics.stem_contact_event,
           g3(r.metrics.tilt_rms_error), g3(r.metrics.energy_max_error), g3(r.metrics.contact_path_rms_error),
           g3(r.cpu_seconds), std::to_string(r.steps), std::to_string(r.rhs_evaluations),
           std::to_string(r.solver_iterations)});
      all_t.css.push_back({"", "", "", class_css(r)});
    }
  doc.table(to_doc(all_t));
}

// The stability map (setup x scene x ladder value, each cell the run's class) and the reference's
// own run on every scene, reported the same way.
void stability_section(const std::vector<SceneGroup>& scenes, Document& doc) {
  doc.heading(2, "Stability map");
  doc.para("Every run classified (harness/measure/classify.h): ok; diverged (NaN, energy above 2 E0, G below the floor by more "
       "than R/10, speed blow-up); unphysical (energy gain in a dissipative scene, or Jellett's integral drifting "
       "beyond 1e-3 where it must hold); clamped (an engine limit hit, e.g. Bullet's angular-velocity clamp); failed "
       "(the engine refused the scene or threw); contact_lost; with the time it happened. \"regime differs\": the run "
       "finished but inverts where the reference does not, or the reverse. One table per setup: scenes down, its "
       "ladder across.");
  std::vector<std::string> order;
  for (const SceneGroup& s : scenes)
    for (const SetupGroup& u : s.setups)
      if (std::find(order.begin(), order.end(), u.name) == order.end()) order.push_back(u.name);
  for (const std::string& name : order) {
    std::map<long long, std::string> ladder, grid;  // index -> value as text
    std::string key, grid_key, engine;
    for (const SceneGroup& s : scenes)
      for (const SetupGroup& u : s.setups)
        if (u.name == name) {
          key = u.key;
          grid_key = u.grid_key;
          engine = u.engine;
          for (const SweepRecord& r : u.points) {
            ladder[r.ladder_index] = ladder_text(r);
            if (!r.grid_key.empty()) grid[r.grid_index] = grid_text(r);
          }
        }
    // A grid: one row per scene and grid value.
    if (grid.empty()) grid[0] = "";
    SweepTable t{{"scene \\ " + key}, {}, {}};
    for (const auto& [i, v] : ladder) t.header.push_back(v);
    for (const SceneGroup& s : scenes)
      for (const auto& [g, gv] : grid) {
        std::vector<std::string> row{grid_key.empty() ? s.name : s.name + ", " + last_part(grid_key) + "=" + gv},
            css{""};
        for (const auto& [i, v] : ladder) {
          std::string cell = "-", c;
          for (const SetupGroup& u : s.setups)
            if (u.name == name)
              for (const SweepRecord& r : u.points)
                if (r.ladder_index == i && r.grid_index == g) {
                  cell = class_cell(r);
                  c = class_css(r);
                }
          row.push_back(cell);
          css.push_back(c);
        }
        t.rows.push_back(row);
        t.css.push_back(css);
      }
    doc.heading(3, name + " (" + engine + ")");
    doc.table(to_doc(t));
  }

  doc.heading(3, "The reference on each scene");
  doc.para("The analytic reference at the scene's own tolerance, against which every point is measured: its "
                 "cost, its own class, its energy balance |E_end - E0| / E0 (a conservation error only where the "
                 "friction law conserves energy: none or rolling) and the largest relative drift of Jellett's "
                 "integral on one surface.");
  SweepTable rt{{"scene", "method", "rtol", "status", "class", "steps", "rhs evals", "CPU s", "|E_end - E0| / E0",
            "Jellett drift", "inversion t"},
           {},
           {}};
  for (const SceneGroup& s : scenes) {
    std::optional<SweepRecord::ReferenceRun> f;
    for (const SetupGroup& u : s.setups)
      for (const SweepRecord& r : u.points)
        if (r.reference) f = r.reference;
    if (!f) {
      rt.rows.push_back({s.name, "-", "-", "-", "-", "-", "-", "-", "-", "-", time_text(s.reference_inversion)});
      rt.css.push_back({});
      continue;
    }
    const double de = f->energy_initial != 0 ? std::fabs(f->energy_final - f->energy_initial) / std::fabs(f->energy_initial)
                                             : std::numeric_limits<double>::quiet_NaN();
    rt.rows.push_back({s.name, f->method, fmt("%g", f->rtol), f->status, f->run_class, std::to_string(f->steps),
                       std::to_string(f->rhs_evaluations), g3(f->cpu_seconds), g3(de), g3(f->jellett_max_relative_drift),
                       time_text(s.reference_inversion)});
    rt.css.push_back({"", "", "", "", f->run_class == "ok" ? "c-ok" : "c-" + f->run_class});
  }
  doc.table(to_doc(rt));
}

Document build_doc(const std::vector<SweepRecord>& records, const std::vector<std::string>& images,
                   const std::string& plots_note) {
  Document doc;
  doc.title = "tippe: work-precision sweep";
  doc.top_links = {{"all reports", "../index.html"},
                   {"records.jsonl", "records.jsonl"},
                   {"sweep.json", "sweep.json"},
                   {"report.md", "report.md"}};
  const std::vector<SceneGroup> scenes = group(records);
  doc.heading(1, "Work-precision sweep");
  const std::vector<std::string> verdicts = sweep_verdicts(scenes);
  for (const std::string& v : verdicts) doc.para(v, "verdict");
  if (!verdicts.empty())
    doc.para(std::string("Safe, the one criterion of this page's sentences, its tables, its boundary searches and the gates: ") +
             "the run finished (status ok), the stability map classes it ok (no divergence, no net energy gain in "
             "a dissipative scene " + energy_gain_rules_text(records) +
             ", no Jellett drift where J is conserved), and it is in the reference's regime "
             "(it inverts where the reference does and finishes without inverting where it does not, judged inside "
             "the reference's converged window); where the reference inverts, the setting to use also has its "
             "inversion time within 1 % (10 % when no point is). Points the stability map classes "
             "unphysical or diverged never count, nor are they ever the setting to use.",
             "note");
  size_t points = 0;
  std::set<std::string> setups, commits;
  std::map<std::string, std::string> versions;
  long long repeats = 0;
  for (const SceneGroup& s : scenes)
    for (const SetupGroup& u : s.setups) {
      setups.insert(u.name);
      for (const SweepRecord& r : u.points) {
        ++points;
        commits.insert(r.git_commit);
        if (r.engine_version != "unknown") versions[r.engine] = r.engine_version;
        repeats = std::max(repeats, r.repeats);
      }
    }
  std::string commit_text;
  for (const auto& c : commits) commit_text += (commit_text.empty() ? "" : ", ") + c;
  std::string version_text;
  for (const auto& [e, v] : versions) version_text += (version_text.empty() ? "" : "; ") + e + ": " + v;
  doc.para(std::to_string(points) + " points over " + std::to_string(scenes.size()) + " scene(s) and " +
           std::to_string(setups.size()) + " setup(s), each point run " + std::to_string(repeats) +
           " time(s). Errors are against the analytic reference run at each scene's own tolerances; cost is "
           "the CPU time of the run's own thread (the minimum over the repeats), so timings stay fair "
           "on a loaded machine. Times are in each scene's own unit (seconds for SI scenes). Built from "
           "records.jsonl alone (commit " +
           (commit_text.empty() ? "unknown" : commit_text) + "; " + version_text + ").");
  if (points == 0) {
    doc.para("No point has finished yet.");
    return doc;
  }
  // Boundary searches first: the number a user came for (the largest safe setting).
  for (const ReportPart& part : boundary_report(records)) {
    if (part.kind == ReportPart::H2) doc.heading(2, part.text);
    else if (part.kind == ReportPart::H3) doc.heading(3, part.text);
    else if (part.kind == ReportPart::Tab) doc.table(to_doc(SweepTable{part.header, part.rows}));
    else doc.para(part.text);
  }
  doc.heading(2, "Setups");
  SweepTable st{{"setup", "engine", "fixed settings", "ladder"}, {}};
  bool any_grid = false;
  for (const SceneGroup& s : scenes)
    for (const SetupGroup& u : s.setups) any_grid = any_grid || !u.grid_key.empty();
  if (any_grid) st.header.push_back("grid");
  std::set<std::string> listed;
  for (const SceneGroup& s : scenes)
    for (const SetupGroup& u : s.setups) {
      if (!listed.insert(u.name).second) continue;
      std::string set;
      std::vector<std::string> ladder, grid;
      for (const auto& x : u.set) set += (set.empty() ? "" : "; ") + x;
      for (const SweepRecord& r : u.points) {
        if (std::find(ladder.begin(), ladder.end(), ladder_text(r)) == ladder.end()) ladder.push_back(ladder_text(r));
        if (!u.grid_key.empty() && std::find(grid.begin(), grid.end(), grid_text(r)) == grid.end())
          grid.push_back(grid_text(r));
      }
      const auto join = [](const std::vector<std::string>& v) {
        std::string t;
        for (const auto& x : v) t += (t.empty() ? "" : ", ") + x;
        return t;
      };
      st.rows.push_back({u.name, u.engine, set.empty() ? "-" : set, u.key + " = " + join(ladder)});
      if (any_grid) st.rows.back().push_back(u.grid_key.empty() ? "-" : u.grid_key + " = " + join(grid));
    }
  doc.table(to_doc(st));
  if (!plots_note.empty()) doc.para("Charts: " + plots_note + ".");
  doc.para("Charts put error against cost on log-log axes, one line per setup (per grid value of a setup with a grid; the analytic model's own "
                 "tolerance ladders are the thick reddish-purple lines); runs that did not finish (diverged, failed, ...) and "
                 "errors of exactly 0 (a setting equal to the reference's) are left out of them and listed in the "
                 "tables.");
  choices_section(records, doc);
  stability_section(scenes, doc);
  for (size_t k = 0; k < scenes.size(); ++k) scene_section(scenes[k], k, images, doc);
  return doc;
}

}  // namespace

std::string render_sweep_markdown(const std::vector<SweepRecord>& records) {
  return render_document_markdown(build_doc(records, {}, ""));
}

void write_sweep_report(const std::string& dir, const std::vector<SweepRecord>& records, bool plots) {
  std::vector<std::string> images;
  std::string note;
  if (plots)
    images = render_sweep_charts(dir, group(records), note);
  else
    note = "plots skipped (--no-plots)";
  const Document doc = build_doc(records, images, note);
  write_file_atomic((fs::path(dir) / "report.md").string(), render_document_markdown(doc));
  write_file_atomic((fs::path(dir) / "index.html").string(), render_document_html(doc));
}

}  // namespace tippe
