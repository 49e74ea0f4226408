// The per-step checks every engine adapter shares: limits, step budget, events.
#include "engines/core/step_checks.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <stdexcept>

#include "engines/core/settings.h"

namespace tippe {

const char* to_string(RunStatus s) {
  switch (s) {
    case RunStatus::Ok: return "ok";
    case RunStatus::ContactLost: return "contact_lost";
    case RunStatus::Diverged: return "diverged";
    case RunStatus::Unphysical: return "unphysical";
    case RunStatus::Clamped: return "clamped";
    case RunStatus::Failed: return "failed";
  }
  return "?";
}

void check_settable_state(const std::string& engine, const BodyState& x) {
  if (!(x.p_WG.allFinite() && x.v_WG.allFinite() && x.q_WB.coeffs().allFinite() && x.w_B.allFinite()) ||
      x.q_WB.norm() < 1e-12)
    throw std::invalid_argument(engine + ": set_state: non-finite state or zero quaternion");
}

Observation observe_with_contacts(const BodyModel& body, const BodyState& x, const ContactReport& c) {
  Observation o = c.ball && c.stem ? observe_kinematics_on_both(body, x) : observe_kinematics(body, x);
  o.normal_force = c.normal_force;
  o.engine_contact_valid = c.point_valid;
  o.p_WC_engine = c.p_WC;
  return o;
}

void add_surface_force(ContactReport& r, bool stem, double f_n, const Vec3& f_t_W, const Vec3& p_W) {
  (stem ? r.friction_stem_W : r.friction_ball_W) += f_t_W;
  ++(stem ? r.points_stem : r.points_ball);
  if (f_n > 0) {
    (stem ? r.p_WC_stem : r.p_WC_ball) += f_n * p_W;
    (stem ? r.weight_stem : r.weight_ball) += f_n;
  }
}

void finish_surface_points(ContactReport& r) {
  if (r.weight_ball > 0) r.p_WC_ball /= r.weight_ball;
  if (r.weight_stem > 0) r.p_WC_stem /= r.weight_stem;
}

void add_stage_forces(StepMeanForces& mean, const ContactReport& stage, double weight, const Vec3& shift_W) {
  mean.set = true;
  mean.normal_ball += weight * stage.normal_force_ball;
  mean.normal_stem += weight * stage.normal_force_stem;
  mean.friction_ball_W += weight * stage.friction_ball_W;
  mean.friction_stem_W += weight * stage.friction_stem_W;
  // The bench's moments are about each stage's centre of mass; a force held over the step has
  // the same moment about the step start's (the adapters add the bench's part after the stages).
  mean.bench.f_ball_W += weight * stage.bench.f_ball_W;
  mean.bench.f_stem_W += weight * stage.bench.f_stem_W;
  mean.bench.m_ball_W += weight * stage.bench.m_ball_W;
  mean.bench.m_stem_W += weight * stage.bench.m_stem_W;
  if (stage.weight_ball > 0) {
    mean.p_WC_ball += weight * stage.weight_ball * (stage.p_WC_ball - shift_W);
    mean.weight_ball += weight * stage.weight_ball;
  }
  if (stage.weight_stem > 0) {
    mean.p_WC_stem += weight * stage.weight_stem * (stage.p_WC_stem - shift_W);
    mean.weight_stem += weight * stage.weight_stem;
  }
}

void finish_stage_forces(StepMeanForces& mean) {
  if (mean.weight_ball > 0) mean.p_WC_ball /= mean.weight_ball;
  if (mean.weight_stem > 0) mean.p_WC_stem /= mean.weight_stem;
}

EngineContactForces contact_forces(const ContactReport& r) {
  EngineContactForces f;
  f.ball = {r.ball, r.normal_force_ball, r.friction_ball_W, r.weight_ball > 0, r.p_WC_ball, r.points_ball};
  f.stem = {r.stem, r.normal_force_stem, r.friction_stem_W, r.weight_stem > 0, r.p_WC_stem, r.points_stem};
  return f;
}

double Simulator::friction_work() const { return std::numeric_limits<double>::quiet_NaN(); }

double EnergyLedgerTotals::accounted() const {
  auto or0 = [](double v) { return std::isfinite(v) ? v : 0.0; };
  return or0(normal_work) + or0(friction_work) + or0(drilling_work) - or0(impact_energy);
}

EnergyLedgerTotals StepChecks::energy_ledger() const {
  EnergyLedgerTotals l;
  l.normal_work = normal_work_;
  l.friction_work = friction_work_;
  if (has_potential_) l.elastic_energy = elastic(last_);
  return l;
}

void StepChecks::set_contact_potential(const ContactPotential& p) {
  has_potential_ = true;
  potential_ = p;
}

double StepChecks::elastic(const StepProbe& p) const {
  const double e = potential_.exponent + 1.0;
  auto u = [&](double k, double gap) {
    const double d = -gap - potential_.offset;
    return d > 0 ? k / e * std::pow(d, e) : 0.0;
  };
  return u(potential_.k_ball, p.gap_ball) + (body_.stem ? u(potential_.k_stem, p.gap_stem) : 0.0);
}

StepChecks::StepProbe StepChecks::probe(const BodyState& x) const {
  StepProbe p;
  p.state = x;
  p.cos_theta = (x.q_WB * Vec3::UnitZ()).z();
  p.gap_ball = surface_gap(body_, x, Surface::Ball);
  p.gap_stem = body_.stem ? surface_gap(body_, x, Surface::Stem) : 1e300;
  return p;
}

void StepChecks::start(const BodyState& x0) {
  last_ = probe(x0);
  e0_ = energy(body_, x0);
  speed_scale_ = std::max({x0.w_B.norm(), x0.v_WG.norm() / body_.R, std::sqrt(body_.g / body_.R), 1e-12});
  contact_surface_ = Surface::Ball;
}

void StepChecks::restart(const BodyState& x) { last_ = probe(x); }

void StepChecks::fail(RunStatus s, double t, const std::string& why) {
  status_ = s;
  status_time_ = t;
  status_detail_ = why;
  events_.push_back({to_string(s), t, why, 0.0});
}

bool StepChecks::within_budget(double horizon, double h, double now) {
  if (status_ != RunStatus::Ok || !(horizon / h > static_cast<double>(kMaxEngineSteps))) return true;
  fail(RunStatus::Failed, now,
       "step budget: a run to t = " + round_trip_text(horizon) + " takes " + round_trip_text(std::ceil(horizon / h)) +
           " steps of " + round_trip_text(h) + ", more than the budget of " + std::to_string(kMaxEngineSteps));
  return false;
}

bool StepChecks::after_step(double t, const BodyState& y, const ContactReport& c) {
  // Only what the checks need (the full observables are computed when observed): this runs
  // every engine step, so its cost is the adapter's overhead.
  const bool finite = y.p_WG.allFinite() && y.v_WG.allFinite() && y.q_WB.coeffs().allFinite() && y.w_B.allFinite();
  if (!finite) {
    fail(RunStatus::Diverged, t, "non-finite state");
    return false;
  }
  const StepProbe now = probe(y);
  add_friction_work(y, y.t - last_.state.t, c);
  track_events(last_, now, c);
  last_ = now;
  const double gap = std::min(now.gap_ball, now.gap_stem);
  if (gap < -limits_.penetration_fraction * body_.R) {
    std::ostringstream why;
    why << "fell through the floor: lowest point at " << gap << " (limit " << -limits_.penetration_fraction * body_.R << ")";
    fail(RunStatus::Diverged, t, why.str());
    return false;
  }
  const double e = energy(body_, y);
  if (e0_ > 0 && e > limits_.energy_factor * e0_) {
    std::ostringstream why;
    why << "energy " << e << " above " << limits_.energy_factor << " E0 = " << limits_.energy_factor * e0_;
    fail(RunStatus::Diverged, t, why.str());
    return false;
  }
  const double speed = std::max(y.w_B.norm(), y.v_WG.norm() / body_.R);
  if (speed > limits_.speed_factor * speed_scale_) {
    std::ostringstream why;
    why << "speed blow-up: " << speed << " rad/s equivalent";
    fail(RunStatus::Diverged, t, why.str());
    return false;
  }
  return true;
}

void StepChecks::add_friction_work(const BodyState& y, double h, const ContactReport& c) {
  // The force acts over the step; its work is booked with the mean of the material point's
  // velocity at the step's start and end, v_C = (v_C(x_n) + v_C(x_n+1)) / 2, at the force's point
  // (the geometric contact point when the engine gave none). For an impulse that is exact (the
  // work of an impulse P on a rigid body is P . (v_C- + v_C+) / 2, Kelvin's theorem): an impact
  // or the step that stops a slip is booked as the energy it removes. For a smooth force it is
  // the kinetic energy the force gave in the step, so what is left in the numerical remainder is
  // the integrator's own error. A sticking contact (v_C = 0 at both ends) does no work. (The end
  // velocity alone booked an impact's friction impulse as up to 3e-3 E0 more work than it did:
  // Siconos at the stem's touchdown on toy_viscous.)
  if (c.step_work.set) {
    // The engine's integrator integrated the forces' power over its step itself (Simbody's
    // explicit integrators: the power as state variables its stages advance): booked as given.
    normal_work_ += c.step_work.normal;
    friction_work_ += c.step_work.friction;
    return;
  }
  const Vec3 w_W = y.q_WB * y.w_B;
  const BodyState& x = last_.state;
  const Vec3 w0_W = x.q_WB * x.w_B;
  // The step's forces: the report's, or the weighted stages' where the adapter gave them.
  const StepMeanForces& m = c.step_mean;
  for (const Surface s : {Surface::Ball, Surface::Stem}) {
    const bool stem = s == Surface::Stem;
    const Vec3& f = m.set ? (stem ? m.friction_stem_W : m.friction_ball_W) : (stem ? c.friction_stem_W : c.friction_ball_W);
    const double f_n = m.set ? (stem ? m.normal_stem : m.normal_ball) : (stem ? c.normal_force_stem : c.normal_force_ball);
    if ((f.isZero(0.0) && f_n == 0.0) || (stem && !body_.stem)) continue;
    const double weight = m.set ? (stem ? m.weight_stem : m.weight_ball) : (stem ? c.weight_stem : c.weight_ball);
    const Vec3& p_WC = m.set ? (stem ? m.p_WC_stem : m.p_WC_ball) : (stem ? c.p_WC_stem : c.p_WC_ball);
    if (smooth_forces_) {
      // A force law read at the step's end (Simbody with CPodes or Verlet, whose steps would see
      // the state variables its explicit integrators book the work with), at its point there:
      // its power at the end times the step, first order in the step. Neither it nor the
      // trapezoid of the two ends' power is sharp where the force changes within a step (the
      // Hertz contact's ringing, a touchdown): on leine_glocker (RK-Merson, 30 s) they leave
      // 5.3e-4 and 2.2e-4 E0 in the numerical term where the integrator's own quadrature leaves
      // 4.7e-8 (test_simbody.cpp). (The trapezoid once looked worse against a test's "work the
      // bench applied", the power sampled every 1e-4 s and summed, at the same instants as the
      // step ends there: that sum is 1.1e-3 off the integrated work, the trapezoid 8e-5 and the
      // step end 1.1e-3, test_contact_forces.cpp.)
      const Vec3 r = weight > 0 ? Vec3(p_WC - y.p_WG) : contact_offset_W(body_, y.q_WB, s);
      const Vec3 v_end = y.v_WG + w_W.cross(r);
      friction_work_ += f.dot(v_end) * h;
      normal_work_ += f_n * v_end.z() * h;
      continue;
    }
    // A solver's impulse acts at the point its contact Jacobian was built at, where the engine
    // reports its point (or, with none, the geometric contact point): the collision of the step's
    // start state, or its end's for an engine that said so (set_impulse_at_step_end). Its lever
    // arm is that point from the same state's centre of mass, and the same lever arm in the lab
    // frame gives the material point's velocity at both ends, as the engine's velocity update
    // v+ = v- + M^-1 J^T P uses it. (The arm from the step's end G for an engine whose point is
    // the start's, off by v_G h, with the start's geometric point shifted for the other end,
    // booked 4.2-4.9e-4 E0 of work that no force did over the first second of leine_glocker in
    // Bullet, ODE and DART alike: test_energy_ledger_steps.cpp.)
    const BodyState& at = impulse_at_end_ ? y : x;
    const Vec3 r = weight > 0 ? Vec3(p_WC - at.p_WG) : contact_offset_W(body_, at.q_WB, s);
    const Vec3 v_C = 0.5 * (x.v_WG + w0_W.cross(r) + y.v_WG + w_W.cross(r));
    // The bench's part of the friction at the bench's own point: F . v_C = F . v_G + (r x F) . w
    // with the step's mean velocities, which also holds for a weighted sum of forces at several
    // points (Siconos' theta-mean of two steps' forces).
    const BenchWrench& b = m.set ? m.bench : c.bench;
    const Vec3& f_bench = stem ? b.f_stem_W : b.f_ball_W;
    if (f_bench.isZero(0.0)) {
      friction_work_ += f.dot(v_C) * h;
    } else if (std::isfinite(c.bench.work)) {
      friction_work_ += (f - f_bench).dot(v_C) * h;  // the bench's part: the adapter's work, below
    } else {
      const Vec3& m_bench = stem ? b.m_stem_W : b.m_ball_W;
      const Vec3 v_G = 0.5 * (x.v_WG + y.v_WG), w_mean = 0.5 * (w0_W + w_W);
      friction_work_ += ((f - f_bench).dot(v_C) + f_bench.dot(v_G) + m_bench.dot(w_mean)) * h;
    }
    normal_work_ += f_n * v_C.z() * h;
  }
  if (std::isfinite(c.bench.work) && c.bench.work != 0.0) friction_work_ += c.bench.work;
}

void StepChecks::track_events(const StepProbe& a, const StepProbe& b, const ContactReport& c) {
  const double ta = a.state.t, tb = b.state.t;
  // An engine's dense output is piecewise linear between its steps (fixed or its own): events
  // are located by linear interpolation of the event function between the two step ends.
  auto cross = [&](double fa, double fb) { return ta + (tb - ta) * fa / (fa - fb); };
  if (!inverted_ && a.cos_theta > 0 && b.cos_theta <= 0) {
    inverted_ = true;
    events_.push_back({"inversion", cross(a.cos_theta, b.cos_theta), "theta crosses 90 deg", 0.0});
  }
  if (body_.stem && !stem_touched_ && c.stem) {
    stem_touched_ = true;
    const double te = (a.gap_stem > 0 && b.gap_stem <= 0) ? cross(a.gap_stem, b.gap_stem) : tb;
    events_.push_back({"stem_contact", te, "first stem contact reported by the engine", 0.0});
  }
  Surface s = Surface::None;
  if (c.ball && c.stem) s = Surface::Both;
  else if (c.ball) s = Surface::Ball;
  else if (c.stem) s = Surface::Stem;
  if (s != contact_surface_) {
    events_.push_back({"switch", tb, std::string(to_string(contact_surface_)) + " -> " + to_string(s), 0.0});
    contact_surface_ = s;
  }
}

}  // namespace tippe
