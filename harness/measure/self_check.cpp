// The reference's self-check: the second method, where two reference runs part, and running the second one.
#include "harness/measure/self_check.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <limits>
#include "harness/io/json_fields.h"
#include "harness/io/text.h"
#include "harness/records/records.h"
#include "harness/measure/run.h"
#include "engines/core/registry.h"

namespace tippe {

namespace fs = std::filesystem;
using nlohmann::json;

SelfCheckMethod self_check_method(const RunSpec& run) {
  if (run.method == "rosenbrock4") {
    // Stiff scenes: see compare.h. The bounds are the scene reader's (rtol >= 1e-15; atol > 0).
    return {"rosenbrock4", std::max(run.rtol / 10, 1e-15), run.atol / 10};
  }
  return {run.method == "dopri5" ? "bulirsch_stoer" : "dopri5", run.rtol, run.atol};
}

double self_check_event_tolerance(const Scene& scene) {
  return std::min(std::max(1e3 * scene.run.rtol, 1e-9), 1e-5) * scene.run.duration;
}

namespace {


// The earliest of several places where the two runs part.
struct Parting {
  std::optional<double> t;
  std::string reason;
  void consider(double at, std::string why) {
    if (!t || at < *t) {
      t = at;
      reason = std::move(why);
    }
  }
};

}  // namespace

SelfCheck compare_reference_runs(const RunRecord& reference, const Trajectory& ref_traj, const RunRecord& check,
                                 const Trajectory& check_traj, const Scene& scene) {
  SelfCheck sc;
  const SelfCheckMethod plan = self_check_method(scene.run);
  sc.method = plan.method;
  sc.rtol = plan.rtol;
  sc.atol = plan.atol;
  sc.cpu_seconds = check.work.cpu_seconds;
  const std::string a = scene.run.method, b = plan.method == a ? a + " at rtol " + g6(plan.rtol) : plan.method;
  Parting part;

  // Events, in order: the same names and details, at times within the tolerance.
  const double tol = self_check_event_tolerance(scene);
  const auto& ea = reference.events;
  const auto& eb = check.events;
  const size_t n = std::min(ea.size(), eb.size());
  for (size_t i = 0; i < n; ++i) {
    const Event& x = ea[i];
    const Event& y = eb[i];
    if (x.name != y.name || x.detail != y.detail) {
      part.consider(std::min(x.time, y.time), "event " + std::to_string(i) + ": " + a + " has " + x.name + " (" +
                                                 x.detail + ") at t = " + g6(x.time) + ", " + b +
                                                 " has " + y.name + " (" + y.detail + ") at t = " +
                                                 g6(y.time));
      break;
    }
    if (!(std::abs(x.time - y.time) <= tol)) {
      part.consider(std::min(x.time, y.time), "event " + std::to_string(i) + " (" + x.name + ") at t = " +
                                                 g6(x.time) + " and " + g6(y.time) +
                                                 ": the times differ by " + g6(std::abs(x.time - y.time)) +
                                                 " > " + g6(tol));
      break;
    }
  }
  if (!part.t && ea.size() != eb.size()) {
    const bool ref_longer = ea.size() > eb.size();
    const Event& extra = ref_longer ? ea[n] : eb[n];
    part.consider(extra.time, (ref_longer ? a : b) + " has " + std::to_string((ref_longer ? ea : eb).size() - n) +
                                  " more event(s) from " + extra.name + " at t = " + g6(extra.time));
  }
  // The reference's own warning: past it, event times are not fixed by the motion.
  for (const auto* events : {&ea, &eb})
    for (const Event& e : *events)
      if (e.name == "unresolved") {
        part.consider(e.time, "unresolved at t = " + g6(e.time) + ": " + e.detail);
        break;
      }

  // Runs that end differently.
  if (reference.status != check.status)
    part.consider(std::min(reference.status == "ok" ? check.status_time : reference.status_time,
                           check.status == "ok" ? reference.status_time : check.status_time),
                  a + " ends " + reference.status + ", " + b + " " + check.status +
                      (check.status != "ok" ? " at t = " + g6(check.status_time) + " (" +
                                                  check.status_detail + ")"
                                            : std::string()));

  // The sampled state, on the common grid (both runs sample the same scene's grid).
  const size_t m = std::min(ref_traj.size(), check_traj.size());
  const double E0 = ref_traj.size() ? ref_traj.energy.front() : 1.0;
  const double e_scale = std::isfinite(E0) && E0 != 0.0 ? std::abs(E0) : 1.0;
  for (size_t k = 0; k < m; ++k) {
    if (!(std::abs(ref_traj.t[k] - check_traj.t[k]) <= 0.5 * scene.run.sample_interval)) break;
    if (part.t && ref_traj.t[k] > *part.t) break;
    const double dth = std::abs(ref_traj.theta[k] - check_traj.theta[k]);
    const double de = std::abs(ref_traj.energy[k] - check_traj.energy[k]) / e_scale;
    if (dth <= kSelfCheckStateTolerance && de <= kSelfCheckStateTolerance) continue;
    const double until = k ? ref_traj.t[k - 1] : 0.0;
    const bool tilt = !(dth <= kSelfCheckStateTolerance);
    part.consider(until, std::string(tilt ? "the tilt" : "the energy") + " differs by " +
                             g6(tilt ? dth : de) + (tilt ? " rad" : " E0") + " > " +
                             g6(kSelfCheckStateTolerance) + " at t = " + g6(ref_traj.t[k]));
    break;
  }
  sc.converged_until = part.t;
  sc.reason = part.reason;
  return sc;
}

SelfCheck run_self_check(const Scene& scene, const RunRecord& reference, const Trajectory& ref_traj) {
  Scene second = scene;
  const SelfCheckMethod plan = self_check_method(scene.run);
  second.run.method = plan.method;
  second.run.rtol = plan.rtol;
  second.run.atol = plan.atol;
  TrajectorySink sink;
  const RunRecord check = run_scene(second, reference_engine().name, &sink);
  return compare_reference_runs(reference, ref_traj, check, sink.trajectory, scene);
}

}  // namespace tippe
