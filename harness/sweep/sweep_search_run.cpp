// Running a sweep with boundary searches: the plan grows wave by wave from the records, on threads or over a farm of ranks.
#include <chrono>
#include <cstdio>
#include <filesystem>

#include "harness/sweep/sweep_search.h"

namespace tippe {

namespace fs = std::filesystem;

// Why waves, and why planned from the records file: a search's next point depends on the outcome of
// its last one, so the plan cannot be known up front. The coordinator derives it from what OUT
// holds (search_frontier, a pure function of the records), so that a resumed run, a shard and an
// uninterrupted run all replay to the same points with the same ids and indices; every rank gets
// the wave as text and loads the same points. Each wave is an ordinary run_sweep over the grown
// plan: locking, resuming, fsynced records, references and MPI stay as they are.
SweepOutcome run_search_sweep(SweepPlan plan, const SweepOptions& o, TaskFarm& farm) {
  if (!has_search(plan)) return run_sweep(plan, o, farm);
  const auto t0 = std::chrono::steady_clock::now();
  const fs::path records_file = fs::path(o.out_dir) / "records.jsonl";
  SweepOutcome total;
  bool first = true;
  size_t waves = 0;
  for (;;) {
    const std::string wave = from_coordinator(farm, [&] {
      // --restart sets the earlier records aside: nothing to replay from.
      if (first && o.restart) return encode_search_points({});
      RecordsFile file;
      try {
        file = read_records(records_file.string());
      } catch (const SweepRecordError&) {
        // Before the first wave run_sweep checks the directory and refuses it with its reasons.
        if (!first) throw;
      }
      SweepPlan grown = plan;
      std::vector<SearchPoint> all;
      for (;;) {
        const std::vector<SearchPoint> f = search_frontier(grown, file.records);
        if (f.empty()) break;
        add_search_points(grown, f);
        all.insert(all.end(), f.begin(), f.end());
      }
      return encode_search_points(all);
    });
    const std::vector<SearchPoint> points = decode_search_points(wave);
    add_search_points(plan, points);
    if (!first && points.empty()) break;
    SweepOptions w = o;
    w.restart = first && o.restart;
    w.write_report = nullptr;
    // The first wave (the planned points, and any a resumed search replayed) has the progress
    // line; a bisection wave is a point per open bracket, announced in one line.
    if (!first) {
      w.progress = false;
      if (o.progress && farm.coordinator())
        std::fprintf(stderr, "[sweep] search wave %zu: %zu bisection point(s)\n", ++waves, points.size());
    }
    const SweepOutcome r = run_sweep(plan, w, farm);
    total.ran += r.ran;
    total.partial_bytes_dropped += r.partial_bytes_dropped;
    if (first) total.references_cached = r.references_cached;
    total.references_computed += r.references_computed;
    total.self_checks_computed += r.self_checks_computed;
    first = false;
  }
  SweepOptions last = o;
  last.restart = false;
  last.progress = false;
  const SweepOutcome r = run_sweep(plan, last, farm);  // nothing left to run: the report
  total.points = r.points;
  total.skipped = r.points - total.ran;
  total.wall_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return total;
}

SweepOutcome run_search_sweep(SweepPlan plan, const SweepOptions& options) {
  auto farm = make_thread_farm(options.jobs);
  return run_search_sweep(std::move(plan), options, *farm);
}

}  // namespace tippe
