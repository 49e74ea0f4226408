// The DART adapter's settings ([engines.dart]): every choice that decides accuracy, each default with its reason.
#pragma once

#include <string>

#include "engines/core/settings.h"

namespace tippe {

// Every setting of the DART model that decides accuracy, read from [engines.dart].
struct DartSettings {
  // DART's step is semi-implicit Euler (velocities from the LCP, positions by the FreeJoint's
  // exponential map), first order like ODE and Bullet: the same 1e-4 default.
  double timestep = 1e-4;
  // Boxed LCP of the contact rows: "dantzig" (DART's default: a pivoting, exact solve; for one
  // body with two contacts the matrix is at most 6x6) or "pgs" (projected Gauss-Seidel,
  // iterative, for comparison).
  std::string lcp_solver = "dantzig";
  // DART's default falls back to PGS when Dantzig fails; off, a failed solve leaves the
  // contact impulses of that step at zero. On as in DART.
  bool pgs_fallback = true;
  // PGS sweeps (DART's default 30), used by "pgs" and by the fallback.
  int pgs_iterations = 50;
  // The floor is a box (top face z = 0) and the ball and the stem tip spheres, for every
  // detector: measured against the exact geometry (a sphere of radius 1 pressed 1e-4..5e-4 into
  // the floor at 50 positions and attitudes, DART 6.12.1 with FCL 0.7):
  //   "dart"     DART's own detector (sphere-box):   1 contact, point and depth exact (5.5e-17)
  //   "fcl"      FCL primitives (setPrimitiveShapeType(PRIMITIVE)): the same, exact
  //   "fcl_mesh" DART's FCL default, primitives as meshes: 0 to 6 contacts per query (a resting
  //              sphere is sometimes missed), contact point off by up to 0.022 R, depth by 2.3x
  //   "bullet"   DART's Bullet backend (Debian's single-precision Bullet 3.24; engines as
  //              modules only): 1 contact, point off the lowest point by up to 1.6e-3 R
  //              horizontally at the default floor_width (tests/engines/test_dart.cpp)
  // "dart" is the default: exact, and DART's own code path. "fcl_mesh" only shows what the
  // default of DART's FCL detector does to a ball. A plane is not used: DART 6.12's FCL detector
  // turns a PlaneShape into a thin box mesh, and its own detector has no plane (the Bullet
  // backend has one, btStaticPlaneShape: its runs were not examined, so every detector keeps the
  // same box). Neither DART nor FCL has a capsule (FCL replaces a CapsuleShape by a sphere of
  // radius 0.1 with an error message), so the stem is the sphere of radius r at its tip P: on a
  // plane that is the same contact as the capsule O-P the other engines use (the capsule's O end
  // lies inside the ball, r < R, so only its P end can reach the floor).
  std::string collision_detector = "dart";
  // The floor box's width in ball radii (it is 1 R thick). Only the Bullet backend's answer
  // depends on it: its convex-convex test (GJK on the box's corners, in single precision) works
  // at the box's size, so the contact lands off the ball's lowest point by about 1e-7 of the
  // width (measured: 1.6e-3 R at 1e4 R, 9e-6 R at 100 R; the double-precision detectors 1e-13 R
  // at 1e4 R). The top must stay on it: 1e4 R by default, far beyond any scene's travel.
  double floor_width = 1e4;
  // Contacts kept per collision query (CollisionOption::maxNumContacts, DART's default 1000):
  // a sphere on a plane gives 1 contact, ball and stem 2.
  int max_contacts = 4;
  // ContactConstraint's error reduction (DART's defaults: 0.01 of the depth per step, at most
  // 1e-3 length/time of push-out speed), allowed penetration (0) and the constraint force
  // mixing, relative to the diagonal of the contact matrix (1e-5). Process-wide in DART:
  // written before every step (see kDartGlobalsMutex).
  double erp = 0.01;
  double max_erv = 1e-3;
  double error_allowance = 0.0;
  double cfm = 1e-5;
  // Friction coefficient that stands in for the rolling constraint (friction = rolling).
  double rolling_mu = 1e3;

  template <class V>
  void visit(V& v) {
    shared_settings::timestep(v, timestep);
    v("lcp_solver", lcp_solver, {"dantzig", "pgs"});
    v("pgs_fallback", pgs_fallback);
    shared_settings::iterations(v, "pgs_iterations", pgs_iterations);
    v("collision_detector", collision_detector, {"dart", "fcl", "fcl_mesh", "bullet"});
    v("floor_width", floor_width, 10.0, 1e8);
    v("max_contacts", max_contacts, 1, 1000);
    shared_settings::fraction(v, "erp", erp);
    v("max_erv", max_erv, 0.0, 1e300);
    v("error_allowance", error_allowance, 0.0, 1e300);
    shared_settings::fraction(v, "cfm", cfm);
    shared_settings::rolling_mu(v, rolling_mu);
  }
};

}  // namespace tippe
