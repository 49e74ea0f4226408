// Gate files: reading and checking them into checks, and the table of metrics a gate may bound.
#include "harness/gating/gate.h"
#include "harness/io/text.h"

#include "engines/core/registry.h"

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

#include "harness/records/records.h"
#include "harness/io/scene_io.h"
#include "harness/scene/resolve.h"
#include "harness/io/toml_reader.h"

namespace tippe {

namespace {

namespace fs = std::filesystem;
using nlohmann::json;

// ---- small helpers ----------------------------------------------------------------------------

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
  std::optional<bool> require_no_wrong_event;
  std::optional<bool> allow_unconverged;
  std::map<std::string, double> max;
};

class GateReader : public TomlReader {
 public:
  explicit GateReader(std::string file) : TomlReader(std::move(file)) {}

  Spec spec(const toml::table& t, const std::string& key, bool is_defaults) const {
    static const std::vector<std::string> check_keys = {"name",   "scene", "engine", "set", "duration",
                                                        "status", "require_same_events", "require_no_wrong_event", "allow_unconverged",
                                                        "max"};
    static const std::vector<std::string> default_keys = {"scene",  "engine", "set", "duration",
                                                          "status", "require_same_events", "require_no_wrong_event", "allow_unconverged",
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
    if (const toml::node* n = t.get("require_no_wrong_event")) {
      const auto* b = n->as_boolean();
      if (!b) fail(key + ".require_no_wrong_event", "expected true or false, got " + toml_value_text(*n));
      s.require_no_wrong_event = b->get();
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

};

// Where a merged value came from, for messages: the check's own key or [defaults]'.
std::string origin(const Spec& check, const Spec& defaults, bool from_check, const std::string& field) {
  return (from_check ? check.key : defaults.key) + "." + field;
}

}  // namespace

// ---- gate files -----------------------------------------------------------------------------

GateFile load_gate_file(const std::string& path) {
  // The path names the JUnit suite and is in the JSON results: checked before anything is read.
  if (!is_valid_utf8(path)) throw SceneError(utf8_replaced(path) + ": cannot read: the path is not valid UTF-8");
  GateReader reader(path);
  const toml::table root = read_toml_file(path);

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
    c.require_no_wrong_event =
        s.require_no_wrong_event ? *s.require_no_wrong_event : defaults.require_no_wrong_event.value_or(false);
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

}  // namespace tippe
