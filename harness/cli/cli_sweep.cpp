// `tippe sweep`: work-precision sweeps into a resumable directory, on threads or MPI ranks, in shards (--shard, --merge), and --report to rebuild one.
#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <optional>
#include <thread>

#include "harness/cli/cli.h"
#include "harness/sweep/mpi_farm.h"
#include "harness/sweep/sweep_search.h"
#include "harness/io/scene_io.h"
#include "harness/sweep/sweep.h"
#include "harness/report/sweep_analysis.h"

namespace tippe::cli {

namespace {

namespace fs = std::filesystem;

struct SweepCliOptions {
  std::string sweep;
  std::string out;
  std::string report_dir;
  std::vector<std::string> merge;
  std::string shard;
  int jobs = 0;  // 0: one per core
  bool restart = false;
  bool no_plots = false;
};

int report_only(const SweepCliOptions& o) {
  if (!o.sweep.empty() || !o.out.empty() || o.restart || !o.shard.empty())
    throw UsageError(
        "--report DIR rebuilds a report from DIR/records.jsonl; it takes no sweep file, --out, --restart or --shard");
  const fs::path records = fs::path(o.report_dir) / "records.jsonl";
  std::error_code ec;
  if (!fs::is_regular_file(records, ec)) throw UsageError(records.string() + ": cannot read (not a sweep directory?)");
  // Locked like every output directory: a report is not rebuilt under a sweep still running.
  const InterruptGuard interrupts;
  OutputDir dir(o.report_dir, OutputKind::Sweep);
  RecordsFile f;
  try {
    f = read_records(records.string());
  } catch (const SweepInputError& e) {
    throw UsageError(e.what());
  } catch (const std::runtime_error& e) {
    throw UsageError(e.what());
  }
  // A partial last line belongs to a sweep that was cut short; the next run of it drops it.
  if (f.partial_bytes)
    std::fprintf(stderr, "tippe: note: %s ends in a partial line (%zu bytes), left out of the report\n",
                 records.string().c_str(), f.partial_bytes);
  // The rebuilt report replaces the old one as a unit; the records stay as they are.
  write_sweep_report(dir.stage(true).string(), f.records, !o.no_plots);
  dir.commit();
  std::printf("report: %s (%zu points)\n", (fs::path(o.report_dir) / "index.html").string().c_str(), f.records.size());
  return 0;
}

SweepReportWriter report_writer(bool plots) {
  return [plots](const std::string& dir, const std::vector<SweepRecord>& records) {
    write_sweep_report(dir, records, plots);
  };
}

int merge(const SweepCliOptions& o) {
  if (!o.sweep.empty() || !o.report_dir.empty() || !o.shard.empty() || o.jobs)
    throw UsageError("--merge DIR... --out DIR combines shard directories; it takes no sweep file, --report, "
                     "--shard or --jobs (the shards' sweep.json say which sweep they are)");
  if (o.out.empty()) throw UsageError("--merge needs --out DIR, the directory of the merged sweep");
  MergeOutcome r;
  try {
    r = merge_sweeps(o.merge, o.out, o.restart, report_writer(!o.no_plots));
  } catch (const SweepInputError& e) {
    throw UsageError(e.what());
  }
  for (const std::string& w : r.warnings) std::fprintf(stderr, "tippe: warning: %s\n", w.c_str());
  std::printf("merged: %zu shards, %zu points\n", r.shards, r.points);
  std::printf("records: %s\n", (fs::path(o.out) / "records.jsonl").string().c_str());
  std::printf("report: %s\n", (fs::path(o.out) / "index.html").string().c_str());
  return 0;
}

SweepOptions run_options(const SweepCliOptions& o, int jobs) {
  SweepOptions opts;
  opts.out_dir = o.out.empty() ? (fs::path("out") / (fs::path(o.sweep).stem().string() + "-sweep")).string() : o.out;
  opts.jobs = jobs;
  opts.restart = o.restart;
  opts.write_report = report_writer(!o.no_plots);
  if (!o.shard.empty()) {
    try {
      opts.shard = parse_shard(o.shard);
    } catch (const std::invalid_argument& e) {
      throw UsageError(e.what());
    }
  }
  return opts;
}

void print_outcome(const SweepOutcome& r, const SweepOptions& opts, const std::string& how) {
  std::printf("sweep: %zu points%s (%zu from an earlier run, %zu run now) in %.1f s wall with %s\n", r.points,
              opts.shard ? (" of shard " + std::to_string(opts.shard->index) + "/" +
                            std::to_string(opts.shard->count)).c_str()
                         : "",
              r.skipped, r.ran, r.wall_seconds, how.c_str());
  std::printf("records: %s\n", (fs::path(opts.out_dir) / "records.jsonl").string().c_str());
  std::printf("report: %s\n", (fs::path(opts.out_dir) / "index.html").string().c_str());
}

int run_local(const SweepCliOptions& o) {
  if (o.sweep.empty()) throw UsageError("a sweep file is required (or --report DIR, or --merge DIR...)");
  const SweepOptions opts =
      run_options(o, o.jobs > 0 ? o.jobs : std::max(1, static_cast<int>(std::thread::hardware_concurrency())));
  // Every scene and point is loaded and checked before the output directory is touched.
  const SweepPlan plan = load_sweep(o.sweep);
  SweepOutcome r;
  try {
    r = run_search_sweep(plan, opts);
  } catch (const SweepInputError& e) {
    throw UsageError(e.what());
  }
  print_outcome(r, opts, std::to_string(opts.jobs) + " job(s)");
  return 0;
}

#ifdef TIPPE_HAVE_MPI
// Every rank runs this; rank 0 coordinates and alone writes and prints.
int run_mpi(const SweepCliOptions& o, const MpiSession& mpi) {
  if (o.sweep.empty()) throw UsageError("a sweep file is required");
  if (o.jobs)
    throw UsageError("--jobs is for a run in one process; under mpirun rank 0 hands out the points and every "
                     "other rank runs one at a time (start as many ranks as cores, plus one)");
  const SweepOptions opts = run_options(o, 1);
  auto farm = make_mpi_farm(mpi);
  // Every rank reads the sweep itself; they must all have read the same one (a node with other
  // files, or another checkout, would make other records).
  std::optional<SweepPlan> plan;
  std::string token;
  try {
    plan = load_sweep(o.sweep);
    token = plan->spec.hash + " " + plan->plan_hash;
  } catch (const SceneError& e) {
    token = std::string("!") + e.what();
  }
  const std::vector<std::string> tokens = farm->gather(token);
  std::string verdict;
  if (farm->coordinator()) {
    if (tokens[0][0] == '!') verdict = tokens[0].substr(1);
    for (size_t r = 1; r < tokens.size() && verdict.empty(); ++r)
      if (tokens[r] != tokens[0])
        verdict = "rank " + std::to_string(r) + ": " +
                  (tokens[r][0] == '!' ? tokens[r].substr(1)
                                       : "read another sweep than rank 0 (sweep and plan hash " + tokens[r] +
                                             ", rank 0 has " + tokens[0] + "); every rank needs the same files");
  }
  farm->broadcast(verdict);
  if (!verdict.empty()) throw UsageError(verdict);
  SweepOutcome r;
  try {
    r = run_search_sweep(*plan, opts, *farm);
  } catch (const SweepInputError& e) {
    throw UsageError(e.what());
  }
  if (farm->coordinator())
    print_outcome(r, opts, std::to_string(farm->workers()) + " worker rank(s) (MPI, " + std::to_string(mpi.size()) +
                               " ranks)");
  return 0;
}
#endif

// --merge, --report or a sweep on threads.
int in_one_process(const SweepCliOptions& o) {
  if (!o.merge.empty()) return merge(o);
  if (!o.report_dir.empty()) return report_only(o);
  return run_local(o);
}

int sweep(const SweepCliOptions& o) {
  const int launched = mpi_launch_size();
#ifdef TIPPE_HAVE_MPI
  // MPI starts only when a launcher started this process: a plain `tippe sweep` never touches it.
  std::unique_ptr<MpiSession> mpi;
  if (launched > 0) mpi = std::make_unique<MpiSession>();
  if (mpi && mpi->size() > 1) {
    // --merge and --report write one directory: rank 0 does them alone.
    if (!o.merge.empty() || !o.report_dir.empty()) return mpi->rank() == 0 ? in_one_process(o) : 0;
    // The other ranks' errors are rank 0's too (every step agrees), so only rank 0 prints them,
    // and before MPI_Finalize: no rank leaves that before all arrive, so the launcher cannot
    // kill rank 0 for another rank's exit code while its message is half written.
    try {
      return run_mpi(o, *mpi);
    } catch (const std::exception&) {
      return error_exit(std::current_exception(), mpi->rank() == 0);
    }
  }
#else
  if (launched > 1)
    throw UsageError("this tippe was built without MPI but started as one of " + std::to_string(launched) +
                     " ranks; install libopenmpi-dev and rebuild (bash scripts/build.sh), or run without mpirun");
#endif
  return in_one_process(o);
}

}  // namespace

Command setup_sweep(CLI::App& app) {
  auto o = std::make_shared<SweepCliOptions>();
  CLI::App* sub = app.add_subcommand(
      "sweep", "Work-precision sweep: scenes x engine setups x a ladder of settings (or a boundary search along "
      "one, ladder.search); records.jsonl and a report");
  sub->add_option("sweep", o->sweep, "Sweep file (TOML), e.g. harness/sweeps/default.toml");
  sub->add_option("--out", o->out, "Output directory (default out/<sweep name>-sweep); rerun to resume");
  sub->add_option("--jobs,-j", o->jobs, "Runs in parallel (default: one per core)")->check(CLI::Range(1, kMaxJobs));
  sub->add_flag("--restart", o->restart,
                "Begin the output directory again (needed when the sweep file or a scene's physics changed); "
                "earlier records are kept as records.jsonl.old (.old.2, ... when that exists)");
  sub->add_option("--report", o->report_dir, "Only rebuild DIR's report from DIR/records.jsonl");
  sub->add_option("--shard", o->shard,
                  "Run only share I of N (I/N, 0-based) of the points, e.g. a job array's index; "
                  "merge the shards' directories with --merge");
  sub->add_option("--merge", o->merge,
                  "Combine the directories of shards 0/N..N-1/N of one sweep into --out DIR, as if run whole")
      ->expected(1, -1);
  sub->add_flag("--no-plots", o->no_plots, "Skip the gnuplot SVGs");
  return {sub, [o] { return sweep(*o); }};
}

}  // namespace tippe::cli
