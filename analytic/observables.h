// Observables shared by every simulator: tilt, geometric contact, energy and Jellett's integral.
#pragma once

#include "analytic/scene.h"
#include "analytic/state.h"

namespace tippe {

// Geometry and mass the observables need, derived once from a scene.
struct BodyModel {
  double R = 0, r = 0, l = 0;  // ball radius, tip radius, O->P distance
  double M = 0, d = 0, A = 0, C = 0;
  double g = 0;
  bool stem = true;
  double switch_cos = -1.0;  // e_z.e_Z below which the stem tip is the lower surface: -(R-r)/l

  static BodyModel from_scene(const Scene& scene);
  // Offsets from G along e_Z of the ball centre O and of the tip centre P.
  double z_O() const { return d; }
  double z_P() const { return d + l; }
};

// Lab-frame vector from G to the lowest point of the given surface (R_C of the source).
Vec3 contact_offset_W(const BodyModel& m, const Quat& q_WB, Surface s);
// The lower surface (ball unless the stem exists and cos(theta) < switch_cos).
Surface lower_surface(const BodyModel& m, const Quat& q_WB);
// Height above the floor of the lowest point of a surface (negative: penetration).
double surface_gap(const BodyModel& m, const BodyState& x, Surface s);
double energy(const BodyModel& m, const BodyState& x);
double jellett(const BodyModel& m, const BodyState& x, Surface s);
double tilt(const Quat& q_WB);
// Fills every kinematic observable of x; force fields are left for the caller. The contact
// quantities (point, slip, Jellett's J, surface) are those of the lower surface. Without
// `slip`, slip_speed is left at 0 (for a caller that takes it from its contact forces).
Observation observe_kinematics(const BodyModel& m, const BodyState& x, bool slip = true);
// The horizontal speed of the material point at surface s's contact point: observe_kinematics'
// slip_speed.
double contact_slip_speed(const BodyModel& m, const BodyState& x, Surface s);
// The same with ball and stem on the floor together (surface Both), as the reference reports its
// two-contact phase: the contact quantities are the ball's.
Observation observe_kinematics_on_both(const BodyModel& m, const BodyState& x);

}  // namespace tippe
