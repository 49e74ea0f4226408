// The one interface every simulator (the analytic reference and each engine) implements.
#pragma once

#include <cstddef>
#include <limits>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "analytic/observables.h"
#include "analytic/scene.h"
#include "analytic/state.h"

namespace tippe {

// How a run ended (or is going). Anything but Ok ends the run at status_time.
enum class RunStatus { Ok, ContactLost, Diverged, Unphysical, Clamped, Failed };
const char* to_string(RunStatus s);

// An event located in time: "inversion" (theta crosses 90 deg), "stem_contact" (first stem
// touchdown), "switch" (contact surface changes), "stick", "slip", "contact_lost",
// "touchdown", "two_contact" ...
struct Event {
  std::string name;
  double time = 0.0;
  std::string detail;
  double value = 0.0;  // event-specific number (e.g. energy removed by an impact)
};

struct WorkCounters {
  long long steps = 0;            // accepted integrator or engine steps
  long long rhs_evaluations = 0;  // analytic: right-hand-side calls; engines: steps
  long long solver_iterations = 0;
  // The run's time, filled by run_simulator (harness/measure/run.cpp), never by a simulator: the
  // span of its sampling loop (every advance_to and the sampling between them), each clock read
  // once at either end. Per advance_to, a thread CPU clock read (a system call) cost more than a
  // sample.
  double wall_seconds = 0.0;
  double cpu_seconds = 0.0;       // CPU time of the calling thread
};

// Mass properties as the engine holds them, read back from its own objects (never the scene's
// numbers copied): mass, the centre of mass relative to G in the body frame B (zero when the
// engine's body is built at G) and the inertia about G in B.
struct MassReadback {
  double mass = 0.0;
  Vec3 p_GCm_B = Vec3::Zero();
  Eigen::Matrix3d I_G_B = Eigen::Matrix3d::Zero();
};

// One contact surface's force on the top over the last step, as the engine computed it (its
// solver's or its force law's, never recomputed by the bench): the floor's normal is +z, so F_n is
// the force's z part and the friction force F_t its horizontal part. With several engine points on
// one surface, F_n and F_t are their sums and p_WC their F_n-weighted mean.
struct SurfaceContactForce {
  bool active = false;        // the engine reports a contact on this surface
  double f_n = 0.0;           // normal force
  Vec3 f_t_W = Vec3::Zero();  // tangential (friction) force, lab frame
  bool point_valid = false;   // p_WC is known (F_n > 0)
  Vec3 p_WC = Vec3::Zero();   // point of application, lab frame
  // The contact points the engine reported on this surface in the step (summed over its internal
  // steps where it takes several), with or without force: a sphere on a plane touches at one, and
  // more is the engine's own (a cached manifold, a box face's corners), never the bench's.
  int points = 0;
};

// The forces at the top's two contact surfaces. Where the bench applies the friction law itself
// (viscous, gliding), F_t is the force the bench applied in that step.
struct EngineContactForces {
  SurfaceContactForce ball, stem;
  Vec3 friction_W() const { return ball.f_t_W + stem.f_t_W; }
};

// A run's energy ledger so far (docs/energy-ledger.md): the work the contact forces did on the top
// (positive: energy given to it), the energy removed at impacts, the energy stored in a soft
// contact. NaN marks a term the simulator cannot give (never a made-up number): an engine whose
// contact stores energy by a law the bench cannot evaluate, torques an engine does not report,
// impacts an engine resolves inside its normal force. E(t) - E0 - (normal + friction + drilling
// work) + impact_energy is the simulator's numerical energy (integrator, constraint stabilization;
// NaN terms count as 0 there, and the record says which were not available).
struct EnergyLedgerTotals {
  double normal_work = std::numeric_limits<double>::quiet_NaN();    // F_n v_C.n h summed
  double friction_work = std::numeric_limits<double>::quiet_NaN();  // F_t . v_C h summed
  double drilling_work = std::numeric_limits<double>::quiet_NaN();  // torques about the normal and rolling torques . w h
  double impact_energy = std::numeric_limits<double>::quiet_NaN();  // removed at impacts (>= 0)
  double elastic_energy = std::numeric_limits<double>::quiet_NaN(); // stored in the soft contact now (>= 0)
  // The work terms and impacts as counted in the numerical energy (NaN as 0).
  double accounted() const;
};

// Ordered key=value pairs of every setting that decides accuracy, as used in the run.
using SettingsList = std::vector<std::pair<std::string, std::string>>;

class Simulator {
 public:
  virtual ~Simulator() = default;
  virtual std::string engine() const = 0;
  // Engine library version ("mujoco 2.2.2"), for provenance.
  virtual std::string version() const = 0;
  // Advances to time t (engines: to the last step not beyond t + half a step). Stops early
  // when the status leaves Ok; never throws for a diverging engine.
  virtual void advance_to(double t) = 0;
  virtual Observation observe() const = 0;
  // The body's state at the simulator's current time (t, p_WG, q_WB, v_WG, w_B of G).
  virtual BodyState state() const = 0;
  // Replaces position, attitude and velocities at the current time (x.t is ignored); events,
  // work and status are kept. Throws std::invalid_argument for a non-finite state.
  virtual void set_state(const BodyState& x) = 0;
  virtual MassReadback mass_properties() const = 0;
  virtual WorkCounters work() const = 0;
  virtual RunStatus status() const = 0;
  virtual double status_time() const = 0;
  virtual std::string status_detail() const = 0;
  virtual std::vector<Event> events() const = 0;
  // events().size() without the copy (a run asks after every sample).
  virtual size_t event_count() const { return events().size(); }
  virtual SettingsList settings() const = 0;
  // The contact forces of the last step (of the initial state before the first): an adapter
  // supplies what its engine computed; the default is a simulator that reports none.
  virtual EngineContactForces contact_forces() const { return {}; }
  // The work of the friction forces of contact_forces() over the run so far: per step, F_t . v_C
  // times the step at each surface, v_C the velocity of the top's material point at the force's
  // point, the mean of the step's start and end (exact for an impulse; docs/energy-ledger.md).
  // NaN where the simulator reports no contact forces.
  virtual double friction_work() const;
  // The energy ledger of the run so far (EnergyLedgerTotals). The default: nothing available.
  virtual EnergyLedgerTotals energy_ledger() const { return {}; }
  // Notes on approximations in force (e.g. "rolling approximated by mu = 1e3").
  virtual std::vector<std::string> notes() const { return {}; }
};

// Builds a simulator by its registered name (engines/registry.h); throws std::invalid_argument
// for an unknown engine or an invalid setting.
std::unique_ptr<Simulator> make_simulator(const std::string& engine, const Scene& scene);
// Every registered name, the reference first.
std::vector<std::string> available_engines();

}  // namespace tippe
