// The one-call entry points of <tippe/tippe.h>: a scene in, the reference's run summary out.
#include "include/tippe/tippe.h"

#include <cmath>
#include <limits>
#include <sstream>

#include "harness/library/columns.h"
#include "harness/records/records.h"
#include "harness/measure/run.h"
#include "harness/io/scene_io.h"
#include "harness/scene/resolve.h"

namespace tippe {

namespace {

RunSummary to_summary(const RunRecord& r) {
  RunSummary s;
  const nlohmann::json j = to_json(r);
  s.format = j.at("format").get<std::string>();
  s.scene = r.scene_name;
  s.scene_file = r.scene_file;
  s.scene_hash = r.scene_hash;
  s.engine = r.engine;
  s.engine_version = r.engine_version;
  s.status = r.status;
  s.status_time = r.status_time;
  s.status_detail = r.status_detail;
  s.inversion_time = r.inversion_time;
  s.stem_contact_time = r.stem_contact_time;
  s.samples = r.samples;
  s.final_time = r.final_time;
  s.final_tilt = r.final_tilt;
  s.energy_initial = r.energy_initial;
  s.energy_final = r.energy_final;
  s.jellett_initial = r.jellett_initial;
  s.jellett_max_relative_drift = r.jellett_max_relative_drift;
  s.jellett_drift_ball = r.jellett_drift_ball;
  s.jellett_drift_stem = r.jellett_drift_stem;
  s.min_normal_force = r.min_normal_force;
  s.mass_properties = {r.mass.mass, r.mass.com_offset, r.mass.inertia_transverse, r.mass.inertia_axial};
  s.inversion_possible = r.inversion_possible;
  s.work = {r.work.steps, r.work.rhs_evaluations, r.work.solver_iterations, r.work.wall_seconds, r.work.cpu_seconds};
  for (const Event& e : r.events) s.events.push_back({e.name, e.time, e.detail, e.value});
  for (const auto& [k, v] : r.settings) s.settings[k] = v;
  s.notes = r.notes;
  s.json = j.dump(2) + "\n";
  return s;
}

RunSummary run_reference(const Scene& scene, TrajectoryColumns* trajectory) {
  ColumnTrajectorySink columns;
  const RunRecord r = run_scene(scene, "analytic", trajectory ? &columns : nullptr);
  if (trajectory) *trajectory = std::move(columns.columns);
  return to_summary(r);
}

}  // namespace

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
