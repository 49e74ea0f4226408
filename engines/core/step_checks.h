// The per-step checks every engine adapter shares, fixed-step or not: the failure limits, the
// step budget, the event probes (inversion, first stem contact, contact surface switches).
#pragma once

#include <limits>
#include <string>
#include <vector>

#include "analytic/initial_state.h"
#include "engines/core/simulator.h"

namespace tippe {

// The part of a surface's friction force that the bench applied (a viscous or gliding law), and
// its moment about the centre of mass, r_GC x F, with r_GC the lever arm the bench applied it at.
// The ledger books this part at the bench's point, not at the engine's contact point: a soft
// contact's point lies inside the penetration, and the two points' velocities differ by the spin
// times that depth (MuJoCo's two-contact slide on toy_viscous booked 3e-4 E0 of work that no
// force did, the same at every step: docs/findings/energy-gain-rule.md, "The bench's own force").
struct BenchWrench {
  Vec3 f_ball_W = Vec3::Zero(), f_stem_W = Vec3::Zero();
  Vec3 m_ball_W = Vec3::Zero(), m_stem_W = Vec3::Zero();
  // The work of these forces over the step as the engine integrated them, where the adapter
  // measured it: an engine that holds the force as a generalized force in its own coordinates
  // (MuJoCo's free joint: the torque in the body frame, turning with the body over the step)
  // does work that the lab-frame moment above misses by O(h) per unit time. NaN: booked from the
  // force and moment held in the lab frame (Bullet, ODE, DART, Siconos).
  double work = std::numeric_limits<double>::quiet_NaN();
};

// The contact forces of a step as the ledger books them, where they differ from the report's own
// (which stay the last evaluation's, for the events, the observables and the gliding law): an
// engine whose step evaluates its contact several times (MuJoCo's RK4: four stages, its velocity
// update their weighted sum) gives the weighted sum of the stages' forces, each stage's point
// moved with its centre of mass to the step's start (add_stage_forces).
struct StepMeanForces {
  bool set = false;
  double normal_ball = 0.0, normal_stem = 0.0;
  Vec3 friction_ball_W = Vec3::Zero(), friction_stem_W = Vec3::Zero();
  Vec3 p_WC_ball = Vec3::Zero(), p_WC_stem = Vec3::Zero();  // F_n-weighted sums, then points
  double weight_ball = 0.0, weight_stem = 0.0;
  BenchWrench bench;
};

// The contact forces' work over the step as the engine's own integrator integrated their power,
// where the adapter has it (Simbody: the power as state variables its integrator's stages
// advance with the motion): the ledger books it as given, with no quadrature of its own.
struct StepWork {
  bool set = false;
  double normal = 0.0, friction = 0.0;  // friction: the tangential forces', the bench's law included
};

// What an engine says about its contacts after a step.
struct ContactReport {
  bool ball = false;               // the engine has a contact on the ball geom
  bool stem = false;               // ... on the stem geom
  double normal_force = 0.0;       // sum of normal forces on the body (N or scene units)
  double normal_force_ball = 0.0;  // the part of normal_force on the ball geom
  double normal_force_stem = 0.0;  // ... on the stem geom
  bool point_valid = false;
  Vec3 p_WC = Vec3::Zero();        // engine's contact point (force-weighted mean when several)
  // Per surface, the friction force on the top (lab frame) and the F_n-weighted point: filled by
  // add_surface_force and finish_surface_points, read by contact_forces().
  Vec3 friction_ball_W = Vec3::Zero(), friction_stem_W = Vec3::Zero();
  Vec3 p_WC_ball = Vec3::Zero(), p_WC_stem = Vec3::Zero();
  double weight_ball = 0.0, weight_stem = 0.0;  // the positive F_n summed into each point
  int points_ball = 0, points_stem = 0;         // the engine's points on each (add_surface_force calls)
  BenchWrench bench;         // the part of the friction the bench applied (add_bench_friction)
  StepMeanForces step_mean;  // set by an adapter whose step's forces are not the report's
  StepWork step_work;        // set by an adapter whose integrator gives the step's work
};

// Adds a stage's report (finished) to `mean` with its weight in the step's velocity update, its
// points moved by shift_W (the stage's centre of mass to the step start's); finish_stage_forces
// turns the weighted sums into points once every stage is in.
void add_stage_forces(StepMeanForces& mean, const ContactReport& stage, double weight, const Vec3& shift_W);
void finish_stage_forces(StepMeanForces& mean);

// The potential an engine's soft contact law gives its normal force as a function of the
// penetration depth d of a surface (the elastic part of the law, its damping left out):
// U(d) = k_s / (p + 1) * max(0, d - offset)^(p + 1), i.e. the spring F = k_s (d - offset)^p.
// An adapter whose engine has such a law sets it (StepChecks::set_contact_potential); for the
// others the elastic energy is not available (NaN), never guessed.
struct ContactPotential {
  double k_ball = 0.0, k_stem = 0.0;  // stiffness per surface
  double exponent = 1.0;              // p: 1 a linear spring, 1.5 Hertz
  double offset = 0.0;                // depth at which the spring starts (ODE's surface layer)
};

// Adds one engine contact point's friction force and its point to the per-surface fields of r (the
// normal sums, flags and mean point are the adapter's own, unchanged); finish_surface_points
// turns the weighted sums into points once every point is in.
void add_surface_force(ContactReport& r, bool stem, double f_n, const Vec3& f_t_W, const Vec3& p_W);
void finish_surface_points(ContactReport& r);
// The report as the simulator interface carries it.
EngineContactForces contact_forces(const ContactReport& r);

// Limits that turn a run into a result instead of a crash (issue: failures are results).
struct FailureLimits {
  double energy_factor = 2.0;      // E above energy_factor * E0 (E0 > 0) -> diverged
  double penetration_fraction = 0.1;  // lowest surface below the floor by more than R/10 -> diverged
  double speed_factor = 100.0;     // |w| or |v_G| beyond factor * initial scale -> diverged
};

// The most steps one engine run takes: 1e9 steps are hours of any engine's time (a step costs
// microseconds), far beyond a run the bench reports on; a timestep far below the run's scale
// (1e-8 over a long run, a user's model) ends the run as failed with this said, never hangs.
inline constexpr long long kMaxEngineSteps = 1000000000LL;

// Throws std::invalid_argument ("ENGINE: set_state: ...") for a state no engine can take.
void check_settable_state(const std::string& engine, const BodyState& x);

// One run's checks and events. An adapter calls start() once its engine is built, after_step()
// after every step the engine accepted (fixed or its own), restart() after set_state, and fail()
// for what only it can see (an engine error, a limit of its own). The run's status, events and
// the state the last step ended in are read from here.
class StepChecks {
 public:
  explicit StepChecks(const BodyModel& body) : body_(body) {}

  // The initial state: the probes, E0 and the speed scale the limits are relative to.
  void start(const BodyState& x0);
  // The engine's contact law has a potential (ContactPotential); call before start().
  void set_contact_potential(const ContactPotential& p);
  // The engine's contact forces are a smooth law read at each step's end (Simbody with an
  // integrator that cannot book the work itself: ContactReport::step_work), not a solver's
  // impulse over the step: the ledger books their power at the step's end times the step instead
  // of the impulse's exact work (the force times the step's mean point velocity).
  void set_smooth_forces() { smooth_forces_ = true; }
  // The engine's contact impulse acts through the contact Jacobian of the step's end state, at the
  // point it reports there (Siconos' Moreau-Jean scheme evaluates its relations at q_n+1), not
  // the start's (a semi-implicit Euler step's collision before the solve: Bullet, ODE, MuJoCo's
  // Euler, DART): the ledger takes the force's lever arm from the end's centre of mass.
  void set_impulse_at_step_end() { impulse_at_end_ = true; }
  // A state set from outside: the probes restart from it, so no crossing is found across the jump.
  void restart(const BodyState& x);
  // After a step ending at time t in state y with the engine's contacts c: events, then the
  // limits in a fixed order (finite, penetration, energy, speed). False when the run ended.
  bool after_step(double t, const BodyState& y, const ContactReport& c);
  // The step budget: a run to `horizon` with steps of h that would take more than
  // kMaxEngineSteps ends failed at `now` before it starts them. False when it did.
  bool within_budget(double horizon, double h, double now);
  void fail(RunStatus s, double t, const std::string& why);

  bool ok() const { return status_ == RunStatus::Ok; }
  RunStatus status() const { return status_; }
  double status_time() const { return status_time_; }
  const std::string& status_detail() const { return status_detail_; }
  const std::vector<Event>& events() const { return events_; }
  // The state the last accepted step ended in (or the start's, or set_state's).
  const BodyState& last_state() const { return last_.state; }
  // The friction work of the steps so far (Simulator::friction_work).
  double friction_work() const { return friction_work_; }
  // The ledger of the steps so far (Simulator::energy_ledger): normal and friction work, the
  // elastic energy at the last state where the adapter set a contact potential; drilling work
  // and impacts are not available (the adapters report no contact torques, and an engine's
  // impacts are inside its normal work).
  EnergyLedgerTotals energy_ledger() const;

 private:
  struct StepProbe {
    BodyState state;
    double cos_theta = 1.0, gap_ball = 0.0, gap_stem = 0.0;
  };
  StepProbe probe(const BodyState& x) const;
  void add_friction_work(const BodyState& y, double h, const ContactReport& c);
  void track_events(const StepProbe& before, const StepProbe& after, const ContactReport& c);

  BodyModel body_;
  FailureLimits limits_;
  double e0_ = 0.0, speed_scale_ = 0.0;
  RunStatus status_ = RunStatus::Ok;
  double status_time_ = 0.0;
  std::string status_detail_;
  std::vector<Event> events_;
  StepProbe last_;
  bool inverted_ = false, stem_touched_ = false;
  double friction_work_ = 0.0, normal_work_ = 0.0;
  bool smooth_forces_ = false, impulse_at_end_ = false;
  bool has_potential_ = false;
  ContactPotential potential_;
  double elastic(const StepProbe& p) const;
  Surface contact_surface_ = Surface::Ball;
};

// The observables of state x with the engine's contacts c: ball and stem on the floor together,
// as the engine reports its contacts, make the sample one on both surfaces, as the reference's
// are in its two-contact phase. Jellett's J is conserved on one surface only, so such samples
// end a run of the J check (SampleSummary). Labelled by the lower surface alone, an engine's
// two-contact phase was checked as a run on the stem, and its J "drift" there (0.34 to 0.40 of J
// on extremes/tilt_near_pi, every engine alike) classed it unphysical.
Observation observe_with_contacts(const BodyModel& body, const BodyState& x, const ContactReport& c);

// The base of every engine adapter: the run's status and events are its StepChecks'.
class CheckedSimulator : public Simulator {
 public:
  RunStatus status() const override { return checks_.status(); }
  double status_time() const override { return checks_.status_time(); }
  std::string status_detail() const override { return checks_.status_detail(); }
  std::vector<Event> events() const override { return checks_.events(); }
  size_t event_count() const override { return checks_.events().size(); }
  double friction_work() const override { return checks_.friction_work(); }
  EnergyLedgerTotals energy_ledger() const override { return checks_.energy_ledger(); }

 protected:
  explicit CheckedSimulator(const Scene& scene) : checks_(BodyModel::from_scene(scene)) {}
  StepChecks checks_;
};

}  // namespace tippe
