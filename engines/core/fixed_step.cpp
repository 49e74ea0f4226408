// Shared stepping loop of the fixed-step engines: events, failure classification, viscous and
// gliding laws, work.
#include "fixed_step.h"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>

#include "../../analytic/stop_request.h"
#include "settings.h"

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

FixedStepSimulator::FixedStepSimulator(const Scene& scene, const EngineInfo& info)
    : info_(info), scene_(scene), body_(BodyModel::from_scene(scene)) {}

void FixedStepSimulator::start(double dt) {
  // A step that is not a positive number would run no step and call it a run (NaN), or never end.
  if (!(dt > 0) || !std::isfinite(dt))
    throw std::invalid_argument("timestep " + round_trip_text(dt) + ": must be a positive finite number");
  dt_ = dt;
  const BodyState x0 = engine_state();
  last_.state = x0;
  last_.cos_theta = (x0.q_WB * Vec3::UnitZ()).z();
  last_.gap_ball = surface_gap(body_, x0, Surface::Ball);
  last_.gap_stem = body_.stem ? surface_gap(body_, x0, Surface::Stem) : 1e300;
  e0_ = energy(body_, x0);
  speed_scale_ = std::max({x0.w_B.norm(), x0.v_WG.norm() / body_.R, std::sqrt(body_.g / body_.R), 1e-12});
  contact_surface_ = Surface::Ball;
}

Observation FixedStepSimulator::observe() const {
  const ContactReport c = engine_contacts();
  // Ball and stem on the floor together, as the engine reports its contacts: the sample is on
  // both surfaces, as the reference's are in its two-contact phase. Jellett's J is conserved on
  // one surface only, so such samples end a run of the J check (SampleSummary). Labelled by the
  // lower surface alone, an engine's two-contact phase was checked as a run on the stem, and its
  // J "drift" there (0.34 to 0.40 of J on extremes/tilt_near_pi, every engine alike) classed it
  // unphysical.
  Observation o = c.ball && c.stem ? observe_kinematics_on_both(body_, engine_state()) : observe_kinematics(body_, engine_state());
  o.normal_force = c.normal_force;
  o.engine_contact_valid = c.point_valid;
  o.p_WC_engine = c.p_WC;
  return o;
}

void FixedStepSimulator::set_state(const BodyState& x) {
  if (!(x.p_WG.allFinite() && x.v_WG.allFinite() && x.q_WB.coeffs().allFinite() && x.w_B.allFinite()) ||
      x.q_WB.norm() < 1e-12)
    throw std::invalid_argument(engine() + ": set_state: non-finite state or zero quaternion");
  BodyState y = x;
  y.t = time();
  y.q_WB.normalize();
  engine_set_state(y);
  // The event probes restart from the new state: no crossing is found across the jump.
  const BodyState z = engine_state();
  last_.state = z;
  last_.cos_theta = (z.q_WB * Vec3::UnitZ()).z();
  last_.gap_ball = surface_gap(body_, z, Surface::Ball);
  last_.gap_stem = body_.stem ? surface_gap(body_, z, Surface::Stem) : 1e300;
}

double FixedStepSimulator::native_mu(double rolling_mu) const {
  switch (scene_.contact.friction) {
    case FrictionLaw::Coulomb: return scene_.contact.mu;
    case FrictionLaw::Rolling: return rolling_mu;
    // Viscous and gliding: step_once applies F_t = -k v_C or -mu F_n v_C through apply_force_W.
    case FrictionLaw::Viscous:
    case FrictionLaw::Gliding:
    case FrictionLaw::None: return 0.0;
  }
  return 0.0;
}

std::vector<std::string> FixedStepSimulator::friction_law_notes(const FrictionNoteText& text, double rolling_mu) const {
  std::ostringstream mu;
  mu << rolling_mu;
  std::vector<std::string> notes;
  switch (scene_.contact.friction) {
    case FrictionLaw::Rolling:
      notes.push_back("rolling approximated by Coulomb friction with mu = " + mu.str() + text.rolling_detail);
      break;
    case FrictionLaw::Viscous:
      notes.push_back("viscous friction applied by the bench as an external force" + text.force_how +
                      " at the geometric contact point; " + text.engine + " contacts frictionless");
      break;
    case FrictionLaw::Gliding:
      notes.push_back("gliding friction -mu F_n v_C applied by the bench as an external force" + text.force_how +
                      " at each geometric contact point, F_n per geom from " + text.normal_source + "; " + text.engine +
                      " contacts frictionless");
      break;
    default: break;
  }
  return notes;
}

std::string FixedStepSimulator::full_sphere_note() const {
  const BodyModel& m = body_;
  if (m.stem && scene_.body.truncation_height > 0 && scene_.body.truncation_height / m.R < (m.R - m.r) / m.l)
    return "ball modelled as a full sphere although its cut cap can reach the floor before the stem tip";
  return {};
}

void FixedStepSimulator::fail(RunStatus s, double t, const std::string& why) {
  status_ = s;
  status_time_ = t;
  status_detail_ = why;
  events_.push_back({to_string(s), t, why, 0.0});
}

void FixedStepSimulator::advance_to(double t) {
  // The step budget ends a run that would take more steps (to t, or over the scene's duration) as
  // failed, before it starts them.
  const double horizon = std::max(t, scene_.run.duration);
  if (status_ == RunStatus::Ok && horizon / dt_ > static_cast<double>(kMaxEngineSteps)) {
    fail(RunStatus::Failed, time(),
         "step budget: a run to t = " + round_trip_text(horizon) + " takes " + round_trip_text(std::ceil(horizon / dt_)) +
             " steps of " + round_trip_text(dt_) + ", more than the budget of " + std::to_string(kMaxEngineSteps));
    return;
  }
  // Steps whose end lies within half a step of t count as reaching t. A signal ends the run
  // within kStepsPerStopPoll steps (Interrupted, see analytic/stop_request.h).
  while (status_ == RunStatus::Ok && (static_cast<double>(n_steps_) + 0.5) * dt_ <= t) {
    if (n_steps_ % kStepsPerStopPoll == 0) poll_stop();
    step_once();
  }
}

void FixedStepSimulator::step_once() {
  // The state the last step ended in, as the per-step checks read it (start and set_state set it
  // too): the engine's state is read once per step, not again here.
  const BodyState& x = last_.state;
  if (scene_.contact.friction == FrictionLaw::Viscous) {
    // The source's law F_t = -k v_C at every contact the engine has, each at its own geometric
    // contact point with its own velocity (the engine's own contact is frictionless in this
    // mode). With ball and stem both down, friction at one of them only would let the other
    // slide freely: the reference applies the law at each contact, so the engines must too.
    const ContactReport c = engine_contacts();
    const Vec3 w_W = x.q_WB * x.w_B;
    for (const Surface s : {Surface::Ball, Surface::Stem}) {
      if (!(s == Surface::Ball ? c.ball : c.stem && body_.stem)) continue;
      const Vec3 R_C = contact_offset_W(body_, x.q_WB, s);
      Vec3 v_C = x.v_WG + w_W.cross(R_C);
      v_C.z() = 0.0;
      apply_force_W(-scene_.contact.k * v_C, x.p_WG + R_C);
    }
  }
  if (scene_.contact.friction == FrictionLaw::Gliding) {
    // Rutstam's gliding law F_t = -mu F_n v_C at every contact the engine has, each with its own
    // normal force, contact point and velocity (the engine's own contact is frictionless in this
    // mode). The normal force is the engine's from the previous step (the report describes the
    // step just taken): an explicit law, first order in dt, as the engine's solve cannot carry
    // a friction proportional to the force it is solving for. Before the first step it is the
    // report of the initial state (0 where the engine has not solved yet: one step without
    // friction).
    const ContactReport c = engine_contacts();
    const Vec3 w_W = x.q_WB * x.w_B;
    for (const Surface s : {Surface::Ball, Surface::Stem}) {
      if (!(s == Surface::Ball ? c.ball : c.stem && body_.stem)) continue;
      const double f_n = std::max(0.0, s == Surface::Ball ? c.normal_force_ball : c.normal_force_stem);
      const Vec3 R_C = contact_offset_W(body_, x.q_WB, s);
      Vec3 v_C = x.v_WG + w_W.cross(R_C);
      v_C.z() = 0.0;
      apply_force_W(-scene_.contact.mu * f_n * v_C, x.p_WG + R_C);
    }
  }
  engine_step();
  ++n_steps_;
  work_.steps = n_steps_;
  work_.rhs_evaluations = n_steps_;
  work_.solver_iterations = engine_solver_iterations();
  const double t = static_cast<double>(n_steps_) * dt_;
  const std::string failure = engine_failure();
  if (!failure.empty()) return fail(RunStatus::Failed, t, failure);
  // Only what the per-step checks need (the full observables are computed when observed):
  // this loop runs every engine step, so its cost is the adapter's overhead.
  StepProbe now;
  now.state = engine_state();
  const BodyState& y = now.state;
  const bool finite = y.p_WG.allFinite() && y.v_WG.allFinite() && y.q_WB.coeffs().allFinite() &&
                      y.w_B.allFinite();
  if (!finite) return fail(RunStatus::Diverged, t, "non-finite state");
  now.cos_theta = (y.q_WB * Vec3::UnitZ()).z();
  now.gap_ball = surface_gap(body_, y, Surface::Ball);
  now.gap_stem = body_.stem ? surface_gap(body_, y, Surface::Stem) : 1e300;
  track_events(last_, now);
  last_ = now;
  const double gap = std::min(now.gap_ball, now.gap_stem);
  if (gap < -limits_.penetration_fraction * body_.R) {
    std::ostringstream why;
    why << "fell through the floor: lowest point at " << gap << " (limit " << -limits_.penetration_fraction * body_.R << ")";
    return fail(RunStatus::Diverged, t, why.str());
  }
  const double e = energy(body_, y);
  if (e0_ > 0 && e > limits_.energy_factor * e0_) {
    std::ostringstream why;
    why << "energy " << e << " above " << limits_.energy_factor << " E0 = " << limits_.energy_factor * e0_;
    return fail(RunStatus::Diverged, t, why.str());
  }
  const double speed = std::max(y.w_B.norm(), y.v_WG.norm() / body_.R);
  if (speed > limits_.speed_factor * speed_scale_) {
    std::ostringstream why;
    why << "speed blow-up: " << speed << " rad/s equivalent";
    return fail(RunStatus::Diverged, t, why.str());
  }
  const std::string limit = engine_limit_hit();
  if (!limit.empty()) return fail(RunStatus::Clamped, t, limit);
}

void FixedStepSimulator::track_events(const StepProbe& a, const StepProbe& b) {
  const double ta = a.state.t, tb = b.state.t;
  // The engine's dense output is piecewise linear between steps: events are located by
  // linear interpolation of the event function between the two step ends.
  auto cross = [&](double fa, double fb) { return ta + (tb - ta) * fa / (fa - fb); };
  if (!inverted_ && a.cos_theta > 0 && b.cos_theta <= 0) {
    inverted_ = true;
    events_.push_back({"inversion", cross(a.cos_theta, b.cos_theta), "theta crosses 90 deg", 0.0});
  }
  const ContactReport c = engine_contacts();
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
