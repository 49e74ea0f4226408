// The Bullet adapter's pieces shared by its files (construction, contacts, checks, step): the world and shape it subclasses, the objects it owns and the simulator class.
#pragma once

#include <btBulletDynamicsCommon.h>

#include <memory>
#include <string>
#include <vector>

#include "engines/bullet/bullet_settings.h"
#include "engines/bullet/bullet_sim.h"
#include "engines/core/fixed_step.h"

#ifndef BT_USE_DOUBLE_PRECISION
#error "the Bullet adapter needs the double-precision build of Bullet (pkg-config bullet-float64)"
#endif

namespace tippe {
namespace bullet_detail {

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

inline btVector3 to_bt(const Vec3& v) { return btVector3(v.x(), v.y(), v.z()); }
inline Vec3 to_eigen(const btVector3& v) { return Vec3(v.x(), v.y(), v.z()); }
// Bullet's quaternion constructor and storage are (x, y, z, w), Eigen's constructor (w, x, y, z).
inline btQuaternion to_bt(const Quat& q) { return btQuaternion(q.x(), q.y(), q.z(), q.w()); }
inline Quat to_eigen(const btQuaternion& q) { return Quat(q.w(), q.x(), q.y(), q.z()); }

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

  void solveConstraints(btContactSolverInfo& info) override;
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
  // The per-surface friction impulses on the top (lab frame) and points (add_surface_force, with
  // impulses for forces: divided by dt when the step's report is made).
  ContactReport surfaces;
};

}  // namespace bullet_detail

class BulletSimulator : public FixedStepSimulator {
 public:
  explicit BulletSimulator(const Scene& scene);
  BulletSimulator(const BulletSimulator&) = delete;
  BulletSimulator& operator=(const BulletSimulator&) = delete;

  SettingsList settings() const override;
  std::vector<std::string> notes() const override;

  BulletReadback readback() const;
  MassReadback mass_properties() const override;

 protected:
  void engine_step() override;
  BodyState engine_state() const override;
  void engine_set_state(const BodyState& x) override;
  void apply_force_W(const Vec3& f_W, const Vec3& p_W) override;
  // solver_iterations_: Bullet does not report the sweeps it made, so it counts the configured
  // ones. With m_leastSquaresResidualThreshold = 0 it stops early only at an exactly zero residual
  // (e.g. no contact rows), so this is an upper bound that is reached whenever there is a contact.

 private:
  struct PendingForce {
    Vec3 f_W;
    Vec3 r_W;  // from G to the point of application
  };
  void configure_solver();
  void make_notes();
  void collect_contacts(bullet_detail::ContactSum& sum) const;
  bool is_stem_point(const btManifoldPoint& cp, bool body_is_0) const;
  void check_rotation(const char* when);
  bool gyroscopic_dropped() const;

  BulletSettings settings_;
  double h_ = 0.0;  // internal step
  double mu_ = 0.0, rolling_ = 0.0, spinning_ = 0.0;
  bullet_detail::BulletObjects o_;
  std::vector<PendingForce> pending_;
  long long internal_steps_ = 0;
  long long gyro_dropped_steps_ = 0;  // internal steps in which solve33 dropped w x I w
  double gyro_dropped_first_ = -1.0;  // time of the first such step
};

}  // namespace tippe
