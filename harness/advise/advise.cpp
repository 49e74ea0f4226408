// `tippe advise`: each engine's configurations from the registry, a boundary search of the cost knob in each, the cheapest confirmed one, and its gate.
#include "harness/advise/advise.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <map>
#include <stdexcept>

#include "harness/advise/advice_record.h"
#include "harness/gating/gate.h"
#include "harness/io/files.h"
#include "harness/io/scene_io.h"
#include "harness/scene/resolve.h"
#include "harness/io/text.h"
#include "harness/measure/classify.h"
#include "harness/measure/metrics.h"
#include "engines/core/registry.h"
#include "harness/report/document.h"
#include "harness/report/sweep_analysis.h"
#include "harness/sweep/sweep.h"

namespace tippe {

namespace {

namespace fs = std::filesystem;

std::string sig3(double v) {
  char buf[40];
  std::snprintf(buf, sizeof buf, "%.3g", v);
  return buf;
}

// A TOML basic string: quotes and backslashes escaped; a control character is refused (no path
// or value the bench writes has one, and TOML would need an escape the reader must undo).
std::string toml_string(const std::string& s) {
  std::string out = "\"";
  for (char c : s) {
    if (static_cast<unsigned char>(c) < 0x20) throw std::invalid_argument("a control character in \"" + s + "\"");
    if (c == '"' || c == '\\') out += '\\';
    out += c;
  }
  return out + "\"";
}

std::string join(const std::vector<std::string>& v, const char* sep) {
  std::string t;
  for (const std::string& x : v) t += (t.empty() ? "" : sep) + x;
  return t;
}

std::string unquote(const std::string& v) {
  return v.size() >= 2 && v.front() == '"' && v.back() == '"' ? v.substr(1, v.size() - 2) : v;
}

// A piece of a setup name: the value's letters, digits, '.', '_' and '-' (names are is_valid_name).
std::string name_piece(const std::string& v) {
  std::string out;
  for (char c : unquote(v)) out += (std::isalnum(static_cast<unsigned char>(c)) || c == '.' || c == '_' || c == '-') ? c : '_';
  return out.empty() ? "x" : out;
}

std::vector<std::string> split_commas(const std::string& s) {
  std::vector<std::string> out;
  size_t start = 0;
  for (;;) {
    const size_t at = s.find(',', start);
    out.push_back(trim(s.substr(start, at == std::string::npos ? std::string::npos : at - start)));
    if (at == std::string::npos) return out;
    start = at + 1;
  }
}

std::string knob_key(const std::string& engine, const std::string& knob) { return "engines." + engine + "." + knob; }

// The sweep file text of the searches (one setup per configuration) or of the confirming runs.
// `repeats`: the runs of each point (the confirming runs' cost; a search's points run once).
std::string sweep_text(const std::string& description, const std::string& scene_rel, std::optional<double> duration,
                       const std::vector<std::pair<AdviceConfig, std::string>>& setups, int repeats = 1) {
  std::string t = "# Written by `tippe advise` (" + description + "); resumable: `tippe sweep` runs it too.\n";
  t += "description = " + toml_string(description) + "\nrepeats = " + std::to_string(repeats) + "\n";
  t += "scenes = [ { file = " + toml_string(scene_rel) +
       (duration ? ", duration = " + search_value_text(*duration) : std::string()) + " } ]\n";
  for (const auto& [c, ladder] : setups) {
    t += "\n[[setup]]\nname = " + toml_string(c.setup) + "\nengine = " + toml_string(c.engine) + "\n";
    const std::vector<std::string> set = c.set();
    if (!set.empty()) {
      t += "set = [";
      for (size_t i = 0; i < set.size(); ++i) t += (i ? ", " : "") + toml_string(set[i]);
      t += "]\n";
    }
    t += ladder + "\n";
  }
  return t;
}

std::string search_ladder(const std::string& key, const AdviseOptions& o, const std::string& criterion) {
  return "ladder.search = { key = " + toml_string(key) + ", from = " + search_value_text(o.from) +
         ", to = " + search_value_text(o.to) + ", criterion = " + toml_string(criterion) +
         ", resolution = " + search_value_text(o.resolution) + " }";
}

// Runs a sweep file into a directory with the sweep machinery (resumable, --jobs), then reads
// its records back; `runs` grows by its points times the file's repeats.
std::vector<SweepRecord> run_sweep_file(const std::string& file, const std::string& dir, const AdviseOptions& o,
                                        size_t& runs, bool report) {
  SweepOptions so;
  so.out_dir = dir;
  so.jobs = o.jobs;
  so.restart = o.restart;
  so.progress = o.progress;
  const bool plots = o.plots;
  if (report)
    so.write_report = [plots](const std::string& d, const std::vector<SweepRecord>& r) { write_sweep_report(d, r, plots); };
  const SweepPlan plan = load_sweep(file);
  const SweepOutcome out = run_search_sweep(plan, so);
  runs += out.points * static_cast<size_t>(plan.spec.repeats);
  return read_records((fs::path(dir) / "records.jsonl").string()).records;
}

long long estimated_runs(const AdviseOptions& o) {
  SweepSearch s;
  s.from = o.from;
  s.to = o.to;
  s.resolution = o.resolution;
  const size_t coarse = search_coarse_grid(s).size();
  // One crossing expected (a monotonic criterion): bisected from one coarse interval down to
  // the resolution.
  const double interval = std::log10(o.to / o.from) / std::max<double>(1, static_cast<double>(coarse) - 1);
  const long long bisect = static_cast<long long>(std::ceil(std::log2(std::max(1.0, interval / o.resolution))));
  return static_cast<long long>(coarse) + bisect;
}

}  // namespace

std::vector<std::string> AdviceConfig::set() const {
  std::vector<std::string> out;
  for (size_t i = 0; i < keys.size(); ++i) out.push_back(knob_key(engine, keys[i]) + "=" + values[i]);
  return out;
}

std::string AdviceConfig::text() const {
  std::string t;
  for (size_t i = 0; i < keys.size(); ++i) t += (i ? ", " : "") + keys[i] + " = " + unquote(values[i]);
  return t.empty() ? "its defaults" : t;
}

std::vector<AdviceConfig> advice_configs(const std::string& engine, const std::vector<std::string>& overrides) {
  std::vector<SettingAxis> axes = engine_info(engine).advice_axes;
  for (const std::string& o : overrides) {
    const size_t eq = o.find('='), dot = o.find('.');
    if (eq == std::string::npos || dot == std::string::npos || dot > eq)
      throw std::invalid_argument("--axis " + o + ": expected ENGINE.KEY=VALUE[,VALUE...]");
    if (o.substr(0, dot) != engine) continue;
    const std::string key = trim(o.substr(dot + 1, eq - dot - 1));
    const auto it = std::find_if(axes.begin(), axes.end(), [&](const SettingAxis& a) { return a.key == key; });
    if (it == axes.end()) {
      std::string known;
      for (const SettingAxis& a : axes) known += (known.empty() ? "" : ", ") + a.key;
      throw std::invalid_argument("--axis " + o + ": " + key + " is not an axis " + engine + " declares (" +
                                  (known.empty() ? "none" : known) + ")");
    }
    it->values = split_commas(o.substr(eq + 1));
    for (const std::string& v : it->values)
      if (v.empty()) throw std::invalid_argument("--axis " + o + ": an empty value");
  }
  std::vector<AdviceConfig> out;
  std::vector<size_t> idx(axes.size(), 0);
  for (;;) {
    AdviceConfig c;
    c.engine = engine;
    c.setup = engine;
    for (size_t a = 0; a < axes.size(); ++a) {
      c.keys.push_back(axes[a].key);
      c.values.push_back(axes[a].values[idx[a]]);
      c.setup += "-" + name_piece(axes[a].values[idx[a]]);
    }
    out.push_back(c);
    size_t a = axes.size();
    while (a > 0) {
      --a;
      if (++idx[a] < axes[a].values.size()) break;
      idx[a] = 0;
      if (a == 0) return out;
    }
    if (axes.empty()) return out;
  }
}

std::vector<std::string> advice_ties_text(const AdviceEngine& e) {
  std::vector<std::string> out;
  for (const AdviceEngine::Tie& x : e.ties)
    out.push_back(e.configs.at(x.config).text() + ", " + e.knob + " " + search_value_text(x.step) + " (" +
                  sig3(x.cpu_seconds) + " CPU s)");
  return out;
}

void choose_advice(AdviceEngine& e, const SearchCriterion& criterion, const std::vector<SweepRecord>& confirm) {
  e.chosen.reset();
  e.ties.clear();
  size_t safe_boundaries = 0;
  // The configurations with a safe boundary whose confirming run is safe, in order.
  std::vector<std::pair<size_t, const SweepRecord*>> confirmed;
  for (size_t i = 0; i < e.configs.size() && i < e.boundaries.size(); ++i) {
    const SearchBoundary& b = e.boundaries[i];
    if ((b.status != "found" && b.status != "all_safe") || !b.boundary) continue;
    ++safe_boundaries;
    const auto r = std::find_if(confirm.begin(), confirm.end(),
                                [&](const SweepRecord& x) { return x.setup == e.configs[i].setup; });
    if (r == confirm.end() || !is_safe(criterion, *r) || !std::isfinite(r->cpu_seconds)) continue;
    confirmed.emplace_back(i, &*r);
  }
  // The cheapest (the first of equals), then those the machine's noise could have chosen instead.
  const SweepRecord* best = nullptr;
  for (const auto& [i, r] : confirmed)
    if (!best || r->cpu_seconds < best->cpu_seconds) {
      e.chosen = i;
      best = r;
    }
  if (best) {
    const SearchBoundary& b = e.boundaries[*e.chosen];
    e.step = best->ladder_value;
    e.boundary = *b.boundary;
    e.beyond = b.beyond ? *b.beyond : 0;
    e.cpu_seconds = best->cpu_seconds;
    e.confirm_point = best->point_id;
    for (const auto& [i, r] : confirmed)
      if (i != *e.chosen && within_cost_resolution(r->cpu_seconds, best->cpu_seconds))
        e.ties.push_back({i, r->ladder_value, r->cpu_seconds});
    std::stable_sort(e.ties.begin(), e.ties.end(), [](const AdviceEngine::Tie& a, const AdviceEngine::Tie& b) {
      return a.cpu_seconds < b.cpu_seconds;
    });
  }
  if (!e.chosen) {
    if (e.configs.empty()) e.reason = "no configuration searched (the run budget, --max-runs, allows none)";
    else if (safe_boundaries == 0) {
      std::string why;
      for (const SearchBoundary& b : e.boundaries)
        if (b.status == "incomplete") why = " (a search did not finish)";
      e.reason = "no configuration is safe at any " + e.knob + " in the searched range, even the finest" + why;
    } else {
      e.reason = "the search found a safe " + e.knob + " but the confirming run at the boundary / " + sig3(kAdviceMargin) +
                 " was not safe: the criterion is not monotonic in the " + e.knob;
    }
  }
  // Sensitivity: per axis, the largest boundary among the configurations with each value.
  e.sensitivity.clear();
  e.sensitivity_rows.clear();
  if (e.configs.empty()) return;
  for (size_t a = 0; a < e.configs.front().keys.size(); ++a) {
    std::map<std::string, double> best_of;
    std::vector<std::string> order;
    for (size_t i = 0; i < e.configs.size() && i < e.boundaries.size(); ++i) {
      const std::string& v = e.configs[i].values[a];
      if (!best_of.count(v)) {
        best_of[v] = 0;
        order.push_back(v);
      }
      const SearchBoundary& b = e.boundaries[i];
      if ((b.status == "found" || b.status == "all_safe") && b.boundary) best_of[v] = std::max(best_of[v], *b.boundary);
    }
    double lo = INFINITY, hi = 0;
    for (const std::string& v : order) {
      lo = std::min(lo, best_of[v]);
      hi = std::max(hi, best_of[v]);
    }
    const std::string key = e.configs.front().keys[a];
    std::string sentence;
    if (order.size() < 2) sentence = key + " fixed at " + unquote(order.front());
    else if (hi == 0) sentence = key + ": no value gives a safe " + e.knob;
    else if (lo == 0) sentence = key + " decides whether any " + e.knob + " is safe";
    else if (hi / lo < std::pow(10.0, e.boundaries.front().search.resolution) + 1e-12)
      sentence = key + " moved the boundary not at all (within the search's resolution)";
    else sentence = key + " moved the boundary " + sig3(hi / lo) + "x";
    e.sensitivity.push_back(sentence);
    for (const std::string& v : order)
      e.sensitivity_rows.push_back({key, unquote(v), best_of[v] > 0 ? sig3(best_of[v]) : "none safe",
                                    best_of[v] > 0 && hi > 0 ? sig3(hi / best_of[v]) : "-"});
  }
}

AdviceResult run_advise(const AdviseOptions& o) {
  if (o.out.empty()) throw std::invalid_argument("--out DIR is required");
  if (!(o.from > 0 && o.to > o.from)) throw std::invalid_argument("the range needs 0 < --from < --to");
  if (o.max_runs < 1) throw std::invalid_argument("--max-runs must be at least 1");
  if (o.repeats < 1 || o.repeats > kMaxRepeats)
    throw std::invalid_argument("--repeats must be from 1 to " + std::to_string(kMaxRepeats));
  AdviceResult res;
  res.repeats = o.repeats;
  std::vector<std::string> over;
  if (o.duration) over.push_back("run.duration=" + search_value_text(*o.duration));
  const Scene scene = load_scene(o.scene, over);  // its own errors name the file and key
  res.scene_name = scene.name;
  res.duration = scene.run.duration;
  res.criterion = o.criterion.empty() ? "regime and inversion within " + sig3(100 * o.tolerance) + "%" : o.criterion;
  const SearchCriterion criterion = parse_criterion(res.criterion);
  res.criterion = criterion_text(criterion);

  std::vector<std::string> engines = o.engines;
  if (engines.empty())
    for (const std::string& n : engine_names())
      if (!engine_info(n).cost_knob.empty()) engines.push_back(n);
  const long long per_config = estimated_runs(o);
  long long budget = o.max_runs;
  std::vector<std::pair<AdviceConfig, std::string>> setups;
  for (const std::string& n : engines) {
    const EngineInfo& info = engine_info(n);
    if (info.role != EngineRole::Engine) throw std::invalid_argument("--engines: " + n + " is the reference, not an engine");
    if (info.cost_knob.empty()) throw std::invalid_argument("--engines: " + n + " declares no cost knob to search");
    AdviceEngine e;
    e.engine = n;
    e.knob = info.cost_knob;
    for (const AdviceConfig& c : advice_configs(n, o.axis_overrides)) {
      if (budget >= per_config) {
        budget -= per_config;
        e.configs.push_back(c);
        setups.push_back({c, search_ladder(knob_key(n, e.knob), o, res.criterion)});
      } else {
        e.unsearched.push_back(c);
      }
    }
    res.engines.push_back(e);
  }

  fs::create_directories(o.out);
  const fs::path out(o.out);
  const std::string scene_rel = fs::relative(fs::absolute(o.scene), fs::absolute(out)).generic_string();
  const std::string what = "the cheapest safe settings of each engine on " + scene.name;
  std::vector<SweepRecord> records;
  if (!setups.empty()) {
    write_file_atomic((out / "advise-sweep.toml").string(), sweep_text(what, scene_rel, o.duration, setups));
    records = run_sweep_file((out / "advise-sweep.toml").string(), (out / "sweep").string(), o, res.runs, true);
  }
  const std::vector<SearchBoundary> all = search_boundaries(records);
  std::vector<std::pair<AdviceConfig, std::string>> confirm_setups;
  for (AdviceEngine& e : res.engines)
    for (const AdviceConfig& c : e.configs) {
      const auto b = std::find_if(all.begin(), all.end(), [&](const SearchBoundary& x) { return x.setup == c.setup; });
      e.boundaries.push_back(b != all.end() ? *b : SearchBoundary{});
      if (b != all.end() && (b->status == "found" || b->status == "all_safe") && b->boundary)
        confirm_setups.push_back({c, "ladder.key = " + toml_string(knob_key(e.engine, e.knob)) + "\nladder.values = [" +
                                         search_value_text(search_round(*b->boundary / kAdviceMargin)) + "]"});
    }
  for (const SweepRecord& r : records)
    if (r.reference_inversion_time) res.reference_inversion = r.reference_inversion_time;
  res.reference_inverts = res.reference_inversion.has_value();
  std::vector<SweepRecord> confirm;
  if (!confirm_setups.empty()) {
    write_file_atomic((out / "confirm-sweep.toml").string(),
                      sweep_text("confirming runs of " + what + " at the boundary / " + sig3(kAdviceMargin), scene_rel,
                                 o.duration, confirm_setups, o.repeats));
    confirm = run_sweep_file((out / "confirm-sweep.toml").string(), (out / "confirm").string(), o, res.runs, false);
  }
  for (AdviceEngine& e : res.engines) choose_advice(e, criterion, confirm);

  // The gate: each advised configuration pinned at its step, and its search's boundary bounded.
  std::string gate, gate_sweep;
  std::vector<std::pair<AdviceConfig, std::string>> gate_setups;
  for (const AdviceEngine& e : res.engines) {
    if (!e.chosen) continue;
    const AdviceConfig& c = e.configs[*e.chosen];
    gate_setups.push_back({c, search_ladder(knob_key(e.engine, e.knob), o, res.criterion)});
    std::vector<std::string> set = c.set();
    set.push_back(knob_key(e.engine, e.knob) + "=" + search_value_text(e.step));
    gate += "\n# " + e.engine + ": " + c.text() + ", " + e.knob + " " + search_value_text(e.step) + " (the boundary " +
            search_value_text(e.boundary) + " / " + sig3(kAdviceMargin) + "; " + sig3(e.cpu_seconds) + " CPU s).\n";
    gate += "[[check]]\nname = " + toml_string(e.engine + "-advised") + "\nscene = " + toml_string(scene_rel) +
            "\nengine = " + toml_string(e.engine) + "\nduration = " + search_value_text(res.duration) + "\nset = [";
    for (size_t i = 0; i < set.size(); ++i) gate += (i ? ", " : "") + toml_string(set[i]);
    gate += "]\n";
    // The criterion as the check's rows: the same measurement as is_safe on a record (the
    // reference's regime: the same events, where it does not invert; the inversion's error where
    // it does; no net energy gain, the class's rule, where the law dissipates).
    if (criterion.regime && !res.reference_inverts) gate += "require_same_events = true\n";
    std::string max;
    if ((criterion.inversion || criterion.regime) && res.reference_inverts)
      max += "inversion_time_rel_error = " + search_value_text(criterion.inversion ? *criterion.inversion : 10.0) + "\n";
    if (energy_must_not_rise(scene)) max += "energy_gain_events = 0\n";
    for (const Threshold& t : criterion.bounds) max += t.metric + " = " + search_value_text(t.max) + "\n";
    if (!max.empty()) gate += "[check.max]\n" + max;
    gate += "\n[[boundary]]\nname = " + toml_string(e.engine + "-boundary") + "\nsweep = \"gate-sweep.toml\"\nsetup = " +
            toml_string(c.setup) + "\nrequire = " +
            toml_string("max_safe_" + e.knob + " >= " + search_value_text(e.step)) + "\n";
  }
  if (!gate_setups.empty()) {
    write_file_atomic((out / "gate-sweep.toml").string(),
                      sweep_text("the boundary searches of the advised settings on " + scene.name, scene_rel, o.duration,
                                 gate_setups));
    const std::string head =
        "# Written by `tippe advise` for " + scene.name + " (criterion: " + res.criterion +
        "): `tippe gate advice.toml` passes as written and fails when an engine upgrade or a change of the model "
        "breaks the advice: each engine's advised settings are run against the reference, and its boundary "
        "search (gate-sweep.toml) must still find the advised step safe.\n";
    write_file_atomic((out / "advice.toml").string(), head + gate);
    res.gate_written = true;
  } else {
    std::error_code ec;
    fs::remove(out / "advice.toml", ec);  // an earlier run's advice no longer holds
  }

  // The record: what the page says, for a program (its fields: advice_record.h).
  write_file_atomic((out / "advice.json").string(), advice_json_text(advice_record(res)));

  // The page: one sentence per engine, the configurations, the evidence.
  Document doc;
  doc.title = "Advice for " + scene.name;
  doc.heading(1, doc.title);
  for (const AdviceEngine& e : res.engines) {
    std::string t = e.engine + ": ";
    if (e.chosen) {
      const AdviceConfig& c = e.configs[*e.chosen];
      t += c.text() + ", " + e.knob + " " + search_value_text(e.step) + " keeps the top " +
           (res.reference_inverts ? "inverting like the reference" : "in the reference's regime (no inversion)") +
           " to t = " + sig3(res.duration) + " (" + res.criterion + "); " + sig3(e.cpu_seconds) + " CPU s" +
           (res.repeats > 1 ? " (the least of " + std::to_string(res.repeats) + " runs)" : std::string()) +
           "; the largest safe " + e.knob + " is " + search_value_text(e.boundary) +
           (e.beyond > 0 ? " (unsafe at " + search_value_text(e.beyond) + ")" : " (safe to the end of the range)");
      if (!e.sensitivity.empty()) t += "; " + join(e.sensitivity, ", ");
      const std::vector<std::string> ties = advice_ties_text(e);
      if (!ties.empty())
        t += "; within " + sig3(100 * kCostResolution) + " % of its CPU time, not told apart: " + join(ties, "; ");
      t += ".";
    } else {
      t += "no advice: " + e.reason + ".";
    }
    if (!e.unsearched.empty()) t += " " + std::to_string(e.unsearched.size()) + " configuration(s) not searched (--max-runs).";
    doc.para(t, "verdict");
  }
  const EnergyGainRule rule = energy_gain_rule(scene);
  doc.para(std::string("Safe: the run finished, the stability map classes it ok (no divergence, no net energy gain "
                       "above 1e-6 E0 and the energy of 1e-4 R of contact depth in a dissipative scene, counting ") +
           energy_counted_text(rule) + " (energy_gain_rule = " + to_string(rule) +
           "), no Jellett drift where J is conserved), and " +
           res.criterion + ". The advised " + "step is the largest safe step found / " + sig3(kAdviceMargin) +
           ", confirmed by a run there" +
           (res.repeats > 1 ? "; a configuration's CPU time is the least of its confirming point's " +
                                  std::to_string(res.repeats) + " runs, interleaved with the other configurations' (--repeats)"
                            : std::string()) +
           ". " +
           (res.gate_written ? "advice.toml is the gate that keeps it: `tippe gate advice.toml`."
                             : "No engine has advice: no gate is written."));
  doc.heading(2, "Configurations");
  DocTable t;
  t.header = {"engine", "configuration", "search", "largest safe step", "first unsafe", "runs", "advised",
              res.repeats > 1 ? "CPU s (least of " + std::to_string(res.repeats) + ")" : std::string("CPU s")};
  for (const AdviceEngine& e : res.engines) {
    for (size_t i = 0; i < e.configs.size(); ++i) {
      const SearchBoundary& b = e.boundaries[i];
      const bool chosen = e.chosen && *e.chosen == i;
      const auto tie = std::find_if(e.ties.begin(), e.ties.end(), [&](const AdviceEngine::Tie& x) { return x.config == i; });
      std::string advised, cpu;
      if (chosen) {
        advised = search_value_text(e.step) + " (confirmed)";
        cpu = sig3(e.cpu_seconds);
      } else if (tie != e.ties.end()) {
        advised = "not told apart: " + search_value_text(tie->step) + " (confirmed)";
        cpu = sig3(tie->cpu_seconds);
      }
      t.rows.push_back({e.engine, e.configs[i].text(), b.status.empty() ? "no records" : b.status,
                        b.boundary ? search_value_text(*b.boundary) : "-", b.beyond ? search_value_text(*b.beyond) : "-",
                        std::to_string(b.runs), advised, cpu});
    }
    for (const AdviceConfig& c : e.unsearched) t.rows.push_back({e.engine, c.text(), "not searched (budget)", "", "", "0", "", ""});
  }
  doc.table(t);
  doc.heading(2, "Sensitivity: which setting moved the boundary");
  DocTable s;
  s.header = {"engine", "axis", "value", "largest safe step with it", "smaller than the best by"};
  for (const AdviceEngine& e : res.engines)
    for (const auto& row : e.sensitivity_rows) s.rows.push_back({e.engine, row[0], row[1], row[2], row[3]});
  doc.table(s);
  doc.heading(2, "Evidence");
  std::vector<DocLink> links = {{"the boundary searches (sweep report)", "sweep/index.html"},
                                {"their records", "sweep/records.jsonl"}};
  if (!confirm.empty()) links.push_back({"the confirming runs", "confirm/records.jsonl"});
  if (res.gate_written) links.push_back({"the gate", "advice.toml"});
  links.push_back({"the advice as a record", "advice.json"});
  doc.links(links);
  doc.para(std::to_string(res.runs) + " runs; the searches resume from OUT/sweep when run again, and run under MPI or in "
           "shards as `tippe sweep advise-sweep.toml --out sweep` does.");
  write_file_atomic((out / "index.md").string(), render_document_markdown(doc));
  write_file_atomic((out / "index.html").string(), render_document_html(doc));
  return res;
}

}  // namespace tippe
