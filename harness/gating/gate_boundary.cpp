// Gate checks on boundary searches: reading [[boundary]] tables and judging a search's boundary from its sweep's records.
#include "harness/gating/gate_boundary.h"

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <map>
#include <set>

#include <toml++/toml.h>

#include "harness/io/scene_io.h"
#include "harness/io/text.h"
#include "harness/sweep/sweep_search.h"
#include "harness/io/toml_reader.h"

namespace tippe {

namespace {

namespace fs = std::filesystem;


}  // namespace

std::vector<BoundaryCheck> load_boundary_checks(const std::string& gate_path, const std::vector<std::string>& check_names) {
  std::vector<BoundaryCheck> out;
  const toml::table root = read_toml_file(gate_path);
  const toml::node* bn = root.get("boundary");
  if (!bn) return out;
  const auto fail = [&](const std::string& key, const std::string& why) -> void {
    throw SceneError(gate_path + ": " + key + ": " + why);
  };
  const auto* arr = bn->as_array();
  if (!arr) fail("boundary", "expected [[boundary]] tables, got " + toml_value_text(*bn));
  if (arr->empty() && check_names.empty())
    fail("boundary", "no checks (a gate file needs one or more [[check]] or [[boundary]] tables)");
  std::set<std::string> names(check_names.begin(), check_names.end());
  std::map<std::string, SweepPlan> sweeps;
  const fs::path base = fs::path(gate_path).parent_path();
  for (size_t i = 0; i < arr->size(); ++i) {
    const std::string key = "boundary[" + std::to_string(i) + "]";
    const auto* t = arr->get(i)->as_table();
    if (!t) fail(key, "expected a [[boundary]] table, got " + toml_value_text(*arr->get(i)));
    for (auto&& [k, v] : *t) {
      (void)v;
      const std::string name(k.str());
      if (name != "name" && name != "sweep" && name != "setup" && name != "scene" && name != "grid" &&
          name != "require" && name != "allow_non_monotonic")
        fail(key + "." + name, "unknown key (expected one of: name, sweep, setup, scene, grid, require, allow_non_monotonic)");
    }
    const auto string = [&](const char* k, bool required) {
      const toml::node* n = t->get(k);
      if (!n) {
        if (required) fail(key + "." + k, "missing (required)");
        return std::string();
      }
      const auto* s = n->as_string();
      if (!s) fail(key + "." + k, "expected a string, got " + toml_value_text(*n));
      return std::string(s->get());
    };
    BoundaryCheck c;
    c.name = string("name", true);
    if (!is_valid_name(c.name)) fail(key + ".name", "\"" + c.name + "\" is not a usable name (" + kNameRule + ")");
    if (!names.insert(c.name).second) fail(key + ".name", "\"" + c.name + "\" is already the name of a check");
    c.sweep = string("sweep", true);
    c.sweep_path = (fs::path(c.sweep).is_absolute() ? fs::path(c.sweep) : base / c.sweep).lexically_normal().string();
    auto it = sweeps.find(c.sweep_path);
    if (it == sweeps.end()) {
      try {
        it = sweeps.emplace(c.sweep_path, load_sweep(c.sweep_path)).first;
      } catch (const SceneError& e) {
        fail(key + ".sweep", e.what());
      }
    }
    const SweepPlan& plan = it->second;
    c.setup = string("setup", true);
    const auto su = std::find_if(plan.spec.setups.begin(), plan.spec.setups.end(),
                                 [&](const SweepSetup& s) { return s.name == c.setup; });
    if (su == plan.spec.setups.end()) fail(key + ".setup", "\"" + c.setup + "\" is not a setup of " + c.sweep);
    if (!su->search) fail(key + ".setup", "setup \"" + c.setup + "\" of " + c.sweep + " has no ladder.search");
    c.scene = string("scene", false);
    if (c.scene.empty()) {
      if (plan.scenes.size() != 1)
        fail(key + ".scene", "missing (required: " + c.sweep + " has " + std::to_string(plan.scenes.size()) + " scenes)");
      c.scene = plan.scenes.front().name;
    } else if (std::none_of(plan.scenes.begin(), plan.scenes.end(), [&](const Scene& s) { return s.name == c.scene; })) {
      fail(key + ".scene", "\"" + c.scene + "\" is not a scene of " + c.sweep);
    }
    c.grid = string("grid", false);
    if (su->has_grid() && std::find(su->grid_labels.begin(), su->grid_labels.end(), c.grid) == su->grid_labels.end())
      fail(key + ".grid", (c.grid.empty() ? std::string("missing") : "\"" + c.grid + "\" is not a value") +
                              " (setup \"" + c.setup + "\" has a grid over " + su->grid_key + ")");
    if (!su->has_grid() && !c.grid.empty()) fail(key + ".grid", "setup \"" + c.setup + "\" has no grid");
    const std::string req = string("require", true);
    try {
      c.require = parse_bound_text(req);
    } catch (const std::invalid_argument& e) {
      fail(key + ".require", e.what());
    }
    const std::string quantity = boundary_quantity(su->ladder_key);
    if (c.require.name != quantity)
      fail(key + ".require", "\"" + c.require.name + "\" is not what setup \"" + c.setup + "\" finds (expected " +
                                 quantity + ", the boundary of " + su->ladder_key + ")");
    if (const toml::node* n = t->get("allow_non_monotonic")) {
      const auto* b = n->as_boolean();
      if (!b) fail(key + ".allow_non_monotonic", "expected true or false, got " + toml_value_text(*n));
      c.allow_non_monotonic = b->get();
    }
    out.push_back(c);
  }
  return out;
}

CheckResult evaluate_boundary(const BoundaryCheck& check, const std::vector<SweepRecord>& records) {
  CheckResult r;
  r.name = check.name;
  r.scene = check.scene;
  const std::vector<SearchBoundary> all = search_boundaries(records);
  const auto it = std::find_if(all.begin(), all.end(), [&](const SearchBoundary& b) {
    return b.setup == check.setup && b.scene == check.scene && (b.grid_key.empty() || b.grid_label == check.grid);
  });
  if (it == all.end()) {
    GateRow row;
    row.kind = GateRowKind::Error;
    row.metric = "search";
    row.measured = "absent";
    row.required = "found";
    row.message = "no record of the search " + check.setup + " on " + check.scene;
    r.rows.push_back(row);
    r.passed = false;
    return r;
  }
  const SearchBoundary& b = *it;
  r.engine = b.engine;
  GateRow state;
  state.kind = GateRowKind::Status;
  state.metric = "search";
  state.measured = b.status + " (" + std::to_string(b.runs) + " runs)";
  state.required = "found|all_safe";
  state.passed = b.status == "found" || b.status == "all_safe";
  if (!state.passed)
    state.message = "search " + b.status + (b.status == "none_safe" ? ": even the finest setting fails " + b.criterion : "");
  r.rows.push_back(state);
  if (!check.allow_non_monotonic) {
    GateRow mono;
    mono.kind = GateRowKind::Status;
    mono.metric = "monotonic";
    mono.measured = b.monotonic() ? "yes" : "no (" + std::to_string(b.replay.crossings.size()) + " crossings)";
    mono.required = "yes";
    mono.passed = b.monotonic();
    if (!mono.passed) mono.message = b.criterion + " changes " + std::to_string(b.replay.crossings.size()) + " times along " + b.key;
    r.rows.push_back(mono);
  }
  GateRow bound;
  bound.kind = GateRowKind::Threshold;
  bound.metric = b.quantity;
  bound.limit = check.require.bound;
  bound.required = check.require.op + " " + g6(check.require.bound);
  if (b.boundary) {
    bound.value = *b.boundary;
    bound.measured = (b.status == "all_safe" ? (larger_is_softer(b.key) ? ">= " : "<= ") : "") + g6(*b.boundary);
    // A range's soft end that is still safe is a lower bound of a max_safe quantity: judged at it.
    bound.passed = check.require.op == ">=" ? *b.boundary >= check.require.bound : *b.boundary <= check.require.bound;
    if (!bound.passed)
      bound.message = b.quantity + " " + g6(*b.boundary) + (check.require.op == ">=" ? " < " : " > ") +
                      g6(check.require.bound) + " (" + b.criterion + "; bracket " + g6(*b.boundary) +
                      (b.beyond ? " .. " + g6(*b.beyond) : std::string(" .. beyond the range")) + ")";
  } else {
    bound.measured = "none";
    bound.message = b.quantity + ": no safe value (" + b.status + ")";
  }
  r.rows.push_back(bound);
  r.passed = std::all_of(r.rows.begin(), r.rows.end(), [](const GateRow& x) { return x.passed; });
  return r;
}

}  // namespace tippe
