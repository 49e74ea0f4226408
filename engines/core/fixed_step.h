// Shared stepping loop of the fixed-step engines: events, failure classification, viscous and
// gliding laws, work.
#pragma once

#include <string>
#include <vector>

#include "analytic/initial_state.h"
#include "engines/core/registry.h"
#include "engines/core/simulator.h"
#include "engines/core/bench_friction.h"
#include "engines/core/step_checks.h"

namespace tippe {

// The template of an engine adapter: the stepping loop and every check, the identity (name and
// version from the engine's EngineInfo) and what an adapter's engine_step leaves behind
// (contacts, limit hit, solver iterations, notes) are here; an adapter builds its world and
// implements the protected engine_* calls.
class FixedStepSimulator : public CheckedSimulator {
 public:
  std::string engine() const override { return info_.name; }
  std::string version() const override { return info_.version; }
  std::vector<std::string> notes() const override { return notes_; }
  void advance_to(double t) override;
  Observation observe() const override;
  WorkCounters work() const override { return work_; }
  BodyState state() const override { return engine_state(); }
  void set_state(const BodyState& x) override;
  EngineContactForces contact_forces() const override;

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

  // The friction coefficient the engine's own contact carries (bench_friction.h's native_mu).
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
  // The engine's contacts plus the bench's friction of the last step (viscous, gliding).
  ContactReport contacts_with_bench_friction() const { return with_bench_friction(engine_contacts(), bench_applied_); }

  const EngineInfo& info_;
  Scene scene_;
  BodyModel body_;
  double dt_ = 0.0;
  long long n_steps_ = 0;
  WorkCounters work_;
  // The bench-applied friction of the last step (viscous, gliding), for contact_forces().
  BenchFrictionForces bench_applied_;
};

}  // namespace tippe
