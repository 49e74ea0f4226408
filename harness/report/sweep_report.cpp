// Analysis of sweep records (convergence orders, cheapest settings, regimes) and the report made from them alone.

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
#include <string>
#include <tuple>
#include <vector>

#include "registry.h"
#include "report/gnuplot.h"
#include "records.h"
#include "report/report.h"
#include "sweep.h"
#include "sweep_search.h"

namespace tippe {

namespace {

namespace fs = std::filesystem;

constexpr double kInf = std::numeric_limits<double>::infinity();

bool usable(double v) { return std::isfinite(v) && v > 0; }

}  // namespace

// ---- analysis ---------------------------------------------------------------------------------

ConvergenceFit convergence_order(const std::vector<double>& h, const std::vector<double>& error) {
  ConvergenceFit fit;
  std::vector<size_t> pts;
  for (size_t i = 0; i < h.size() && i < error.size(); ++i)
    if (usable(h[i]) && usable(error[i])) pts.push_back(i);
  std::stable_sort(pts.begin(), pts.end(), [&](size_t a, size_t b) { return h[a] < h[b]; });
  // Equal steps say nothing about a slope: the first of each is kept.
  pts.erase(std::unique(pts.begin(), pts.end(), [&](size_t a, size_t b) { return h[a] == h[b]; }), pts.end());
  const size_t n = pts.size();
  if (n < 2) {
    fit.note = "fewer than 2 points with a finite, non-zero error";
    return fit;
  }
  std::vector<double> x(n), y(n), s(n - 1);
  for (size_t k = 0; k < n; ++k) {
    x[k] = std::log(h[pts[k]]);
    y[k] = std::log(error[pts[k]]);
  }
  for (size_t k = 0; k + 1 < n; ++k) s[k] = (y[k + 1] - y[k]) / (x[k + 1] - x[k]);

  size_t best_a = 0, best_b = 0;
  double best_dev = kInf, best_p = 0;
  bool found = false;
  for (size_t a = 0; a + 1 < n; ++a) {
    for (size_t b = a + 1; b < n; ++b) {
      if (s[b - 1] < 0.5) break;  // the error no longer falls with the step: a floor or saturation
      double mx = 0, my = 0;
      for (size_t k = a; k <= b; ++k) {
        mx += x[k];
        my += y[k];
      }
      const double m = static_cast<double>(b - a + 1);
      mx /= m;
      my /= m;
      double sxy = 0, sxx = 0;
      for (size_t k = a; k <= b; ++k) {
        sxy += (x[k] - mx) * (y[k] - my);
        sxx += (x[k] - mx) * (x[k] - mx);
      }
      const double p = sxy / sxx;
      double dev = 0;
      for (size_t k = a; k < b; ++k) dev = std::max(dev, std::abs(s[k] - p));
      if (dev > std::max(0.25, 0.15 * p)) continue;
      const size_t len = b - a + 1, best_len = found ? best_b - best_a + 1 : 0;
      // Longest first; then the straighter line; then the finer steps (the asymptotic end).
      if (!found || len > best_len || (len == best_len && dev < best_dev - 1e-9)) {
        found = true;
        best_a = a;
        best_b = b;
        best_dev = dev;
        best_p = p;
      }
    }
  }
  if (!found) {
    fit.note = "the error does not fall with the step anywhere in the ladder";
    return fit;
  }
  fit.ok = true;
  fit.order = best_p;
  for (size_t k = best_a; k <= best_b; ++k) fit.used.push_back(pts[k]);
  if (fit.used.size() == 2) fit.note = "only 2 points";
  return fit;
}

namespace {

long long cheapest_where(const std::vector<SweepRecord>& records, const std::function<bool(double)>& accept) {
  long long best = -1;
  for (size_t i = 0; i < records.size(); ++i) {
    const SweepRecord& r = records[i];
    const auto& e = r.metrics.inversion_time_rel_error;
    if (r.status != "ok" || !e || !std::isfinite(*e) || !accept(std::abs(*e)) || !std::isfinite(r.cpu_seconds))
      continue;
    if (best < 0) {
      best = static_cast<long long>(i);
      continue;
    }
    const SweepRecord& b = records[static_cast<size_t>(best)];
    if (r.cpu_seconds < b.cpu_seconds || (r.cpu_seconds == b.cpu_seconds && r.steps < b.steps))
      best = static_cast<long long>(i);
  }
  return best;
}

}  // namespace

long long cheapest_below(const std::vector<SweepRecord>& records, double threshold) {
  return cheapest_where(records, [threshold](double e) { return e < threshold; });
}

long long cheapest_at_least_as_accurate(const std::vector<SweepRecord>& records, double error) {
  return cheapest_where(records, [error](double e) { return e <= error; });
}

bool agrees_with_reference_regime(const SweepRecord& r) {
  if (r.reference_inversion_time) return r.inversion_time.has_value();
  return r.status == "ok" && !r.inversion_time;
}

bool larger_is_softer(const std::string& ladder_key) {
  const std::string last =
      ladder_key.substr(ladder_key.rfind('.') == std::string::npos ? 0 : ladder_key.rfind('.') + 1);
  return last.find("iterations") == std::string::npos && last.find("substeps") == std::string::npos;
}

long long softest_agreeing(const std::vector<SweepRecord>& records) {
  if (records.empty()) return -1;
  // A ladder of choices has no softer end.
  for (const SweepRecord& r : records)
    if (!std::isfinite(r.ladder_value)) return -1;
  std::vector<size_t> order(records.size());
  for (size_t i = 0; i < order.size(); ++i) order[i] = i;
  const bool larger_soft = larger_is_softer(records.front().ladder_key);
  // Finest first.
  std::stable_sort(order.begin(), order.end(), [&](size_t a, size_t b) {
    return larger_soft ? records[a].ladder_value < records[b].ladder_value
                       : records[a].ladder_value > records[b].ladder_value;
  });
  long long softest = -1;
  for (size_t i : order) {
    if (!agrees_with_reference_regime(records[i])) break;
    softest = static_cast<long long>(i);
  }
  return softest;
}

RegimeTrend regime_trend(const std::vector<SweepRecord>& records) {
  RegimeTrend out{"-", std::nullopt, {}};
  if (records.empty() || records.front().reference_inversion_time) return out;
  const std::string& key = records.front().ladder_key;
  if (key.substr(key.rfind('.') == std::string::npos ? 0 : key.rfind('.') + 1) != "timestep") return out;
  // Finished runs only: a run that diverged or was clamped says nothing about when a stable run
  // of that step would leave the regime.
  std::vector<const SweepRecord*> ok;
  for (const SweepRecord& r : records)
    if (r.status == "ok" && std::isfinite(r.ladder_value)) ok.push_back(&r);
  if (ok.size() < 2) return out;
  std::stable_sort(ok.begin(), ok.end(),
                   [](const SweepRecord* a, const SweepRecord* b) { return a->ladder_value > b->ladder_value; });
  for (const SweepRecord* r : ok)
    if (r->inversion_time) out.inversion_by_step.emplace_back(r->ladder_value, *r->inversion_time);
  if (out.inversion_by_step.empty()) {
    out.verdict = "none";
    return out;
  }
  // The finest runs in the regime, walking from the finest up to the first that inverts.
  size_t k = ok.size();
  while (k > 0 && !ok[k - 1]->inversion_time) --k;
  if (k < ok.size()) out.in_regime_from = ok[k]->ladder_value;
  // Between the coarsest inverting run and the agreeing tail, every run must invert for the
  // departure to be one thing that moves with the step.
  size_t first = 0;
  while (!ok[first]->inversion_time) ++first;
  for (size_t i = first; i < k; ++i)
    if (!ok[i]->inversion_time) {
      out.verdict = "mixed";
      return out;
    }
  if (out.in_regime_from) {
    out.verdict = "goes away";
    return out;
  }
  // Every finished run inverts. 1 %: an inversion time read off samples of the run moves by a
  // sample or two between runs that are the same physics. The two finest runs within it: the
  // departure has converged in the step (the engine's model, not its step error). Otherwise,
  // each finer run no earlier than the coarser one: it moves later as the step shrinks.
  const double t_fine = *ok[k - 1]->inversion_time, t_next = *ok[k - 2]->inversion_time;
  if (k - first >= 2 && std::abs(t_fine - t_next) <= 0.01 * t_fine) {
    out.verdict = "converges";
    return out;
  }
  bool later = true;
  for (size_t i = first + 1; i < k; ++i)
    later = later && *ok[i]->inversion_time >= 0.99 * *ok[i - 1]->inversion_time;
  out.verdict = later ? "moves later" : "earlier at a finer step";
  return out;
}

// ---- report -----------------------------------------------------------------------------------

namespace {

std::string fmt(const char* f, double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, f, v);
  return buf;
}
std::string g3(double v) { return std::isfinite(v) ? fmt("%.3g", v) : "-"; }
std::string pct(double v) { return std::isfinite(v) ? fmt("%.3g", 100 * v) + " %" : "-"; }
std::string pct(const std::optional<double>& v) { return v ? pct(*v) : "-"; }
std::string time_text(const std::optional<double>& t) { return t ? fmt("%.6g", *t) : "none"; }

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
std::string last_part(const std::string& key) { return key.substr(key.rfind('.') + 1); }
std::string setting_text(const SweepRecord& r) {
  return r.ladder_key + " = " + ladder_text(r) + (r.grid_key.empty() ? "" : ", " + r.grid_key + " = " + grid_text(r));
}
std::string short_setting(const SweepRecord& r) {
  return last_part(r.ladder_key) + " = " + ladder_text(r) +
         (r.grid_key.empty() ? "" : ", " + last_part(r.grid_key) + " = " + grid_text(r));
}

// A report as a list of blocks, rendered both as Markdown and as HTML.
struct Table {
  std::vector<std::string> header;
  std::vector<std::vector<std::string>> rows;
  // Optional CSS class of each cell (same shape as rows; "" for none): the HTML colours.
  std::vector<std::vector<std::string>> css = {};
};
struct Block {
  enum Kind { H1, H2, H3, Para, Tab, Image } kind;
  std::string text;  // heading, paragraph, or image caption
  Table table;
  std::string file;  // image
};

std::string md_cell(const std::string& s) {
  std::string out;
  for (char c : s) out += c == '|' ? std::string("\\|") : std::string(1, c);
  return out;
}

std::string render_md(const std::vector<Block>& doc) {
  std::ostringstream os;
  for (const Block& b : doc) {
    switch (b.kind) {
      case Block::H1:
        os << "# " << b.text << "\n\n";
        break;
      case Block::H2:
        os << "## " << b.text << "\n\n";
        break;
      case Block::H3:
        os << "### " << b.text << "\n\n";
        break;
      case Block::Para:
        os << b.text << "\n\n";
        break;
      case Block::Image:
        os << "![" << b.text << "](" << b.file << ")\n\n";
        break;
      case Block::Tab: {
        os << "|";
        for (const auto& h : b.table.header) os << " " << md_cell(h) << " |";
        os << "\n|";
        for (size_t i = 0; i < b.table.header.size(); ++i) os << "---|";
        os << "\n";
        for (const auto& row : b.table.rows) {
          os << "|";
          for (const auto& c : row) os << " " << md_cell(c) << " |";
          os << "\n";
        }
        os << "\n";
        break;
      }
    }
  }
  return os.str();
}

std::string render_page(const std::vector<Block>& doc, const std::string& title) {
  std::ostringstream os;
  os << "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n<title>" << html_escape(title)
     << "</title>\n<style>\n"
        "body { font-family: system-ui, sans-serif; margin: 1.5em auto; max-width: 1150px; padding: 0 1em; color: "
        "#222; }\n"
        "table { border-collapse: collapse; margin: 0.5em 0 1.2em; font-size: 0.9em; }\n"
        "th, td { border: 1px solid #ccc; padding: 0.25em 0.5em; text-align: left; vertical-align: top; }\n"
        "thead th { background: #f0f0f0; }\n"
        "figure { margin: 1em 0; } figure img { max-width: 100%; border: 1px solid #ddd; }\n"
        "figcaption { font-size: 0.9em; color: #444; }\n"
        "h2 { border-bottom: 2px solid #ddd; margin-top: 2em; }\n"
        // Stability map: one colour per run class; `regime` marks a run that finished but parts
        // from the reference's regime (inverts where it does not, or the reverse).
        "td.c-ok { background: #c8e6c9; } td.c-regime { background: #fff59d; }\n"
        "td.c-unphysical { background: #ffcc80; } td.c-clamped { background: #ce93d8; }\n"
        "td.c-diverged { background: #ef9a9a; } td.c-failed { background: #bdbdbd; }\n"
        "td.c-contact_lost { background: #90caf9; }\n"
        "</style>\n</head>\n<body>\n";
  for (const Block& b : doc) {
    switch (b.kind) {
      case Block::H1:
        os << "<h1>" << html_escape(b.text) << "</h1>\n";
        break;
      case Block::H2:
        os << "<h2>" << html_escape(b.text) << "</h2>\n";
        break;
      case Block::H3:
        os << "<h3>" << html_escape(b.text) << "</h3>\n";
        break;
      case Block::Para:
        os << "<p>" << html_escape(b.text) << "</p>\n";
        break;
      case Block::Image:
        os << "<figure><img src=\"" << html_escape(b.file) << "\" alt=\"" << html_escape(b.text) << "\"><figcaption>"
           << html_escape(b.text) << "</figcaption></figure>\n";
        break;
      case Block::Tab:
        os << "<table>\n<thead><tr>";
        for (const auto& h : b.table.header) os << "<th>" << html_escape(h) << "</th>";
        os << "</tr></thead>\n<tbody>\n";
        for (size_t i = 0; i < b.table.rows.size(); ++i) {
          os << "<tr>";
          for (size_t j = 0; j < b.table.rows[i].size(); ++j) {
            const std::string cls =
                i < b.table.css.size() && j < b.table.css[i].size() ? b.table.css[i][j] : std::string();
            os << (cls.empty() ? "<td>" : "<td class=\"" + html_escape(cls) + "\">") << html_escape(b.table.rows[i][j])
               << "</td>";
          }
          os << "</tr>\n";
        }
        os << "</tbody>\n</table>\n";
        break;
    }
  }
  os << "</body>\n</html>\n";
  return os.str();
}

// The records of one scene, grouped by setup in sweep order.
struct SetupGroup {
  std::string name, engine, key;
  std::vector<std::string> set;
  std::vector<SweepRecord> points;  // grid, then ladder order
  std::string grid_key;             // empty: no grid
};

// One line along a setup's ladder: the whole setup, or one grid value of it.
struct Line {
  std::string title;  // "SETUP", or "SETUP KEY=VALUE" (KEY the grid key's last part)
  std::vector<SweepRecord> points;  // ladder order
};
std::vector<Line> lines_of(const SetupGroup& u) {
  std::vector<Line> out;
  for (const SweepRecord& r : u.points) {
    const std::string title = u.grid_key.empty() ? u.name : u.name + " " + last_part(u.grid_key) + "=" + grid_text(r);
    if (out.empty() || out.back().title != title) out.push_back({title, {}});
    out.back().points.push_back(r);
  }
  return out;
}
struct SceneGroup {
  std::string name, file;
  double duration = 0;
  std::optional<double> reference_inversion, reference_stem_contact;
  std::vector<SetupGroup> setups;
};

std::vector<SceneGroup> group(const std::vector<SweepRecord>& input) {
  std::vector<SweepRecord> records;
  std::set<std::string> seen;
  for (const SweepRecord& r : input)
    if (seen.insert(r.point_id).second) records.push_back(r);
  std::stable_sort(records.begin(), records.end(), [](const SweepRecord& a, const SweepRecord& b) {
    return std::tie(a.scene_index, a.setup_index, a.grid_index, a.ladder_index) <
           std::tie(b.scene_index, b.setup_index, b.grid_index, b.ladder_index);
  });
  std::vector<SceneGroup> scenes;
  for (const SweepRecord& r : records) {
    auto s = std::find_if(scenes.begin(), scenes.end(), [&](const SceneGroup& g) { return g.name == r.scene; });
    if (s == scenes.end()) {
      scenes.push_back(
          {r.scene, r.scene_file, r.duration, r.reference_inversion_time, r.reference_stem_contact_time, {}});
      s = scenes.end() - 1;
    }
    auto u = std::find_if(s->setups.begin(), s->setups.end(), [&](const SetupGroup& g) { return g.name == r.setup; });
    if (u == s->setups.end()) {
      s->setups.push_back({r.setup, r.engine, r.ladder_key, r.set, {}, r.grid_key});
      u = s->setups.end() - 1;
    }
    u->points.push_back(r);
  }
  return scenes;
}

struct MetricInfo {
  const char* key;
  const char* label;
  std::optional<double> (*get)(const SweepRecord&);
};
const std::vector<MetricInfo>& metric_infos() {
  static const std::vector<MetricInfo> m = {
      {"inversion_time_rel_error", "|relative error of the inversion time|",
       [](const SweepRecord& r) { return r.metrics.inversion_time_rel_error; }},
      {"stem_contact_time_rel_error", "|relative error of the first stem contact time|",
       [](const SweepRecord& r) { return r.metrics.stem_contact_time_rel_error; }},
      {"tilt_rms_error", "RMS tilt error (rad)",
       [](const SweepRecord& r) { return std::optional<double>(r.metrics.tilt_rms_error); }},
      {"energy_max_error", "max |E - E_ref| / E0",
       [](const SweepRecord& r) { return std::optional<double>(r.metrics.energy_max_error); }},
      {"contact_path_rms_error", "RMS floor contact path error / R",
       [](const SweepRecord& r) { return std::optional<double>(r.metrics.contact_path_rms_error); }},
  };
  return m;
}

std::string engine_colour(const std::string& engine) {
  // Registered engines have their own (engines/registry.h).
  return engine_plot_colour(engine);
}

// One series of a chart: a setup's points as (x, y), in ladder order.
struct Series {
  std::string title, engine;
  int variant = 0;  // how many earlier setups of the same engine: picks dash and point type
  std::vector<std::pair<double, double>> xy;
};
struct Chart {
  std::string file, title, caption, ylabel;
  bool logy = true;
  std::optional<double> hline;  // regime charts: the end of the run
  std::vector<Series> series;
};

// One series per line (a setup, or a grid value of it), with the lines' points beside it.
std::vector<Series> setup_series(const SceneGroup& s, std::vector<std::vector<SweepRecord>>& points) {
  std::vector<Series> out;
  std::map<std::string, int> per_engine;
  points.clear();
  for (const SetupGroup& u : s.setups)
    for (Line& l : lines_of(u)) {
      out.push_back({l.title, u.engine, per_engine[u.engine]++, {}});
      points.push_back(std::move(l.points));
    }
  return out;
}

std::vector<Chart> make_charts(const SceneGroup& s) {
  std::vector<Chart> charts;
  for (const MetricInfo& m : metric_infos()) {
    Chart c;
    c.file = "wp-" + s.name + "-" + m.key + ".svg";
    c.ylabel = m.label;
    c.title = s.name + ": " + m.key;
    c.caption = s.name + ": " + m.label + " against CPU seconds, one line per setup (per grid value) along its ladder.";
    std::vector<std::vector<SweepRecord>> points;
    c.series = setup_series(s, points);
    for (size_t i = 0; i < points.size(); ++i)
      for (const SweepRecord& r : points[i]) {
        const auto e = m.get(r);
        if (r.status == "ok" && e && usable(std::abs(*e)) && usable(r.cpu_seconds))
          c.series[i].xy.emplace_back(r.cpu_seconds, std::abs(*e));
      }
    charts.push_back(c);
  }
  if (!s.reference_inversion) {
    Chart c;
    c.file = "regime-" + s.name + ".svg";
    c.ylabel = "inversion time (on the dashed line: no inversion)";
    c.title = s.name + ": regime of every point";
    c.caption = s.name +
                ": the reference does not invert. Inversion time of every point against CPU seconds; points "
                "on the dashed line (the end of the run) did not invert, crosses mark runs that ended early "
                "(at their status time).";
    c.logy = false;
    c.hline = s.duration;
    std::vector<std::vector<SweepRecord>> points;
    c.series = setup_series(s, points);
    Series early{"ended early", "", 0, {}};
    for (size_t i = 0; i < points.size(); ++i)
      for (const SweepRecord& r : points[i]) {
        if (!usable(r.cpu_seconds)) continue;
        if (r.inversion_time)
          c.series[i].xy.emplace_back(r.cpu_seconds, *r.inversion_time);
        else if (r.status == "ok")
          c.series[i].xy.emplace_back(r.cpu_seconds, r.duration);
        else
          early.xy.emplace_back(r.cpu_seconds, r.status_time);
      }
    c.series.push_back(early);
    charts.push_back(c);
  }
  return charts;
}

// Writes the data and one gnuplot script for every chart with data, runs gnuplot, and returns
// the SVGs that came out; `note` says what is missing.
std::vector<std::string> render_charts(const fs::path& dir, const std::vector<Chart>& charts, std::string& note) {
  std::vector<std::string> made;
  std::string why;
  const std::string gnuplot = gnuplot_command(&why);
  if (gnuplot.empty()) {
    note = why;
    return made;
  }
  std::ostringstream gp;
  gp << "# Work-precision charts of a tippe sweep (written by tippe sweep; data in sweep-*.dat).\n"
        "set terminal svg size 900,540 dynamic noenhanced font 'Helvetica,12' background rgb 'white'\n"
        "set grid\nset key outside right top\nset logscale x\nset format x '%g'\n"
        // Keeps the extreme points off the frame.
        "set offsets graph 0.04, graph 0.04, graph 0.06, graph 0.06\n"
        "set xlabel 'CPU seconds of the run (own thread, minimum over repeats)'\n";
  std::vector<std::string> planned;
  for (const Chart& c : charts) {
    std::vector<const Series*> nonempty;
    for (const Series& s : c.series)
      if (!s.xy.empty()) nonempty.push_back(&s);
    if (nonempty.empty()) continue;
    const std::string dat = "sweep-" + c.file.substr(0, c.file.size() - 4) + ".dat";
    std::ostringstream d;
    d.precision(17);
    for (size_t i = 0; i < nonempty.size(); ++i) {
      // The title is data (`title columnheader(1)` below): no name reaches the script.
      d << gp_column_header(nonempty[i]->title) << "\n";
      for (const auto& [x, y] : nonempty[i]->xy) d << x << " " << y << "\n";
      d << "\n\n";
    }
    write_file_atomic((dir / dat).string(), d.str());
    gp << "\nset output " << gp_literal(c.file) << "\n";
    gp << (c.logy ? "set logscale y\nset format y '%g'\nset autoscale y\n"
                  : "unset logscale y\nset format y '%g'\nset yrange [0:" + fmt("%.17g", 1.08 * c.hline.value_or(1.0)) +
                        "]\n");
    gp << "set ylabel " << gp_literal(c.ylabel) << "\nset title " << gp_literal(c.title) << "\n";
    gp << (c.hline ? "set arrow 1 from graph 0, first " + fmt("%.17g", *c.hline) + " to graph 1, first " +
                         fmt("%.17g", *c.hline) + " nohead dt 2 lc rgb '#555555'\n"
                   : std::string("unset arrow 1\n"));
    gp << "plot ";
    for (size_t i = 0; i < nonempty.size(); ++i) {
      const Series& s = *nonempty[i];
      if (i) gp << ", \\\n     ";
      if (s.engine.empty()) {
        gp << gp_literal(dat) << " index " << i
           << " using 1:2 with points pt 2 ps 1.5 lc rgb '#000000' title columnheader(1)";
      } else {
        const bool analytic = s.engine == reference_engine().name;
        gp << gp_literal(dat) << " index " << i << " using 1:2 with linespoints lw " << (analytic ? 2.5 : 1.5)
           << " dt " << (1 + s.variant % 5) << " pt " << (analytic ? 5 : 7 + 2 * (s.variant % 4)) << " ps 0.9 lc rgb "
           << gp_literal(engine_colour(s.engine)) << " title columnheader(1)";
      }
    }
    gp << "\n";
    planned.push_back(c.file);
  }
  if (planned.empty()) {
    note = "no chart: no point has a finite, non-zero error";
    return made;
  }
  write_file_atomic((dir / "sweep-plots.gp").string(), gp.str());
  const int code = run_gnuplot(gnuplot, dir, "sweep-plots.gp", "sweep-plots.log");
  std::vector<std::string> missing;
  for (const std::string& f : planned) {
    std::error_code ec;
    if (fs::exists(dir / f, ec) && fs::file_size(dir / f, ec) > 0)
      made.push_back(f);
    else
      missing.push_back(f);
  }
  if (code != 0 || !missing.empty())
    note = "some plots failed (gnuplot exit " + std::to_string(code) + "; see sweep-plots.log)";
  return made;
}

std::string points_text(const std::vector<double>& values, const std::vector<size_t>& used) {
  std::string t;
  for (size_t i : used) t += (t.empty() ? "" : ", ") + fmt("%g", values[i]);
  return t;
}

void scene_section(const SceneGroup& s, const std::vector<std::string>& images, std::vector<Block>& doc) {
  doc.push_back({Block::H2, "Scene " + s.name, {}, {}});
  std::string ref = "Scene file " + s.file + " (as the sweep file names it), run to t = " + fmt("%g", s.duration) +
                    ". The reference ";
  ref += s.reference_inversion ? "inverts at t = " + fmt("%.10g", *s.reference_inversion)
                               : "does not invert (it settles into rolling): errors in the inversion time mean "
                                 "nothing here, so the regime of every point is what counts";
  ref += s.reference_stem_contact ? "; its stem first touches at t = " + fmt("%.10g", *s.reference_stem_contact) + "."
                                  : "; its stem never touches.";
  doc.push_back({Block::Para, ref, {}, {}});

  std::vector<SweepRecord> all, analytic;
  std::vector<std::string> engines;
  for (const SetupGroup& u : s.setups) {
    all.insert(all.end(), u.points.begin(), u.points.end());
    if (u.engine == reference_engine().name) analytic.insert(analytic.end(), u.points.begin(), u.points.end());
    if (std::find(engines.begin(), engines.end(), u.engine) == engines.end()) engines.push_back(u.engine);
  }

  if (s.reference_inversion) {
    doc.push_back({Block::H3, "Cheapest setting of each engine by inversion-time error", {}, {}});
    doc.push_back({Block::Para,
                   "For each engine (over all its setups) the point with the least CPU time whose run finished "
                   "(status ok) with |relative inversion-time error| below the bound. \"Analytic at least as "
                   "accurate\": the cheapest point of the analytic model's own ladders with an error no larger than "
                   "this point's; the ratio is this point's CPU time over that one's.",
                   {},
                   {}});
    Table t{{"engine", "error below", "setup", "setting", "inversion error", "CPU s", "steps",
             "analytic at least as accurate", "cost ratio"},
            {}};
    for (const std::string& e : engines) {
      std::vector<SweepRecord> mine;
      for (const SweepRecord& r : all)
        if (r.engine == e) mine.push_back(r);
      for (double bound : {0.1, 0.01, 0.001}) {
        const long long i = cheapest_below(mine, bound);
        if (i < 0) {
          t.rows.push_back({e, pct(bound), "none reaches it", "", "", "", "", "", ""});
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
        t.rows.push_back({e, pct(bound), r.setup, setting_text(r), pct(*r.metrics.inversion_time_rel_error),
                          g3(r.cpu_seconds), std::to_string(r.steps), a_text, ratio});
      }
    }
    doc.push_back({Block::Tab, "", t, {}});
  }

  // Convergence in the time step: only ladders over a time step have one.
  Table conv{{"setup", "engine", "ladder", "order (inversion time)", "points in the asymptotic range",
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
    doc.push_back({Block::H3, "Empirical order of convergence in the time step", {}, {}});
    doc.push_back({Block::Para,
                   "Least-squares slope of log(error) against log(dt) over the asymptotic range: the longest run of "
                   "consecutive time steps whose local slopes are all at least 0.5 (points where the error no longer "
                   "falls, at a floor or saturated, are left out) and agree with the fitted slope within "
                   "max(0.25, 15 %). Only runs that finished (status ok) count.",
                   {},
                   {}});
    doc.push_back({Block::Tab, "", conv, {}});
  }

  doc.push_back(
      {Block::H3, s.reference_inversion ? "Regime: does it still invert?" : "Regime: does it still roll?", {}, {}});
  doc.push_back({Block::Para,
                 std::string("The reference ") + (s.reference_inversion ? "inverts" : "does not invert") +
                     ". For each setup, the softest setting (largest time step or tolerance, fewest iterations) "
                     "reached from the finest one before the first point whose regime differs from the "
                     "reference's" +
                     (s.reference_inversion ? " (no inversion)" : " (it inverts, or the run ends early)") +
                     ". Every verdict here holds up to the runs' horizon, t = " + fmt("%.4g", s.duration) +
                     (s.reference_inversion
                          ? "."
                          : "; for a time-step ladder, the last column says whether leaving the reference's regime "
                            "goes away as the step shrinks (the finest runs roll), only moves later (every finished "
                            "run inverts, later at a smaller step), or converges (the two finest runs invert within "
                            "1 % of each other: the engine's model, not its step)."),
                 {},
                 {}});
  Table reg{{"setup", "engine", "softest setting in the reference's regime", "points out of the regime",
             "as the step shrinks"},
            {}};
  for (const SetupGroup& u : s.setups)
    for (const Line& l : lines_of(u)) {
      const long long k = softest_agreeing(l.points);
      const bool choices = std::any_of(l.points.begin(), l.points.end(),
                                       [](const SweepRecord& r) { return !std::isfinite(r.ladder_value); });
      std::string out;
      for (const SweepRecord& r : l.points)
        if (!agrees_with_reference_regime(r)) {
          std::string what = r.inversion_time
                                 ? "inverts at " + fmt("%.4g", *r.inversion_time)
                                 : (r.status == "ok" ? "no inversion" : r.status + " at " + fmt("%.4g", r.status_time));
          out += (out.empty() ? "" : "; ") + ladder_text(r) + ": " + what;
        }
      reg.rows.push_back({l.title, u.engine,
                          choices ? "- (a ladder of choices)"
                          : k >= 0 ? setting_text(l.points[static_cast<size_t>(k)])
                                   : "none (even the finest disagrees)",
                          out.empty() ? "none" : out, trend_text(regime_trend(l.points))});
    }
  doc.push_back({Block::Tab, "", reg, {}});

  if (!images.empty()) {
    doc.push_back({Block::H3, "Charts", {}, {}});
    for (const Chart& c : make_charts(s))
      if (std::find(images.begin(), images.end(), c.file) != images.end())
        doc.push_back({Block::Image, c.caption, {}, c.file});
  }

  doc.push_back({Block::H3, "Every point", {}, {}});
  Table all_t{{"setup", "setting", "status", "inversion t", "inversion error", "stem contact error", "tilt RMS (rad)",
               "energy max (/E0)", "contact path RMS (/R)", "CPU s (min)", "steps", "rhs evals", "solver iters"},
              {}};
  for (const SetupGroup& u : s.setups)
    for (const SweepRecord& r : u.points) {
      const std::string status = r.status == "ok" ? "ok" : r.status + " at " + fmt("%.4g", r.status_time);
      all_t.rows.push_back(
          {r.setup, short_setting(r), status, time_text(r.inversion_time),
           r.metrics.inversion_event == "both" ? pct(r.metrics.inversion_time_rel_error) : r.metrics.inversion_event,
           r.metrics.stem_contact_event == "both" ? pct(r.metrics.stem_contact_time_rel_error)
                                                  : r.metrics.stem_contact_event,
           g3(r.metrics.tilt_rms_error), g3(r.metrics.energy_max_error), g3(r.metrics.contact_path_rms_error),
           g3(r.cpu_seconds), std::to_string(r.steps), std::to_string(r.rhs_evaluations),
           std::to_string(r.solver_iterations)});
    }
  doc.push_back({Block::Tab, "", all_t, {}});
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

// The stability map (setup x scene x ladder value, each cell the run's class) and the reference's
// own run on every scene, reported the same way.
void stability_section(const std::vector<SceneGroup>& scenes, std::vector<Block>& doc) {
  doc.push_back({Block::H2, "Stability map", {}, {}});
  doc.push_back(
      {Block::Para,
       "Every run classified (harness/classify.h): ok; diverged (NaN, energy above 2 E0, G below the floor by more "
       "than R/10, speed blow-up); unphysical (energy gain in a dissipative scene, or Jellett's integral drifting "
       "beyond 1e-3 where it must hold); clamped (an engine limit hit, e.g. Bullet's angular-velocity clamp); failed "
       "(the engine refused the scene or threw); contact_lost; with the time it happened. \"regime differs\": the run "
       "finished but inverts where the reference does not, or the reverse. One table per setup: scenes down, its "
       "ladder across.",
       {},
       {}});
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
    Table t{{"scene \\ " + key}, {}, {}};
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
    doc.push_back({Block::H3, name + " (" + engine + ")", {}, {}});
    doc.push_back({Block::Tab, "", t, {}});
  }

  doc.push_back({Block::H3, "The reference on each scene", {}, {}});
  doc.push_back({Block::Para,
                 "The analytic reference at the scene's own tolerance, against which every point is measured: its "
                 "cost, its own class, its energy balance |E_end - E0| / E0 (a conservation error only where the "
                 "friction law conserves energy: none or rolling) and the largest relative drift of Jellett's "
                 "integral on one surface.",
                 {},
                 {}});
  Table rt{{"scene", "method", "rtol", "status", "class", "steps", "rhs evals", "CPU s", "|E_end - E0| / E0",
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
  doc.push_back({Block::Tab, "", rt, {}});
}

// A spread as a percentage; one below 1e-5 % of a time is rounding, said as such.
std::string spread_text(double v) {
  if (v == 0) return "0 %";
  if (v < 1e-7) return "< 1e-5 %";
  return pct(v);
}

std::string choice_verdict(const ChoiceEffect& e) {
  if (e.regime_moves) return "moves the regime";
  if (e.time_moves()) return "moves the inversion time by " + spread_text(*e.largest_spread);
  if (e.steps == 0) return "not compared (no step at which two of its values ran)";
  return "does not move the verdict";
}

std::string join_list(const std::vector<std::string>& v, const char* sep) {
  std::string t;
  for (const auto& x : v) t += (t.empty() ? "" : sep) + x;
  return t;
}

// "at STEP" of the first step at which the regime differs, and at how many it does.
std::string regime_where(const ChoiceEffect& e) {
  if (e.regime_at.empty()) return "";
  if (e.steps > 1 && e.regime_steps == e.steps) return "at every step (" + std::to_string(e.steps) + ")";
  return "at " + e.regime_at +
         (e.steps > 1 ? " (" + std::to_string(e.regime_steps) + " of " + std::to_string(e.steps) + " steps)" : "");
}

std::string choice_detail(const ChoiceEffect& e) {
  const std::string at_regime = e.regime_at.empty() ? "" : regime_where(e) + ": ";
  const std::string at_spread = e.spread_at.empty() ? "" : " at " + e.spread_at;
  std::string spread = e.largest_spread ? "inversion times " + spread_text(*e.largest_spread) + " apart" + at_spread + " (" +
                                              join_list(e.spread_times, ", ") + ")"
                                        : std::string();
  if (e.regime_moves) return at_regime + join_list(e.regime_outcomes, "; ") + (spread.empty() ? "" : "; " + spread);
  if (!spread.empty()) return (e.time_moves() ? "largest: " : "the same regime at every step; largest: ") + spread;
  if (e.steps == 0) return "-";
  return "the same regime at every step; no step at which two of its values invert";
}

// Which choices (grid values, or a ladder of non-numbers) move the verdict on each scene.
void choices_section(const std::vector<SweepRecord>& records, std::vector<Block>& doc) {
  const std::vector<ChoiceEffect> effects = modelling_choices(records);
  if (effects.empty()) return;
  doc.push_back({Block::H2, "Modelling choices", {}, {}});
  doc.push_back({Block::Para,
                 "For each setup with a choice axis (its grid, or a ladder of non-numbers) on each scene: its values "
                 "compared at the same value of the other axis (the time step). A choice moves the verdict when, at "
                 "some step, its values give different regimes (one inverts, another does not, or a run ends early) "
                 "or inversion times more than " +
                     pct(kChoiceTimeThreshold) +
                     " apart; the spread is (largest - smallest) / smallest of the inversion times at that step, the "
                     "largest over the steps.",
                 {},
                 {}});
  // Per engine: every choice key, and what it does on each scene.
  std::vector<std::string> engines;
  for (const ChoiceEffect& e : effects)
    if (std::find(engines.begin(), engines.end(), e.engine) == engines.end()) engines.push_back(e.engine);
  for (const std::string& engine : engines) {
    std::vector<std::string> keys;
    for (const ChoiceEffect& e : effects)
      if (e.engine == engine && std::find(keys.begin(), keys.end(), e.key) == keys.end()) keys.push_back(e.key);
    std::vector<std::string> parts;
    for (const std::string& key : keys) {
      std::vector<std::string> moves, stays;
      for (const ChoiceEffect& e : effects) {
        if (e.engine != engine || e.key != key) continue;
        const std::string where = e.scene + (e.setup.empty() ? "" : " (" + e.setup + ")");
        if (e.regime_moves)
          moves.push_back(where + ": the regime" + (e.regime_at.empty() ? "" : " " + regime_where(e)) +
                          (e.time_moves() ? ", and the inversion time by " + spread_text(*e.largest_spread) : ""));
        else if (e.time_moves())
          moves.push_back(where + ": the inversion time by " + spread_text(*e.largest_spread) +
                          (e.spread_at.empty() ? "" : " at " + e.spread_at));
        else
          stays.push_back(where + (e.largest_spread ? ": within " + spread_text(*e.largest_spread)
                                   : e.steps ? ": the same regime, never two inversions to compare"
                                             : ": not compared"));
      }
      std::string t = last_part(key) + " ";
      if (moves.empty())
        t += "does not move the verdict (" + join_list(stays, "; ") + ")";
      else
        t += "moves it (" + join_list(moves, "; ") + ")" +
             (stays.empty() ? "" : "; not on " + join_list(stays, "; "));
      parts.push_back(t);
    }
    doc.push_back({Block::Para, engine + ": " + join_list(parts, ". ") + ".", {}, {}});
  }
  Table t{{"engine", "scene", "reference", "setup", "choice", "values", "verdict", "detail"}, {}};
  for (const ChoiceEffect& e : effects)
    t.rows.push_back({e.engine, e.scene,
                      e.reference_inversion ? "inverts at " + fmt("%.5g", *e.reference_inversion) : "does not invert",
                      e.setup, e.key, join_list(e.values, ", "), choice_verdict(e), choice_detail(e)});
  doc.push_back({Block::Tab, "", t, {}});
}

std::vector<Block> build_doc(const std::vector<SweepRecord>& records, const std::vector<std::string>& images,
                             const std::string& plots_note) {
  std::vector<Block> doc;
  const std::vector<SceneGroup> scenes = group(records);
  doc.push_back({Block::H1, "Work-precision sweep", {}, {}});
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
  doc.push_back({Block::Para,
                 std::to_string(points) + " points over " + std::to_string(scenes.size()) + " scene(s) and " +
                     std::to_string(setups.size()) + " setup(s), each point run " + std::to_string(repeats) +
                     " time(s). Errors are against the analytic reference run at each scene's own tolerances; cost is "
                     "the CPU time of the run's own thread (the minimum over the repeats), so timings stay fair "
                     "on a loaded machine. Built from records.jsonl alone (commit " +
                     (commit_text.empty() ? "unknown" : commit_text) + "; " + version_text + ").",
                 {},
                 {}});
  if (points == 0) {
    doc.push_back({Block::Para, "No point has finished yet.", {}, {}});
    return doc;
  }
  // Boundary searches first: the number a user came for (the largest safe setting).
  for (const ReportPart& part : boundary_report(records)) {
    const Block::Kind kind = part.kind == ReportPart::H2 ? Block::H2
                             : part.kind == ReportPart::H3 ? Block::H3
                             : part.kind == ReportPart::Tab ? Block::Tab
                                                            : Block::Para;
    doc.push_back({kind, part.text, Table{part.header, part.rows}, {}});
  }
  Table st{{"setup", "engine", "fixed settings", "ladder"}, {}};
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
  doc.push_back({Block::Tab, "", st, {}});
  if (!plots_note.empty()) doc.push_back({Block::Para, "Charts: " + plots_note + ".", {}, {}});
  doc.push_back({Block::Para,
                 "Charts put error against cost on log-log axes, one line per setup (per grid value of a setup with a grid; the analytic model's own "
                 "tolerance ladders are the thick purple lines); runs that did not finish (diverged, failed, ...) and "
                 "errors of exactly 0 (a setting equal to the reference's) are left out of them and listed in the "
                 "tables.",
                 {},
                 {}});
  choices_section(records, doc);
  stability_section(scenes, doc);
  for (const SceneGroup& s : scenes) scene_section(s, images, doc);
  return doc;
}

}  // namespace

std::string ladder_text(const SweepRecord& r) {
  return std::isfinite(r.ladder_value) ? fmt("%g", r.ladder_value) : r.ladder_label;
}
std::string grid_text(const SweepRecord& r) {
  return std::isfinite(r.grid_value) ? fmt("%g", r.grid_value) : r.grid_label;
}

std::vector<ChoiceEffect> modelling_choices(const std::vector<SweepRecord>& records) {
  std::vector<ChoiceEffect> out;
  for (const SceneGroup& s : group(records))
    for (const SetupGroup& u : s.setups) {
      const bool grid = !u.grid_key.empty();
      const bool categorical = std::any_of(u.points.begin(), u.points.end(),
                                           [](const SweepRecord& r) { return !std::isfinite(r.ladder_value); });
      if (!grid && !categorical) continue;
      ChoiceEffect e;
      e.scene = s.name;
      e.setup = u.name;
      e.engine = u.engine;
      e.key = grid ? u.grid_key : u.key;
      e.at_key = grid ? u.key : "";
      e.reference_inversion = s.reference_inversion;
      const auto choice = [&](const SweepRecord& r) { return grid ? grid_text(r) : ladder_text(r); };
      std::map<long long, std::string> values;
      std::map<long long, std::vector<const SweepRecord*>> steps;  // ladder index (grid) or one step
      std::map<long long, std::string> step_text;
      for (const SweepRecord& r : u.points) {
        values.emplace(grid ? r.grid_index : r.ladder_index, choice(r));
        const long long k = grid ? r.ladder_index : 0;
        steps[k].push_back(&r);
        step_text[k] = grid ? last_part(u.key) + " = " + ladder_text(r) : "";
      }
      for (const auto& [i, v] : values) e.values.push_back(v);
      for (const auto& [k, pts] : steps) {
        if (pts.size() < 2) continue;
        ++e.steps;
        // inverts / does not invert / ends early: a different one for any value moves the regime.
        std::set<int> kinds;
        std::vector<std::string> outcomes, times;
        double lo = kInf, hi = -kInf;
        for (const SweepRecord* r : pts) {
          std::string what;
          if (r->inversion_time) {
            kinds.insert(0);
            what = "inverts at " + fmt("%.5g", *r->inversion_time);
            lo = std::min(lo, *r->inversion_time);
            hi = std::max(hi, *r->inversion_time);
            times.push_back(choice(*r) + " " + fmt("%.5g", *r->inversion_time));
          } else if (r->status == "ok") {
            kinds.insert(1);
            what = "does not invert";
          } else {
            kinds.insert(2);
            what = r->status + " at " + fmt("%.4g", r->status_time);
          }
          outcomes.push_back(choice(*r) + ": " + what + (agrees_with_reference_regime(*r) ? " (the reference's regime)" : ""));
        }
        if (kinds.size() > 1) {
          if (!e.regime_moves) {
            e.regime_at = step_text[k];
            e.regime_outcomes = outcomes;
          }
          e.regime_moves = true;
          ++e.regime_steps;
        }
        if (times.size() >= 2 && lo > 0) {
          const double spread = (hi - lo) / lo;
          if (!e.largest_spread || spread > *e.largest_spread) {
            e.largest_spread = spread;
            e.spread_at = step_text[k];
            e.spread_times = times;
          }
        }
      }
      out.push_back(e);
    }
  return out;
}

std::string render_sweep_markdown(const std::vector<SweepRecord>& records) {
  return render_md(build_doc(records, {}, ""));
}

void write_sweep_report(const std::string& dir, const std::vector<SweepRecord>& records, bool plots) {
  std::vector<std::string> images;
  std::string note;
  if (plots) {
    std::vector<Chart> charts;
    for (const SceneGroup& s : group(records)) {
      const auto c = make_charts(s);
      charts.insert(charts.end(), c.begin(), c.end());
    }
    images = render_charts(dir, charts, note);
  } else {
    note = "plots skipped (--no-plots)";
  }
  const std::vector<Block> doc = build_doc(records, images, note);
  write_file_atomic((fs::path(dir) / "report.md").string(), render_md(doc));
  write_file_atomic((fs::path(dir) / "index.html").string(), render_page(doc, "tippe: work-precision sweep"));
}

}  // namespace tippe
