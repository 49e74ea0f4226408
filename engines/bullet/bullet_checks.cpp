// Bullet adapter, checks and notes: the rotation clamp and the dropped gyroscopic term watched each internal step, and the notes that state the run's modelling choices.
#include "engines/bullet/bullet_adapter.h"

#include <cmath>
#include <sstream>
#include <string>
#include <vector>

namespace tippe {

using namespace bullet_detail;

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

}  // namespace tippe
