// The library's one-call interface: run the reference on a scene and get its summary.json as a struct.
#pragma once

// Self-contained on purpose (the standard library only): it is the installed interface of
// tippe::core, so that consumers need none of the harness's headers and the harness's files can
// move without changing what is installed.

#include <map>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

namespace tippe {

// One located event of a run (summary.json "events"): "inversion", "stem_contact", "switch", ...
struct SummaryEvent {
  std::string name;
  double time = 0.0;  // s
  std::string detail;
  double value = 0.0;  // event-specific number (e.g. energy removed by an impact, J)
};

// summary.json "mass_properties": kg, m, kg m^2, kg m^2.
struct SummaryMass {
  double mass = 0.0, com_offset = 0.0, inertia_transverse = 0.0, inertia_axial = 0.0;
};

// summary.json "work".
struct SummaryWork {
  long long steps = 0, rhs_evaluations = 0, solver_iterations = 0;
  double wall_seconds = 0.0, cpu_seconds = 0.0;
};

// The fields of summary.json under the same names (schemas/run-summary.schema.json gives their
// meaning and units). A number JSON writes as null is NaN here, an absent time is std::nullopt.
struct RunSummary {
  std::string format;  // "tippe-run-1"
  std::string scene, scene_file, scene_hash;
  std::string engine, engine_version;
  std::string status;  // ok, contact_lost, diverged, unphysical, clamped, failed
  double status_time = 0.0;
  std::string status_detail;
  std::optional<double> inversion_time, stem_contact_time;  // s
  long long samples = 0;
  double final_time = 0.0;  // s
  double final_tilt = 0.0;  // rad
  double energy_initial = 0.0, energy_final = 0.0;  // J
  double jellett_initial = 0.0;  // kg m^3/s (J = L_G . R_C)
  double jellett_max_relative_drift = 0.0;
  std::optional<double> jellett_drift_ball, jellett_drift_stem;
  double min_normal_force = 0.0;  // N
  SummaryMass mass_properties;
  bool inversion_possible = false;
  SummaryWork work;
  std::vector<SummaryEvent> events;
  std::map<std::string, std::string> settings;
  std::vector<std::string> notes;
  std::string json;  // the whole summary.json text (scene_spec and provenance included)
};

// The trajectory, column by column (the columns of trajectory.csv, schemas/trajectory.md).
struct TrajectoryColumns {
  std::vector<std::string> columns;                   // file order, "surface" included
  std::map<std::string, std::vector<double>> values;  // every column but "surface"
  std::vector<std::string> surface;                   // none, ball, stem or both per row
};

// Invalid input: the message reads "FILE: KEY: reason", as the command line's.
class InputError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// Runs the analytic reference on a scene file, as `tippe run SCENE` does, and returns its
// summary (without writing any file). `overrides` are "KEY=VALUE" strings as for --set; when
// `trajectory` is given it receives every sample. Throws InputError for a bad scene.
RunSummary run_scene_file(const std::string& path, const std::vector<std::string>& overrides = {},
                          TrajectoryColumns* trajectory = nullptr);

// The same for a scene given as TOML text; `label` stands for the file in messages and is the
// default scene name (its stem).
RunSummary run_scene_text(const std::string& toml, const std::string& label = "scene",
                          const std::vector<std::string>& overrides = {}, TrajectoryColumns* trajectory = nullptr);

// The project's version ("0.1.0").
std::string version();

}  // namespace tippe
