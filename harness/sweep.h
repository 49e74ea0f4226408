// Work-precision sweeps: sweep files, their points, resumable runs into records.jsonl, and the report's analysis.
#pragma once

#include <algorithm>
#include <cstddef>
#include <filesystem>
#include <functional>
#include <limits>
#include <nlohmann/json.hpp>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "compare.h"
#include "scene.h"
#include "task_farm.h"

namespace tippe {

// ---- sweep files ------------------------------------------------------------------------------

// One entry of `scenes`: a path (relative to the sweep file) or a table {file, duration}.
struct SweepScene {
  std::string file;                // as written in the sweep file
  std::string path;                // resolved against the sweep file's directory
  std::optional<double> duration;  // this scene's own override of run.duration
};

// One [[setup]]: an engine, fixed overrides, the key swept over `values`, and optionally a
// second key (a grid: every ladder value with every grid value).
//
// The file form is two tables, not an array of axes:
//   ladder = { key = "engines.mujoco.timestep", values = [1e-3, 5e-4] }
//   grid   = { key = "engines.mujoco.body_frame", values = ["com", "ball_centre"] }
// because the two axes play different parts: the ladder is walked along (a work-precision line,
// a convergence order, the softest setting still in the reference's regime), the grid picks the
// line (one line per grid value, and the "Modelling choices" comparison across them at each
// ladder value). `ladder = [{...}, {...}]` would leave which is which to the order of the
// entries; with two names, a one-axis file reads exactly as before and a grid says what it does.
// Values of either axis are all numbers, all strings or all booleans (a categorical axis:
// `values = ["com", "ball_centre"]`); strings follow the rule of names (is_valid_name), since
// they become report labels.
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

struct SweepSetup {
  std::string name, engine;
  std::vector<std::string> set;  // "KEY=VALUE" overrides, as written
  std::string ladder_key;
  std::vector<double> ladder_values;      // NaN for a value that is not a number
  std::vector<std::string> ladder_texts;  // each value as a TOML value (integers stay integers, strings quoted)
  std::vector<std::string> ladder_labels;  // each value as records carry it (the text, strings unquoted)
  std::string grid_key;                    // the second axis; empty: a one-axis ladder
  std::vector<double> grid_values;         // as the ladder's
  std::vector<std::string> grid_texts, grid_labels;
  bool has_grid() const { return !grid_key.empty(); }
  // A boundary search: ladder_values are its coarse grid (the points planned up front); the
  // bisection's points come in waves (sweep_search.h), each with its own value.
  std::optional<SweepSearch> search;
  // `scenes = ["toy_viscous", ...]`: the names of the sweep's scenes this setup runs on (empty:
  // every scene), for a setup that means nothing on some (an inversion-time criterion where the
  // reference does not invert).
  std::vector<std::string> only_scenes;
  bool runs_on(const std::string& scene) const {
    return only_scenes.empty() || std::find(only_scenes.begin(), only_scenes.end(), scene) != only_scenes.end();
  }
  // Points of this setup: ladder values times grid values (1 without a grid).
  size_t point_count() const { return ladder_values.size() * (has_grid() ? grid_values.size() : 1); }
};

struct SweepSpec {
  std::string file;  // as given
  std::string hash;  // FNV-1a 64 of the file's bytes (16 hex digits)
  std::string text;  // the file's bytes
  std::string description;
  int repeats = 1;                 // timing repeats per point; the minimum CPU time is kept
  std::optional<double> duration;  // override of every scene's run.duration
  std::vector<SweepScene> scenes;
  std::vector<SweepSetup> setups;
};

// One run of a sweep: a scene with a setup's overrides and one ladder value applied.
struct SweepPoint {
  size_t scene_index = 0, setup_index = 0, ladder_index = 0;
  size_t grid_index = 0;  // 0 without a grid
  // The ladder value run: the setup's ladder_values[ladder_index], or a search's bisection value.
  double ladder_value = 0;
  std::string ladder_text, ladder_label;
  std::string id;  // sweep_point_id(...)
  Scene scene;     // as run (every override applied)
};

// A sweep file with every scene and point loaded and checked.
struct SweepPlan {
  SweepSpec spec;
  std::vector<Scene> scenes;                // the reference's scenes (duration override applied)
  std::vector<std::string> physics_hashes;  // physics_hash of each of those
  std::vector<SweepPoint> points;           // scene-major, then setup, then grid, then ladder order
  std::string plan_hash;                    // hash over the point ids: changes when any scene's physics does
  // The points known up front (the first `planned` of `points`): a boundary search adds its
  // bisection points after them as its records come in (extend_search_plan, sweep_search.h).
  size_t planned = 0;
  std::vector<std::vector<std::string>> scene_overrides;  // each scene's own overrides (its duration)
};

// Reads and checks a sweep file and every point it expands to. Throws SceneError
// "FILE: KEY: reason" (KEY dotted with 0-based indices, e.g. "setup[1].ladder.values[2]"), or
// "FILE:LINE:COL: reason" for TOML syntax. Rules:
//  - top level: description (string, one line), repeats (integer 1..100, default 1), duration
//    (number > 0), scenes (non-empty array), setup (non-empty array of tables); nothing else.
//  - scenes[i]: a path, or {file = PATH, duration = NUMBER > 0}; relative to the sweep file;
//    each must load as a scene (its own error is quoted); no scene listed twice.
//  - setup[i]: name (letters, digits, '.', '_', '-'; unique), engine (one of
//    available_engines()), set (array of "KEY=VALUE" strings, optional), ladder = {key, values}
//    (values a non-empty array of distinct values: all finite numbers, all strings that pass
//    is_valid_name, or all booleans), grid = {key, values} (optional, the same rules; its key
//    other than the ladder's). A setup may only touch its engine's settings (engines.ENGINE.*)
//    or, for the analytic model, engines.analytic.rtol/atol/method (their older spelling
//    run.rtol/atol/method is refused on a scene that gives them in [engines.analytic], as every
//    shipped scene does): a sweep never changes the physics. Neither axis' key may also be in `set`. Instead of values, the ladder may be a
//    boundary search, ladder.search = {key, from, to, criterion, resolution, per_decade}
//    (read_search, sweep_search.h). scenes (optional): names of the sweep's scenes the setup runs
//    on, each once (default: every scene).
//  - every scene with every setup, ladder and grid value must load (the scene's checks and
//    validate_engine_settings: a value the engine setting refuses, "pyramid" for a cone, is
//    refused here); the scene's message is quoted after the sweep key
//    (setup[i].ladder.values[j] or setup[i].grid.values[j]).
SweepPlan load_sweep(const std::string& path);

// FNV-1a 64 of the parts, each followed by a 0 byte, as 16 hex digits.
std::string fnv1a_hex(const std::vector<std::string>& parts);
// Stable id of a point: hash of the scene's physics, the setup (name, engine, overrides, key),
// the ladder value's text and the repeats; with a grid, then its key and the grid value's text
// (a one-axis point's id is what it was before grids existed: published directories resume).
// A search's id also hashes the search (criterion, range, resolution, grid density).
std::string sweep_point_id(const std::string& physics_hash, const SweepSetup& setup, const std::string& value_text,
                           int repeats, const std::string& grid_value_text = "");

// ---- records ----------------------------------------------------------------------------------

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

// ---- running ----------------------------------------------------------------------------------

// "I/N" with 0 <= I < N <= 1000000; throws std::invalid_argument quoting the text.
SweepShard parse_shard(const std::string& text);
// The indices into plan.points of shard I of N, increasing. The shares partition the points and
// balance their a priori cost (longest processing time first); a pure function of the plan.
std::vector<size_t> shard_points(const SweepPlan& plan, const SweepShard& shard);

struct SweepOptions {
  std::string out_dir;
  std::optional<SweepShard> shard;  // only this share of the points (sweep.json records which)
  int jobs = 1;
  bool restart = false;  // a DIR started with another sweep file (or other scene physics) is begun again
  bool progress = true;  // progress line with the time left on stderr
  bool plots = true;     // gnuplot SVGs in the report
  bool report = true;    // false: records only (a boundary search's waves write the report once, at the end)
};


struct SweepOutcome {
  size_t points = 0, skipped = 0, ran = 0;  // skipped: finished by an earlier run of the same DIR
  size_t references_cached = 0;
  size_t partial_bytes_dropped = 0;
  double wall_seconds = 0;
};

// Runs every point of `plan` (or of options.shard's share) not yet in OUT/records.jsonl, on
// `jobs` threads, appending one fsynced line per finished point; then writes the report. Layout
// of OUT: sweep.json (the sweep file, its hash, the plan hash and the shard), records.jsonl, reference/<physics_hash>/{summary.json,
// trajectory.csv}, report.md, index.html, *.svg. Throws SweepInputError before anything is
// written; an engine that diverges or throws is a point with that status, not an error.
SweepOutcome run_sweep(const SweepPlan& plan, const SweepOptions& options);
// The same over a farm of processes (every rank calls it; task_farm.h): the coordinator does all
// of the above that touches OUT; each missing reference is computed by one worker and shared with
// every rank; the points are handed out one at a time. options.jobs is not used. Records are those
// of a local run (apart from timings and order).
SweepOutcome run_sweep(const SweepPlan& plan, const SweepOptions& options, TaskFarm& farm);

// Runs `make` on the coordinator and gives its result to every rank. When it throws, every rank
// throws the same: a SweepInputError as one, anything else as std::runtime_error with its text.
std::string from_coordinator(TaskFarm& farm, const std::function<std::string()>& make);

// `tippe sweep --merge`: shard directories of one sweep into one directory, as if run whole:
// sweep.json without a shard, records.jsonl in plan order, the references, the report. Refuses
// (SweepInputError naming the directory and the reason) shards of another sweep file or plan, of
// another shard count, a missing or repeated shard, a shard with unfinished or foreign points, an
// output directory that is one of the shards or holds another sweep.
struct MergeOutcome {
  size_t shards = 0, points = 0;
  std::vector<std::string> warnings;
};
MergeOutcome merge_sweeps(const std::vector<std::string>& shard_dirs, const std::string& out_dir, bool restart,
                          bool plots);

// ---- analysis (pure functions of records) -----------------------------------------------------

// Empirical order of convergence: least-squares slope of log(error) against log(h) over the
// asymptotic range, found as the longest run of consecutive points (in h) whose local slopes are
// all >= 0.5 (the error really falls with h: a floor or saturation is left out) and within
// max(0.25, 0.15 p) of the fitted slope p; ties go to the smaller residual, then the finer points.
struct ConvergenceFit {
  bool ok = false;  // at least two points in the range
  double order = 0;
  std::vector<size_t> used;  // indices into the input, in increasing h
  std::string note;          // why not, or "only 2 points"
};
// h and error of the same length; non-finite or non-positive pairs are ignored.
ConvergenceFit convergence_order(const std::vector<double>& h, const std::vector<double>& error);

// The cheapest point (least cpu_seconds; ties: fewer steps) among `records` with status ok and
// |inversion_time_rel_error| < threshold; -1 when none.
long long cheapest_below(const std::vector<SweepRecord>& records, double threshold);
// The cheapest point with status ok and |inversion_time_rel_error| <= error; -1 when none.
long long cheapest_at_least_as_accurate(const std::vector<SweepRecord>& records, double error);

// Whether a point is in the reference's regime: the reference inverts and so does the run (status
// ok or not), or the reference does not invert and the run finished (status ok) without inverting.
bool agrees_with_reference_regime(const SweepRecord& r);
// Whether a larger value of this ladder key is the softer (cheaper, less accurate) setting:
// true for time steps and tolerances, false for iteration and substep counts.
bool larger_is_softer(const std::string& ladder_key);
// One setup's points: walking from the finest setting to softer ones, the softest reached before
// the first point out of the reference's regime; -1 when even the finest disagrees or there are
// no points. Indices into `records`.
long long softest_agreeing(const std::vector<SweepRecord>& records);
// Where the reference does not invert and a time-step ladder's runs leave its regime (they
// invert): how that departure behaves as the step shrinks, read from the finished runs (status
// ok) finest last. "goes away": the finest runs are in the regime (from `in_regime_from` down);
// "converges": every finished run inverts and the two finest within 1 % of each other (the
// engine's model, not its step); "moves later": every finished run inverts, each finer one no
// earlier than 1 % before the next coarser, the two finest apart; "earlier at a finer step":
// neither; "none": no finished run leaves the regime; "mixed": the regime comes and goes along
// the ladder; "-": not a time-step ladder, the reference inverts, or
// fewer than two finished runs. The answer holds up to the runs' horizon only.
struct RegimeTrend {
  std::string verdict;
  std::optional<double> in_regime_from;                   // the coarsest step of the finest run of agreeing points
  std::vector<std::pair<double, double>> inversion_by_step;  // (step, inversion time), coarsest first
};
RegimeTrend regime_trend(const std::vector<SweepRecord>& records);

// The text of an axis value of a record: the number as %g, else the label.
std::string ladder_text(const SweepRecord& r);
std::string grid_text(const SweepRecord& r);

// "Modelling choices": what a choice axis (a setup's grid, or a ladder of non-numbers) does to the
// verdict on one scene. At each value of the other axis (the step; a one-axis setup has one), the
// choice's values are compared: the regime (inverts, does not invert, ends early) and, where
// two or more invert, the relative spread of their inversion times, (max - min) / min.
constexpr double kChoiceTimeThreshold = 0.01;  // a spread above this moves the verdict
struct ChoiceEffect {
  std::string scene, setup, engine;
  std::string key, at_key;          // the choice axis; the other one ("" without)
  std::vector<std::string> values;  // the choice's values, in sweep order
  std::optional<double> reference_inversion;  // the reference's, on this scene
  size_t steps = 0;                 // steps at which two or more values ran
  bool regime_moves = false;
  size_t regime_steps = 0;                    // steps at which the regime differs
  std::string regime_at;                      // the first of them
  std::vector<std::string> regime_outcomes;   // there, "VALUE: OUTCOME" for each value ("in the
                                              // reference's regime" added where it is)
  std::optional<double> largest_spread;       // over the steps where two or more invert
  std::string spread_at;                      // the step of the largest spread
  std::vector<std::string> spread_times;      // there, "VALUE T" for each value that inverts
  bool time_moves() const { return largest_spread && *largest_spread > kChoiceTimeThreshold; }
  bool moves() const { return regime_moves || time_moves(); }
};
// One entry per (scene, setup) with a choice axis, in sweep order.
std::vector<ChoiceEffect> modelling_choices(const std::vector<SweepRecord>& records);

// report.md, index.html and (when `plots`) the SVGs, into dir, from the records alone.
void write_sweep_report(const std::string& dir, const std::vector<SweepRecord>& records, bool plots);
std::string render_sweep_markdown(const std::vector<SweepRecord>& records);

}  // namespace tippe
