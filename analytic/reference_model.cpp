// The analytic reference: adaptive integration with dense output (Bulirsch-Stoer, Dormand-Prince
// 5(4) or Rosenbrock4), events located by TOMS 748 root finding on the dense output, mode
// changes (impacts, stick/slip, release) applied at the event.
#include "analytic/reference_model.h"

#include "analytic/boost_binomial.h"  // first: it must precede every Boost.Math and Odeint header
#include <boost/math/tools/toms748_solve.hpp>

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

#include "analytic/detail/reference_impl.h"
#include "analytic/initial_state.h"
#include "analytic/stop_request.h"

namespace tippe {

using namespace reference_detail;

ContactForces ReferenceModel::Impl::forces_at(const StateVector& y, const ContactMode& m) {
  ++owner.rhs_evals_;
  return dyn.evaluate(y, m, nullptr);
}

void ReferenceModel::Impl::note_forces(const ContactForces& f) {
  if (!f.solvable) singular = true;
  graze_last = GrazeNote{};
  for (int s = 0; s < 2; ++s)
    if (mode.slot[s].active && mode.slot[s].graze)
      graze_last = {true, f.graze_fraction[s], std::max({f.graze_lifted_accel[s], -f.graze_loaded_accel[s], 0.0})};
}

void ReferenceModel::Impl::track_graze(const GrazeNote& n) {
  if (!n.grazing) return;
  graze_lo = std::min(graze_lo, n.fraction);
  graze_hi = std::max(graze_hi, n.fraction);
  graze_violation = std::max(graze_violation, n.violation);
}

std::vector<double> ReferenceModel::Impl::g_all(const StateVector& y, Vec3* power) {
  const ContactForces f = forces_at(y, mode);
  note_forces(f);
  if (power) *power = contact_power(y, f);
  std::vector<double> out(fns.size());
  for (size_t i = 0; i < fns.size(); ++i) out[i] = g(fns[i], y, &f);
  return out;
}

StateVector ReferenceModel::Impl::state_at(double t) {
  StateVector y;
  if (t >= stepper.current_time()) return stepper.current_state();
  stepper.calc_state(t, y);
  return y;
}

double ReferenceModel::Impl::locate(const EvFn& fn, double a, double b, double ga, double gb) {
  auto f = [&](double t) {
    const StateVector y = state_at(t);
    const ContactForces cf = forces_at(y, mode);
    return g(fn, y, &cf);
  };
  // Event times to ~4 ulp of the time value: far inside the 1e-9 relative the design asks.
  auto tol = [](double lo, double hi) { return std::abs(hi - lo) <= 8e-16 * std::max(1.0, std::abs(hi)); };
  boost::uintmax_t iters = 200;
  const auto r = boost::math::tools::toms748_solve(f, a, b, ga, gb, tol, iters);
  // The earliest time at which the event function has crossed (g <= 0).
  return r.second;
}

ContactForces ReferenceModel::Impl::forces_at_noted(const StateVector& y) {
  const ContactForces f = forces_at(y, mode);
  note_forces(f);
  return f;
}

// Second derivative of the gap of slot k (acceleration of its sphere centre along z).
double ReferenceModel::Impl::gap_acceleration(const StateVector& y, const ContactMode& m, int k) {
  StateVector dy;
  ++owner.rhs_evals_;
  dyn.evaluate(y, m, &dy);
  const BodyState x = unpack(y, 0);
  const Quat q = x.q_WB.normalized();
  const Vec3 w_W = q * x.w_B, wdot_W = q * Vec3(dy[10], dy[11], dy[12]);
  const Vec3 r_GO = dyn.geometry(x, k).r_GO_W;
  return dy[5] + wdot_W.cross(r_GO).z() + w_W.cross(w_W.cross(r_GO)).z();
}

void ReferenceModel::Impl::restart(double t, const StateVector& y, double first_dt) {
  double dt = dt_hint > 0 ? dt_hint : 1e-4;
  if (first_dt > 0) dt = std::min(dt, first_dt);
  stepper.initialize(y, t, dt);
  build_event_functions();
  refresh_references(y);
  g_start = g_all(y, &p_start);
  // A contact that starts to slide from zero slip starts on the positive side of its
  // SlipReversal function (0 there): the continuation's flip of the direction makes a slip
  // that grows against the reference a self-consistent motion in which the force drives the
  // slip; a crossing from exactly 0 would not be bracketed, so it is counted as one.
  for (size_t i = 0; i < fns.size(); ++i)
    if (((fns[i].kind == EvKind::SlipReversal || fns[i].kind == EvKind::SlipZero) && fresh_slip[fns[i].slot]) ||
        (fns[i].kind == EvKind::DrillReversal && fresh_drill[fns[i].slot]))
      if (!(g_start[i] > 0)) g_start[i] = std::numeric_limits<double>::denorm_min();
  fresh_slip = fresh_drill = {false, false};
  track_graze(graze_last);
  pending = false;
  ledger_t = t;
  power_fit.valid = false;
}

void ReferenceModel::Impl::step() {
  // Everything up to the current time has been observed before a new step is asked for, so
  // the dense output of the last step is no longer needed: put |q| back to 1 when the rate
  // term has let it drift beyond 1e-13 (costs one right-hand side, rarely).
  {
    StateVector y = stepper.current_state();
    const double n = std::sqrt(y[6] * y[6] + y[7] * y[7] + y[8] * y[8] + y[9] * y[9]);
    if (std::abs(n - 1.0) > 1e-13) {
      for (int i = 6; i < 10; ++i) y[i] /= n;
      stepper.initialize(y, stepper.current_time(), stepper.current_time_step());
      ++owner.rhs_evals_;
      // p_start stays: the power at the state before, off by the ~1e-13 relative of the
      // renormalization (a node of the interpolant only; the booking does not use it).
    }
  }
  // Plain names, not a structured binding: the lambda below captures them, which C++17
  // allows only for variables (clang rejects capturing a binding; g++ accepts it).
  singular = false;
  const auto step_span = stepper.do_step(system);
  const double t0 = step_span.first, t1 = step_span.second;
  ++owner.steps_;
  dt_hint = stepper.current_time_step();
  const StateVector y1 = stepper.current_state();
  // Event functions are checked at interior points of the step too: a long high-order step
  // can hold a dip of F_n below zero and back, or several nutation periods. At least 2 checks,
  // and one per 1/64 of a rotation period 2 pi / |w| (the dip of F_n to loss of contact on the
  // reference's spin-20 top lasts about 1/20 of a period).
  // Coarse checks (8 per period) first; the fine ones only where a normal force comes within
  // 30 % of M g of zero, so a top far from lifting off pays for few checks.
  const double w = unpack(y1, t1).w_B.norm();
  const double periods = (t1 - t0) * w / (2 * M_PI);
  std::vector<double> t_chk;
  std::vector<GrazeNote> raw_chk;
  std::vector<std::vector<double>> g_chk;
  std::vector<Vec3> p_chk;  // the contact power at the check points
  auto sample = [&](int n_checks) {
    t_chk.assign(n_checks + 1, t0);
    raw_chk.assign(n_checks + 1, GrazeNote{});
    g_chk.assign(n_checks + 1, g_start);
    p_chk.assign(n_checks + 1, p_start);
    for (int k = 1; k <= n_checks; ++k) {
      t_chk[k] = k == n_checks ? t1 : t0 + (t1 - t0) * k / n_checks;
      StateVector yk;
      if (k == n_checks) yk = y1;
      else stepper.calc_state(t_chk[k], yk);
      g_chk[k] = g_all(yk, &p_chk[k]);
      raw_chk[k] = graze_last;
    }
  };
  // Checks per step, 2..1024. A step whose end is not finite (a failing explicit method on a
  // stiff scene) gets the fewest: its NaN must not reach the int conversion (undefined), and
  // the step fails on its own further on.
  auto checks = [&](double per_period) {
    const double n = std::ceil(periods * per_period);
    return std::isfinite(n) ? static_cast<int>(std::clamp(n, 2.0, 1024.0)) : 2;
  };
  sample(checks(8.0));
  const double load = dyn.body().M * dyn.body().g;
  bool near_lift = false;
  for (size_t i = 0; i < fns.size(); ++i)
    if (fns[i].kind == EvKind::NormalForce)
      for (const auto& gk : g_chk) near_lift = near_lift || gk[i] < 0.3 * load;
  if (near_lift) sample(checks(64.0));
  if (singular) {
    // The contact system of the current mode has no unique solution somewhere in the step
    // (its forces are meaningless there): a clear failure rather than events found on them.
    size_t k = 1;
    for (; k + 1 < t_chk.size(); ++k) {
      singular = false;
      (void)forces_at_noted(state_at(t_chk[k]));
      if (singular) break;
    }
    const double ts = t_chk[k];
    return end(ReferenceStatus::Failed, ts,
               std::string("the contact system of mode ") + to_string(surface_of(mode)) +
                   (mode.slot[0].graze || mode.slot[1].graze ? " (grazing)" : "") + " is singular",
               state_at(ts));
  }
  const int n_checks = static_cast<int>(t_chk.size()) - 1;
  const std::vector<double>& g1 = g_chk[n_checks];
  double best_t = t1 + 1.0;
  int best = -1;
  std::vector<std::pair<double, int>> found;
  for (size_t i = 0; i < fns.size(); ++i) {
    int k = 1;
    while (k <= n_checks && !(g_chk[k - 1][i] > 0 && g_chk[k][i] <= 0)) ++k;
    if (k > n_checks) continue;
    const double te = locate(fns[i], t_chk[k - 1], t_chk[k], g_chk[k - 1][i], g_chk[k][i]);
    found.emplace_back(te, static_cast<int>(i));
    const bool records_only = fns[i].kind == EvKind::Inversion || fns[i].kind == EvKind::Reversion;
    if (!records_only && te < best_t) {
      best_t = te;
      best = static_cast<int>(i);
    }
  }
  std::sort(found.begin(), found.end());
  for (const auto& [te, i] : found) {
    if (best >= 0 && te > best_t) break;
    if (fns[i].kind == EvKind::Inversion) owner.events_.push_back({"inversion", te, "theta crosses 90 deg downward", 0.0});
    if (fns[i].kind == EvKind::Reversion) owner.events_.push_back({"reversion", te, "theta crosses 90 deg back", 0.0});
  }
  accumulate_friction_work(t0, best >= 0 ? best_t : t1);
  for (size_t i = 0; i < fns.size(); ++i)
    if (fns[i].kind == EvKind::Touchdown)
      for (size_t k = 1; k < t_chk.size(); ++k)
        if (t_chk[k] <= (best >= 0 ? best_t : t1))
          flight_max_gap[fns[i].slot] = std::max(flight_max_gap[fns[i].slot], g_chk[k][i] - 1e-10 * dyn.body().R);
  for (size_t k = 1; k < t_chk.size(); ++k)
    if (t_chk[k] <= (best >= 0 ? best_t : t1)) track_graze(raw_chk[k]);
  if (best >= 0) {
    const StateVector yb = state_at(best_t);
    const ContactForces fb = forces_at(yb, mode);
    note_forces(fb);
    track_graze(graze_last);
    close_power_fit(contact_power(yb, fb));
  } else {
    close_power_fit(p_chk[n_checks]);
  }
  if (best >= 0) {
    pending = true;
    pending_fn = fns[best];
    pending_t = best_t;
    return;
  }
  g_start = g1;
  p_start = p_chk[n_checks];
  refresh_references(y1);
}


ReferenceModel::ReferenceModel(const Scene& scene) : body_(BodyModel::from_scene(scene)) {
  start(scene, scene_initial_state(scene), scene.initial.height > 0);
}

ReferenceModel::ReferenceModel(const Scene& scene, const BodyState& x_start) : body_(BodyModel::from_scene(scene)) {
  // In flight when the lowest surface is clear of the floor by more than round-off (and the
  // scene allows flight); otherwise on the surface it rests on, as at a scene's own start.
  double gap = surface_gap(body_, x_start, Surface::Ball);
  if (body_.stem) gap = std::min(gap, surface_gap(body_, x_start, Surface::Stem));
  start(scene, x_start, scene.contact.flight && gap > 1e-12 * body_.R);
}

void ReferenceModel::start(const Scene& scene, const BodyState& x0, bool in_flight) {
  impl_ = std::make_unique<Impl>(*this, scene);
  const double t0 = x0.t;
  t_obs_ = t0;
  const double v_scale = std::max({x0.v_WG.norm(), x0.w_B.norm() * body_.R, std::sqrt(body_.g * body_.R)});
  impl_->v_scale = v_scale;
  impl_->slip_eps = std::max(1e-7, 10.0 * scene.run.rtol) * v_scale;
  impl_->coupled_floor = 1e-3 * impl_->slip_eps * scene.contact.mu;
  impl_->slip_start_v = impl_->slip_eps;
  impl_->fit_tolerance = kFitTolerance * body_.M * v_scale * v_scale;
  const double period = std::min(2 * M_PI / std::max(x0.w_B.norm(), 1e-9), std::sqrt(body_.R / body_.g));
  impl_->dt_hint = 1e-3 * period;
  if (scene.contact.friction == FrictionLaw::Viscous && scene.contact.k > 0 && scene.run.method != "rosenbrock4") {
    // The slip of a viscous contact relaxes in about M/k; far below the motion's own time scale
    // an explicit method's step is bounded by it, and it can blow up on the first step.
    const double relax = body_.M / scene.contact.k;
    if (relax < 1e-3 * period) {
      std::ostringstream os;
      os << " (the viscous slip relaxes in M/k = " << relax << ", " << period / relax
         << " times faster than the motion: stiff for " << scene.run.method << "; run.method = \"rosenbrock4\" is made for it)";
      impl_->failure_hint = os.str();
    }
  }
  if (scene.contact.friction == FrictionLaw::Gliding && scene.contact.mu > 0 && scene.run.method != "rosenbrock4") {
    // The gliding slip relaxes in about 1 / (mu g (1 + M R^2 / A)) (F_n ~ M g): stiff likewise
    // for a large mu.
    const double relax = 1.0 / (scene.contact.mu * body_.g * (1.0 + body_.M * body_.R * body_.R / body_.A));
    if (relax < 1e-3 * period) {
      std::ostringstream os;
      os << " (the gliding slip relaxes in 1 / (mu g (1 + M R^2 / A)) = " << relax << ", " << period / relax
         << " times faster than the motion: stiff for " << scene.run.method << "; run.method = \"rosenbrock4\" is made for it)";
      impl_->failure_hint = os.str();
    }
  }
  const StateVector y0 = pack(x0);
  ContactMode none;
  impl_->y_obs = y0;
  if (in_flight) {
    // Starts in free flight; touchdowns are events like any other.
    impl_->mode = none;
    impl_->restart(t0, y0);
    impl_->ledger_obs = impl_->ledger;
    return;
  }
  // On the surface the initial state rests on: the ball, or the stem of a top started inverted.
  const bool on_stem = lower_surface(body_, x0.q_WB) == Surface::Stem;
  impl_->mode = impl_->settle(y0, {!on_stem, on_stem}, none);
  if (!impl_->mode.any_active()) {
    impl_->end(ReferenceStatus::ContactLost, t0, "F_n < 0 at the start: the floor cannot hold the top", y0);
    return;
  }
  impl_->restart(t0, impl_->project_booked(y0, t0));
  impl_->ledger_obs = impl_->ledger;
  impl_->y_obs = impl_->stepper.current_state();
}

ReferenceModel::~ReferenceModel() = default;

// A run that makes no progress ends failed instead of hanging: a step that does not advance t,
// or more than this many steps per sample interval of the way asked for. The stiffest shipped
// scene (extremes/k_high on Rosenbrock) takes ~96 steps per sample and every other one under 10,
// so 1e5 is a thousand times any real run; g = 1e300 shrinks the step to ~1e-150 s instead.
constexpr double kMaxStepsPerSample = 1e5;

void ReferenceModel::advance_to(double t) {
  Impl& m = *impl_;
  const double t_start = m.stepper.current_time();
  const long long steps_start = steps_;
  const double budget =
      kMaxStepsPerSample * (1.0 + std::max(0.0, t - t_start) / std::max(m.run.sample_interval, 1e-300));
  while (status_ == ReferenceStatus::Ok) {
    if (m.pending) {
      if (m.pending_t <= t) {
        m.handle(m.pending_fn, m.pending_t);
        continue;
      }
      break;
    }
    if (m.stepper.current_time() >= t) break;
    const double t_before = m.stepper.current_time();
    // A signal ends the run within kStepsPerStopPoll steps, however long the way to t.
    if ((steps_ - steps_start) % kStepsPerStopPoll == 0) poll_stop();
    m.step();
    const StateVector& y = m.stepper.current_state();
    for (double v : y)
      if (!std::isfinite(v)) {
        m.end(ReferenceStatus::Failed, m.stepper.current_time(), "non-finite state" + m.failure_hint, y);
        return;
      }
    const double t_now = m.stepper.current_time();
    const bool stuck = !(t_now > t_before);
    if (stuck || static_cast<double>(steps_ - steps_start) > budget) {
      std::ostringstream os;
      if (stuck)
        os << "no progress: a step does not advance t = " << t_now;
      else
        os << "no progress: more than " << budget << " steps from t = " << t_start << " to " << t
           << " (the last step was " << t_now - t_before << ")";
      os << m.failure_hint;
      m.end(ReferenceStatus::Failed, t_now, os.str(), y);
      return;
    }
  }
  if (status_ != ReferenceStatus::Ok) return;
  t_obs_ = t;
  m.y_obs = m.state_at(t);
  m.ledger_obs_valid = false;
}

BodyState ReferenceModel::state() const {
  BodyState x = unpack(impl_->y_obs, t_obs_);
  x.q_WB.normalize();
  return x;
}

double ReferenceModel::raw_quaternion_norm() const {
  const StateVector& y = impl_->stepper.current_state();
  return std::sqrt(y[6] * y[6] + y[7] * y[7] + y[8] * y[8] + y[9] * y[9]);
}

ContactForces ReferenceModel::forces() const { return impl_->dyn.evaluate(impl_->y_obs, impl_->mode, nullptr); }

Surface ReferenceModel::contact_surface() const { return surface_of(impl_->mode); }

std::pair<double, double> ReferenceModel::graze_fraction_range() const { return {impl_->graze_lo, impl_->graze_hi}; }

double ReferenceModel::graze_violation() const { return impl_->graze_violation; }

}  // namespace tippe
