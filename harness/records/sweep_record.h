// The sweep record (one line of records.jsonl), sweep.json, and the predicates on a record every reader of them shares.
#pragma once

#include <cstddef>
#include <filesystem>
#include <limits>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "harness/records/comparison.h"
#include "harness/records/metric_bounds.h"

namespace tippe {

// A judgement: repeats only sharpen the minimum CPU time of a point, which settles after a few;
// more than 100 is likelier a typo than a wish for a sweep that many times as long.
constexpr int kMaxRepeats = 100;

// `ladder.search`: instead of fixed values, the boundary of a criterion along the ladder's key,
// bracketed on a coarse log grid and bisected in log space (sweep_search.h). Records carry it so
// that the report and gates find each search's points from the records alone.
struct SweepSearch {
  std::string criterion;  // "regime" or "METRIC <= BOUND" (a gate metric), trimmed
  double from = 0, to = 0;  // 0 < from < to, the key's range
  double resolution = 0.05;  // log10 units: bisection stops when the bracket is narrower
  int per_decade = 1;        // coarse grid points per decade
  // from and to written as integers: every value is a whole number (an iteration count), and a
  // bracket of two neighbouring integers is as fine as the search gets.
  bool integer = false;
};

// A sweep's plan is refused above this many points, before a single one is loaded: each point
// loads its scene (about a millisecond), and the largest shipped sweep has 264. 1e5 points is a
// day of planning-free running at ~1 s a point on 100 cores; more is likelier a runaway ladder.
constexpr size_t kMaxSweepPoints = 100000;

// Input a sweep cannot start with (jobs < 1, an output directory started with another sweep,
// or in use): found before anything is written; `tippe sweep` exits 2.
class SweepInputError : public std::invalid_argument {
 public:
  using std::invalid_argument::invalid_argument;
};

// A record (or sweep.json) read back that is not one: "KEY: reason", KEY dotted
// ("work.steps"); read_records puts "FILE:LINE: " before it. Records are input (shared,
// downloaded, edited): bad ones are bad input, exit 2, like a bad sweep file.
class SweepRecordError : public SweepInputError {
 public:
  using SweepInputError::SweepInputError;
};

// One line of records.jsonl: a finished point, with everything the report needs.
struct SweepRecord {
  std::string point_id;
  std::string scene, scene_file, physics_hash;
  long long scene_index = 0;
  std::string setup, engine;
  std::vector<std::string> set;
  std::string ladder_key;
  double ladder_value = 0;   // NaN (null) for a value that is not a number
  std::string ladder_label;  // the value as text ("0.001", "com", "true"); from the number in older records
  long long setup_index = 0, ladder_index = 0;
  // The grid's axis ("grid": null without one, and in records from before grids).
  std::string grid_key;  // empty: no grid
  double grid_value = std::numeric_limits<double>::quiet_NaN();
  std::string grid_label;
  long long grid_index = 0;
  long long repeats = 1;
  double duration = 0;  // the scene's run.duration as run
  std::string status = "ok";
  double status_time = 0;
  std::string status_detail;
  std::optional<double> inversion_time, stem_contact_time;  // this run's first events
  std::optional<double> reference_inversion_time, reference_stem_contact_time;
  Metrics metrics;         // compare_runs against the reference; its cpu/wall/cost fields are the minima below
  double cpu_seconds = 0;  // the run's own thread, minimum over the repeats
  std::vector<double> cpu_seconds_repeats;  // every repeat, in order
  double wall_seconds = 0;                  // minimum over the repeats
  long long steps = 0, rhs_evaluations = 0, solver_iterations = 0;
  std::string engine_version, git_commit;
  nlohmann::json settings = nlohmann::json::object();  // every accuracy setting in force
  // classify_run of this run (classify.h): ok, diverged, unphysical, clamped, failed or
  // contact_lost, when it happened (NaN: not dated, or ok) and why. Records written before
  // classification existed read back with the class their status implies.
  std::string run_class = "ok";
  double class_time = std::numeric_limits<double>::quiet_NaN();
  std::string class_reason;
  // The reference's own run on this scene (the same for every point of it), so that the report
  // shows how the reference itself fares at the extremes: cost, conservation, its class.
  struct ReferenceRun {
    std::string status, method, run_class;
    double rtol = 0, cpu_seconds = 0;
    long long steps = 0, rhs_evaluations = 0;
    double energy_initial = 0, energy_final = 0, jellett_max_relative_drift = 0, final_tilt = 0;
  };
  std::optional<ReferenceRun> reference;  // absent in records written before it existed
  std::optional<SweepSearch> search;      // the point's boundary search ("search": null without one)
};
nlohmann::json to_json(const SweepRecord& r);
// Every field checked for its type and range (indices 0 <= i < kMaxSweepPoints, repeats as in a
// sweep file, counts >= 0, times and costs numbers or null, the class a known name, keys and
// labels of the axes names (is_valid_name) or numbers, a label equal to its axis' number, a
// search null or absent or with the rules of ladder.search);
// throws SweepRecordError "KEY: reason" for anything else, another format included.
SweepRecord sweep_record_from_json(const nlohmann::json& j);
// One line of records.jsonl, '\n' included.
std::string to_jsonl(const SweepRecord& r);

// Length of the longest prefix of `text` that is made of complete ('\n'-terminated) lines.
size_t complete_lines_length(const std::string& text);

struct RecordsFile {
  std::vector<SweepRecord> records;  // complete lines, in file order
  std::vector<size_t> lines;         // the 1-based line of each record
  size_t complete_bytes = 0;         // bytes of the complete lines
  size_t partial_bytes = 0;          // a last line without '\n' (a write cut short), dropped
};
// Reads records.jsonl (a missing file is empty; one over kMaxRecordFileBytes throws
// std::runtime_error). A complete line that is not a record throws SweepRecordError
// "FILE:LINE: KEY: reason"; a partial last line is only measured.
RecordsFile read_records(const std::string& path);
// The same on the file's text, `name` standing for the file; throws only SweepRecordError.
RecordsFile parse_records_text(const std::string& text, const std::string& name);
// read_records, then truncates the file to its complete lines (fsynced) when the last is partial.
RecordsFile recover_records(const std::string& path);
// Renames `file`, when it exists, to the first free name of FILE.old, FILE.old.2, FILE.old.3, ...
// (--restart keeps every earlier record file, never one over another). Returns the new name, or ""
// when there was no file. Throws std::runtime_error naming the file when the rename fails.
std::filesystem::path keep_aside(const std::filesystem::path& file);

// One of N deterministic shares of a sweep's points (`--shard I/N`), for job arrays.
struct SweepShard {
  int index = 0, count = 1;
};

// sweep.json read back: the fields a resumed run and a merge use, each checked.
struct SweepMeta {
  nlohmann::json meta;  // the whole object
  std::string sweep_hash, plan_hash;
  std::optional<size_t> points;  // absent in files from before it existed
  std::optional<SweepShard> shard;
  std::vector<std::string> shard_point_ids;
};
// Throws SweepRecordError "NAME: KEY: reason": not JSON, sweep_hash or plan_hash not a string,
// points not an integer in [0, kMaxSweepPoints], shard not null or {index, count, point_ids} with
// 1 <= count <= 1000000, 0 <= index < count and at most `points` ids.
SweepMeta parse_sweep_meta(const std::string& text, const std::string& name);

// Whether a point is in the reference's regime: the reference inverts and so does the run (status
// ok or not), or the reference does not invert and the run finished (status ok) without inverting.
bool agrees_with_reference_regime(const SweepRecord& r);
// Whether a larger value of this ladder key is the softer (cheaper, less accurate) setting:
// true for time steps and tolerances, false for iteration and substep counts.
bool larger_is_softer(const std::string& ladder_key);
// The text of an axis value of a record: the number as %g, else the label.
std::string ladder_text(const SweepRecord& r);
std::string grid_text(const SweepRecord& r);

// Limits of `ladder.search`. The resolution is in log10 units: 1e-3 is a factor of 1.0023, finer
// than any step a run could tell apart from its neighbour, and far above the 6 significant digits
// the values are written with; above 1 (a decade) a bracket says little a ladder would not.
constexpr double kMinSearchResolution = 1e-3, kMaxSearchResolution = 1.0;
constexpr int kMaxSearchPerDecade = 20;
constexpr double kMaxSearchDecades = 20;
// ---- the one criterion of "safe" --------------------------------------------------------------

// Whether a point is a setting a user may rely on. Every reader that decides it calls
// is_safe: the boundary search, the sweep page's "setting to use" and its regime counts, the
// gates on a search's boundary ([[boundary]]) and `tippe advise`. Its terms, all required:
//  - the run finished (status ok) and the stability map classes it ok: a run that ends in time
//    having diverged or broken a conservation law (classify.h: an energy rise in a dissipative
//    scene, Jellett's J drifting where it is conserved) is no setting to use, whatever else it got
//    right;
//  - `regime`: in the reference's regime (agrees_with_reference_regime), judged only inside the
//    reference's converged window: an inversion pairing "unconverged" (the reference's or the
//    run's inversion after its self-check parted) is not safe, since nothing is known there;
//  - `inversion`: where the reference inverts, the run inverts too and |relative inversion-time
//    error| <= the tolerance (a term that asks nothing where the reference does not invert);
//  - each `bounds` entry: |METRIC| <= BOUND (threshold_row's rule: an absent or NaN metric fails).
// Text form (parse_criterion): terms joined by " and ": "regime", "inversion within 1%" (or a
// fraction: "inversion within 0.01"), "METRIC <= BOUND". "regime" and "METRIC <= BOUND" alone
// read as they did before the terms could be combined.
struct SearchCriterion {
  bool regime = true;
  std::optional<double> inversion;  // the tolerance on |inversion_time_rel_error|, as a fraction
  std::vector<Threshold> bounds;
  // The one metric bound of a single "METRIC <= BOUND" criterion (what a search's not_applicable
  // status is about); nullptr otherwise.
  const Threshold* only_bound() const { return !regime && !inversion && bounds.size() == 1 ? &bounds.front() : nullptr; }
};
// Throws std::invalid_argument with the reason.
SearchCriterion parse_criterion(const std::string& text);
// The criterion as text, in parse_criterion's form (what pages and gate files print).
std::string criterion_text(const SearchCriterion& c);
// The one predicate: see SearchCriterion.
bool is_safe(const SearchCriterion& c, const SweepRecord& r);
// The same with a reason when it fails ("" when safe): the first term that failed.
std::string unsafe_reason(const SearchCriterion& c, const SweepRecord& r);
// The search's name for is_safe (kept for its readers).
inline bool criterion_passes(const SearchCriterion& c, const SweepRecord& r) { return is_safe(c, r); }

}  // namespace tippe
