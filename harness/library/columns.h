// Every column of a run's trajectory.csv kept as numbers in memory: the library's and the Python module's trajectories, without text.
#pragma once

#include "include/tippe/tippe.h"

#include "harness/records/records.h"

namespace tippe {

// The values of trajectory_row_values per column (file order, as trajectory.csv's header),
// "surface" as its name per row: the same numbers the CSV's 17 digits read back to, never
// formatted.
class ColumnTrajectorySink : public SampleSink {
 public:
  ColumnTrajectorySink();
  void write(const Observation& o) override;
  TrajectoryColumns columns;

 private:
  std::vector<std::vector<double>*> slots_;  // per column, its vector in `columns.values` (null: surface)
};

}  // namespace tippe
