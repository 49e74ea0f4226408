// Test-only window into the Bullet adapter: what its btRigidBody, shapes and contacts hold, without exposing Bullet types.
#pragma once

#include <string>
#include <vector>

#include "engines/core/simulator.h"

namespace tippe {

// Read back from the engine objects, in the body frame B (origin G) unless named W.
struct BulletReadback {
  double mass = 0.0;                    // 1 / getInvMass()
  Vec3 inertia_B = Vec3::Zero();        // getLocalInertia()
  Vec3 inv_inertia_B = Vec3::Zero();    // getInvInertiaDiagLocal()
  Vec3 p_WG = Vec3::Zero();             // centre-of-mass transform origin
  Quat q_WB = Quat::Identity();         // centre-of-mass transform rotation
  Vec3 ball_centre_B = Vec3::Zero();    // compound child 0 origin
  double ball_radius = 0.0;
  bool has_stem = false;
  Vec3 stem_centre_B = Vec3::Zero();    // compound child 1 origin (mid-segment)
  Vec3 stem_axis_B = Vec3::Zero();      // child 1 rotation applied to the capsule's up axis
  double stem_radius = 0.0;
  double stem_half_length = 0.0;        // btCapsuleShape::getHalfHeight (half the O-P segment)
  double body_friction = 0.0, floor_friction = 0.0;
  double body_rolling_friction = 0.0, body_spinning_friction = 0.0;
  double body_restitution = 0.0, floor_restitution = 0.0;
  std::string gyroscopic;               // decoded from btRigidBody::getFlags()
  Vec3 total_force_W = Vec3::Zero();    // force accumulator now (Bullet clears it after a step)
  Vec3 total_torque_W = Vec3::Zero();
  // Combined coefficients in the body-floor manifold points now, as the solver used them.
  std::vector<double> point_friction, point_rolling_friction, point_spinning_friction, point_restitution;
};

// Throws std::invalid_argument when sim is not a Bullet simulator.
BulletReadback bullet_readback(const Simulator& sim);

}  // namespace tippe
