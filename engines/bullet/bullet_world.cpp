// Bullet adapter, construction: the world with its per-point material hook, the floor, the top's compound body at G and the solver's settings, from the scene.
#include "engines/bullet/bullet_adapter.h"

#include <stdexcept>

#include "engines/core/settings.h"

namespace tippe {

using namespace bullet_detail;

void TopWorld::solveConstraints(btContactSolverInfo& info) {
  btDispatcher* d = getDispatcher();
  for (int i = 0; i < d->getNumManifolds(); ++i) {
    btPersistentManifold* m = d->getManifoldByIndexInternal(i);
    if (m->getBody0() != material.body && m->getBody1() != material.body) continue;
    for (int j = 0; j < m->getNumContacts(); ++j) {
      btManifoldPoint& cp = m->getContactPoint(j);
      cp.m_combinedFriction = material.friction;
      cp.m_combinedRollingFriction = material.rolling;
      cp.m_combinedSpinningFriction = material.spinning;
      cp.m_combinedRestitution = 0;
    }
  }
  btDiscreteDynamicsWorld::solveConstraints(info);
}

BulletSimulator::BulletSimulator(const Scene& scene)
    : FixedStepSimulator(scene, bullet_engine_info()), settings_(read_settings<BulletSettings>("bullet", scene)) {
  const BodyModel& m = body();
  if (!(m.M > 0 && m.A > 0 && m.C > 0 && m.R > 0) || (m.stem && !(m.r > 0 && m.l >= 0)))
    throw std::invalid_argument("bullet: needs M, A, C, R > 0 (and r > 0, l >= 0 with a stem)");
  h_ = settings_.timestep / settings_.substeps;

  const ContactSpec& c = scene.contact;
  mu_ = native_mu(settings_.rolling_mu);
  // Spinning friction is Bullet's torsional row: |tau| <= spinning * normal impulse per point,
  // i.e. a length, the scene's mu_d. Without drilling both stay exactly 0 (no torsional rows).
  spinning_ = c.drilling > 0 ? c.drilling : 0.0;
  rolling_ = c.drilling > 0 ? kRollingGateOverR * m.R : 0.0;

  o_.config = std::make_unique<btDefaultCollisionConfiguration>();
  o_.dispatcher = std::make_unique<btCollisionDispatcher>(o_.config.get());
  o_.broadphase = std::make_unique<btDbvtBroadphase>();
  o_.solver = std::make_unique<btSequentialImpulseConstraintSolver>();
  o_.world = std::make_unique<TopWorld>(o_.dispatcher.get(), o_.broadphase.get(), o_.solver.get(), o_.config.get());
  o_.world->setGravity(btVector3(0, 0, -scene.gravity));
  configure_solver();

  o_.floor_shape = std::make_unique<btStaticPlaneShape>(btVector3(0, 0, 1), 0);
  {
    btRigidBody::btRigidBodyConstructionInfo info(0, nullptr, o_.floor_shape.get(), btVector3(0, 0, 0));
    info.m_friction = 1;
    info.m_rollingFriction = 0;
    info.m_spinningFriction = 0;
    info.m_restitution = 0;
    o_.floor = std::make_unique<btRigidBody>(info);
    o_.world->addRigidBody(o_.floor.get());
  }

  // Sphere and capsule are Bullet's implicit shapes (all radius is margin): their surfaces are
  // exact, unlike a hull. The ball is a full sphere about O = G + d e_Z: the cap cut at h is not
  // modelled (see notes).
  o_.body_shape = std::make_unique<TopShape>(settings_.contact_breaking_threshold);
  o_.ball_shape = std::make_unique<btSphereShape>(m.R);
  btTransform child;
  child.setIdentity();
  child.setOrigin(btVector3(0, 0, m.z_O()));
  o_.body_shape->addChildShape(child, o_.ball_shape.get());  // child index 0
  if (m.stem && settings_.stem_shape == "tip_sphere") {
    o_.stem_shape = std::make_unique<btSphereShape>(m.r);
    child.setOrigin(btVector3(0, 0, m.z_P()));
    o_.body_shape->addChildShape(child, o_.stem_shape.get());  // child index 1
  } else if (m.stem) {
    // Bullet's capsule height is the segment between the cap centres, centred on its origin:
    // O to P is the segment, so the origin sits at the middle, d + l/2.
    o_.stem_shape = std::make_unique<btCapsuleShapeZ>(m.r, m.l);
    child.setOrigin(btVector3(0, 0, m.z_O() + 0.5 * m.l));
    o_.body_shape->addChildShape(child, o_.stem_shape.get());  // child index 1
  }

  const BodyState x0 = scene_initial_state(scene);
  const Quat q0 = x0.q_WB.normalized();
  btTransform start_W;
  start_W.setIdentity();
  start_W.setOrigin(to_bt(x0.p_WG));
  start_W.setRotation(to_bt(q0));
  {
    // The body frame is the principal frame at G, so the inertia is the scene's diagonal; never
    // calculateLocalInertia (a box approximation for capsules and compounds).
    const btVector3 I_B = btVector3(m.A, m.A, m.C) / settings_.mass_unit;
    btRigidBody::btRigidBodyConstructionInfo info(m.M / settings_.mass_unit, nullptr, o_.body_shape.get(), I_B);
    info.m_startWorldTransform = start_W;
    info.m_linearDamping = 0;
    info.m_angularDamping = 0;
    info.m_additionalDamping = false;
    info.m_friction = mu_;
    info.m_rollingFriction = rolling_;
    info.m_spinningFriction = spinning_;
    info.m_restitution = 0;
    info.m_linearSleepingThreshold = 0;
    info.m_angularSleepingThreshold = 0;
    o_.body = std::make_unique<btRigidBody>(info);
  }
  btRigidBody* b = o_.body.get();
  b->setMassProps(m.M / settings_.mass_unit, btVector3(m.A, m.A, m.C) / settings_.mass_unit);
  b->updateInertiaTensor();
  b->setDamping(0, 0);
  b->setActivationState(DISABLE_DEACTIVATION);
  int flags = b->getFlags() & ~(BT_ENABLE_GYROSCOPIC_FORCE_EXPLICIT | BT_ENABLE_GYROSCOPIC_FORCE_IMPLICIT_WORLD |
                                BT_ENABLE_GYROSCOPIC_FORCE_IMPLICIT_BODY);
  if (settings_.gyroscopic == "explicit") flags |= BT_ENABLE_GYROSCOPIC_FORCE_EXPLICIT;
  else if (settings_.gyroscopic == "implicit_world") flags |= BT_ENABLE_GYROSCOPIC_FORCE_IMPLICIT_WORLD;
  else if (settings_.gyroscopic == "implicit_body") flags |= BT_ENABLE_GYROSCOPIC_FORCE_IMPLICIT_BODY;
  b->setFlags(flags);
  b->setLinearVelocity(to_bt(x0.v_WG));
  b->setAngularVelocity(to_bt(q0 * x0.w_B));
  o_.world->addRigidBody(b);  // after setGravity: the body takes the world's gravity here
  o_.world->material = {b, mu_, rolling_, spinning_};

  // Manifolds of the initial state, so that the first step's report (and the viscous law, which
  // acts only while the engine reports a contact) sees the resting contact.
  o_.world->performDiscreteCollisionDetection();
  ContactSum sum;
  collect_contacts(sum);
  report_.ball = sum.ball;
  report_.stem = sum.stem;

  make_notes();
  start(settings_.timestep);
}

void BulletSimulator::configure_solver() {
  btContactSolverInfo& si = o_.world->getSolverInfo();
  si.m_numIterations = settings_.solver_iterations;
  si.m_erp = settings_.erp;
  si.m_erp2 = settings_.erp2;
  si.m_globalCfm = settings_.cfm;
  si.m_splitImpulse = settings_.split_impulse ? 1 : 0;
  si.m_splitImpulsePenetrationThreshold = settings_.split_impulse_threshold;
  si.m_splitImpulseTurnErp = settings_.split_impulse_turn_erp;
  si.m_warmstartingFactor = settings_.warmstarting_factor;
  si.m_sor = settings_.sor;
  // Stated although they are Bullet's defaults: no allowed penetration, no early exit.
  si.m_linearSlop = 0;
  si.m_leastSquaresResidualThreshold = 0;
  si.m_restitution = 0;
  // Only the explicit gyroscopic mode reads it: a cap on the physics, lifted.
  si.m_maxGyroscopicForce = BT_LARGE_FLOAT;
  // SOLVER_SIMD is Bullet's default (its double build falls back to scalar rows); no random
  // row order (SOLVER_RANDMIZE_ORDER), so runs are reproducible.
  int mode = SOLVER_SIMD;
  if (settings_.warmstarting) mode |= SOLVER_USE_WARMSTARTING;
  if (settings_.friction_directions == 2) mode |= SOLVER_USE_2_FRICTION_DIRECTIONS;
  if (!settings_.velocity_friction_direction) mode |= SOLVER_DISABLE_VELOCITY_DEPENDENT_FRICTION_DIRECTION;
  si.m_solverMode = mode;
}

}  // namespace tippe
