// The ledger's per-step booking of an engine's contact impulse (engines/core/step_checks.cpp): exact for an impulse at the point and configuration the engine applied it (Kelvin's theorem), and the engines' ledgers close where they have no energy term of their own.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "harness/io/scene_io.h"
#include "harness/scene/resolve.h"
#include "harness/measure/run.h"
#include "harness/records/trajectory.h"
#include "engines/core/bench_friction.h"
#include "engines/core/registry.h"
#include "engines/core/step_checks.h"
#include "tests/support/fixtures.h"

namespace tippe::test_energy_ledger_steps {
namespace {

Eigen::Matrix3d inertia_W(const BodyModel& b, const Quat& q) {
  const Eigen::Matrix3d R = q.toRotationMatrix();
  return R * Vec3(b.A, b.A, b.C).asDiagonal() * R.transpose();
}

double kinetic(const BodyModel& b, const Eigen::Matrix3d& I_W, const Vec3& v, const Vec3& w_W) {
  return 0.5 * b.M * v.squaredNorm() + 0.5 * w_W.dot(I_W * w_W);
}

// One step of a rigid top: the start x (tilted, spinning, its centre moving fast sideways) and
// the end's configuration (moved by v h, turned by w h: far enough that a lever arm from the
// wrong one is seen). An impulse P at the configuration `at`'s geometric contact point changes
// the velocities as a rigid body's: v+ = v- + P / M, w+ = w- + I_W^-1 (r x P), r from that
// configuration's G, I_W its inertia. Its work is exactly that kinetic energy change.
struct ImpulseStep {
  BodyState x, y;
  ContactReport report;
  double delta_ke = 0.0;
};

ImpulseStep impulse_step(const BodyModel& b, bool at_end) {
  ImpulseStep s;
  const double h = 1e-2;
  s.x.t = 0.0;
  s.x.q_WB = Quat(Eigen::AngleAxisd(0.4, Vec3(1, 0.3, 0).normalized()));
  s.x.w_B = Vec3(0.7, -0.4, 9.0);
  s.x.v_WG = Vec3(0.8, -0.5, 0.05);
  s.x.p_WG = Vec3(0, 0, 0) - contact_offset_W(b, s.x.q_WB, Surface::Ball);  // touching the floor
  // The end's configuration: moved and turned as by the start's velocities (the booking's
  // identity does not depend on how the engine moved it).
  s.y.t = h;
  const Vec3 w0_W = s.x.q_WB * s.x.w_B;
  s.y.p_WG = s.x.p_WG + h * s.x.v_WG;
  s.y.q_WB = (Quat(Eigen::AngleAxisd(w0_W.norm() * h, w0_W.normalized())) * s.x.q_WB).normalized();
  const BodyState& a = at_end ? s.y : s.x;
  const Vec3 p_WC = a.p_WG + contact_offset_W(b, a.q_WB, Surface::Ball);
  // A normal impulse and a friction impulse against the slip, of a Coulomb contact's sizes.
  const Vec3 P(-0.02 * h, 0.013 * h, 1.1 * b.M * b.g * h);
  const Eigen::Matrix3d I_W = inertia_W(b, a.q_WB);
  const Vec3 w1_W = w0_W + I_W.inverse() * (p_WC - a.p_WG).cross(P);
  s.y.v_WG = s.x.v_WG + P / b.M;
  s.y.w_B = s.y.q_WB.conjugate() * w1_W;
  s.delta_ke = kinetic(b, I_W, s.y.v_WG, w1_W) - kinetic(b, I_W, s.x.v_WG, w0_W);
  ContactReport& r = s.report;
  r.ball = true;
  r.normal_force = r.normal_force_ball = P.z() / h;
  add_surface_force(r, false, P.z() / h, Vec3(P.x() / h, P.y() / h, 0.0), p_WC);
  finish_surface_points(r);
  return s;
}

// The step's kinetic energy change is a difference of kinetic energies ~1e4 times larger (the
// spin's): round-off of a few ulps of those, ~5e-12 of the change measured.
constexpr double kRoundOff = 1e-10;

double booked(const StepChecks& c) {
  const EnergyLedgerTotals l = c.energy_ledger();
  return l.normal_work + l.friction_work;
}

TEST(LedgerBooking, AnImpulseAtTheStartsPointIsBookedAsTheKineticEnergyItGives) {
  // A semi-implicit Euler engine (Bullet, ODE, MuJoCo's Euler, DART) applies its contact impulse
  // through the Jacobian of the step's start, at the point its collision found there. The lever
  // arm from the end's G (the booking before) is off by v_G h: 22 % of this step's work.
  const BodyModel b = BodyModel::from_scene(fixtures::dimensionless_scene());
  const ImpulseStep s = impulse_step(b, false);
  StepChecks c(b);
  c.start(s.x);
  ASSERT_TRUE(c.after_step(s.y.t, s.y, s.report));
  std::printf("impulse at the start's point: work booked %.15g, kinetic energy change %.15g\n", booked(c), s.delta_ke);
  ASSERT_GT(std::abs(s.delta_ke), 1e-4);
  EXPECT_NEAR(booked(c), s.delta_ke, kRoundOff * std::abs(s.delta_ke));
  // The booking before: the arm from the end's G at the end, the start's geometric point moved as
  // the engine's from the end's at the start. Off by far more than the bound above.
  const ContactReport& r = s.report;
  const Vec3 f = r.friction_ball_W + Vec3(0, 0, r.normal_force_ball);
  const Vec3 arm = r.p_WC_ball - s.y.p_WG;
  const Vec3 arm0 = arm + contact_offset_W(b, s.x.q_WB, Surface::Ball) - contact_offset_W(b, s.y.q_WB, Surface::Ball);
  const Vec3 v_C = 0.5 * (s.y.v_WG + (s.y.q_WB * s.y.w_B).cross(arm) + s.x.v_WG + (s.x.q_WB * s.x.w_B).cross(arm0));
  const double before = f.dot(v_C) * (s.y.t - s.x.t);
  std::printf("booked before: %.15g (off by %.3g of the step's work)\n", before, std::abs(before / s.delta_ke - 1));
  EXPECT_GT(std::abs(before - s.delta_ke), 1e-3 * std::abs(s.delta_ke));
}

TEST(LedgerBooking, AnImpulseAtTheEndsPointIsBookedSoWhenTheEngineSaysSo) {
  // Siconos' Moreau-Jean step evaluates its contact relations at q_n+1: its adapter says so
  // (set_impulse_at_step_end), and the lever arm is from the end's G.
  const BodyModel b = BodyModel::from_scene(fixtures::dimensionless_scene());
  const ImpulseStep s = impulse_step(b, true);
  StepChecks c(b);
  c.set_impulse_at_step_end();
  c.start(s.x);
  ASSERT_TRUE(c.after_step(s.y.t, s.y, s.report));
  EXPECT_NEAR(booked(c), s.delta_ke, kRoundOff * std::abs(s.delta_ke));
  // Booked at the start's configuration instead, the same impulse is off by far more.
  StepChecks wrong(b);
  wrong.start(s.x);
  ASSERT_TRUE(wrong.after_step(s.y.t, s.y, s.report));
  EXPECT_GT(std::abs(booked(wrong) - s.delta_ke), 1e-4 * std::abs(s.delta_ke));
}

TEST(LedgerBooking, TheStepsMeanForcesAreBookedWhereTheAdapterGivesThem) {
  // MuJoCo's RK4 keeps its last stage's force; its adapter gives the stages' weighted sum in
  // step_mean, which the ledger books instead of the report's own forces.
  const BodyModel b = BodyModel::from_scene(fixtures::dimensionless_scene());
  const ImpulseStep s = impulse_step(b, false);
  ContactReport r = s.report;
  // Two stages of the same force, the second's centre of mass (and so its point) moved by 0.1:
  // its point is moved back to the start's.
  ContactReport moved = s.report;
  moved.p_WC_ball += Vec3(0.1, 0.0, 0.0);
  StepMeanForces m;
  add_stage_forces(m, s.report, 0.25, Vec3::Zero());
  add_stage_forces(m, moved, 0.75, Vec3(0.1, 0.0, 0.0));
  finish_stage_forces(m);
  r.step_mean = m;
  // The report's own forces: a last stage off the floor.
  r.normal_force_ball = 0.0;
  r.friction_ball_W = Vec3::Zero();
  StepChecks c(b);
  c.start(s.x);
  ASSERT_TRUE(c.after_step(s.y.t, s.y, r));
  EXPECT_NEAR(booked(c), s.delta_ke, kRoundOff * std::abs(s.delta_ke));
}

// A step of a soft contact (the engine's point half a penetration depth inside the ball, the
// weighted mean of its contact) with the bench's viscous force at the geometric contact point.
struct BenchForceStep {
  ImpulseStep s;
  BenchFrictionForces bench;
  double work = 0.0;  // the bench force's work: F . (v_G + w x r) with the step's mean velocities
};

BenchForceStep bench_force_step(const BodyModel& b) {
  BenchForceStep k;
  k.s = impulse_step(b, false);
  ContactReport r;
  r.ball = true;
  const double depth = 1e-3 * b.R;
  const Vec3 p_geo = k.s.x.p_WG + contact_offset_W(b, k.s.x.q_WB, Surface::Ball);
  r.normal_force = r.normal_force_ball = b.M * b.g;
  add_surface_force(r, false, b.M * b.g, Vec3::Zero(), p_geo + Vec3(0, 0, 0.5 * depth));
  finish_surface_points(r);
  k.bench.n = 1;
  k.bench.r_GC_W[0] = contact_offset_W(b, k.s.x.q_WB, Surface::Ball);
  k.bench.f_W[0] = Vec3(-0.3, 0.2, 0.0) * b.M * b.g;
  add_bench_friction(r, k.bench);
  k.s.report = r;
  const Vec3 v_G = 0.5 * (k.s.x.v_WG + k.s.y.v_WG);
  const Vec3 w = 0.5 * (k.s.x.q_WB * k.s.x.w_B + k.s.y.q_WB * k.s.y.w_B);
  k.work = k.bench.f_W[0].dot(v_G + w.cross(k.bench.r_GC_W[0])) * (k.s.y.t - k.s.x.t);
  return k;
}

double friction_booked(const StepChecks& c) { return c.energy_ledger().friction_work; }

TEST(LedgerBooking, TheBenchsForceIsBookedAtTheBenchsPoint) {
  // A soft contact's point is inside the penetration; the bench applies its viscous force at the
  // geometric contact point. Booked at the engine's point, MuJoCo's two-contact slide on
  // toy_viscous gained 3e-4 E0 of work no force did (the same at every step size).
  const BodyModel b = BodyModel::from_scene(fixtures::dimensionless_scene());
  const BenchForceStep k = bench_force_step(b);
  StepChecks c(b);
  c.start(k.s.x);
  ASSERT_TRUE(c.after_step(k.s.y.t, k.s.y, k.s.report));
  ASSERT_GT(std::abs(k.work), 1e-6);
  // Two ways of summing the same products: a few ulps of the terms (each ~|work|).
  EXPECT_NEAR(friction_booked(c), k.work, 1e-12 * std::abs(k.work));
  // The engine's point instead is off by F . (w x depth/2 e_z) h.
  const Vec3 arm = k.s.report.p_WC_ball - k.s.x.p_WG;
  const Vec3 v_C = 0.5 * (k.s.x.v_WG + (k.s.x.q_WB * k.s.x.w_B).cross(arm) + k.s.y.v_WG + (k.s.y.q_WB * k.s.y.w_B).cross(arm));
  const double at_engine_point = k.bench.f_W[0].dot(v_C) * (k.s.y.t - k.s.x.t);
  std::printf("bench force: booked %.15g, at the engine's point %.15g\n", friction_booked(c), at_engine_point);
  EXPECT_GT(std::abs(at_engine_point - k.work), 1e-6 * std::abs(k.work));
}

TEST(LedgerBooking, TheAdaptersOwnWorkOfTheBenchsForceIsBookedInstead) {
  // MuJoCo and DART hold the bench's force in their own coordinates (the torque in the body
  // frame) and measure its work on their own velocities; the ledger books that, once a step.
  const BodyModel b = BodyModel::from_scene(fixtures::dimensionless_scene());
  BenchForceStep k = bench_force_step(b);
  k.s.report.bench.work = 0.75 * k.work;
  StepChecks c(b);
  c.start(k.s.x);
  ASSERT_TRUE(c.after_step(k.s.y.t, k.s.y, k.s.report));
  EXPECT_EQ(friction_booked(c), 0.75 * k.work);
}

TEST(LedgerBooking, TheStepsWorkIsBookedAsTheEngineGivesIt) {
  // An engine whose integrator integrated its forces' power over the step (Simbody's explicit
  // integrators) gives the step's work in step_work: the ledger books it as given, whatever the
  // report's forces would book (here an impulse whose quadrature gives another value).
  const BodyModel b = BodyModel::from_scene(fixtures::dimensionless_scene());
  const ImpulseStep s = impulse_step(b, false);
  ContactReport r = s.report;
  r.step_work.set = true;
  r.step_work.normal = 0.25 * s.delta_ke;
  r.step_work.friction = 0.5 * s.delta_ke;
  StepChecks c(b);
  c.start(s.x);
  ASSERT_TRUE(c.after_step(s.y.t, s.y, r));
  const EnergyLedgerTotals l = c.energy_ledger();
  EXPECT_EQ(l.normal_work, 0.25 * s.delta_ke);
  EXPECT_EQ(l.friction_work, 0.5 * s.delta_ke);
  EXPECT_EQ(c.friction_work(), 0.5 * s.delta_ke);
}

// An engine configuration and the bound its ledger closes to over the first second of
// leine_glocker (the Coulomb top's slip dies out there, its friction removing 7.1e-3 E0).
struct Closing {
  std::string engine, key, value;  // a setting that removes the engine's own energy term
  double bound;                    // |N| / E0
};

TEST(LedgerBooking, EnginesLedgersCloseWhereTheyHaveNoEnergyTermOfTheirOwn) {
  // Measured |N| / E0 with the booking (before it: the lever arm from the end's G, the last RK4
  // stage's force for MuJoCo): Bullet without split impulse 1.6e-7 (4.9e-4), ODE without its
  // gyroscopic term 1.6e-7 (4.9e-4), DART 1.4e-6 (4.2e-4, its explicit Coriolis term's work
  // within the first second), MuJoCo RK4 2.0e-6 (1.7e-3) and Euler 7.5e-6 (4.3e-4), Siconos
  // 1.1e-8 (2.5e-6), Simbody (RK-Merson, its work integrated by its own stages) 6.2e-8 (1.97e-4
  // with the power at each step's end times the step). Each bound is about five times the
  // measured value, and below the value before by 20 or more.
  const std::vector<Closing> cases = {
      {"bullet", "split_impulse", "false", 1e-6}, {"ode", "gyroscopic", "false", 1e-6},
      {"dart", "", "", 1e-5},                     {"mujoco", "", "", 1e-5},
      {"mujoco", "integrator", "Euler", 4e-5},    {"siconos", "", "", 1e-7},
      {"simbody", "", "", 3e-7}};
  const auto available = available_engines();
  Scene base = load_scene(std::string(TIPPE_SOURCE_DIR) + "/harness/scenes/leine_glocker.toml");
  base.run.duration = 1.0;
  for (const Closing& k : cases) {
    if (std::find(available.begin(), available.end(), k.engine) == available.end()) continue;
    Scene s = base;
    if (k.value == "false") s.engines[k.engine][k.key] = false;
    else if (!k.key.empty()) s.engines[k.engine][k.key] = k.value;
    TrajectorySink sink;
    const RunRecord r = run_scene(s, k.engine, &sink);
    ASSERT_EQ(r.status, "ok") << k.engine << ": " << r.status_detail;
    const Trajectory& tr = sink.trajectory;
    const double e0 = std::abs(tr.energy[0]);
    double worst = 0.0;
    for (size_t i = 0; i < tr.size(); ++i) worst = std::max(worst, std::abs(tr.numerical_energy[i]) / e0);
    std::printf("[%s %s=%s] leine_glocker 1 s: |N| <= %.3g E0, friction work %.3g E0\n", k.engine.c_str(), k.key.c_str(),
                k.value.c_str(), worst, tr.friction_work.back() / e0);
    EXPECT_LE(worst, k.bound) << k.engine << " " << k.key;
    EXPECT_LT(tr.friction_work.back() / e0, -7e-3) << k.engine << ": the slip's dissipation is booked";
  }
}

TEST(LedgerBooking, SiconosBenchForceIsBookedAsMoreauJeanAppliesIt) {
  // Moreau-Jean integrates the external forces as theta f(t_n+1) + (1 - theta) f(t_n): the bench's
  // viscous force acts as the mean of this step's and the last's. At the stem's touchdown on
  // toy_viscous (t = 4.638) the stem's first viscous force acted at half its size; booked whole,
  // it was twice the energy it removed, N rising 3.6e-3 E0 in one step. Measured with the mean:
  // no sample rise of N above 4.4e-6 E0 over the whole run (1.5e-7 since the bench's part is
  // booked at the bench's point, EnginesBookTheBenchsViscousForceAsTheyApplyIt).
  const auto available = available_engines();
  if (std::find(available.begin(), available.end(), "siconos") == available.end()) GTEST_SKIP() << "Siconos not built";
  Scene s = load_scene(std::string(TIPPE_SOURCE_DIR) + "/harness/scenes/toy_viscous.toml");
  s.run.duration = 4.7;
  TrajectorySink sink;
  const RunRecord r = run_scene(s, "siconos", &sink);
  ASSERT_EQ(r.status, "ok") << r.status_detail;
  ASSERT_TRUE(r.stem_contact_time.has_value() && *r.stem_contact_time < 4.69) << "the touchdown is in the run";
  const Trajectory& tr = sink.trajectory;
  const double e0 = std::abs(tr.energy[0]);
  double worst = 0.0;
  for (size_t i = 1; i < tr.size(); ++i) worst = std::max(worst, (tr.numerical_energy[i] - tr.numerical_energy[i - 1]) / e0);
  std::printf("[siconos] toy_viscous to 4.7 s: largest sample rise of N %.3g E0\n", worst);
  EXPECT_LE(worst, 5e-5);
}

TEST(LedgerBooking, EnginesBookTheBenchsViscousForceAsTheyApplyIt) {
  // toy_viscous to just past the stem's touchdown (4.64 s), where ball and stem slide together and
  // the viscous force removes half the energy in 0.1 s. Measured max |N| / E0 (with the bench's
  // force booked at the engine's contact point before): MuJoCo RK4 9.0e-7 (3.2e-4 by 4.75 s, the
  // same at half and a quarter of the step: the soft contact's point inside the penetration),
  // Siconos 2.1e-6 (4.9e-4). Both now fall by four with each halving of the step (second order;
  // to 6 s: MuJoCo 8.9e-7, 2.2e-7, 5.6e-8; Siconos 2.0e-6, 5.1e-7, 1.3e-7). Bounds: about three
  // times the measured, 70 times below before.
  struct Case {
    std::string engine;
    double bound;
  };
  const auto available = available_engines();
  Scene s = load_scene(std::string(TIPPE_SOURCE_DIR) + "/harness/scenes/toy_viscous.toml");
  s.run.duration = 4.75;
  for (const Case& k : {Case{"mujoco", 3e-6}, Case{"siconos", 7e-6}}) {
    if (std::find(available.begin(), available.end(), k.engine) == available.end()) continue;
    TrajectorySink sink;
    const RunRecord r = run_scene(s, k.engine, &sink);
    ASSERT_EQ(r.status, "ok") << k.engine << ": " << r.status_detail;
    ASSERT_TRUE(r.stem_contact_time.has_value() && *r.stem_contact_time < 4.65) << k.engine << ": the touchdown is in the run";
    const Trajectory& tr = sink.trajectory;
    const double e0 = std::abs(tr.energy[0]);
    double worst = 0.0;
    for (size_t i = 0; i < tr.size(); ++i) worst = std::max(worst, std::abs(tr.numerical_energy[i]) / e0);
    std::printf("[%s] toy_viscous to 4.75 s: |N| <= %.3g E0, friction work %.3g E0\n", k.engine.c_str(), worst,
                tr.friction_work.back() / e0);
    EXPECT_LE(worst, k.bound) << k.engine;
    EXPECT_LT(tr.friction_work.back() / e0, -0.5) << k.engine << ": the two-contact slide is in the run";
  }
}

}  // namespace
}  // namespace tippe
