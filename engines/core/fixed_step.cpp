// Shared stepping loop of the fixed-step engines: events, failure classification, viscous and
// gliding laws, work.
#include "engines/core/fixed_step.h"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>

#include "analytic/stop_request.h"
#include "engines/core/bench_friction.h"
#include "engines/core/settings.h"

namespace tippe {

FixedStepSimulator::FixedStepSimulator(const Scene& scene, const EngineInfo& info)
    : CheckedSimulator(scene), info_(info), scene_(scene), body_(BodyModel::from_scene(scene)) {}

void FixedStepSimulator::start(double dt) {
  // A step that is not a positive number would run no step and call it a run (NaN), or never end.
  if (!(dt > 0) || !std::isfinite(dt))
    throw std::invalid_argument("timestep " + round_trip_text(dt) + ": must be a positive finite number");
  dt_ = dt;
  checks_.start(engine_state());
}

Observation FixedStepSimulator::observe() const { return observe_with_contacts(body_, engine_state(), engine_contacts()); }

EngineContactForces FixedStepSimulator::contact_forces() const {
  return tippe::contact_forces(contacts_with_bench_friction());
}

void FixedStepSimulator::set_state(const BodyState& x) {
  check_settable_state(engine(), x);
  BodyState y = x;
  y.t = time();
  y.q_WB.normalize();
  engine_set_state(y);
  bench_applied_.n = 0;
  checks_.restart(engine_state());
}

double FixedStepSimulator::native_mu(double rolling_mu) const { return tippe::native_mu(scene_.contact, rolling_mu); }

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

void FixedStepSimulator::advance_to(double t) {
  // The step budget ends a run that would take more steps (to t, or over the scene's duration) as
  // failed, before it starts them.
  if (!checks_.within_budget(std::max(t, scene_.run.duration), dt_, time())) return;
  // Steps whose end lies within half a step of t count as reaching t. A signal ends the run
  // within kStepsPerStopPoll steps (Interrupted, see analytic/stop_request.h).
  while (checks_.ok() && (static_cast<double>(n_steps_) + 0.5) * dt_ <= t) {
    if (n_steps_ % kStepsPerStopPoll == 0) poll_stop();
    step_once();
  }
}

void FixedStepSimulator::step_once() {
  // The state the last step ended in, as the per-step checks read it (start and set_state set it
  // too): the engine's state is read once per step, not again here.
  const BodyState& x = checks_.last_state();
  bench_applied_.n = 0;
  if (bench_applies_friction(scene_.contact.friction)) {
    const BenchFrictionForces f = bench_friction_forces(body_, scene_.contact, x, engine_contacts());
    for (int i = 0; i < f.n; ++i) apply_force_W(f.f_W[i], x.p_WG + f.r_GC_W[i]);
    bench_applied_ = f;
  }
  engine_step();
  ++n_steps_;
  work_.steps = n_steps_;
  work_.rhs_evaluations = n_steps_;
  work_.solver_iterations = engine_solver_iterations();
  const double t = static_cast<double>(n_steps_) * dt_;
  const std::string failure = engine_failure();
  if (!failure.empty()) return checks_.fail(RunStatus::Failed, t, failure);
  // The contacts with the bench's friction of the step, for its work (the events read the flags).
  if (!checks_.after_step(t, engine_state(), contacts_with_bench_friction())) return;
  const std::string limit = engine_limit_hit();
  if (!limit.empty()) return checks_.fail(RunStatus::Clamped, t, limit);
}

}  // namespace tippe
