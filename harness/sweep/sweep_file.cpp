// Sweep files: reading a sweep file into a checked plan of points, and the points' stable ids.
#include "harness/sweep/sweep.h"
#include "harness/io/hash.h"
#include "harness/io/text.h"

#include <toml++/toml.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <limits>
#include <map>
#include <set>
#include <sstream>
#include <stdexcept>

#include "harness/io/scene_io.h"
#include "harness/scene/resolve.h"
#include "harness/io/toml_reader.h"
#include "engines/core/registry.h"
#include "harness/sweep/sweep_search.h"

namespace tippe {

namespace {

namespace fs = std::filesystem;
using nlohmann::json;





// Checks one sweep file; every message names the file and the dotted key.
class SweepReader : public TomlReader {
 public:
  explicit SweepReader(std::string file) : TomlReader(std::move(file)) {}

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
    s.file = file();
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
    const fs::path base = fs::path(file()).parent_path();
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
        u.search = read_search(*lt->get("search"), file(), key + ".ladder.search", u.ladder_key);
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
};


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
  const toml::table root = read_toml_file(path, &text);
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


}  // namespace tippe
