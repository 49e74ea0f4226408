// The comparison record (comparison.json): the reference, every engine's run and metrics, the reference's self-check.
#pragma once

#include <optional>
#include <string>
#include <vector>
#include <nlohmann/json.hpp>
#include "harness/io/provenance.h"
#include "harness/records/records.h"
#include "analytic/scene.h"

namespace tippe {

// One row of the aligned event sequences (measure/event_alignment.h): "match", "substitution",
// "missing" (the reference's only) or "extra" (the engine's only); a side without an event there
// has an empty kind and no time.
struct AlignedEventRow {
  std::string op;
  std::string reference_kind, engine_kind;
  std::optional<double> reference_time, engine_time;
};
// The rows a record keeps of an alignment (the first ones; the counts are of all of them): the
// report shows them, and a sweep's records.jsonl carries them on every line.
inline constexpr size_t kMaxAlignedEventRowsKept = 20;

// Metrics of one engine against the reference. Event metrics: an event one side has and the
// other lacks is a finding: `*_event` says which ("both", "neither", "engine_only",
// "reference_only") and the errors are then absent (null in JSON).
struct Metrics {
  std::string inversion_event, stem_contact_event;
  std::optional<double> inversion_time_abs_error, inversion_time_rel_error;
  std::optional<double> stem_contact_time_abs_error, stem_contact_time_rel_error;
  double tilt_max_error = 0, tilt_rms_error = 0;              // rad, on the common grid
  double energy_max_error = 0;                                // max |E - E_ref| / E0
  double energy_final_ratio = 0;                              // E_final / E0 of the engine
  long long energy_gain_events = 0;                           // dissipative scenes: net rises above tolerance (metrics.h)
  double energy_max_gain = 0;                                 // largest net rise, / E0
  // How the two above counted energy (measure/metrics.h, EnergyGainRule): "ledger" or "total";
  // empty in records written before the rule was a setting (they counted the total).
  std::string energy_gain_rule;
  // The engine's energy ledger at the end of its run (RunRecord), / |E0| of the engine's run;
  // absent (null) where the engine cannot give the term and in records written before it.
  std::optional<double> normal_work, friction_work, drilling_work, impact_energy;
  std::optional<double> elastic_energy_max, numerical_energy_max, numerical_energy_final;
  double contact_path_rms_error = 0, contact_path_max_error = 0;  // floor contact path, / R
  double com_path_rms_error = 0, com_path_max_error = 0;          // path of G (x, y), / R
  double latitude_rms_error = 0;                              // contact latitude on the ball, rad
  std::optional<double> jellett_drift_ball, jellett_drift_stem;
  double jellett_max_relative_drift = 0;
  double wall_seconds = 0, cpu_seconds = 0, real_time_factor = 0;
  long long steps = 0;
  double cost_ratio = 0;        // engine CPU seconds / reference CPU seconds
  double compared_until = 0;    // common grid end (the shorter of the two runs, and the window below)
  // The end of the reference's converged window (SelfCheck::converged_until) when the metrics
  // against the reference stop there; absent: compared over the whole common grid.
  std::optional<double> reference_converged_until;
  // The event sequences aligned (measure/event_alignment.h: the canonical vocabulary, what is
  // left out and why). Absent (null in JSON) in records written before the alignment existed.
  std::optional<long long> events_reference;  // canonical events of the reference in the window
  std::optional<long long> events_engine;     // ... of the engine
  std::optional<long long> events_matched, events_missing, events_extra;  // matched + missing = events_reference
  std::optional<double> event_time_max_error;  // s, largest |t_engine - t_ref| of matched events (0: none matched)
  std::optional<long long> first_wrong_event_index;  // index in the aligned pairs; absent: none wrong
  std::string first_wrong_event;  // "reference: X at t=.., engine: Y at t=.."; "" when none is wrong
  std::string events_not_compared;  // events left out of the comparison, counted ("stick 1 (reference)")
  std::optional<double> event_min_dwell;  // s: surface phases shorter than this merged (a bench setting)
  std::vector<AlignedEventRow> event_alignment;  // the first kMaxAlignedEventRowsKept aligned pairs
  std::optional<long long> event_alignment_rows;  // how many pairs the whole alignment has
};

nlohmann::json to_json(const Metrics& m);
Metrics metrics_from_json(const nlohmann::json& j);

struct SelfCheck {
  std::string method;  // the second run's
  double rtol = 0, atol = 0;
  std::optional<double> converged_until;  // absent: the two agree over the whole run
  std::string reason;                     // where and how they part ("" when they do not)
  double cpu_seconds = 0;                 // the second run's
};
// {"method", "rtol", "atol", "converged_until" (number or null), "reason", "cpu_seconds"}
nlohmann::json to_json(const SelfCheck& s);
// Throws nlohmann::json::exception for a missing or mistyped field, std::invalid_argument for a
// converged_until that is neither null nor a finite number >= 0.
SelfCheck self_check_from_json(const nlohmann::json& j);

struct EngineResult {
  RunRecord run;
  Metrics metrics;
};

struct Comparison {
  RunRecord reference;
  std::vector<EngineResult> engines;
  nlohmann::json scene;   // scene_to_json
  Provenance provenance;
  bool reference_cached = false;  // the reference came from the cache, not from this run
  // The reference's self-check (absent when the scene's run.self_check is false). When it
  // parts, every engine's metrics stop at its converged_until.
  std::optional<SelfCheck> self_check;
  bool self_check_cached = false;
};


// comparison.json: {"format", "scene_name", "scene_file", "scene_hash", "physics_hash", "scene",
// "provenance" (with "engine_versions"), "reference": {"cached", "summary", "self_check" (when
// run: to_json(SelfCheck))}, "engines":
// [{"engine", "summary", "metrics"}, ...]}; summaries are to_json(RunRecord), except that only
// the first kMaxSwitchEventsKept "switch" events are listed and the rest counted in
// "events_omitted": {"switch": N}.
inline constexpr long long kMaxSwitchEventsKept = 100;
nlohmann::json to_json(const Comparison& c);
// Throws nlohmann::json::exception for a missing or mistyped field, std::invalid_argument
// ("KEY: reason") for a scene or engine name that breaks is_valid_name, an engine twice, or an
// engine named "reference": the names become file names in the record's directory. Records
// older than the self-check (no reference.self_check, no metrics.reference_converged_until) read
// as not checked; present, they are checked (a number >= 0 or null).
Comparison comparison_from_json(const nlohmann::json& j);

// Hash of the physics of a scene (everything but the engine settings and the name): the key of
// the reference cache.
std::string physics_hash(const Scene& scene);
// The same over a scene_to_json document (e.g. a record's scene_spec).
std::string physics_hash(const nlohmann::json& scene_json);

}  // namespace tippe
