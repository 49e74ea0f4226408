// The bench's MJCF of a scene (engines.mujoco settings checked, contact dimensionality, friction and
// solref as MuJoCo will use them) and its compilation: shared by the adapter and mujoco_mjcf().
#pragma once

#include <mujoco/mujoco.h>

#include <string>
#include <vector>

#include "engines/mujoco/mujoco_settings.h"
#include "analytic/observables.h"
#include "analytic/scene.h"
#include "analytic/state.h"

namespace tippe::mujoco_detail {

// engines.mujoco.* read and checked, alone and together; throws std::invalid_argument naming the key.
MujocoSettings read_checked_settings(const Scene& scene);
// The contact dimensionality the scene's law needs, and the one used (the setting, else that).
int derived_condim(const Scene& scene);
int used_condim(const MujocoSettings& s, const Scene& scene);
// The solref MuJoCo uses (its refsafe rule raises a timeconst below 2 timestep).
std::vector<double> used_solref(const MujocoSettings& s);
// The body frame's origin in the principal frame at G (along e_Z).
double frame_origin_z(const MujocoSettings& s, const BodyModel& m);
// Geom friction [tangential, torsional, rolling].
Vec3 used_friction(const MujocoSettings& s, const Scene& scene);
int used_noslip_iterations(const MujocoSettings& s, const Scene& scene);
// The whole model, initial state included (keyframe "initial").
std::string build_mjcf(const Scene& scene, const MujocoSettings& s);
// Compiles MJCF text through a one-file VFS; throws std::runtime_error with MuJoCo's message.
mjModel* compile_mjcf(const std::string& xml, std::string& warning);

}  // namespace tippe::mujoco_detail
