// The command line's verbs as functions (compare, import-mjcf, gate, the registry, advice as JSON): the `tippe` command and the Python module call these, so both do one thing.
#pragma once

// Input errors are tippe::InputError (<tippe/tippe.h>) carrying the command line's message
// ("FILE: KEY: reason"); the command line prints them as "tippe: error: MESSAGE" and exits 2,
// the Python module raises them as ValueError.

#include <filesystem>
#include <functional>
#include <map>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>
#include "include/tippe/tippe.h"

#include "harness/gating/gate.h"
#include "harness/gating/gate_boundary.h"
#include "harness/library/columns.h"
#include "harness/measure/compare.h"
#include "engines/mujoco/mujoco_import.h"
#include "harness/records/trajectory.h"
#include "engines/core/simulator.h"

namespace tippe {

// `tippe compare` without its printing: checks the input (InputError), then runs the comparison
// and, when `out` is set, writes comparison.json, the trajectories and the report there as one
// unit (staged beside it, swapped in whole: an interrupted run leaves an earlier one as it was).
struct CompareRequest {
  std::vector<std::string> engines = engine_names();
  std::string out;    // "" : nothing written
  int jobs = 0;       // 0: one per core, at most one per run
  std::string cache;  // reference cache directory ("" : none)
  bool plots = true;
  bool progress = true;  // the command line's progress board on stderr
  // Each run's time as it goes (from the worker threads), and each run's sampled columns.
  std::function<void(const std::string& run, double t, double duration)> on_progress;
  std::map<std::string, Trajectory>* trajectories = nullptr;
};
Comparison compare_scene(const Scene& scene, const CompareRequest& request);
// What `tippe compare` prints of a comparison.json: the scene's notes, the summary table, the findings.
std::string comparison_summary_text(const nlohmann::json& comparison);

// `tippe import-mjcf`'s checks and the scene it writes, as text (read back and checked as a
// scene file): nothing is written. `out` is where the scene will live (its name, and the
// model's path relative to it); "" : a scene named after the model with the model's absolute path.
struct MjcfSceneRequest {
  std::string model, body, keyframe, out;
  double duration = 5.0;
  double sample_interval = 0.0;  // 0: the larger of 1 ms and the model's timestep
};
struct MjcfScene {
  MjcfTopImport top;
  std::string text;
};
MjcfScene import_mjcf_scene(const MjcfSceneRequest& request);

// `tippe gate`'s runs: the gate file and its boundary checks loaded (every input checked, SceneError),
// then every check's comparison and every boundary sweep run, one result per check in file order.
struct GatePlan {
  GateFile file;
  std::vector<BoundaryCheck> boundaries;
  std::vector<std::filesystem::path> inputs;  // the gate file, scenes, models, sweep files
};
GatePlan load_gate_plan(const std::string& gates);
struct GateRequest {
  int jobs = 0;  // 0: one per core, at most one per run of a comparison
  std::string cache = "out/.reference-cache";  // "" : none
  std::string boundary_out = "out/.boundary-runs";
  bool self_check = true;
};
std::vector<CheckResult> run_gate(const GatePlan& plan, const GateRequest& request);

// The registry as JSON: per simulator its name, role, version, colour, settings (key, type,
// default, allowed and, for numbers, bounds), advice axes and cost knob (`tippe info`'s facts).
nlohmann::json engines_to_json();

}  // namespace tippe
