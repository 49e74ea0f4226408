// The comparison report's plots: decimated series and engine-minus-reference differences into plot-N.dat, one gnuplot script, the SVGs.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <map>
#include <utility>

#include "harness/measure/compare.h"
#include "harness/records/records.h"
#include "harness/report/gnuplot.h"
#include "harness/report/report.h"
#include "harness/report/report_text.h"

namespace tippe {

namespace {

namespace fs = std::filesystem;
using nlohmann::json;
using namespace report_text;

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
  std::string title, engine;
  bool reference = false;
  std::string file;  // plot-N.dat: numbered, so that no name read from a record becomes a path
  std::map<std::string, int> block;  // quantity -> gnuplot index; absent: no finite point
};

// The reference's column at time t, linearly interpolated between its samples; NaN outside them.
double interpolate(const std::vector<double>& t, const std::vector<double>& y, double at) {
  if (t.empty() || at < t.front() || at > t.back()) return std::nan("");
  const auto it = std::lower_bound(t.begin(), t.end(), at);
  const size_t i = static_cast<size_t>(it - t.begin());
  if (t[i] == at || i == 0) return y[i];
  const double w = (at - t[i - 1]) / (t[i] - t[i - 1]);
  return y[i - 1] + w * (y[i] - y[i - 1]);
}

void drop_last_sample(Trajectory& tr) {
  for (auto* col : {&tr.t, &tr.theta, &tr.energy, &tr.jellett, &tr.normal_force, &tr.x_C, &tr.y_C}) col->pop_back();
  if (!tr.surface.empty()) tr.surface.pop_back();
}

// The floor contact path over R, with a blank line (gnuplot starts a new segment) wherever the
// contact surface changes between kept samples: a switch from the ball to the stem moves the
// contact point by a stem's length, which a joined line would draw as a path it never took.
std::string path_block(const Trajectory& tr, double R) {
  const size_t n = tr.x_C.size();
  const size_t stride = std::max<size_t>(1, n / 1000);
  const bool has_surface = tr.surface.size() == n;
  std::string block;
  long long last_surface = -1;
  bool any = false;
  for (size_t i = 0; i < n; ++i) {
    const bool switch_here = has_surface && i > 0 && tr.surface[i] != tr.surface[i - 1];
    if (i % stride != 0 && i != n - 1 && !switch_here) continue;
    if (!std::isfinite(tr.x_C[i]) || !std::isfinite(tr.y_C[i])) continue;
    if (has_surface && any && tr.surface[i] != last_surface) block += "\n";
    char line[96];
    std::snprintf(line, sizeof line, "%.9g %.9g\n", tr.x_C[i] / R, tr.y_C[i] / R);
    block += line;
    any = true;
    if (has_surface) last_surface = tr.surface[i];
  }
  return block;
}

// Differences below this are the rounding of equal states (two runs from the same initial
// state differ by ~1e-16 at t = 0); on a log axis they would stretch it by ten decades.
constexpr double kDifferenceFloor = 1e-13;

std::string xy_block(const std::vector<double>& x, const std::vector<double>& y, bool difference) {
  std::string block;
  for (size_t i : decimate_minmax(y, 400)) {
    if (!std::isfinite(x[i]) || !std::isfinite(y[i]) || (difference && !(y[i] > kDifferenceFloor))) continue;
    char line[96];
    std::snprintf(line, sizeof line, "%.9g %.9g\n", x[i], y[i]);
    block += line;
  }
  return block;
}

// Writes one run's decimated series as gnuplot data blocks; an engine's also its absolute
// difference from the reference (interpolated to the engine's sample times).
void write_plot_data(const fs::path& dir, Series& series, Trajectory tr, const json& summary, const json& scene,
                     const Trajectory* reference, double ref_E0) {
  // The sample that ends a run early may carry the blown-up state; it would flatten every axis.
  if (str(summary, "status") != "ok" && tr.size() > 1) drop_last_sample(tr);
  const double E0 = tr.size() ? tr.energy.front() : 1.0;
  const double J0 = tr.size() ? tr.jellett.front() : 1.0;
  const double Mg = num(scene.at("mass_properties"), "mass") * num(scene, "gravity");
  const double R = scene.contains("body") && has_number(scene.at("body"), "sphere_radius")
                       ? num(scene.at("body"), "sphere_radius") : 1.0;
  auto scaled = [](const std::vector<double>& v, double by) {
    std::vector<double> out(v);
    if (std::isfinite(by) && by != 0.0)
      for (double& x : out) x /= by;
    return out;
  };
  std::vector<std::pair<std::string, std::string>> blocks = {
      {"theta", xy_block(tr.t, tr.theta, false)},
      {"energy", xy_block(tr.t, scaled(tr.energy, std::abs(E0) > 0 ? E0 : 1.0), false)},
      {"path", path_block(tr, R > 0 ? R : 1.0)},
      {"jellett", xy_block(tr.t, scaled(tr.jellett, std::abs(J0) > 1e-300 ? J0 : 1.0), false)},
      {"normal_force", xy_block(tr.t, scaled(tr.normal_force, Mg), false)},
  };
  if (reference) {
    std::vector<double> d_theta(tr.size()), d_energy(tr.size());
    const double e0 = std::isfinite(ref_E0) && ref_E0 != 0 ? std::abs(ref_E0) : 1.0;
    for (size_t i = 0; i < tr.size(); ++i) {
      d_theta[i] = std::abs(tr.theta[i] - interpolate(reference->t, reference->theta, tr.t[i]));
      d_energy[i] = std::abs(tr.energy[i] - interpolate(reference->t, reference->energy, tr.t[i])) / e0;
    }
    blocks.push_back({"theta_diff", xy_block(tr.t, d_theta, true)});
    blocks.push_back({"energy_diff", xy_block(tr.t, d_energy, true)});
  }
  // Each block opens with its title, read by plots.gp as `title columnheader(1)`: the script
  // itself never holds a name read from a record.
  std::string text = "# decimated series for plots.gp, one block per quantity\n";
  int index = 0;
  for (const auto& [name, block] : blocks) {
    if (block.empty()) continue;
    text += "# " + name + "\n" + gp_column_header(series.title) + "\n" + block + "\n\n";
    series.block[name] = index++;
  }
  write_file_atomic((dir / series.file).string(), text);
}

struct PlotSpec {
  std::string file, quantity, title, ylabel;
  bool logy = false, path = false;
};

// The plots in page order. Labels with units are filled in per scene (plot_figures).
const std::vector<PlotSpec>& plot_specs() {
  static const std::vector<PlotSpec> specs = {
      {"theta.svg", "theta", "tilt θ(t)", "θ (rad)"},
      {"theta_error.svg", "theta_diff", "|θ - θ_ref| (reference interpolated to each engine sample time)",
       "|θ - θ_ref| (rad)", true},
      {"energy.svg", "energy", "energy E(t)/E0", "E / E0 (dimensionless)"},
      {"energy_error.svg", "energy_diff", "|E - E_ref| / E0_ref (reference interpolated to each engine sample time)",
       "|E - E_ref| / E0_ref (dimensionless)", true},
      {"contact_path.svg", "path", "floor contact path (breaks at ball/stem switches)", "", false, true},
      {"jellett.svg", "jellett", "Jellett integral J(t)/J0", "J / J0 (dimensionless)"},
      {"normal_force.svg", "normal_force", "normal force F_n(t)/(M g)", "F_n / (M g) (dimensionless)"},
  };
  return specs;
}

std::vector<GpFigure> plot_figures(const std::vector<Series>& series, const json& comparison) {
  const json& ref = comparison.at("reference").at("summary");
  const SceneUnits u = scene_units(comparison.at("scene"));
  std::vector<GpFigure> figures;
  for (const PlotSpec& p : plot_specs()) {
    GpFigure f;
    f.output = p.file;
    f.title = p.title;
    f.logy = p.logy;
    if (p.path) {
      f.xlabel = "x_C / R (dimensionless; R the ball radius)";
      f.ylabel = "y_C / R (dimensionless)";
      f.equal_axes = true;
    } else {
      f.xlabel = "t (" + u.time + ")";
      f.ylabel = p.ylabel;
      if (has_number(ref, "inversion_time")) f.xmark = num(ref, "inversion_time");
    }
    for (const Series& sr : series) {
      auto it = sr.block.find(p.quantity);
      if (it == sr.block.end()) continue;
      GpSeries s;
      s.data_file = sr.file;
      s.index = it->second;
      s.colour = sr.reference ? "#000000" : engine_colour(sr.engine);
      s.line_width = sr.reference ? 3.5 : 1.5;
      s.point_type = sr.reference ? 0 : engine_point_type(sr.engine);
      s.point_every = p.path ? 60 : 40;
      f.series.push_back(s);
    }
    figures.push_back(f);
  }
  return figures;
}

}  // namespace

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
      {"theta_error.svg",
       "|θ_engine - θ_reference| on a log axis: the reference's tilt is linearly interpolated to each engine's sample "
       "times (within the reference's run); differences below 1e-13 (rounding, e.g. at t = 0) are left out."},
      {"energy.svg", "Energy E(t) divided by each run's initial energy E0."},
      {"energy_error.svg",
       "|E_engine - E_reference| / E0 of the reference on a log axis, the reference interpolated linearly to each "
       "engine's sample times; differences below 1e-13 are left out."},
      {"contact_path.svg",
       "Path of the geometric floor contact point (x_C, y_C) / R, equal axes; the line breaks where the contact "
       "switches between the ball and the stem."},
      {"jellett.svg", "Jellett's integral J(t) divided by each run's initial J0 (conserved on one contact surface)."},
      {"normal_force.svg", "Normal force F_n(t) in units of the weight M g (decimated: extremes kept)."},
  };
  auto it = captions.find(file);
  return it != captions.end() ? it->second : file;
}

PlotSet render_plots(const std::string& out_dir, const json& c) {
  PlotSet result;
  const fs::path dir(out_dir);
  std::error_code ec;
  // Plots an earlier run made and this one cannot remake (no gnuplot, no trajectories: published
  // reports keep the SVGs and not the CSVs) stay and are still shown.
  auto keep_existing = [&](const std::string& why) {
    for (const auto& f : plot_file_names())
      if (fs::exists(dir / f, ec) && fs::file_size(dir / f, ec) > 0) result.files.push_back(f);
    result.note = why + (result.files.empty() ? "" : "; the plots shown are kept from an earlier run that had them");
    return result;
  };
  std::string why;
  const std::string gnuplot = gnuplot_command(&why);
  if (gnuplot.empty()) return keep_existing(why);
  std::vector<Series> series;
  std::vector<std::string> missing;
  const json& ref = c.at("reference").at("summary");
  std::optional<Trajectory> ref_tr;
  double ref_E0 = std::nan("");
  auto add = [&](const std::string& name, const std::string& engine, const json& summary, bool reference) {
    const fs::path csv = dir / (name + ".csv");
    Series s;
    s.engine = engine;
    s.reference = reference;
    s.title = reference ? "reference (" + engine + ")" : engine;
    s.file = "plot-" + std::to_string(series.size() + missing.size()) + ".dat";
    try {
      Trajectory tr = Trajectory::from_csv(read_trajectory_csv(csv.string()));
      if (reference) {
        ref_tr = tr;
        if (tr.size()) ref_E0 = tr.energy.front();
      }
      write_plot_data(dir, s, tr, summary, c.at("scene"), reference || !ref_tr ? nullptr : &*ref_tr, ref_E0);
      series.push_back(s);
    } catch (const std::exception&) {
      missing.push_back(name + ".csv");
    }
  };
  add("reference", str(ref, "engine"), ref, true);
  for (const json& e : c.at("engines")) add(str(e, "engine"), str(e, "engine"), e.at("summary"), false);
  std::string missing_text;
  for (const auto& m : missing) missing_text += (missing_text.empty() ? "" : ", ") + m;
  if (series.empty())
    return keep_existing("plots not remade here: this directory holds no trajectory (" + missing_text +
                         "), from which they are drawn");

  GpPage page;
  page.comment = "Plots of the comparison in this directory (written by tippe; regenerate with `tippe report DIR`).";
  const std::vector<GpFigure> figures = plot_figures(series, c);
  // A plot this run has no data for (an engine that matches the reference exactly has no
  // difference to draw) must not be shown from an earlier run's file.
  for (const GpFigure& f : figures)
    if (f.series.empty()) fs::remove(dir / f.output, ec);
  write_file_atomic((dir / "plots.gp").string(), gnuplot_script(page, figures));
  const int code = run_gnuplot(gnuplot, dir, "plots.gp", "plots.log");
  if (code != 0)
    return keep_existing(code == 127 ? "plots skipped: gnuplot not found (" + gnuplot + ")"
                                     : "plots failed: gnuplot exited with status " + std::to_string(code) +
                                           " (see plots.log)");
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

}  // namespace tippe
