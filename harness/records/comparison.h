// The comparison record (comparison.json): the reference, every engine's run and metrics, the reference's self-check.
#pragma once

#include <algorithm>
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
  std::optional<double> friction_work_reference_sticks;  // while the reference's contact sticks
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

// The values an aligned row's op may hold.
const std::vector<std::string>& aligned_event_ops();

template <class R, class V>
std::enable_if_t<std::is_same_v<std::remove_const_t<R>, AlignedEventRow>> visit(R& r, V& v) {
  v(Field("op").one_of(aligned_event_ops()), r.op);
  v(Field("reference").since().empty_as_null(), r.reference_kind);
  v(Field("t_reference").since(), r.reference_time);
  v(Field("engine").since().empty_as_null(), r.engine_kind);
  v(Field("t_engine").since(), r.engine_time);
}

// The metrics' one field list: comparison.json's "metrics" objects, their schema, and the
// metric table a bound may name (metric_bounds.h: every number here but those `not_bounded`, in
// this order, which is the order of a gate's rows). Fields `since` a later format read as absent
// from records written before them.
template <class R, class V>
std::enable_if_t<std::is_same_v<std::remove_const_t<R>, Metrics>> visit(R& m, V& v) {
  v(Field("inversion_event", "both, neither, engine_only or reference_only: which runs have an inversion"),
    m.inversion_event);
  v(Field("inversion_time_abs_error", "s, engine - reference"), m.inversion_time_abs_error);
  v(Field("inversion_time_rel_error", "fraction of the reference's time"), m.inversion_time_rel_error);
  v(Field("stem_contact_event", "both, neither, engine_only or reference_only: which runs touch the stem"),
    m.stem_contact_event);
  v(Field("stem_contact_time_abs_error", "s, engine - reference"), m.stem_contact_time_abs_error);
  v(Field("stem_contact_time_rel_error", "fraction of the reference's time"), m.stem_contact_time_rel_error);
  v(Field("tilt_max_error", "rad"), m.tilt_max_error);
  v(Field("tilt_rms_error", "rad"), m.tilt_rms_error);
  v(Field("energy_max_error", "/ E0"), m.energy_max_error);
  v(Field("energy_final_ratio", "E_final / E0 of the engine"), m.energy_final_ratio);
  v(Field("energy_gain_events", "count"), m.energy_gain_events);
  v(Field("energy_max_gain", "/ E0"), m.energy_max_gain);
  // Sorted in the schema, which a new rule then extends in one place.
  static const std::vector<std::string> rules = [] {
    std::vector<std::string> r = energy_gain_rule_names();
    std::sort(r.begin(), r.end());
    return r;
  }();
  v(Field("energy_gain_rule",
          "how energy_gain_events and energy_max_gain counted energy (harness/measure/metrics.h): stored (E with the "
          "contact's stored elastic energy where the engine gives it), total (E) or ledger (energy created by the "
          "ledger's account); absent in records written before it")
        .since()
        .one_of(rules),
    m.energy_gain_rule);
  v(Field("numerical_energy_max",
          "energy ledger (docs/energy-ledger.md): largest |numerical energy| N = E - E0 - work + impacts, / |E0| of "
          "the engine's run; null: not available")
        .since(),
    m.numerical_energy_max);
  v(Field("numerical_energy_final",
          "energy ledger (docs/energy-ledger.md): numerical energy at the end, / |E0| of the engine's run; null: not "
          "available")
        .since(),
    m.numerical_energy_final);
  v(Field("friction_work",
          "energy ledger (docs/energy-ledger.md): work of the friction forces on the top, / |E0| of the engine's run; "
          "null: not available")
        .since(),
    m.friction_work);
  v(Field("friction_work_reference_sticks",
          "energy ledger (docs/energy-ledger.md): the engine's friction work while the reference's contact sticks "
          "(from the reference's stick event to its next slip or change of contact, in the compared window), / |E0| "
          "of the engine's run: the creep or slip of a contact that should roll (the reference's own is 0); null: the "
          "reference never sticks there, the ledger is not available, or a record written before it")
        .since(),
    m.friction_work_reference_sticks);
  v(Field("normal_work",
          "energy ledger (docs/energy-ledger.md): work of the normal forces on the top, / |E0| of the engine's run; "
          "null: not available")
        .since(),
    m.normal_work);
  v(Field("drilling_work",
          "energy ledger (docs/energy-ledger.md): work of the drilling and rolling torques, / |E0| of the engine's "
          "run; null: not available")
        .since(),
    m.drilling_work);
  v(Field("impact_energy",
          "energy ledger (docs/energy-ledger.md): energy removed at impacts, / |E0| of the engine's run; null: not "
          "available")
        .since(),
    m.impact_energy);
  v(Field("elastic_energy_max",
          "energy ledger (docs/energy-ledger.md): largest elastic energy stored in the contact, / |E0| of the "
          "engine's run; null: not available")
        .since(),
    m.elastic_energy_max);
  v(Field("contact_path_rms_error", "/ R"), m.contact_path_rms_error);
  v(Field("contact_path_max_error", "/ R"), m.contact_path_max_error);
  v(Field("com_path_rms_error", "/ R"), m.com_path_rms_error);
  v(Field("com_path_max_error", "/ R"), m.com_path_max_error);
  v(Field("latitude_rms_error", "rad"), m.latitude_rms_error);
  v(Field("jellett_drift_ball", "relative"), m.jellett_drift_ball);
  v(Field("jellett_drift_stem", "relative"), m.jellett_drift_stem);
  v(Field("jellett_max_relative_drift", "relative"), m.jellett_max_relative_drift);
  // Timing is never bounded: it depends on the machine and its load (cost_ratio, a ratio of CPU
  // times on the same machine, is).
  static constexpr const char* kTiming =
      "timing is never gated (it depends on the machine and its load); bound steps or cost_ratio";
  v(Field("wall_seconds", "s").not_bounded(kTiming), m.wall_seconds);
  v(Field("cpu_seconds", "s").not_bounded(kTiming), m.cpu_seconds);
  v(Field("real_time_factor", "simulated s per wall s").not_bounded(kTiming), m.real_time_factor);
  v(Field("steps", "engine steps"), m.steps);
  v(Field("cost_ratio", "engine CPU / reference CPU"), m.cost_ratio);
  v(Field("compared_until", "s"), m.compared_until);
  v(Field("reference_converged_until",
          "s: end of the reference's converged window when the metrics stop there; null: compared over the whole "
          "common grid")
        .since()
        .minimum(0)
        .not_bounded("the reference's, not the engine's: it marks a gate's rows instead"),
    m.reference_converged_until);
  v(Field("event_time_max_error", "largest |t_engine - t_reference| of matched events (0 when none is matched)")
        .since()
        .minimum(0),
    m.event_time_max_error);
  // The event alignment: the counts on each side and of matches describe the sequences (missing
  // and extra judge them), the first wrong event is a text (require_no_wrong_event gates it), the
  // dwell is a setting of the bench.
  static constexpr const char* kDescribes =
      "a count that describes the aligned event sequences; bound events_missing or events_extra, which judge them";
  static constexpr const char* kWrongEvent =
      "require the aligned event sequences to agree with require_no_wrong_event = true";
  v(Field("events_reference",
          "canonical events of the reference in the compared window (absent in records older than the event "
          "alignment)")
        .since()
        .minimum(0)
        .not_bounded(kDescribes),
    m.events_reference);
  v(Field("events_engine", "canonical events of the engine in the compared window")
        .since()
        .minimum(0)
        .not_bounded(kDescribes),
    m.events_engine);
  v(Field("events_matched", "aligned pairs of the same kind; events_matched + events_missing = events_reference")
        .since()
        .minimum(0)
        .not_bounded(kDescribes),
    m.events_matched);
  v(Field("events_missing", "reference events the engine lacks (a substitution counts one missing and one extra)")
        .since()
        .minimum(0),
    m.events_missing);
  v(Field("events_extra", "engine events the reference lacks").since().minimum(0), m.events_extra);
  v(Field("first_wrong_event_index",
          "index in the aligned sequence of the first pair that is not a match; null when none")
        .since()
        .minimum(0)
        .not_bounded(kWrongEvent),
    m.first_wrong_event_index);
  v(Field("first_wrong_event",
          "\"reference: KIND at t=T, engine: KIND at t=T\" (a side without an event there reads \"none\"); null when "
          "the sequences agree")
        .since()
        .empty_as_null()
        .not_bounded("not a number: require the aligned event sequences to agree with require_no_wrong_event = true"),
    m.first_wrong_event);
  v(Field("events_not_compared", "events left out of the comparison, counted by name and side").since(),
    m.events_not_compared);
  v(Field("event_min_dwell", "surface phases shorter than this were merged on both sides (a setting of the bench)")
        .since()
        .minimum(0)
        .not_bounded("a setting of the bench, not a measurement"),
    m.event_min_dwell);
  static const std::string alignment_doc =
      "the first " + std::to_string(kMaxAlignedEventRowsKept) + " aligned pairs (kMaxAlignedEventRowsKept)";
  v(Field("event_alignment", alignment_doc.c_str()).since(), m.event_alignment);
  v(Field("event_alignment_rows", "how many aligned pairs the whole alignment has")
        .since()
        .minimum(0)
        .not_bounded(kDescribes),
    m.event_alignment_rows);
}

nlohmann::json to_json(const Metrics& m);
Metrics metrics_from_json(const nlohmann::json& j);

struct SelfCheck {
  std::string method;  // the second run's
  double rtol = 0, atol = 0;
  std::optional<double> converged_until;  // absent: the two agree over the whole run
  std::string reason;                     // where and how they part ("" when they do not)
  double cpu_seconds = 0;                 // the second run's
};
template <class R, class V>
std::enable_if_t<std::is_same_v<std::remove_const_t<R>, SelfCheck>> visit(R& s, V& v) {
  v(Field("method", "the second run's integration method"), s.method);
  v(Field("rtol", "the second run's relative tolerance"), s.rtol);
  // Records written before the absolute tolerance was a setting of the check: 0.
  v(Field("atol", "the second run's absolute tolerance").since(), s.atol);
  v(Field("converged_until", "s: where the two runs part; null: they agree over the whole run").minimum(0),
    s.converged_until);
  v(Field("reason", "where and how the two runs part (empty when they do not)"), s.reason);
  v(Field("cpu_seconds", "s: the second run's"), s.cpu_seconds);
}
// The fields of its `visit`, as JSON.
nlohmann::json to_json(const SelfCheck& s);
// Throws nlohmann::json::exception for a missing or mistyped field, std::invalid_argument
// ("reference.self_check.KEY: reason") for a converged_until that is neither null nor a finite
// number >= 0.
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
