// `tippe gate`: runs the checks of a gate file (engine settings against thresholds on comparison metrics) for CI, with table, JUnit and JSON output.
#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <map>
#include <memory>
#include <thread>

#include "harness/cli/cli.h"
#include "harness/library/verbs.h"
#include "harness/measure/compare.h"
#include "harness/gating/gate.h"
#include "harness/gating/gate_boundary.h"
#include "harness/sweep/sweep_search.h"
#include "harness/io/output_dir.h"
#include "harness/records/records.h"
#include "harness/io/scene_io.h"
#include "harness/report/sweep_analysis.h"

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
  const GatePlan plan = load_gate_plan(o.gates);
  check_output(o.junit, "--junit");
  check_output(o.json, "--json");
  const std::vector<fs::path>& inputs = plan.inputs;
  if (!o.junit.empty() && o.junit != "-") refuse_output_over_inputs(o.junit, inputs, "--junit");
  if (!o.json.empty() && o.json != "-") refuse_output_over_inputs(o.json, inputs, "--json");
  std::error_code ec;
  if (o.junit == "-" && o.json == "-") throw UsageError("--junit and --json both name stdout (-)");
  if (!o.junit.empty() && !o.json.empty() && o.junit != "-" && o.json != "-" &&
      fs::weakly_canonical(fs::absolute(o.junit), ec) == fs::weakly_canonical(fs::absolute(o.json), ec))
    throw UsageError("--junit and --json name the same file " + o.junit);

  GateRequest request;
  request.jobs = o.jobs;
  request.cache = o.no_cache ? "" : o.cache;
  request.boundary_out = o.boundary_out;
  request.self_check = !o.no_self_check;
  const std::vector<CheckResult> results = run_gate(plan, request);

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
