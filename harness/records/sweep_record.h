// The sweep record (one line of records.jsonl), sweep.json, and the predicates on a record every reader of them shares.
#pragma once

#include <cstddef>
#include <filesystem>
#include <limits>
#include <optional>
#include <stdexcept>
#include <string>
#include <type_traits>
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

// Limits of `ladder.search`. The resolution is in log10 units: 1e-3 is a factor of 1.0023, finer
// than any step a run could tell apart from its neighbour, and far above the 6 significant digits
// the values are written with; above 1 (a decade) a bracket says little a ladder would not.
constexpr double kMinSearchResolution = 1e-3, kMaxSearchResolution = 1.0;
constexpr int kMaxSearchPerDecade = 20;
constexpr double kMaxSearchDecades = 20;

// ---- the sweep record's field list ------------------------------------------------------------

// What a sweep record's `visit` says of one field: its JSON key, its doc and the check its reader
// makes (records are input: every field is checked, an error names the dotted key); the schema
// (sweep_schema.h) says the same of each field. The sweep record
// keeps its own list rather than records/fields.h's because its JSON groups some members
// ("work", "grid", "class") and its reader's messages are those of a sweep file's.
class SweepField {
 public:
  enum class Check { none, name, key, label, status, run_class, criterion };
  // `doc`: the field's unit and meaning, the schema's description (sweep_schema.h).
  SweepField(const char* key, const char* doc = "") : key_(key), doc_(doc) {}
  // Absent (or null) in records written before it: the reader keeps the default (a label: the
  // number's text; a group: nothing read).
  SweepField since() const { SweepField f = *this; f.since_ = true; return f; }
  // A name that becomes a file name and a report label (is_valid_name).
  SweepField name() const { return with(Check::name); }
  // A setting key ("engines.ode.timestep"), the rule of names.
  SweepField setting_key() const { return with(Check::key); }
  // An axis value's text: a name or a number equal to `value` (named `value_key` in messages).
  SweepField label_of(const char* value_key, double value) const {
    SweepField f = with(Check::label);
    f.value_key_ = value_key;
    f.value_ = value;
    return f;
  }
  SweepField status() const { return with(Check::status); }        // run_status_names()
  SweepField run_class() const { return with(Check::run_class); }  // a stability-map class
  SweepField criterion() const { return with(Check::criterion); }  // parse_criterion's form
  // An integer in [lo, hi]; a number >= lo.
  SweepField range(long long lo, long long hi) const { SweepField f = *this; f.lo_ = lo; f.hi_ = hi; return f; }
  SweepField at_least(double lo) const { SweepField f = *this; f.min_ = lo; return f; }
  // A number always written as one: null (which the reader takes as NaN elsewhere) is refused.
  SweepField not_null() const { SweepField f = *this; f.not_null_ = true; return f; }
  // A group written as null (and null read as nothing) when `null` holds.
  SweepField null_if(bool null) const { SweepField f = *this; f.null_ = null; f.nullable_ = true; return f; }

  const char* key() const { return key_; }
  const char* doc() const { return doc_; }
  bool is_since() const { return since_; }
  Check check() const { return check_; }
  const char* value_key() const { return value_key_; }
  double value() const { return value_; }
  long long lo() const { return lo_; }
  long long hi() const { return hi_; }
  double min() const { return min_; }
  bool nullable() const { return nullable_; }
  bool is_null() const { return null_; }
  bool is_not_null() const { return not_null_; }

 private:
  SweepField with(Check c) const { SweepField f = *this; f.check_ = c; return f; }
  const char* key_;
  const char* doc_;
  bool since_ = false, nullable_ = false, null_ = false, not_null_ = false;
  Check check_ = Check::none;
  const char* value_key_ = "";
  double value_ = 0;
  long long lo_ = 0, hi_ = std::numeric_limits<long long>::max();
  double min_ = -std::numeric_limits<double>::infinity();
};

// A point's indices are below the plan's size; work counters are counts.
constexpr long long kMaxSweepIndex = static_cast<long long>(kMaxSweepPoints) - 1;
constexpr long long kMaxSweepCount = std::numeric_limits<long long>::max();

// The fields of records.jsonl's line but "format" (to_json writes it, the reader checks it
// first), in the order the reader checks them (a record with several faults names the first).
// `v(field, member)` for a field, `v.group(field, fields)` for a JSON object that groups members
// of the struct (fields: a callable taking the visitor of the group's own fields). A field's doc
// is its description in schemas/sweep-record.schema.json, generated from this list.
template <class R, class V>
std::enable_if_t<std::is_same_v<std::remove_const_t<R>, SweepRecord::ReferenceRun>> visit(R& f, V& v) {
  v(SweepField("status", "how the reference's run ended").status(), f.status);
  v(SweepField("method", "the reference's integration method"), f.method);
  v(SweepField("class", "the reference run's stability class").run_class(), f.run_class);
  v(SweepField("rtol", "the reference's relative tolerance").at_least(0.0), f.rtol);
  v(SweepField("cpu_seconds", "s: the reference run's CPU time; null: not run").at_least(0.0), f.cpu_seconds);
  v(SweepField("steps").range(0, kMaxSweepCount), f.steps);
  v(SweepField("rhs_evaluations").range(0, kMaxSweepCount), f.rhs_evaluations);
  v(SweepField("energy_initial", "J"), f.energy_initial);
  v(SweepField("energy_final", "J"), f.energy_final);
  v(SweepField("jellett_max_relative_drift", "the largest relative drift of Jellett's integral on one surface"),
    f.jellett_max_relative_drift);
  v(SweepField("final_tilt", "rad: tilt of the symmetry axis from the vertical at the last sample"), f.final_tilt);
}
// The rules of `ladder.search` in a sweep file (sweep_search.h); the reader then checks the
// range as a whole (check_search). from, to and resolution are never null: a search has a range.
template <class R, class V>
std::enable_if_t<std::is_same_v<std::remove_const_t<R>, SweepSearch>> visit(R& q, V& v) {
  v(SweepField("criterion", "\"regime\" or terms joined by \" and \" (sweep_record.h, SearchCriterion)").criterion(),
    q.criterion);
  v(SweepField("from", "the key's range: from > 0 (the search is in log10)")
        .at_least(std::numeric_limits<double>::min())
        .not_null(),
    q.from);
  v(SweepField("to", "the key's range: to > from, at most 20 decades above it").at_least(q.from).not_null(), q.to);
  v(SweepField("resolution", "log10 units, at most 1: bisection stops when the bracket is narrower")
        .at_least(kMinSearchResolution)
        .not_null(),
    q.resolution);
  v(SweepField("per_decade", "coarse grid points per decade").range(1, kMaxSearchPerDecade), q.per_decade);
  v(SweepField("integer", "from and to are whole numbers (an iteration count)").since(), q.integer);
}
template <class R, class V>
std::enable_if_t<std::is_same_v<std::remove_const_t<R>, SweepRecord>> visit(R& r, V& v) {
  v(SweepField("point_id", "the point's identity in the plan"), r.point_id);
  v(SweepField("scene", "the scene's name").name(), r.scene);
  v(SweepField("scene_file"), r.scene_file);
  v(SweepField("physics_hash", "hash of the scene's physics (engine tables left out)"), r.physics_hash);
  v(SweepField("scene_index").range(0, kMaxSweepIndex), r.scene_index);
  v(SweepField("setup", "the setup's name").name(), r.setup);
  v(SweepField("engine").name(), r.engine);
  v(SweepField("set", "KEY=VALUE overrides of the setup"), r.set);
  v(SweepField("ladder_key", "the setting the ladder steps through").setting_key(), r.ladder_key);
  v(SweepField("ladder_value", "null: a value that is not a number"), r.ladder_value);
  // Records from before categorical ladders carry only the number.
  v(SweepField("ladder_label").label_of("ladder_value", r.ladder_value).since(), r.ladder_label);
  v(SweepField("setup_index").range(0, kMaxSweepIndex), r.setup_index);
  v(SweepField("ladder_index").range(0, kMaxSweepIndex), r.ladder_index);
  v.group(SweepField("grid", "the grid's axis; null (or absent) without one").null_if(r.grid_key.empty()), [&](auto& g) {
    g(SweepField("key").setting_key(), r.grid_key);
    g(SweepField("value", "null: a value that is not a number"), r.grid_value);
    g(SweepField("label").label_of("grid.value", r.grid_value), r.grid_label);
    g(SweepField("index").range(0, kMaxSweepIndex), r.grid_index);
  });
  v(SweepField("repeats", "runs of the point; its times are their minima").range(1, kMaxRepeats), r.repeats);
  v(SweepField("duration", "s: the scene's run.duration as run").at_least(0.0), r.duration);
  v(SweepField("status", "how the run ended").status(), r.status);
  v(SweepField("status_time", "s"), r.status_time);
  v(SweepField("status_detail"), r.status_detail);
  v(SweepField("inversion_time", "s: this run's first inversion; null: none"), r.inversion_time);
  v(SweepField("stem_contact_time", "s: this run's first stem contact; null: none"), r.stem_contact_time);
  v(SweepField("reference_inversion_time", "s: the reference's first inversion; null: none"), r.reference_inversion_time);
  v(SweepField("reference_stem_contact_time", "s: the reference's first stem contact; null: none"),
    r.reference_stem_contact_time);
  v(SweepField("metrics", "the run against the reference; its times and costs are the minima over the repeats"),
    r.metrics);
  v.group(SweepField("work"), [&](auto& g) {
    g(SweepField("cpu_seconds", "s: the run's own thread, minimum over the repeats").at_least(0.0), r.cpu_seconds);
    g(SweepField("cpu_seconds_repeats", "s: every repeat, in order"), r.cpu_seconds_repeats);
    g(SweepField("wall_seconds", "s: minimum over the repeats").at_least(0.0), r.wall_seconds);
    g(SweepField("steps").range(0, kMaxSweepCount), r.steps);
    g(SweepField("rhs_evaluations").range(0, kMaxSweepCount), r.rhs_evaluations);
    g(SweepField("solver_iterations").range(0, kMaxSweepCount), r.solver_iterations);
  });
  v(SweepField("engine_version"), r.engine_version);
  v(SweepField("git_commit", kGitCommitDoc), r.git_commit);
  v(SweepField("settings", "every accuracy setting in force, each as text"), r.settings);
  // Absent in records written before classification: the class the status implies.
  v.group(SweepField("class", "the stability class of the run (README, 'Stability map'); absent in records written "
                              "before classification: the class the status implies")
              .since(),
          [&](auto& g) {
            g(SweepField("name").run_class(), r.run_class);
            g(SweepField("time", "s: when it happened; null: not dated, or ok"), r.class_time);
            g(SweepField("reason"), r.class_reason);
          });
  // Absent (or null) in records written before it, and for a record with no reference run.
  v(SweepField("reference", "the reference's own run on this scene; null or absent: none").since(), r.reference);
  v(SweepField("search", "the point's boundary search (a sweep file's ladder.search); null or absent without one")
        .since(),
    r.search);
}

// The stability-map classes a record's class may name (classify.h's RunClassKind, in its
// order): the reader refuses any other, since they name the report's CSS classes.
const std::vector<std::string>& run_class_names();

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
