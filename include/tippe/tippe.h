// The library's one-call interface: run the reference on a scene and get its summary.json as a struct.
#pragma once

// Self-contained on purpose (the standard library only): it is the installed interface of
// tippe::core, so that consumers need none of the harness's headers and the harness's files can
// move without changing what is installed.

#include <map>
#include <optional>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <vector>

namespace tippe {

// Each struct below lists its fields once in a `visit`, as (summary.json key, member), in
// summary.json's order: the library fills a RunSummary from the run's record by these keys, a
// test checks that every field of the record (harness/records/records.h) is here under the same
// key and type, and a consumer may walk them with any callable taking (const char* key, member&):
//   tippe::visit(summary, [](const char* key, const auto& value) { ... });

// One located event of a run (summary.json "events"): "inversion", "stem_contact", "switch", ...
struct SummaryEvent {
  std::string name;
  double time = 0.0;  // s
  std::string detail;
  double value = 0.0;  // event-specific number (e.g. energy removed by an impact, J)
};
template <class S, class V>
std::enable_if_t<std::is_same_v<std::remove_const_t<S>, SummaryEvent>> visit(S& e, V&& v) {
  v("name", e.name);
  v("time", e.time);
  v("detail", e.detail);
  v("value", e.value);
}

// summary.json "mass_properties": kg, m, kg m^2, kg m^2.
struct SummaryMass {
  double mass = 0.0, com_offset = 0.0, inertia_transverse = 0.0, inertia_axial = 0.0;
};
template <class S, class V>
std::enable_if_t<std::is_same_v<std::remove_const_t<S>, SummaryMass>> visit(S& m, V&& v) {
  v("mass", m.mass);
  v("com_offset", m.com_offset);
  v("inertia_transverse", m.inertia_transverse);
  v("inertia_axial", m.inertia_axial);
}

// summary.json "work".
struct SummaryWork {
  long long steps = 0, rhs_evaluations = 0, solver_iterations = 0;
  double wall_seconds = 0.0, cpu_seconds = 0.0;
};
template <class S, class V>
std::enable_if_t<std::is_same_v<std::remove_const_t<S>, SummaryWork>> visit(S& w, V&& v) {
  v("steps", w.steps);
  v("rhs_evaluations", w.rhs_evaluations);
  v("solver_iterations", w.solver_iterations);
  v("wall_seconds", w.wall_seconds);
  v("cpu_seconds", w.cpu_seconds);
}

// summary.json "ledger_at_inversion": the energy ledger at the first sample at or after the
// run's first inversion (J; time in s).
struct SummaryLedgerPoint {
  double time = 0.0, energy = 0.0;
  double normal_work = 0.0, friction_work = 0.0, drilling_work = 0.0, impact_energy = 0.0, numerical_energy = 0.0;
};
template <class S, class V>
std::enable_if_t<std::is_same_v<std::remove_const_t<S>, SummaryLedgerPoint>> visit(S& l, V&& v) {
  v("time", l.time);
  v("energy", l.energy);
  v("normal_work", l.normal_work);
  v("friction_work", l.friction_work);
  v("drilling_work", l.drilling_work);
  v("impact_energy", l.impact_energy);
  v("numerical_energy", l.numerical_energy);
}

// summary.json "provenance": the build and when and where the run was made.
struct SummaryProvenance {
  std::string git_commit, compiler, cxx_flags;
  std::string date;  // UTC, ISO 8601, when the run started
  std::string hostname;
};
template <class S, class V>
std::enable_if_t<std::is_same_v<std::remove_const_t<S>, SummaryProvenance>> visit(S& p, V&& v) {
  v("git_commit", p.git_commit);
  v("compiler", p.compiler);
  v("cxx_flags", p.cxx_flags);
  v("date", p.date);
  v("hostname", p.hostname);
}

// The fields of summary.json under the same names (schemas/run-summary.schema.json gives their
// meaning and units), all but "scene_spec" (the scene as run, a JSON object: it is in `json`).
// A number JSON writes as null is NaN here, an absent time or part is std::nullopt.
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
  // The energy ledger (docs/energy-ledger.md), J, NaN for a term the simulator cannot give.
  double friction_work = 0.0, normal_work = 0.0, drilling_work = 0.0, impact_energy = 0.0;
  double elastic_energy_max = 0.0;
  double numerical_energy_max = 0.0, numerical_energy_final = 0.0;
  std::vector<std::string> ledger_not_available;  // the ledger's terms the simulator could not give
  std::optional<SummaryLedgerPoint> ledger_at_inversion;  // none: no inversion or no ledger
  SummaryMass mass_properties;
  bool inversion_possible = false;
  SummaryWork work;
  std::vector<SummaryEvent> events;
  std::map<std::string, std::string> settings;
  std::vector<std::string> notes;
  SummaryProvenance provenance;
  std::string json;  // the whole summary.json text (scene_spec included)
};
template <class S, class V>
std::enable_if_t<std::is_same_v<std::remove_const_t<S>, RunSummary>> visit(S& s, V&& v) {
  v("format", s.format);
  v("scene", s.scene);
  v("scene_file", s.scene_file);
  v("scene_hash", s.scene_hash);
  v("engine", s.engine);
  v("engine_version", s.engine_version);
  v("status", s.status);
  v("status_time", s.status_time);
  v("status_detail", s.status_detail);
  v("inversion_time", s.inversion_time);
  v("stem_contact_time", s.stem_contact_time);
  v("samples", s.samples);
  v("final_time", s.final_time);
  v("final_tilt", s.final_tilt);
  v("energy_initial", s.energy_initial);
  v("energy_final", s.energy_final);
  v("jellett_initial", s.jellett_initial);
  v("jellett_max_relative_drift", s.jellett_max_relative_drift);
  v("jellett_drift_ball", s.jellett_drift_ball);
  v("jellett_drift_stem", s.jellett_drift_stem);
  v("min_normal_force", s.min_normal_force);
  v("friction_work", s.friction_work);
  v("normal_work", s.normal_work);
  v("drilling_work", s.drilling_work);
  v("impact_energy", s.impact_energy);
  v("elastic_energy_max", s.elastic_energy_max);
  v("numerical_energy_max", s.numerical_energy_max);
  v("numerical_energy_final", s.numerical_energy_final);
  v("ledger_not_available", s.ledger_not_available);
  v("ledger_at_inversion", s.ledger_at_inversion);
  v("mass_properties", s.mass_properties);
  v("inversion_possible", s.inversion_possible);
  v("work", s.work);
  v("events", s.events);
  v("settings", s.settings);
  v("notes", s.notes);
  v("provenance", s.provenance);
}

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
