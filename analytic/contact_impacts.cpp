// Impulses at the contacts: touchdown impacts with their friction laws, the normal projections, and stopping a contact.
#include "analytic/contact_dynamics.h"
#include "analytic/detail/contact_unknowns.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>

namespace tippe {

namespace {

using contact_detail::kMaxUnknowns;
using contact_detail::MatN;
using contact_detail::VecN;

}  // namespace

BodyState ContactDynamics::stop_contact(const BodyState& x, int slot, bool spin) const {
  const Quat q = x.q_WB.normalized();
  const Eigen::Matrix3d R_WB = q.toRotationMatrix();
  const Vec3 I_B(m_.A, m_.A, m_.C);
  const Eigen::Matrix3d Iinv_W = R_WB * I_B.cwiseInverse().asDiagonal() * R_WB.transpose();
  const Vec3 w_W = q * x.w_B;
  const Vec3 r = geometry(x, slot).r_GC_W;
  const Vec3 v_C = x.v_WG + w_W.cross(r);
  const int n = spin ? 4 : 3;
  // Unknowns: the impulse at C (x, y, z) and the angular impulse about e_z; rows: the velocity
  // of C and w_z. K = J M^-1 J^T, symmetric positive definite.
  Vec3 f[4], tau[4];
  for (int j = 0; j < 3; ++j) {
    f[j] = Vec3::Unit(j);
    tau[j] = r.cross(f[j]);
  }
  f[3] = Vec3::Zero();
  tau[3] = Vec3::UnitZ();
  Eigen::Matrix4d K = Eigen::Matrix4d::Identity();
  Eigen::Vector4d b(-v_C.x(), -v_C.y(), -v_C.z(), -w_W.z());
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) K(i, j) = f[i].dot(f[j]) / m_.M + tau[i].dot(Iinv_W * tau[j]);
  const Eigen::VectorXd u = K.topLeftCorner(n, n).ldlt().solve(b.head(n));
  Vec3 P = Vec3::Zero(), L = Vec3::Zero();
  for (int j = 0; j < n; ++j) {
    P += f[j] * u(j);
    L += tau[j] * u(j);
  }
  BodyState post = x;
  post.v_WG = x.v_WG + P / m_.M;
  post.w_B = q.conjugate() * Vec3(w_W + Iinv_W * L);
  return post;
}

BodyState ContactDynamics::impact(const BodyState& x, std::array<bool, 2> touching, std::array<bool, 2>* kept,
                                  std::array<double, 2>* normal_impulse, Impulses kind) const {
  const bool both_normal_only = kind == Impulses::Bilateral;
  const bool normal_only = kind != Impulses::Impact;
  const Quat q = x.q_WB.normalized();
  const Eigen::Matrix3d R_WB = q.toRotationMatrix();
  const Vec3 I_B(m_.A, m_.A, m_.C);
  const Eigen::Matrix3d Iinv_W = R_WB * I_B.cwiseInverse().asDiagonal() * R_WB.transpose();
  const Vec3 w_W = q * x.w_B;
  const Vec3 e_z = Vec3::UnitZ();
  ContactGeometry g[2] = {geometry(x, 0), geometry(x, 1)};
  Vec3 v_pre[2];
  for (int s = 0; s < 2; ++s) v_pre[s] = x.v_WG + w_W.cross(g[s].r_GC_W);

  // Tangential impulses: rolling stops the whole contact velocity; Coulomb tries that and,
  // outside the cone, slides along the pre-impact slip; viscous and none have no impulsive
  // friction (a finite force transmits no impulse). Gliding friction is left out of impacts
  // too (normal impulse only): strictly its force -mu F_n v_C follows an impulsive F_n with
  // the impulse -mu integral(v_C dP_n), a simplification of this model that matters only where
  // a gliding top touches down (the bare ball never does). The decoupled drilling torque
  // transmits no impulse here: a simplification kept from before (its own bound mu_d P_n would
  // slow the spin about the vertical at an impact), so that the decoupled law's impacts are
  // unchanged.
  // Under the coupled law the impulsive friction is bounded jointly, as the smooth law's
  // force and torque are (Leine and Glocker 2003, the same ellipse in impulses):
  // (|P_t| / (mu P_n))^2 + (P_tau / (mu_d P_n))^2 <= 1, P_tau the angular impulse about the
  // vertical at the contact. A sticking contact stops its slip and the spin about the
  // vertical; outside the ellipse it slides along the pre-impact generalised slip
  // u = (mu v, mu_d w_z): (P_t, P_tau) = -P_n (mu^2 v, mu_d^2 w_z) / |u|, the smooth law's
  // direction (maximal dissipation on the ellipse).
  const bool full_stop = !normal_only && (c_.friction == FrictionLaw::Rolling || c_.friction == FrictionLaw::Coulomb);
  const bool drill = full_stop && coupled();

  // Generalised impulses and velocity measures: a column is an impulse (f at contact `at`
  // plus a pure torque tau), a row measures a . v_G + b . w_W (+ bias, the pre-impact value).
  struct GCol {
    Vec3 f, tau;
    int at;
  };
  struct GRow {
    Vec3 a, b;
    double bias;
  };
  auto contact_row = [&](int s, const Vec3& dir) { return GRow{dir, g[s].r_GC_W.cross(dir), v_pre[s].dot(dir)}; };

  struct Solution {
    bool ok = false;
    Vec3 P[2] = {Vec3::Zero(), Vec3::Zero()};  // force impulse per contact
    double tau[2] = {0.0, 0.0};                // angular impulse about the vertical per contact
  };
  auto solve = [&](std::array<bool, 2> in_set, std::array<bool, 2> sliding) {
    Solution sol;
    GCol cols[7];
    GRow rows[7];
    int n = 0;
    bool drill_row = false;  // one row holds w_z: the spin about the vertical is the body's own
    for (int s = 0; s < 2; ++s) {
      if (!in_set[s]) continue;
      GCol normal{e_z, Vec3::Zero(), s};
      if (sliding[s] && drill) {
        const Vec3 u(c_.mu * v_pre[s].x(), c_.mu * v_pre[s].y(), c_.drilling * w_W.z());  // coupled_slip()
        const double S = u.norm();
        if (S > 0) {
          normal.f -= c_.mu * Vec3(u.x(), u.y(), 0.0) / S;
          normal.tau = -c_.drilling * u.z() / S * e_z;
        }
      } else if (sliding[s]) {
        Vec3 t = v_pre[s];
        t.z() = 0;
        if (t.norm() > 0) normal.f -= c_.mu * t.normalized();
      }
      cols[n] = normal;
      rows[n++] = contact_row(s, e_z);
      if (full_stop && !sliding[s]) {
        for (const Vec3& dir : {Vec3(Vec3::UnitX()), Vec3(Vec3::UnitY())}) {
          cols[n] = {dir, Vec3::Zero(), s};
          rows[n++] = contact_row(s, dir);
        }
        if (drill && !drill_row) {
          cols[n] = {Vec3::Zero(), e_z, s};
          rows[n++] = {Vec3::Zero(), e_z, w_W.z()};
          drill_row = true;
        }
      }
    }
    MatN K(n, n);
    VecN b(n);
    Vec3 dw[7];
    for (int j = 0; j < n; ++j) dw[j] = Iinv_W * (g[cols[j].at].r_GC_W.cross(cols[j].f) + cols[j].tau);
    for (int i = 0; i < n; ++i) {
      b(i) = -rows[i].bias;
      for (int j = 0; j < n; ++j) K(i, j) = rows[i].a.dot(cols[j].f) / m_.M + rows[i].b.dot(dw[j]);
    }
    const auto lu = K.fullPivLu();
    if (!lu.isInvertible()) return sol;
    const VecN u = lu.solve(b);
    for (int j = 0; j < n; ++j) {
      sol.P[cols[j].at] += cols[j].f * u(j);
      sol.tau[cols[j].at] += cols[j].tau.z() * u(j);
    }
    sol.ok = true;
    if (both_normal_only) return sol;
    for (int s = 0; s < 2; ++s) {
      if (!in_set[s]) continue;
      if (sol.P[s].z() < 0) sol.ok = false;
    }
    // Contacts left out of the set must not approach the floor afterwards.
    for (int s = 0; s < 2; ++s) {
      if (!touching[s] || in_set[s]) continue;
      Vec3 dv = Vec3::Zero(), dL = Vec3::Zero();
      for (int j = 0; j < 2; ++j) {
        dv += sol.P[j];
        dL += g[j].r_GC_W.cross(sol.P[j]) + sol.tau[j] * e_z;
      }
      const Vec3 v = v_pre[s] + dv / m_.M + (Iinv_W * dL).cross(g[s].r_GC_W);
      if (v.z() < -1e-12 * std::max(1.0, v_pre[s].norm())) sol.ok = false;
    }
    return sol;
  };
  // Coupled law: the drilling impulse of a sticking solution belongs to the contacts that
  // stick, shared in proportion to their normal impulses where both do (each one's bound
  // scales with its own P_n); the share is what each contact's ellipse is checked with.
  auto outside = [&](const Solution& sol, std::array<bool, 2> in_set, std::array<bool, 2> sliding, int s) {
    const double pn = sol.P[s].z(), pt = std::hypot(sol.P[s].x(), sol.P[s].y());
    if (!drill) return pt > c_.mu * pn;
    double tau = 0.0, pn_stuck = 0.0;
    for (int k = 0; k < 2; ++k)
      if (in_set[k] && !sliding[k]) {
        tau += sol.tau[k];
        pn_stuck += sol.P[k].z();
      }
    const double share = pn_stuck > 0 ? tau * pn / pn_stuck : tau;
    return std::hypot(pt / c_.mu, share / c_.drilling) > pn;
  };

  const std::array<std::array<bool, 2>, 3> sets = {{{true, false}, {false, true}, {true, true}}};
  Solution best;
  if (kind == Impulses::Unilateral) {
    // Nothing approaching: no impulse (the empty set solves the complementarity problem).
    bool approaching = false;
    for (int s = 0; s < 2; ++s) approaching = approaching || (touching[s] && v_pre[s].z() < 0);
    if (!approaching) {
      if (kept) *kept = {false, false};
      if (normal_impulse) *normal_impulse = {0.0, 0.0};
      return x;
    }
  }
  for (const auto& set : sets) {
    if (both_normal_only && set != touching) continue;
    if ((set[0] && !touching[0]) || (set[1] && !touching[1])) continue;
    std::array<bool, 2> sliding{false, false};
    Solution sol = solve(set, sliding);
    if (c_.friction == FrictionLaw::Coulomb && !normal_only) {
      // Only a touchdown has impulsive friction: the projections are normal impulses alone. (The
      // cone test used to run for them too, where a pulling normal impulse of the bilateral
      // projection fails it at once (0 > mu P_n, P_n < 0) and the contact slid with the
      // friction impulse -mu P_n t, which then pushed along the slip: a hold that added energy.)
      // Stick where the stuck impulses lie in the cone (the ellipse), slide where they leave
      // it; where sticking has no solution (a pulling normal impulse, or both contacts stuck,
      // which over-constrains the body) every contact of the set slides. Measured on 3000
      // random touchdowns of the Leine-Glocker top: without the last rule 648 found no
      // impulse at all (the touchdown left the approach to the drift correction).
      bool redo = false;
      if (sol.ok) {
        for (int s = 0; s < 2; ++s)
          if (set[s] && outside(sol, set, sliding, s)) sliding[s] = redo = true;
      } else {
        sliding = set;
        redo = true;
      }
      if (redo) sol = solve(set, sliding);
      if (!sol.ok && sliding != set) sol = solve(set, set);
    }
    if (sol.ok) {
      best = sol;
      break;
    }
  }
  BodyState post = x;
  if (!best.ok) {
    if (kept) *kept = {false, false};
    return post;
  }
  Vec3 dv = Vec3::Zero(), dL = Vec3::Zero();
  for (int s = 0; s < 2; ++s) {
    dv += best.P[s];
    dL += g[s].r_GC_W.cross(best.P[s]) + best.tau[s] * e_z;
    if (normal_impulse) (*normal_impulse)[s] = best.P[s].z();
  }
  post.v_WG = x.v_WG + dv / m_.M;
  const Vec3 w_post_W = w_W + Iinv_W * dL;
  post.w_B = q.conjugate() * w_post_W;
  if (kept) {
    for (int s = 0; s < 2; ++s) {
      const Vec3 v = post.v_WG + w_post_W.cross(g[s].r_GC_W);
      (*kept)[s] = touching[s] && std::abs(v.z()) <= 1e-9 * std::max(1.0, v_pre[s].norm());
    }
  }
  return post;
}

}  // namespace tippe
