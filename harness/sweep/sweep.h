// Work-precision sweeps: sweep files and their points, and resumable, sharded and distributed runs into records.jsonl.
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

#include "harness/io/hash.h"
#include "harness/records/sweep_record.h"
#include "analytic/scene.h"
#include "harness/measure/task_farm.h"

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
//    shipped scene does): a sweep never changes the physics. Neither axis' key may also be in
//    `set`. Instead of values, the ladder may be a
//    boundary search, ladder.search = {key, from, to, criterion, resolution, per_decade}
//    (read_search, sweep_search.h). scenes (optional): names of the sweep's scenes the setup runs
//    on, each once (default: every scene).
//  - every scene with every setup, ladder and grid value must load (the scene's checks and
//    validate_engine_settings: a value the engine setting refuses, "pyramid" for a cone, is
//    refused here); the scene's message is quoted after the sweep key
//    (setup[i].ladder.values[j] or setup[i].grid.values[j]).
SweepPlan load_sweep(const std::string& path);

// Stable id of a point: hash of the scene's physics, the setup (name, engine, overrides, key),
// the ladder value's text and the repeats; with a grid, then its key and the grid value's text
// (a one-axis point's id is what it was before grids existed: published directories resume).
// A search's id also hashes the search (criterion, range, resolution, grid density).
std::string sweep_point_id(const std::string& physics_hash, const SweepSetup& setup, const std::string& value_text,
                           int repeats, const std::string& grid_value_text = "");

// ---- running ----------------------------------------------------------------------------------

// "I/N" with 0 <= I < N <= 1000000; throws std::invalid_argument quoting the text.
SweepShard parse_shard(const std::string& text);
// The indices into plan.points of shard I of N, increasing. The shares partition the points and
// balance their a priori cost (longest processing time first); a pure function of the plan.
std::vector<size_t> shard_points(const SweepPlan& plan, const SweepShard& shard);

using SweepReportWriter = std::function<void(const std::string& dir, const std::vector<SweepRecord>& records)>;

struct SweepOptions {
  std::string out_dir;
  std::optional<SweepShard> shard;  // only this share of the points (sweep.json records which)
  int jobs = 1;
  bool restart = false;  // a DIR started with another sweep file (or other scene physics) is begun again
  bool progress = true;  // progress line with the time left on stderr
  // Writes the report into a staging directory from the finished records (the command line gives
  // write_sweep_report); empty: records only (a boundary search's waves report once, at the end).
  // The sweep itself knows nothing of reports: running and reporting meet in the command line.
  SweepReportWriter write_report;
};


struct SweepOutcome {
  size_t points = 0, skipped = 0, ran = 0;  // skipped: finished by an earlier run of the same DIR
  size_t references_cached = 0;  // read from OUT/reference/ (with or without their self-check)
  // Computed now: whole references (the reference run, and its self-check when asked for), and
  // the self-check alone of a cached reference that had none (an entry written before the
  // self-check existed, or whose self_check.json was lost, cut short or made for another run).
  size_t references_computed = 0, self_checks_computed = 0;
  size_t partial_bytes_dropped = 0;
  double wall_seconds = 0;
};

// Runs every point of `plan` (or of options.shard's share) not yet in OUT/records.jsonl, on
// `jobs` threads, appending one fsynced line per finished point; then writes the report. Layout
// of OUT: sweep.json (the sweep file, its hash, the plan hash and the shard), records.jsonl,
// reference/<physics_hash>/{summary.json, trajectory.csv, self_check.json}, report.md,
// index.html, *.svg. Throws SweepInputError before anything is written; an engine that diverges
// or throws is a point with that status, not an error.
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
                          const SweepReportWriter& write_report);

}  // namespace tippe
