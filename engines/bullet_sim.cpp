// Bullet 3.24 (double) adapter: one btRigidBody at G with a ball+stem compound shape on a static plane, stepped by the shared fixed-step loop.
#include "bullet_sim.h"

#include <btBulletDynamicsCommon.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "adapters.h"
#include "bullet_settings.h"
#include "fixed_step.h"
#include "registry.h"
#include "settings.h"

#ifndef BT_USE_DOUBLE_PRECISION
#error "the Bullet adapter needs the double-precision build of Bullet (pkg-config bullet-float64)"
#endif

namespace tippe {
namespace {

constexpr double kPi = 3.14159265358979323846;

// Bullet 3.24's btDiscreteDynamicsWorld never calls btRigidBody::integrateVelocities (whose
// MAX_ANGVEL clamp at |omega| h = pi/2 only serves btSimpleDynamicsWorld): velocities are
// integrated inside the constraint solver. The limit that is on the path is in
// btTransformUtil::integrateTransform, which caps the rotation applied in one internal step at
// ANGULAR_MOTION_THRESHOLD = pi/4 while leaving the velocity as it is: above it the attitude
// update is simply wrong. Checked on the installed library: |omega| h = 2 keeps |omega| and
// rotates by 1.624 rad instead of 2.
constexpr double kRotationClamp = 0.25 * kPi;

// Rolling resistance (a length, relative to R) that only switches on Bullet's spinning-friction
// row: btSequentialImpulseConstraintSolver::convertContact adds the torsional rows of a contact
// point only when its combined rolling friction is > 0 (checked on the installed library: with
// rolling 0 a spinning friction of 0.1 leaves the spin untouched, with 1e-12 it removes exactly
// mu_d F_n t / C). The rolling torque it allows, 1e-12 R F_n, is ~1e-11 of the gravity torque.
constexpr double kRollingGateOverR = 1e-12;

// A manifold point within this gap (relative to R) counts as touching even without impulse.
constexpr double kTouchGapOverR = 1e-6;

btVector3 to_bt(const Vec3& v) { return btVector3(v.x(), v.y(), v.z()); }
Vec3 to_eigen(const btVector3& v) { return Vec3(v.x(), v.y(), v.z()); }
// Bullet's quaternion constructor and storage are (x, y, z, w), Eigen's constructor (w, x, y, z).
btQuaternion to_bt(const Quat& q) { return btQuaternion(q.x(), q.y(), q.z(), q.w()); }
Quat to_eigen(const btQuaternion& q) { return Quat(q.w(), q.x(), q.y(), q.z()); }

std::string num(double v) { return round_trip_text(v); }

// Coefficients the solver must see in every body-floor contact point.
struct ContactMaterial {
  const btCollisionObject* body = nullptr;
  btScalar friction = 0, rolling = 0, spinning = 0;
};

// The discrete world with one hook. Bullet combines the coefficients of the two objects when a
// point is added (btManifoldResult: friction = product, rolling/spinning = sum of cross
// products) and caps each at 10 (MAX_FRICTION), which would silently turn rolling_mu = 1e3 into
// 10. So the objects carry floor 1 / body mu (what Bullet's own combination gives for mu <= 10)
// and, before each solve, every body-floor point gets the scene's exact values. This is per
// world, unlike the process-wide gContactAddedCallback.
class TopWorld : public btDiscreteDynamicsWorld {
 public:
  using btDiscreteDynamicsWorld::btDiscreteDynamicsWorld;
  ContactMaterial material;

  void solveConstraints(btContactSolverInfo& info) override {
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
};

// The body's compound shape with its own contact breaking threshold: Bullet asks each shape for
// it (getContactBreakingThreshold) when it makes a manifold, so the setting is per simulator,
// unlike the process-wide gContactBreakingThreshold that threads of a sweep share.
class TopShape : public btCompoundShape {
 public:
  explicit TopShape(double breaking_factor) : breaking_factor_(breaking_factor) {}
  btScalar getContactBreakingThreshold(btScalar) const override { return getAngularMotionDisc() * breaking_factor_; }

 private:
  double breaking_factor_;
};

// Owns one simulator's Bullet objects; destroyed world first (its destructor still walks the
// bodies' broadphase proxies), then bodies, shapes, solver, broadphase, dispatcher.
struct BulletObjects {
  std::unique_ptr<btDefaultCollisionConfiguration> config;
  std::unique_ptr<btCollisionDispatcher> dispatcher;
  std::unique_ptr<btDbvtBroadphase> broadphase;
  std::unique_ptr<btSequentialImpulseConstraintSolver> solver;
  std::unique_ptr<btStaticPlaneShape> floor_shape;
  std::unique_ptr<btSphereShape> ball_shape;
  std::unique_ptr<btConvexInternalShape> stem_shape;  // btCapsuleShapeZ or btSphereShape
  std::unique_ptr<TopShape> body_shape;
  std::unique_ptr<btRigidBody> floor;
  std::unique_ptr<btRigidBody> body;
  std::unique_ptr<TopWorld> world;

  BulletObjects() = default;
  BulletObjects(const BulletObjects&) = delete;
  BulletObjects& operator=(const BulletObjects&) = delete;
  ~BulletObjects() {
    if (world) {
      if (body) world->removeRigidBody(body.get());
      if (floor) world->removeRigidBody(floor.get());
    }
    world.reset();
  }
};

// Contacts gathered over the internal steps of one scene step.
struct ContactSum {
  bool ball = false, stem = false;
  double impulse = 0.0;
  double impulse_ball = 0.0, impulse_stem = 0.0;  // the parts of impulse on each geom
  Vec3 moment = Vec3::Zero();
  double max_point_impulse = 0.0;  // in Bullet's units (its spinning-friction cap is there)
};

}  // namespace

class BulletSimulator : public FixedStepSimulator {
 public:
  explicit BulletSimulator(const Scene& scene);
  BulletSimulator(const BulletSimulator&) = delete;
  BulletSimulator& operator=(const BulletSimulator&) = delete;

  std::string engine() const override { return "bullet"; }
  std::string version() const override {
    return "bullet " + std::to_string(BT_BULLET_VERSION / 100) + "." + std::to_string(BT_BULLET_VERSION % 100);
  }
  SettingsList settings() const override;
  std::vector<std::string> notes() const override;

  BulletReadback readback() const;
  MassReadback mass_properties() const override;

 protected:
  void engine_step() override;
  BodyState engine_state() const override;
  void engine_set_state(const BodyState& x) override;
  ContactReport engine_contacts() const override { return report_; }
  void apply_force_W(const Vec3& f_W, const Vec3& p_W) override;
  std::string engine_limit_hit() const override { return limit_; }
  // Bullet does not report the sweeps it made: this counts the configured ones. With
  // m_leastSquaresResidualThreshold = 0 it stops early only at an exactly zero residual (e.g. no
  // contact rows), so this is an upper bound that is reached whenever there is a contact.
  long long engine_solver_iterations() const override { return solver_iterations_; }

 private:
  struct PendingForce {
    Vec3 f_W;
    Vec3 r_W;  // from G to the point of application
  };
  void configure_solver();
  void make_notes();
  void collect_contacts(ContactSum& sum) const;
  bool is_stem_point(const btManifoldPoint& cp, bool body_is_0) const;
  void check_rotation(const char* when);
  bool gyroscopic_dropped() const;

  BulletSettings settings_;
  double h_ = 0.0;  // internal step
  double mu_ = 0.0, rolling_ = 0.0, spinning_ = 0.0;
  std::vector<std::string> notes_;
  BulletObjects o_;
  std::vector<PendingForce> pending_;
  ContactReport report_;
  std::string limit_;
  long long solver_iterations_ = 0;
  long long internal_steps_ = 0;
  long long gyro_dropped_steps_ = 0;  // internal steps in which solve33 dropped w x I w
  double gyro_dropped_first_ = -1.0;  // time of the first such step
};

BulletSimulator::BulletSimulator(const Scene& scene)
    : FixedStepSimulator(scene), settings_(read_settings<BulletSettings>("bullet", scene)) {
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

void BulletSimulator::make_notes() {
  const Scene& sc = scene();
  auto short_num = [](double v) {
    std::ostringstream os;
    os << v;
    return os.str();
  };
  const bool frictional = sc.contact.friction == FrictionLaw::Coulomb || sc.contact.friction == FrictionLaw::Rolling;
  notes_ = friction_law_notes({"Bullet", "", "Bullet's previous scene step (explicit)",
                               " (written into each contact point: Bullet's own product of the two frictions is capped at 10)"},
                              settings_.rolling_mu);
  if (frictional && settings_.friction_directions == 2)
    notes_.push_back("Coulomb friction as a box in two tangent directions (first along the slip velocity), each bounded by mu P_n: "
                     "the friction force can exceed mu F_n by up to sqrt(2)");
  if (frictional && settings_.friction_directions == 1)
    notes_.push_back("one friction direction per contact point (along the slip velocity): a sticking contact is held only along it");
  if (sc.contact.drilling > 0)
    notes_.push_back("drilling friction as Bullet's spinning friction, |tau| <= mu_d P_n per contact point; Bullet adds that row only "
                     "with rolling friction > 0, so a rolling resistance of " + short_num(rolling_) +
                     " (length) is set: rolling torque <= " + short_num(kRollingGateOverR) + " R F_n");
  if (sc.contact.drilling > 0 && sc.contact.drilling_law == DrillingLaw::Coupled)
    notes_.push_back("drilling decoupled: Bullet bounds the spinning torque (|tau| <= mu_d P_n) and the friction force (mu P_n) in "
                     "rows of their own; the scene's coupled law bounds them jointly (Leine-Glocker ellipse), which Bullet cannot "
                     "represent: this run is the decoupled law");
  if (!settings_.split_impulse)
    notes_.push_back("penetration removed by Baumgarte velocity (split_impulse = false): the correction adds kinetic energy");
  else if (settings_.split_impulse_threshold < 0)
    notes_.push_back("split impulse only beyond " + short_num(-settings_.split_impulse_threshold) +
                     " penetration; shallower contacts corrected by Baumgarte velocity (adds kinetic energy)");
  if (settings_.gyroscopic == "none") notes_.push_back("gyroscopic term off (gyroscopic = none): not the top's physics");
  if (settings_.gyroscopic == "explicit") notes_.push_back("explicit gyroscopic torque: unstable for a fast spin");
  if (!full_sphere_note().empty()) notes_.push_back(full_sphere_note());
}

SettingsList BulletSimulator::settings() const {
  SettingsList s = list_settings(settings_);
  s.emplace_back("internal_step", num(h_));
  s.emplace_back("contact_friction", num(mu_));
  s.emplace_back("contact_rolling_friction", num(rolling_));
  s.emplace_back("contact_spinning_friction", num(spinning_));
  s.emplace_back("rotation_clamp_omega", num(kRotationClamp / h_));
  return s;
}

void BulletSimulator::check_rotation(const char* when) {
  if (!limit_.empty()) return;
  const double wh = o_.body->getAngularVelocity().length() * h_;
  if (!(wh <= kRotationClamp)) {
    std::ostringstream os;
    os.precision(6);
    os << "Bullet rotation clamp: |omega| h = " << wh << " > pi/4 " << when
       << " an internal step (btTransformUtil::integrateTransform shortens the rotation)";
    limit_ = os.str();
  }
}

// Whether Bullet's gyroscopic step about to be taken drops w x I w: the determinant of the
// Newton matrix exactly as btRigidBody::computeGyroscopicImpulseImplicit_Body builds it (the
// world variant's matrix is its rotation, the same determinant), against solve33's guard.
bool BulletSimulator::gyroscopic_dropped() const {
  const btRigidBody* b = o_.body.get();
  const int f = b->getFlags();
  if (!(f & (BT_ENABLE_GYROSCOPIC_FORCE_IMPLICIT_BODY | BT_ENABLE_GYROSCOPIC_FORCE_IMPLICIT_WORLD))) return false;
  const btVector3 idl = b->getLocalInertia();
  const btVector3 w_B = quatRotate(b->getWorldTransform().getRotation().inverse(), b->getAngularVelocity());
  btMatrix3x3 Ib;
  Ib.setValue(idl.x(), 0, 0, 0, idl.y(), 0, 0, 0, idl.z());
  btMatrix3x3 skew0, skew1;
  w_B.getSkewSymmetricMatrix(&skew0[0], &skew0[1], &skew0[2]);
  (Ib * w_B).getSkewSymmetricMatrix(&skew1[0], &skew1[1], &skew1[2]);
  const btMatrix3x3 J = Ib + (skew0 * Ib - skew1) * h_;
  const double det = btDot(J.getColumn(0), btCross(J.getColumn(1), J.getColumn(2)));
  return !(std::abs(det) > SIMD_EPSILON);
}

std::vector<std::string> BulletSimulator::notes() const {
  std::vector<std::string> n = notes_;
  if (gyro_dropped_steps_ > 0) {
    const btVector3 I = o_.body->getLocalInertia();
    std::ostringstream os;
    os.precision(3);
    os << "gyroscopic term w x I w dropped by Bullet in " << gyro_dropped_steps_ << " of " << internal_steps_
       << " internal steps (from t = " << gyro_dropped_first_ << "): its implicit step's 3x3 solve (btMatrix3x3::solve33) "
       << "inverts the determinant only above SIMD_EPSILON = " << SIMD_EPSILON << ", and A^2 C = " << I.x() * I.y() * I.z()
       << " in Bullet's units; a smaller engines.bullet.mass_unit avoids it (the determinant goes as mass_unit^-3)";
    n.push_back(os.str());
  }
  return n;
}

void BulletSimulator::engine_step() {
  btRigidBody* b = o_.body.get();
  ContactSum sum;
  for (int k = 0; k < settings_.substeps; ++k) {
    check_rotation("before");
    // stepSimulation clears the force accumulators after every call (checked by the tests):
    // the bench's force is re-applied for each internal step so that it acts over the whole dt.
    for (const PendingForce& f : pending_) b->applyForce(to_bt(f.f_W / settings_.mass_unit), to_bt(f.r_W));
    // Bullet computes its gyroscopic step from this velocity and attitude (stepSimulation changes
    // neither before the solve).
    ++internal_steps_;
    if (gyroscopic_dropped()) {
      if (gyro_dropped_steps_ == 0) gyro_dropped_first_ = time() + k * h_;
      ++gyro_dropped_steps_;
    }
    // maxSubSteps = 0 is Bullet's variable-step mode: exactly one internal step of h_, no
    // accumulator of leftover time and no interpolated transforms.
    o_.world->stepSimulation(h_, 0, h_);
    // The velocity after the step is the one integrateTransform has just used.
    check_rotation("in");
    collect_contacts(sum);
  }
  pending_.clear();
  solver_iterations_ += static_cast<long long>(settings_.solver_iterations) * settings_.substeps;

  ContactReport r;
  r.ball = sum.ball;
  r.stem = sum.stem;
  // Mean normal force over the scene step: the impulses of all internal steps over dt.
  r.normal_force = sum.impulse / settings_.timestep;
  // Per geom likewise: what the gliding law takes as each contact's F_n for the next step.
  r.normal_force_ball = sum.impulse_ball / settings_.timestep;
  r.normal_force_stem = sum.impulse_stem / settings_.timestep;
  if (sum.impulse > 0) {
    r.point_valid = true;
    r.p_WC = sum.moment / sum.impulse;
  }
  report_ = r;
  // The torsional row's bound is min(mu_d P_n, mu_d) (btSequentialImpulseConstraintSolver caps
  // rollingFrictionMagnitude at m_friction): a unit-dependent cap, reached only when one point's
  // normal impulse in one internal step exceeds 1.
  if (limit_.empty() && spinning_ > 0 && sum.max_point_impulse > 1.0)
    limit_ = "Bullet spinning-friction cap: normal impulse " + num(sum.max_point_impulse) +
             " > 1 (Bullet's mass unit) in one internal step bounds the drilling torque by mu_d instead of mu_d P_n";
}

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
    }
  }
}

BodyState BulletSimulator::engine_state() const {
  const btRigidBody* b = o_.body.get();
  const btTransform& T_WB = b->getCenterOfMassTransform();
  btQuaternion q;
  T_WB.getBasis().getRotation(q);
  BodyState x;
  x.t = time();
  x.p_WG = to_eigen(T_WB.getOrigin());
  x.v_WG = to_eigen(b->getLinearVelocity());
  x.q_WB = to_eigen(q).normalized();
  x.w_B = x.q_WB.conjugate() * to_eigen(b->getAngularVelocity());
  return x;
}

void BulletSimulator::engine_set_state(const BodyState& x) {
  btRigidBody* b = o_.body.get();
  btTransform T;
  T.setIdentity();
  T.setOrigin(to_bt(x.p_WG));
  T.setRotation(to_bt(x.q_WB));
  b->setCenterOfMassTransform(T);
  b->setInterpolationWorldTransform(T);
  b->setLinearVelocity(to_bt(x.v_WG));
  b->setAngularVelocity(to_bt(x.q_WB * x.w_B));
  b->setInterpolationLinearVelocity(to_bt(x.v_WG));
  b->setInterpolationAngularVelocity(to_bt(x.q_WB * x.w_B));
  b->updateInertiaTensor();
  // Manifolds of the new state for the next step's report and the bench-applied laws.
  o_.world->updateSingleAabb(b);
  o_.world->performDiscreteCollisionDetection();
  ContactSum sum;
  collect_contacts(sum);
  report_.ball = sum.ball;
  report_.stem = sum.stem;
}

MassReadback BulletSimulator::mass_properties() const {
  const btRigidBody* b = o_.body.get();
  MassReadback mp;
  mp.mass = 1.0 / b->getInvMass();
  // The rigid body's frame is its centre of mass, built at G: the offset is zero by construction.
  mp.p_GCm_B = Vec3::Zero();
  mp.I_G_B = to_eigen(b->getLocalInertia()).asDiagonal();
  return mp;
}

void BulletSimulator::apply_force_W(const Vec3& f_W, const Vec3& p_W) {
  pending_.push_back({f_W, p_W - to_eigen(o_.body->getCenterOfMassPosition())});
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

std::unique_ptr<Simulator> make_bullet_simulator(const Scene& scene) {
  return std::make_unique<BulletSimulator>(scene);
}

void validate_bullet_settings(const Scene& scene) { (void)read_settings<BulletSettings>("bullet", scene); }

const EngineInfo& bullet_engine_info() {
  static const EngineInfo info = [] {
    EngineInfo e;
    e.name = "bullet";
    e.role = EngineRole::Engine;
    e.make = make_bullet_simulator;
    set_settings_struct<BulletSettings>(e);
    e.version = "bullet " + std::to_string(BT_BULLET_VERSION / 100) + "." + std::to_string(BT_BULLET_VERSION % 100);
    e.colour = "#D55E00";  // Okabe-Ito vermillion
    return e;
  }();
  return info;
}

}  // namespace tippe
