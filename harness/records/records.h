// Run records: their summary numbers, JSON and CSV writers, atomic files.
#pragma once

#include <cstddef>
#include <cstdio>
#include <istream>
#include <limits>
#include <map>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "harness/io/files.h"
#include "analytic/scene.h"
#include "engines/core/simulator.h"

namespace tippe {

// The values a record's enumerated fields may hold when read back (records are input): a run's
// status (to_string(RunStatus)) and its events' names (what the reference and the fixed-step
// loop emit, plus the statuses a failing run records as an event).
const std::vector<std::string>& run_status_names();
const std::vector<std::string>& event_names();


struct Provenance {
  std::string git_commit, compiler, cxx_flags;  // from build_info()
  std::string date;                             // UTC, ISO 8601, when the run started
  std::string hostname;
};
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

// The ledger's numbers at one sample, from the simulator's totals and the sample's energy
// (Observation's ledger fields; e0: the run's first energy).
void fill_ledger(Observation& o, const EnergyLedgerTotals& l, double e0);

// Receives every sample of a run as it is produced, so a run's memory does not grow with its length.
struct SampleSink {
  virtual ~SampleSink() = default;
  virtual void write(const Observation& o) = 0;
};

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

// An integer field of a record (counts of samples, steps, events): a JSON integer within the
// range of long long. Throws nlohmann::json::exception for a missing field or any other value;
// json::get<long long> would convert a float such as 1e300 with undefined behaviour.
long long json_integer(const nlohmann::json& j, const char* key);

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
  std::string path_, tmp_;
  std::FILE* f_ = nullptr;
  std::vector<char> buffer_;
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
