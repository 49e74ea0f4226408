// CI gates: reading and checking gate files, judging one engine run against its thresholds, and the table, JUnit and JSON renderings.
#include "gating/gate.h"

#include "registry.h"

#include <algorithm>
#include <array>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <initializer_list>
#include <map>
#include <set>
#include <sstream>
#include <stdexcept>

#include <toml++/toml.h>

#include "records/records.h"
#include "io/scene_io.h"
#include "io/toml_text.h"

namespace tippe {

namespace {

namespace fs = std::filesystem;
using nlohmann::json;

// ---- small helpers ----------------------------------------------------------------------------

// Short enough for a CI log, long enough that a value just over its threshold does not print
// equal to it; integral values (steps, counts) print without an exponent.
std::string fmt(double v) {
  if (std::isnan(v)) return "nan";
  if (std::isinf(v)) return v > 0 ? "inf" : "-inf";
  char buf[64];
  if (v == std::floor(v) && std::abs(v) < 1e15)
    std::snprintf(buf, sizeof buf, "%.0f", v);
  else
    std::snprintf(buf, sizeof buf, "%.6g", v);
  return buf;
}

std::string trim(const std::string& s) {
  const auto b = s.find_first_not_of(" \t");
  if (b == std::string::npos) return {};
  const auto e = s.find_last_not_of(" \t");
  return s.substr(b, e - b + 1);
}

std::string idx(const std::string& key, size_t i) { return key + "[" + std::to_string(i) + "]"; }

std::string join(const std::vector<std::string>& v, const std::string& sep) {
  std::string out;
  for (const auto& s : v) out += (out.empty() ? "" : sep) + s;
  return out;
}

const std::vector<std::string>& gate_engines() {
  // The reference against itself is not a gate; the engines are what teams tune.
  static const std::vector<std::string> e = engine_names();
  return e;
}

const std::vector<std::string>& run_statuses() {
  static const std::vector<std::string> s = [] {
    std::vector<std::string> v;
    for (RunStatus r : {RunStatus::Ok, RunStatus::ContactLost, RunStatus::Diverged, RunStatus::Unphysical,
                        RunStatus::Clamped, RunStatus::Failed})
      v.emplace_back(to_string(r));
    return v;
  }();
  return s;
}

// The scene's own message without its "FILE: " prefix, with the scene file named at the end.
std::string quote_scene_error(const SceneError& e, const std::string& scene_path) {
  std::string msg = e.what();
  const std::string prefix = scene_path + ": ";
  if (msg.rfind(prefix, 0) == 0) msg = msg.substr(prefix.size()) + " (scene " + scene_path + ")";
  return msg;
}

// The key a scene error is about ("engines.ode.timestep"), or "" when it names none.
std::string scene_error_key(const SceneError& e, const std::string& scene_path) {
  const std::string msg = e.what();
  const std::string prefix = scene_path + ": ";
  if (msg.rfind(prefix, 0) != 0) return {};
  const std::string rest = msg.substr(prefix.size());
  return rest.substr(0, rest.find(": "));
}

// ---- gate files -----------------------------------------------------------------------------

// What one [[check]] or [defaults] table says, before the two are merged.
struct Spec {
  std::string key;  // "check[2]" or "defaults"
  std::optional<std::string> name, scene, engine, status;
  std::optional<std::vector<std::string>> set;
  std::optional<double> duration;
  std::optional<bool> require_same_events;
  std::optional<bool> allow_unconverged;
  std::map<std::string, double> max;
};

class GateReader {
 public:
  explicit GateReader(std::string file) : file_(std::move(file)) {}

  [[noreturn]] void fail(const std::string& key, const std::string& why) const {
    throw SceneError(file_ + ": " + key + ": " + why);
  }

  // The one form of every range error, as in scene files: "KEY: VALUE is out of range (expected RANGE)".
  [[noreturn]] void out_of_range(const std::string& key, double v, const std::string& expected) const {
    fail(key, fmt(v) + " is out of range (expected " + expected + ")");
  }

  void keys(const toml::table& t, const std::string& prefix, const std::vector<std::string>& allowed) const {
    for (auto&& [k, v] : t) {
      (void)v;
      const std::string key(k.str());
      if (std::find(allowed.begin(), allowed.end(), key) == allowed.end())
        fail(prefix.empty() ? key : prefix + "." + key, "unknown key (expected one of: " + join(allowed, ", ") + ")");
    }
  }

  std::string string(const toml::node& n, const std::string& key) const {
    const auto* s = n.as_string();
    if (!s) fail(key, "expected a string, got " + toml_value_text(n));
    return s->get();
  }

  double number(const toml::node& n, const std::string& key) const {
    double v;
    if (const auto* f = n.as_floating_point()) v = f->get();
    else if (const auto* i = n.as_integer()) v = static_cast<double>(i->get());
    else fail(key, "expected a number, got " + toml_value_text(n));
    if (!std::isfinite(v)) fail(key, "must be a finite number, got " + fmt(v));
    return v;
  }

  Spec spec(const toml::table& t, const std::string& key, bool is_defaults) const {
    static const std::vector<std::string> check_keys = {"name",   "scene", "engine", "set", "duration",
                                                        "status", "require_same_events", "allow_unconverged",
                                                        "max"};
    static const std::vector<std::string> default_keys = {"scene",  "engine", "set", "duration",
                                                          "status", "require_same_events", "allow_unconverged",
                                                          "max"};
    keys(t, key, is_defaults ? default_keys : check_keys);
    Spec s;
    s.key = key;
    if (const toml::node* n = t.get("name")) {
      s.name = string(*n, key + ".name");
      if (!is_valid_name(*s.name))
        fail(key + ".name", "\"" + *s.name + "\" is not a usable name (letters, digits, '.', '_', '-')");
    }
    if (const toml::node* n = t.get("scene")) {
      s.scene = string(*n, key + ".scene");
      if (s.scene->empty()) fail(key + ".scene", "empty file name");
    }
    if (const toml::node* n = t.get("engine")) {
      s.engine = string(*n, key + ".engine");
      const auto& e = gate_engines();
      if (std::find(e.begin(), e.end(), *s.engine) == e.end())
        fail(key + ".engine", "unknown engine \"" + *s.engine + "\" (expected one of: " + join(e, ", ") + ")");
    }
    if (const toml::node* n = t.get("status")) {
      s.status = string(*n, key + ".status");
      const auto& st = run_statuses();
      if (std::find(st.begin(), st.end(), *s.status) == st.end())
        fail(key + ".status", "unknown run status \"" + *s.status + "\" (expected one of: " + join(st, ", ") + ")");
    }
    if (const toml::node* n = t.get("require_same_events")) {
      const auto* b = n->as_boolean();
      if (!b) fail(key + ".require_same_events", "expected true or false, got " + toml_value_text(*n));
      s.require_same_events = b->get();
    }
    if (const toml::node* n = t.get("allow_unconverged")) {
      const auto* b = n->as_boolean();
      if (!b) fail(key + ".allow_unconverged", "expected true or false, got " + toml_value_text(*n));
      s.allow_unconverged = b->get();
    }
    if (const toml::node* n = t.get("duration")) {
      s.duration = number(*n, key + ".duration");
      if (!(*s.duration > 0)) out_of_range(key + ".duration", *s.duration, "duration > 0");
    }
    if (const toml::node* n = t.get("set")) {
      const auto* a = n->as_array();
      if (!a) fail(key + ".set", "expected an array of \"KEY=VALUE\" strings, got " + toml_value_text(*n));
      std::vector<std::string> set;
      std::set<std::string> seen;
      for (size_t j = 0; j < a->size(); ++j) {
        const std::string sk = idx(key + ".set", j);
        const std::string o = string(*a->get(j), sk);
        const auto eq = o.find('=');
        if (eq == std::string::npos || trim(o.substr(0, eq)).empty())
          fail(sk, "malformed override \"" + o + "\" (expected KEY=VALUE)");
        if (!seen.insert(trim(o.substr(0, eq))).second) fail(sk, trim(o.substr(0, eq)) + " is set twice");
        set.push_back(o);
      }
      s.set = set;
    }
    if (const toml::node* n = t.get("max")) {
      const auto* m = n->as_table();
      if (!m) fail(key + ".max", "expected a table of metric = threshold, got " + toml_value_text(*n));
      for (auto&& [k, v] : *m) {
        const std::string metric(k.str());
        const std::string mk = key + ".max." + metric;
        if (const std::string why = gate_metric_problem(metric); !why.empty()) fail(mk, why);
        const double x = number(v, mk);
        if (const std::string why = threshold_problem(metric, x); !why.empty()) fail(mk, why);
        s.max[metric] = x;
      }
    }
    return s;
  }

  const std::string& file() const { return file_; }

 private:
  std::string file_;
};

// Where a merged value came from, for messages: the check's own key or [defaults]'.
std::string origin(const Spec& check, const Spec& defaults, bool from_check, const std::string& field) {
  return (from_check ? check.key : defaults.key) + "." + field;
}

}  // namespace

// ---- metrics table ------------------------------------------------------------------------------

#define TIPPE_GATE_VALUE(field, unit) \
  {#field, [](const Metrics& m) -> std::optional<double> { return static_cast<double>(m.field); }, unit}
#define TIPPE_GATE_OPTIONAL(field, unit) \
  {#field, [](const Metrics& m) -> std::optional<double> { return m.field; }, unit}

const std::vector<GateMetric>& gate_metrics() {
  static const std::vector<GateMetric> table = {
      TIPPE_GATE_OPTIONAL(inversion_time_abs_error, "s, engine - reference"),
      TIPPE_GATE_OPTIONAL(inversion_time_rel_error, "fraction of the reference's time"),
      TIPPE_GATE_OPTIONAL(stem_contact_time_abs_error, "s, engine - reference"),
      TIPPE_GATE_OPTIONAL(stem_contact_time_rel_error, "fraction of the reference's time"),
      TIPPE_GATE_VALUE(tilt_max_error, "rad"),
      TIPPE_GATE_VALUE(tilt_rms_error, "rad"),
      TIPPE_GATE_VALUE(energy_max_error, "/ E0"),
      TIPPE_GATE_VALUE(energy_final_ratio, "E_final / E0 of the engine"),
      TIPPE_GATE_VALUE(energy_gain_events, "count"),
      TIPPE_GATE_VALUE(energy_max_gain, "/ E0"),
      TIPPE_GATE_VALUE(contact_path_rms_error, "/ R"),
      TIPPE_GATE_VALUE(contact_path_max_error, "/ R"),
      TIPPE_GATE_VALUE(com_path_rms_error, "/ R"),
      TIPPE_GATE_VALUE(com_path_max_error, "/ R"),
      TIPPE_GATE_VALUE(latitude_rms_error, "rad"),
      TIPPE_GATE_OPTIONAL(jellett_drift_ball, "relative"),
      TIPPE_GATE_OPTIONAL(jellett_drift_stem, "relative"),
      TIPPE_GATE_VALUE(jellett_max_relative_drift, "relative"),
      TIPPE_GATE_VALUE(steps, "engine steps"),
      TIPPE_GATE_VALUE(cost_ratio, "engine CPU / reference CPU"),
      TIPPE_GATE_VALUE(compared_until, "s"),
  };
  return table;
}

#undef TIPPE_GATE_VALUE
#undef TIPPE_GATE_OPTIONAL

const GateMetric* find_gate_metric(const std::string& name) {
  for (const GateMetric& g : gate_metrics())
    if (name == g.name) return &g;
  return nullptr;
}

std::string gate_metric_problem(const std::string& metric) {
  if (metric == "wall_seconds" || metric == "cpu_seconds" || metric == "real_time_factor")
    return "timing is never gated (it depends on the machine and its load); bound steps or cost_ratio";
  if (!find_gate_metric(metric)) {
    std::vector<std::string> names;
    for (const auto& g : gate_metrics()) names.emplace_back(g.name);
    return "unknown metric (expected one of: " + join(names, ", ") + ")";
  }
  return {};
}

std::string threshold_problem(const std::string& metric, double x) {
  // No upper bound: metrics differ in unit and scale (steps, seconds, ratios), and a loose
  // threshold is a visible choice of the gate's author, not a typo that hides a failure.
  if (!(x >= 0)) return fmt(x) + " is out of range (expected " + metric + " >= 0: |value| is compared)";
  return {};
}

BoundText parse_bound_text(const std::string& text) {
  const size_t le = text.find("<="), ge = text.find(">=");
  if ((le == std::string::npos) == (ge == std::string::npos))
    throw std::invalid_argument("\"" + utf8_replaced(text.substr(0, 80)) +
                                "\" is not a bound (expected NAME <= NUMBER or NAME >= NUMBER)");
  const size_t at = le != std::string::npos ? le : ge;
  BoundText b;
  b.name = trim(text.substr(0, at));
  b.op = text.substr(at, 2);
  const std::string value = trim(text.substr(at + 2));
  if (b.name.empty()) throw std::invalid_argument("\"" + utf8_replaced(text.substr(0, 80)) + "\": no name before " + b.op);
  char* end = nullptr;
  errno = 0;
  b.bound = value.empty() ? 0.0 : std::strtod(value.c_str(), &end);
  if (value.empty() || end != value.c_str() + value.size() || !std::isfinite(b.bound) ||
      value.find_first_not_of("0123456789+-.eE") != std::string::npos)
    throw std::invalid_argument("\"" + utf8_replaced(value.substr(0, 40)) + "\" after " + b.op +
                                " is not a finite number");
  return b;
}

Threshold parse_threshold_text(const std::string& text) {
  const BoundText b = parse_bound_text(text);
  if (b.op != "<=") throw std::invalid_argument("a metric is bounded from above: " + b.name + " <= NUMBER (|value| is compared)");
  if (const std::string why = gate_metric_problem(b.name); !why.empty()) throw std::invalid_argument(b.name + ": " + why);
  if (const std::string why = threshold_problem(b.name, b.bound); !why.empty()) throw std::invalid_argument(why);
  return Threshold{b.name, b.bound};
}

// ---- gate files -----------------------------------------------------------------------------

GateFile load_gate_file(const std::string& path) {
  // The path names the JUnit suite and is in the JSON results: checked before anything is read.
  if (!is_valid_utf8(path)) throw SceneError(utf8_replaced(path) + ": cannot read: the path is not valid UTF-8");
  GateReader reader(path);
  std::string text;
  try {
    text = read_file_text(path, kMaxInputFileBytes);
  } catch (const std::runtime_error& e) {
    throw SceneError(e.what());
  }
  toml::table root;
  try {
    root = toml::parse(text, path);
  } catch (const toml::parse_error& e) {
    throw SceneError(path + ":" + std::to_string(e.source().begin.line) + ":" +
                     std::to_string(e.source().begin.column) + ": " + std::string(e.description()));
  }

  // [[boundary]] checks bound a sweep's boundary search instead (gate_boundary.h).
  reader.keys(root, "", {"defaults", "check", "boundary"});
  Spec defaults;
  defaults.key = "defaults";
  if (const toml::node* d = root.get("defaults")) {
    const auto* t = d->as_table();
    if (!t) reader.fail("defaults", "expected a table, got " + toml_value_text(*d));
    defaults = reader.spec(*t, "defaults", true);
  }
  const toml::node* cn = root.get("check");
  if (!cn && root.get("boundary")) {
    GateFile only_boundaries;
    only_boundaries.file = path;
    return only_boundaries;
  }
  if (!cn) reader.fail("check", "no checks (a gate file needs one or more [[check]] or [[boundary]] tables)");
  const auto* checks = cn->as_array();
  if (!checks) reader.fail("check", "expected [[check]] tables, got " + toml_value_text(*cn));
  if (checks->empty()) reader.fail("check", "no checks (a gate file needs one or more [[check]] tables)");

  GateFile g;
  g.file = path;
  const fs::path base = fs::path(path).parent_path();
  std::map<std::string, size_t> names;
  for (size_t i = 0; i < checks->size(); ++i) {
    const std::string key = idx("check", i);
    const toml::node& n = *checks->get(i);
    const auto* t = n.as_table();
    if (!t) reader.fail(key, "expected a [[check]] table, got " + toml_value_text(n));
    const Spec s = reader.spec(*t, key, false);

    Check c;
    if (!s.name) reader.fail(key + ".name", "missing (required)");
    c.name = *s.name;
    if (auto [it, fresh] = names.emplace(c.name, i); !fresh)
      reader.fail(key + ".name", "\"" + c.name + "\" is already the name of " + idx("check", it->second));
    if (!s.scene && !defaults.scene) reader.fail(key + ".scene", "missing (required, here or in [defaults])");
    const std::string scene_key = origin(s, defaults, s.scene.has_value(), "scene");
    c.scene = s.scene ? *s.scene : *defaults.scene;
    c.scene_path = (fs::path(c.scene).is_absolute() ? fs::path(c.scene) : base / c.scene).lexically_normal().string();
    if (!s.engine && !defaults.engine) reader.fail(key + ".engine", "missing (required, here or in [defaults])");
    c.engine = s.engine ? *s.engine : *defaults.engine;
    c.status = s.status ? *s.status : defaults.status.value_or("ok");
    c.require_same_events = s.require_same_events ? *s.require_same_events : defaults.require_same_events.value_or(false);
    c.allow_unconverged = s.allow_unconverged ? *s.allow_unconverged : defaults.allow_unconverged.value_or(false);
    c.duration = s.duration ? s.duration : defaults.duration;
    const std::string duration_key = origin(s, defaults, s.duration.has_value(), "duration");

    // Each override remembers its own key so that a scene error lands on the line that caused it.
    std::vector<std::string> set_keys;
    for (const Spec* from : {static_cast<const Spec*>(&defaults), &s}) {
      if (!from->set) continue;
      for (size_t j = 0; j < from->set->size(); ++j) {
        c.set.push_back((*from->set)[j]);
        set_keys.push_back(idx(from->key + ".set", j));
      }
    }
    for (size_t j = 0; j < c.set.size(); ++j) {
      // A setting of another engine would be read by nobody: the check would pass or fail on
      // settings other than the ones its author meant.
      const std::string k = trim(c.set[j].substr(0, c.set[j].find('=')));
      const std::string prefix = "engines.";
      if (k.rfind(prefix, 0) == 0) {
        const std::string eng = k.substr(prefix.size(), k.find('.', prefix.size()) - prefix.size());
        if (eng != c.engine)
          reader.fail(set_keys[j], "\"" + k + "\" is a setting of " + eng + ", but check \"" + c.name + "\" runs " +
                                       c.engine + " (engines." + c.engine + ".KEY)");
      }
    }
    if (c.duration) c.overrides.push_back("run.duration=" + json(*c.duration).dump());
    c.overrides.insert(c.overrides.end(), c.set.begin(), c.set.end());

    std::map<std::string, double> max = defaults.max;
    for (const auto& [m, v] : s.max) max[m] = v;
    for (const GateMetric& gm : gate_metrics())
      if (auto it = max.find(gm.name); it != max.end()) c.max.push_back({gm.name, it->second});

    try {
      c.loaded = load_scene(c.scene_path, c.overrides);
    } catch (const SceneError&) {
      // Blame the first layer that breaks: the scene itself, the duration, then the overrides.
      try {
        load_scene(c.scene_path);
      } catch (const SceneError& x) {
        reader.fail(scene_key, quote_scene_error(x, c.scene_path));
      }
      if (c.duration) {
        try {
          load_scene(c.scene_path, {c.overrides.front()});
        } catch (const SceneError& x) {
          reader.fail(duration_key, quote_scene_error(x, c.scene_path));
        }
      }
      try {
        load_scene(c.scene_path, c.overrides);
      } catch (const SceneError& x) {
        const std::string bad = scene_error_key(x, c.scene_path);
        for (size_t j = 0; j < c.set.size(); ++j)
          if (!bad.empty() && trim(c.set[j].substr(0, c.set[j].find('='))) == bad)
            reader.fail(set_keys[j], quote_scene_error(x, c.scene_path));
        reader.fail(c.set.empty() ? key : set_keys.size() == 1 ? set_keys[0] : key + ".set",
                    quote_scene_error(x, c.scene_path));
      }
    }
    g.checks.push_back(std::move(c));
  }
  return g;
}

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
  if (metric == "jellett_drift_ball") return "the engine never rolled on the ball";
  if (metric == "jellett_drift_stem") return "the engine never rolled on the stem";
  return "not computed";
}

std::string nan_reason(const std::string& metric, const Metrics& m) {
  if (metric == "energy_final_ratio") return "the engine produced no samples";
  if (!std::isfinite(m.compared_until) && metric != "compared_until" && metric != "steps" && metric != "cost_ratio")
    return "no samples in common with the reference";
  return "not a number";
}

// "0.0812" or "|-0.0812|": the message says what was compared.
std::string compared(double v) { return v < 0 ? "|" + fmt(v) + "|" : fmt(v); }

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
      r.message += " at t = " + fmt(engine.status_time);
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

}  // namespace

GateRow threshold_row(const Threshold& t, const Metrics& m) {
  GateRow r;
  r.kind = GateRowKind::Threshold;
  r.metric = t.metric;
  r.limit = t.max;
  r.required = fmt(t.max);
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
    r.measured = fmt(*r.value);
    r.passed = std::abs(*r.value) <= t.max;
    if (!r.passed) r.message = t.metric + " " + compared(*r.value) + " > " + fmt(t.max);
  }
  return r;
}

namespace {

// Metrics computed over the samples the reference and the engine have in common: cut at the end
// of the reference's converged window.
bool windowed_metric(const std::string& metric) {
  static const std::set<std::string> names = {"tilt_max_error",         "tilt_rms_error",         "energy_max_error",
                                              "contact_path_rms_error", "contact_path_max_error", "com_path_rms_error",
                                              "com_path_max_error",     "latitude_rms_error",     "compared_until"};
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
  const std::string x = fmt(*m.reference_converged_until);
  const std::string why = "reference not converged after t = " + x + " (the check runs to t = " +
                          fmt(check.loaded.run.duration) + ")";
  for (GateRow& row : rows) {
    std::string which;
    const bool event = row.kind == GateRowKind::Events || (row.kind == GateRowKind::Threshold && event_metric(row.metric, &which, m));
    if (row.kind == GateRowKind::Events) which = row.measured;
    if (event) {
      if (which != "unconverged") continue;  // the pairing was judged inside the window
      row.measured = "unconverged";
      row.passed = check.allow_unconverged;
      row.message = row.passed ? "" : row.metric + ": " + why + "; the event is not judged";
      continue;
    }
    if (row.kind != GateRowKind::Threshold || !windowed_metric(row.metric)) continue;
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

json number_or_null(const std::optional<double>& v) {
  return v && std::isfinite(*v) ? json(*v) : json(nullptr);
}

// Text and attribute values: the five XML specials, and control characters XML 1.0 cannot
// carry at all (an engine's status detail could hold any byte).
std::string xml_escape(const std::string& text, bool attribute) {
  // A byte that is not UTF-8 would make the whole document malformed (the declaration says UTF-8).
  const std::string s = utf8_replaced(text);
  std::string out;
  out.reserve(s.size());
  for (char ch : s) {
    const unsigned char c = static_cast<unsigned char>(ch);
    switch (ch) {
      case '&': out += "&amp;"; break;
      case '<': out += "&lt;"; break;
      case '>': out += "&gt;"; break;
      case '"': out += "&quot;"; break;
      case '\'': out += "&apos;"; break;
      case '\n': out += attribute ? "&#10;" : "\n"; break;
      case '\t': out += attribute ? "&#9;" : "\t"; break;
      case '\r': out += "&#13;"; break;
      default:
        if (c < 0x20 || c == 0x7f)
          out += '?';
        else
          out += ch;
    }
  }
  return out;
}

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
  const std::string suite = xml_escape(suite_name, true);
  const std::string counts = " tests=\"" + std::to_string(results.size()) + "\" failures=\"" +
                             std::to_string(failures) + "\" errors=\"" + std::to_string(errors) + "\"";
  std::string x = "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n";
  x += "<testsuites name=\"" + suite + "\"" + counts + " time=\"" + seconds_text(total) + "\">\n";
  x += "  <testsuite name=\"" + suite + "\"" + counts + " skipped=\"0\" time=\"" + seconds_text(total) + "\">\n";
  for (const CheckResult& r : results) {
    x += "    <testcase classname=\"" + suite + "\" name=\"" + xml_escape(r.name, true) + "\" time=\"" +
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
    x += "      <" + tag + " message=\"" + xml_escape(join(failure_messages(r), "; "), true) + "\" type=\"" +
         kind_name(first_kind) + "\">" + xml_escape(details, false) + "</" + tag + ">\n";
    x += "    </testcase>\n";
  }
  x += "  </testsuite>\n</testsuites>\n";
  return x;
}

json to_json(const std::vector<CheckResult>& results) {
  json list = json::array();
  size_t failed = 0;
  for (const CheckResult& r : results) {
    failed += !r.passed;
    json rows = json::array();
    for (const GateRow& row : r.rows)
      rows.push_back({{"kind", kind_name(row.kind)},
                      {"metric", row.metric},
                      {"value", number_or_null(row.value)},
                      {"threshold", number_or_null(row.limit)},
                      {"measured", row.measured},
                      {"required", row.required},
                      {"passed", row.passed},
                      {"message", row.message}});
    list.push_back({{"name", r.name},
                    {"engine", r.engine},
                    {"scene", r.scene},
                    {"set", r.set},
                    {"passed", r.passed},
                    {"seconds", number_or_null(r.seconds)},
                    {"rows", rows}});
  }
  return json{{"format", "tippe-gate-1"},
              {"passed", failed == 0},
              {"checks", results.size()},
              {"failed", failed},
              {"results", list}};
}

}  // namespace tippe
