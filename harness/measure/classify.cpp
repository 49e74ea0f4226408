// Classification of one finished run: ok, or what went wrong first (diverged, unphysical, clamped, failed, contact_lost) and when.
#include "harness/measure/classify.h"
#include "harness/io/text.h"

#include <algorithm>
#include <cmath>
#include <optional>
#include <sstream>
#include <vector>

#include "engines/core/fixed_step.h"

namespace tippe {

namespace {



struct Finding {
  double time;
  std::string reason;
};

std::optional<RunClassKind> kind_of_status(const std::string& status) {
  if (status == "ok") return RunClassKind::Ok;
  if (status == "diverged") return RunClassKind::Diverged;
  if (status == "unphysical") return RunClassKind::Unphysical;
  if (status == "clamped") return RunClassKind::Clamped;
  if (status == "failed") return RunClassKind::Failed;
  if (status == "contact_lost") return RunClassKind::ContactLost;
  return std::nullopt;
}

std::optional<Finding> first_divergence(const Trajectory& tr) {
  const size_t n = tr.size();
  if (n == 0) return std::nullopt;
  const double e0 = tr.energy[0];
  const double factor = FailureLimits{}.energy_factor;
  for (size_t k = 0; k < n; ++k) {
    // A sample whose own time is not finite is dated by the last good one.
    const double t = std::isfinite(tr.t[k]) ? tr.t[k] : (k > 0 ? tr.t[k - 1] : std::nan(""));
    if (!std::isfinite(tr.t[k]) || !std::isfinite(tr.theta[k]) || !std::isfinite(tr.energy[k]) ||
        !std::isfinite(tr.jellett[k]))
      return Finding{t, "non-finite sample (t, tilt, energy or Jellett's J)"};
    if (e0 > 0 && tr.energy[k] > factor * e0)
      return Finding{t, "energy " + g6(tr.energy[k]) + " above " + g6(factor) + " E0 = " + g6(factor * e0)};
  }
  return std::nullopt;
}

std::optional<Finding> first_energy_gain(const Scene& scene, const Trajectory& tr) {
  // The rule of metrics.h (energy_gains): the same measurement as energy_gain_events.
  const EnergyGainRule rule = energy_gain_rule(scene);
  const EnergyGains g = energy_gains(tr, contact_energy_allowance(scene), rule);
  if (!g.events) return std::nullopt;
  const bool relative = tr.energy[0] != 0;
  const bool ledger = rule == EnergyGainRule::Ledger && !tr.numerical_energy.empty() &&
                      std::isfinite(tr.numerical_energy.back());
  const bool stored = rule == EnergyGainRule::Stored && has_elastic_store(tr);
  return Finding{g.time, std::string(ledger   ? "energy created (by the ledger: not friction work, not released from the contact's store) rose by "
                                     : stored ? "energy with the contact's stored elastic energy rose by "
                                              : "energy rose by ") +
                             g6(g.rise_at_first) + (relative ? " E0" : "") + " between t = " + g6(g.since) +
                             " (its lowest so far) and " + g6(g.time) + " in a dissipative scene (tolerance " +
                             g6(g.tolerance) + " E0 on the net rise: 1e-06 E0 and the energy of 1e-4 R of contact depth; energy_gain_rule = " +
                             to_string(rule) + ")"};
}

std::optional<double> record_drift(const RunRecord& run, int surface) {
  return surface == static_cast<int>(Surface::Ball) ? run.jellett_drift_ball : run.jellett_drift_stem;
}

// Whether J drifted beyond the tolerance is the record's verdict: SampleSummary computed it during
// the run with every "switch" event, while a record read back from comparison.json keeps only the
// first kMaxSwitchEventsKept of them, and stretches rebuilt from those can run across a switch
// (observed: ODE on toy_viscous, 4.6e-4 in its record, 1.0e-3 rebuilt). The trajectory only
// dates it: the first sample beyond the tolerance on a surface whose record drift is beyond it.
std::optional<Finding> first_jellett_drift(const Trajectory& tr, const RunRecord& run) {
  std::optional<Finding> undated;
  bool any = false;
  for (const int s : {static_cast<int>(Surface::Ball), static_cast<int>(Surface::Stem)}) {
    const auto drift = record_drift(run, s);
    if (!drift || !(*drift > kJellettDriftTolerance)) continue;
    any = true;
    if (!undated)
      undated = Finding{std::nan(""), "Jellett's J drifted by " + g6(*drift) + " relative on the " +
                                          to_string(static_cast<Surface>(s)) + " (tolerance " +
                                          g6(kJellettDriftTolerance) + "; no sample dates it)"};
  }
  if (!any) return std::nullopt;

  std::vector<double> switches;
  for (const auto& e : run.events)
    if (e.name == "switch") switches.push_back(e.time);
  std::sort(switches.begin(), switches.end());
  size_t next_switch = 0;
  int run_surface = static_cast<int>(Surface::None);
  double j0 = 0.0, run_start = 0.0;
  for (size_t k = 0; k < tr.size(); ++k) {
    // A switch reported since the previous sample ends the stretch, as in SampleSummary::add.
    bool switched = false;
    while (next_switch < switches.size() && switches[next_switch] <= tr.t[k]) {
      switched = true;
      ++next_switch;
    }
    if (switched) run_surface = static_cast<int>(Surface::None);
    const int s = tr.surface[k];
    if (s != static_cast<int>(Surface::Ball) && s != static_cast<int>(Surface::Stem)) {
      run_surface = static_cast<int>(Surface::None);
      continue;
    }
    if (s != run_surface) {
      run_surface = s;
      j0 = tr.jellett[k];
      run_start = tr.t[k];
      continue;
    }
    const auto flagged = record_drift(run, s);
    if (!flagged || !(*flagged > kJellettDriftTolerance)) continue;
    const double drift = jellett_relative_drift(tr.jellett[k], j0);
    if (drift > kJellettDriftTolerance)
      return Finding{tr.t[k], "Jellett's J drifted by " + g6(drift) + " relative on the " +
                                  to_string(static_cast<Surface>(s)) + " since t = " + g6(run_start) +
                                  " (tolerance " + g6(kJellettDriftTolerance) + "; J is conserved there; " +
                                  g6(*flagged) + " over the run)"};
  }
  return undated;
}

// The earliest sign that the run broke a conservation law or injected energy (a finding the
// samples cannot date comes last).
std::optional<Finding> first_unphysical(const Scene& scene, const RunRecord& run, const Trajectory& tr) {
  std::optional<Finding> gain, drift;
  if (energy_must_not_rise(scene)) gain = first_energy_gain(scene, tr);
  if (jellett_must_hold(scene)) drift = first_jellett_drift(tr, run);
  if (gain && drift) return !(drift->time < gain->time) ? gain : drift;
  return gain ? gain : drift;
}

}  // namespace

const char* to_string(RunClassKind kind) {
  switch (kind) {
    case RunClassKind::Ok: return "ok";
    case RunClassKind::Diverged: return "diverged";
    case RunClassKind::Unphysical: return "unphysical";
    case RunClassKind::Clamped: return "clamped";
    case RunClassKind::Failed: return "failed";
    case RunClassKind::ContactLost: return "contact_lost";
  }
  return "?";
}

bool jellett_must_hold(const Scene& scene) { return !(scene.contact.drilling > 0); }

RunClass classify_run(const Scene& scene, const RunRecord& run, const Metrics* vs_reference,
                      const Trajectory& trajectory) {
  RunClass out;
  const std::optional<RunClassKind> status = kind_of_status(run.status);
  if (!status || *status != RunClassKind::Ok) {
    out.kind = status.value_or(RunClassKind::Failed);
    out.time = run.status_time;
    out.reason = status ? run.status_detail : "unknown run status \"" + run.status + "\"";
    if (out.reason.empty()) out.reason = run.status;
    // What the engine's verdict hides but a reader wants: an earlier sign of trouble.
    if (const auto early = first_unphysical(scene, run, trajectory); early && early->time < run.status_time)
      out.reason += "; earlier, at t = " + g6(early->time) + ": " + early->reason;
    return out;
  }

  if (const auto d = first_divergence(trajectory)) return {RunClassKind::Diverged, d->time, d->reason};
  if (const auto u = first_unphysical(scene, run, trajectory)) return {RunClassKind::Unphysical, u->time, u->reason};

  if (trajectory.size() == 0) {
    const double nan = std::nan("");
    if (vs_reference && energy_must_not_rise(scene) && vs_reference->energy_gain_events > 0)
      return {RunClassKind::Unphysical, nan,
              std::to_string(vs_reference->energy_gain_events) + " net energy rises above the tolerance (" + g6(kEnergyGainTolerance) +
                  " E0 and the energy of 1e-4 R of contact depth) in a dissipative scene (largest " + g6(vs_reference->energy_max_gain) +
                  " E0; no trajectory to date them)"};
  }
  return out;
}

}  // namespace tippe
