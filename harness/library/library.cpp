// The one-call entry points of <tippe/tippe.h>: a scene in, the reference's run summary out.
#include "include/tippe/tippe.h"

#include <cmath>
#include <limits>
#include <sstream>

#include "harness/library/columns.h"
#include "harness/library/summary.h"
#include "harness/records/records.h"
#include "harness/measure/run.h"
#include "harness/io/scene_io.h"
#include "harness/scene/resolve.h"

namespace tippe {

namespace {

RunSummary run_reference(const Scene& scene, TrajectoryColumns* trajectory) {
  ColumnTrajectorySink columns;
  const RunRecord r = run_scene(scene, "analytic", trajectory ? &columns : nullptr);
  if (trajectory) *trajectory = std::move(columns.columns);
  return to_summary(r);
}

}  // namespace

RunSummary to_summary(const RunRecord& r) {
  const nlohmann::json j = to_json(r);
  RunSummary s = JsonReader::read<RunSummary>(j, "");
  s.json = j.dump(2) + "\n";
  return s;
}

ColumnTrajectorySink::ColumnTrajectorySink() {
  columns.columns = trajectory_columns();
  for (const std::string& c : columns.columns) slots_.push_back(c == "surface" ? nullptr : &columns.values[c]);
}

void ColumnTrajectorySink::write(const Observation& o) {
  double v[kTrajectoryColumns];
  trajectory_row_values(o, v);
  for (size_t i = 0; i < kTrajectoryColumns; ++i) {
    if (slots_[i]) slots_[i]->push_back(v[i]);
    else columns.surface.emplace_back(to_string(o.surface));
  }
}

RunSummary run_scene_file(const std::string& path, const std::vector<std::string>& overrides,
                          TrajectoryColumns* trajectory) {
  Scene scene;
  try {
    scene = load_scene(path, overrides);
  } catch (const SceneError& e) {
    throw InputError(e.what());
  }
  return run_reference(scene, trajectory);
}

RunSummary run_scene_text(const std::string& toml, const std::string& label, const std::vector<std::string>& overrides,
                          TrajectoryColumns* trajectory) {
  Scene scene;
  try {
    scene = parse_scene_text(toml, label, overrides);
  } catch (const SceneError& e) {
    throw InputError(e.what());
  }
  return run_reference(scene, trajectory);
}

std::string version() { return TIPPE_VERSION; }

}  // namespace tippe
