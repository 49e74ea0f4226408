// The MuJoCo adapter's notes and settings list for a run of the bench's own MJCF (a user's model has its own: mujoco_user_model.h).
#pragma once

#include <string>
#include <vector>

#include "engines/mujoco/mujoco_settings.h"
#include "analytic/observables.h"
#include "analytic/scene.h"

namespace tippe::mujoco_detail {

// The settings in force: [engines.mujoco] without the user-model keys, then the contact
// dimensionality, friction, noslip iterations and solref MuJoCo uses (`condim`: used_condim).
SettingsList scene_model_settings(const MujocoSettings& s, const Scene& scene, int condim);

// What MuJoCo does to the scene's law (cone, drilling, condim, solref, body frame, soft contact,
// integrator): the adapter's own notes, which follow the friction-law notes every engine shares.
std::vector<std::string> scene_model_notes(const Scene& scene, const BodyModel& body, const MujocoSettings& s,
                                           int condim);

}  // namespace tippe::mujoco_detail
