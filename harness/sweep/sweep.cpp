// Work-precision sweeps: reading sweep files into checked plans, the records.jsonl format, and resumable parallel runs.
#include "sweep/sweep.h"
#include "io/progress.h"

#include <fcntl.h>
#include <sys/file.h>
#include <toml++/toml.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <exception>
#include <filesystem>
#include <fstream>
#include <functional>
#include <initializer_list>
#include <limits>
#include <map>
#include <memory>
#include <mutex>
#include <set>
#include <sstream>
#include <stdexcept>
#include <thread>
#include <tuple>

#include "measure/classify.h"
#include "io/interrupt.h"
#include "io/output_dir.h"
#include "io/provenance.h"
#include "records/records.h"
#include "registry.h"
#include "io/scene_io.h"
#include "sweep/sweep_search.h"
#include "io/toml_text.h"
#include "timing.h"

namespace tippe {

namespace {

namespace fs = std::filesystem;
using nlohmann::json;

// A judgement: repeats only sharpen the minimum CPU time of a point, which settles after a few;
// more than 100 is likelier a typo than a wish for a sweep that many times as long.
constexpr int kMaxRepeats = 100;

std::string num(double v) {
  std::ostringstream os;
  os.precision(12);
  os << v;
  return os.str();
}

std::string trim(const std::string& s) {
  const auto b = s.find_first_not_of(" \t");
  if (b == std::string::npos) return {};
  const auto e = s.find_last_not_of(" \t");
  return s.substr(b, e - b + 1);
}

std::string idx(const std::string& key, size_t i) { return key + "[" + std::to_string(i) + "]"; }

// Checks one sweep file; every message names the file and the dotted key.
class SweepReader {
 public:
  explicit SweepReader(std::string file) : file_(std::move(file)) {}

  [[noreturn]] void fail(const std::string& key, const std::string& why) const {
    throw SceneError(file_ + ": " + key + ": " + why);
  }

  // The one form of every range error, as in scene files: "KEY: VALUE is out of range (expected RANGE)".
  [[noreturn]] void out_of_range(const std::string& key, const std::string& value, const std::string& expected) const {
    fail(key, value + " is out of range (expected " + expected + ")");
  }

  void keys(const toml::table& t, const std::string& prefix, std::initializer_list<const char*> allowed) const {
    for (auto&& [k, v] : t) {
      (void)v;
      const std::string key(k.str());
      if (std::none_of(allowed.begin(), allowed.end(), [&](const char* a) { return key == a; })) {
        std::string list;
        for (const char* a : allowed) list += (list.empty() ? "" : ", ") + std::string(a);
        fail(prefix.empty() ? key : prefix + "." + key, "unknown key (expected one of: " + list + ")");
      }
    }
  }

  double number(const toml::node& n, const std::string& key) const {
    double v;
    if (const auto* f = n.as_floating_point())
      v = f->get();
    else if (const auto* i = n.as_integer())
      v = static_cast<double>(i->get());
    else
      fail(key, "expected a number, got " + toml_value_text(n));
    if (!std::isfinite(v)) fail(key, "must be a finite number, got " + num(v));
    return v;
  }

  std::string string(const toml::node& n, const std::string& key) const {
    const auto* s = n.as_string();
    if (!s) fail(key, "expected a string, got " + toml_value_text(n));
    return s->get();
  }

  const toml::array& array(const toml::node& n, const std::string& key) const {
    const auto* a = n.as_array();
    if (!a) fail(key, "expected an array, got " + toml_value_text(n));
    return *a;
  }

  const toml::table& table(const toml::node& n, const std::string& key) const {
    const auto* t = n.as_table();
    if (!t) fail(key, "expected a table, got " + toml_value_text(n));
    return *t;
  }

  // An axis value as the TOML text an override needs: integers stay integers (iteration
  // counts), floats keep the shortest text that reads back to the same double, strings (which
  // follow the rule of names, so need no escape) are quoted, booleans are true or false. `label`
  // is the text a record carries, `value` the number (NaN for a string or a boolean).
  std::string value_text(const toml::node& n, const std::string& key, double& value, std::string& label) const {
    value = std::numeric_limits<double>::quiet_NaN();
    if (const auto* str = n.as_string()) {
      label = str->get();
      if (!is_valid_name(label))
        fail(key, "\"" + utf8_replaced(label.substr(0, 40)) + "\" is not a usable value (" + kNameRule +
                      "; it becomes a report label)");
      return "\"" + label + "\"";
    }
    if (const auto* b = n.as_boolean()) return label = b->get() ? "true" : "false";
    if (!n.is_number()) fail(key, "expected a number, a string or a boolean, got " + toml_value_text(n));
    value = number(n, key);
    if (const auto* i = n.as_integer()) return label = std::to_string(i->get());
    return label = json(value).dump();
  }

  // `ladder` or `grid` of a setup: {key, values}. Every value adds `per_value` points to
  // `planned`, refused beyond kMaxSweepPoints before anything is loaded.
  void read_axis(const toml::node& node, const std::string& where, const std::string& engine,
                 const std::set<std::string>& set_keys, std::string& axis_key, std::vector<double>& values,
                 std::vector<std::string>& texts, std::vector<std::string>& labels, size_t scenes, size_t per_value,
                 size_t& planned) const {
    const toml::table& l = table(node, where);
    keys(l, where, {"key", "values"});
    const toml::node* lk = l.get("key");
    if (!lk) fail(where + ".key", "missing (required)");
    axis_key = trim(string(*lk, where + ".key"));
    check_setting_key(engine, axis_key, where + ".key");
    const std::string setup = where.substr(0, where.rfind('.'));
    if (set_keys.count(axis_key)) fail(where + ".key", axis_key + " is also fixed in " + setup + ".set");
    const toml::node* lv = l.get("values");
    if (!lv) fail(where + ".values", "missing (required)");
    const toml::array& a = array(*lv, where + ".values");
    if (a.empty()) fail(where + ".values", "must list at least one value");
    const auto kind = [](const toml::node& n) { return n.is_string() ? "a string" : n.is_boolean() ? "a boolean" : "a number"; };
    for (size_t j = 0; j < a.size(); ++j) {
      const std::string vk = idx(where + ".values", j);
      // The plan's size is known from the file alone: refused here, before a single point is
      // loaded (and before the quadratic check of distinct values runs over a huge ladder).
      planned += per_value;
      if (scenes * planned > kMaxSweepPoints)
        fail(vk, std::to_string(scenes) + " scene(s) x " + std::to_string(planned) +
                     (per_value == 1 ? " ladder value(s)" : " point(s) per scene") + " so far is more than " +
                     std::to_string(kMaxSweepPoints) +
                     " points, the most a sweep plans; split it into several sweep files");
      const toml::node& n = *a.get(j);
      double v;
      std::string label;
      const std::string vt = value_text(n, vk, v, label);
      if (j > 0 && std::string(kind(n)) != kind(*a.get(0)))
        fail(vk, "expected " + std::string(kind(*a.get(0))) + " like " + idx(where + ".values", 0) + ", got " +
                     toml_value_text(n) + " (an axis' values are all numbers, all strings or all booleans)");
      for (size_t m = 0; m < values.size(); ++m)
        if (std::isnan(v) ? texts[m] == vt : values[m] == v)
          fail(vk, (std::isnan(v) ? label : num(v)) + " repeats " + idx(where + ".values", m));
      values.push_back(v);
      texts.push_back(vt);
      labels.push_back(label);
    }
  }

  SweepSpec read(const toml::table& root, const std::string& text) const {
    SweepSpec s;
    s.file = file_;
    s.text = text;
    s.hash = fnv1a_hex({text});
    keys(root, "", {"description", "repeats", "duration", "scenes", "setup"});
    if (const toml::node* d = root.get("description")) {
      s.description = string(*d, "description");
      if (s.description.find_first_of("\r\n") != std::string::npos) fail("description", "must be one line");
    }
    if (const toml::node* r = root.get("repeats")) {
      const auto* i = r->as_integer();
      const std::string range = "1 <= repeats <= " + std::to_string(kMaxRepeats);
      if (!i) fail("repeats", "expected an integer (" + range + "), got " + toml_value_text(*r));
      if (i->get() < 1 || i->get() > kMaxRepeats) out_of_range("repeats", std::to_string(i->get()), range);
      s.repeats = static_cast<int>(i->get());
    }
    if (const toml::node* d = root.get("duration")) {
      s.duration = number(*d, "duration");
      if (!(*s.duration > 0)) out_of_range("duration", num(*s.duration), "duration > 0");
    }

    const toml::node* sc = root.get("scenes");
    if (!sc) fail("scenes", "missing (required: an array of scene files)");
    const toml::array& scenes = array(*sc, "scenes");
    if (scenes.empty()) fail("scenes", "must list at least one scene");
    const fs::path base = fs::path(file_).parent_path();
    for (size_t i = 0; i < scenes.size(); ++i) {
      const std::string key = idx("scenes", i);
      SweepScene e;
      const toml::node& n = *scenes.get(i);
      if (n.is_string()) {
        e.file = string(n, key);
      } else if (const auto* t = n.as_table()) {
        keys(*t, key, {"file", "duration"});
        const toml::node* f = t->get("file");
        if (!f) fail(key + ".file", "missing (required)");
        e.file = string(*f, key + ".file");
        if (const toml::node* d = t->get("duration")) {
          e.duration = number(*d, key + ".duration");
          if (!(*e.duration > 0)) out_of_range(key + ".duration", num(*e.duration), "duration > 0");
        }
      } else {
        fail(key, "expected a file name or a table {file, duration}, got " + toml_value_text(n));
      }
      if (e.file.empty()) fail(key, "empty file name");
      e.path = (fs::path(e.file).is_absolute() ? fs::path(e.file) : base / e.file).lexically_normal().string();
      s.scenes.push_back(e);
    }

    const toml::node* su = root.get("setup");
    if (!su) fail("setup", "missing (required: one or more [[setup]] tables)");
    if (su->is_table()) fail("setup", "expected [[setup]] tables, got a table (write [[setup]], not [setup])");
    const toml::array& setups = array(*su, "setup");
    if (setups.empty()) fail("setup", "must have at least one [[setup]]");
    const std::vector<std::string> engines = available_engines();
    std::map<std::string, size_t> names;
    size_t planned = 0;  // ladder values so far, over the setups
    for (size_t i = 0; i < setups.size(); ++i) {
      const std::string key = idx("setup", i);
      const toml::table& t = table(*setups.get(i), key);
      keys(t, key, {"name", "engine", "set", "ladder", "grid", "scenes"});
      SweepSetup u;
      const toml::node* name = t.get("name");
      if (!name) fail(key + ".name", "missing (required)");
      u.name = string(*name, key + ".name");
      if (!is_valid_name(u.name))
        fail(key + ".name", "\"" + u.name + "\" is not a usable name (letters, digits, '.', '_', '-')");
      if (auto [it, fresh] = names.emplace(u.name, i); !fresh)
        fail(key + ".name", "\"" + u.name + "\" is already the name of " + idx("setup", it->second));
      const toml::node* engine = t.get("engine");
      if (!engine) fail(key + ".engine", "missing (required)");
      u.engine = string(*engine, key + ".engine");
      if (std::find(engines.begin(), engines.end(), u.engine) == engines.end()) {
        std::string list;
        for (const auto& e : engines) list += (list.empty() ? "" : ", ") + e;
        fail(key + ".engine", "unknown engine \"" + u.engine + "\" (expected one of: " + list + ")");
      }
      std::set<std::string> set_keys;
      if (const toml::node* set = t.get("set")) {
        const toml::array& a = array(*set, key + ".set");
        for (size_t j = 0; j < a.size(); ++j) {
          const std::string sk = idx(key + ".set", j);
          const std::string o = string(*a.get(j), sk);
          const auto eq = o.find('=');
          if (eq == std::string::npos || trim(o.substr(0, eq)).empty())
            fail(sk, "malformed override \"" + o + "\" (expected KEY=VALUE)");
          const std::string k = trim(o.substr(0, eq));
          check_setting_key(u.engine, k, sk);
          if (!set_keys.insert(k).second) fail(sk, k + " is set twice");
          u.set.push_back(o);
        }
      }
      if (const toml::node* only = t.get("scenes")) {
        // Names, checked against the scenes' once they are loaded (load_sweep).
        const toml::array& a = array(*only, key + ".scenes");
        if (a.empty()) fail(key + ".scenes", "must name at least one scene (leave it out for every scene)");
        for (size_t j = 0; j < a.size(); ++j) {
          const std::string n = string(*a.get(j), idx(key + ".scenes", j));
          if (std::find(u.only_scenes.begin(), u.only_scenes.end(), n) != u.only_scenes.end())
            fail(idx(key + ".scenes", j), "\"" + utf8_replaced(n.substr(0, 40)) + "\" is listed twice");
          u.only_scenes.push_back(n);
        }
      }
      const toml::node* ladder = t.get("ladder");
      if (!ladder) fail(key + ".ladder", "missing (required: {key = \"...\", values = [...]})");
      if (const auto* lt = ladder->as_table(); lt && lt->get("search")) {
        // A boundary search (sweep_search.h): its coarse grid is the ladder planned up front.
        keys(*lt, key + ".ladder", {"search"});
        u.search = read_search(*lt->get("search"), file_, key + ".ladder.search", u.ladder_key);
        check_setting_key(u.engine, u.ladder_key, key + ".ladder.search.key");
        if (set_keys.count(u.ladder_key))
          fail(key + ".ladder.search.key", u.ladder_key + " is also fixed in " + key + ".set");
        for (double v : search_coarse_grid(*u.search)) {
          u.ladder_values.push_back(v);
          u.ladder_texts.push_back(search_value_text(v));
          u.ladder_labels.push_back(search_value_text(v));
        }
        planned += u.ladder_values.size();
        if (s.scenes.size() * planned > kMaxSweepPoints)
          fail(key + ".ladder.search", "its coarse grid makes more than " + std::to_string(kMaxSweepPoints) +
                                           " points, the most a sweep plans");
      } else {
        read_axis(*ladder, key + ".ladder", u.engine, set_keys, u.ladder_key, u.ladder_values, u.ladder_texts,
                  u.ladder_labels, s.scenes.size(), 1, planned);
      }
      if (const toml::node* grid = t.get("grid")) {
        // Each grid value beyond the first adds the ladder's points again.
        planned -= u.ladder_values.size();
        read_axis(*grid, key + ".grid", u.engine, set_keys, u.grid_key, u.grid_values, u.grid_texts, u.grid_labels,
                  s.scenes.size(), u.ladder_values.size(), planned);
        if (u.grid_key == u.ladder_key) fail(key + ".grid.key", u.grid_key + " is also " + key + "'s ladder key");
      }
      s.setups.push_back(u);
    }
    return s;
  }

 private:
  // A sweep compares settings of one engine on fixed physics; a setup that could change the
  // scene itself would make its errors mean nothing.
  void check_setting_key(const std::string& engine, const std::string& k, const std::string& where) const {
    if (engine == reference_engine().name) {
      // The reference's settings: [engines.NAME] or their older spelling in [run].
      const std::string e = "engines." + engine + ".";
      if (k != "run.rtol" && k != "run.atol" && k != "run.method" && k != e + "rtol" && k != e + "atol" &&
          k != e + "method")
        fail(where, "\"" + k + "\" is not a setting of the " + engine + " model (" + e + "rtol, " + e + "atol, " + e +
                        "method, or run.rtol, run.atol, run.method); a sweep never changes the physics");
    } else if (k.rfind("engines." + engine + ".", 0) != 0 || k.size() == engine.size() + 9) {
      fail(where, "\"" + k + "\" is not a setting of " + engine + " (expected engines." + engine +
                      ".KEY); a sweep never changes the physics");
    }
  }

  std::string file_;
};

// The scene's own message without its "FILE: " prefix, with the file named at the end.
std::string quote_scene_error(const SceneError& e, const std::string& scene_path) {
  std::string msg = e.what();
  const std::string prefix = scene_path + ": ";
  if (msg.rfind(prefix, 0) == 0) msg = msg.substr(prefix.size()) + " (scene " + scene_path + ")";
  return msg;
}

// Which override a scene error is about: the key the scene names, matched against "KEY=VALUE".
std::optional<size_t> override_named(const SceneError& e, const std::string& scene_path,
                                     const std::vector<std::string>& set) {
  std::string msg = e.what();
  const std::string prefix = scene_path + ": ";
  if (msg.rfind(prefix, 0) != 0) return std::nullopt;
  msg = msg.substr(prefix.size());
  const std::string key = msg.substr(0, msg.find(": "));
  for (size_t j = 0; j < set.size(); ++j)
    if (trim(set[j].substr(0, set[j].find('='))) == key) return j;
  return std::nullopt;
}

}  // namespace

std::string fnv1a_hex(const std::vector<std::string>& parts) {
  std::uint64_t h = 0xcbf29ce484222325ULL;
  auto feed = [&h](unsigned char c) {
    h ^= c;
    h *= 0x100000001b3ULL;
  };
  for (const auto& p : parts) {
    for (unsigned char c : p) feed(c);
    feed(0);
  }
  char buf[17];
  std::snprintf(buf, sizeof buf, "%016llx", static_cast<unsigned long long>(h));
  return buf;
}

std::string sweep_point_id(const std::string& physics_hash, const SweepSetup& setup, const std::string& value_text,
                           int repeats, const std::string& grid_value_text) {
  std::vector<std::string> parts = {"tippe-sweep-point-1", physics_hash, setup.name, setup.engine};
  parts.push_back(std::to_string(setup.set.size()));
  for (const auto& s : setup.set) parts.push_back(s);
  parts.push_back(setup.ladder_key);
  parts.push_back(value_text);
  parts.push_back(std::to_string(repeats));
  // After everything a one-axis id hashes, so that those stay what they were.
  if (setup.has_grid()) {
    parts.push_back("grid");
    parts.push_back(setup.grid_key);
    parts.push_back(grid_value_text);
  }
  if (setup.search) {
    const SweepSearch& q = *setup.search;
    for (const std::string& x : {std::string("search"), q.criterion, json(q.from).dump(), json(q.to).dump(),
                                 json(q.resolution).dump(), std::to_string(q.per_decade)})
      parts.push_back(x);
    if (q.integer) parts.push_back("integer");
  }
  return fnv1a_hex(parts);
}

SweepPlan load_sweep(const std::string& path) {
  SweepReader reader(path);
  // The path is in sweep.json and every record: JSON, so UTF-8, checked before anything is read.
  if (!is_valid_utf8(path)) throw SceneError(utf8_replaced(path) + ": cannot read: the path is not valid UTF-8");
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
  SweepPlan plan;
  plan.spec = reader.read(root, text);
  const SweepSpec& s = plan.spec;

  std::map<std::string, size_t> scene_names;
  std::vector<std::vector<std::string>> scene_overrides;
  for (size_t i = 0; i < s.scenes.size(); ++i) {
    const SweepScene& e = s.scenes[i];
    const std::string key = idx("scenes", i);
    std::vector<std::string> over;
    const std::optional<double> duration = e.duration ? e.duration : s.duration;
    if (duration) over.push_back("run.duration=" + json(*duration).dump());
    Scene scene;
    try {
      scene = load_scene(e.path);
    } catch (const SceneError& x) {
      reader.fail(key, quote_scene_error(x, e.path));
    }
    if (!over.empty()) {
      try {
        scene = load_scene(e.path, over);
      } catch (const SceneError& x) {
        reader.fail(e.duration ? key + ".duration" : std::string("duration"), quote_scene_error(x, e.path));
      }
    }
    if (auto [it, fresh] = scene_names.emplace(scene.name, i); !fresh)
      reader.fail(key, "scene \"" + scene.name + "\" is already listed as " + idx("scenes", it->second));
    plan.physics_hashes.push_back(physics_hash(scene));
    plan.scenes.push_back(std::move(scene));
    scene_overrides.push_back(over);
  }

  for (size_t u = 0; u < s.setups.size(); ++u)
    for (size_t j = 0; j < s.setups[u].only_scenes.size(); ++j)
      if (!scene_names.count(s.setups[u].only_scenes[j])) {
        std::string list;
        for (const auto& [n, k] : scene_names) list += (list.empty() ? "" : ", ") + n;
        reader.fail(idx(idx("setup", u) + ".scenes", j), "\"" + utf8_replaced(s.setups[u].only_scenes[j].substr(0, 40)) +
                                                             "\" is not the name of a scene of this sweep (expected one of: " + list + ")");
      }
  std::vector<std::string> ids;
  for (size_t i = 0; i < s.scenes.size(); ++i) {
    const std::string& file = s.scenes[i].path;
    for (size_t u = 0; u < s.setups.size(); ++u) {
      const SweepSetup& setup = s.setups[u];
      if (!setup.runs_on(plan.scenes[i].name)) continue;
      const std::string key = idx("setup", u);
      std::vector<std::string> over = scene_overrides[i];
      over.insert(over.end(), setup.set.begin(), setup.set.end());
      try {
        load_scene(file, over);
      } catch (const SceneError& x) {
        const auto j = override_named(x, file, setup.set);
        reader.fail(j ? idx(key + ".set", *j) : key + ".set", quote_scene_error(x, file));
      }
      // A grid value the engine refuses is named as the grid's, whatever the ladder value.
      for (size_t g = 0; g < setup.grid_values.size(); ++g) {
        std::vector<std::string> grid_over = over;
        grid_over.push_back(setup.grid_key + "=" + setup.grid_texts[g]);
        try {
          load_scene(file, grid_over);
        } catch (const SceneError& x) {
          reader.fail(idx(key + ".grid.values", g), quote_scene_error(x, file));
        }
      }
      const size_t grid_count = setup.has_grid() ? setup.grid_values.size() : 1;
      for (size_t g = 0; g < grid_count; ++g) {
        for (size_t k = 0; k < setup.ladder_values.size(); ++k) {
          std::vector<std::string> point_over = over;
          point_over.push_back(setup.ladder_key + "=" + setup.ladder_texts[k]);
          if (setup.has_grid()) point_over.push_back(setup.grid_key + "=" + setup.grid_texts[g]);
          SweepPoint p;
          p.scene_index = i;
          p.setup_index = u;
          p.ladder_index = k;
          p.grid_index = g;
          p.ladder_value = setup.ladder_values[k];
          p.ladder_text = setup.ladder_texts[k];
          p.ladder_label = setup.ladder_labels[k];
          try {
            p.scene = load_scene(file, point_over);
          } catch (const SceneError& x) {
            // A search's coarse value: its ends are `from` and `to`, the others lie between.
            const std::string where =
                !setup.search ? idx(key + ".ladder.values", k)
                : k == 0      ? key + ".ladder.search.from"
                : k + 1 == setup.ladder_values.size() ? key + ".ladder.search.to"
                                                      : key + ".ladder.search (at " + setup.ladder_texts[k] + ")";
            reader.fail(where +
                            (setup.has_grid() ? " (with " + idx(key + ".grid.values", g) + ")" : std::string()),
                        quote_scene_error(x, file));
          }
          p.id = setup.has_grid()
                     ? sweep_point_id(plan.physics_hashes[i], setup, setup.ladder_texts[k], s.repeats, setup.grid_texts[g])
                     : sweep_point_id(plan.physics_hashes[i], setup, setup.ladder_texts[k], s.repeats);
          ids.push_back(p.id);
          plan.points.push_back(std::move(p));
        }
      }
    }
  }
  plan.plan_hash = fnv1a_hex(ids);
  plan.planned = plan.points.size();
  plan.scene_overrides = scene_overrides;
  return plan;
}

// ---- records ----------------------------------------------------------------------------------

namespace {

json number(double v) { return std::isfinite(v) ? json(v) : json(nullptr); }
json number(const std::optional<double>& v) { return v ? number(*v) : json(nullptr); }

// A record read back is input like any file: every field is checked for its type and range, and
// an error names its dotted key ("work.steps: ..."), never a bare json exception or a number
// converted with undefined behaviour (steps = 1e300 read as a long long).
class RecordReader {
 public:
  [[noreturn]] static void fail(const std::string& key, const std::string& why) {
    throw SweepRecordError(key + ": " + why);
  }
  static std::string dotted(const std::string& prefix, const char* key) {
    return prefix.empty() ? std::string(key) : prefix + "." + key;
  }
  static const json& at(const json& j, const std::string& prefix, const char* key) {
    if (!j.is_object()) fail(prefix.empty() ? "record" : prefix, std::string("expected an object, got ") + j.type_name());
    const auto it = j.find(key);
    if (it == j.end()) fail(dotted(prefix, key), "missing");
    return *it;
  }
  static std::string string(const json& j, const std::string& prefix, const char* key) {
    const json& v = at(j, prefix, key);
    if (!v.is_string()) fail(dotted(prefix, key), std::string("expected a string, got ") + v.type_name());
    return v.get<std::string>();
  }
  // A number or null (NaN: not finite when written); `lo` bounds it from below when given.
  static double number(const json& j, const std::string& prefix, const char* key,
                       double lo = -std::numeric_limits<double>::infinity()) {
    const json& v = at(j, prefix, key);
    if (v.is_null()) return std::nan("");
    if (!v.is_number()) fail(dotted(prefix, key), std::string("expected a number or null, got ") + v.type_name());
    const double x = v.get<double>();
    if (!(x >= lo)) fail(dotted(prefix, key), v.dump() + " is out of range (expected >= " + num(lo) + ")");
    return x;
  }
  static std::optional<double> optional(const json& j, const std::string& prefix, const char* key) {
    const double x = number(j, prefix, key);
    if (std::isnan(x)) return std::nullopt;
    return x;
  }
  // An integer in [lo, hi]: a float, a string or a value beyond long long is refused by name.
  static long long integer(const json& j, const std::string& prefix, const char* key, long long lo, long long hi) {
    const json& v = at(j, prefix, key);
    const std::string k = dotted(prefix, key);
    const std::string range = std::to_string(lo) + " <= " + key + " <= " + std::to_string(hi);
    if (!v.is_number_integer())
      fail(k, (v.is_number() ? v.dump() + " is not an integer" : std::string("expected an integer, got ") + v.type_name()) +
                  " (expected " + range + ")");
    long long x = 0;
    if (v.is_number_unsigned()) {
      if (v.get<std::uint64_t>() > static_cast<std::uint64_t>(hi)) fail(k, v.dump() + " is out of range (expected " + range + ")");
      x = static_cast<long long>(v.get<std::uint64_t>());
    } else {
      x = v.get<long long>();
    }
    if (x < lo || x > hi) fail(k, v.dump() + " is out of range (expected " + range + ")");
    return x;
  }
  // A setting key ("engines.ode.timestep"): the rule of names, as it reaches report labels.
  static std::string key(const json& j, const std::string& prefix, const char* k) {
    const std::string v = string(j, prefix, k);
    if (!is_valid_name(v))
      fail(dotted(prefix, k), "\"" + utf8_replaced(v.substr(0, 40)) + "\" is not a usable key (" + kNameRule + ")");
    return v;
  }
  // An axis value as text: a name or a number; the number of `value` (NaN: none) when it is one.
  static std::string label(const json& j, const std::string& prefix, const char* k, double value,
                           const char* value_key) {
    const std::string v = string(j, prefix, k);
    const std::string where = dotted(prefix, k);
    const std::string shown = "\"" + utf8_replaced(v.substr(0, 40)) + "\"";
    const std::optional<double> x = number_text_value(v);
    if (!x && !is_valid_name(v)) fail(where, shown + " is neither a number nor a usable name (" + kNameRule + ")");
    if (!std::isnan(value) && (!x || *x != value))
      fail(where, shown + " is not " + value_key + " " + num(value));
    if (std::isnan(value) && x) fail(where, shown + " is a number, but " + value_key + " is null");
    return v;
  }
  // The number a text is, all of it, finite; nullopt otherwise.
  static std::optional<double> number_text_value(const std::string& v) {
    if (v.empty() || v.size() > 40) return std::nullopt;
    char* end = nullptr;
    const double x = std::strtod(v.c_str(), &end);
    if (end != v.c_str() + v.size() || !std::isfinite(x)) return std::nullopt;
    // strtod reads "inf", "nan", hex and leading blanks; a label is none of those.
    if (v.find_first_not_of("0123456789+-.eE") != std::string::npos) return std::nullopt;
    return x;
  }
  // One of `names`.
  static std::string name(const json& j, const std::string& prefix, const char* key,
                          std::initializer_list<const char*> names) {
    const std::string v = string(j, prefix, key);
    std::string list;
    for (const char* n : names) {
      if (v == n) return v;
      list += (list.empty() ? "" : ", ") + std::string(n);
    }
    fail(dotted(prefix, key), "\"" + utf8_replaced(v.substr(0, 40)) + "\" is not one of " + list);
  }
};

// Bounds of a record's counts: a point's indices are below the plan's size, repeats as in a
// sweep file, work counters are counts (long long holds any a run can reach).
constexpr long long kMaxCount = std::numeric_limits<long long>::max();

json reference_json(const std::optional<SweepRecord::ReferenceRun>& f) {
  if (!f) return nullptr;
  return json{{"status", f->status},
              {"method", f->method},
              {"class", f->run_class},
              {"rtol", number(f->rtol)},
              {"cpu_seconds", number(f->cpu_seconds)},
              {"steps", f->steps},
              {"rhs_evaluations", f->rhs_evaluations},
              {"energy_initial", number(f->energy_initial)},
              {"energy_final", number(f->energy_final)},
              {"jellett_max_relative_drift", number(f->jellett_max_relative_drift)},
              {"final_tilt", number(f->final_tilt)}};
}

// The class a status implies when no trajectory is at hand (records from before classification).
std::string class_of_status(const std::string& status) {
  for (const char* c : {"ok", "diverged", "clamped", "failed", "contact_lost"})
    if (status == c) return status;
  return "failed";
}

json search_json(const std::optional<SweepSearch>& q) {
  if (!q) return nullptr;
  return json{{"criterion", q->criterion},
              {"from", q->from},
              {"to", q->to},
              {"resolution", q->resolution},
              {"per_decade", q->per_decade},
              {"integer", q->integer}};
}

// A record's search, with the rules of `ladder.search` in a sweep file (sweep_search.h).
SweepSearch search_from_json(const json& j) {
  using R = RecordReader;
  SweepSearch q;
  q.criterion = R::string(j, "search", "criterion");
  try {
    parse_criterion(q.criterion);
  } catch (const std::invalid_argument& e) {
    R::fail("search.criterion", e.what());
  }
  q.from = R::number(j, "search", "from", std::numeric_limits<double>::min());
  q.to = R::number(j, "search", "to", q.from);
  q.resolution = R::number(j, "search", "resolution", kMinSearchResolution);
  if (!(q.to > q.from) || !(q.resolution <= kMaxSearchResolution) || std::log10(q.to / q.from) > kMaxSearchDecades)
    R::fail("search", "not a search's range and resolution (expected 0 < from < to, at most " + num(kMaxSearchDecades) +
                          " decades, resolution <= " + num(kMaxSearchResolution) + ")");
  q.per_decade = static_cast<int>(R::integer(j, "search", "per_decade", 1, kMaxSearchPerDecade));
  if (j.contains("integer")) {
    const json& i = j.at("integer");
    if (!i.is_boolean()) R::fail("search.integer", std::string("expected true or false, got ") + i.type_name());
    q.integer = i.get<bool>();
    if (q.integer && (q.from != std::floor(q.from) || q.to != std::floor(q.to)))
      R::fail("search.integer", "from and to of an integer search are whole numbers");
  }
  return q;
}

}  // namespace

json to_json(const SweepRecord& r) {
  json cpu = json::array();
  for (double c : r.cpu_seconds_repeats) cpu.push_back(number(c));
  return json{
      {"format", "tippe-sweep-record-1"},
      {"point_id", r.point_id},
      {"scene", r.scene},
      {"scene_file", r.scene_file},
      {"physics_hash", r.physics_hash},
      {"scene_index", r.scene_index},
      {"setup", r.setup},
      {"engine", r.engine},
      {"set", r.set},
      {"ladder_key", r.ladder_key},
      {"ladder_value", number(r.ladder_value)},
      {"ladder_label", !r.ladder_label.empty() || !std::isfinite(r.ladder_value) ? r.ladder_label
                                                                                 : json(r.ladder_value).dump()},
      {"setup_index", r.setup_index},
      {"ladder_index", r.ladder_index},
      {"grid", r.grid_key.empty() ? json(nullptr)
                                  : json{{"key", r.grid_key},
                                         {"value", number(r.grid_value)},
                                         {"label", r.grid_label},
                                         {"index", r.grid_index}}},
      {"repeats", r.repeats},
      {"duration", number(r.duration)},
      {"status", r.status},
      {"status_time", number(r.status_time)},
      {"status_detail", r.status_detail},
      {"inversion_time", number(r.inversion_time)},
      {"stem_contact_time", number(r.stem_contact_time)},
      {"reference_inversion_time", number(r.reference_inversion_time)},
      {"reference_stem_contact_time", number(r.reference_stem_contact_time)},
      {"metrics", to_json(r.metrics)},
      {"work",
       {{"cpu_seconds", number(r.cpu_seconds)},
        {"cpu_seconds_repeats", cpu},
        {"wall_seconds", number(r.wall_seconds)},
        {"steps", r.steps},
        {"rhs_evaluations", r.rhs_evaluations},
        {"solver_iterations", r.solver_iterations}}},
      {"engine_version", r.engine_version},
      {"git_commit", r.git_commit},
      {"settings", r.settings},
      {"class", {{"name", r.run_class}, {"time", number(r.class_time)}, {"reason", r.class_reason}}},
      {"reference", reference_json(r.reference)},
      {"search", search_json(r.search)},
  };
}

SweepRecord sweep_record_from_json(const json& j) {
  using R = RecordReader;
  const std::string format = R::string(j, "", "format");
  if (format != "tippe-sweep-record-1")
    R::fail("format", "unknown record format \"" + utf8_replaced(format.substr(0, 40)) + "\" (expected tippe-sweep-record-1)");
  const long long max_index = static_cast<long long>(kMaxSweepPoints) - 1;
  SweepRecord r;
  r.point_id = R::string(j, "", "point_id");
  r.scene = R::string(j, "", "scene");
  r.scene_file = R::string(j, "", "scene_file");
  r.physics_hash = R::string(j, "", "physics_hash");
  r.scene_index = R::integer(j, "", "scene_index", 0, max_index);
  r.setup = R::string(j, "", "setup");
  r.engine = R::string(j, "", "engine");
  // Names read back become file names and report labels: the rule of names in input files.
  for (const auto& [key, name] : {std::pair<const char*, const std::string*>{"scene", &r.scene},
                                  {"setup", &r.setup},
                                  {"engine", &r.engine}})
    if (!is_valid_name(*name)) R::fail(key, "\"" + *name + "\" is not a usable name (" + kNameRule + ")");
  const json& set = R::at(j, "", "set");
  if (!set.is_array()) R::fail("set", std::string("expected an array, got ") + set.type_name());
  for (size_t i = 0; i < set.size(); ++i) {
    if (!set[i].is_string()) R::fail("set[" + std::to_string(i) + "]", std::string("expected a string, got ") + set[i].type_name());
    r.set.push_back(set[i].get<std::string>());
  }
  r.ladder_key = R::key(j, "", "ladder_key");
  r.ladder_value = R::number(j, "", "ladder_value");
  // Records from before categorical ladders carry only the number.
  if (j.contains("ladder_label"))
    r.ladder_label = R::label(j, "", "ladder_label", r.ladder_value, "ladder_value");
  else if (std::isnan(r.ladder_value))
    R::fail("ladder_label", "missing (required when ladder_value is null)");
  else
    r.ladder_label = json(r.ladder_value).dump();
  r.setup_index = R::integer(j, "", "setup_index", 0, max_index);
  r.ladder_index = R::integer(j, "", "ladder_index", 0, max_index);
  if (j.contains("grid") && !j.at("grid").is_null()) {
    const json& g = j.at("grid");
    r.grid_key = R::key(g, "grid", "key");
    r.grid_value = R::number(g, "grid", "value");
    r.grid_label = R::label(g, "grid", "label", r.grid_value, "grid.value");
    r.grid_index = R::integer(g, "grid", "index", 0, max_index);
  }
  r.repeats = R::integer(j, "", "repeats", 1, kMaxRepeats);
  r.duration = R::number(j, "", "duration", 0.0);
  // Any status reads (a newer build's reads with the class "failed" when no class is written); the
  // class, which names the report's CSS classes, must be a known one.
  r.status = R::string(j, "", "status");
  r.status_time = R::number(j, "", "status_time");
  r.status_detail = R::string(j, "", "status_detail");
  r.inversion_time = R::optional(j, "", "inversion_time");
  r.stem_contact_time = R::optional(j, "", "stem_contact_time");
  r.reference_inversion_time = R::optional(j, "", "reference_inversion_time");
  r.reference_stem_contact_time = R::optional(j, "", "reference_stem_contact_time");
  try {
    r.metrics = metrics_from_json(R::at(j, "", "metrics"));
  } catch (const json::exception& e) {
    // metrics_from_json names the field in its own words after json's "[json.exception...] ".
    std::string why = e.what();
    if (const size_t close = why.find("] "); close != std::string::npos) why.erase(0, close + 2);
    R::fail("metrics", why);
  }
  const json& w = R::at(j, "", "work");
  r.cpu_seconds = R::number(w, "work", "cpu_seconds", 0.0);
  const json& cpu = R::at(w, "work", "cpu_seconds_repeats");
  if (!cpu.is_array() || cpu.size() > static_cast<size_t>(kMaxRepeats))
    R::fail("work.cpu_seconds_repeats", "expected an array of at most " + std::to_string(kMaxRepeats) + " numbers");
  for (const json& c : cpu) {
    if (!c.is_null() && !c.is_number()) R::fail("work.cpu_seconds_repeats", std::string("expected numbers, got ") + c.type_name());
    r.cpu_seconds_repeats.push_back(c.is_null() ? std::nan("") : c.get<double>());
  }
  r.wall_seconds = R::number(w, "work", "wall_seconds", 0.0);
  r.steps = R::integer(w, "work", "steps", 0, kMaxCount);
  r.rhs_evaluations = R::integer(w, "work", "rhs_evaluations", 0, kMaxCount);
  r.solver_iterations = R::integer(w, "work", "solver_iterations", 0, kMaxCount);
  r.engine_version = R::string(j, "", "engine_version");
  r.git_commit = R::string(j, "", "git_commit");
  r.settings = R::at(j, "", "settings");
  if (!r.settings.is_object()) R::fail("settings", std::string("expected an object, got ") + r.settings.type_name());
  if (j.contains("class")) {
    const json& c = R::at(j, "", "class");
    r.run_class = R::name(c, "class", "name", {"ok", "diverged", "unphysical", "clamped", "failed", "contact_lost"});
    r.class_time = R::number(c, "class", "time");
    r.class_reason = R::string(c, "class", "reason");
  } else {
    r.run_class = class_of_status(r.status);
  }
  if (j.contains("reference") && !j.at("reference").is_null()) {
    const json& x = j.at("reference");
    SweepRecord::ReferenceRun f;
    f.status = R::string(x, "reference", "status");
    f.method = R::string(x, "reference", "method");
    f.run_class = R::name(x, "reference", "class", {"ok", "diverged", "unphysical", "clamped", "failed", "contact_lost"});
    f.rtol = R::number(x, "reference", "rtol", 0.0);
    f.cpu_seconds = R::number(x, "reference", "cpu_seconds", 0.0);
    f.steps = R::integer(x, "reference", "steps", 0, kMaxCount);
    f.rhs_evaluations = R::integer(x, "reference", "rhs_evaluations", 0, kMaxCount);
    f.energy_initial = R::number(x, "reference", "energy_initial");
    f.energy_final = R::number(x, "reference", "energy_final");
    f.jellett_max_relative_drift = R::number(x, "reference", "jellett_max_relative_drift");
    f.final_tilt = R::number(x, "reference", "final_tilt");
    r.reference = f;
  }
  if (j.contains("search") && !j.at("search").is_null()) r.search = search_from_json(j.at("search"));
  return r;
}

// An engine's status detail is not guaranteed UTF-8; a replacement character beats losing the point.
std::string to_jsonl(const SweepRecord& r) {
  return to_json(r).dump(-1, ' ', false, json::error_handler_t::replace) + "\n";
}

size_t complete_lines_length(const std::string& text) {
  const auto last = text.rfind('\n');
  return last == std::string::npos ? 0 : last + 1;
}

RecordsFile parse_records_text(const std::string& text, const std::string& name) {
  RecordsFile f;
  f.complete_bytes = complete_lines_length(text);
  f.partial_bytes = text.size() - f.complete_bytes;
  size_t pos = 0, line = 0;
  while (pos < f.complete_bytes) {
    const size_t end = text.find('\n', pos);
    ++line;
    const std::string l = text.substr(pos, end - pos);
    pos = end + 1;
    if (trim(l).empty()) continue;
    const std::string where = name + ":" + std::to_string(line) + ": ";
    const json j = json::parse(l, nullptr, /*allow_exceptions=*/false);
    if (j.is_discarded()) throw SweepRecordError(where + "not a sweep record: not one JSON value");
    try {
      f.records.push_back(sweep_record_from_json(j));
    } catch (const SweepRecordError& e) {
      throw SweepRecordError(where + e.what());
    }
    f.lines.push_back(line);
  }
  return f;
}

fs::path keep_aside(const fs::path& file) {
  std::error_code ec;
  if (!fs::exists(file, ec)) return {};
  for (int k = 1;; ++k) {
    const fs::path to = file.string() + ".old" + (k == 1 ? std::string() : "." + std::to_string(k));
    if (fs::exists(to, ec)) continue;
    fs::rename(file, to, ec);
    if (ec) throw std::runtime_error(file.string() + ": cannot keep it aside as " + to.string() + ": " + ec.message());
    return to;
  }
}

RecordsFile read_records(const std::string& path) {
  std::error_code ec;
  if (!fs::exists(path, ec)) return {};
  return parse_records_text(read_file_text(path), path);
}

RecordsFile recover_records(const std::string& path) {
  RecordsFile f = read_records(path);
  if (f.partial_bytes == 0) return f;
  const int fd = ::open(path.c_str(), O_WRONLY | O_CLOEXEC);
  if (fd < 0) throw std::runtime_error(path + ": cannot open to drop a partial line: " + std::strerror(errno));
  const bool ok = ::ftruncate(fd, static_cast<off_t>(f.complete_bytes)) == 0 && ::fsync(fd) == 0;
  const int err = errno;
  ::close(fd);
  if (!ok) throw std::runtime_error(path + ": cannot drop a partial line: " + std::strerror(err));
  return f;
}

SweepMeta parse_sweep_meta(const std::string& text, const std::string& name) {
  using R = RecordReader;
  SweepMeta m;
  m.meta = json::parse(text, nullptr, /*allow_exceptions=*/false);
  try {
    if (m.meta.is_discarded()) R::fail("sweep.json", "not JSON");
    m.sweep_hash = R::string(m.meta, "", "sweep_hash");
    m.plan_hash = R::string(m.meta, "", "plan_hash");
    if (m.meta.contains("points"))
      m.points = static_cast<size_t>(R::integer(m.meta, "", "points", 0, static_cast<long long>(kMaxSweepPoints)));
    const json shard = m.meta.value("shard", json(nullptr));
    if (!shard.is_null()) {
      // The bound of parse_shard, so that a shard read back is one `--shard` could have made.
      const long long count = R::integer(shard, "shard", "count", 1, 1000000);
      const long long index = R::integer(shard, "shard", "index", 0, count - 1);
      m.shard = SweepShard{static_cast<int>(index), static_cast<int>(count)};
      const json& ids = R::at(shard, "shard", "point_ids");
      if (!ids.is_array()) R::fail("shard.point_ids", std::string("expected an array, got ") + ids.type_name());
      if (ids.size() > m.points.value_or(kMaxSweepPoints))
        R::fail("shard.point_ids", std::to_string(ids.size()) + " ids, more than the sweep's " +
                                       std::to_string(m.points.value_or(kMaxSweepPoints)) + " points");
      for (size_t i = 0; i < ids.size(); ++i) {
        if (!ids[i].is_string())
          R::fail("shard.point_ids[" + std::to_string(i) + "]", std::string("expected a string, got ") + ids[i].type_name());
        m.shard_point_ids.push_back(ids[i].get<std::string>());
      }
    }
  } catch (const SweepRecordError& e) {
    throw SweepRecordError(name + ": " + e.what());
  }
  return m;
}

// ---- running ----------------------------------------------------------------------------------

namespace {

// The reference of one scene, shared read-only by every point of it.
struct Reference {
  RunRecord record;
  Trajectory trajectory;
  std::optional<SweepRecord::ReferenceRun> summary;  // filled once loaded or computed
  // A reference that failed is a result: every point of its scene is recorded as failed with
  // this reason (non-empty) instead of being run against nothing.
  std::string failure;
  double failure_time = std::nan("");
};

// A point whose scene's reference failed: a failed record carrying the reference's reason, so that
// the other scenes' points run and the report shows which scene and why.
SweepRecord reference_failed_record(SweepRecord r, const Scene& scene, const Reference& ref) {
  const double nan = std::nan("");
  r.status = to_string(RunStatus::Failed);
  r.status_time = ref.failure_time;
  r.status_detail = "not run: " + ref.failure;
  r.run_class = "failed";
  r.class_time = ref.failure_time;
  r.class_reason = r.status_detail;
  Metrics& m = r.metrics;
  m.inversion_event = m.stem_contact_event = "no_reference";
  for (double* v : {&m.tilt_max_error, &m.tilt_rms_error, &m.energy_max_error, &m.energy_final_ratio,
                    &m.energy_max_gain, &m.contact_path_rms_error, &m.contact_path_max_error, &m.com_path_rms_error,
                    &m.com_path_max_error, &m.latitude_rms_error, &m.jellett_max_relative_drift, &m.wall_seconds,
                    &m.cpu_seconds, &m.real_time_factor, &m.cost_ratio, &m.compared_until})
    *v = nan;
  r.cpu_seconds = r.wall_seconds = 0;
  r.cpu_seconds_repeats = {0.0};
  r.engine_version = "unknown";
  SweepRecord::ReferenceRun f;
  f.status = f.run_class = "failed";
  f.method = scene.run.method;
  f.rtol = scene.run.rtol;
  f.cpu_seconds = f.energy_initial = f.energy_final = f.jellett_max_relative_drift = f.final_tilt = nan;
  r.reference = f;
  return r;
}

SweepRecord::ReferenceRun reference_summary(const Scene& scene, const Reference& ref) {
  SweepRecord::ReferenceRun f;
  f.status = ref.record.status;
  f.method = scene.run.method;
  f.rtol = scene.run.rtol;
  f.cpu_seconds = ref.record.work.cpu_seconds;
  f.steps = ref.record.work.steps;
  f.rhs_evaluations = ref.record.work.rhs_evaluations;
  f.energy_initial = ref.record.energy_initial;
  f.energy_final = ref.record.energy_final;
  f.jellett_max_relative_drift = ref.record.jellett_max_relative_drift;
  f.final_tilt = ref.record.final_tilt;
  f.run_class = to_string(classify_run(scene, ref.record, nullptr, ref.trajectory).kind);
  return f;
}


// The reference's two cache files as texts, "summary.json" then "trajectory.csv", each behind its
// length: what a worker sends back and what the coordinator shares with every rank.
std::string pack_texts(const std::string& summary, const std::string& csv) {
  return std::to_string(summary.size()) + "\n" + summary + std::to_string(csv.size()) + "\n" + csv;
}
// Reads one pack_texts pair at `pos` (advanced past it); throws std::runtime_error when cut short.
std::pair<std::string, std::string> unpack_texts(const std::string& bytes, size_t& pos) {
  auto field = [&]() {
    const size_t nl = bytes.find('\n', pos);
    if (nl == std::string::npos) throw std::runtime_error("reference message cut short");
    const size_t n = std::stoull(bytes.substr(pos, nl - pos));
    if (nl + 1 + n > bytes.size()) throw std::runtime_error("reference message cut short");
    std::string text = bytes.substr(nl + 1, n);
    pos = nl + 1 + n;
    return text;
  };
  std::string summary = field();
  return {std::move(summary), field()};
}

// What a reference's task sends back: 'R' and its two cache files' texts, or 'F' and, for a
// reference that failed, the time and the reason (a result, not an error: its scene's points are
// recorded as failed).
std::string failed_reference_text(double time, const std::string& why) {
  return "F" + pack_texts(json(number(time)).dump(), why);
}
// Reads a failed_reference_text at `pos` into ref; false (pos unmoved) for an 'R' entry.
bool read_failed_reference(const std::string& bytes, size_t& pos, Reference& ref) {
  if (pos >= bytes.size() || (bytes[pos] != 'F' && bytes[pos] != 'R')) throw std::runtime_error("reference message cut short");
  if (bytes[pos] == 'R') {
    ++pos;
    return false;
  }
  ++pos;
  const auto [time, why] = unpack_texts(bytes, pos);
  const json t = json::parse(time);
  ref.failure_time = t.is_number() ? t.get<double>() : std::nan("");
  ref.failure = why;
  return true;
}

// Runs the reference at the scene's own tolerances, on whichever process the task lands.
std::string compute_reference_texts(const Scene& scene) {
  CsvTrajectoryText csv;
  TrajectorySink sink({&csv});
  RunRecord record;
  try {
    auto sim = make_simulator(reference_engine().name, scene);
    record = run_simulator(*sim, scene, &sink);
  } catch (const std::exception& e) {
    return failed_reference_text(sink.trajectory.size() ? sink.trajectory.t.back() : 0.0,
                                 "the reference run of " + scene.name + " failed: exception: " + e.what());
  }
  if (record.status == to_string(RunStatus::Failed) || sink.trajectory.size() == 0)
    return failed_reference_text(record.status_time, "the reference run of " + scene.name + " failed at t = " +
                                                         num(record.status_time) + ": " + record.status_detail);
  return "R" + pack_texts(to_json(record).dump(2) + "\n", csv.text);
}

// Into the cache (the summary last, so that its presence says the trajectory beside it is
// complete) and into memory, read back from the very texts every other rank will read. A failed
// reference is kept in memory only: the next run of the sweep finds its points recorded.
void store_reference(const fs::path& dir, const Scene& scene, const std::string& hash, const std::string& texts,
                     Reference& ref) {
  size_t pos = 0;
  if (read_failed_reference(texts, pos, ref)) return;
  const auto [summary, csv] = unpack_texts(texts, pos);
  fs::create_directories(dir);
  write_file_atomic((dir / "trajectory.csv").string(), csv);
  write_file_atomic((dir / "summary.json").string(), summary);
  const std::string why = reference_from_text(summary, csv, scene, hash, dir.string(), ref.record, ref.trajectory);
  if (!why.empty()) throw std::runtime_error("reference of " + scene.name + " does not read back: " + why);
}

json settings_object(const SettingsList& s) {
  json o = json::object();
  for (const auto& [k, v] : s) o[k] = v;
  return o;
}

std::string exception_text(const std::exception_ptr& e) {
  try {
    std::rethrow_exception(e);
  } catch (const std::exception& x) {
    return x.what();
  } catch (...) {
    return "unknown exception";
  }
}

// Runs one point `repeats` times on the calling thread; errors come from the first run (the
// runs are deterministic), the CPU time is the minimum, so that a busy machine inflates it least.
SweepRecord run_point(const SweepPlan& plan, const SweepPoint& p, const Reference& ref) {
  const SweepSetup& setup = plan.spec.setups[p.setup_index];
  SweepRecord r;
  r.point_id = p.id;
  r.scene = p.scene.name;
  r.scene_file = plan.spec.scenes[p.scene_index].file;
  r.physics_hash = plan.physics_hashes[p.scene_index];
  r.scene_index = static_cast<long long>(p.scene_index);
  r.setup = setup.name;
  r.engine = setup.engine;
  r.set = setup.set;
  r.ladder_key = setup.ladder_key;
  r.ladder_value = p.ladder_value;
  r.ladder_label = p.ladder_label;
  r.search = setup.search;
  r.setup_index = static_cast<long long>(p.setup_index);
  r.ladder_index = static_cast<long long>(p.ladder_index);
  if (setup.has_grid()) {
    r.grid_key = setup.grid_key;
    r.grid_value = setup.grid_values[p.grid_index];
    r.grid_label = setup.grid_labels[p.grid_index];
    r.grid_index = static_cast<long long>(p.grid_index);
  }
  r.repeats = plan.spec.repeats;
  r.duration = p.scene.run.duration;
  r.reference_inversion_time = ref.record.inversion_time;
  r.reference_stem_contact_time = ref.record.stem_contact_time;
  r.git_commit = build_info().git_commit;
  if (!ref.failure.empty()) return reference_failed_record(std::move(r), p.scene, ref);

  RunRecord first;
  TrajectorySink sink;
  double cpu_min = std::numeric_limits<double>::infinity(), wall_min = cpu_min;
  for (int k = 0; k < plan.spec.repeats; ++k) {
    RunRecord run;
    std::unique_ptr<Simulator> sim;
    try {
      sim = make_simulator(setup.engine, p.scene);
      run = run_simulator(*sim, p.scene, k == 0 ? &sink : nullptr);
    } catch (const Interrupted&) {
      throw;  // a signal is not a result of the point
    } catch (...) {
      // An engine that refuses the scene or throws mid-run is a failed point, not a failed sweep.
      run = RunRecord{};
      run.engine = setup.engine;
      run.status = to_string(RunStatus::Failed);
      run.status_time = sink.trajectory.size() ? sink.trajectory.t.back() : 0.0;
      run.status_detail = "exception: " + exception_text(std::current_exception());
      if (sim) {
        run.engine_version = sim->version();
        run.settings = sim->settings();
        run.work = sim->work();
      }
      if (k == 0) first = run;
      break;
    }
    cpu_min = std::min(cpu_min, run.work.cpu_seconds);
    wall_min = std::min(wall_min, run.work.wall_seconds);
    r.cpu_seconds_repeats.push_back(run.work.cpu_seconds);
    if (k == 0) first = std::move(run);
  }
  if (r.cpu_seconds_repeats.empty()) {
    cpu_min = first.work.cpu_seconds;
    wall_min = first.work.wall_seconds;
    r.cpu_seconds_repeats.push_back(cpu_min);
  }

  r.status = first.status;
  r.status_time = first.status_time;
  r.status_detail = first.status_detail;
  r.inversion_time = first.inversion_time;
  r.stem_contact_time = first.stem_contact_time;
  r.metrics = compare_runs(ref.record, ref.trajectory, first, sink.trajectory, p.scene);
  r.cpu_seconds = cpu_min;
  r.wall_seconds = wall_min;
  r.metrics.cpu_seconds = cpu_min;
  r.metrics.wall_seconds = wall_min;
  r.metrics.cost_ratio = ref.record.work.cpu_seconds > 0 ? cpu_min / ref.record.work.cpu_seconds : 0.0;
  r.metrics.real_time_factor = wall_min > 0 && std::isfinite(first.final_time) ? first.final_time / wall_min : 0.0;
  r.steps = first.work.steps;
  r.rhs_evaluations = first.work.rhs_evaluations;
  r.solver_iterations = first.work.solver_iterations;
  r.engine_version = first.engine_version.empty() ? "unknown" : first.engine_version;
  r.settings = settings_object(first.settings);
  const RunClass c = classify_run(p.scene, first, &r.metrics, sink.trajectory);
  r.run_class = to_string(c.kind);
  r.class_time = c.time;
  r.class_reason = c.reason;
  r.reference = ref.summary;
  return r;
}

// A priori cost of a point in arbitrary units: steps for a time-step ladder; per setup, the
// progress line scales it by the seconds per unit measured on that setup's finished points.
double point_weight(const SweepPlan& plan, const SweepPoint& p) {
  const SweepSetup& s = plan.spec.setups[p.setup_index];
  const auto is_step = [](const std::string& k) {
    return k.size() >= 8 && k.compare(k.size() - 8, 8, "timestep") == 0;
  };
  // The time step may be either axis of a grid.
  double v = is_step(s.ladder_key) ? p.ladder_value : std::nan("");
  if (s.has_grid() && is_step(s.grid_key)) v = s.grid_values[p.grid_index];
  const double per_time = v > 0 ? 1.0 / v : (s.engine == reference_engine().name ? 100.0 : 1e4);
  return plan.spec.repeats * p.scene.run.duration * per_time;
}

std::string clock_text(double seconds) {
  const long long s = static_cast<long long>(std::llround(std::max(0.0, seconds)));
  char buf[32];
  if (s >= 3600)
    std::snprintf(buf, sizeof buf, "%lld:%02lld:%02lld", s / 3600, s / 60 % 60, s % 60);
  else
    std::snprintf(buf, sizeof buf, "%lld:%02lld", s / 60, s % 60);
  return buf;
}

// The one progress line: points done, what runs, elapsed and an estimate of the time left. Each
// setup's wall time is fitted as a + b * weight over its finished points: a is the per-point
// overhead (a MuJoCo model compile, the comparison), which would make a plain ratio taken on a
// short point overestimate every long one.
class SweepProgress {
 public:
  // total: the points of this run's share (the whole plan, or a shard's); lines: one full line
  // every 10 s instead of redrawing one (stderr passed on by an MPI launcher).
  SweepProgress(const SweepPlan& plan, std::vector<size_t> todo, size_t total, size_t skipped, int jobs, bool lines)
      : plan_(plan),
        todo_(std::move(todo)),
        total_(total),
        skipped_(skipped),
        jobs_(jobs),
        lines_(lines),
        start_(now()),
        started_(plan.points.size(), -1.0),
        finished_(plan.points.size(), false) {}

  void begin(size_t point) {
    std::lock_guard<std::mutex> lock(m_);
    started_[point] = now() - start_;
  }
  void end(size_t point, double wall) {
    std::lock_guard<std::mutex> lock(m_);
    finished_[point] = true;
    ++done_;
    samples_[plan_.points[point].setup_index].emplace_back(point_weight(plan_, plan_.points[point]), wall);
  }

  void print(bool final_line) {
    std::lock_guard<std::mutex> lock(m_);
    const double elapsed = now() - start_;
    if (lines_ && !final_line && elapsed - last_line_ < kProgressLineSeconds) return;
    last_line_ = elapsed;
    char buf[160];
    std::snprintf(buf, sizeof buf, "[sweep] %zu/%zu points", done_ + skipped_, total_);
    std::string line = buf;
    if (skipped_) line += " (" + std::to_string(skipped_) + " from an earlier run)";
    size_t running = 0;
    for (size_t p : todo_) running += started_[p] >= 0 && !finished_[p];
    if (!final_line) line += " | " + std::to_string(running) + " running";
    line += " | " + clock_text(elapsed) + " elapsed";
    if (!final_line) {
      const double left = estimate_left(elapsed);
      line += std::isfinite(left) ? " | ~" + clock_text(left) + " left" : " | estimating";
    }
    if (lines_) {
      std::fprintf(stderr, "%s\n", line.c_str());
      std::fflush(stderr);
      return;
    }
    const size_t len = line.size();
    if (line.size() < width_) line.append(width_ - line.size(), ' ');
    width_ = len;
    std::fprintf(stderr, "\r%s", line.c_str());
    if (final_line) std::fputc('\n', stderr);
    std::fflush(stderr);
  }

 private:
  static double now() {
    return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
  }
  // Expected wall seconds of a point of weight w of this setup; NaN before any point finished.
  double expect(size_t setup, double w) const {
    auto it = samples_.find(setup);
    double sw = 0, st = 0;
    if (it == samples_.end()) {
      // No point of this setup yet: the ratio over every finished point.
      for (const auto& [s, v] : samples_)
        for (const auto& [x, t] : v) {
          sw += x;
          st += t;
        }
      return sw > 0 ? st / sw * w : std::nan("");
    }
    const auto& v = it->second;
    double sww = 0, swt = 0;
    for (const auto& [x, t] : v) {
      sw += x;
      st += t;
      sww += x * x;
      swt += x * t;
    }
    const double n = static_cast<double>(v.size()), det = n * sww - sw * sw;
    if (v.size() >= 2 && det > 1e-12 * sww * n) {
      const double b = (n * swt - sw * st) / det, a = (st - b * sw) / n;
      if (b > 0 && a >= 0) return a + b * w;
    }
    return sw > 0 ? st / sw * w : std::nan("");
  }
  double estimate_left(double elapsed) const {
    if (samples_.empty()) return std::nan("");
    double left = 0;
    for (size_t p : todo_) {
      if (finished_[p]) continue;
      const double expect = this->expect(plan_.points[p].setup_index, point_weight(plan_, plan_.points[p]));
      left += started_[p] >= 0 ? std::max(0.0, expect - (elapsed - started_[p])) : expect;
    }
    return left / jobs_;
  }

  const SweepPlan& plan_;
  std::vector<size_t> todo_;
  size_t total_, skipped_;
  int jobs_;
  bool lines_;
  double last_line_ = -1e9;
  double start_;
  std::mutex m_;
  std::vector<double> started_;
  std::vector<bool> finished_;
  size_t done_ = 0;
  std::map<size_t, std::vector<std::pair<double, double>>> samples_;  // setup -> (weight, wall)
  size_t width_ = 0;
};

// Appends whole lines to records.jsonl, each flushed to disk before the next point is counted.
class RecordAppender {
 public:
  explicit RecordAppender(const fs::path& path) : path_(path.string()) {
    const bool existed = fs::exists(path);
    fd_ = ::open(path_.c_str(), O_WRONLY | O_APPEND | O_CREAT | O_CLOEXEC, 0644);
    if (fd_ < 0) throw std::runtime_error(path_ + ": cannot open: " + std::strerror(errno));
    if (!existed) {
      // The new file's directory entry must survive a crash too.
      const int dir = ::open(path.parent_path().empty() ? "." : path.parent_path().c_str(), O_RDONLY | O_CLOEXEC);
      if (dir >= 0) {
        ::fsync(dir);
        ::close(dir);
      }
    }
  }
  ~RecordAppender() {
    if (fd_ >= 0) ::close(fd_);
  }
  RecordAppender(const RecordAppender&) = delete;
  RecordAppender& operator=(const RecordAppender&) = delete;

  void append(const std::string& line) {
    std::lock_guard<std::mutex> lock(m_);
    size_t off = 0;
    while (off < line.size()) {
      const ssize_t n = ::write(fd_, line.data() + off, line.size() - off);
      if (n < 0 && errno == EINTR) continue;
      if (n <= 0) throw std::runtime_error(path_ + ": cannot write: " + std::strerror(errno));
      off += static_cast<size_t>(n);
    }
    if (::fsync(fd_) != 0) throw std::runtime_error(path_ + ": cannot sync: " + std::strerror(errno));
  }

 private:
  std::string path_;
  int fd_ = -1;
  std::mutex m_;
};


json shard_json(const SweepPlan& plan, const std::optional<SweepShard>& shard, const std::vector<size_t>& share) {
  if (!shard) return nullptr;
  json ids = json::array();
  // The points planned up front: a boundary search's later points follow their search's shard.
  for (size_t i : share)
    if (i < plan.planned) ids.push_back(plan.points[i].id);
  return json{{"index", shard->index}, {"count", shard->count}, {"point_ids", ids}};
}

json sweep_json(const SweepPlan& plan, const json& shard) {
  const Provenance p = current_provenance();
  json scenes = json::array(), setups = json::array();
  for (const Scene& s : plan.scenes) scenes.push_back(s.name);
  for (const SweepSetup& s : plan.spec.setups) setups.push_back(s.name);
  return json{{"format", "tippe-sweep-1"},
              {"sweep_file", plan.spec.file},
              {"sweep_hash", plan.spec.hash},
              {"plan_hash", plan.plan_hash},
              {"description", plan.spec.description},
              {"repeats", plan.spec.repeats},
              {"points", plan.planned},
              {"scenes", scenes},
              {"setups", setups},
              {"sweep_text", plan.spec.text},
              {"shard", shard},
              {"provenance", to_json(p)}};
}


std::string shard_text(const std::optional<SweepShard>& shard) {
  if (!shard) return "the whole sweep";
  return "shard " + std::to_string(shard->index) + "/" + std::to_string(shard->count);
}

// What the coordinator found in OUT and decided, shared with every rank: which points run, in
// which order, and which references must be computed.
struct Prepared {
  std::vector<size_t> todo;        // indices into plan.points, in the order they are handed out
  std::vector<size_t> needed;      // scenes with a point in todo
  std::vector<size_t> to_compute;  // of those, the ones not in the cache
  size_t share = 0, skipped = 0, cached = 0, partial_bytes = 0;
};

std::string encode(const Prepared& p) {
  std::ostringstream ss;
  auto list = [&](const std::vector<size_t>& v) {
    ss << v.size();
    for (size_t x : v) ss << ' ' << x;
    ss << '\n';
  };
  ss << p.share << ' ' << p.skipped << ' ' << p.cached << ' ' << p.partial_bytes << '\n';
  list(p.todo);
  list(p.needed);
  list(p.to_compute);
  return ss.str();
}

Prepared decode(const std::string& bytes) {
  std::istringstream ss(bytes);
  Prepared p;
  auto list = [&](std::vector<size_t>& v) {
    size_t n = 0;
    ss >> n;
    v.resize(n);
    for (size_t& x : v) ss >> x;
  };
  ss >> p.share >> p.skipped >> p.cached >> p.partial_bytes;
  list(p.todo);
  list(p.needed);
  list(p.to_compute);
  if (!ss) throw std::runtime_error("MPI: the coordinator's plan message is cut short");
  return p;
}

// The coordinator's half of the start: checks OUT, takes its lock, recovers records.jsonl and
// decides what runs. Throws SweepInputError before anything is written.
Prepared prepare(const SweepPlan& plan, const SweepOptions& o, std::unique_ptr<OutputDir>& lock,
                 std::vector<Reference>& refs) {
  if (o.jobs < 1) throw SweepInputError("jobs must be at least 1, got " + std::to_string(o.jobs));
  if (o.out_dir.empty()) throw SweepInputError("no output directory");
  const fs::path out = o.out_dir;
  const fs::path sweep_file = out / "sweep.json", records_file = out / "records.jsonl";
  std::vector<size_t> share;
  if (o.shard) {
    share = shard_points(plan, *o.shard);
  } else {
    share.resize(plan.points.size());
    for (size_t i = 0; i < share.size(); ++i) share[i] = i;
  }
  const json shard = shard_json(plan, o.shard, share);

  // What OUT holds is checked before anything is written to it.
  bool fresh = true;
  std::error_code ec;
  if (fs::exists(sweep_file, ec)) {
    std::optional<SweepMeta> old;
    try {
      old = parse_sweep_meta(read_file_text(sweep_file.string()), sweep_file.string());
    } catch (const std::exception& e) {
      if (!o.restart)
        throw SweepInputError(std::string(e.what()) + " (not a sweep record); give --restart to begin the directory again");
    }
    if (old) {
      const std::string& h = old->sweep_hash;
      const std::string& ph = old->plan_hash;
      if (h != plan.spec.hash && !o.restart)
        throw SweepInputError(sweep_file.string() + ": sweep_hash: " + out.string() +
                              " was started with another sweep file (hash " + utf8_replaced(h) + ", " + plan.spec.file +
                              " now has " + plan.spec.hash + "); give --restart to begin it again, or another --out");
      if (ph != plan.plan_hash && !o.restart)
        throw SweepInputError(sweep_file.string() + ": plan_hash: the physics of a scene of " + plan.spec.file +
                              " changed since " + out.string() +
                              " was started; give --restart to begin it again, or another --out");
      const json old_shard = old->meta.value("shard", json(nullptr));
      if (old_shard != shard && h == plan.spec.hash && ph == plan.plan_hash && !o.restart)
        throw SweepInputError(sweep_file.string() + ": shard: " + out.string() + " holds " + shard_text(old->shard) +
                              ", this run is " + shard_text(o.shard) +
                              "; give each shard its own --out (or --restart to begin it again)");
      fresh = h != plan.spec.hash || ph != plan.plan_hash || old_shard != shard;
    }
  } else if (fs::exists(records_file, ec) && !o.restart) {
    throw SweepInputError(records_file.string() + ": records without " + sweep_file.string() +
                          "; give --restart to begin the directory again, or another --out");
  }

  lock = std::make_unique<OutputDir>(out);
  if (fresh || o.restart) {
    // Beginning again: earlier records are kept aside, never silently mixed with the new ones.
    keep_aside(records_file);
    write_file_atomic(sweep_file.string(), sweep_json(plan, shard).dump(2) + "\n");
  }

  Prepared p;
  p.share = share.size();
  RecordsFile existing;
  try {
    existing = recover_records(records_file.string());
  } catch (const std::exception& e) {
    throw SweepInputError(std::string(e.what()) + "; give --restart to begin the directory again, or another --out");
  }
  p.partial_bytes = existing.partial_bytes;
  if (existing.partial_bytes)
    std::fprintf(stderr, "tippe: %s: dropped a partial last line (%zu bytes); its point runs again\n",
                 records_file.string().c_str(), existing.partial_bytes);
  // Records read back are input: each must be a point of this run's share, where the plan has it.
  std::map<std::string, size_t> in_share;
  for (size_t i : share) in_share.emplace(plan.points[i].id, i);
  for (size_t k = 0; k < existing.records.size(); ++k) {
    const SweepRecord& r = existing.records[k];
    const std::string where = records_file.string() + ":" + std::to_string(existing.lines[k]) + ": ";
    const auto it = in_share.find(r.point_id);
    if (it == in_share.end())
      throw SweepInputError(where + "point_id: " + utf8_replaced(r.point_id.substr(0, 40)) + " is not a point of " +
                            (o.shard ? shard_text(o.shard) + " of " : std::string()) + plan.spec.file +
                            "'s plan; give --restart to begin the directory again, or another --out");
    const SweepPoint& p = plan.points[it->second];
    for (const auto& [key, got, want] :
         {std::make_tuple("scene_index", r.scene_index, p.scene_index), std::make_tuple("setup_index", r.setup_index, p.setup_index),
          std::make_tuple("ladder_index", r.ladder_index, p.ladder_index),
          std::make_tuple("grid.index", r.grid_index, p.grid_index)})
      if (got != static_cast<long long>(want))
        throw SweepInputError(where + key + ": " + std::to_string(got) + " is not point " + r.point_id + "'s (" +
                              std::to_string(want) + " in the plan); give --restart to begin the directory again");
  }
  std::set<std::string> done;
  size_t duplicates = 0;
  for (const SweepRecord& r : existing.records) duplicates += !done.insert(r.point_id).second;
  if (duplicates)
    std::fprintf(stderr, "tippe: warning: %s: %zu duplicate point ids (the report uses the first)\n",
                 records_file.string().c_str(), duplicates);

  std::vector<size_t> todo;
  for (size_t i : share)
    if (!done.count(plan.points[i].id)) todo.push_back(i);
  p.skipped = share.size() - todo.size();
  // The two cheapest points of each setup first: a few seconds in, every setup's overhead and
  // seconds per unit of weight are measured and the time left is a real estimate. Then the
  // longest first, so that the last point to finish is a short one and the cores stay busy.
  std::stable_sort(todo.begin(), todo.end(), [&](size_t a, size_t b) {
    return point_weight(plan, plan.points[a]) > point_weight(plan, plan.points[b]);
  });
  std::vector<size_t> order;
  std::map<size_t, int> calibration;
  std::set<size_t> first;
  for (auto it = todo.rbegin(); it != todo.rend(); ++it)
    if (++calibration[plan.points[*it].setup_index] <= 2) {
      order.push_back(*it);
      first.insert(*it);
    }
  for (size_t q : todo)
    if (!first.count(q)) order.push_back(q);
  p.todo = std::move(order);

  for (size_t i = 0; i < plan.scenes.size(); ++i)
    if (std::any_of(p.todo.begin(), p.todo.end(), [&](size_t q) { return plan.points[q].scene_index == i; }))
      p.needed.push_back(i);
  for (size_t i : p.needed) {
    const fs::path dir = out / "reference" / plan.physics_hashes[i];
    // The comparison cache's rule: same physics, same build, complete files.
    if (load_cached_reference(dir, plan.scenes[i], plan.physics_hashes[i], refs[i].record, refs[i].trajectory))
      ++p.cached;
    else
      p.to_compute.push_back(i);
  }
  return p;
}

}  // namespace

std::string from_coordinator(TaskFarm& farm, const std::function<std::string()>& make) {
  std::string message;
  if (farm.coordinator()) {
    try {
      message = "ok\n" + make();
    } catch (const SweepInputError& e) {
      message = std::string("input\n") + e.what();
    } catch (const OutputError& e) {
      // An output directory that cannot be used (held by another tippe, not creatable) is bad input too.
      message = std::string("input\n") + e.what();
    } catch (const std::exception& e) {
      message = std::string("error\n") + e.what();
    }
  }
  farm.broadcast(message);
  const size_t nl = message.find('\n');
  const std::string kind = message.substr(0, nl);
  message.erase(0, nl + 1);
  if (kind == "input") throw SweepInputError(message);
  if (kind != "ok") throw std::runtime_error(message);
  return message;
}

SweepShard parse_shard(const std::string& text) {
  const size_t slash = text.find('/');
  auto number = [&](const std::string& part, long long& v) {
    if (part.empty() || part.size() > 9 || !std::all_of(part.begin(), part.end(), ::isdigit)) return false;
    v = std::stoll(part);
    return true;
  };
  long long i = -1, n = -1;
  if (slash == std::string::npos || !number(text.substr(0, slash), i) || !number(text.substr(slash + 1), n))
    throw std::invalid_argument("--shard \"" + text + "\": expected I/N, e.g. 0/4");
  if (n < 1 || n > 1000000 || i >= n)
    throw std::invalid_argument("--shard \"" + text + "\": I/N needs 1 <= N <= 1000000 and 0 <= I < N");
  return SweepShard{static_cast<int>(i), static_cast<int>(n)};
}

std::vector<size_t> shard_points(const SweepPlan& plan, const SweepShard& shard) {
  // Longest processing time first: the points by a priori weight, heaviest first (ties in plan
  // order), each to the shard with the least weight so far (ties to the lowest shard). A pure
  // function of the plan, so every job of an array computes the same partition.
  // A boundary search is one unit (its later points depend on its earlier records, so they
  // must be in one shard), weighed by its points planned up front; any other point is its own.
  std::vector<size_t> unit_of(plan.points.size());
  std::map<std::tuple<size_t, size_t, size_t>, size_t> search_unit;
  std::vector<double> w;
  for (size_t i = 0; i < plan.points.size(); ++i) {
    const SweepPoint& p = plan.points[i];
    size_t u = w.size();
    if (plan.spec.setups[p.setup_index].search)
      u = search_unit.emplace(std::make_tuple(p.scene_index, p.setup_index, p.grid_index), w.size()).first->second;
    if (u == w.size()) w.push_back(0.0);
    unit_of[i] = u;
    if (i < plan.planned) w[u] += point_weight(plan, p);
  }
  std::vector<size_t> byweight(w.size());
  for (size_t i = 0; i < byweight.size(); ++i) byweight[i] = i;
  std::stable_sort(byweight.begin(), byweight.end(), [&](size_t a, size_t b) { return w[a] > w[b]; });
  std::vector<double> load(static_cast<size_t>(shard.count), 0.0);
  std::vector<bool> unit_mine(w.size(), false);
  for (size_t u : byweight) {
    const size_t s = static_cast<size_t>(std::min_element(load.begin(), load.end()) - load.begin());
    load[s] += w[u];
    unit_mine[u] = s == static_cast<size_t>(shard.index);
  }
  std::vector<size_t> mine;
  for (size_t i = 0; i < plan.points.size(); ++i)
    if (unit_mine[unit_of[i]]) mine.push_back(i);
  return mine;
}

SweepOutcome run_sweep(const SweepPlan& plan, const SweepOptions& o) {
  auto farm = make_thread_farm(o.jobs);
  return run_sweep(plan, o, *farm);
}

SweepOutcome run_sweep(const SweepPlan& plan, const SweepOptions& o, TaskFarm& farm) {
  const fs::path out = o.out_dir;
  const fs::path records_file = out / "records.jsonl";
  const auto t0 = std::chrono::steady_clock::now();
  std::vector<Reference> refs(plan.scenes.size());

  // 1. The coordinator decides; its decision (or its refusal) reaches every rank.
  std::unique_ptr<OutputDir> lock;
  Prepared prep;
  const std::string decision = from_coordinator(farm, [&] {
    prep = prepare(plan, o, lock, refs);
    return encode(prep);
  });
  if (!farm.coordinator()) prep = decode(decision);

  SweepOutcome outcome;
  outcome.points = prep.share;
  outcome.skipped = prep.skipped;
  outcome.references_cached = prep.cached;
  outcome.partial_bytes_dropped = prep.partial_bytes;

  // 2. Each missing reference is computed once, wherever a worker is free; the coordinator caches it.
  if (farm.coordinator() && o.progress && !prep.to_compute.empty())
    std::fprintf(stderr, "[sweep] computing %zu reference(s)\n", prep.to_compute.size());
  farm.run(
      prep.to_compute.size(), [&](size_t k) { return compute_reference_texts(plan.scenes[prep.to_compute[k]]); },
      [&](size_t k, std::string&& texts) {
        const size_t i = prep.to_compute[k];
        store_reference(out / "reference" / plan.physics_hashes[i], plan.scenes[i], plan.physics_hashes[i], texts,
                        refs[i]);
      });

  // 3. Every rank gets the same texts of every reference it needs, and reads them the way the cache is read.
  if (farm.distributed()) {
    const std::string bytes = from_coordinator(farm, [&] {
      std::string texts;
      for (size_t i : prep.needed) {
        if (!refs[i].failure.empty()) {
          texts += failed_reference_text(refs[i].failure_time, refs[i].failure);
          continue;
        }
        const fs::path dir = out / "reference" / plan.physics_hashes[i];
        texts += "R" + pack_texts(read_file_text((dir / "summary.json").string()),
                                  read_file_text((dir / "trajectory.csv").string()));
      }
      return texts;
    });
    std::string error;
    if (!farm.coordinator()) {
      try {
        size_t pos = 0;
        for (size_t i : prep.needed) {
          if (read_failed_reference(bytes, pos, refs[i])) continue;
          const auto [summary, csv] = unpack_texts(bytes, pos);
          const std::string why = reference_from_text(summary, csv, plan.scenes[i], plan.physics_hashes[i],
                                                      "the reference of " + plan.scenes[i].name + " from rank 0",
                                                      refs[i].record, refs[i].trajectory);
          if (!why.empty()) throw std::runtime_error(why);
        }
      } catch (const std::exception& e) {
        error = e.what();
      }
    }
    error = first_error(farm, error);
    if (!error.empty()) throw std::runtime_error(error);
  }
  for (size_t i : prep.needed)
    if (refs[i].failure.empty()) refs[i].summary = reference_summary(plan.scenes[i], refs[i]);
  if (farm.coordinator())
    for (size_t i : prep.needed)
      if (!refs[i].failure.empty()) {
        size_t n = 0;
        for (size_t q : prep.todo) n += plan.points[q].scene_index == i;
        std::fprintf(stderr, "tippe: warning: %s; its %zu point(s) are recorded as failed\n", refs[i].failure.c_str(), n);
      }

  // 4. The points: each runs once, on some worker; the coordinator appends its line.
  if (!prep.todo.empty()) {
    std::unique_ptr<RecordAppender> appender;
    std::unique_ptr<SweepProgress> progress;
    std::vector<std::chrono::steady_clock::time_point> started(prep.todo.size());
    if (farm.coordinator()) {
      appender = std::make_unique<RecordAppender>(records_file);
      progress = std::make_unique<SweepProgress>(plan, prep.todo, prep.share, prep.skipped, farm.workers(),
                                                 farm.distributed() || progress_mode() == ProgressMode::Lines);
    }
    const bool show = o.progress && progress_mode() != ProgressMode::Quiet;
    TaskFarm::Idle idle;
    if (show && farm.coordinator()) idle = [&] { progress->print(false); };
    farm.run(
        prep.todo.size(),
        [&](size_t k) {
          const size_t p = prep.todo[k];
          return to_jsonl(run_point(plan, plan.points[p], refs[plan.points[p].scene_index]));
        },
        [&](size_t k, std::string&& line) {
          appender->append(line);
          progress->end(prep.todo[k],
                        std::chrono::duration<double>(std::chrono::steady_clock::now() - started[k]).count());
        },
        [&](size_t k) {
          started[k] = std::chrono::steady_clock::now();
          progress->begin(prep.todo[k]);
        },
        idle);
    if (show && farm.coordinator()) progress->print(true);
  }
  outcome.ran = prep.todo.size();
  outcome.wall_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();

  if (farm.coordinator() && o.report) {
    // The report's files change as one unit: an interrupted rerun of a finished sweep leaves the old report.
    const InterruptGuard guard;
    const std::vector<SweepRecord> records = read_records(records_file.string()).records;
    write_sweep_report(lock->stage(true).string(), records, o.plots);
    lock->commit();
  }
  return outcome;
}

}  // namespace tippe
