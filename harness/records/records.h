// Run records: their summary numbers, JSON and CSV writers, atomic files.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdio>
#include <istream>
#include <limits>
#include <map>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "harness/io/files.h"
#include "harness/records/fields.h"
#include "analytic/scene.h"
#include "engines/core/simulator.h"

namespace tippe {

// The values a record's enumerated fields may hold when read back (records are input): a run's
// status (to_string(RunStatus)) and its events' names (what the reference and the fixed-step
// loop emit, plus the statuses a failing run records as an event).
const std::vector<std::string>& run_status_names();
const std::vector<std::string>& event_names();


// The doc of every record's git_commit field (the run's provenance and the sweep point's).
inline constexpr char kGitCommitDoc[] = "the commit the build was made from; \"-dirty\" appended when its tracked files had changes";

struct Provenance {
  std::string git_commit, compiler, cxx_flags;  // from build_info()
  std::string date;                             // UTC, ISO 8601, when the run started
  std::string hostname;
};
template <class R, class V>
std::enable_if_t<std::is_same_v<std::remove_const_t<R>, Provenance>> visit(R& p, V& v) {
  v(Field("git_commit", kGitCommitDoc), p.git_commit);
  v(Field("compiler"), p.compiler);
  v(Field("cxx_flags"), p.cxx_flags);
  v(Field("date", "UTC, ISO 8601, when the run started"), p.date);
  v(Field("hostname"), p.hostname);
}
// Build info plus the current date and host.
Provenance current_provenance();
// The "provenance" object of every record (run, comparison, sweep); the reader throws
// nlohmann::json::exception for a missing or mistyped field.
nlohmann::json to_json(const Provenance& p);
Provenance provenance_from_json(const nlohmann::json& j);

// Everything a run leaves behind except its trajectory.
struct RunRecord {
  std::string scene_name, scene_file, scene_hash;
  nlohmann::json scene_spec;  // scene_to_json of the scene as run (overrides applied)
  std::string engine, engine_version;
  std::string status = "ok";  // to_string(RunStatus)
  double status_time = 0.0;
  std::string status_detail;
  std::vector<Event> events;
  SettingsList settings;
  std::vector<std::string> notes;
  WorkCounters work;
  MassProperties mass;
  bool inversion_possible = false;
  Provenance provenance;

  // From the samples and events. Values that have no sample to come from are NaN (JSON null).
  std::optional<double> inversion_time;     // first "inversion" event
  std::optional<double> stem_contact_time;  // first "stem_contact" event
  long long samples = 0;
  double final_time = 0.0;  // time of the last sample
  double final_tilt = 0.0;
  double energy_initial = 0.0, energy_final = 0.0;
  double jellett_initial = 0.0;
  // Largest |J - J_first| / max(|J_first|, tiny) within a run of samples on one surface (Ball or
  // Stem; samples on None or Both end a run and are not counted). J is only conserved while the
  // contact stays on one surface, so drift across a switch says nothing; a "switch" event between
  // two samples (chattering faster than the sample interval) also ends a run.
  double jellett_max_relative_drift = 0.0;
  std::optional<double> jellett_drift_ball, jellett_drift_stem;  // absent: no run on that surface
  double min_normal_force = 0.0;
  // The work of the friction forces the simulator reported (Simulator::friction_work), scene
  // units of energy; NaN (JSON null) where it reports none, and in records written before it.
  double friction_work = std::numeric_limits<double>::quiet_NaN();
  // The energy ledger's totals (Simulator::energy_ledger, docs/energy-ledger.md), scene units of
  // energy, NaN (JSON null) for a term the simulator cannot give and in records written before:
  // work of the normal force and of the drilling torque on the top, energy removed at impacts,
  // the largest elastic energy stored in the contact, and the numerical energy N(t) = E(t) - E0 -
  // (normal + friction + drilling work) + impacts: its largest |N| over the samples and its value
  // at the last sample.
  double normal_work = std::numeric_limits<double>::quiet_NaN();
  double drilling_work = std::numeric_limits<double>::quiet_NaN();
  double impact_energy = std::numeric_limits<double>::quiet_NaN();
  double elastic_energy_max = std::numeric_limits<double>::quiet_NaN();
  double numerical_energy_max = std::numeric_limits<double>::quiet_NaN();
  double numerical_energy_final = std::numeric_limits<double>::quiet_NaN();
  // The ledger's terms the simulator could not give (e.g. "elastic_energy"), named in the record.
  std::vector<std::string> ledger_not_available;
  // The ledger at the first sample at or after the first "inversion" event (what the run had
  // spent by the time it turned over, for the report's attribution of a flip); absent when the
  // run does not invert or has no ledger.
  struct LedgerPoint {
    double time = 0.0, energy = 0.0;
    double normal_work = 0.0, friction_work = 0.0, drilling_work = 0.0, impact_energy = 0.0, numerical_energy = 0.0;
  };
  std::optional<LedgerPoint> ledger_at_inversion;
};

// The ledger's terms a simulator may not give (RunRecord::ledger_not_available).
const std::vector<std::string>& ledger_term_names();

// ---- the field lists (records/fields.h): summary.json and its schema follow them ----------------

// A simulator's event (engines/core/simulator.h) as a record lists it.
template <class R, class V>
std::enable_if_t<std::is_same_v<std::remove_const_t<R>, Event>> visit(R& e, V& v) {
  v(Field("name").one_of(event_names()), e.name);
  v(Field("time", "s"), e.time);
  v(Field("detail"), e.detail);
  v(Field("value", "event-specific (e.g. J removed by an impact)"), e.value);
}
template <class R, class V>
std::enable_if_t<std::is_same_v<std::remove_const_t<R>, MassProperties>> visit(R& m, V& v) {
  v(Field("mass", "kg"), m.mass);
  v(Field("com_offset", "m, centre of mass below the ball centre"), m.com_offset);
  v(Field("inertia_transverse", "kg m^2, A about G"), m.inertia_transverse);
  v(Field("inertia_axial", "kg m^2, C about G"), m.inertia_axial);
}
template <class R, class V>
std::enable_if_t<std::is_same_v<std::remove_const_t<R>, WorkCounters>> visit(R& w, V& v) {
  v(Field("steps"), w.steps);
  v(Field("rhs_evaluations"), w.rhs_evaluations);
  v(Field("solver_iterations"), w.solver_iterations);
  v(Field("wall_seconds", "s"), w.wall_seconds);
  v(Field("cpu_seconds", "s"), w.cpu_seconds);
}
template <class R, class V>
std::enable_if_t<std::is_same_v<std::remove_const_t<R>, RunRecord::LedgerPoint>> visit(R& l, V& v) {
  v(Field("time", "s"), l.time);
  v(Field("energy", "J: E at that sample"), l.energy);
  v(Field("normal_work", "J"), l.normal_work);
  v(Field("friction_work", "J"), l.friction_work);
  v(Field("drilling_work", "J"), l.drilling_work);
  v(Field("impact_energy", "J"), l.impact_energy);
  v(Field("numerical_energy", "J"), l.numerical_energy);
}

// summary.json's fields but "format" (to_json writes it, from_json checks it), in the order
// from_json reads them (a record with several faults names the first).
template <class R, class V>
std::enable_if_t<std::is_same_v<std::remove_const_t<R>, RunRecord>> visit(R& r, V& v) {
  v(Field("scene", "scene name"), r.scene_name);
  v(Field("scene_file", "the scene file as given"), r.scene_file);
  v(Field("scene_hash", "FNV-1a 64 of the file's bytes and the overrides, 16 hex digits"), r.scene_hash);
  v(Field("scene_spec", "every field of the scene as run (overrides applied)").since(), r.scene_spec);
  v(Field("engine"), r.engine);
  v(Field("engine_version"), r.engine_version);
  v(Field("status", "how the run ended").one_of(run_status_names()), r.status);
  v(Field("status_time", "s: when the status left ok (0 for ok)"), r.status_time);
  v(Field("status_detail"), r.status_detail);
  v(Field("inversion_time", "s: first 'inversion' event (tilt crosses 90 deg); null: none"), r.inversion_time);
  v(Field("stem_contact_time", "s: first 'stem_contact' event; null: none"), r.stem_contact_time);
  v(Field("samples", "rows of trajectory.csv").minimum(0), r.samples);
  v(Field("final_time", "s: time of the last sample"), r.final_time);
  v(Field("final_tilt", "rad: tilt of the symmetry axis from the vertical at the last sample"), r.final_tilt);
  v(Field("energy_initial", "J"), r.energy_initial);
  v(Field("energy_final", "J"), r.energy_final);
  v(Field("jellett_initial", "kg m^3/s: Jellett's integral J = L_G . R_C at the first sample"), r.jellett_initial);
  v(Field("jellett_max_relative_drift",
          "largest relative drift of Jellett's integral within a run of samples on one surface"),
    r.jellett_max_relative_drift);
  v(Field("jellett_drift_ball", "the same on the ball only; null: no run on the ball"), r.jellett_drift_ball);
  v(Field("jellett_drift_stem", "the same on the stem only; null: no run on the stem"), r.jellett_drift_stem);
  v(Field("min_normal_force", "N"), r.min_normal_force);
  v(Field("friction_work",
          "J: the work of the friction forces on the top over the run (sum over steps and contacts of F_t . v_C dt; "
          "the reference's own integral of its tangential force's power); null: not reported (records written before it)")
        .since(),
    r.friction_work);
  v(Field("normal_work",
          "J: energy ledger, the work of the normal forces on the top (sum over steps and contacts of F_n v_C.z dt); "
          "null: not available")
        .since(),
    r.normal_work);
  v(Field("drilling_work",
          "J: energy ledger, the work of the drilling and rolling torques on the top; null: not available (engines "
          "report no contact torques)")
        .since(),
    r.drilling_work);
  v(Field("impact_energy",
          "J: energy ledger, the energy removed at impacts (the reference's impact, hold and projection events); null: "
          "not available (an engine's impacts are inside its normal work)")
        .since(),
    r.impact_energy);
  v(Field("elastic_energy_max",
          "J: energy ledger, the largest elastic energy stored in a soft contact (the engine's contact law's potential "
          "of the penetration); null: not available")
        .since(),
    r.elastic_energy_max);
  v(Field("numerical_energy_max",
          "J: energy ledger, the largest |N(t)| of the numerical energy N = E - E0 - (normal + friction + drilling "
          "work) + impact_energy over the samples (null terms as 0); null: no ledger")
        .since(),
    r.numerical_energy_max);
  v(Field("numerical_energy_final", "J: energy ledger, N at the last sample; null: no ledger").since(),
    r.numerical_energy_final);
  v(Field("ledger_not_available",
          "the ledger's terms the simulator could not give (absent in records written before it)")
        .since()
        .one_of(ledger_term_names()),
    r.ledger_not_available);
  v(Field("ledger_at_inversion",
          "the energy ledger at the first sample at or after the run's first inversion event (J; time in s); null: no "
          "inversion or no ledger; absent in records written before it")
        .since(),
    r.ledger_at_inversion);
  v(Field("mass_properties"), r.mass);
  v(Field("inversion_possible", "1 - alpha < A/C < 1 + alpha"), r.inversion_possible);
  v(Field("work"), r.work);
  v(Field("events"), r.events);
  v(Field("settings", "every setting that decides accuracy, as used"), r.settings);
  v(Field("notes"), r.notes);
  v(Field("provenance", "Where and with what build the record was made"), r.provenance);
}

// The ledger's numbers at one sample, from the simulator's totals and the sample's energy
// (Observation's ledger fields; e0: the run's first energy).
void fill_ledger(Observation& o, const EnergyLedgerTotals& l, double e0);

// Receives every sample of a run as it is produced, so a run's memory does not grow with its length.
struct SampleSink {
  virtual ~SampleSink() = default;
  virtual void write(const Observation& o) = 0;
};

// A number without a value (a metric with nothing to measure, a ledger term an engine does not
// report).
inline constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// Jellett's J's drift relative to its value j0 where the contact surface last changed; the floor
// keeps J = 0 exactly (no spin) from dividing by zero. The summary and the classifier both use it,
// so a drift the classifier names is the number the reports show.
inline double jellett_relative_drift(double j, double j0) {
  constexpr double kTinyJ = 1e-300;
  return std::abs(j - j0) / std::max(std::abs(j0), kTinyJ);
}

// Folds samples into the summary numbers of a RunRecord (used by run_simulator; public so that
// the numbers can be recomputed or tested on any sequence).
class SampleSummary {
 public:
  // contact_switched: the simulator reported a "switch" event since the previous sample.
  void add(const Observation& o, bool contact_switched = false);
  void fill(RunRecord& r) const;

 private:
  long long n_ = 0;
  Observation first_, last_;
  double min_fn_ = 0.0;
  Surface run_surface_ = Surface::None;  // None: not inside a run
  double run_j0_ = 0.0;
  std::optional<double> drift_ball_, drift_stem_;
  double elastic_max_ = std::numeric_limits<double>::quiet_NaN();
  double numerical_max_ = std::numeric_limits<double>::quiet_NaN();
};

// The "format" of summary.json (schemas/run-summary.schema.json).
constexpr const char* kRunRecordFormat = "tippe-run-1";

// summary.json. Non-finite numbers are written as null. Settings become an object (key order
// is not kept: from_json returns them sorted by key).
nlohmann::json to_json(const RunRecord& r);
// Throws nlohmann::json::exception for a missing or mistyped field or another format; a
// summary without "format" (written before it existed) is read as tippe-run-1.
RunRecord from_json(const nlohmann::json& j);


// The trajectory columns, in file order.
const std::vector<std::string>& trajectory_columns();
inline constexpr size_t kTrajectoryColumns = 33;
// One sample's values in trajectory_columns() order into `values` (kTrajectoryColumns of them):
// the one list of what a row holds, for the CSV text and for columns kept as numbers (the
// Python module's arrays). "surface" holds its Surface code; an engine contact point the engine
// did not report is NaN.
void trajectory_row_values(const Observation& o, double* values);

// Writes trajectory.csv: numbers with 17 significant digits (nan for an engine contact point
// the engine did not report), surface as text. Rows go to `path.tmp.PID`; commit() renames it
// to `path`. Destroyed without commit (an error, an exception) it removes the temporary.
class CsvTrajectoryWriter : public SampleSink {
 public:
  explicit CsvTrajectoryWriter(std::string path);
  ~CsvTrajectoryWriter() override;
  CsvTrajectoryWriter(const CsvTrajectoryWriter&) = delete;
  CsvTrajectoryWriter& operator=(const CsvTrajectoryWriter&) = delete;

  void write(const Observation& o) override;
  void commit();
  const std::string& temp_path() const { return tmp_; }

 private:
  void fail(const std::string& what);
  void flush_rows();  // buffer_'s rows to the file
  std::string path_, tmp_;
  std::FILE* f_ = nullptr;
  std::unique_ptr<char[]> buffer_;  // the header and rows not yet handed to f_ (not zeroed)
  size_t capacity_ = 0, used_ = 0;
};

// The CSV text of a trajectory, kept in memory (a reference sent between processes).
class CsvTrajectoryText : public SampleSink {
 public:
  CsvTrajectoryText();
  void write(const Observation& o) override;
  std::string text;  // header and every row so far
};

// One row of trajectory.csv ('\n' included) into `line`, which holds kTrajectoryRowMax chars;
// its length. Every number has 17 significant digits, so it reads back to the same double.
size_t format_trajectory_row(const Observation& o, char* line);
std::string trajectory_csv_header();  // '\n' included

// A trajectory.csv read back: numeric columns by name, surface as Surface codes (0..3).
struct CsvTrajectory {
  std::vector<std::string> columns;  // header order
  std::map<std::string, std::vector<double>> values;  // every column but surface
  std::vector<int> surface;
  size_t rows() const { return surface.size(); }
  // Throws std::out_of_range naming the column when it does not exist.
  const std::vector<double>& column(const std::string& name) const;
};
// Throws std::runtime_error "FILE:LINE: reason" for a file that is not a trajectory.
CsvTrajectory read_trajectory_csv(const std::string& path);
// The same from a stream; `name` stands for the file in messages.
CsvTrajectory parse_trajectory_csv(std::istream& in, const std::string& name);

}  // namespace tippe
