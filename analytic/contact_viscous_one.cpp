// One contact held on the floor under the viscous law, sliding: a viscous run's common mode, its one normal force in closed form.
//
// Why a second path: the general solve (contact_dynamics.cpp) builds a row and a column per
// unknown for up to two contacts and solves the system of their count; with one unknown that
// bookkeeping was a fifth of every right-hand side. This is the same arithmetic, operation for
// operation, restricted to that mode, so its results are bit for bit the general solve's
// (tests/analytic/test_contact_dynamics.cpp compares the two on random states).
#include "analytic/contact_dynamics.h"
#include "analytic/detail/contact_kinematics.h"

namespace tippe {

using contact_detail::gravity_force;
using contact_detail::gyroscopic_torque;
using contact_detail::kinematics;
using contact_detail::Kinematics;
using contact_detail::sliding_drill_coeff;
using contact_detail::slot_kinematics;
using contact_detail::SlotKinematics;
using contact_detail::write_derivative;

ContactForces ContactDynamics::evaluate_viscous_one(const StateVector& y, int s, const ContactSlot& slot,
                                                    StateVector* dydt) const {
  const Kinematics k = kinematics(y, m_);
  const Vec3& w_W = k.w_W;
  const Vec3 e_z = Vec3::UnitZ();

  ContactForces out;
  Vec3 F_known = gravity_force(m_), T_known = gyroscopic_torque(k);
  const SlotKinematics sk = slot_kinematics(k, m_, s);
  const Vec3& r = sk.g.r_GC_W;
  const Vec3& slip = sk.slip_W;
  out.slip_W[s] = slip;
  const Vec3& centripetal = sk.centripetal_W;
  F_known += -c_.k * slip;
  T_known += r.cross(-c_.k * slip);
  const double drill_coeff = c_.drilling > 0.0 ? sliding_drill_coeff(c_.drilling, slot, w_W) : 0.0;
  // The normal force's column (force e_z at C, its moment and the drilling torque it carries)
  // and the constraint's row (the vertical acceleration of C), as the general solve has them.
  const Vec3 col_tau = r.cross(e_z) + drill_coeff * e_z, row_tau = r.cross(e_z);
  const double bias = e_z.dot(centripetal);
  const Vec3 a_free = F_known / m_.M;
  const Vec3 alpha_free = k.Iinv_W * T_known;
  const Vec3 alpha_col = k.Iinv_W * col_tau;
  const double b = -(e_z.dot(a_free) + row_tau.dot(alpha_free) + bias);
  const double K = e_z.dot(e_z) / m_.M + row_tau.dot(alpha_col);
  out.solvable = K != 0.0;
  const double fn = b / K;
  Vec3 F = F_known, T = T_known;
  F += e_z * fn;
  T += col_tau * fn;
  out.normal[s] = fn;
  Vec3 f = fn * e_z;
  f += -c_.k * out.slip_W[s];
  out.force_W[s] = f;
  out.drill_torque[s] = drill_coeff * fn;
  if (dydt) write_derivative(k, y, m_, F, T, *dydt);
  return out;
}

}  // namespace tippe
