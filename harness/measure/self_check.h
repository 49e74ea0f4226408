// The reference's self-check: a second run by an independent method, and the time until which the two agree.
#pragma once

#include <optional>
#include <string>
#include "harness/records/comparison.h"
#include "harness/records/trajectory.h"
#include "analytic/scene.h"

namespace tippe {

// ---- the reference's self-check -----------------------------------------------------------------
//
// A second reference run over the same scene with an independent method, and the time up to
// which the two agree: the reference is "converged until" then. After it the metrics against the
// reference are not computed (Metrics::reference_converged_until) and gates say so.

// The second run's method and tolerances. bulirsch_stoer <-> dopri5: an extrapolation method and
// an embedded Runge-Kutta pair share no error estimate, so agreement is not one method agreeing
// with itself. rosenbrock4 -> rosenbrock4 at rtol/10 and atol/10: the scenes that need it are
// stiff (k_high: slip relaxes in 1e-7 s), where both explicit methods need ~1e6 steps a second
// and would cost minutes or fail; a tenfold tighter run of the same method is a convergence test
// (it catches a tolerance too loose for the motion), the independent test a stiff scene allows.
struct SelfCheckMethod {
  std::string method;
  double rtol = 0, atol = 0;
};
SelfCheckMethod self_check_method(const RunSpec& run);

// Two event times agree within max(1e3 rtol, 1e-9), at most 1e-5, times the duration. Measured
// (bulirsch_stoer against dopri5, source_dimensionless, after the stem touchdown up to the
// `unresolved` event): 2.5e-7 at rtol 1e-10 (the bound: 2.5e-6), 1.2e-10 at rtol 1e-12 (2.5e-8),
// 1e-4 at rtol 1e-8 (2.3e-4). The cap: event times are compared to 1e-5 of the duration at best
// (the tightest shipped gate bounds an event time to 8e-6 of it), so a looser reference parts.
double self_check_event_tolerance(const Scene& scene);
// Two sampled states agree while |theta_1 - theta_2| <= this (rad) and |E_1 - E_2| <= this * |E0|.
// 1e-6 is 1/60 of the tightest state bound in the shipped gates (tilt_rms_error and
// energy_max_error 6e-5), so a difference under it moves no shipped verdict by more than ~2 %,
// and ten times the largest difference measured inside the converged windows of the shipped
// scenes at rtol 1e-10 (1e-7, source_dimensionless between the stem touchdown and t = 21.37).
inline constexpr double kSelfCheckStateTolerance = 1e-6;


// Pure: where the second run `check` parts from `reference` (same scene, same sample grid):
// the earliest of the first event that differs (name, detail, or time beyond
// self_check_event_tolerance; one run having events the other lacks), an `unresolved` event in
// either run (the reference's own word that the motion stops fixing later events), the first
// sample whose tilt or energy differ beyond kSelfCheckStateTolerance (converged until the sample
// before), and a status that differs. method/rtol/atol/cpu_seconds are filled from `check`.
SelfCheck compare_reference_runs(const RunRecord& reference, const Trajectory& ref_traj, const RunRecord& check,
                                 const Trajectory& check_traj, const Scene& scene);
// Runs the second reference (self_check_method) on `scene` and compares it with the reference.
SelfCheck run_self_check(const Scene& scene, const RunRecord& reference, const Trajectory& ref_traj);

}  // namespace tippe
