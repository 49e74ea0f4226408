// DART 6.12 adapter: one FreeJoint body at G carrying a ball and a stem shape on a floor, stepped by the shared fixed-step loop.
//
// Collision backends: DART's own detector ("dart"), FCL ("fcl", "fcl_mesh") and Bullet ("bullet",
// DART's libdart-collision-bullet). That last links Debian's single-precision Bullet
// (libBulletCollision.so), the Bullet adapter the double-precision build (bullet-float64); both
// export the same C++ symbols. Each adapter is a module opened with RTLD_LOCAL, so each binds its
// own Bullet and both run in one process (tests/engines/test_dart.cpp); a build that links every
// engine into one binary cannot, and refuses "bullet" (TIPPE_DART_BULLET_BACKEND unset).
#include <dart/collision/CollisionGroup.hpp>
#include <dart/collision/CollisionObject.hpp>
#include <dart/collision/CollisionResult.hpp>
#include <dart/collision/dart/DARTCollisionDetector.hpp>
#if defined(TIPPE_DART_BULLET_BACKEND)
#include <dart/collision/bullet/BulletCollisionDetector.hpp>
#endif
#include <dart/collision/fcl/FCLCollisionDetector.hpp>
#include <dart/config.hpp>
#include <dart/constraint/BoxedLcpConstraintSolver.hpp>
#include <dart/constraint/ContactConstraint.hpp>
#include <dart/constraint/DantzigBoxedLcpSolver.hpp>
#include <dart/constraint/PgsBoxedLcpSolver.hpp>
#include <dart/dynamics/BodyNode.hpp>
#include <dart/dynamics/BoxShape.hpp>
#include <dart/dynamics/FreeJoint.hpp>
#include <dart/dynamics/ShapeNode.hpp>
#include <dart/dynamics/Skeleton.hpp>
#include <dart/dynamics/SphereShape.hpp>
#include <dart/dynamics/WeldJoint.hpp>
#include <dart/simulation/World.hpp>

#include <cmath>
#include <limits>
#include <memory>
#include <mutex>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "engines/core/adapters.h"
#include "engines/dart/dart_settings.h"
#include "engines/core/fixed_step.h"
#include "engines/core/registry.h"
#include "engines/core/settings.h"

namespace tippe {
namespace {

// ContactConstraint's parameters are static members, shared by every DART world in the process.
// Simulators on several threads (sweeps) each write their own values and step under this lock,
// so a step never sees another simulator's values.
std::mutex kDartGlobalsMutex;

}  // namespace

class DartSimulator : public FixedStepSimulator {
 public:
  explicit DartSimulator(const Scene& scene);

  SettingsList settings() const override;
  MassReadback mass_properties() const override;
  // World::step alone: the contact parameters written once, then no lock, no parameters and no
  // contact read per step (single-threaded benchmarks only: another world could change them).
  void library_steps(long long n) override {
    {
      std::lock_guard<std::mutex> lock(kDartGlobalsMutex);
      write_contact_parameters();
    }
    for (long long i = 0; i < n; ++i) world_->step(true);
  }

 protected:
  void engine_step() override;
  BodyState engine_state() const override;
  void engine_set_state(const BodyState& x) override;
  void apply_force_W(const Vec3& f_W, const Vec3& p_W) override;

 private:
  void read_contacts();
  void make_notes();
  void write_contact_parameters() const;

  DartSettings settings_;
  dart::simulation::WorldPtr world_;
  dart::dynamics::SkeletonPtr top_, floor_skel_;
  dart::dynamics::BodyNode* body_ = nullptr;
  dart::dynamics::FreeJoint* joint_ = nullptr;
  dart::dynamics::ShapeNode* ball_ = nullptr;
  dart::dynamics::ShapeNode* stem_ = nullptr;
};

DartSimulator::DartSimulator(const Scene& scene)
    : FixedStepSimulator(scene, dart_engine_info()), settings_(read_settings<DartSettings>("dart", scene)) {
  using namespace dart;
  const BodyModel& m = body();
  if (!(m.M > 0 && m.A > 0 && m.C > 0 && m.R > 0) || (m.stem && !(m.r > 0 && m.l >= 0)))
    throw std::invalid_argument("dart: needs M, A, C, R > 0 (and r > 0, l >= 0 with a stem)");

  world_ = simulation::World::create("tippe");
  world_->setGravity(Eigen::Vector3d(0, 0, -scene.gravity));
  world_->setTimeStep(settings_.timestep);

  // Solver: the primary boxed LCP solver and its fallback.
  std::shared_ptr<constraint::BoxedLcpSolver> primary, secondary;
  auto pgs = std::make_shared<constraint::PgsBoxedLcpSolver>();
  constraint::PgsBoxedLcpSolver::Option opt;
  opt.mMaxIteration = settings_.pgs_iterations;
  pgs->setOption(opt);
  if (settings_.lcp_solver == "pgs") primary = pgs;
  else primary = std::make_shared<constraint::DantzigBoxedLcpSolver>();
  if (settings_.pgs_fallback && settings_.lcp_solver == "dantzig") secondary = pgs;
  world_->setConstraintSolver(std::make_unique<constraint::BoxedLcpConstraintSolver>(primary, secondary));

  auto* solver = world_->getConstraintSolver();
  if (settings_.collision_detector == "dart") {
    solver->setCollisionDetector(collision::DARTCollisionDetector::create());
  } else if (settings_.collision_detector == "bullet") {
#if defined(TIPPE_DART_BULLET_BACKEND)
    solver->setCollisionDetector(collision::BulletCollisionDetector::create());
#else
    throw std::invalid_argument(
        "dart: collision_detector = \"bullet\" needs the engines as modules (TIPPE_ENGINE_MODULES=ON): DART's Bullet "
        "backend links single-precision Bullet, which cannot share one binary with the Bullet adapter's double-precision "
        "build");
#endif
  } else {
    auto fcl = collision::FCLCollisionDetector::create();
    fcl->setPrimitiveShapeType(settings_.collision_detector == "fcl" ? collision::FCLCollisionDetector::PRIMITIVE
                                                                      : collision::FCLCollisionDetector::MESH);
    // DART's own contact point computation: its documentation calls FCL's incorrect.
    fcl->setContactPointComputationMethod(collision::FCLCollisionDetector::DART);
    solver->setCollisionDetector(fcl);
  }
  solver->getCollisionOption().maxNumContacts = static_cast<std::size_t>(settings_.max_contacts);

  const double mu = native_mu(settings_.rolling_mu);

  // The floor: a fixed skeleton with a box whose top face is z = 0, floor_width R wide and 1 R
  // thick (a sphere meets only the top face while its centre is above it); see collision_detector.
  floor_skel_ = dynamics::Skeleton::create("floor");
  {
    auto pair = floor_skel_->createJointAndBodyNodePair<dynamics::WeldJoint>();
    dynamics::ShapePtr shape;
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    const double side = settings_.floor_width * m.R, thick = m.R;
    shape = std::make_shared<dynamics::BoxShape>(Eigen::Vector3d(side, side, thick));
    T.translation() = Eigen::Vector3d(0, 0, -0.5 * thick);
    auto* sn = pair.second->createShapeNodeWith<dynamics::CollisionAspect, dynamics::DynamicsAspect>(shape);
    sn->setRelativeTransform(T);
    // DART combines the two shapes' coefficients by their minimum: the floor carries the same
    // mu as the top, so the minimum is the scene's (checked by the conformance suite's
    // sliding ball: rolling from 2 v0 / (7 mu g)).
    sn->getDynamicsAspect()->setFrictionCoeff(mu);
    sn->getDynamicsAspect()->setRestitutionCoeff(0.0);
    floor_skel_->setMobile(false);
  }

  // The top: one body whose frame is the principal frame at G (the FreeJoint's child frame).
  top_ = dynamics::Skeleton::create("top");
  auto pair = top_->createJointAndBodyNodePair<dynamics::FreeJoint>();
  joint_ = pair.first;
  body_ = pair.second;
  // From the scene's mass properties, never from the shapes.
  body_->setInertia(dynamics::Inertia(m.M, Eigen::Vector3d::Zero(), Vec3(m.A, m.A, m.C).asDiagonal()));
  for (std::size_t i = 0; i < 6; ++i) joint_->setDampingCoefficient(i, 0.0);
  // The ball is a full sphere about O = G + d e_Z: the cap cut at h is not modelled.
  {
    auto sphere = std::make_shared<dynamics::SphereShape>(m.R);
    ball_ = body_->createShapeNodeWith<dynamics::CollisionAspect, dynamics::DynamicsAspect>(sphere);
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    T.translation() = Eigen::Vector3d(0, 0, m.z_O());
    ball_->setRelativeTransform(T);
    ball_->getDynamicsAspect()->setFrictionCoeff(mu);
    ball_->getDynamicsAspect()->setRestitutionCoeff(0.0);
  }
  if (m.stem) {
    // The sphere at the stem tip P (see collision_detector).
    auto shape = std::make_shared<dynamics::SphereShape>(m.r);
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    T.translation() = Eigen::Vector3d(0, 0, m.z_O() + m.l);
    stem_ = body_->createShapeNodeWith<dynamics::CollisionAspect, dynamics::DynamicsAspect>(shape);
    stem_->setRelativeTransform(T);
    stem_->getDynamicsAspect()->setFrictionCoeff(mu);
    stem_->getDynamicsAspect()->setRestitutionCoeff(0.0);
  }
  world_->addSkeleton(floor_skel_);
  world_->addSkeleton(top_);

  engine_set_state(scene_initial_state(scene));
  // Contacts of the initial state, so that the first step's bench-applied laws see the resting
  // contact (as in the other adapters).
  {
    std::lock_guard<std::mutex> lock(kDartGlobalsMutex);
    collision::CollisionResult result;
    auto group = world_->getConstraintSolver()->getCollisionGroup();
    group->collide(solver->getCollisionOption(), &result);
    for (const auto& c : result.getContacts()) {
      const auto* a = c.collisionObject1->getShapeFrame();
      const auto* b = c.collisionObject2->getShapeFrame();
      if (a == ball_ || b == ball_) report_.ball = true;
      if (stem_ && (a == stem_ || b == stem_)) report_.stem = true;
    }
  }
  make_notes();
  start(settings_.timestep);
}

SettingsList DartSimulator::settings() const { return list_settings(settings_); }

void DartSimulator::make_notes() {
  notes_ = friction_law_notes({"DART", "", "DART's previous step (contact forces, explicit)", ""}, settings_.rolling_mu);
  const ContactSpec& c = scene().contact;
  if (c.friction == FrictionLaw::Coulomb || c.friction == FrictionLaw::Rolling)
    notes_.push_back("Coulomb friction as a box in two tangent directions (pyramid, not cone), each bounded by mu F_n");
  if (settings_.collision_detector == "bullet")
    notes_.push_back("collision_detector = bullet: DART's Bullet backend, in single precision (Debian's Bullet build)");
  if (settings_.collision_detector == "fcl_mesh")
    notes_.push_back("collision_detector = fcl_mesh: FCL meshes stand in for the ball and the stem tip (faceted; contacts "
                     "can be missed or misplaced)");
  if (settings_.lcp_solver == "pgs")
    notes_.push_back("pgs: iterative contact solve, " + std::to_string(settings_.pgs_iterations) + " iterations");
  if (c.drilling > 0)
    notes_.push_back("drilling friction NOT modelled: DART 6.12's contact constraint has no torsional friction row, so this "
                     "run is of the scene without it (contact.drilling ignored)");
  // World::step: forward dynamics at the step's start, velocities integrated, the contact LCP
  // solved on them, then positions by the FreeJoint's exponential map.
  notes_.push_back("semi-implicit Euler step (first order): forces, the gyroscopic term w x I w included, from the state at "
                   "the start of each step (DART's forward dynamics)");
  if (!full_sphere_note().empty()) notes_.push_back(full_sphere_note());
}

// DART's process-wide ContactConstraint parameters, this simulator's values (under the lock).
void DartSimulator::write_contact_parameters() const {
  using dart::constraint::ContactConstraint;
  ContactConstraint::setErrorReductionParameter(settings_.erp);
  ContactConstraint::setMaxErrorReductionVelocity(settings_.max_erv);
  ContactConstraint::setErrorAllowance(settings_.error_allowance);
  ContactConstraint::setConstraintForceMixing(settings_.cfm);
}

void DartSimulator::engine_step() {
  // The bench's force is held over the step as a spatial force in the body frame (addExtForce),
  // and DART's free joint velocities are the body's spatial velocity in that frame, with a
  // constant mass matrix: the step's velocity update gives the force the work h F . (V0 + V1) / 2
  // (BenchWrench::work), which a lab-frame moment books with an O(h) error per unit time.
  const Eigen::Vector6d F_ext = body_->getExternalForceLocal();
  const double p0 = F_ext.dot(body_->getSpatialVelocity());
  {
    std::lock_guard<std::mutex> lock(kDartGlobalsMutex);
    write_contact_parameters();
    // resetCommand = true clears the external forces the bench added for this step.
    world_->step(true);
  }
  if (settings_.lcp_solver == "pgs") solver_iterations_ += settings_.pgs_iterations;
  read_contacts();
  report_.bench.work = 0.5 * (p0 + F_ext.dot(body_->getSpatialVelocity())) * world_->getTimeStep();
}

void DartSimulator::read_contacts() {
  ContactReport r;
  Vec3 moment = Vec3::Zero();
  for (const auto& c : world_->getLastCollisionResult().getContacts()) {
    const auto* a = c.collisionObject1->getShapeFrame();
    const auto* b = c.collisionObject2->getShapeFrame();
    const bool on_ball = a == ball_ || b == ball_;
    const bool on_stem = stem_ && (a == stem_ || b == stem_);
    if (!on_ball && !on_stem) continue;
    (on_stem ? r.stem : r.ball) = true;
    // Contact::force is the constraint force of the step on object 1; the floor is horizontal,
    // so its z part (with the sign that makes it the force on the top) is the normal force.
    const double f_n = (a == ball_ || a == stem_) ? c.force.z() : -c.force.z();
    r.normal_force += f_n;
    (on_stem ? r.normal_force_stem : r.normal_force_ball) += f_n;
    moment += f_n * c.point;
    // ContactConstraint::applyImpulse stores in Contact::force the normal and both tangent
    // impulses of the step over dt, in the lab frame: its horizontal part is the friction force.
    const Eigen::Vector3d f_W = (a == ball_ || a == stem_) ? Eigen::Vector3d(c.force) : Eigen::Vector3d(-c.force);
    add_surface_force(r, on_stem, f_n, Vec3(f_W.x(), f_W.y(), 0.0), c.point);
  }
  finish_surface_points(r);
  if (r.normal_force > 0) {
    r.point_valid = true;
    r.p_WC = moment / r.normal_force;
  }
  report_ = r;
}

BodyState DartSimulator::engine_state() const {
  BodyState x;
  x.t = time();
  const Eigen::Isometry3d& T = body_->getWorldTransform();
  x.p_WG = T.translation();
  x.q_WB = Quat(T.linear()).normalized();
  // The body origin is G: its classical linear velocity is v_G. One call for both halves:
  // getLinearVelocity() and getAngularVelocity() each compute this 6-vector and keep half.
  const Eigen::Vector6d V_W = body_->getSpatialVelocity(dart::dynamics::Frame::World(), dart::dynamics::Frame::World());
  x.v_WG = V_W.tail<3>();
  x.w_B = x.q_WB.conjugate() * Vec3(V_W.head<3>());
  return x;
}

void DartSimulator::engine_set_state(const BodyState& x) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = x.q_WB.normalized().toRotationMatrix();
  T.translation() = x.p_WG;
  joint_->setTransform(T);
  joint_->setLinearVelocity(x.v_WG);
  joint_->setAngularVelocity(x.q_WB.normalized() * x.w_B);
}

void DartSimulator::apply_force_W(const Vec3& f_W, const Vec3& p_W) {
  // Force in world coordinates at an offset in body coordinates from the body origin G.
  const Eigen::Isometry3d& T = body_->getWorldTransform();
  const Vec3 offset_B = T.linear().transpose() * (p_W - T.translation());
  body_->addExtForce(f_W, offset_B, false, true);
}

MassReadback DartSimulator::mass_properties() const {
  const dart::dynamics::Inertia& I = body_->getInertia();
  MassReadback mp;
  mp.mass = I.getMass();
  mp.p_GCm_B = I.getLocalCOM();
  // DART's moment is about the centre of mass; about G by the parallel-axis theorem.
  const Vec3 c = mp.p_GCm_B;
  mp.I_G_B = I.getMoment() + mp.mass * (c.squaredNorm() * Eigen::Matrix3d::Identity() - c * c.transpose());
  return mp;
}

std::unique_ptr<Simulator> make_dart_simulator(const Scene& scene) { return std::make_unique<DartSimulator>(scene); }

const EngineInfo& dart_engine_info() {
  static const EngineInfo info = [] {
    EngineInfo e = engine_entry<DartSettings>(  // Okabe-Ito orange
        "dart", EngineRole::Engine, make_dart_simulator, std::string("dart ") + DART_VERSION, "#E69F00");
    // The LCP solver: Dantzig's pivoting (exact) or projected Gauss-Seidel (iterative).
    e.advice_axes = {{"lcp_solver", {"\"dantzig\"", "\"pgs\""}}};
    e.cost_knob = "timestep";
    return e;
  }();
  return info;
}

}  // namespace tippe

// The module's one exported symbol, tippe_engine_dart: the registry's way in (registry.h).
TIPPE_ENGINE_ENTRY_POINT(dart)
