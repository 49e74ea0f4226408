// The state of a reference run and its steps, shared by the reference's source files (internal, not installed).
#pragma once

#include <array>
#include <limits>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "analytic/reference_model.h"
#include "analytic/detail/dense_stepper.h"

namespace tippe {
namespace reference_detail {

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
inline constexpr double kHoldApex = 1e-6;

// How far apart the two interpolants' work to the step's end may be where a sample takes it
// from them (ReferenceModel::Impl::PowerFit, reference_ledger.cpp), as a share of the scene's
// energy scale M v_scale^2. 1e-13: four orders below the ledger's closure bound (1e-9 E0) and
// below its Gauss-5 booking error on Bulirsch-Stoer (~7e-10 E0). Measured on every shipped scene against the per-sample quadrature
// it replaces: the samples' ledgers move by at most 8e-11 E0 (rutstam_gliding_ball; 99 % of
// every scene's samples by less than 1e-12 E0), the run's final ledger by round-off
// (docs/findings/reference-sample-cost.md).
inline constexpr double kFitTolerance = 1e-13;

inline const char* slot_name(int s) { return s == 0 ? "ball" : "stem"; }

inline Surface surface_of(const ContactMode& m) {
  const bool b = m.slot[0].active, s = m.slot[1].active;
  return b && s ? Surface::Both : b ? Surface::Ball : s ? Surface::Stem : Surface::None;
}

inline std::string fmt(double v) {
  std::ostringstream os;
  os.precision(10);
  os << v;
  return os.str();
}

}  // namespace reference_detail

// Integration and observation: reference_model.cpp; event functions and their handling:
// reference_events.cpp; contact modes, projections and the run's end: reference_modes.cpp; the
// energy ledger's contact work: reference_ledger.cpp.
struct ReferenceModel::Impl {
  using DenseStepper = reference_detail::DenseStepper;
  using System = reference_detail::System;
  using EvKind = reference_detail::EvKind;
  using EvFn = reference_detail::EvFn;

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
  // The contact power over the last booked interval [a, b] (b = ledger_t), at a, at the five
  // Gauss nodes the booking evaluated and at b (the end's check point or event): a sample inside
  // the interval takes the work from its time to b from their interpolant, with no contact solve
  // of its own, where that agrees with the interpolant without a's value to fit_tolerance;
  // otherwise from power_halves, or the quadrature of [t, b] as every sample did before
  // (ReferenceModel::energy_ledger).
  struct PowerFit {
    bool valid = false;
    double a = 0.0, b = 0.0;
    std::array<Vec3, 7> p{};  // at a, at the Gauss nodes of [a, b], at b
    // The work from t in [a, b] to b of the interpolated power: through all seven values
    // (`with_start`) or through the last six.
    Vec3 work_to_end(double t, bool with_start) const;
    // The first, where the two agree to `tolerance`.
    bool trusted_work_to_end(double t, double tolerance, Vec3& work) const;
  } power_fit;
  // The same on either half of power_fit's interval, fitted on demand (refine_power_fit: ten
  // contact solves) once a second sample of the step finds power_fit not trusted; the first
  // takes the quadrature (five), so a step sampled once costs no more than before.
  std::array<PowerFit, 2> power_halves{};
  int fit_misses = 0;  // samples of power_fit's interval that did not trust it
  void refine_power_fit();
  // The work from t (in power_fit's interval) to its end from power_fit or its halves, where
  // trusted; false where the caller takes the quadrature.
  bool fitted_work_to_end(double t, Vec3& work);
  Vec3 p_start = Vec3::Zero();  // the contact power at the stepper's current time
  double fit_tolerance = 0.0;   // in energy, set at the start: see kFitTolerance
  double graze_lo = std::numeric_limits<double>::infinity(), graze_hi = -std::numeric_limits<double>::infinity();
  bool singular = false;  // a check point met a contact system without a unique solution

  Impl(ReferenceModel& o, const Scene& scene)
      : owner(o),
        dyn(BodyModel::from_scene(scene), scene.contact),
        run(scene.run),
        flight_allowed(scene.contact.flight),
        stepper_ptr(reference_detail::make_stepper(
            scene.run, [this](const StateVector& y, StateVector& scale) { dyn.slip_scale(y, mode, scale); })),
        stepper(*stepper_ptr) {
    system = [this](const StateVector& y, StateVector& dy, double) {
      ++owner.rhs_evals_;
      dyn.evaluate(y, mode, &dy);
    };
  }

  ContactForces forces_at(const StateVector& y, const ContactMode& m);

  void build_event_functions();

  void refresh_references(const StateVector& y);

  Vec3 coupled_slip(const ContactForces& f, double w_z, int s) const;
  // Its size in velocity units, |(v, (mu_d / mu) w_z)|, for the stick threshold slip_eps.
  double coupled_speed(const Vec3& u) const { return u.norm() / dyn.contact().mu; }

  double g(const EvFn& fn, const StateVector& y, const ContactForces* f);

  // Notes a singular system and, in graze_last, the graze fraction and how far a grazing
  // contact's neighbouring fields are consistent themselves; track_graze() takes a note into
  // the ranges, for points of the motion only (a check point past an event is not one).
  struct GrazeNote {
    bool grazing = false;
    double fraction = 0.0, violation = 0.0;
  } graze_last;
  void note_forces(const ContactForces& f);
  void track_graze(const GrazeNote& n);
  double graze_violation = 0.0;

  // The event functions at y; `power`: the contact power there too, from the same forces.
  std::vector<double> g_all(const StateVector& y, Vec3* power = nullptr);

  StateVector state_at(double t);

  double locate(const EvFn& fn, double a, double b, double ga, double gb);

  ContactForces forces_at_noted(const StateVector& y);

  Vec3 contact_power(const StateVector& y);
  Vec3 contact_power(const StateVector& y, const ContactForces& f) const;

  // `nodes`: where given, the power at the five Gauss nodes (zero where no contact is held).
  Vec3 gauss5(double a, double b, std::array<Vec3, 5>* nodes = nullptr);
  Vec3 friction_work(double a, double b, std::array<Vec3, 5>* nodes = nullptr);
  void accumulate_friction_work(double a, double b);
  // The power at the end of the booked interval (from the check point or the event there): the
  // fit accumulate_friction_work opened is complete.
  void close_power_fit(const Vec3& p_end);

  double gap_acceleration(const StateVector& y, const ContactMode& m, int k);

  void restart(double t, const StateVector& y, double first_dt = 0.0);

  void step();

  Vec3 coupled_slide_dir(const ContactForces& f, int s) const;

  ContactMode settle(const StateVector& y, std::array<bool, 2> candidates, const ContactMode& prev);

  StateVector project(const StateVector& y, StateVector* positioned = nullptr);

  StateVector project_booked(const StateVector& y, double t);

  void set_mode(const ContactMode& m, double t);

  void end(ReferenceStatus status, double t, const std::string& why, const StateVector& y);

  void handle(const EvFn& fn, double te);
};

}  // namespace tippe
