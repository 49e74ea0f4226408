// The reference's contact modes: which contacts hold and stick (settle), the projection onto them at restarts, and the run's end.
#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

#include "analytic/detail/reference_impl.h"

namespace tippe {

using namespace reference_detail;

// Coupled law: the direction of the generalised slip in which a contact whose sticking
// forces (F_t, tau) have left the ellipse starts to slide: the slip that makes the sliding
// law's force point as the sticking one does, u ~ -(F_t / mu, tau / mu_d) (the normal of
// the ellipse at (F_t, tau) scaled back to its boundary).
Vec3 ReferenceModel::Impl::coupled_slide_dir(const ContactForces& f, int s) const {
  const ContactSpec& c = dyn.contact();
  const Vec3 u(-f.force_W[s].x() / c.mu, -f.force_W[s].y() / c.mu, -f.drill_torque[s] / c.drilling);
  return u.norm() > 0 ? Vec3(u.normalized()) : ref_coupled[s];
}

ContactMode ReferenceModel::Impl::settle(const StateVector& y, std::array<bool, 2> candidates, const ContactMode& prev) {
  const ContactSpec& c = dyn.contact();
  ContactMode m;
  const BodyState x = unpack(y, 0);
  for (int s = 0; s < 2; ++s) {
    ContactSlot& slot = m.slot[s];
    slot.active = candidates[s];
    slot.slip_dir_W = prev.slot[s].slip_dir_W;
    slot.drill_stick = prev.slot[s].active && prev.slot[s].drill_stick;
    slot.drill_dir = prev.slot[s].drill_dir;
    slot.graze = false;
    slot.coupled_dir = prev.slot[s].coupled_dir;
    slot.coupled_floor = coupled_floor;
    if (c.friction == FrictionLaw::Rolling) slot.stick = true;
    if (c.friction == FrictionLaw::Coulomb && dyn.coupled()) {
      const Vec3 u = dyn.coupled_slip(x, s);
      slot.stick = slot.drill_stick = coupled_speed(u) <= slip_eps;
      if (!slot.stick) slot.coupled_dir = u.normalized();
    } else if (c.friction == FrictionLaw::Coulomb) {
      Vec3 v = dyn.contact_velocity(x, s);
      v.z() = 0;
      slot.stick = v.norm() <= slip_eps;
      if (!slot.stick) slot.slip_dir_W = v.normalized();
    }
  }
  for (int iter = 0; iter < 6; ++iter) {
    const ContactForces f = forces_at(y, m);
    int worst = -1;
    for (int s = 0; s < 2; ++s)
      if (m.slot[s].active && f.normal[s] < 0 && (worst < 0 || f.normal[s] < f.normal[worst])) worst = s;
    if (worst >= 0) {
      m.slot[worst].active = false;
      if (m.any_active() && c.friction == FrictionLaw::Viscous && gap_acceleration(y, m, worst) < 0) {
        // Neither held nor lifted is consistent (see the NormalForce event): graze.
        m.slot[worst].active = m.slot[worst].graze = true;
      }
      continue;
    }
    bool changed = false;
    for (int s = 0; s < 2; ++s) {
      ContactSlot& slot = m.slot[s];
      if (!slot.active) continue;
      if (dyn.coupled()) {
        if (slot.stick && dyn.coupled_demand(f, s) > f.normal[s]) {
          slot.stick = slot.drill_stick = false;
          slot.coupled_dir = coupled_slide_dir(f, s);
          zero_slip[s] = true;  // it starts to slide from (near) zero slip, see handle()
          slot.slip_start = true;
          changed = true;
        }
        continue;
      }
      if (c.friction == FrictionLaw::Coulomb && slot.stick) {
        const Vec3 ft(f.force_W[s].x(), f.force_W[s].y(), 0.0);
        if (ft.norm() > c.mu * f.normal[s]) {
          slot.stick = false;
          slot.slip_dir_W = -ft.normalized();
          zero_slip[s] = true;  // as under the coupled law
          slot.slip_start = true;
          changed = true;
        }
      }
      if (slot.drill_stick && std::abs(f.drill_torque[s]) > c.drilling * f.normal[s]) {
        slot.drill_stick = false;
        m.slot[0].drill_dir = m.slot[1].drill_dir = f.drill_torque[s] > 0 ? -1.0 : 1.0;  // the spin starts against the torque
        zero_drill[s] = true;
        changed = true;
      }
    }
    if (!changed) break;
  }
  return m;
}

// Puts the held contacts exactly on the floor, and removes the normal velocity of a single
// held contact or the approaching normal velocities of two (integration drift of the order
// of the tolerance, at each restart).
// `positioned` (may be null): the state after the position part (and the attitude's
// rotation, which keeps the lab-frame angular velocity), before the velocity part.
StateVector ReferenceModel::Impl::project(const StateVector& y, StateVector* positioned) {
  BodyState x = unpack(y, 0);
  x.q_WB.normalize();
  const int s = mode.slot[0].active ? 0 : (mode.slot[1].active ? 1 : -1);
  if (mode.slot[0].active && mode.slot[1].active) {
    // Both held: the tilt is fixed at the switching tilt. Rotate about the horizontal axis
    // normal to e_Z to put it there exactly (removes the drift of the second contact).
    const BodyModel& b = dyn.body();
    const Vec3 e_Z = x.q_WB * Vec3::UnitZ();
    const Vec3 axis = Vec3::UnitZ().cross(e_Z);
    if (axis.norm() > 0) {
      const double delta = std::acos(std::clamp(b.switch_cos, -1.0, 1.0)) - std::acos(std::clamp(e_Z.z(), -1.0, 1.0));
      const Vec3 w_W = x.q_WB * x.w_B;
      x.q_WB = (Quat(Eigen::AngleAxisd(delta, axis.normalized())) * x.q_WB).normalized();
      x.w_B = x.q_WB.conjugate() * w_W;
    }
  }
  const bool both = mode.slot[0].active && mode.slot[1].active;
  for (int k = 0; k < 2; ++k)
      if (mode.slot[k].active && ((both && dyn.coupled() && (mode.slot[k].stick || zero_slip[k])) || zero_drill[k])) {
        // The coupled law sticks as a whole: the spin about the vertical is held at zero too
        // (on one contact by stop_contact below); a decoupled drilling slip starts from zero spin.
        Vec3 w_W = x.q_WB * x.w_B;
        w_W.z() = 0.0;
        x.w_B = x.q_WB.conjugate() * w_W;
      }
  if (s >= 0) {
    const ContactGeometry geo = dyn.geometry(x, s);
    const Vec3 w_W = x.q_WB * x.w_B;
    x.p_WG.z() = -geo.r_GC_W.z();
    if (positioned) *positioned = pack(x);
    if (mode.slot[0].active && mode.slot[1].active) {
      // Two contacts held: the drift of their normal velocities is removed where it
      // approaches the floor, by normal impulses >= 0 (the floor cannot pull); a separating
      // drift (tolerance-sized) is left to the constraint, which holds its rate.
      std::array<double, 2> unused{0, 0};
      const BodyState held = dyn.impact(x, {true, true}, nullptr, &unused, ContactDynamics::Impulses::Unilateral);
      x.v_WG = held.v_WG;
      x.w_B = held.w_B;
    } else {
      x.v_WG.z() = -w_W.cross(geo.r_GO_W).z();
      if (mode.slot[s].stick || zero_slip[s]) {
        // By the impulse at the contact that stops it with the least change of kinetic energy
        // (never a gain): the slip left is the drift of a stuck integration, or what a small
        // slip's solved direction left across it where it vanished (ContactSlot::slip_start).
        const BodyState stopped = dyn.stop_contact(x, s, dyn.coupled());
        x.v_WG = stopped.v_WG;
        x.w_B = stopped.w_B;
      }
    }
  } else if (positioned) {
    *positioned = pack(x);
  }
  for (int k = 0; k < 2; ++k) {
    fresh_slip[k] = fresh_slip[k] || zero_slip[k];
    fresh_drill[k] = fresh_drill[k] || zero_drill[k];
  }
  zero_slip = zero_drill = {false, false};
  return pack(x);
}

// project() with its energy change booked: an event for the two-contact projection, the
// ledger's drift term for the one-contact correction (tolerance-sized, every restart).
StateVector ReferenceModel::Impl::project_booked(const StateVector& y, double t) {
  const BodyModel& b = dyn.body();
  StateVector positioned;
  const StateVector p = project(y, &positioned);
  const double e_y = energy(b, unpack(y, t)), e_pos = energy(b, unpack(positioned, t)), e_p = energy(b, unpack(p, t));
  ledger.drift += e_y - e_pos;  // positions and attitude: tolerance-sized, either sign
  if (mode.slot[0].active && mode.slot[1].active) {
    // The velocity part, impulses >= 0 only: it can only remove energy. One event per
    // two-contact restart, zero or not, so that runs with the same restarts have the same
    // events.
    ledger.projections += e_pos - e_p;
    owner.events_.push_back({"projection", t, "two-contact drift removed", e_pos - e_p});
  } else {
    ledger.drift += e_pos - e_p;
  }
  return p;
}

void ReferenceModel::Impl::set_mode(const ContactMode& m, double t) {
  const Surface before = surface_of(mode), after = surface_of(m);
  mode = m;
  if (before != after) {
    owner.events_.push_back({"switch", t, std::string(to_string(before)) + " -> " + to_string(after),
                             static_cast<double>(static_cast<int>(after))});
    if (after == Surface::Both) owner.events_.push_back({"two_contact", t, "ball and stem held together", 0.0});
  }
}

void ReferenceModel::Impl::end(ReferenceStatus status, double t, const std::string& why, const StateVector& y) {
  owner.status_ = status;
  owner.status_time_ = t;
  owner.status_detail_ = why;
  owner.events_.push_back({status == ReferenceStatus::ContactLost ? "contact_lost" : "failed", t, why, 0.0});
  owner.t_obs_ = t;
  y_obs = y;
  ledger_obs = ledger;
  ledger_obs_valid = true;
}

}  // namespace tippe
