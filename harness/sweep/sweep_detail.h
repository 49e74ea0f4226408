// What the parts of a sweep run share: each scene's reference, the coordinator's decision of what runs, one point's run, and a point's a-priori cost.
#pragma once

#include <cmath>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "harness/measure/compare.h"
#include "harness/sweep/sweep.h"

namespace tippe {
class OutputDir;  // harness/io/output_dir.h: prepare() holds the sweep directory's lock
}  // namespace tippe

namespace tippe::sweep_detail {

// The reference of one scene, shared read-only by every point of it.
struct Reference {
  RunRecord record;
  Trajectory trajectory;
  std::optional<SweepRecord::ReferenceRun> summary;  // filled once loaded or computed
  // Its self-check (the scene's engines.analytic.self_check, on by default): a second reference
  // by an independent method; every point's metrics against the reference stop at its
  // converged_until, as in a comparison. Absent: not asked for.
  std::optional<SelfCheck> self_check;
  // A reference that failed is a result: every point of its scene is recorded as failed with
  // this reason (non-empty) instead of being run against nothing.
  std::string failure;
  double failure_time = std::nan("");
};

// A point whose scene's reference failed: a failed record carrying the reference's reason, so that
// the other scenes' points run and the report shows which scene and why.
SweepRecord reference_failed_record(SweepRecord r, const Scene& scene, const Reference& ref);
SweepRecord::ReferenceRun reference_summary(const Scene& scene, const Reference& ref);

// Texts each behind its length: what a worker sends back and what the coordinator shares with
// every rank.
std::string pack_texts(const std::vector<std::string>& texts);
// Reads `count` pack_texts fields at `pos` (advanced past them); throws std::runtime_error when
// cut short.
std::vector<std::string> unpack_texts(const std::string& bytes, size_t& pos, size_t count);
// A reference as a message: 'R' and its cache files' texts, "summary.json", "trajectory.csv" and
// its self-check as JSON ("null" when not asked for).
std::string reference_text(const std::string& summary, const std::string& csv, const std::optional<SelfCheck>& check);
// Reads a reference_text's three fields after its 'R' at `pos`.
struct ReferenceTexts {
  std::string summary, csv;
  std::optional<SelfCheck> self_check;
};
ReferenceTexts read_reference_text(const std::string& bytes, size_t& pos);
// What a reference's task sends back: a reference_text, or 'F' and, for a reference that
// failed, the time and the reason (a result, not an error: its scene's points are recorded as
// failed).
std::string failed_reference_text(double time, const std::string& why);
// Reads a failed_reference_text at `pos` into ref; false (pos unmoved) for an 'R' entry.
bool read_failed_reference(const std::string& bytes, size_t& pos, Reference& ref);
// Runs the reference at the scene's own tolerances, on whichever process the task lands, and
// (scene.run.self_check) its self-check beside it.
std::string compute_reference_texts(const Scene& scene);
// Into the cache dir (summary.json, trajectory.csv, self_check.json) and into memory, read back
// from the very texts every other rank will read.
void store_reference(const std::filesystem::path& dir, const Scene& scene, const std::string& hash,
                     const std::string& texts, Reference& ref);
// The self-check alone of a reference read from the cache without one (reference_cache.h): the
// second method's run and the comparison with `ref`, on whichever process the task lands (every
// rank holds the reference by then); to_json(SelfCheck) as text. The reference is not run again.
std::string compute_self_check_text(const Scene& scene, const Reference& ref);
// That text into memory (ref.self_check) and beside the reference in the cache dir; throws
// std::runtime_error naming the scene when it does not read back.
void store_self_check_text(const std::filesystem::path& dir, const Scene& scene, const std::string& hash,
                           const std::string& text, Reference& ref);

// A point's repeats are interleaved with other points' runs, so that a slow phase of the machine
// (a heavy neighbour on the other core, the host's load) is unlikely to last through all of
// them: the point's record comes from its first run, and each later repeat adds its times.
struct RepeatTime {
  double cpu = 0, wall = 0;  // the run's own thread's CPU seconds, wall seconds
};
struct FirstRun {
  SweepRecord record;
  double final_time = std::nan("");     // the simulated time the run reached (real_time_factor)
  double reference_cpu = 0;             // the reference's CPU seconds (cost_ratio)
  bool timed = true;                    // false: the scene's reference failed and nothing ran
};
// Runs the point once on the calling thread into its record, its times those of this run.
FirstRun run_point_first(const SweepPlan& plan, const SweepPoint& p, const Reference& ref);
// Runs the point again for its times alone; none when it throws (its first run's record says why)
// or when its scene's reference failed.
std::optional<RepeatTime> time_point(const SweepPlan& plan, const SweepPoint& p, const Reference& ref);
// Every repeat's times, in the order they ran (the first run's first), into the record: CPU and
// wall seconds their minima, cpu_seconds_repeats the list, cost_ratio and real_time_factor from them.
void set_repeat_times(FirstRun& f, const std::vector<RepeatTime>& times);
// The tasks' texts, as a worker (another rank) sends them back: exact both ways.
std::string first_run_text(const FirstRun& f);
FirstRun read_first_run_text(const std::string& text);
std::string repeat_time_text(const std::optional<RepeatTime>& t);
std::optional<RepeatTime> read_repeat_time_text(const std::string& text);
// The order the runs are handed out in: for each block of `block` consecutive points (indices
// 0..points-1 of the order they are to run in), `repeats` rounds over the block, each running every
// point of it once. Between two repeats of a point every other point of its block runs once; a
// point's record is complete when its block's last round reaches it, so an interrupted sweep loses
// at most a block's runs. repeats = 1: each point once, in order.
struct SweepTask {
  size_t point = 0;  // index into the points to run
  int round = 0;     // 0: the run that makes the record; 1..repeats-1: timing only
};
std::vector<SweepTask> repeat_schedule(size_t points, int repeats, size_t block);
// A priori cost of a point in arbitrary units (steps for a time-step ladder).
double point_weight(const SweepPlan& plan, const SweepPoint& p);

// What the coordinator found in OUT and decided, shared with every rank: which points run, in
// which order, and which references must be computed.
struct Prepared {
  std::vector<size_t> todo;        // indices into plan.points, in the order they are handed out
  std::vector<size_t> needed;      // scenes with a point in todo
  std::vector<size_t> to_compute;  // of those, the ones not in the cache
  std::vector<size_t> to_check;    // of those, the ones in the cache without the self-check asked for
  size_t share = 0, skipped = 0, cached = 0, partial_bytes = 0;
};

// The coordinator's half of a sweep's start (sweep_prepare.cpp): checks OUT, takes its lock,
// recovers records.jsonl, decides what runs and loads the cached references into `refs`. Throws
// SweepInputError before anything is written.
Prepared prepare(const SweepPlan& plan, const SweepOptions& o, std::unique_ptr<OutputDir>& lock,
                 std::vector<Reference>& refs);
// The decision as the message every rank reads.
std::string encode(const Prepared& p);
Prepared decode(const std::string& bytes);

}  // namespace tippe::sweep_detail
