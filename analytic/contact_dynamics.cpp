// Equations of motion under a contact mode: contact forces from the acceleration constraints.
//
// Why this form: the source (tippe_top_equations_ja.md) eliminates the contact force by hand
// for the ball and for rolling only, with d and R hard-coded and a sign error in F_n2. Here the
// forces at every active contact are the unknowns of one small linear system, written in the
// lab frame with the general R_C, so every law works on the ball, the stem and both at once.
// Each constraint row says that a component of the acceleration of the material point at C
// vanishes: n . (a_G + dw/dt x R_C + w x (w x r_GO)) = 0, with r_GO the vector from G to the
// centre of the contacting sphere (the lowest point moves over the sphere, the centre does not).
#include "analytic/contact_dynamics.h"
#include "analytic/detail/contact_kinematics.h"
#include "analytic/detail/contact_unknowns.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <limits>

namespace tippe {

namespace {

using contact_detail::gravity_force;
using contact_detail::gyroscopic_torque;
using contact_detail::kinematics;
using contact_detail::Kinematics;
using contact_detail::kMaxUnknowns;
using contact_detail::sliding_drill_coeff;
using contact_detail::slot_kinematics;
using contact_detail::SlotKinematics;
using contact_detail::write_derivative;
using contact_detail::MatN;
using contact_detail::VecN;

struct Column {  // generalized force per unit of an unknown
  Vec3 f, tau;
};
struct Row {  // row . (a_G, dw/dt) + bias = 0
  Vec3 f, tau;
  double bias;
};

}  // namespace

StateVector pack(const BodyState& x) {
  return {x.p_WG.x(), x.p_WG.y(), x.p_WG.z(), x.v_WG.x(), x.v_WG.y(), x.v_WG.z(),
          x.q_WB.w(), x.q_WB.x(), x.q_WB.y(), x.q_WB.z(), x.w_B.x(), x.w_B.y(), x.w_B.z()};
}

BodyState unpack(const StateVector& y, double t) {
  BodyState x;
  x.t = t;
  x.p_WG = Vec3(y[0], y[1], y[2]);
  x.v_WG = Vec3(y[3], y[4], y[5]);
  x.q_WB = Quat(y[6], y[7], y[8], y[9]);
  x.w_B = Vec3(y[10], y[11], y[12]);
  return x;
}

ContactGeometry ContactDynamics::geometry(const BodyState& x, int slot) const {
  const Quat q = x.q_WB.normalized();
  const Vec3 e_Z = q * Vec3::UnitZ();
  ContactGeometry g;
  g.radius = slot == 0 ? m_.R : m_.r;
  g.r_GO_W = (slot == 0 ? m_.z_O() : m_.z_P()) * e_Z;
  g.r_GC_W = g.r_GO_W - g.radius * Vec3::UnitZ();
  return g;
}

Vec3 ContactDynamics::contact_velocity(const BodyState& x, int slot) const {
  const Vec3 w_W = x.q_WB.normalized() * x.w_B;
  return x.v_WG + w_W.cross(geometry(x, slot).r_GC_W);
}

Vec3 ContactDynamics::coupled_slip(const BodyState& x, int slot) const {
  const Vec3 v = contact_velocity(x, slot);
  const double w_z = (x.q_WB.normalized() * x.w_B).z();
  return Vec3(c_.mu * v.x(), c_.mu * v.y(), c_.drilling * w_z);
}

double ContactDynamics::coupled_demand(const ContactForces& f, int slot) const {
  // mu > 0 and mu_d > 0 are the scene reader's conditions for the coupled law.
  const double ft = std::hypot(f.force_W[slot].x(), f.force_W[slot].y());
  return std::hypot(ft / c_.mu, f.drill_torque[slot] / c_.drilling);
}

double ContactDynamics::gap_acceleration(const StateVector& y, const StateVector& dy, int slot) const {
  const BodyState x = unpack(y, 0);
  const Quat q = x.q_WB.normalized();
  const Vec3 w_W = q * x.w_B, wdot_W = q * Vec3(dy[10], dy[11], dy[12]);
  const Vec3 r_GO = geometry(x, slot).r_GO_W;
  return dy[5] + wdot_W.cross(r_GO).z() + w_W.cross(w_W.cross(r_GO)).z();
}

ContactForces ContactDynamics::evaluate(const StateVector& y, const ContactMode& mode, StateVector* dydt) const {
  // The common mode of a viscous run in closed form (contact_viscous_one.cpp), bit for bit what
  // the general solve gives it.
  if (c_.friction == FrictionLaw::Viscous && mode.slot[0].active != mode.slot[1].active) {
    const int s = mode.slot[0].active ? 0 : 1;
    const ContactSlot& slot = mode.slot[s];
    if (!slot.graze && !slot.stick && !slot.drill_stick) return evaluate_viscous_one(y, s, slot, dydt);
  }
  return evaluate_general(y, mode, dydt);
}

ContactForces ContactDynamics::evaluate_general(const StateVector& y, const ContactMode& mode, StateVector* dydt) const {
  int grazing = -1, n_grazing = 0;
  for (int s = 0; s < 2; ++s)
    if (mode.slot[s].active && mode.slot[s].graze) {
      grazing = s;
      ++n_grazing;
    }
  if (n_grazing == 0) {
    for (int s = 0; s < 2; ++s)
      if (c_.friction == FrictionLaw::Coulomb && mode.slot[s].active && !mode.slot[s].stick && mode.slot[s].slip_start)
        return evaluate_slip_start(y, mode, dydt);
    return evaluate_fixed(y, mode, dydt, 1.0);
  }
  // Filippov's combination of the lifted (share 0) and the loaded (share 1) fields; both are
  // linear in the share, so the combination is the exact solution at the share found.
  StateVector d0, d1;
  const ContactForces f0 = evaluate_fixed(y, mode, &d0, 0.0), f1 = evaluate_fixed(y, mode, &d1, 1.0);
  ContactForces out = f1;
  out.solvable = f0.solvable && f1.solvable && n_grazing == 1;  // two grazing contacts: not a mode of this model
  const int s = grazing;
  const double a0 = gap_acceleration(y, d0, s), a1 = gap_acceleration(y, d1, s);
  // a0 = a1 only where the slip (so the viscous force) vanishes: both fields agree there.
  const double raw = a0 != a1 ? a0 / (a0 - a1) : (a0 < 0 ? 1.0 : 0.0);
  const double f = std::clamp(raw, 0.0, 1.0);
  out.graze_lifted_accel[s] = a0;
  out.graze_loaded_accel[s] = a1;
  out.graze_fraction_raw[s] = raw;
  out.graze_fraction[s] = f;
  for (int k = 0; k < 2; ++k) {
    out.normal[k] = (1 - f) * f0.normal[k] + f * f1.normal[k];
    out.force_W[k] = (1 - f) * f0.force_W[k] + f * f1.force_W[k];
    out.drill_torque[k] = (1 - f) * f0.drill_torque[k] + f * f1.drill_torque[k];
  }
  out.normal[s] = 0.0;
  if (dydt)
    for (size_t i = 0; i < d0.size(); ++i) (*dydt)[i] = (1 - f) * d0[i] + f * d1[i];
  return out;
}

void ContactDynamics::slip_scale(const StateVector& y, const ContactMode& mode, StateVector& scale) const {
  scale.fill(std::numeric_limits<double>::infinity());
  if (c_.friction != FrictionLaw::Coulomb) return;
  for (int s = 0; s < 2; ++s) {
    const ContactSlot& slot = mode.slot[s];
    if (!slot.active || slot.stick || slot.slip_start || slot.graze) continue;
    // The slip the direction is taken from: the horizontal velocity at C, or the coupled
    // law's generalised slip (the same quantities as evaluate_fixed()).
    auto slip_of = [&](const StateVector& yy) {
      const BodyState x = unpack(yy, 0.0);
      if (coupled()) return coupled_slip(x, s);
      Vec3 v = contact_velocity(x, s);
      v.z() = 0.0;
      return v;
    };
    const double size = slip_of(y).norm();
    if (!(size > 0.0) || (coupled() && !(size > slot.coupled_floor))) continue;
    // ds/dy_j by central differences: s is linear in v and w and smooth in q on the scale of
    // a radian, so a step of cbrt(eps) of the component (or of 1) gives it to ~1e-10, far
    // more than a bound needs.
    const double cbrt_eps = std::cbrt(std::numeric_limits<double>::epsilon());
    for (size_t j = 0; j < y.size(); ++j) {
      StateVector yp = y, ym = y;
      yp[j] = y[j] + cbrt_eps * std::max(std::abs(y[j]), 1.0);
      const double h = yp[j] - y[j];
      ym[j] = y[j] - h;
      const double rate = (slip_of(yp) - slip_of(ym)).norm() / (2 * h);
      if (rate > 0.0) scale[j] = std::min(scale[j], size / rate);
    }
  }
}

Vec3 ContactDynamics::slip_rate(const StateVector& y, const StateVector& dy, int s) const {
  const BodyState x = unpack(y, 0);
  const Quat q = x.q_WB.normalized();
  const Vec3 w_W = q * x.w_B, wdot_W = q * Vec3(dy[10], dy[11], dy[12]);
  const ContactGeometry geo = geometry(x, s);
  // d/dt (v_G + w x r_GC), r_GC = r_GO - radius e_z with r_GO fixed in the body.
  const Vec3 a = Vec3(dy[3], dy[4], dy[5]) + wdot_W.cross(geo.r_GC_W) + w_W.cross(w_W.cross(geo.r_GO_W));
  if (coupled()) return Vec3(c_.mu * a.x(), c_.mu * a.y(), c_.drilling * wdot_W.z());
  return Vec3(a.x(), a.y(), 0.0);
}

ContactForces ContactDynamics::evaluate_slip_start(const StateVector& y, const ContactMode& mode, StateVector* dydt) const {
  // Newton on the unit sphere (the unit circle for the decoupled law) for G(n) = T (a(n) -
  // (a(n) . n) n) = 0, T a basis of the plane normal to n and a(n) the rate of the
  // generalised slip when the friction takes the direction n: the direction along which a small
  // slip grows or shrinks (a = lambda n; the root nearest the guess, the last direction: lambda
  // > 0 for a slip started from zero, < 0 for one dying out).
  // The Jacobian by differences of 1e-7 rad (right to ~1e-7, so each iteration gains seven
  // digits); iterations to an angle of 1e-14, so that the right-hand side is smooth in the
  // state to round-off (the step control sees no noise from the solve).
  ContactMode m = mode;
  const bool three = coupled();
  StateVector dy{};
  for (int sweep = 0; sweep < 2; ++sweep)
    for (int s = 0; s < 2; ++s) {
      ContactSlot& slot = m.slot[s];
      if (!slot.active || slot.stick || !slot.slip_start) continue;
      Vec3& dir = three ? slot.coupled_dir : slot.slip_dir_W;
      if (!three) dir.z() = 0.0;
      dir.normalize();
      auto rate = [&](const Vec3& n) {
        dir = n;
        StateVector d;
        evaluate_fixed(y, m, &d, 1.0);
        return slip_rate(y, d, s);
      };
      for (int iter = 0; iter < 30; ++iter) {
        const Vec3 n = dir;
        Vec3 t1 = three ? n.unitOrthogonal() : Vec3(-n.y(), n.x(), 0.0);
        Vec3 t2 = n.cross(t1);
        const int k = three ? 2 : 1;
        const Vec3 basis[2] = {t1, t2};
        auto G = [&](const Vec3& nn) {
          const Vec3 a = rate(nn);
          const Vec3 p = a - a.dot(nn) * nn;
          return Eigen::Vector2d(basis[0].dot(p), basis[1].dot(p));
        };
        const Eigen::Vector2d g0 = G(n);
        constexpr double h = 1e-7;
        Eigen::Matrix2d J = Eigen::Matrix2d::Identity();
        for (int j = 0; j < k; ++j) {
          const Eigen::Vector2d gj = G((n + h * basis[j]).normalized());
          J.col(j) = (gj - g0) / h;
        }
        Eigen::Vector2d delta = Eigen::Vector2d::Zero();
        if (k == 1) {
          delta(0) = J(0, 0) != 0.0 ? -g0(0) / J(0, 0) : 0.0;
        } else {
          delta = J.fullPivLu().solve(-g0);
        }
        // A step of at most 0.5 rad: Newton from a guess far from the root must not jump to
        // another root (e.g. the antipodal one, on which lambda has the other sign).
        const double len = delta.norm();
        if (!std::isfinite(len)) break;
        if (len > 0.5) delta *= 0.5 / len;
        dir = (n + delta(0) * basis[0] + delta(1) * basis[1]).normalized();
        if (len < 1e-14) break;
      }
    }
  ContactForces out = evaluate_fixed(y, m, &dy, 1.0);
  for (int s = 0; s < 2; ++s) {
    const ContactSlot& slot = m.slot[s];
    if (!slot.active || slot.stick || !slot.slip_start) continue;
    out.start_dir[s] = three ? slot.coupled_dir : slot.slip_dir_W;
    out.start_rate[s] = slip_rate(y, dy, s).dot(out.start_dir[s]);
  }
  if (dydt) *dydt = dy;
  return out;
}

ContactForces ContactDynamics::evaluate_fixed(const StateVector& y, const ContactMode& mode, StateVector* dydt,
                                              double share) const {
  const Kinematics k = kinematics(y, m_);
  const Vec3& w_W = k.w_W;
  const Eigen::Matrix3d& Iinv_W = k.Iinv_W;
  const Vec3 e_z = Vec3::UnitZ();

  ContactForces out;
  Vec3 F_known = gravity_force(m_), T_known = gyroscopic_torque(k);
  Column cols[kMaxUnknowns];
  Row rows[kMaxUnknowns];
  int n = 0;
  struct SlotIndex {
    int normal = -1, tangential = -1, drill = -1;
    bool graze = false;
    Vec3 normal_dir = Vec3::UnitZ();
    double drill_coeff = 0.0;
  } idx[2];

  for (int s = 0; s < 2; ++s) {
    const ContactSlot& slot = mode.slot[s];
    if (!slot.active) continue;
    const SlotKinematics sk = slot_kinematics(k, m_, s);
    const Vec3& r = sk.g.r_GC_W;
    const Vec3& slip = sk.slip_W;
    out.slip_W[s] = slip;
    const Vec3& centripetal = sk.centripetal_W;
    auto add_row = [&](const Vec3& dir) {
      rows[n - 1] = {dir, r.cross(dir), dir.dot(centripetal)};
    };
    // Normal force, carrying the sliding friction and drilling torque that scale with it.
    Vec3 fdir = e_z;
    double drill_coeff = 0.0;
    const bool coupled_sliding = coupled() && !slot.stick;
    if (coupled_sliding) {
      // Coupled Coulomb-Contensou law in the ellipsoidal approximation of Leine and Glocker
      // (2003, "A set-valued force law for spatial Coulomb-Contensou friction", Eur. J. Mech.
      // A/Solids 22, 193-216): the friction force F_t and the drilling torque tau of a contact
      // lie in the ellipse (|F_t| / (mu F_n))^2 + (tau / (mu_d F_n))^2 <= 1 (the exact
      // Contensou set of a circular patch of radius a is a convex set with semi-axes mu F_n
      // and 2/3 mu a F_n; the ellipse through those points replaces it). Sliding is the
      // principle of maximal dissipation on that set: with the generalised slip
      // u = (mu v, mu_d w_z) and S = |u|, the dissipation function (the ellipse's support
      // function) is F_n S, and (F_t, tau) = -grad_(v, w_z) (F_n S), i.e.
      //   F_t = -mu F_n (mu v) / S,   tau = -mu_d F_n (mu_d w_z) / S,
      // or, with e = mu_d / mu, F_t = -mu F_n v / sqrt(v^2 + (e w_z)^2) and
      // tau = -mu_d F_n e w_z / sqrt(v^2 + (e w_z)^2): on the ellipse, and the power
      // F_t . v + tau w_z = -F_n S <= 0. Unlike the decoupled law, a spinning contact has no
      // stick of its slip alone: at v = 0 with w_z != 0 the force vanishes and grows linearly
      // with v (slope mu F_n / (e |w_z|)), so the slip of a spinning top decays smoothly
      // instead of sticking. The law sticks only where u = 0, v and w_z together. The unit
      // vector u / S takes the side of the slot's reference direction, as the Coulomb slip
      // direction below, so that the dense output stays smooth through a zero of u.
      const Vec3 u(c_.mu * slip.x(), c_.mu * slip.y(), c_.drilling * w_W.z());  // coupled_slip()
      const double S = u.norm();
      Vec3 dir = S > slot.coupled_floor && !slot.slip_start ? Vec3(u / S) : slot.coupled_dir;
      if (dir.dot(slot.coupled_dir) < 0) dir = -dir;
      fdir -= c_.mu * Vec3(dir.x(), dir.y(), 0.0);
      drill_coeff = -c_.drilling * dir.z();
    }
    if (c_.friction == FrictionLaw::Coulomb && !slot.stick && !coupled_sliding) {
      // Beyond a zero of the slip (reached along a line) s/|s| flips; taking the side of the
      // slot's reference direction continues the sliding law smoothly through it, so the
      // integrator never steps over a kink and the "slip vanishes" event is located on a
      // smooth dense output. The reference is refreshed every step.
      const double speed = slip.norm();
      Vec3 dir = speed > 0.0 && !slot.slip_start ? Vec3(slip / speed) : slot.slip_dir_W;
      if (dir.dot(slot.slip_dir_W) < 0) dir = -dir;
      fdir -= c_.mu * dir;
    }
    if (c_.friction == FrictionLaw::Gliding) {
      // Rutstam's gliding law F_t = -mu F_n v_C (mu in s/m): unlike the viscous force it scales
      // with the unknown normal force, so it rides on the normal column (sliding Coulomb with
      // mu v_C in place of mu v_C/|v_C|) and enters the normal row's coupling through K. It is
      // smooth through zero slip (no slip events) and vanishes with F_n, so "held" and "lifted"
      // join continuously where F_n reaches 0: a contact lifts there, it never grazes.
      fdir -= c_.mu * slip;
    }
    if (slot.graze) {
      // Zero normal force and the given share of the viscous force; no constraint.
      idx[s].graze = true;
      F_known += -share * c_.k * slip;
      T_known += r.cross(-share * c_.k * slip);
      continue;
    }
    if (c_.friction == FrictionLaw::Viscous) {
      F_known += -c_.k * slip;
      T_known += r.cross(-c_.k * slip);
    }
    if (c_.drilling > 0.0 && !slot.drill_stick && !coupled_sliding) drill_coeff = sliding_drill_coeff(c_.drilling, slot, w_W);
    idx[s].normal = n;
    idx[s].normal_dir = fdir;
    idx[s].drill_coeff = drill_coeff;
    cols[n] = {fdir, r.cross(fdir) + drill_coeff * e_z};
    ++n;
    add_row(e_z);
    if (slot.stick) {
      idx[s].tangential = n;
      for (const Vec3& dir : {Vec3(Vec3::UnitX()), Vec3(Vec3::UnitY())}) {
        cols[n] = {dir, r.cross(dir)};
        ++n;
        add_row(dir);
      }
    }
    if (slot.drill_stick) {
      idx[s].drill = n;
      cols[n] = {Vec3::Zero(), e_z};
      ++n;
      rows[n - 1] = {Vec3::Zero(), e_z, 0.0};
    }
  }

  VecN u(n);
  if (n > 0) {
    MatN K(n, n);
    VecN b(n);
    const Vec3 a_free = F_known / m_.M;
    const Vec3 alpha_free = Iinv_W * T_known;
    // Angular acceleration per unit of each unknown, once per column rather than once per entry.
    Vec3 alpha_col[kMaxUnknowns];
    for (int j = 0; j < n; ++j) alpha_col[j] = Iinv_W * cols[j].tau;
    for (int i = 0; i < n; ++i) {
      b(i) = -(rows[i].f.dot(a_free) + rows[i].tau.dot(alpha_free) + rows[i].bias);
      for (int j = 0; j < n; ++j) K(i, j) = rows[i].f.dot(cols[j].f) / m_.M + rows[i].tau.dot(alpha_col[j]);
    }
    if (n == 1) {
      // One sliding or frictionless contact: the common case of a run, solved directly.
      out.solvable = K(0, 0) != 0.0;
      u(0) = b(0) / K(0, 0);
    } else if (n == 3) {
      // Three unknowns, mostly one sticking contact (rolling, Coulomb stick): the common case of
      // a rolling run. The closed-form inverse costs a fifth of the pivoting LU of the general
      // case (docs/findings/reference-integration-cost.md). Singular relative to the entries'
      // scale, not to Eigen's absolute 1e-12 on the determinant, which would misjudge a heavy
      // body in SI units.
      const Eigen::Matrix3d K3 = K.topLeftCorner<3, 3>();
      const double scale = K3.cwiseAbs().maxCoeff();
      Eigen::Matrix3d inv = Eigen::Matrix3d::Zero();
      bool invertible = false;
      K3.computeInverseWithCheck(inv, invertible, 1e-13 * scale * scale * scale);
      out.solvable = invertible;
      u = inv * Eigen::Vector3d(b.head<3>());
    } else {
      const auto lu = K.fullPivLu();
      out.solvable = lu.isInvertible();
      u = lu.solve(b);
    }
  }

  Vec3 F = F_known, T = T_known;
  for (int j = 0; j < n; ++j) {
    F += cols[j].f * u(j);
    T += cols[j].tau * u(j);
  }
  for (int s = 0; s < 2; ++s) {
    if (idx[s].graze) {
      out.graze_fraction[s] = share;
      out.force_W[s] = -share * c_.k * out.slip_W[s];
      continue;
    }
    if (idx[s].normal < 0) continue;
    const double fn = u(idx[s].normal);
    out.normal[s] = fn;
    Vec3 f = fn * idx[s].normal_dir;
    if (idx[s].tangential >= 0) f += u(idx[s].tangential) * Vec3::UnitX() + u(idx[s].tangential + 1) * Vec3::UnitY();
    if (c_.friction == FrictionLaw::Viscous) f += -c_.k * out.slip_W[s];
    out.force_W[s] = f;
    out.drill_torque[s] = idx[s].drill >= 0 ? u(idx[s].drill) : idx[s].drill_coeff * fn;
  }

  if (dydt) write_derivative(k, y, m_, F, T, *dydt);
  return out;
}

}  // namespace tippe
