// The sweep report's charts: work-precision (error against CPU seconds) and regime charts per scene, through the one gnuplot writer.
#include <algorithm>
#include <cmath>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "harness/records/records.h"
#include "engines/core/registry.h"
#include "harness/report/gnuplot.h"
#include "harness/report/sweep_groups.h"

namespace tippe::sweep_report_detail {

namespace {

namespace fs = std::filesystem;


struct MetricInfo {
  const char* key;
  const char* label;
  std::optional<double> (*get)(const SweepRecord&);
};
const std::vector<MetricInfo>& metric_infos() {
  static const std::vector<MetricInfo> m = {
      {"inversion_time_rel_error", "|relative error of the inversion time| (dimensionless)",
       [](const SweepRecord& r) { return r.metrics.inversion_time_rel_error; }},
      {"stem_contact_time_rel_error", "|relative error of the first stem contact time| (dimensionless)",
       [](const SweepRecord& r) { return r.metrics.stem_contact_time_rel_error; }},
      {"tilt_rms_error", "RMS tilt error (rad)",
       [](const SweepRecord& r) { return std::optional<double>(r.metrics.tilt_rms_error); }},
      {"energy_max_error", "max |E - E_ref| / E0 (dimensionless)",
       [](const SweepRecord& r) { return std::optional<double>(r.metrics.energy_max_error); }},
      {"contact_path_rms_error", "RMS floor contact path error / R (dimensionless)",
       [](const SweepRecord& r) { return std::optional<double>(r.metrics.contact_path_rms_error); }},
  };
  return m;
}

// One series of a chart: a setup's points as (x, y), in ladder order.
struct ChartSeries {
  std::string title, engine;
  int variant = 0;  // how many earlier setups of the same engine: picks dash and point type
  std::vector<std::pair<double, double>> xy;
};
struct Chart {
  std::string file, title, caption, ylabel;
  bool logy = true;
  std::optional<double> hline;  // regime charts: the end of the run
  std::vector<ChartSeries> series;
};

// One series per line (a setup, or a grid value of it), with the lines' points beside it.
std::vector<ChartSeries> setup_series(const SceneGroup& s, std::vector<std::vector<SweepRecord>>& points) {
  std::vector<ChartSeries> out;
  std::map<std::string, int> per_engine;
  points.clear();
  for (const SetupGroup& u : s.setups)
    for (Line& l : lines_of(u)) {
      out.push_back({l.title, u.engine, per_engine[u.engine]++, {}});
      points.push_back(std::move(l.points));
    }
  return out;
}

std::vector<Chart> make_charts(const SceneGroup& s, size_t scene) {
  std::vector<Chart> charts;
  const std::string tag = "s" + std::to_string(scene + 1);
  for (const MetricInfo& m : metric_infos()) {
    Chart c;
    c.file = "wp-" + tag + "-" + m.key + ".svg";
    c.ylabel = m.label;
    c.title = std::string(m.key) + " against cost";
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
    c.file = "regime-" + tag + ".svg";
    c.ylabel = "inversion time (scene time unit; on the dashed line: none)";
    c.title = "regime of every point (the reference does not invert)";
    c.caption = s.name +
                ": the reference does not invert. Inversion time of every point against CPU seconds; points "
                "on the dashed line (the end of the run) did not invert, crosses mark runs that ended early "
                "(at their status time).";
    c.logy = false;
    c.hline = s.duration;
    std::vector<std::vector<SweepRecord>> points;
    c.series = setup_series(s, points);
    ChartSeries early{"ended early", "", 0, {}};
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

}  // namespace

std::vector<ChartFile> chart_files(const SceneGroup& s, size_t scene) {
  std::vector<ChartFile> out;
  for (const Chart& c : make_charts(s, scene)) out.push_back({c.file, c.caption});
  return out;
}

std::vector<std::string> render_sweep_charts(const fs::path& dir, const std::vector<SceneGroup>& scenes,
                                             std::string& note) {
  std::vector<std::string> made;
  std::string why;
  const std::string gnuplot = gnuplot_command(&why);
  if (gnuplot.empty()) {
    note = why;
    return made;
  }
  // Charts of an earlier report (other scenes, or names of an older version) would be left
  // beside the new ones and copied with them: every chart comes from the records, so all go.
  std::error_code ec;
  for (const auto& entry : fs::directory_iterator(dir, ec)) {
    const std::string name = entry.path().filename().string();
    const auto ends = [&](const std::string& tail) {
      return name.size() >= tail.size() && name.compare(name.size() - tail.size(), tail.size(), tail) == 0;
    };
    if ((name.rfind("wp-", 0) == 0 || name.rfind("regime-", 0) == 0) && ends(".svg")) fs::remove(entry.path(), ec);
    else if (name.rfind("sweep-", 0) == 0 && ends(".dat")) fs::remove(entry.path(), ec);
  }
  std::vector<Chart> charts;
  for (size_t k = 0; k < scenes.size(); ++k) {
    const auto c = make_charts(scenes[k], k);
    charts.insert(charts.end(), c.begin(), c.end());
  }
  std::vector<GpFigure> figures;
  std::vector<std::string> planned;
  for (const Chart& c : charts) {
    std::vector<const ChartSeries*> nonempty;
    for (const ChartSeries& s : c.series)
      if (!s.xy.empty()) nonempty.push_back(&s);
    if (nonempty.empty()) continue;
    const std::string dat = "sweep-" + c.file.substr(0, c.file.size() - 4) + ".dat";
    std::string d;
    GpFigure f;
    f.output = c.file;
    f.title = c.title;
    f.xlabel = "CPU seconds of the run (s; own thread, minimum over repeats)";
    f.ylabel = c.ylabel;
    f.logx = true;
    f.logy = c.logy;
    if (!c.logy) f.yrange = std::make_pair(0.0, 1.08 * c.hline.value_or(1.0));
    f.ymark = c.hline;
    for (size_t i = 0; i < nonempty.size(); ++i) {
      const ChartSeries& s = *nonempty[i];
      // The title is data (`title columnheader(1)`): no name reaches the script.
      d += gp_column_header(s.title) + "\n";
      for (const auto& [x, y] : s.xy) d += fmt("%.17g", x) + " " + fmt("%.17g", y) + "\n";
      d += "\n\n";
      GpSeries g;
      g.data_file = dat;
      g.index = static_cast<int>(i);
      if (s.engine.empty()) {
        g.points_only = true;
        g.point_type = 2;
        g.colour = "#000000";
      } else {
        const bool reference = s.engine == reference_engine().name;
        g.colour = engine_colour(s.engine);
        g.line_width = reference ? 2.5 : 1.5;
        g.dash = 1 + s.variant % 5;
        g.point_type = engine_point_type(s.engine);
      }
      f.series.push_back(g);
    }
    write_file_atomic((dir / dat).string(), d);
    figures.push_back(f);
    planned.push_back(c.file);
  }
  if (planned.empty()) {
    note = "no chart: no point has a finite, non-zero error";
    return made;
  }
  GpPage page;
  page.comment = "Work-precision charts of a tippe sweep (written by tippe sweep; data in sweep-*.dat).";
  page.width = 900;
  page.font_size = 12;
  page.key = "outside right top";
  write_file_atomic((dir / "sweep-plots.gp").string(), gnuplot_script(page, figures));
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

}  // namespace tippe::sweep_report_detail
