// Side-by-side runs of the reference and engines on one scene, and the metrics that compare them.
#pragma once

#include <filesystem>

#include <functional>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "registry.h"
#include "records/records.h"
#include "scene.h"

namespace tippe {

// One engine's trajectory as the metrics need it (from a run in memory or a trajectory.csv).
struct Trajectory {
  std::vector<double> t, theta, energy, jellett, normal_force, slip_speed, contact_latitude;
  std::vector<double> x_C, y_C, x_G, y_G;
  std::vector<int> surface;  // Surface codes
  static Trajectory from_csv(const CsvTrajectory& csv);
  void append(const Observation& o);
  size_t size() const { return t.size(); }
};

// Keeps the sampled columns of a run in memory while passing every sample on to `next` (e.g.
// a CsvTrajectoryWriter), so one run yields both the metrics' input and the file.
class TrajectorySink : public SampleSink {
 public:
  explicit TrajectorySink(std::vector<SampleSink*> next = {}) : next_(std::move(next)) {}
  void write(const Observation& o) override;
  Trajectory trajectory;

 private:
  std::vector<SampleSink*> next_;
};

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
  long long energy_gain_events = 0;                           // dissipative scenes: rises above tolerance
  double energy_max_gain = 0;                                 // largest rise, / E0
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
};

// Tolerance for energy gain events: a rise of E between samples above this fraction of E0 in
// a dissipative scene is energy the integrator injected.
inline constexpr double kEnergyGainTolerance = 1e-6;

// Whether the scene's contact law removes energy (viscous k > 0, Coulomb mu > 0, or drilling
// friction), so that any rise of E between samples is an integrator artefact.
bool energy_must_not_rise(const Scene& scene);

// Pure function of two trajectories and their records (tested on synthetic data). The common
// grid: samples matched by index up to the shorter run when every pair of times agrees within
// half a sample interval, else the engine interpolated linearly onto the reference's times.
// Pairs where either value is not finite are left out of the error sums. With no common sample
// the error metrics are NaN (null in JSON).
// `converged_until`: the reference is trusted only to this time (its self-check): the errors
// against it are summed over samples at t <= converged_until, and an event pairing is judged
// only when the reference's event (or, when the reference has none, the engine's) comes at or
// before it; otherwise the pairing is "unconverged" and its errors are absent. Metrics of the
// engine alone (energy ratio and gains, Jellett drift, work) cover the whole run.
Metrics compare_runs(const RunRecord& reference, const Trajectory& ref_traj, const RunRecord& engine,
                     const Trajectory& engine_traj, const Scene& scene,
                     std::optional<double> converged_until = std::nullopt);
nlohmann::json to_json(const Metrics& m);
Metrics metrics_from_json(const nlohmann::json& j);

// ---- the reference's self-check -----------------------------------------------------------------
//
// A second reference run over the same scene with an independent method, and the time up to
// which the two agree: the reference is "converged until" then. After it the metrics against the
// reference are not computed (Metrics::reference_converged_until) and gates say so.

// The second run's method and tolerances. bulirsch_stoer <-> dopri5: an extrapolation method and
// an embedded Runge-Kutta pair share no error estimate, so agreement is not one method agreeing
// with itself. rosenbrock4 -> rosenbrock4 at rtol/10 and atol/10: the scenes that need it are
// stiff (k_high: slip relaxes in 1e-7 s), where both explicit methods need ~1e6 steps a second
// and would cost minutes or fail; a tenfold tighter run of the same method is a convergence test
// (it catches a tolerance too loose for the motion), the independent test a stiff scene allows.
struct SelfCheckMethod {
  std::string method;
  double rtol = 0, atol = 0;
};
SelfCheckMethod self_check_method(const RunSpec& run);

// Two event times agree within max(1e3 rtol, 1e-9), at most 1e-5, times the duration. Measured
// (bulirsch_stoer against dopri5, source_dimensionless, after the stem touchdown up to the
// `unresolved` event): 2.5e-7 at rtol 1e-10 (the bound: 2.5e-6), 1.2e-10 at rtol 1e-12 (2.5e-8),
// 1e-4 at rtol 1e-8 (2.3e-4). The cap: event times are compared to 1e-5 of the duration at best
// (the tightest shipped gate bounds an event time to 8e-6 of it), so a looser reference parts.
double self_check_event_tolerance(const Scene& scene);
// Two sampled states agree while |theta_1 - theta_2| <= this (rad) and |E_1 - E_2| <= this * |E0|.
// 1e-6 is 1/60 of the tightest state bound in the shipped gates (tilt_rms_error and
// energy_max_error 6e-5), so a difference under it moves no shipped verdict by more than ~2 %,
// and ten times the largest difference measured inside the converged windows of the shipped
// scenes at rtol 1e-10 (1e-7, source_dimensionless between the stem touchdown and t = 21.37).
inline constexpr double kSelfCheckStateTolerance = 1e-6;

struct SelfCheck {
  std::string method;  // the second run's
  double rtol = 0, atol = 0;
  std::optional<double> converged_until;  // absent: the two agree over the whole run
  std::string reason;                     // where and how they part ("" when they do not)
  double cpu_seconds = 0;                 // the second run's
};

// Pure: where the second run `check` parts from `reference` (same scene, same sample grid):
// the earliest of the first event that differs (name, detail, or time beyond
// self_check_event_tolerance; one run having events the other lacks), an `unresolved` event in
// either run (the reference's own word that the motion stops fixing later events), the first
// sample whose tilt or energy differ beyond kSelfCheckStateTolerance (converged until the sample
// before), and a status that differs. method/rtol/atol/cpu_seconds are filled from `check`.
SelfCheck compare_reference_runs(const RunRecord& reference, const Trajectory& ref_traj, const RunRecord& check,
                                 const Trajectory& check_traj, const Scene& scene);
// Runs the second reference (self_check_method) on `scene` and compares it with the reference.
SelfCheck run_self_check(const Scene& scene, const RunRecord& reference, const Trajectory& ref_traj);
// {"method", "rtol", "atol", "converged_until" (number or null), "reason", "cpu_seconds"}
nlohmann::json to_json(const SelfCheck& s);
// Throws nlohmann::json::exception for a missing or mistyped field, std::invalid_argument for a
// converged_until that is neither null nor a finite number >= 0.
SelfCheck self_check_from_json(const nlohmann::json& j);

struct CompareOptions {
  std::vector<std::string> engines = engine_names();  // every registered engine (engines/registry.h)
  int jobs = 1;
  std::string out_dir;    // where comparison.json, trajectories and reports go ("" = none)
  std::string cache_dir;  // reference cache ("" = no cache)
  bool progress = true;   // progress line on stderr
  bool plots = true;      // render gnuplot SVGs when gnuplot is found
};

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

// Runs (or loads from the cache) the reference at the scene's tolerances, then every engine,
// in parallel when jobs > 1, and (scene.run.self_check) the reference's self-check beside them;
// writes the outputs when out_dir is set. An engine that fails to
// build (bad setting) throws std::invalid_argument before anything runs; an engine that
// diverges is a result.
// Invalid input (unknown or repeated engine, jobs < 1, a bad [engines.NAME] setting) throws
// before any file is written. A cache entry is used only when its summary has the same physics
// hash, git commit and reference version as this build; otherwise it is re-run and replaced.
// The self-check is cached beside it (self_check.json, keyed by the cached reference's
// provenance and the second method and tolerances); a cached reference without a matching one
// gets its self-check run now, never taken for a checked one.
Comparison run_comparison(const Scene& scene, const CompareOptions& options);
// The checks run_comparison makes before it writes anything (engines known and listed once, jobs,
// engine settings): throws std::invalid_argument as it does.
void check_compare_input(const Scene& scene, const CompareOptions& options);
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

// A reference cache entry, DIR/{summary.json, trajectory.csv} (shared by compare, gate and
// sweep): loaded when both files are complete and were made from the physics `hash` by this
// build of the reference (same commit, same version string); false for anything else.
bool load_cached_reference(const std::filesystem::path& dir, const Scene& scene, const std::string& hash,
                           RunRecord& record, Trajectory& trajectory);
// The same rule over the two files' texts (a reference sent from another process); `where`
// names their origin in the reason. Empty: accepted; otherwise why not.
std::string reference_from_text(const std::string& summary_json, const std::string& trajectory_csv,
                                const Scene& scene, const std::string& hash, const std::string& where,
                                RunRecord& record, Trajectory& trajectory);

}  // namespace tippe
