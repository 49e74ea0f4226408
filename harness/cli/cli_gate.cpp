// `tippe gate`: runs the checks of a gate file (engine settings against thresholds on comparison metrics) for CI, with table, JUnit and JSON output.
#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <map>
#include <memory>
#include <thread>

#include "cli/cli.h"
#include "measure/compare.h"
#include "gating/gate.h"
#include "gating/gate_boundary.h"
#include "sweep/sweep_search.h"
#include "io/output_dir.h"
#include "records/records.h"
#include "io/scene_io.h"
#include "report/sweep_analysis.h"

namespace tippe::cli {

namespace {

namespace fs = std::filesystem;

struct GateCliOptions {
  std::string gates;
  std::string junit, json;
  int jobs = 0;  // 0: one per core, at most one per run of a comparison
  std::string cache = "out/.reference-cache";
  std::string boundary_out = "out/.boundary-runs";
  bool no_cache = false;
  bool no_self_check = false;
};

// Checks that share a scene and its overrides: one comparison, one reference run, each engine
// run once however many checks judge it.
struct Group {
  std::vector<size_t> checks;
  std::vector<std::string> engines;
};

// A report path must be writable as a file; found before anything runs, so that a typo does
// not cost a whole gate run.
void check_output(const std::string& path, const char* option) {
  if (path.empty() || path == "-") return;
  if (const std::string problem = result_file_problem(path); !problem.empty())
    throw UsageError(std::string(option) + ": " + path + ": " + problem);
}

int gate(const GateCliOptions& o) {
  // Everything that can be wrong with the input (gate file, scenes, overrides, engine settings,
  // output paths) is found before the first run.
  const GateFile g = load_gate_file(o.gates);
  std::vector<std::string> check_names;
  for (const Check& c : g.checks) check_names.push_back(c.name);
  const std::vector<BoundaryCheck> boundaries = load_boundary_checks(o.gates, check_names);
  check_output(o.junit, "--junit");
  check_output(o.json, "--json");
  // A report written over the gate file, a scene, a model or a sweep file would destroy it.
  std::vector<fs::path> inputs = {o.gates};
  for (const Check& c : g.checks)
    for (const fs::path& f : scene_input_files(c.loaded)) inputs.push_back(f);
  for (const BoundaryCheck& b : boundaries) inputs.emplace_back(b.sweep_path);
  if (!o.junit.empty() && o.junit != "-") refuse_output_over_inputs(o.junit, inputs, "--junit");
  if (!o.json.empty() && o.json != "-") refuse_output_over_inputs(o.json, inputs, "--json");
  std::error_code ec;
  if (o.junit == "-" && o.json == "-") throw UsageError("--junit and --json both name stdout (-)");
  if (!o.junit.empty() && !o.json.empty() && o.junit != "-" && o.json != "-" &&
      fs::weakly_canonical(fs::absolute(o.junit), ec) == fs::weakly_canonical(fs::absolute(o.json), ec))
    throw UsageError("--junit and --json name the same file " + o.junit);

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
  std::fprintf(stderr, "gate %s: %zu check(s) in %zu comparison(s)\n", o.gates.c_str(), g.checks.size(),
               groups.size());

  std::vector<CheckResult> results(g.checks.size());
  for (const Group& grp : groups) {
    Scene scene = g.checks[grp.checks.front()].loaded;
    if (o.no_self_check) scene.run.self_check = false;
    CompareOptions opts;
    opts.engines = grp.engines;
    const int runs = static_cast<int>(grp.engines.size()) + 1;
    opts.jobs = o.jobs > 0 ? o.jobs
                           : std::max(1, std::min(runs, static_cast<int>(std::thread::hardware_concurrency())));
    opts.out_dir = "";
    opts.cache_dir = o.no_cache ? "" : o.cache;
    opts.progress = true;
    Comparison cmp;
    try {
      cmp = run_comparison(scene, opts);
    } catch (const std::invalid_argument& e) {
      // The gate file was checked as run_comparison checks its input; this is a gap in that.
      throw UsageError(o.gates + ": " + "check[" + std::to_string(grp.checks.front()) + "]: " + e.what());
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
  // must not stand in for this one's), into its own directory under --boundary-out.
  std::map<std::string, std::vector<SweepRecord>> sweep_records;
  for (const BoundaryCheck& b : boundaries) {
    if (sweep_records.count(b.sweep_path)) continue;
    std::vector<SweepRecord>& records = sweep_records[b.sweep_path];
    try {
      const SweepPlan plan = load_sweep(b.sweep_path);
      SweepOptions so;
      so.out_dir = (fs::path(o.boundary_out) / (fs::path(b.sweep_path).stem().string() + "-" + plan.spec.hash)).string();
      so.jobs = o.jobs > 0 ? o.jobs : std::max(1, static_cast<int>(std::thread::hardware_concurrency()));
      so.restart = true;
      so.write_report = [](const std::string& dir, const std::vector<SweepRecord>& records) {
        write_sweep_report(dir, records, /*plots=*/false);
      };
      std::fprintf(stderr, "gate %s: boundary search %s into %s\n", o.gates.c_str(), b.sweep_path.c_str(),
                   so.out_dir.c_str());
      run_search_sweep(plan, so);
      records = read_records((fs::path(so.out_dir) / "records.jsonl").string()).records;
    } catch (const SweepInputError& e) {
      throw UsageError(e.what());
    }
  }
  for (const BoundaryCheck& b : boundaries) results.push_back(evaluate_boundary(b, sweep_records[b.sweep_path]));

  // With a report on stdout (-), stdout holds that report alone and the table goes to stderr.
  const bool report_on_stdout = o.junit == "-" || o.json == "-";
  std::fprintf(report_on_stdout ? stderr : stdout, "%s", render_table(results).c_str());
  std::fflush(report_on_stdout ? stderr : stdout);
  auto write = [](const std::string& path, const std::string& text) {
    if (path != "-") return write_result_file(path, text);
    if (std::fwrite(text.data(), 1, text.size(), stdout) != text.size() || std::fflush(stdout) != 0)
      throw OutputError("stdout: cannot write the report");
  };
  if (!o.junit.empty()) write(o.junit, render_junit(results, o.gates));
  if (!o.json.empty()) {
    nlohmann::json j = to_json(results);
    j["gate_file"] = o.gates;
    write(o.json, j.dump(2) + "\n");
  }
  return all_passed(results) ? 0 : 1;
}

}  // namespace

Command setup_gate(CLI::App& app) {
  auto o = std::make_shared<GateCliOptions>();
  CLI::App* sub = app.add_subcommand(
      "gate", "Run a gate file's checks (engine settings against metric thresholds); exit 1 when any fails");
  sub->add_option("gates", o->gates, "Gate file (TOML), e.g. harness/gates/default.toml")->required();
  sub->add_option("--junit", o->junit, "Write a JUnit XML report to FILE (- for stdout)");
  sub->add_option("--json", o->json, "Write the results as JSON to FILE (- for stdout)");
  sub->add_option("--jobs,-j", o->jobs, "Runs in parallel within a comparison (default: one per core)")
      ->check(CLI::Range(1, kMaxJobs));
  sub->add_option("--cache", o->cache, "Reference cache directory")->capture_default_str();
  sub->add_option("--boundary-out", o->boundary_out, "Directory of the sweeps that [[boundary]] checks run")
      ->capture_default_str();
  sub->add_flag("--no-cache", o->no_cache, "Always run the reference; leave the cache alone");
  sub->add_flag("--no-self-check", o->no_self_check,
                "Skip the reference's self-check: metrics are then compared over the whole run unchecked");
  return {sub, [o] { return gate(*o); }};
}

}  // namespace tippe::cli
