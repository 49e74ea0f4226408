// MuJoCo-side pieces shared by the importer and the adapter: loading a user's MJCF and finding the top in it.
#pragma once

#include <mujoco/mujoco.h>

#include <mutex>
#include <string>

#include "engines/mujoco/mujoco_import.h"

namespace tippe {

// mj_loadXML keeps process-wide "last model" state in 2.2: one load at a time, every caller.
std::mutex& mujoco_load_mutex();

// mj_loadXML of a file; throws MjcfImportError "PATH: MuJoCo's message". A compiler warning of a
// successful load goes to `warning`.
mjModel* load_mjcf_file(const std::string& path, std::string& warning);

// The ids the adapter needs to run the top of a user's model.
struct MjTopIds {
  int body = -1, joint = -1, qadr = 0, vadr = 0, ball = -1, stem = -1, floor = -1, key = -1;
};

// import_mjcf_top on a model already compiled; `label` names the file in messages.
MjcfTopImport analyse_mjcf_top(const mjModel* m, const std::string& label, const std::string& body,
                               const std::string& keyframe, MjTopIds* ids = nullptr);

}  // namespace tippe
