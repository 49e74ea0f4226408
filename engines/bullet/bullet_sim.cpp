// Bullet 3.24 (double) adapter: one btRigidBody at G with a ball+stem compound shape on a static plane, stepped by the shared fixed-step loop; here its step, state and registration.
#include "engines/bullet/bullet_sim.h"

#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "engines/core/adapters.h"
#include "engines/bullet/bullet_adapter.h"
#include "engines/core/registry.h"
#include "engines/core/settings.h"

namespace tippe {

using namespace bullet_detail;

namespace {

std::string num(double v) { return round_trip_text(v); }

}  // namespace

SettingsList BulletSimulator::settings() const {
  SettingsList s = list_settings(settings_);
  s.emplace_back("internal_step", num(h_));
  s.emplace_back("contact_friction", num(mu_));
  s.emplace_back("contact_rolling_friction", num(rolling_));
  s.emplace_back("contact_spinning_friction", num(spinning_));
  s.emplace_back("rotation_clamp_omega", num(kRotationClamp / h_));
  return s;
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
  // The friction impulses of all internal steps over dt: the mean friction force of the step.
  r.friction_ball_W = sum.surfaces.friction_ball_W / settings_.timestep;
  r.friction_stem_W = sum.surfaces.friction_stem_W / settings_.timestep;
  r.p_WC_ball = sum.surfaces.p_WC_ball;
  r.p_WC_stem = sum.surfaces.p_WC_stem;
  r.weight_ball = sum.surfaces.weight_ball;
  r.weight_stem = sum.surfaces.weight_stem;
  r.points_ball = sum.surfaces.points_ball;
  r.points_stem = sum.surfaces.points_stem;
  finish_surface_points(r);
  report_ = r;
  // The torsional row's bound is min(mu_d P_n, mu_d) (btSequentialImpulseConstraintSolver caps
  // rollingFrictionMagnitude at m_friction): a unit-dependent cap, reached only when one point's
  // normal impulse in one internal step exceeds 1.
  if (limit_.empty() && spinning_ > 0 && sum.max_point_impulse > 1.0)
    limit_ = "Bullet spinning-friction cap: normal impulse " + num(sum.max_point_impulse) +
             " > 1 (Bullet's mass unit) in one internal step bounds the drilling torque by mu_d instead of mu_d P_n";
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

std::unique_ptr<Simulator> make_bullet_simulator(const Scene& scene) {
  return std::make_unique<BulletSimulator>(scene);
}

void validate_bullet_settings(const Scene& scene) { (void)read_settings<BulletSettings>("bullet", scene); }

const EngineInfo& bullet_engine_info() {
  static const EngineInfo info = [] {
    EngineInfo e = engine_entry<BulletSettings>(  // Okabe-Ito vermillion
        "bullet", EngineRole::Engine, make_bullet_simulator,
        "bullet " + std::to_string(BT_BULLET_VERSION / 100) + "." + std::to_string(BT_BULLET_VERSION % 100), "#D55E00");
    // The sequential-impulse solver's iterations, split impulse (position correction kept out of
    // the velocities) and the gyroscopic integration.
    e.advice_axes = {{"solver_iterations", {"50", "10"}},
                     {"split_impulse", {"true", "false"}},
                     {"gyroscopic", {"\"implicit_body\"", "\"explicit\""}}};
    e.cost_knob = "timestep";
    return e;
  }();
  return info;
}

}  // namespace tippe

// The module's one exported symbol, tippe_engine_bullet: the registry's way in (registry.h).
TIPPE_ENGINE_ENTRY_POINT(bullet)
