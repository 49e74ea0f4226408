// The metrics of one engine's run against the reference: event times, state errors on a common grid, energy gains.
#pragma once

#include <limits>
#include <optional>
#include <string>
#include <vector>
#include "harness/records/comparison.h"
#include "harness/records/trajectory.h"
#include "analytic/scene.h"

namespace tippe {

// The energy-gain rule, one for the stability map's class (classify.h), the metrics
// energy_gain_events / energy_max_gain and so every gate and `advise`: in a dissipative scene
// (energy_must_not_rise) E (with what the contact stores, EnergyGainRule below) can only fall, so
// any NET rise of it over a stretch of the run, its value at a sample above the lowest of every
// earlier sample, is energy the integrator injected. A gain is such a net rise above
// kEnergyGainTolerance * |E0|.
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
// The tolerance is the sum of two stated parts, checked on every sample against the lowest E so far:
//  1. kEnergyGainTolerance * |E0|, a floor well above arithmetic: E is a sum of terms each at
//     most a few E0 on every shipped scene (the spin energy dominates E0), each exact to ~1e-16
//     of itself; a state integrated over 1e6 steps accumulates ~sqrt(1e6) * 1e-16 = 1e-13
//     relative. 1e-6 is 1e7 above that.
//  2. contact_energy_allowance(scene) = M g * kContactDepthResolution * R: a soft contact
//     (penalty, ERP/CFM, MuJoCo's soft constraint) lets the top sink into the floor, storing
//     energy the bench's E (kinetic + M g z_G) does not see, and its release reads as a rise of
//     about M g times the change of depth (plus the spring's own share, of the same order). The
//     bench resolves contact geometry to 1e-4 R (ODE's surface layer is chosen below it, the
//     tightest contact-path gate is 3e-4 R): a depth that changes by less is a rigid contact to
//     it, and so is the energy that goes in and out of that depth. Without it, MuJoCo's soft
//     contact settling on its tutorial top (rises of 1.0e-6 .. 3e-6 E0 at t = 0.12 .. 0.15 s for
//     every integrator, cone and step from 1e-4 to 1e-3: not the step's doing) was counted as
//     a gain; with it (the tolerance is 5.1e-6 E0 there) it is not, while MuJoCo's Euler integrator's real gains on
//     that top (1.5e-4 E0 at 1e-4) still are. The allowance was set after seeing those runs, at
//     the bench's stated geometric resolution, not at the runs' numbers.
// docs/findings/energy-gain-rule.md gives what the change of rule moved.
inline constexpr double kEnergyGainTolerance = 1e-6;

// The rule applied to one trajectory (E0 = its first energy; |E0| = 0 makes the tolerance
// absolute). The tolerance is kEnergyGainTolerance * |E0| + allowance. `events`: the stretches in which the net rise is above the tolerance (a stretch
// ends when it falls back to or below it); `max_rise`: the largest net rise, / |E0| (absolute
// when E0 = 0); `time`: the first sample above the tolerance, `since`: the time of the lowest
// energy before it (NaN when none).
struct EnergyGains {
  long long events = 0;
  double max_rise = 0;
  double rise_at_first = 0;  // the net rise at `time`, / |E0|
  double tolerance = 0;      // the threshold applied, / |E0|
  double time = std::numeric_limits<double>::quiet_NaN(), since = std::numeric_limits<double>::quiet_NaN();
};
// How the energy-gain rule counts energy (a bench choice, recorded beside the verdict as the
// metrics' energy_gain_rule):
//  - Stored (the default): the rule is applied to E + U - U0, where U is the elastic energy the
//    engine's contact law stores at the sample (Simbody's Hertz contact; ODE's spring where its
//    step resolves it: engines/core, docs/energy-ledger.md), and to E where the run has no U at
//    its first sample (a rigid contact, or a soft one with no potential: MuJoCo's soft
//    constraint, Bullet's and DART's penetration recovery, whose store the allowance below
//    covers). A soft contact giving back what it stored moves energy, creates none: in a
//    dissipative scene E + U can only fall. U is a function of the state (the depth), not a
//    booking, so the rule adds no error of its own; what it cannot see is energy created while
//    friction removes more, which the ledger rule sees.
//  - Total: the rule is applied to E itself, every rise a gain, a soft contact's release too
//    (measured: every one of Simbody's gains on the shipped scenes, 1301 on mujoco_tutorial, is
//    such a release; docs/findings/energy-gain-rule.md).
//  - Ledger: the rule is applied to the energy the run's ledger says was CREATED:
//    C = (E + U) - (E0 + U0) - (friction + drilling work) + impact energy where the engine's
//    contact law gives its elastic energy U (the top's and the contact's energy together, less
//    what friction took), and C = E - E0 - (normal + friction + drilling work) + impact energy
//    (the numerical energy) where it does not, the normal force's work then counted as an
//    exchange with the contact's store. Samples without a ledger (the reference, trajectories
//    written before it) fall back to E.
// Why Stored, not Ledger, is the default (decided; docs/findings/energy-gain-rule.md, "Which rule
// the class uses"): with the booking fixed, the ledger's created energy is each engine's own
// numerical energy, the integrator's truncation error in energy, of either sign. At the class's
// tolerance it refuses first-order engines at nearly every step a user takes: on the
// work-precision sweep (144 points) 32 points go ok -> unphysical (created energy 1.4e-5 ..
// 4.0e-5 E0 when first counted) and 30 of its 93 points safe in the reference's regime stop
// being so, answers that agree with the reference (inversion within 1 %) among them, the
// reference's own integrators at rtol 1e-3 too; DART and MuJoCo's Euler integrator have no safe
// step left on toy_viscous, Bullet's softest safe step on source_dimensionless goes from 3e-3 to
// 3e-5. "Safe" is "gives the reference's answer"; a class that refuses answers which agree would
// answer another question.
// The class keeps what the trajectory shows (E + U rising where only friction and damping act);
// the numerical energy is reported beside it (numerical_energy_max, the verdict's ledger
// sentence) and bounded where a user asks for it (a gate's [check.max] numerical_energy_max).
// Ledger stays selectable (energy_gains' `rule`, the scene key run.energy_gain_rule).
// The tolerance is the same under all three (kEnergyGainTolerance * |E0| + the allowance, both
// stated above): the rule changes what is counted, not how much is tolerated.
// In the order of energy_gain_rule_names() (analytic/scene.h), whose names to_string gives.
enum class EnergyGainRule { Stored, Total, Ledger };
const char* to_string(EnergyGainRule r);
inline constexpr EnergyGainRule kDefaultEnergyGainRule = EnergyGainRule::Stored;
// What the rule counts, in words for a page ("E plus the elastic energy ...").
std::string energy_counted_text(EnergyGainRule r);
// The rule a scene asks for (run.energy_gain_rule, validated when the scene was read; its default
// "stored" is kDefaultEnergyGainRule).
EnergyGainRule energy_gain_rule(const Scene& scene);
// Whether the run has a store of elastic energy: U given at every sample and finite at the first
// (a per-run property of the engine's contact law). Stored counts E + U - U0 where it has, E
// where not; Ledger takes U0 from it; the class's message says which energy rose.
bool has_elastic_store(const Trajectory& trajectory);
// The series the rule is applied to, one value per sample (E + U - U0 under Stored, E0 + C(t)
// under Ledger, E under Total).
std::vector<double> energy_counted(const Trajectory& trajectory, EnergyGainRule rule);
// The engine's friction work while the reference's contact sticks: from each of the reference's
// "stick" events to its next "slip" or change of contact (lift, flight, touchdown, impact, two
// contacts, stem contact, a switch of surface), cut at `until` (the reference's converged window);
// the engine's friction work summed over its sample intervals inside one. Work the reference's
// contact does not do there: the creep or slip of a contact that should roll. Null where the
// reference never sticks before `until`, or the engine's trajectory has no friction work.
std::optional<double> friction_work_where_reference_sticks(const std::vector<Event>& reference_events,
                                                          const Trajectory& engine, double until);

// The depth resolution of the allowance, a fraction of R (see above).
inline constexpr double kContactDepthResolution = 1e-4;
// M g kContactDepthResolution R of the scene (0 when its mass is unknown, as in synthetic scenes).
double contact_energy_allowance(const Scene& scene);
// `allowance`: the absolute energy added to kEnergyGainTolerance * |E0| (contact_energy_allowance).
EnergyGains energy_gains(const Trajectory& trajectory, double allowance = 0.0,
                         EnergyGainRule rule = kDefaultEnergyGainRule);

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
