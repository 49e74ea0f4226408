// A run's sampled trajectory in memory, as the metrics read it: from a run or from a trajectory.csv.
#pragma once

#include <string>
#include <vector>
#include "harness/records/records.h"

namespace tippe {

// One engine's trajectory as the metrics need it (from a run in memory or a trajectory.csv).
struct Trajectory {
  std::vector<double> t, theta, energy, jellett, normal_force, slip_speed, contact_latitude;
  std::vector<double> x_C, y_C, x_G, y_G;
  // The energy ledger (Observation's fields); all NaN for a trajectory written before them.
  std::vector<double> normal_work, friction_work, drilling_work, impact_energy, elastic_energy, numerical_energy;
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

}  // namespace tippe
