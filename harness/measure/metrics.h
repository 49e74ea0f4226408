// The metrics of one engine's run against the reference: event times, state errors on a common grid, energy gains.
#pragma once

#include <limits>
#include <optional>
#include "records/comparison.h"
#include "records/trajectory.h"
#include "scene.h"

namespace tippe {

// The energy-gain rule, one for the stability map's class (classify.h), the metrics
// energy_gain_events / energy_max_gain and so every gate and `advise`: in a dissipative scene
// (energy_must_not_rise) E can only fall, so any NET rise of E over a stretch of the run, E at a
// sample above the lowest E of every earlier sample, is energy the integrator injected. A gain is
// such a net rise above kEnergyGainTolerance * |E0|.
//
// Why a net rise and not a rise between two samples: a rule on neighbouring samples depends on
// the sample interval. A steady injection of rate P is a rise of P * dt_sample between samples:
// the same run is "unphysical" sampled every 0.1 s and "ok" sampled every 1e-3 s, and a run whose
// rises come in many small steps (MuJoCo's Euler integrator on a user's top: 1e-5 .. 1e-3 E0 a
// second, in rises of ~1e-6 E0 between samples) passes or fails by how finely it is sampled.
// The net rise over a window does not depend on the sampling once the samples resolve the run
// (finer sampling can only show the same net rises), and it is immune to noise below the
// tolerance however long the run: jitter never accumulates into a net rise.
//
// Where 1e-6 comes from (no shipped run was looked at to choose it): it is a floor, well above
// what arithmetic alone can produce and below anything the bench resolves otherwise.
//  - Round-off: E is a sum of terms each at most a few E0 on every shipped scene (the spin
//    energy dominates E0), each exact to ~1e-16 of itself; a state integrated over 1e6 steps
//    accumulates ~sqrt(1e6) * 1e-16 = 1e-13 relative. 1e-6 is 1e7 above that, so a net rise above
//    it is no round-off.
//  - Resolution: the tightest energy threshold any shipped gate sets is energy_max_error <= 6e-5
//    of E0 (Bullet, harness/gates/default.toml); a gain 60x smaller than what the bench resolves
//    against the reference is still counted, because a dissipative law admits none at all.
// What it does not tell apart: a soft contact (penalty, ERP/CFM, MuJoCo's soft constraint) lets
// the top sink into the floor, storing energy the bench's E (kinetic + m g z_G) does not see; its
// release reads as a rise of up to m g * (the change of penetration). A touchdown whose
// penetration changes by more than 1e-6 E0 / (m g) is counted as a gain (as the rule on samples
// counted it before). BENCHMARKS.md ("One criterion of safe") gives what the change of rule moved.
inline constexpr double kEnergyGainTolerance = 1e-6;

// The rule applied to one trajectory (E0 = its first energy; |E0| = 0 makes the tolerance
// absolute). `events`: the stretches in which the net rise is above the tolerance (a stretch
// ends when it falls back to or below it); `max_rise`: the largest net rise, / |E0| (absolute
// when E0 = 0); `time`: the first sample above the tolerance, `since`: the time of the lowest
// energy before it (NaN when none).
struct EnergyGains {
  long long events = 0;
  double max_rise = 0;
  double rise_at_first = 0;  // the net rise at `time`, / |E0|
  double time = std::numeric_limits<double>::quiet_NaN(), since = std::numeric_limits<double>::quiet_NaN();
};
EnergyGains energy_gains(const Trajectory& trajectory);

// Whether the scene's contact law removes energy (viscous k > 0, Coulomb mu > 0, or drilling
// friction), so that any rise of E between samples is an integrator artefact.
bool energy_must_not_rise(const Scene& scene);

// Pure function of two trajectories and their records (tested on synthetic data). The common
// grid: samples matched by index up to the shorter run when every pair of times agrees within
// half a sample interval, else the engine interpolated linearly onto the reference's times.
// Pairs where either value is not finite are left out of the error sums. With no common sample
// the error metrics are NaN (null in JSON).
// `converged_until`: the reference is trusted only to this time (its self-check): the errors
// against it are summed over samples at t <= converged_until, and an event pairing is judged
// only when the reference's event (or, when the reference has none, the engine's) comes at or
// before it; otherwise the pairing is "unconverged" and its errors are absent. Metrics of the
// engine alone (energy ratio and gains, Jellett drift, work) cover the whole run.
Metrics compare_runs(const RunRecord& reference, const Trajectory& ref_traj, const RunRecord& engine,
                     const Trajectory& engine_traj, const Scene& scene,
                     std::optional<double> converged_until = std::nullopt);

}  // namespace tippe
