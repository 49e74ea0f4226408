// Test-only window into the MuJoCo adapter: what its compiled mjModel and mjData hold, without exposing MuJoCo types.
#pragma once

#include <vector>

#include "engines/core/simulator.h"

namespace tippe {

// The top body's mass properties as the compiled mjModel stores them: body_mass, body_ipos
// (centre of mass in the body frame, whose origin is G or the ball centre O: engines.mujoco.body_frame), body_inertia (principal moments) and
// body_iquat (principal axes in the body frame).
struct MujocoModelReadback {
  double mass = 0.0;
  Vec3 ipos_B = Vec3::Zero();
  Vec3 inertia = Vec3::Zero();
  Quat iquat_B = Quat::Identity();
  double timestep = 0.0;
  // Where the body frame's origin is in the principal frame at G: 0 (body_frame "com") or d e_Z
  // (the ball's centre, "ball_centre"); ipos_B + frame_origin_G is the centre of mass about G.
  Vec3 frame_origin_G = Vec3::Zero();
  int nq = 0, nv = 0;
};

// Throw std::invalid_argument when sim is not a MuJoCo simulator.
MujocoModelReadback mujoco_model_readback(const Simulator& sim);
// mjData.qpos and qvel as they are now (free joint: position, quaternion w x y z; linear
// velocity in W, angular velocity in B).
std::vector<double> mujoco_qpos(const Simulator& sim);
std::vector<double> mujoco_qvel(const Simulator& sim);
// mjData.xpos and xquat of the top's body as they are now (7 numbers).
std::vector<double> mujoco_body_pose(const Simulator& sim);

}  // namespace tippe
