// Observables shared by every simulator, computed from the common state by one function.
#include "analytic/observables.h"

#include <algorithm>
#include <cmath>

namespace tippe {

const char* to_string(FrictionLaw law) {
  switch (law) {
    case FrictionLaw::Rolling: return "rolling";
    case FrictionLaw::Viscous: return "viscous";
    case FrictionLaw::Coulomb: return "coulomb";
    case FrictionLaw::None: return "none";
    case FrictionLaw::Gliding: return "gliding";
  }
  return "?";
}

const char* to_string(DrillingLaw law) {
  switch (law) {
    case DrillingLaw::Decoupled: return "decoupled";
    case DrillingLaw::Coupled: return "coupled";
  }
  return "?";
}

const char* to_string(MassModel model) {
  switch (model) {
    case MassModel::Seed: return "seed";
    case MassModel::Solid: return "solid";
    case MassModel::Given: return "given";
  }
  return "?";
}

const char* to_string(Surface s) {
  switch (s) {
    case Surface::None: return "none";
    case Surface::Ball: return "ball";
    case Surface::Stem: return "stem";
    case Surface::Both: return "both";
  }
  return "?";
}

BodyModel BodyModel::from_scene(const Scene& scene) {
  BodyModel m;
  m.R = scene.body.sphere_radius;
  m.r = scene.body.stem_radius;
  m.l = scene.body.stem_length;
  m.M = scene.mass.mass;
  m.d = scene.mass.com_offset;
  m.A = scene.mass.inertia_transverse;
  m.C = scene.mass.inertia_axial;
  m.g = scene.gravity;
  m.stem = scene.contact.stem;
  m.switch_cos = m.stem ? -(m.R - m.r) / m.l : -2.0;
  return m;
}

Vec3 contact_offset_W(const BodyModel& m, const Quat& q_WB, Surface s) {
  const Vec3 e_Z = q_WB * Vec3::UnitZ();
  if (s == Surface::Stem) return m.z_P() * e_Z - m.r * Vec3::UnitZ();
  return m.z_O() * e_Z - m.R * Vec3::UnitZ();
}

Surface lower_surface(const BodyModel& m, const Quat& q_WB) {
  if (!m.stem) return Surface::Ball;
  const double c = (q_WB * Vec3::UnitZ()).z();
  return c < m.switch_cos ? Surface::Stem : Surface::Ball;
}

double surface_gap(const BodyModel& m, const BodyState& x, Surface s) {
  return x.p_WG.z() + contact_offset_W(m, x.q_WB, s).z();
}

double energy(const BodyModel& m, const BodyState& x) {
  const Vec3& w = x.w_B;
  const double rot = 0.5 * (m.A * (w.x() * w.x() + w.y() * w.y()) + m.C * w.z() * w.z());
  return 0.5 * m.M * x.v_WG.squaredNorm() + rot + m.M * m.g * x.p_WG.z();
}

double jellett(const BodyModel& m, const BodyState& x, Surface s) {
  const Vec3& w = x.w_B;
  const Vec3 L_B(m.A * w.x(), m.A * w.y(), m.C * w.z());
  const Vec3 R_C_B = x.q_WB.conjugate() * contact_offset_W(m, x.q_WB, s);
  return L_B.dot(R_C_B);
}

// atan2 rather than acos of e_Z.z: acos loses all digits near 0 and pi (a tilt of 1e-9 rad
// has cos = 1 - 5e-19, which rounds to 1), and the extremes start that close to vertical.
double tilt(const Quat& q_WB) {
  const Vec3 e_Z = q_WB * Vec3::UnitZ();
  return std::atan2(std::hypot(e_Z.x(), e_Z.y()), e_Z.z());
}

namespace {

double slip_speed_at(const BodyState& x, const Vec3& R_C_W) {
  const Vec3 w_W = x.q_WB * x.w_B;
  const Vec3 v_C = x.v_WG + w_W.cross(R_C_W);
  return std::hypot(v_C.x(), v_C.y());
}

// The observables of x with the contact quantities taken on surface `on`.
Observation observe_on(const BodyModel& m, const BodyState& x, Surface on, bool slip = true) {
  Observation o;
  o.state = x;
  o.theta = tilt(x.q_WB);
  o.surface = on;
  const Vec3 R_C_W = contact_offset_W(m, x.q_WB, on);
  o.p_WC = x.p_WG + R_C_W;
  if (slip) o.slip_speed = slip_speed_at(x, R_C_W);
  o.energy = energy(m, x);
  o.jellett = jellett(m, x, on);
  // Latitude of the ball point under O measured from the south pole -e_Z.
  const Vec3 down_B = x.q_WB.conjugate() * (-Vec3::UnitZ());
  o.contact_latitude = std::atan2(std::hypot(down_B.x(), down_B.y()), -down_B.z());
  return o;
}

}  // namespace

Observation observe_kinematics(const BodyModel& m, const BodyState& x, bool slip) {
  return observe_on(m, x, lower_surface(m, x.q_WB), slip);
}

double contact_slip_speed(const BodyModel& m, const BodyState& x, Surface s) {
  return slip_speed_at(x, contact_offset_W(m, x.q_WB, s));
}

Observation observe_kinematics_on_both(const BodyModel& m, const BodyState& x) {
  Observation o = observe_on(m, x, Surface::Ball);
  o.surface = Surface::Both;
  return o;
}

}  // namespace tippe
