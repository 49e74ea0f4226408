// CI gates: gate files (named checks of an engine's settings against thresholds on comparison metrics), their evaluation and JUnit/JSON/table output.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "harness/measure/compare.h"
#include "harness/records/fields.h"
#include "harness/records/metric_bounds.h"
#include "harness/records/records.h"
#include "analytic/scene.h"

namespace tippe {

struct Check {
  std::string name;
  std::string scene;       // as written in the gate file
  std::string scene_path;  // resolved against the gate file's directory
  std::string engine;      // a registered engine (engines/core/registry.h), not the reference
  std::vector<std::string> set;        // [defaults].set then the check's own, as written
  std::optional<double> duration;      // the check's duration, else [defaults].duration
  std::vector<std::string> overrides;  // what load_scene gets: run.duration=... first, then `set`
  std::string status = "ok";           // required run status
  bool require_same_events = false;
  // The aligned event sequences (measure/event_alignment.h) may have no first wrong event.
  bool require_no_wrong_event = false;
  // Whether a threshold may be judged on the reference's converged window when that ends before
  // the check's duration (the reference's self-check, compare.h). false: such a row fails.
  bool allow_unconverged = false;
  std::vector<Threshold> max;  // in gate_metrics() order; [defaults].max merged under the check's
  Scene loaded;                // the scene with every override applied (checked at load)
};

struct GateFile {
  std::string file;  // as given
  std::vector<Check> checks;
};

// Reads and checks a gate file, and loads every check's scene with its overrides (which also
// checks the engine settings). Throws SceneError "FILE: KEY: reason" with KEY dotted and 0-based
// ("check[2].max.tilt_rms_error", "defaults.duration"), "FILE:LINE:COL: reason" for TOML syntax,
// "FILE: cannot read: reason". Rules:
//  - top level: [defaults] (optional) and [[check]] (at least one); nothing else.
//  - a check: name (required, unique; letters, digits, '.', '_', '-'), scene (path relative to
//    the gate file), engine (a registered engine), set (array of "KEY=VALUE" strings), duration
//    (number > 0, overrides run.duration), status (a run status: ok, contact_lost, diverged,
//    unphysical, clamped, failed; default ok), require_same_events (boolean, default false),
//    require_no_wrong_event (boolean, default false),
//    max (table: gate metric -> finite number >= 0), allow_unconverged (boolean, default false).
//  - [defaults] takes every check key but name; a check's own scalar wins, its `set` follows
//    the defaults' (later overrides win), its `max` entries replace the defaults' per metric.
//  - `set` may not name another engine's settings (engines.OTHER.*): they would not be used.
//  - scene and engine are required (from the check or [defaults]); the scene with its overrides
//    must load: the scene's own message is quoted after the gate key.
GateFile load_gate_file(const std::string& path);

// ---- evaluation -----------------------------------------------------------------------------

// One line of a check's verdict: the run status, an event pairing or the aligned sequences
// ("first_wrong_event"), or one threshold.
enum class GateRowKind { Status, Events, Threshold, Error };
struct GateRow {
  GateRowKind kind = GateRowKind::Threshold;
  std::string metric;            // "status", "inversion_event", a metric name, or "run"
  std::optional<double> value;   // a threshold row's measurement (nullopt: absent)
  std::optional<double> limit;   // a threshold row's threshold
  std::string measured;          // as shown: "0.00812", "absent", "diverged", "engine_only"
  std::string required;          // as shown: "0.05", "ok", "both|neither"
  bool passed = false;
  std::string message;           // why it failed ("tilt_rms_error 0.0812 > 0.05"); "" when passed
};

struct CheckResult {
  std::string name, engine, scene;
  std::vector<std::string> set;
  std::vector<GateRow> rows;  // status, then events (when required), then thresholds
  bool passed = false;
  double seconds = 0;  // the engine run's wall time: JUnit's time attribute only, never gated
};

// The names of GateRowKind, in its order (a row's "kind" in the JSON result).
const std::vector<std::string>& gate_row_kind_names();

// ---- the result's field lists (records/fields.h): `tippe gate --json`'s "results" follow them --

// A row as the JSON result lists it (written only, never read back: the list takes it const).
template <class V>
void visit(const GateRow& r, V& v) {
  v(Field("kind").one_of(gate_row_kind_names()), gate_row_kind_names().at(static_cast<size_t>(r.kind)));
  v(Field("metric", "status, an event pairing, a metric name or run"), r.metric);
  v(Field("value", "a threshold row's measurement; null: absent"), r.value);
  v(Field("threshold", "a threshold row's bound on |value|"), r.limit);
  v(Field("measured", "as shown"), r.measured);
  v(Field("required", "as shown"), r.required);
  v(Field("passed"), r.passed);
  v(Field("message", "why it failed; empty when passed"), r.message);
}
template <class V>
void visit(const CheckResult& r, V& v) {
  v(Field("name"), r.name);
  v(Field("engine"), r.engine);
  v(Field("scene", "as written in the gate file"), r.scene);
  v(Field("set"), r.set);
  v(Field("passed"), r.passed);
  v(Field("seconds", "s: the engine run's wall time, never gated"), r.seconds);
  v(Field("rows", "status, then events (when required), then thresholds"), r.rows);
}

// Pure: the verdict of `check` on one engine's run against the reference and their metrics.
// A threshold passes when |value| <= max; an absent value (an event error when one side lacks
// the event, a Jellett drift on a surface never run on) or a NaN fails it, with the reason.
// When the reference is converged only to t = X < the check's duration
// (metrics.reference_converged_until), every row compared against the reference over samples
// (tilt, energy error, paths, latitude, compared_until) says "compared to t = X (reference
// converged)" and fails with "reference not converged after t = X", and an event pairing past X
// is "unconverged" and fails; with allow_unconverged the rows are judged on the window instead
// (an unconverged pairing passes), still marked. A gate that silently passed on a shorter window
// than its author asked for would be weaker than it reads: shorten the duration or allow it.
CheckResult evaluate_check(const Check& check, const RunRecord& reference, const RunRecord& engine,
                           const Metrics& metrics);
// One threshold row on `m`: passes when |value| <= max; absent or NaN fails with the reason.
GateRow threshold_row(const Threshold& t, const Metrics& m);
// A check whose comparison could not be run (the reference failed, an output error): it fails
// with one "run" row carrying `why`.
CheckResult error_result(const Check& check, const std::string& why);

bool all_passed(const std::vector<CheckResult>& results);
// One row per status/event/threshold line: check, engine, metric, measured, threshold,
// verdict; then a line counting the checks passed and one per failing line.
std::string render_table(const std::vector<CheckResult>& results);
// JUnit XML: <testsuites> holding one <testsuite name=suite_name>, one <testcase
// classname=suite_name name=CHECK> per check; a failing check carries one <failure> whose
// message lists every failing line ("metric value > threshold"; ...), an errored one an <error>.
// A testcase's time is the wall time of the engine run it judges (checks sharing a run each show
// it, so the suite's total can exceed the real one): for reading CI pages, never for gating.
std::string render_junit(const std::vector<CheckResult>& results, const std::string& suite_name);
// {"format": "tippe-gate-1", "passed", "checks", "failed", "results": [{name, engine, scene, set,
// passed, seconds, rows: [{kind, metric, value, threshold, measured, required, passed, message}]}]}
// (the command line and the Python module add "gate_file").
constexpr const char* kGateResultFormat = "tippe-gate-1";
nlohmann::json to_json(const std::vector<CheckResult>& results);
// The text of schemas/gate-result.schema.json: the result's frame (format, gate_file, passed,
// checks, failed) with "results" from CheckResult's and GateRow's field lists (SchemaBuilder).
std::string gate_result_schema_text();

}  // namespace tippe
