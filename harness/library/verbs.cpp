// The command line's compare and gate runs, the registry and advice as JSON, as functions the `tippe` command and the Python module share.
#include "harness/library/verbs.h"

#include <algorithm>
#include <cstdio>
#include <map>
#include <thread>

#include "harness/io/interrupt.h"
#include "harness/io/output_dir.h"
#include "harness/io/scene_io.h"
#include "harness/scene/resolve.h"
#include "harness/records/records.h"
#include "harness/records/sweep_record.h"
#include "engines/core/registry.h"
#include "harness/report/report.h"
#include "harness/report/sweep_analysis.h"
#include "harness/sweep/sweep.h"
#include "harness/sweep/sweep_search.h"

namespace tippe {

namespace fs = std::filesystem;

Comparison compare_scene(const Scene& scene, const CompareRequest& request) {
  CompareOptions opts;
  opts.engines = request.engines;
  const int runs = static_cast<int>(request.engines.size()) + 1;
  opts.jobs = request.jobs > 0 ? request.jobs
                               : std::max(1, std::min(runs, static_cast<int>(std::thread::hardware_concurrency())));
  opts.cache_dir = request.cache;
  opts.progress = request.progress;
  opts.on_progress = request.on_progress;
  opts.trajectories = request.trajectories;
  // run_comparison checks its input before it writes anything; so does this, before OUT exists.
  try {
    check_compare_input(scene, opts);
  } catch (const std::invalid_argument& e) {
    throw InputError(e.what());
  }
  if (request.out.empty()) return run_comparison(scene, opts);
  // The comparison's files are one unit, written beside OUT and swapped in whole.
  const InterruptGuard interrupts;
  std::vector<fs::path> inputs = scene_input_files(scene);
  if (!opts.cache_dir.empty()) inputs.emplace_back(opts.cache_dir);  // the cache outlives the output
  OutputDir out(request.out, OutputKind::Comparison, inputs);
  opts.out_dir = out.stage(false).string();
  const Comparison c = run_comparison(scene, opts);
  write_report(opts.out_dir, to_json(c), request.plots);
  out.commit();
  return c;
}

std::string comparison_summary_text(const nlohmann::json& j) {
  std::string text;
  // The scene's own notes (an imported model's approximations) head the report.
  if (j.contains("scene") && j.at("scene").is_object())
    for (const auto& n : j.at("scene").value("notes", nlohmann::json::array()))
      if (n.is_string()) text += "scene note: " + n.get<std::string>() + "\n";
  text += render_summary_table(j);
  for (const auto& f : report_findings(j)) text += "- " + f + "\n";
  return text;
}

GatePlan load_gate_plan(const std::string& gates) {
  GatePlan p;
  p.file = load_gate_file(gates);
  std::vector<std::string> check_names;
  for (const Check& c : p.file.checks) check_names.push_back(c.name);
  p.boundaries = load_boundary_checks(gates, check_names);
  // A report written over the gate file, a scene, a model or a sweep file would destroy it.
  p.inputs = {gates};
  for (const Check& c : p.file.checks)
    for (const fs::path& f : scene_input_files(c.loaded)) p.inputs.push_back(f);
  for (const BoundaryCheck& b : p.boundaries) p.inputs.emplace_back(b.sweep_path);
  return p;
}

namespace {

// Checks that share a scene and its overrides: one comparison, one reference run, each engine
// run once however many checks judge it.
struct Group {
  std::vector<size_t> checks;
  std::vector<std::string> engines;
};

}  // namespace

std::vector<CheckResult> run_gate(const GatePlan& plan, const GateRequest& o) {
  const GateFile& g = plan.file;
  std::vector<Group> groups;
  std::map<std::pair<std::string, std::vector<std::string>>, size_t> by_scene;
  for (size_t i = 0; i < g.checks.size(); ++i) {
    const Check& c = g.checks[i];
    auto [it, fresh] = by_scene.emplace(std::make_pair(c.scene_path, c.overrides), groups.size());
    if (fresh) groups.emplace_back();
    Group& grp = groups[it->second];
    grp.checks.push_back(i);
    if (std::find(grp.engines.begin(), grp.engines.end(), c.engine) == grp.engines.end())
      grp.engines.push_back(c.engine);
  }
  std::fprintf(stderr, "gate %s: %zu check(s) in %zu comparison(s)\n", g.file.c_str(), g.checks.size(),
               groups.size());

  std::vector<CheckResult> results(g.checks.size());
  for (const Group& grp : groups) {
    Scene scene = g.checks[grp.checks.front()].loaded;
    if (!o.self_check) scene.run.self_check = false;
    CompareOptions opts;
    opts.engines = grp.engines;
    const int runs = static_cast<int>(grp.engines.size()) + 1;
    opts.jobs = o.jobs > 0 ? o.jobs
                           : std::max(1, std::min(runs, static_cast<int>(std::thread::hardware_concurrency())));
    opts.out_dir = "";
    opts.cache_dir = o.cache;
    opts.progress = true;
    Comparison cmp;
    try {
      cmp = run_comparison(scene, opts);
    } catch (const std::invalid_argument& e) {
      // The gate file was checked as run_comparison checks its input; this is a gap in that.
      throw InputError(g.file + ": " + "check[" + std::to_string(grp.checks.front()) + "]: " + e.what());
    } catch (const Interrupted&) {
      throw;
    } catch (const std::exception& e) {
      // A comparison that cannot be completed fails its checks; the other comparisons still run
      // so that one broken scene does not hide the rest of the gate.
      for (size_t i : grp.checks) results[i] = error_result(g.checks[i], e.what());
      continue;
    }
    for (size_t i : grp.checks) {
      const Check& c = g.checks[i];
      const auto it = std::find_if(cmp.engines.begin(), cmp.engines.end(),
                                   [&](const EngineResult& e) { return e.run.engine == c.engine; });
      if (it == cmp.engines.end()) {
        results[i] = error_result(c, "the comparison has no run of " + c.engine);
        continue;
      }
      results[i] = evaluate_check(c, cmp.reference, it->run, it->metrics);
    }
  }

  // Boundary checks: each sweep they name runs once, from scratch (records of an earlier build
  // must not stand in for this one's), into its own directory under boundary_out.
  std::map<std::string, std::vector<SweepRecord>> sweep_records;
  for (const BoundaryCheck& b : plan.boundaries) {
    if (sweep_records.count(b.sweep_path)) continue;
    std::vector<SweepRecord>& records = sweep_records[b.sweep_path];
    try {
      const SweepPlan sweep = load_sweep(b.sweep_path);
      SweepOptions so;
      so.out_dir =
          (fs::path(o.boundary_out) / (fs::path(b.sweep_path).stem().string() + "-" + sweep.spec.hash)).string();
      so.jobs = o.jobs > 0 ? o.jobs : std::max(1, static_cast<int>(std::thread::hardware_concurrency()));
      so.restart = true;
      so.write_report = [](const std::string& dir, const std::vector<SweepRecord>& records) {
        write_sweep_report(dir, records, /*plots=*/false);
      };
      std::fprintf(stderr, "gate %s: boundary search %s into %s\n", g.file.c_str(), b.sweep_path.c_str(),
                   so.out_dir.c_str());
      run_search_sweep(sweep, so);
      records = read_records((fs::path(so.out_dir) / "records.jsonl").string()).records;
    } catch (const SweepInputError& e) {
      throw InputError(e.what());
    }
  }
  for (const BoundaryCheck& b : plan.boundaries) results.push_back(evaluate_boundary(b, sweep_records[b.sweep_path]));
  return results;
}

nlohmann::json engines_to_json() {
  nlohmann::json out = nlohmann::json::array();
  for (const EngineInfo& e : engine_registry()) {
    nlohmann::json j;
    j["name"] = e.name;
    j["role"] = e.role == EngineRole::Reference ? "reference" : "engine";
    j["version"] = e.version;
    j["colour"] = e.colour;
    nlohmann::json settings = nlohmann::json::array();
    if (e.describe_settings) {
      for (const SettingDoc& d : e.describe_settings()) {
        nlohmann::json s = {{"key", d.key}, {"type", d.type}, {"default", d.default_value}, {"allowed", d.allowed}};
        // The default as a value, and a number's bounds as two: the texts are TOML values
        // (round_trip_text), JSON's too but for an infinite bound, which stays absent.
        const auto parsed = nlohmann::json::parse(d.default_value, nullptr, false);
        if (!parsed.is_discarded()) s["default"] = parsed;
        if (d.type == "number" || d.type == "integer") {
          const auto bounds = nlohmann::json::parse(d.allowed, nullptr, false);
          if (!bounds.is_discarded() && bounds.is_array() && bounds.size() == 2) s["bounds"] = bounds;
        }
        settings.push_back(std::move(s));
      }
    }
    j["settings"] = std::move(settings);
    nlohmann::json axes = nlohmann::json::object();
    for (const SettingAxis& a : e.advice_axes) axes[a.key] = a.values;
    j["advice_axes"] = std::move(axes);
    j["cost_knob"] = e.cost_knob;
    out.push_back(std::move(j));
  }
  return out;
}

}  // namespace tippe
