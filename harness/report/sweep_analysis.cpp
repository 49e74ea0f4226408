// Analysis of sweep records (convergence orders, cheapest settings, regimes, modelling choices), pure functions the report and gates read.

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

#include "engines/core/registry.h"
#include "harness/measure/metrics.h"
#include "harness/records/records.h"
#include "harness/report/sweep_analysis.h"
#include "harness/report/sweep_groups.h"
#include "harness/sweep/sweep_search.h"

namespace tippe {

namespace {

namespace fs = std::filesystem;

constexpr double kInf = std::numeric_limits<double>::infinity();


}  // namespace

// ---- analysis ---------------------------------------------------------------------------------

ConvergenceFit convergence_order(const std::vector<double>& h, const std::vector<double>& error) {
  ConvergenceFit fit;
  std::vector<size_t> pts;
  for (size_t i = 0; i < h.size() && i < error.size(); ++i)
    if (sweep_report_detail::usable(h[i]) && sweep_report_detail::usable(error[i])) pts.push_back(i);
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

long long cheapest_safe(const std::vector<SweepRecord>& records, const SearchCriterion& c) {
  long long best = -1;
  for (size_t i = 0; i < records.size(); ++i) {
    const SweepRecord& r = records[i];
    if (!is_safe(c, r) || !std::isfinite(r.cpu_seconds)) continue;
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

std::vector<size_t> cost_ties(const std::vector<SweepRecord>& records, long long best, const SearchCriterion& c) {
  std::vector<size_t> ties;
  if (best < 0) return ties;
  const double cheapest = records[static_cast<size_t>(best)].cpu_seconds;
  for (size_t i = 0; i < records.size(); ++i)
    if (static_cast<long long>(i) != best && is_safe(c, records[i]) && std::isfinite(records[i].cpu_seconds) &&
        within_cost_resolution(records[i].cpu_seconds, cheapest))
      ties.push_back(i);
  std::stable_sort(ties.begin(), ties.end(),
                   [&](size_t a, size_t b) { return records[a].cpu_seconds < records[b].cpu_seconds; });
  return ties;
}

SearchCriterion setting_criterion(bool reference_inverts, double tolerance) {
  SearchCriterion c;
  c.regime = true;
  if (reference_inverts) c.inversion = tolerance;
  return c;
}

long long cheapest_below(const std::vector<SweepRecord>& records, double threshold) {
  return cheapest_safe(records, setting_criterion(true, threshold));
}

long long cheapest_at_least_as_accurate(const std::vector<SweepRecord>& records, double error) {
  return cheapest_where(records, [error](double e) { return e <= error; });
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
    if (!is_safe(setting_criterion(false, 0), records[i])) break;
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

namespace sweep_report_detail {

std::vector<Line> lines_of(const SetupGroup& u) {
  std::vector<Line> out;
  for (const SweepRecord& r : u.points) {
    const std::string title = u.grid_key.empty() ? u.name : u.name + " " + last_part(u.grid_key) + "=" + grid_text(r);
    if (out.empty() || out.back().title != title) out.push_back({title, {}});
    out.back().points.push_back(r);
  }
  return out;
}
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
}  // namespace sweep_report_detail

using namespace sweep_report_detail;


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

std::string energy_gain_rules_text(const std::vector<SweepRecord>& records) {
  std::set<std::string> rules;
  for (const SweepRecord& r : records) rules.insert(r.metrics.energy_gain_rule.empty() ? "total" : r.metrics.energy_gain_rule);
  const std::vector<std::string>& names = energy_gain_rule_names();
  if (rules.size() == 1) {
    const auto it = std::find(names.begin(), names.end(), *rules.begin());
    if (it != names.end())
      return "counting " + energy_counted_text(static_cast<EnergyGainRule>(it - names.begin())) +
             " (energy_gain_rule = " + *it + ")";
  }
  std::string t;
  for (const std::string& n : rules) t += (t.empty() ? "" : ", ") + n;
  return "counting energy by each record's energy_gain_rule (" + t + ")";
}

}  // namespace tippe
