// The MuJoCo adapter's settings ([engines.mujoco]) as a plain struct, shared by its source files.
#pragma once

#include <string>
#include <vector>

#include "analytic/scene.h"
#include "engines/core/settings.h"

namespace tippe {

// Every setting of the MuJoCo model that decides accuracy, read from [engines.mujoco].
struct MujocoSettings {
  // Small against the spin period (2 pi / 5 ~ 1.3 dimensionless, 0.04 s for the toy) and
  // 20 steps per contact time constant (solref[0] = 0.002).
  double timestep = 1e-4;
  // "RK4": 4th order, so the explicit gyroscopic term w x I w of a fast spinning body causes
  // no visible energy drift; "Euler" (MuJoCo's default, semi-implicit, 1st order) grows the
  // nutation energy by O((w h)^2) per step; "implicit" (2.2: velocity-implicit with the RNE
  // derivatives) is 1st order and numerically damped. RK4 costs 4 forward passes a step.
  std::string integrator = "RK4";
  // "elliptic" is the Coulomb cone itself (|F_t| <= mu F_n, isotropic); "pyramidal" is
  // MuJoCo's default polyhedral approximation of it.
  std::string cone = "elliptic";
  // Friction-to-normal impedance ratio; MuJoCo's default: friction exactly as soft as the normal.
  double impratio = 1.0;
  // Newton: MuJoCo's default, converges quadratically; exact for a handful of constraint rows.
  std::string solver = "Newton";
  // A cap Newton does not reach at this tolerance for one body with at most 3 contacts.
  int iterations = 100;
  // Below MuJoCo's 1e-8 default so that solver error stays far below the compared quantities;
  // it costs an iteration or two.
  double tolerance = 1e-10;
  // MuJoCo's default: no post-pass; the soft contact's own friction is the law being tested.
  int noslip_iterations = 0;
  // friction = rolling: the noslip pass removes the creep that soft friction allows, so the
  // contact point really sticks.
  int noslip_iterations_rolling = 10;
  // Same order as the main tolerance (MuJoCo's default is 1e-6); used only when noslip runs.
  double noslip_tolerance = 1e-10;
  // [timeconst, dampratio]: MuJoCo's default 0.02 s leaves the toy top resting 2.6 % of R deep;
  // 0.002 gives 2.6e-4 R there (4.5e-7 R for the dimensionless top), is critically damped, and
  // keeps MuJoCo's stability rule timeconst >= 2 timestep for every timestep up to 1e-3.
  std::vector<double> solref = {0.002, 1.0};
  // [dmin, dmax, width, midpoint, power]: MuJoCo's default impedance profile.
  std::vector<double> solimp = {0.9, 0.95, 0.001, 0.5, 2.0};
  // 0: derived from the scene's friction law (1 none/viscous/gliding, 3 coulomb/rolling, 4 with
  // drilling); 1, 3, 4 or 6 force that contact dimensionality (diagnostic).
  int condim = 0;
  // Friction coefficient that stands in for the rolling constraint (friction = rolling).
  double rolling_mu = 1e3;
  // Where the free body's frame (and so its joint) has its origin: a modelling choice, not
  // physics, yet MuJoCo 2.2.2's answer depends on it (docs/findings/mujoco-body-frame.md).
  // MuJoCo applies its soft-constraint law to J qacc and never computes J-dot qvel
  // (mj_fwdConstraint: efc_b = J qacc_smooth - aref); for a free joint that omitted term depends
  // on the frame origin. "ball_centre" (the default): the origin at the ball's centre O, where the
  // term is exactly zero for a sphere on a plane, so MuJoCo's contact law acts on the true gap and
  // slip; it is also the frame of MuJoCo's tutorial top and of most hand-written models.
  // "com": the origin at the centre of mass G (the bench's first choice), where the omitted
  // term, d w3 |w_perp| in the friction rows (1.8 m/s^2 on the toy top), holds a false slip that
  // turns Coulomb tops over ten times early.
  std::string body_frame = "ball_centre";
  // The stem's collision shape: a capsule from O to P (what a user models as the stem; the
  // tutorial's is a cylinder), or the sphere of radius r at P alone (the reference's stem
  // contact). Their lowest points agree at every tilt (the capsule's other end lies inside the
  // ball); MuJoCo's capsule-plane routine may still add a second contact at that end within the
  // margin, and the two shapes' contact frames differ, hence a choice to sweep.
  std::string stem_shape = "capsule";
  // The geoms' contact margin (scene length): MuJoCo makes a contact, and its soft constraint
  // acts, from this distance on, before the surfaces touch. 0 (MuJoCo's default) is the rigid
  // contact the reference has; a user's model may carry one, hence a choice to sweep.
  double margin = 0.0;
  // The user's own MJCF (`tippe import-mjcf`): run as written, with its own options; the keys
  // above that are given in the scene override its opt fields (timestep, integrator, cone,
  // impratio, solver, iterations, tolerance, noslip_iterations, noslip_tolerance) and its
  // ball, stem and floor geoms' solref and solimp. The scene reader resolves the path.
  std::string model;
  std::string body;      // the top's body in `model` ("" : the one free body)
  std::string keyframe;  // the start in `model` ("" : the first keyframe, else qpos0)

  template <class V>
  void visit(V& v) {
    shared_settings::timestep(v, timestep);
    v("integrator", integrator, {"Euler", "RK4", "implicit"});
    v("cone", cone, {"elliptic", "pyramidal"});
    v("impratio", impratio, 1e-6, 1e6);
    v("solver", solver, {"Newton", "CG", "PGS"});
    shared_settings::iterations(v, "iterations", iterations);
    v("tolerance", tolerance, 0.0, 1.0);
    v("noslip_iterations", noslip_iterations, 0, 1000000);
    v("noslip_iterations_rolling", noslip_iterations_rolling, 0, 1000000);
    v("noslip_tolerance", noslip_tolerance, 0.0, 1.0);
    v("solref", solref, 2);
    v("solimp", solimp, 5);
    v("condim", condim, 0, 6);
    shared_settings::rolling_mu(v, rolling_mu);
    v("body_frame", body_frame, {"com", "ball_centre"});
    shared_settings::stem_shape(v, stem_shape);
    v("margin", margin, 0.0, 1.0);
    v("model", model);
    v("body", body);
    v("keyframe", keyframe);
  }
};

// Whether [engines.mujoco] gives `key` (a user's model keeps its own value of every key not given).
bool mujoco_setting_given(const Scene& scene, const char* key);

}  // namespace tippe
