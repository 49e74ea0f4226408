// MuJoCo's RK4 step (mj_step with mjINT_RK4) taken stage by stage, so that the adapter can read each stage's contact forces.
#pragma once

#include <functional>

#include <mujoco/mujoco.h>

#include "engines/core/step_checks.h"

namespace tippe {

// One step of mj_step with the RK4 integrator, the same arithmetic in the same order as MuJoCo
// 2.2's mj_RungeKutta(m, d, 4) (the state it leaves is bit-identical), calling after_stage(i, b_i)
// once each stage's forward dynamics is in d (i = 0 .. 3, b_i its weight in the step's update:
// 1/6, 1/3, 1/3, 1/6). MuJoCo keeps only the last stage's contacts and forces; the step's velocity
// update is the b-weighted sum of all four. For a model without activations and without
// mjENBL_FWDINV (rk4_stepwise_supported); the caller uses mj_step otherwise.
bool rk4_stepwise_supported(const mjModel* m);
void rk4_step_by_stages(const mjModel* m, mjData* d, const std::function<void(int, double)>& after_stage);
// The step by stages with each stage's contacts (read(d)) summed by its weight, each stage's
// points moved with body_id's centre of mass back to the step start's (StepMeanForces). (The last
// stage's force alone booked the contact's hops on and off the floor while slipping as work no
// force did: up to 2e-3 E0 a sample on leine_glocker.)
// applied_work: the work of d->qfrc_applied (the bench's forces, held over the step) as RK4
// integrates it, h times the b-weighted sum of its power on the stages' velocities.
StepMeanForces rk4_step_mean_forces(const mjModel* m, mjData* d, int body_id,
                                    const std::function<ContactReport(const mjData*)>& read,
                                    double& applied_work);

}  // namespace tippe
