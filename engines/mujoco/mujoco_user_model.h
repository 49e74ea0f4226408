// The MuJoCo adapter's user-model mode (engines.mujoco.model): checks, overrides, notes and settings of a user's own MJCF.
#pragma once

#include <mujoco/mujoco.h>

#include <string>
#include <vector>

#include "engines/mujoco/mujoco_settings.h"
#include "engines/mujoco/mujoco_top.h"
#include "engines/core/simulator.h"

namespace tippe {

// The user's model, compiled, with the top found and checked against the scene: a scene whose
// body, contact or gravity differ from the model's would compare the reference with another
// top. Throws std::invalid_argument "engines.mujoco.model: ...". With `keep` the compiled model
// is handed over (the caller deletes it).
MjcfTopImport check_user_model(const Scene& scene, const MujocoSettings& s, mjModel** keep, MjTopIds* ids,
                               std::string* warning);

// The keys given in [engines.mujoco], applied on the compiled model; returns their names.
std::vector<std::string> apply_user_overrides(mjModel* m, const Scene& scene, const MujocoSettings& s,
                                              const MjTopIds& ids);

// Whether the scene's start is the keyframe's (the import's), so that the run may start from the
// keyframe's own numbers.
bool same_start(const BodyState& scene, const BodyState& model, double R);

// The run's notes and settings list for a user's model as compiled (options after overrides).
std::vector<std::string> user_model_notes(const mjModel* m, const MjcfTopImport& top, const std::string& model,
                                          bool keyframe_start, const std::vector<std::string>& overridden,
                                          const std::string& compiler_warning);
SettingsList user_model_settings(const mjModel* m, const MjcfTopImport& top, const std::string& model,
                                 bool keyframe_start);

}  // namespace tippe
