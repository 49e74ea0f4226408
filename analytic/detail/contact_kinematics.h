// What every contact evaluation needs of a state and how it writes the state's derivative, shared by the general contact solve and its closed form for one viscous contact, so the two do the same arithmetic.
#pragma once

#include <Eigen/Dense>
#include <algorithm>

#include "analytic/contact_dynamics.h"

// Inlined into both callers: as a call of its own (GCC's choice) it returned its 250-byte result
// through memory on every right-hand side, 2 % of a reference run's instructions.
#if defined(__GNUC__)
#define TIPPE_INLINE_KINEMATICS __attribute__((always_inline)) inline
#else
#define TIPPE_INLINE_KINEMATICS inline
#endif

namespace tippe::contact_detail {

struct Kinematics {
  BodyState x;             // the state as given (q_WB not normalised)
  double qn2;              // |q_WB|^2, for the pull back onto the unit sphere
  Eigen::Matrix3d R_WB;    // from the normalised quaternion
  Vec3 w_W;                // angular velocity, lab frame
  Vec3 I_B;                // principal moments (A, A, C)
  Eigen::Matrix3d Iinv_W;  // inverse inertia, lab frame
};

// Each quantity is built as a local and the whole returned: Eigen rounds R D R^T differently when
// it constructs a matrix from it than when it assigns it to an existing one (95 % of random
// rotations differ in some element, the reference's trajectory by 1e-14 after a second), and the
// general solve's numbers were those of construction.
TIPPE_INLINE_KINEMATICS Kinematics kinematics(const StateVector& y, const BodyModel& m) {
  const BodyState x = unpack(y, 0.0);
  const double qn2 = x.q_WB.squaredNorm();
  const Quat q = x.q_WB.normalized();
  const Eigen::Matrix3d R_WB = q.toRotationMatrix();
  const Vec3 w_W = R_WB * x.w_B;
  const Vec3 I_B(m.A, m.A, m.C);
  // I_W w_W = R (I_B w_B): the world inertia itself is not needed, only its inverse.
  const Eigen::Matrix3d Iinv_W = R_WB * I_B.cwiseInverse().asDiagonal() * R_WB.transpose();
  return Kinematics{x, qn2, R_WB, w_W, I_B, Iinv_W};
}

// What a contact slot's constraint needs of the kinematics: its geometry (ContactDynamics::geometry
// from the rotation at hand, which would otherwise normalise q again), the horizontal velocity of
// the material point at C and the centripetal term w x (w x r_GO) of its sphere's centre.
struct SlotKinematics {
  ContactGeometry g;
  Vec3 slip_W;
  Vec3 centripetal_W;
};

inline SlotKinematics slot_kinematics(const Kinematics& k, const BodyModel& m, int s) {
  ContactGeometry g;
  g.radius = s == 0 ? m.R : m.r;
  g.r_GO_W = (s == 0 ? m.z_O() : m.z_P()) * Vec3(k.R_WB.col(2));
  g.r_GC_W = g.r_GO_W - g.radius * Vec3::UnitZ();
  Vec3 slip = k.x.v_WG + k.w_W.cross(g.r_GC_W);
  slip.z() = 0.0;
  const Vec3 centripetal = k.w_W.cross(k.w_W.cross(g.r_GO_W));
  return SlotKinematics{g, slip, centripetal};
}

inline Vec3 gravity_force(const BodyModel& m) { return -m.M * m.g * Vec3::UnitZ(); }

// -w x (I w) in the lab frame: the torque-free body's own rate of change of I_W w_W.
inline Vec3 gyroscopic_torque(const Kinematics& k) { return -k.w_W.cross(k.R_WB * k.I_B.cwiseProduct(k.x.w_B)); }

// Decoupled drilling law, sliding: the drilling torque per unit normal force, against the slot's
// kept sign of the spin (ContactSlot::drill_dir) or, without one, the spin's own.
inline double sliding_drill_coeff(double mu_d, const ContactSlot& slot, const Vec3& w_W) {
  const double spin_z = w_W.z();
  const double sign = slot.drill_dir != 0.0 ? slot.drill_dir : (spin_z > 0 ? 1.0 : (spin_z < 0 ? -1.0 : 0.0));
  return -mu_d * sign;
}

// The state's derivative from the net force F and torque T (lab frame) on the body.
inline void write_derivative(const Kinematics& k, const StateVector& y, const BodyModel& m, const Vec3& F, const Vec3& T,
                             StateVector& d) {
  const BodyState& x = k.x;
  const Vec3 a_G = F / m.M;
  const Vec3 wdot_B = k.I_B.cwiseInverse().cwiseProduct(k.R_WB.transpose() * T);
  // Quaternion rate from body-frame omega, plus a term that pulls |q| back to 1 at the rate
  // of the motion: the unit sphere is invariant, so the exact solution is unchanged.
  const double kappa = std::max(1.0, x.w_B.norm());
  const double qw = y[6], qx = y[7], qy = y[8], qz = y[9];
  const double wx = x.w_B.x(), wy = x.w_B.y(), wz = x.w_B.z();
  const double pull = kappa * (1.0 - k.qn2);
  d[0] = x.v_WG.x(); d[1] = x.v_WG.y(); d[2] = x.v_WG.z();
  d[3] = a_G.x(); d[4] = a_G.y(); d[5] = a_G.z();
  d[6] = 0.5 * (-qx * wx - qy * wy - qz * wz) + pull * qw;
  d[7] = 0.5 * (qw * wx + qy * wz - qz * wy) + pull * qx;
  d[8] = 0.5 * (qw * wy + qz * wx - qx * wz) + pull * qy;
  d[9] = 0.5 * (qw * wz + qx * wy - qy * wx) + pull * qz;
  d[10] = wdot_B.x(); d[11] = wdot_B.y(); d[12] = wdot_B.z();
}

}  // namespace tippe::contact_detail
