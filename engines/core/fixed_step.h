// Shared stepping loop of the fixed-step engines: events, failure classification, viscous and
// gliding laws, work.
#pragma once

#include <string>
#include <vector>

#include "../../analytic/initial_state.h"
#include "registry.h"
#include "simulator.h"

namespace tippe {

// What an engine says about its contacts after a step.
struct ContactReport {
  bool ball = false;               // the engine has a contact on the ball geom
  bool stem = false;               // ... on the stem geom
  double normal_force = 0.0;       // sum of normal forces on the body (N or scene units)
  double normal_force_ball = 0.0;  // the part of normal_force on the ball geom
  double normal_force_stem = 0.0;  // ... on the stem geom
  bool point_valid = false;
  Vec3 p_WC = Vec3::Zero();        // engine's contact point (force-weighted mean when several)
};

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

// The template of an engine adapter: the stepping loop and every check, the identity (name and
// version from the engine's EngineInfo) and what an adapter's engine_step leaves behind
// (contacts, limit hit, solver iterations, notes) are here; an adapter builds its world and
// implements the protected engine_* calls.
class FixedStepSimulator : public Simulator {
 public:
  std::string engine() const override { return info_.name; }
  std::string version() const override { return info_.version; }
  std::vector<std::string> notes() const override { return notes_; }
  void advance_to(double t) override;
  Observation observe() const override;
  WorkCounters work() const override { return work_; }
  RunStatus status() const override { return status_; }
  double status_time() const override { return status_time_; }
  std::string status_detail() const override { return status_detail_; }
  std::vector<Event> events() const override { return events_; }
  size_t event_count() const override { return events_.size(); }
  BodyState state() const override { return engine_state(); }
  void set_state(const BodyState& x) override;

  // Benchmarks only: n engine steps with none of the adapter's work (no events, checks,
  // observations or viscous/gliding forces), to measure the adapter's overhead against the bare engine.
  void bare_steps(long long n) {
    for (long long i = 0; i < n; ++i) engine_step();
  }
  // Benchmarks only: n steps of the engine library's own step call alone, for an adapter whose
  // engine_step does more than that (locks, process-wide parameters, the contact read).
  virtual void library_steps(long long n) { bare_steps(n); }

 protected:
  // `info`: the engine's registry entry (engines/core/registry.h), which outlives the simulator.
  FixedStepSimulator(const Scene& scene, const EngineInfo& info);
  // Must be called by the derived constructor once the engine is built.
  void start(double dt);

  virtual void engine_step() = 0;                  // advance the engine by dt
  virtual BodyState engine_state() const = 0;      // state at the engine's current time
  // The contacts the last step left in report_ (an adapter may compute them instead).
  virtual ContactReport engine_contacts() const { return report_; }
  // Adds a lab-frame force at a lab-frame point for the next step only.
  virtual void apply_force_W(const Vec3& f_W, const Vec3& p_W) = 0;
  // Non-empty when the last step hit an engine limit (e.g. Bullet's pi/4 rotation-per-step clamp).
  virtual std::string engine_limit_hit() const { return limit_; }
  // Non-empty when the engine itself failed in the last step (e.g. an ODE internal error).
  virtual std::string engine_failure() const { return {}; }
  virtual long long engine_solver_iterations() const { return solver_iterations_; }
  // Writes p_WG, q_WB, v_WG, w_B into the engine at its current time (set_state checks them).
  virtual void engine_set_state(const BodyState& x) = 0;

  // The friction coefficient the engine's own contact carries for the scene's law: mu for
  // Coulomb, the engine's stand-in rolling_mu for rolling, 0 for none and for the laws the
  // bench applies itself (viscous, gliding: the engine's contact must then be frictionless).
  double native_mu(double rolling_mu) const;
  // How an engine words its part in the notes every engine shares about the friction law.
  struct FrictionNoteText {
    std::string engine;          // the library as written in notes: "ODE"
    std::string force_how;       // how the bench's force goes in, e.g. " (mj_applyFT)"; may be empty
    std::string normal_source;   // where F_n comes from: "ODE's previous step (joint feedback, explicit)"
    std::string rolling_detail;  // appended to the rolling note, e.g. " (coefficient, approx1)"
  };
  // The notes on how the scene's friction law is realised (rolling stand-in, viscous or gliding
  // law applied by the bench), the same for every engine; engine-specific notes come after.
  std::vector<std::string> friction_law_notes(const FrictionNoteText& text, double rolling_mu) const;
  // "ball modelled as a full sphere ..." when the cut cap can touch first; empty otherwise.
  std::string full_sphere_note() const;

  const Scene& scene() const { return scene_; }
  const BodyModel& body() const { return body_; }
  double dt() const { return dt_; }
  // The engine's current time: steps taken times dt (engine_state().t must equal it).
  double time() const { return static_cast<double>(n_steps_) * dt_; }

  // What an adapter's engine_step leaves for the loop to read, and its notes.
  ContactReport report_;             // the engine's contacts after the step
  std::string limit_;                // non-empty when the step hit an engine limit
  long long solver_iterations_ = 0;  // the engine's solver iterations so far
  std::vector<std::string> notes_;   // approximations in force, as notes() reports them

 private:
  void step_once();
  // What the per-step checks keep of a step's end.
  struct StepProbe {
    BodyState state;
    double cos_theta = 1.0, gap_ball = 0.0, gap_stem = 0.0;
  };
  void track_events(const StepProbe& before, const StepProbe& after);
  void fail(RunStatus s, double t, const std::string& why);

  const EngineInfo& info_;
  Scene scene_;
  BodyModel body_;
  FailureLimits limits_;
  double dt_ = 0.0;
  long long n_steps_ = 0;
  double e0_ = 0.0, speed_scale_ = 0.0;
  RunStatus status_ = RunStatus::Ok;
  double status_time_ = 0.0;
  std::string status_detail_;
  std::vector<Event> events_;
  WorkCounters work_;
  StepProbe last_;
  bool inverted_ = false, stem_touched_ = false;
  Surface contact_surface_ = Surface::None;
};

}  // namespace tippe
