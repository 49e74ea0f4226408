// The metrics of one engine's run against the reference: event times, state errors on a common grid, energy gains.
#pragma once

#include <optional>
#include "records/comparison.h"
#include "records/trajectory.h"
#include "scene.h"

namespace tippe {

// Tolerance for energy gain events: a rise of E between samples above this fraction of E0 in
// a dissipative scene is energy the integrator injected.
inline constexpr double kEnergyGainTolerance = 1e-6;

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
