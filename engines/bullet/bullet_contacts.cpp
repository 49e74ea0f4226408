// Bullet adapter, contacts: the body-floor manifold points gathered into the bench's contact report, and the test-only readback of the engine objects.
#include "engines/bullet/bullet_adapter.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace tippe {

using namespace bullet_detail;

bool BulletSimulator::is_stem_point(const btManifoldPoint& cp, bool body_is_0) const {
  if (!body().stem) return false;
  // The compound collision algorithm tags each point with the child index on the compound's
  // side: 0 ball, 1 stem.
  const int child = body_is_0 ? cp.m_index0 : cp.m_index1;
  if (child == 0) return false;
  if (child == 1) return true;
  // Fallback by geometry: the surface the body-side point lies closer to.
  const btVector3 p_W = body_is_0 ? cp.getPositionWorldOnA() : cp.getPositionWorldOnB();
  const Vec3 p_B = to_eigen(o_.body->getCenterOfMassTransform().invXform(p_W));
  const BodyModel& m = body();
  const double ball_gap = std::abs((p_B - Vec3(0, 0, m.z_O())).norm() - m.R);
  const double z = std::clamp(p_B.z(), m.z_O(), m.z_P());
  const double stem_gap = std::abs((p_B - Vec3(0, 0, z)).norm() - m.r);
  return stem_gap < ball_gap;
}

void BulletSimulator::collect_contacts(ContactSum& sum) const {
  const btCollisionObject* b = o_.body.get();
  const double touch_gap = kTouchGapOverR * body().R;
  btDispatcher* d = o_.dispatcher.get();
  for (int i = 0; i < d->getNumManifolds(); ++i) {
    const btPersistentManifold* m = d->getManifoldByIndexInternal(i);
    const bool body_is_0 = m->getBody0() == b;
    if (!body_is_0 && m->getBody1() != b) continue;
    for (int j = 0; j < m->getNumContacts(); ++j) {
      const btManifoldPoint& cp = m->getContactPoint(j);
      const double P_bt = cp.getAppliedImpulse();  // Bullet's mass unit
      const double P = P_bt * settings_.mass_unit;
      if (!(cp.getDistance() <= touch_gap || P > 0)) continue;
      const bool stem = is_stem_point(cp, body_is_0);
      (stem ? sum.stem : sum.ball) = true;
      if (P > 0) {
        (stem ? sum.impulse_stem : sum.impulse_ball) += P;
        // The floor-side point, as the collision pass placed it before this step's solve.
        const btVector3& p_W = body_is_0 ? cp.getPositionWorldOnB() : cp.getPositionWorldOnA();
        sum.impulse += P;
        sum.moment += P * to_eigen(p_W);
        sum.max_point_impulse = std::max(sum.max_point_impulse, P_bt);
      }
      // The solver's lateral impulses along the point's friction directions act on body 0 (on
      // body 1 opposite), as its normal impulse along m_normalWorldOnB; the second direction is
      // solved (and written back) only with two friction directions.
      btVector3 lateral = cp.m_appliedImpulseLateral1 * cp.m_lateralFrictionDir1;
      if (settings_.friction_directions == 2) lateral += cp.m_appliedImpulseLateral2 * cp.m_lateralFrictionDir2;
      const Vec3 lateral_W = to_eigen(lateral) * (settings_.mass_unit * (body_is_0 ? 1.0 : -1.0));
      const btVector3& q_W = body_is_0 ? cp.getPositionWorldOnB() : cp.getPositionWorldOnA();
      add_surface_force(sum.surfaces, stem, P, Vec3(lateral_W.x(), lateral_W.y(), 0.0), to_eigen(q_W));
    }
  }
}

BulletReadback BulletSimulator::readback() const {
  const btRigidBody* b = o_.body.get();
  BulletReadback r;
  // In the scene's units (Bullet holds them divided by mass_unit).
  const double mu = settings_.mass_unit;
  r.mass = mu / b->getInvMass();
  r.inertia_B = to_eigen(b->getLocalInertia()) * mu;
  r.inv_inertia_B = to_eigen(b->getInvInertiaDiagLocal()) / mu;
  const btTransform& T_WB = b->getCenterOfMassTransform();
  r.p_WG = to_eigen(T_WB.getOrigin());
  btQuaternion q;
  T_WB.getBasis().getRotation(q);
  r.q_WB = to_eigen(q);
  const btCompoundShape* shape = o_.body_shape.get();
  r.ball_centre_B = to_eigen(shape->getChildTransform(0).getOrigin());
  r.ball_radius = static_cast<const btSphereShape*>(shape->getChildShape(0))->getRadius();
  r.has_stem = shape->getNumChildShapes() > 1;
  if (r.has_stem) {
    const btCollisionShape* stem = shape->getChildShape(1);
    const btTransform& T = shape->getChildTransform(1);
    r.stem_centre_B = to_eigen(T.getOrigin());
    if (stem->getShapeType() == CAPSULE_SHAPE_PROXYTYPE) {
      const auto* capsule = static_cast<const btCapsuleShape*>(stem);
      btVector3 up(0, 0, 0);
      up[capsule->getUpAxis()] = 1;
      r.stem_axis_B = to_eigen(T.getBasis() * up);
      r.stem_radius = capsule->getRadius();
      r.stem_half_length = capsule->getHalfHeight();
    } else {
      // The tip sphere: a segment of length 0 at P along the body's axis.
      r.stem_axis_B = to_eigen(T.getBasis() * btVector3(0, 0, 1));
      r.stem_radius = static_cast<const btSphereShape*>(stem)->getRadius();
      r.stem_half_length = 0;
    }
  }
  r.body_friction = b->getFriction();
  r.floor_friction = o_.floor->getFriction();
  r.body_rolling_friction = b->getRollingFriction();
  r.body_spinning_friction = b->getSpinningFriction();
  r.body_restitution = b->getRestitution();
  r.floor_restitution = o_.floor->getRestitution();
  const int f = b->getFlags();
  r.gyroscopic = (f & BT_ENABLE_GYROSCOPIC_FORCE_IMPLICIT_BODY)    ? "implicit_body"
                 : (f & BT_ENABLE_GYROSCOPIC_FORCE_IMPLICIT_WORLD) ? "implicit_world"
                 : (f & BT_ENABLE_GYROSCOPIC_FORCE_EXPLICIT)       ? "explicit"
                                                                   : "none";
  r.total_force_W = to_eigen(b->getTotalForce()) * mu;
  r.total_torque_W = to_eigen(b->getTotalTorque()) * mu;
  btDispatcher* d = o_.dispatcher.get();
  for (int i = 0; i < d->getNumManifolds(); ++i) {
    const btPersistentManifold* m = d->getManifoldByIndexInternal(i);
    if (m->getBody0() != b && m->getBody1() != b) continue;
    for (int j = 0; j < m->getNumContacts(); ++j) {
      const btManifoldPoint& cp = m->getContactPoint(j);
      r.point_friction.push_back(cp.m_combinedFriction);
      r.point_rolling_friction.push_back(cp.m_combinedRollingFriction);
      r.point_spinning_friction.push_back(cp.m_combinedSpinningFriction);
      r.point_restitution.push_back(cp.m_combinedRestitution);
    }
  }
  return r;
}

BulletReadback bullet_readback(const Simulator& sim) {
  const auto* bullet = dynamic_cast<const BulletSimulator*>(&sim);
  if (!bullet) throw std::invalid_argument("bullet_readback: not a Bullet simulator");
  return bullet->readback();
}

}  // namespace tippe
