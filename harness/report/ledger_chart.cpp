// The energy ledger as a chart: one stacked bar per run (the reference's first), each term of its account / |E0|.
#include "harness/report/ledger_chart.h"

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "harness/io/text.h"
#include "harness/report/ledger_terms.h"
#include "harness/report/report_text.h"

namespace tippe {

namespace {

using nlohmann::json;
using namespace report_text;

struct Bar {
  std::string name;
  std::vector<std::pair<const LedgerTerm*, double>> parts;  // value / |E0|, signed as in E_final - E0
  double total = std::nan("");                               // (E_final - E0) / |E0|
};

Bar bar_of(const std::string& name, const json& s) {
  Bar b;
  b.name = name;
  const double e0 = num(s, "energy_initial");
  const double scale = ledger_scale(s);
  for (const LedgerTerm& t : ledger_terms())
    if (has_number(s, t.key)) b.parts.push_back({&t, t.sign * num(s, t.key) / scale});
  b.total = (num(s, "energy_final") - e0) / scale;
  return b;
}

// A tick spacing of 1, 2 or 5 times a power of ten giving about `n` intervals over `span`.
double nice_step(double span, int n) {
  const double raw = span / n;
  const double p = std::pow(10.0, std::floor(std::log10(raw)));
  for (const double m : {1.0, 2.0, 5.0})
    if (m * p >= raw) return m * p;
  return 10.0 * p;
}

std::string num_text(double v) { return fmt(v, "%.2f"); }

}  // namespace

std::string ledger_chart_svg(const json& c) {
  std::vector<Bar> bars;
  const json& ref = c.at("reference").at("summary");
  if (has_ledger(ref)) bars.push_back(bar_of("reference", ref));
  for (const json& e : c.at("engines"))
    if (e.contains("summary") && has_ledger(e.at("summary"))) bars.push_back(bar_of(str(e, "engine"), e.at("summary")));
  if (bars.empty()) return {};

  // The axis spans every bar's losses and gains, and the totals.
  double lo = 0.0, hi = 0.0;
  for (const Bar& b : bars) {
    double neg = 0.0, pos = 0.0;
    for (const auto& [t, v] : b.parts) (v < 0 ? neg : pos) += v;
    lo = std::min({lo, neg, std::isfinite(b.total) ? b.total : 0.0});
    hi = std::max({hi, pos, std::isfinite(b.total) ? b.total : 0.0});
  }
  if (hi - lo <= 0) hi = lo + 1e-12;
  const double step = nice_step(hi - lo, 5);
  lo = std::floor(lo / step - 1e-9) * step;
  hi = std::ceil(hi / step + 1e-9) * step;

  const int width = 960, left = 120, right = 30, top = 44, row = 30, bar_h = 18;
  const int plot_w = width - left - right;
  const int plot_bottom = top + row * static_cast<int>(bars.size());
  const int height = plot_bottom + 78;
  auto x_of = [&](double v) { return left + (v - lo) / (hi - lo) * plot_w; };

  std::string s;
  s += "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" + std::to_string(width) + "\" height=\"" +
       std::to_string(height) + "\" viewBox=\"0 0 " + std::to_string(width) + " " + std::to_string(height) +
       "\" font-family=\"sans-serif\" font-size=\"13\">\n";
  s += "<title>Energy ledger: each run's E_final - E0 split into its terms, / |E0|</title>\n";
  s += "<rect width=\"100%\" height=\"100%\" fill=\"#ffffff\"/>\n";
  s += "<text x=\"" + std::to_string(left) + "\" y=\"22\" font-size=\"15\">Where each run's energy went (/ |E0|; "
       "losses left of 0, gains right; black tick: E_final - E0)</text>\n";
  // Grid and axis labels.
  for (double v = lo; v <= hi + step * 1e-6; v += step) {
    const double x = x_of(std::abs(v) < step * 1e-9 ? 0.0 : v);
    s += "<line x1=\"" + num_text(x) + "\" y1=\"" + std::to_string(top - 6) + "\" x2=\"" + num_text(x) + "\" y2=\"" +
         std::to_string(plot_bottom) + "\" stroke=\"" + (std::abs(v) < step * 1e-9 ? "#000000" : "#dddddd") + "\"/>\n";
    s += "<text x=\"" + num_text(x) + "\" y=\"" + std::to_string(plot_bottom + 16) + "\" text-anchor=\"middle\">" +
         fmt(std::abs(v) < step * 1e-9 ? 0.0 : v, "%.3g") + "</text>\n";
  }
  for (size_t i = 0; i < bars.size(); ++i) {
    const Bar& b = bars[i];
    const int y = top + row * static_cast<int>(i) + (row - bar_h) / 2;
    s += "<text x=\"" + std::to_string(left - 8) + "\" y=\"" + std::to_string(y + bar_h - 4) +
         "\" text-anchor=\"end\">" + markup_escape(b.name) + "</text>\n";
    double neg = 0.0, pos = 0.0;
    for (const auto& [t, v] : b.parts) {
      if (v == 0 || !std::isfinite(v)) continue;
      const double from = v < 0 ? neg + v : pos, to = v < 0 ? neg : pos + v;
      (v < 0 ? neg : pos) += v;
      s += "<rect class=\"term\" data-term=\"" + std::string(t->key) + "\" data-value=\"" + fmt(v, "%.6g") + "\" x=\"" +
           num_text(x_of(from)) + "\" y=\"" + std::to_string(y) + "\" width=\"" + num_text(x_of(to) - x_of(from)) +
           "\" height=\"" + std::to_string(bar_h) + "\" fill=\"" + t->colour + "\"><title>" + markup_escape(b.name) + ": " +
           t->label + " " + fmt(v, "%.3g") + " E0</title></rect>\n";
    }
    if (std::isfinite(b.total)) {
      const double x = x_of(b.total);
      s += "<line class=\"total\" data-value=\"" + fmt(b.total, "%.6g") + "\" x1=\"" + num_text(x) + "\" y1=\"" +
           std::to_string(y - 3) + "\" x2=\"" + num_text(x) + "\" y2=\"" + std::to_string(y + bar_h + 3) +
           "\" stroke=\"#000000\" stroke-width=\"2\"/>\n";
    }
  }
  // Legend.
  int lx = left;
  const int ly = plot_bottom + 40;
  for (const LedgerTerm& t : ledger_terms()) {
    s += "<rect x=\"" + std::to_string(lx) + "\" y=\"" + std::to_string(ly) + "\" width=\"14\" height=\"14\" fill=\"" +
         t.colour + "\"/><text x=\"" + std::to_string(lx + 20) + "\" y=\"" + std::to_string(ly + 12) + "\">" + t.label +
         "</text>\n";
    lx += 40 + 8 * static_cast<int>(std::string(t.label).size());
  }
  s += "</svg>\n";
  return s;
}

}  // namespace tippe
