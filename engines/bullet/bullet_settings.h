// The Bullet adapter's settings ([engines.bullet]): every choice that decides accuracy, each default with its reason.
#pragma once

#include <string>

#include "engines/core/settings.h"

namespace tippe {

// Every setting of the Bullet model that decides accuracy, read from [engines.bullet].
struct BulletSettings {
  // Scene step. Bullet's step is first order (one PGS solve, semi-implicit Euler); 1e-4 keeps
  // |omega| h at 0.015 for a 150 rad/s top, far below the pi/4 rotation clamp, and the energy
  // drift small (frictionless tilted dimensionless top: |E - E0| = 4e-7 after 30 units, 4e-6 at 1e-3).
  double timestep = 1e-4;
  // Internal fixed steps per scene step (each a full collide-solve-integrate); 1 = none needed at 1e-4.
  int substeps = 1;
  // Scene mass units (kg in the SI scenes) per Bullet mass unit: Bullet is given M, A, C and the
  // bench's forces divided by it, and its impulses are multiplied back; lengths and times stay
  // the scene's. It matters because Bullet's implicit gyroscopic step (the default, both
  // implicit modes) solves its 3x3 Newton system with btMatrix3x3::solve33, which inverts the
  // determinant only when it exceeds SIMD_EPSILON (2.2e-16 in the double build) and otherwise
  // multiplies by it: when det ~ A^2 C, a mass^3 length^6, is below that, w x I w silently
  // vanishes (the SI toy top: 1.2e-18 kg^3 m^6; every SI top of the bench but mujoco_tutorial).
  // 1 = the scene's units, what a Bullet user passes, so the default is Bullet's answer in those
  // units; a run in which the term vanished says so in a note. 1e-3 (grams) moves det by 1e9.
  // Impulses grow by 1/mass_unit in Bullet: its spinning-friction cap (a normal impulse of 1 per
  // internal step) comes closer, and a run that reaches it ends as clamped.
  double mass_unit = 1.0;
  // PGS sweeps per internal step. One point contact converges in a few; the ball+stem phase
  // couples the rows: on the viscous source scene at t = 25, Bullet's default 10 differs from
  // 200 by 4e-4 in the spin, 50 agrees with 200 to 6 digits.
  int solver_iterations = 50;
  // m_erp: in 3.24 used by joints only (there are none here; contacts use erp2). Bullet's default.
  double erp = 0.2;
  // m_erp2: fraction of a contact's penetration removed per internal step, by the split-impulse
  // push or (split off) by Baumgarte velocity. Bullet's default.
  double erp2 = 0.2;
  // m_globalCfm: 0 = hard contact (Bullet's default); > 0 softens the contact.
  double cfm = 0.0;
  // true: penetration is removed by a separate push that leaves no momentum behind. With
  // Baumgarte (false) the correction velocity stays in the body, i.e. penetration turns into
  // kinetic energy (measured: 1 % R depth gives v_z = 2 at h = 1e-3) — wrong for an energy
  // budget over 30 time units.
  bool split_impulse = true;
  // Penetration depth (scene length, <= 0) beyond which the split push is used; shallower
  // contacts get Baumgarte. Bullet's default -0.04 (metres) would leave every contact of this
  // bench on Baumgarte; 0 sends all penetration to the push and needs no length scale.
  double split_impulse_threshold = 0.0;
  // Fraction of the split push's angular part applied (Bullet's default).
  double split_impulse_turn_erp = 0.1;
  // Start each solve from the last step's impulses times the factor (Bullet's defaults).
  bool warmstarting = true;
  double warmstarting_factor = 0.85;
  // PGS over-relaxation (Bullet's default 1: plain Gauss-Seidel).
  double sor = 1.0;
  // The w x I w term. implicit_body: one Newton step of the implicit Euler equations in the
  // body frame, the accurate and stable one for a fast top (Bullet's default); explicit is
  // forward Euler on w x I w, which gains energy at large |omega| h; none is not the top's
  // physics (diagnostic only: the viscous source top then inverts at 12.4 instead of 17.25).
  std::string gyroscopic = "implicit_body";
  // Friction rows per contact point: 2 (SOLVER_USE_2_FRICTION_DIRECTIONS, each bounded by
  // mu P_n: a box) or 1 (along the slip velocity only).
  int friction_directions = 2;
  // First friction direction along the slip velocity (Bullet's default) or a fixed tangent basis
  // (SOLVER_DISABLE_VELOCITY_DEPENDENT_FRICTION_DIRECTION).
  bool velocity_friction_direction = true;
  // Friction coefficient that stands in for the rolling constraint (friction = rolling).
  double rolling_mu = 1e3;
  // The stem's collision shape: a capsule from O to P (what a user models as the stem), or the
  // sphere of radius r at P alone (the reference's stem contact). Their lowest points agree at
  // every tilt (the capsule's other end lies inside the ball); Bullet's support-point routines
  // differ, hence a choice to sweep.
  std::string stem_shape = "capsule";
  // Bullet's contact breaking threshold relative to the body's size: a manifold point is kept
  // (and matched to the next step's point, carrying its warm-start impulse) while it stays within
  // this fraction of the compound's angular motion disc (~ its bounding radius). Bullet's default
  // is gContactBreakingThreshold = 0.02 with CD_USE_RELATIVE_CONTACT_BREAKING_THRESHOLD, i.e.
  // 0.02 x the disc: the value here. A length-scale choice of the engine, not physics.
  double contact_breaking_threshold = 0.02;

  template <class V>
  void visit(V& v) {
    shared_settings::timestep(v, timestep);
    v("substeps", substeps, 1, 100000);
    v("mass_unit", mass_unit, 1e-12, 1e12);
    shared_settings::iterations(v, "solver_iterations", solver_iterations);
    shared_settings::fraction(v, "erp", erp);
    shared_settings::fraction(v, "erp2", erp2);
    shared_settings::fraction(v, "cfm", cfm);
    v("split_impulse", split_impulse);
    v("split_impulse_threshold", split_impulse_threshold, -1e6, 0.0);
    v("split_impulse_turn_erp", split_impulse_turn_erp, 0.0, 1.0);
    v("warmstarting", warmstarting);
    v("warmstarting_factor", warmstarting_factor, 0.0, 1.0);
    v("sor", sor, 0.0, 2.0);
    v("gyroscopic", gyroscopic, {"none", "explicit", "implicit_world", "implicit_body"});
    v("friction_directions", friction_directions, 1, 2);
    v("velocity_friction_direction", velocity_friction_direction);
    shared_settings::rolling_mu(v, rolling_mu);
    shared_settings::stem_shape(v, stem_shape);
    v("contact_breaking_threshold", contact_breaking_threshold, 0.0, 1.0);
  }
};

}  // namespace tippe
