// MuJoCo's RK4 step taken stage by stage (mujoco_rk4.h).
#include "engines/mujoco/mujoco_rk4.h"

#include <vector>

namespace tippe {

bool rk4_stepwise_supported(const mjModel* m) {
  return m->opt.integrator == mjINT_RK4 && m->na == 0 && !(m->opt.enableflags & mjENBL_FWDINV);
}

void rk4_step_by_stages(const mjModel* m, mjData* d, const std::function<void(int, double)>& after_stage) {
  // mj_step: the checks and the forward dynamics at the step's start (stage 0).
  mj_checkPos(m, d);
  mj_checkVel(m, d);
  mj_forward(m, d);
  mj_checkAcc(m, d);
  // MuJoCo's RK4 tableau (engine_forward.c), its coefficients and their order of summation.
  static const mjtNum A[9] = {0.5, 0, 0, 0, 0.5, 0, 0, 0, 1};
  static const mjtNum B[4] = {1.0 / 6.0, 1.0 / 3.0, 1.0 / 3.0, 1.0 / 6.0};
  const int nv = m->nv, nq = m->nq, N = 4;
  const mjtNum h = m->opt.timestep, time = d->time;
  std::vector<mjtNum> dX(2 * nv);
  std::vector<std::vector<mjtNum>> X(N, std::vector<mjtNum>(nq + nv)), F(N, std::vector<mjtNum>(nv));
  mjtNum T[3];
  for (int i = 1; i < N; ++i) {
    mjtNum c = 0;
    for (int j = 0; j < i; ++j) c += A[(i - 1) * (N - 1) + j];
    T[i - 1] = d->time + c * h;
  }
  mju_copy(X[0].data(), d->qpos, nq);
  mju_copy(X[0].data() + nq, d->qvel, nv);
  mju_copy(F[0].data(), d->qacc, nv);
  after_stage(0, B[0]);
  for (int i = 1; i < N; ++i) {
    mju_zero(dX.data(), 2 * nv);
    for (int j = 0; j < i; ++j) {
      mju_addToScl(dX.data(), X[j].data() + nq, A[(i - 1) * (N - 1) + j], nv);
      mju_addToScl(dX.data() + nv, F[j].data(), A[(i - 1) * (N - 1) + j], nv);
    }
    mju_copy(X[i].data(), X[0].data(), nq + nv);
    mj_integratePos(m, X[i].data(), dX.data(), h);
    mju_addToScl(X[i].data() + nq, dX.data() + nv, h, nv);
    mju_copy(d->qpos, X[i].data(), nq);
    mju_copy(d->qvel, X[i].data() + nq, nv);
    d->time = T[i - 1];
    mj_forwardSkip(m, d, mjSTAGE_NONE, 1);  // as MuJoCo: no sensors or energy at the stages
    mju_copy(F[i].data(), d->qacc, nv);
    after_stage(i, B[i]);
  }
  mju_zero(dX.data(), 2 * nv);
  for (int j = 0; j < N; ++j) {
    mju_addToScl(dX.data(), X[j].data() + nq, B[j], nv);
    mju_addToScl(dX.data() + nv, F[j].data(), B[j], nv);
  }
  d->time = time;
  mju_copy(d->qpos, X[0].data(), nq);
  mju_copy(d->qvel, X[0].data() + nq, nv);
  // mj_advance(m, d, act_dot, qacc = dX + nv, qvel = dX): no activations here.
  mju_addToScl(d->qvel, dX.data() + nv, h, nv);
  mj_integratePos(m, d->qpos, dX.data(), h);
  d->time += h;
}

StepMeanForces rk4_step_mean_forces(const mjModel* m, mjData* d, int body_id,
                                    const std::function<ContactReport(const mjData*)>& read,
                                    double& applied_work) {
  StepMeanForces mean;
  Vec3 com0 = Vec3::Zero();
  double power = 0.0;
  rk4_step_by_stages(m, d, [&](int stage, double weight) {
    const Vec3 com(d->xipos[3 * body_id], d->xipos[3 * body_id + 1], d->xipos[3 * body_id + 2]);
    if (stage == 0) com0 = com;
    add_stage_forces(mean, read(d), weight, com - com0);
    power += weight * mju_dot(d->qfrc_applied, d->qvel, m->nv);
  });
  finish_stage_forces(mean);
  applied_work = power * m->opt.timestep;
  return mean;
}

}  // namespace tippe
