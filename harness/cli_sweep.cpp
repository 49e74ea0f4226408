// `tippe sweep`: work-precision sweeps over engine settings into a resumable directory, and --report to rebuild one.
#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <thread>

#include "cli.h"
#include "scene_io.h"
#include "sweep.h"

namespace tippe::cli {

namespace {

namespace fs = std::filesystem;

struct SweepCliOptions {
  std::string sweep;
  std::string out;
  std::string report_dir;
  int jobs = 0;  // 0: one per core
  bool restart = false;
  bool no_plots = false;
};

int report_only(const SweepCliOptions& o) {
  if (!o.sweep.empty() || !o.out.empty() || o.restart)
    throw UsageError(
        "--report DIR rebuilds a report from DIR/records.jsonl; it takes no sweep file, --out or --restart");
  const fs::path records = fs::path(o.report_dir) / "records.jsonl";
  std::error_code ec;
  if (!fs::is_regular_file(records, ec)) throw UsageError(records.string() + ": cannot read (not a sweep directory?)");
  RecordsFile f;
  try {
    f = read_records(records.string());
  } catch (const std::runtime_error& e) {
    throw UsageError(e.what());
  }
  // A partial last line belongs to a sweep that was cut short; the next run of it drops it.
  if (f.partial_bytes)
    std::fprintf(stderr, "tippe: note: %s ends in a partial line (%zu bytes), left out of the report\n",
                 records.string().c_str(), f.partial_bytes);
  write_sweep_report(o.report_dir, f.records, !o.no_plots);
  std::printf("report: %s (%zu points)\n", (fs::path(o.report_dir) / "index.html").string().c_str(), f.records.size());
  return 0;
}

int sweep(const SweepCliOptions& o) {
  if (!o.report_dir.empty()) return report_only(o);
  if (o.sweep.empty()) throw UsageError("a sweep file is required (or --report DIR)");
  // Every scene and point is loaded and checked before the output directory is touched.
  const SweepPlan plan = load_sweep(o.sweep);
  SweepOptions opts;
  opts.out_dir = o.out.empty() ? (fs::path("out") / (fs::path(o.sweep).stem().string() + "-sweep")).string() : o.out;
  opts.jobs = o.jobs > 0 ? o.jobs : std::max(1, static_cast<int>(std::thread::hardware_concurrency()));
  opts.restart = o.restart;
  opts.plots = !o.no_plots;
  SweepOutcome r;
  try {
    r = run_sweep(plan, opts);
  } catch (const SweepInputError& e) {
    throw UsageError(e.what());
  }
  std::printf("sweep: %zu points (%zu from an earlier run, %zu run now) in %.1f s wall with %d job(s)\n", r.points,
              r.skipped, r.ran, r.wall_seconds, opts.jobs);
  std::printf("records: %s\n", (fs::path(opts.out_dir) / "records.jsonl").string().c_str());
  std::printf("report: %s\n", (fs::path(opts.out_dir) / "index.html").string().c_str());
  return 0;
}

}  // namespace

Command setup_sweep(CLI::App& app) {
  auto o = std::make_shared<SweepCliOptions>();
  CLI::App* sub = app.add_subcommand(
      "sweep", "Work-precision sweep: scenes x engine setups x a ladder of settings; records.jsonl and a report");
  sub->add_option("sweep", o->sweep, "Sweep file (TOML), e.g. harness/sweeps/default.toml");
  sub->add_option("--out", o->out, "Output directory (default out/<sweep name>-sweep); rerun to resume");
  sub->add_option("--jobs,-j", o->jobs, "Runs in parallel (default: one per core)")->check(CLI::PositiveNumber);
  sub->add_flag("--restart", o->restart,
                "Begin the output directory again (needed when the sweep file or a scene's physics changed); "
                "earlier records are kept as records.jsonl.old");
  sub->add_option("--report", o->report_dir, "Only rebuild DIR's report from DIR/records.jsonl");
  sub->add_flag("--no-plots", o->no_plots, "Skip the gnuplot SVGs");
  return {sub, [o] { return sweep(*o); }};
}

}  // namespace tippe::cli
