// Side-by-side runs of the reference and engines on one scene, and the metrics that compare them.
#pragma once

#include <filesystem>

#include <functional>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "records.h"
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
  double compared_until = 0;    // common grid end (the shorter of the two runs)
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
Metrics compare_runs(const RunRecord& reference, const Trajectory& ref_traj, const RunRecord& engine,
                     const Trajectory& engine_traj, const Scene& scene);
nlohmann::json to_json(const Metrics& m);
Metrics metrics_from_json(const nlohmann::json& j);

struct CompareOptions {
  std::vector<std::string> engines = {"bullet", "ode", "mujoco"};
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
};

// Runs (or loads from the cache) the reference at the scene's tolerances, then every engine,
// in parallel when jobs > 1; writes the outputs when out_dir is set. An engine that fails to
// build (bad setting) throws std::invalid_argument before anything runs; an engine that
// diverges is a result.
// Invalid input (unknown or repeated engine, jobs < 1, a bad [engines.NAME] setting) throws
// before any file is written. A cache entry is used only when its summary has the same physics
// hash, git commit and reference version as this build; otherwise it is re-run and replaced.
Comparison run_comparison(const Scene& scene, const CompareOptions& options);
// The checks run_comparison makes before it writes anything (engines known and listed once, jobs,
// engine settings): throws std::invalid_argument as it does.
void check_compare_input(const Scene& scene, const CompareOptions& options);
// comparison.json: {"format", "scene_name", "scene_file", "scene_hash", "physics_hash", "scene",
// "provenance" (with "engine_versions"), "reference": {"cached", "summary"}, "engines":
// [{"engine", "summary", "metrics"}, ...]}; summaries are to_json(RunRecord), except that only
// the first kMaxSwitchEventsKept "switch" events are listed and the rest counted in
// "events_omitted": {"switch": N}.
inline constexpr long long kMaxSwitchEventsKept = 100;
nlohmann::json to_json(const Comparison& c);
// Throws nlohmann::json::exception for a missing or mistyped field, std::invalid_argument
// ("KEY: reason") for a scene or engine name that breaks is_valid_name, an engine twice, or an
// engine named "reference": the names become file names in the record's directory.
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
