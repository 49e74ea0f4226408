// The analytic reference: adaptive integration with dense output (Bulirsch-Stoer, Dormand-Prince
// 5(4) or Rosenbrock4), events located by TOMS 748 root finding on the dense output, mode
// changes (impacts, stick/slip, release) applied at the event.
#include "reference_model.h"

#include "boost_binomial.h"  // first: it must precede every Boost.Math and Odeint header
#include <boost/math/tools/toms748_solve.hpp>
#include <boost/numeric/odeint.hpp>

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <sstream>
#include <tuple>

#include "initial_state.h"

namespace tippe {

namespace odeint = boost::numeric::odeint;

namespace {

using Dopri = odeint::runge_kutta_dopri5<StateVector>;
using System = std::function<void(const StateVector&, StateVector&, double)>;

// The dense-output steppers behind one interface, so that the method is a run setting.
struct DenseStepper {
  virtual ~DenseStepper() = default;
  virtual void initialize(const StateVector& y, double t, double dt) = 0;
  virtual std::pair<double, double> do_step(const System& sys) = 0;
  virtual void calc_state(double t, StateVector& y) = 0;
  virtual const StateVector& current_state() const = 0;
  virtual double current_time() const = 0;
  virtual double current_time_step() const = 0;
};

template <class S>
struct DenseStepperOf final : DenseStepper {
  explicit DenseStepperOf(S s) : stepper(std::move(s)) {}
  void initialize(const StateVector& y, double t, double dt) override { stepper.initialize(y, t, dt); }
  std::pair<double, double> do_step(const System& sys) override { return stepper.do_step(sys); }
  void calc_state(double t, StateVector& y) override { stepper.calc_state(t, y); }
  const StateVector& current_state() const override { return stepper.current_state(); }
  double current_time() const override { return stepper.current_time(); }
  double current_time_step() const override { return stepper.current_time_step(); }
  S stepper;
};

// Rosenbrock4 (L-stable, order 4, dense output of order 3) for stiff runs: the viscous law's
// slip relaxes at the rate ~k/M, which limits the explicit methods' step to ~M/k however
// smooth the motion. Boost's stepper works on ublas vectors; this converts at the interface.
class RosenbrockStepper final : public DenseStepper {
 public:
  using UVector = boost::numeric::ublas::vector<double>;
  using UMatrix = boost::numeric::ublas::matrix<double>;
  using Stepper = odeint::rosenbrock4_dense_output<odeint::rosenbrock4_controller<odeint::rosenbrock4<double>>>;

  RosenbrockStepper(double atol, double rtol, double max_dt)
      : stepper_(odeint::rosenbrock4_controller<odeint::rosenbrock4<double>>(atol, rtol, max_dt)), u_(kN), jac_(kN, kN) {}

  void initialize(const StateVector& y, double t, double dt) override {
    to_ublas(y, u_);
    stepper_.initialize(u_, t, dt);
    y_ = y;
  }

  std::pair<double, double> do_step(const System& sys) override {
    auto rhs = [&](const UVector& x, UVector& dxdt, double t) {
      StateVector xs, fs;
      from_ublas(x, xs);
      sys(xs, fs, t);
      to_ublas(fs, dxdt);
    };
    // The controller retries a rejected step from the same state, in the same mode: the
    // Jacobian is kept for those retries.
    bool have_jac = false;
    StateVector x_jac{};
    auto jacobian = [&](const UVector& x, UMatrix& J, const double& t, UVector& dfdt) {
      // The right-hand side does not depend on t (an autonomous system).
      for (size_t i = 0; i < kN; ++i) dfdt[i] = 0.0;
      StateVector x0;
      from_ublas(x, x0);
      if (!have_jac || x0 != x_jac) {
        fill_jacobian(sys, x0, t, jac_);
        x_jac = x0;
        have_jac = true;
      }
      J = jac_;
    };
    const auto span = stepper_.do_step(std::make_pair(rhs, jacobian));
    from_ublas(stepper_.current_state(), y_);
    return span;
  }

  void calc_state(double t, StateVector& y) override {
    stepper_.calc_state(t, u_);
    from_ublas(u_, y);
  }
  const StateVector& current_state() const override { return y_; }
  double current_time() const override { return stepper_.current_time(); }
  double current_time_step() const override { return stepper_.current_time_step(); }

 private:
  static constexpr size_t kN = std::tuple_size<StateVector>::value;

  // Central differences, h_j = cbrt(eps) * scale_j: truncation O(h^2) balances round-off
  // O(eps / h), so J is right to ~1e-10 relative. Forward differences (~1e-8) do not do: the
  // embedded error estimate uses the same J, so an error in J escapes the step control (it
  // made the tilt error 50x larger at rtol 1e-10). scale_j is the larger of |y_j| and the norm
  // of its group (p, v, q, omega; 1 if that is 0), so a zero component is not perturbed at
  // the scale of round-off.
  static void fill_jacobian(const System& sys, const StateVector& x0, double t, UMatrix& J) {
    static constexpr size_t kGroups[5] = {0, 3, 6, 10, kN};
    const double cbrt_eps = std::cbrt(std::numeric_limits<double>::epsilon());
    for (int grp = 0; grp < 4; ++grp) {
      double norm = 0.0;
      for (size_t i = kGroups[grp]; i < kGroups[grp + 1]; ++i) norm += x0[i] * x0[i];
      norm = std::sqrt(norm);
      for (size_t j = kGroups[grp]; j < kGroups[grp + 1]; ++j) {
        const double scale = std::max({std::abs(x0[j]), norm, norm > 0 ? 0.0 : 1.0});
        StateVector xp = x0, xm = x0, fp, fm;
        xp[j] = x0[j] + cbrt_eps * scale;
        const double h = xp[j] - x0[j];  // the step as represented
        xm[j] = x0[j] - h;
        sys(xp, fp, t);
        sys(xm, fm, t);
        for (size_t i = 0; i < kN; ++i) J(i, j) = (fp[i] - fm[i]) / (2 * h);
      }
    }
  }
  static void to_ublas(const StateVector& y, UVector& u) {
    for (size_t i = 0; i < kN; ++i) u[i] = y[i];
  }
  static void from_ublas(const UVector& u, StateVector& y) {
    for (size_t i = 0; i < kN; ++i) y[i] = u[i];
  }
  Stepper stepper_;
  UVector u_;  // scratch for calc_state and initialize
  UMatrix jac_;
  StateVector y_{};
};

std::unique_ptr<DenseStepper> make_stepper(const RunSpec& run) {
  const double max_dt = run.duration / 64.0;
  if (run.method == "rosenbrock4") return std::make_unique<RosenbrockStepper>(run.atol, run.rtol, max_dt);
  if (run.method == "dopri5") {
    auto s = odeint::make_dense_output(run.atol, run.rtol, max_dt, Dopri());
    return std::make_unique<DenseStepperOf<decltype(s)>>(std::move(s));
  }
  // Gragg-Bulirsch-Stoer extrapolation: high and adaptive order, so few, long steps at the
  // tight tolerances a reference needs; its dense output is a Hermite polynomial of high order.
  odeint::bulirsch_stoer_dense_out<StateVector> s(run.atol, run.rtol, 1.0, 1.0, max_dt);
  return std::make_unique<DenseStepperOf<decltype(s)>>(std::move(s));
}

enum class EvKind { Inversion, Reversion, GrazeLift, GrazePress, GrazePinch, NormalForce, SlipReversal, ConeExit, DrillReversal, DrillConeExit,
                    SlipStartEnd, SlipZero, SlipSmall, Touchdown };
struct EvFn {
  EvKind kind;
  int slot;
};

// The cascade closure: a contact that an impact sets bouncing with an apex below kHoldApex R
// is held instead. In a plastic ball/stem cascade the apex falls by a fixed ratio per impact
// (~0.3 on the source top), so the cascade is Zeno: infinitely many impacts before a finite
// time. 1e-6 R is a physical bound, stated in the scene's units and not tied to the
// integrator: far below surface roughness (15 nm on a 15 mm toy top) and below what any
// engine resolves, and far above the position error of a step at the loosest tolerance
// the reference is used with (rtol 1e-8 of z_G ~ R: 1e-8 R), so every method and tolerance
// resolves the bounces above it alike and makes the same decisions.
constexpr double kHoldApex = 1e-6;

const char* slot_name(int s) { return s == 0 ? "ball" : "stem"; }

Surface surface_of(const ContactMode& m) {
  const bool b = m.slot[0].active, s = m.slot[1].active;
  return b && s ? Surface::Both : b ? Surface::Ball : s ? Surface::Stem : Surface::None;
}

std::string fmt(double v) {
  std::ostringstream os;
  os.precision(10);
  os << v;
  return os.str();
}

}  // namespace

struct ReferenceModel::Impl {
  ReferenceModel& owner;
  ContactDynamics dyn;
  RunSpec run;
  bool flight_allowed;
  ContactMode mode;
  std::unique_ptr<DenseStepper> stepper_ptr;
  DenseStepper& stepper;
  StateVector y_obs{};
  std::vector<EvFn> fns;
  std::vector<double> g_start;
  std::array<Vec3, 2> ref_dir{Vec3::UnitX(), Vec3::UnitX()};
  std::array<Vec3, 2> ref_coupled{Vec3::UnitX(), Vec3::UnitX()};  // coupled law: see ContactSlot::coupled_dir
  double drill_ref_sign = 1.0;
  bool pending = false;
  EvFn pending_fn{EvKind::Inversion, 0};
  double pending_t = 0.0;
  bool stem_touched = false;
  // Per slot, while it is off the floor: whether it left at rest (a release or a lift, not a
  // bounce) and the highest gap seen at the check points since; `unresolved_noted`: the
  // `unresolved` event has been recorded (once a run).
  std::array<bool, 2> released_at_rest{false, false};
  std::array<double, 2> flight_max_gap{0.0, 0.0};
  bool unresolved_noted = false;
  double v_scale = 0.0, slip_eps = 0.0;
  // The slip (in velocity units, coupled_speed() under the coupled law) up to which a slip
  // started from zero takes the solved direction (ContactSlot::slip_start): slip_eps, the
  // slip the reference calls zero anyway. The solved direction leads the true one by its
  // relaxation time |v| / (mu F_n |W|) times its turning rate, which costs momentum of order
  // (w t_s / 3) slip_start_v by the end of the start (t_s its duration, w the turning rate);
  // beyond it the integrator follows the direction's relaxation itself, a stiff phase whose
  // number of steps grows as 1 / t_s. Measured on leine_glocker at mu = 0.02, tilt 1 (three
  // slip starts, dopri5): the inversion time 13.4362338872 s is the same to all ten digits for
  // slip_start_v = 1e-2, 1e-1 and 1 slip_eps; on the coupled twin, 1e-2 slip_eps still stalls
  // dopri5 in the stiff phase after the start (0.96 ms after it) and 1e-1 and 1 pass.
  double slip_start_v = 0.0;
  // Coupled law: the generalised slip below which its direction is the slot's reference
  // (ContactSlot::coupled_floor): 1e-3 of the stick threshold, far above the round-off of a
  // slip zeroed at a restart and far below any slip the motion resolves.
  double coupled_floor = 0.0;
  // Coulomb law (either drilling law), per slot: a contact that has just left stick starts from
  // exactly zero slip (project() zeroes the drift of the stuck integration), so that it starts
  // sliding in the direction the stuck forces give (slip_dir_W, coupled_slide_dir), not in that
  // of the drift. A drift against that direction is otherwise a self-consistent wrong branch of
  // the continued law: the reference flips the force to its own side, so the force drives the
  // slip and the friction work falls without bound (measured on leine_glocker at mu = 0.02,
  // tilt 1 rad: E rose to 3.4 E0 in 14 s after the slip start at 7.537 s, the ledger closed).
  std::array<bool, 2> zero_slip{false, false};
  std::array<bool, 2> fresh_slip{false, false};  // ... and its SlipReversal starts positive (restart)
  // The same for the decoupled drilling torque: a spin about the vertical that leaves drilling
  // stick starts from exactly zero (project() zeroes its drift) with the sign the stuck torque
  // gives, and its DrillReversal starts positive.
  std::array<bool, 2> zero_drill{false, false};
  std::array<bool, 2> fresh_drill{false, false};
  double dt_hint = 0.0;
  std::string failure_hint;  // appended to a "non-finite state" failure: what to try instead
  long long events_in_burst = 0;
  System system;
  double burst_start = -1.0;
  EnergyLedger ledger;      // booked up to ledger_t (the end of the last step or its event)
  EnergyLedger ledger_obs;  // the same at the observed time, when ledger_obs_valid
  bool ledger_obs_valid = true;
  double ledger_t = 0.0;
  double graze_lo = std::numeric_limits<double>::infinity(), graze_hi = -std::numeric_limits<double>::infinity();
  bool singular = false;  // a check point met a contact system without a unique solution

  Impl(ReferenceModel& o, const Scene& scene)
      : owner(o),
        dyn(BodyModel::from_scene(scene), scene.contact),
        run(scene.run),
        flight_allowed(scene.contact.flight),
        stepper_ptr(make_stepper(scene.run)),
        stepper(*stepper_ptr) {
    system = [this](const StateVector& y, StateVector& dy, double) {
      ++owner.rhs_evals_;
      dyn.evaluate(y, mode, &dy);
    };
  }

  ContactForces forces_at(const StateVector& y, const ContactMode& m) {
    ++owner.rhs_evals_;
    return dyn.evaluate(y, m, nullptr);
  }

  void build_event_functions() {
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

  void refresh_references(const StateVector& y) {
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
  Vec3 coupled_slip(const ContactForces& f, double w_z, int s) const {
    const ContactSpec& c = dyn.contact();
    return Vec3(c.mu * f.slip_W[s].x(), c.mu * f.slip_W[s].y(), c.drilling * w_z);
  }
  // Its size in velocity units, |(v, (mu_d / mu) w_z)|, for the stick threshold slip_eps.
  double coupled_speed(const Vec3& u) const { return u.norm() / dyn.contact().mu; }

  double g(const EvFn& fn, const StateVector& y, const ContactForces* f) {
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

  // Notes a singular system and, in graze_last, the graze fraction and how far a grazing
  // contact's neighbouring fields are consistent themselves; track_graze() takes a note into
  // the ranges, for points of the motion only (a check point past an event is not one).
  struct GrazeNote {
    bool grazing = false;
    double fraction = 0.0, violation = 0.0;
  } graze_last;
  void note_forces(const ContactForces& f) {
    if (!f.solvable) singular = true;
    graze_last = GrazeNote{};
    for (int s = 0; s < 2; ++s)
      if (mode.slot[s].active && mode.slot[s].graze)
        graze_last = {true, f.graze_fraction[s], std::max({f.graze_lifted_accel[s], -f.graze_loaded_accel[s], 0.0})};
  }
  void track_graze(const GrazeNote& n) {
    if (!n.grazing) return;
    graze_lo = std::min(graze_lo, n.fraction);
    graze_hi = std::max(graze_hi, n.fraction);
    graze_violation = std::max(graze_violation, n.violation);
  }
  double graze_violation = 0.0;

  std::vector<double> g_all(const StateVector& y) {
    const ContactForces f = forces_at(y, mode);
    note_forces(f);
    std::vector<double> out(fns.size());
    for (size_t i = 0; i < fns.size(); ++i) out[i] = g(fns[i], y, &f);
    return out;
  }

  StateVector state_at(double t) {
    StateVector y;
    if (t >= stepper.current_time()) return stepper.current_state();
    stepper.calc_state(t, y);
    return y;
  }

  double locate(const EvFn& fn, double a, double b, double ga, double gb) {
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

  ContactForces forces_at_noted(const StateVector& y) {
    const ContactForces f = forces_at(y, mode);
    note_forces(f);
    return f;
  }

  // Power of the contact forces and torques on the body (<= 0 for a dissipative law; the
  // normal force's share is its work on the drift of a held contact, tolerance-sized).
  double contact_power(const StateVector& y) {
    const ContactForces f = forces_at(y, mode);
    const BodyState x = unpack(y, 0);
    const double wz = (x.q_WB.normalized() * x.w_B).z();
    double p = 0.0;
    for (int s = 0; s < 2; ++s) {
      if (!mode.slot[s].active) continue;
      p += f.force_W[s].dot(dyn.contact_velocity(x, s)) + f.drill_torque[s] * wz;
    }
    return p;
  }

  // Friction work over [a, b] inside the last step (dense output), 5-point Gauss-Legendre
  // (exact to degree 9). Every mode change ends an interval, so the power is smooth on it;
  // measured against E(t) the ledger closes to ~1e-11 E0 (dopri5) and ~7e-10 E0 (bulirsch_stoer,
  // whose own energy error near the end of a graze is that size, see GrazePinch).
  double gauss5(double a, double b) {
    static constexpr double xg[5] = {-0.9061798459386640, -0.5384693101056831, 0.0, 0.5384693101056831, 0.9061798459386640};
    static constexpr double wg[5] = {0.2369268850561891, 0.4786286704993665, 0.5688888888888889, 0.4786286704993665, 0.2369268850561891};
    const double half = 0.5 * (b - a), mid = 0.5 * (a + b);
    double sum = 0.0;
    for (int i = 0; i < 5; ++i) sum += wg[i] * contact_power(state_at(mid + half * xg[i]));
    return half * sum;
  }
  double friction_work(double a, double b) {
    if (!(b > a) || !mode.any_active()) return 0.0;
    return -gauss5(a, b);
  }
  void accumulate_friction_work(double a, double b) {
    ledger.friction += friction_work(a, b);
    ledger_t = b;
  }

  // Second derivative of the gap of slot k (acceleration of its sphere centre along z).
  double gap_acceleration(const StateVector& y, const ContactMode& m, int k) {
    StateVector dy;
    ++owner.rhs_evals_;
    dyn.evaluate(y, m, &dy);
    const BodyState x = unpack(y, 0);
    const Quat q = x.q_WB.normalized();
    const Vec3 w_W = q * x.w_B, wdot_W = q * Vec3(dy[10], dy[11], dy[12]);
    const Vec3 r_GO = dyn.geometry(x, k).r_GO_W;
    return dy[5] + wdot_W.cross(r_GO).z() + w_W.cross(w_W.cross(r_GO)).z();
  }

  void restart(double t, const StateVector& y, double first_dt = 0.0) {
    double dt = dt_hint > 0 ? dt_hint : 1e-4;
    if (first_dt > 0) dt = std::min(dt, first_dt);
    stepper.initialize(y, t, dt);
    build_event_functions();
    refresh_references(y);
    g_start = g_all(y);
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
  }

  void step() {
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
    auto sample = [&](int n_checks) {
      t_chk.assign(n_checks + 1, t0);
      raw_chk.assign(n_checks + 1, GrazeNote{});
      g_chk.assign(n_checks + 1, g_start);
      for (int k = 1; k <= n_checks; ++k) {
        t_chk[k] = k == n_checks ? t1 : t0 + (t1 - t0) * k / n_checks;
        StateVector yk;
        if (k == n_checks) yk = y1;
        else stepper.calc_state(t_chk[k], yk);
        g_chk[k] = g_all(yk);
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
      note_forces(forces_at(state_at(best_t), mode));
      track_graze(graze_last);
    }
    if (best >= 0) {
      pending = true;
      pending_fn = fns[best];
      pending_t = best_t;
      return;
    }
    g_start = g1;
    refresh_references(y1);
  }

  // Coupled law: the direction of the generalised slip in which a contact whose sticking
  // forces (F_t, tau) have left the ellipse starts to slide: the slip that makes the sliding
  // law's force point as the sticking one does, u ~ -(F_t / mu, tau / mu_d) (the normal of
  // the ellipse at (F_t, tau) scaled back to its boundary).
  Vec3 coupled_slide_dir(const ContactForces& f, int s) const {
    const ContactSpec& c = dyn.contact();
    const Vec3 u(-f.force_W[s].x() / c.mu, -f.force_W[s].y() / c.mu, -f.drill_torque[s] / c.drilling);
    return u.norm() > 0 ? Vec3(u.normalized()) : ref_coupled[s];
  }

  ContactMode settle(const StateVector& y, std::array<bool, 2> candidates, const ContactMode& prev) {
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
  StateVector project(const StateVector& y, StateVector* positioned = nullptr) {
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
  StateVector project_booked(const StateVector& y, double t) {
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

  void set_mode(const ContactMode& m, double t) {
    const Surface before = surface_of(mode), after = surface_of(m);
    mode = m;
    if (before != after) {
      owner.events_.push_back({"switch", t, std::string(to_string(before)) + " -> " + to_string(after),
                               static_cast<double>(static_cast<int>(after))});
      if (after == Surface::Both) owner.events_.push_back({"two_contact", t, "ball and stem held together", 0.0});
    }
  }

  void end(ReferenceStatus status, double t, const std::string& why, const StateVector& y) {
    owner.status_ = status;
    owner.status_time_ = t;
    owner.status_detail_ = why;
    owner.events_.push_back({status == ReferenceStatus::ContactLost ? "contact_lost" : "failed", t, why, 0.0});
    owner.t_obs_ = t;
    y_obs = y;
    ledger_obs = ledger;
    ledger_obs_valid = true;
  }

  void handle(const EvFn& fn, double te) {
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
    for (int k = 0; k < 2; ++k)
      if (!next.slot[k].active && (mode.slot[k].active || (fn.kind == EvKind::Touchdown && k == s))) {
        released_at_rest[k] = fn.kind != EvKind::Touchdown;
        flight_max_gap[k] = 0.0;
      }
    set_mode(next, te);
    if (!mode.any_active() && !flight_allowed) return end(ReferenceStatus::ContactLost, te, "no contact can hold", y);
    restart(te, project_booked(y, te), first_dt);
  }
};

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

EnergyLedger ReferenceModel::energy_ledger() const {
  // On demand: the friction work from the observed time to the end of what is booked, on the
  // last step's dense output (costs a quadrature, so not at every observation).
  Impl& m = *impl_;
  if (!m.ledger_obs_valid) {
    m.ledger_obs = m.ledger;
    if (status_ == ReferenceStatus::Ok && t_obs_ < m.ledger_t) m.ledger_obs.friction -= m.friction_work(t_obs_, m.ledger_t);
    m.ledger_obs_valid = true;
  }
  return m.ledger_obs;
}

std::pair<double, double> ReferenceModel::graze_fraction_range() const { return {impl_->graze_lo, impl_->graze_hi}; }

double ReferenceModel::graze_violation() const { return impl_->graze_violation; }

}  // namespace tippe
