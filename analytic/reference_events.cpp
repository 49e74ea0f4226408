// The reference's events: which functions a contact mode watches, their values, and what happens when one crosses zero.
#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

#include "analytic/detail/reference_impl.h"

namespace tippe {

using namespace reference_detail;

void ReferenceModel::Impl::build_event_functions() {
  const BodyModel& b = dyn.body();
  const ContactSpec& c = dyn.contact();
  fns = {{EvKind::Inversion, 0}, {EvKind::Reversion, 0}};
  for (int s = 0; s < 2; ++s) {
    if (s == 1 && !b.stem) continue;
    const ContactSlot& slot = mode.slot[s];
    if (slot.active && slot.graze) {
      fns.push_back({EvKind::GrazeLift, s});
      fns.push_back({EvKind::GrazePress, s});
      fns.push_back({EvKind::GrazePinch, s});
    } else if (slot.active) {
      fns.push_back({EvKind::NormalForce, s});
      // Under the coupled law, SlipReversal and ConeExit watch the generalised slip and the
      // ellipse (the law sticks and slips as a whole); there are no drilling events of its own.
      if (c.friction == FrictionLaw::Coulomb && !slot.stick && slot.slip_start) {
        // A small slip (ContactSlot::slip_start), started from zero or fallen below half of
        // slip_start_v: until it grows to slip_start_v or vanishes.
        fns.push_back({EvKind::SlipStartEnd, s});
        fns.push_back({EvKind::SlipZero, s});
      } else if (c.friction == FrictionLaw::Coulomb) {
        fns.push_back({slot.stick ? EvKind::ConeExit : EvKind::SlipReversal, s});
        if (!slot.stick) fns.push_back({EvKind::SlipSmall, s});
      }
      if (c.drilling > 0 && !dyn.coupled())
        fns.push_back({slot.drill_stick ? EvKind::DrillConeExit : EvKind::DrillReversal, s});
    } else {
      fns.push_back({EvKind::Touchdown, s});
    }
  }
}

void ReferenceModel::Impl::refresh_references(const StateVector& y) {
  const ContactForces f = forces_at(y, mode);
  for (int s = 0; s < 2; ++s) {
    if (mode.slot[s].slip_start && !dyn.coupled()) {
      mode.slot[s].slip_dir_W = ref_dir[s] = f.start_dir[s];  // the solved direction is the next guess
      continue;
    }
    const double speed = f.slip_W[s].norm();
    ref_dir[s] = speed > 0 ? Vec3(f.slip_W[s] / speed) : mode.slot[s].slip_dir_W;
    if (ref_dir[s].dot(mode.slot[s].slip_dir_W) < 0) ref_dir[s] = -ref_dir[s];
    mode.slot[s].slip_dir_W = ref_dir[s];
  }
  const double wz = (unpack(y, 0).q_WB.normalized() * unpack(y, 0).w_B).z();
  // The decoupled drilling torque's sign is continued through a zero of w_z (ContactSlot::
  // drill_dir); exactly 0 is a spin zeroed at a drilling slip start, which keeps its sign.
  const double kept = mode.slot[0].drill_dir != 0.0 ? mode.slot[0].drill_dir : 1.0;
  drill_ref_sign = wz > 0 ? 1.0 : (wz < 0 ? -1.0 : kept);
  for (int s = 0; s < 2; ++s) mode.slot[s].drill_dir = drill_ref_sign;
  if (dyn.coupled())
    for (int s = 0; s < 2; ++s) {
      if (mode.slot[s].slip_start) {
        mode.slot[s].coupled_dir = ref_coupled[s] = f.start_dir[s];
        continue;
      }
      const Vec3 u = coupled_slip(f, wz, s);
      const double S = u.norm();
      Vec3 dir = S > mode.slot[s].coupled_floor ? Vec3(u / S) : mode.slot[s].coupled_dir;
      if (dir.dot(mode.slot[s].coupled_dir) < 0) dir = -dir;
      mode.slot[s].coupled_dir = ref_coupled[s] = dir;
    }
}

// The coupled law's generalised slip (mu v_x, mu v_y, mu_d w_z) from the slip the forces
// report (ContactDynamics::coupled_slip, without normalizing the state again).
Vec3 ReferenceModel::Impl::coupled_slip(const ContactForces& f, double w_z, int s) const {
  const ContactSpec& c = dyn.contact();
  return Vec3(c.mu * f.slip_W[s].x(), c.mu * f.slip_W[s].y(), c.drilling * w_z);
}

double ReferenceModel::Impl::g(const EvFn& fn, const StateVector& y, const ContactForces* f) {
  const BodyState x = unpack(y, 0.0);
  const Quat q = x.q_WB.normalized();
  const ContactSpec& c = dyn.contact();
  switch (fn.kind) {
    case EvKind::Inversion: return (q * Vec3::UnitZ()).z();
    case EvKind::Reversion: return -(q * Vec3::UnitZ()).z();
    case EvKind::Touchdown: {
      // A released contact starts at gap ~0 (within the drift of the held contacts); the
      // allowance of 1e-10 R lets a return to the floor right after a release still change
      // sign. It shifts touchdown times by 1e-10 R / v_n, far below the 1e-9 asked for.
      const ContactGeometry geo = dyn.geometry(x, fn.slot);
      return x.p_WG.z() + geo.r_GC_W.z() + 1e-10 * dyn.body().R;
    }
    case EvKind::DrillReversal: return drill_ref_sign * (q * x.w_B).z();
    default: break;
  }
  const ContactForces& cf = *f;
  const int s = fn.slot;
  switch (fn.kind) {
    case EvKind::NormalForce: return cf.normal[s];
    // A grazing contact is consistent while neither neighbouring field is: lifted would
    // drive it into the floor (a0 < 0) and loaded would pull it off (a1 > 0, i.e. held
    // with full friction it would need F_n < 0); then the fraction a0 / (a0 - a1) lies in
    // [0, 1]. These functions stay continuous where the fraction is 0 / 0 (see GrazePinch;
    // the fraction's own bounds bracketed its pole there as a false root). The offsets
    // put the switching state strictly on the side where the next mode is consistent, so
    // that its own events start positive; they shift a switch by 1e-12 g / |da/dt|.
    case EvKind::GrazeLift: return -cf.graze_lifted_accel[s] + 1e-12 * dyn.body().g;
    case EvKind::GrazePress: return cf.graze_loaded_accel[s] + 1e-12 * dyn.body().g;
    // Inside the graze a0 = -f (a1 - a0), f in [0, 1]: where the viscous force loses its
    // leverage on the gap (a1 - a0 -> 0, the singular point of the graze's own system)
    // a0 and a1 reach 0 together, and beyond it lifted and held are both consistent. The
    // fraction amplifies the error of the accelerations (~rtol g) by g / (a1 - a0), so the
    // graze is ended while it is still resolved, at a leverage of 1e-5 g (fraction right to
    // ~1e-5; at 1e-7 g bulirsch_stoer's energy was off by 1.4e-9 E0 there). On
    // source_dimensionless a0 is then ~-3e-6 g and crosses 0 ~5e-5 time units later: the
    // lift it makes early moves the gap by ~1e-15 R, far below any resolution.
    case EvKind::GrazePinch: return cf.graze_loaded_accel[s] - cf.graze_lifted_accel[s] - 1e-5 * dyn.body().g;
    case EvKind::SlipReversal:
      if (dyn.coupled()) return coupled_slip(cf, (q * x.w_B).z(), s).dot(ref_coupled[s]);
      return cf.slip_W[s].dot(ref_dir[s]);
    case EvKind::ConeExit:
      if (dyn.coupled()) return cf.normal[s] - dyn.coupled_demand(cf, s);
      return c.mu * cf.normal[s] - std::hypot(cf.force_W[s].x(), cf.force_W[s].y());
    case EvKind::DrillConeExit: return c.drilling * cf.normal[s] - std::abs(cf.drill_torque[s]);
    case EvKind::SlipStartEnd:
      if (dyn.coupled()) return slip_start_v - coupled_speed(coupled_slip(cf, (q * x.w_B).z(), s));
      return slip_start_v - cf.slip_W[s].norm();
    case EvKind::SlipZero:
      if (dyn.coupled()) return coupled_slip(cf, (q * x.w_B).z(), s).dot(cf.start_dir[s]);
      return cf.slip_W[s].dot(cf.start_dir[s]);
    case EvKind::SlipSmall:
      if (dyn.coupled()) return coupled_speed(coupled_slip(cf, (q * x.w_B).z(), s)) - 0.5 * slip_start_v;
      return cf.slip_W[s].norm() - 0.5 * slip_start_v;
    default: return 0.0;
  }
}

void ReferenceModel::Impl::handle(const EvFn& fn, double te) {
  StateVector y = state_at(te);
  const BodyState x = unpack(y, te);
  const ContactSpec& c = dyn.contact();
  const int s = fn.slot;
  const BodyModel& b = dyn.body();
  // Guard against an endless sequence of events in a vanishing time (e.g. chattering).
  if (burst_start < 0 || te - burst_start > 1e-9 * std::max(1.0, run.duration)) {
    burst_start = te;
    events_in_burst = 0;
  }
  if (++events_in_burst > 1000) return end(ReferenceStatus::Failed, te, "event accumulation: more than 1000 events within 1e-9 of the run", y);
  ContactMode next = mode;
  double first_dt = 0.0;
  switch (fn.kind) {
    case EvKind::NormalForce: {
      next.slot[s].active = false;
      if (next.any_active() && c.friction == FrictionLaw::Viscous && gap_acceleration(y, next, s) < 0) {
        // F_n of one of two held contacts reaches zero, but without it the other contact
        // drives it straight back into the floor: with the viscous law the friction of a
        // contact does not vanish with its normal force, so "held" and "lifted" do not
        // join continuously. Filippov's continuation keeps the contact on the floor with
        // zero normal force and the share of its viscous force that holds it there.
        next = mode;
        next.slot[s].graze = true;
        owner.events_.push_back({"graze", te, std::string("F_n of the ") + slot_name(s) + " reaches 0; it touches without load", 0.0});
        break;
      }
      const double tilt_deg = tilt(x.q_WB.normalized()) * 180.0 / M_PI;
      if (!next.any_active()) {
        if (!flight_allowed)
          return end(ReferenceStatus::ContactLost, te,
                     std::string("F_n reaches 0 on the ") + slot_name(s) + " at tilt " + fmt(tilt_deg) + " deg", y);
        owner.events_.push_back({"flight", te, std::string("leaves the floor from the ") + slot_name(s), tilt_deg});
      }
      std::array<bool, 2> cand{next.slot[0].active, next.slot[1].active};
      next = settle(y, cand, next);
      break;
    }
    case EvKind::SlipReversal: {
      if (dyn.coupled()) {
        // The generalised slip (v, w_z) passes through (or near) zero: stick as a whole if
        // the sticking forces lie in the ellipse, else slide on in the direction they give.
        const Vec3 u = dyn.coupled_slip(x, s);
        if (coupled_speed(u) > slip_eps) {
          // Not a zero: the slip turned by more than 90 deg from the reference within a step
          // (fast near a slip start, where the slip is small). The continuation's flip must
          // not outlive the event (it would make the force drive the slip): the reference
          // becomes the slip's own direction.
          next.slot[s].coupled_dir = u.normalized();
        } else {
          ContactMode trial = next;
          trial.slot[s].stick = trial.slot[s].drill_stick = true;
          const ContactForces f = forces_at(y, trial);
          const double demand = dyn.coupled_demand(f, s);
          if (demand <= f.normal[s]) {
            next = trial;
            owner.events_.push_back({"stick", te, std::string("slip and spin about the vertical vanish on the ") + slot_name(s) +
                                                      " (coupled law)", demand / f.normal[s]});
          } else if (u.norm() > coupled_floor) {
            // A slip that has begun to grow against the reference (just after a slip start,
            // where its direction is set by the fast, stiff turning of a small slip): the
            // force follows the slip's own direction from here.
            next.slot[s].coupled_dir = u.normalized();
          } else {
            next.slot[s].coupled_dir = coupled_slide_dir(f, s);
            zero_slip[s] = true;
            next.slot[s].slip_start = true;
          }
        }
        break;
      }
      Vec3 v = dyn.contact_velocity(x, s);
      v.z() = 0;
      if (v.norm() > slip_eps) {
        // Not a zero: the slip turned by more than 90 deg from the reference within a step
        // (as under the coupled law above); the force follows the slip's own direction.
        next.slot[s].slip_dir_W = v.normalized();
      } else {
        ContactMode trial = next;
        trial.slot[s].stick = true;
        const ContactForces f = forces_at(y, trial);
        const Vec3 ft(f.force_W[s].x(), f.force_W[s].y(), 0.0);
        if (ft.norm() <= c.mu * f.normal[s]) {
          next = trial;
          owner.events_.push_back({"stick", te, std::string("slip vanishes on the ") + slot_name(s), ft.norm() / f.normal[s]});
        } else if (v.norm() > 1e-3 * slip_eps) {
          // A slip that has begun to grow against the reference (just after a slip start):
          // the force follows the slip's own direction from here. 1e-3 slip_eps: the
          // coupled law's floor (coupled_floor), far above a zeroed slip's round-off.
          next.slot[s].slip_dir_W = v.normalized();
        } else {
          next.slot[s].slip_dir_W = -ft.normalized();
          zero_slip[s] = true;
          next.slot[s].slip_start = true;
        }
      }
      break;
    }
    case EvKind::SlipStartEnd: {
      // The slip has grown to slip_start_v along the solved direction: the law takes the
      // slip's own direction from here (no event: the motion does not change).
      const ContactForces f = forces_at(y, mode);
      next.slot[s].slip_start = false;
      if (dyn.coupled()) {
        const Vec3 u = coupled_slip(f, (x.q_WB.normalized() * x.w_B).z(), s);
        if (u.norm() > 0) next.slot[s].coupled_dir = u.normalized();
      } else if (f.slip_W[s].norm() > 0) {
        next.slot[s].slip_dir_W = f.slip_W[s].normalized();
      }
      break;
    }
    case EvKind::SlipSmall:
      // The slip falls below half of slip_start_v: its direction is solved from here on, as at
      // a slip start, so that its end (where the direction turns ever faster as a shrinking
      // slip does not meet zero head on) is not a stiff phase (no event: the motion goes on).
      next.slot[s].slip_start = true;
      break;
    case EvKind::SlipZero: {
      // A small slip vanishes (it shrinks along its solved direction and crosses zero): stick if
      // the sticking forces allow it, else it starts again from zero in the direction they give.
      ContactMode trial = next;
      trial.slot[s].stick = true;
      trial.slot[s].slip_start = false;
      if (dyn.coupled()) trial.slot[s].drill_stick = true;
      const ContactForces f = forces_at(y, trial);
      const double ft = std::hypot(f.force_W[s].x(), f.force_W[s].y());
      const double demand = dyn.coupled() ? dyn.coupled_demand(f, s) : ft / c.mu;
      if (demand <= f.normal[s]) {
        next = trial;
        if (dyn.coupled())
          owner.events_.push_back({"stick", te, std::string("slip and spin about the vertical vanish on the ") + slot_name(s) + " (coupled law)",
                                   demand / f.normal[s]});
        else
          owner.events_.push_back({"stick", te, std::string("slip vanishes on the ") + slot_name(s), ft / f.normal[s]});
      } else {
        if (dyn.coupled())
          next.slot[s].coupled_dir = coupled_slide_dir(f, s);
        else
          next.slot[s].slip_dir_W = ft > 0 ? Vec3(-Vec3(f.force_W[s].x(), f.force_W[s].y(), 0.0) / ft) : ref_dir[s];
        zero_slip[s] = true;
      }
      break;
    }
    case EvKind::ConeExit: {
      const ContactForces f = forces_at(y, mode);
      if (dyn.coupled()) {
        next.slot[s].stick = next.slot[s].drill_stick = false;
        next.slot[s].coupled_dir = coupled_slide_dir(f, s);
        zero_slip[s] = true;
        next.slot[s].slip_start = true;
        owner.events_.push_back({"slip", te, std::string("friction and drilling torque leave the ellipse on the ") + slot_name(s) + " (coupled law)", 0.0});
        break;
      }
      const Vec3 ft(f.force_W[s].x(), f.force_W[s].y(), 0.0);
      next.slot[s].stick = false;
      next.slot[s].slip_dir_W = ft.norm() > 0 ? Vec3(-ft.normalized()) : ref_dir[s];
      zero_slip[s] = true;
      next.slot[s].slip_start = true;
      owner.events_.push_back({"slip", te, std::string("friction leaves the cone on the ") + slot_name(s), 0.0});
      break;
    }
    case EvKind::DrillReversal: {
      ContactMode trial = next;
      trial.slot[s].drill_stick = true;
      const ContactForces f = forces_at(y, trial);
      const double wz = (x.q_WB.normalized() * x.w_B).z();
      if (std::abs(wz) * b.R > slip_eps) {
        // Not a zero (a spin that turned within a step): the torque opposes the spin's own sign.
        next.slot[0].drill_dir = next.slot[1].drill_dir = wz > 0 ? 1.0 : -1.0;
      } else if (std::abs(f.drill_torque[s]) <= c.drilling * f.normal[s]) {
        next = trial;
        owner.events_.push_back({"drill_stick", te, std::string("spin about the vertical stops on the ") + slot_name(s), 0.0});
      } else {
        // The spin passes through zero: it starts again against the torque that sticking needs.
        next.slot[0].drill_dir = next.slot[1].drill_dir = f.drill_torque[s] > 0 ? -1.0 : 1.0;
        zero_drill[s] = true;
      }
      break;
    }
    case EvKind::GrazeLift:
      next.slot[s].graze = false;
      next.slot[s].active = false;
      owner.events_.push_back({"lift", te, std::string("the ") + slot_name(s) + " leaves the floor", 0.0});
      break;
    case EvKind::GrazePress:
      next.slot[s].graze = false;
      owner.events_.push_back({"press", te, std::string("the ") + slot_name(s) + " carries load again", 0.0});
      break;
    case EvKind::GrazePinch:
      // Past the pinch both neighbouring fields are consistent; the load-free one, lifted,
      // is taken (no contact force where none is needed: the least constraint).
      next.slot[s].graze = false;
      next.slot[s].active = false;
      owner.events_.push_back({"lift", te, std::string("the ") + slot_name(s) + " leaves the floor: the viscous force has lost its leverage on the gap", 0.0});
      break;
    case EvKind::DrillConeExit: {
      const ContactForces f = forces_at(y, mode);
      next.slot[s].drill_stick = false;
      next.slot[s].drill_dir = f.drill_torque[s] > 0 ? -1.0 : 1.0;  // the spin starts against the torque
      next.slot[1 - s].drill_dir = next.slot[s].drill_dir;  // one spin about the vertical
      zero_drill[s] = true;
      owner.events_.push_back({"drill_slip", te, "drilling torque leaves its bound", 0.0});
      break;
    }
    case EvKind::Touchdown: {
      std::array<bool, 2> touching{mode.slot[0].active || s == 0, mode.slot[1].active || s == 1};
      std::array<double, 2> impulse{0, 0};
      const BodyState post = dyn.impact(x, touching, nullptr, &impulse);
      const double removed = energy(b, x) - energy(b, post);
      owner.events_.push_back({"impact", te, std::string(slot_name(s)) + " touches down", removed});
      if (s == 1 && !stem_touched) {
        stem_touched = true;
        owner.events_.push_back({"stem_contact", te, "first stem touchdown", removed});
      }
      ledger.impacts += removed;
      // The excursion's height: the highest gap at the check points, or the height the
      // return speed falls from under the gap acceleration at the return (the check
      // points can miss the apex of a short excursion), whichever is larger.
      double excursion = flight_max_gap[s];
      if (released_at_rest[s] && !unresolved_noted) {
        const double a = gap_acceleration(state_at(te), mode, s), vz = dyn.contact_velocity(x, s).z();
        if (a < 0) excursion = std::max(excursion, vz * vz / (2 * -a));
      }
      if (released_at_rest[s] && excursion < kHoldApex * b.R && !unresolved_noted) {
        // It left the floor at rest and comes back without having risen kHoldApex R: an
        // excursion below what the integration resolves (here the gap is known to ~rtol of
        // the body's size), so when it ends is not determined by the motion, and neither
        // are the times of the events that follow from it. Recorded once, as a warning.
        unresolved_noted = true;
        std::ostringstream os;
        os << "the " << slot_name(s) << " returns from an excursion below " << kHoldApex
           << " R: its return, and the times of the events after it, are below the resolution";
        owner.events_.push_back({"unresolved", te, os.str(), excursion});
      }
      y = pack(post);
      // After the impact each touching contact is held (its normal velocity is 0 to the
      // round-off of the impact's solve), released (it separates), or, when the bounce it
      // starts is too low to matter, held too: the cascade of ever smaller impacts that
      // ball and stem pass to each other (each plastic impact at one lifts the other) is
      // closed there, see kHoldApex.
      std::array<bool, 2> cand{false, false};
      const double v_round = 1e-12 * v_scale;
      for (int k = 0; k < 2; ++k)
        if (touching[k]) cand[k] = dyn.contact_velocity(post, k).z() <= v_round;
      std::array<bool, 2> hold{false, false};
      for (int k = 0; k < 2; ++k) {
        if (!touching[k] || cand[k]) continue;
        const double v = dyn.contact_velocity(post, k).z();
        ContactMode trial = mode;
        trial.slot[0].active = cand[0];
        trial.slot[1].active = cand[1];
        const double a = gap_acceleration(y, trial, k);
        if (a >= 0) continue;  // it leaves the floor for good (until the motion brings it back)
        const double apex = v * v / (2 * -a);
        if (apex <= kHoldApex * b.R) {
          hold[k] = true;
          continue;
        }
        // A contact released with a small separation velocity comes back after about
        // 2 v / |a|: the first step must not jump over that return (the gap starts at 0,
        // so only later steps can bracket the next touchdown).
        const double back = 2 * v / -a;
        first_dt = first_dt > 0 ? std::min(first_dt, 0.25 * back) : 0.25 * back;
      }
      if (hold[0] || hold[1]) {
        // Close the cascade: the bounce skipped and the rest of the cascade after it are
        // replaced by their zero-duration limit. Every sequence of normal impulses at the
        // two contacts that ends with both at rest ends in the same state, the projection
        // with the smallest change of kinetic energy; its pulling share at the skipped
        // contact stands for gravity and the other contact's force over the skipped
        // bounces (whose total duration vanishes with the apex), not for a floor force.
        // The energy it removes, at most ~M g kHoldApex R, is booked in the hold event.
        std::array<bool, 2> held_set{cand[0] || hold[0], cand[1] || hold[1]};
        std::array<double, 2> unused{0, 0};
        const BodyState closed = dyn.impact(post, held_set, nullptr, &unused, ContactDynamics::Impulses::Bilateral);
        const double lost = energy(b, post) - energy(b, closed);
        ledger.holds += lost;
        std::ostringstream os;
        os << "bounce of the " << slot_name(hold[0] ? 0 : 1) << " below " << kHoldApex << " R skipped: cascade closed";
        owner.events_.push_back({"hold", te, os.str(), lost});
        y = pack(closed);
        for (int k = 0; k < 2; ++k) cand[k] = held_set[k];
      }
      if (!cand[0] && !cand[1]) {
        next = mode;
        next.slot[0].active = next.slot[1].active = false;
        if (!flight_allowed) return end(ReferenceStatus::ContactLost, te, "bounces off the floor after an impact", y);
        owner.events_.push_back({"flight", te, "leaves the floor after an impact", 0.0});
      } else {
        next = settle(y, cand, mode);
      }
      if (!mode.any_active()) owner.events_.push_back({"touchdown", te, std::string(slot_name(s)) + " lands", removed});
      break;
    }
    default:
      break;
  }
  if (next.slot[0].active && next.slot[1].active) {
    // A change at one of two held contacts (a stick above all: its friction jumps from the
    // sliding to the sticking value) moves the other's normal force by a jump. Where that
    // leaves a held contact pulling (F_n < 0), its NormalForce event starts negative and
    // never fires: the floor would pull that contact down, and its sliding friction
    // -mu F_n s/|s| with F_n < 0 pushes along the slip, a power mu |F_n| |s| > 0 (held with a
    // ball stuck on the floor, the stem took E from 0.67 to 1.36 E0 in 15 time units,
    // docs/findings/reference-two-contact-energy-gain.md). The mode is settled again: the
    // pulling contact lifts.
    const ContactForces f = forces_at(y, next);
    bool pulling = false;
    for (int k = 0; k < 2; ++k) pulling = pulling || (!next.slot[k].graze && f.normal[k] < 0);
    if (pulling) next = settle(y, {true, true}, next);
  }
  for (int k = 0; k < 2; ++k)
    if (!next.slot[k].active && (mode.slot[k].active || (fn.kind == EvKind::Touchdown && k == s))) {
      released_at_rest[k] = fn.kind != EvKind::Touchdown;
      flight_max_gap[k] = 0.0;
    }
  set_mode(next, te);
  if (!mode.any_active() && !flight_allowed) return end(ReferenceStatus::ContactLost, te, "no contact can hold", y);
  restart(te, project_booked(y, te), first_dt);
}

}  // namespace tippe
