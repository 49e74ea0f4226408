// Tests of the MuJoCo adapter: mass read-back, determinism, settings validation, a frictionless spinning top, the exported MJCF.
#include <gtest/gtest.h>
#include <mujoco/mujoco.h>
#include <unistd.h>

#include <cmath>
#include <memory>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <iostream>
#include <stdexcept>
#include <string>
#include <vector>

#include "engines/core/adapters.h"
#include "analytic/initial_state.h"
#include "engines/mujoco/mujoco_sim.h"
#include "analytic/observables.h"
#include "engines/core/simulator.h"
#include "tests/support/fixtures.h"

namespace tippe::test_mujoco {
namespace {

using namespace fixtures;

// Expects validate_mujoco_settings, make_mujoco_simulator and mujoco_mjcf to throw
// std::invalid_argument whose message names engines.mujoco.KEY.
void expect_setting_error(const Scene& scene, const std::string& key) {
  const std::string want = "engines.mujoco." + key;
  expect_refusal_naming([&] { validate_mujoco_settings(scene); }, "validate_mujoco_settings", want);
  expect_refusal_naming([&] { make_mujoco_simulator(scene); }, "make_mujoco_simulator", want);
  expect_refusal_naming([&] { mujoco_mjcf(scene); }, "mujoco_mjcf", want);
}

TEST(Mujoco, MassReadBackEqualsScene) {
  const Scene scene = dimensionless_scene();
  const auto sim = make_mujoco_simulator(scene);
  const MujocoModelReadback r = mujoco_model_readback(*sim);
  // 1e-12 relative: the values travel as 17-digit decimals through MuJoCo's XML parser and
  // compiler, which round-trip doubles exactly; anything larger would mean MuJoCo (or the
  // adapter) derived them from the geoms or re-balanced them.
  EXPECT_NEAR(r.mass, scene.mass.mass, 1e-12 * scene.mass.mass);
  const double A = scene.mass.inertia_transverse, C = scene.mass.inertia_axial;
  EXPECT_NEAR(r.inertia.x(), A, 1e-12 * A);
  EXPECT_NEAR(r.inertia.y(), A, 1e-12 * A);
  EXPECT_NEAR(r.inertia.z(), C, 1e-12 * C);
  // The body frame's origin is the ball's centre O (the default body_frame), G at -d e_Z from it:
  // the centre of mass about G must vanish (to 1e-12 R) and the principal axes must be the body
  // axes (so that inertia.z is about e_Z).
  EXPECT_LE((r.ipos_B + r.frame_origin_G).norm(), 1e-12 * scene.body.sphere_radius);
  EXPECT_NEAR(r.frame_origin_G.z(), scene.mass.com_offset, 1e-15);
  EXPECT_LE(r.iquat_B.angularDistance(Quat::Identity()), 1e-12);
  EXPECT_EQ(r.nq, 7);
  EXPECT_EQ(r.nv, 6);
  EXPECT_EQ(r.timestep, 1e-4);
}

TEST(Mujoco, InitialStateMatchesScene) {
  // The engine must start from exactly the shared initial state (up to quaternion rounding).
  const Scene scene = dimensionless_scene();
  const auto sim = make_mujoco_simulator(scene);
  const BodyState x0 = scene_initial_state(scene);
  const BodyState y = sim->observe().state;
  EXPECT_EQ(y.t, 0.0);
  // 1e-14: 17-digit decimals round-trip exactly; what remains is the renormalization of the
  // quaternion, a few ulps of unit-size numbers.
  EXPECT_LE((y.p_WG - x0.p_WG).norm(), 1e-14);
  EXPECT_LE((y.v_WG - x0.v_WG).norm(), 1e-14);
  EXPECT_LE(y.q_WB.angularDistance(x0.q_WB), 1e-14);
  EXPECT_LE((y.w_B - x0.w_B).norm(), 1e-14);
}

TEST(Mujoco, SettingsErrorsNameTheKey) {
  // One bad value per setting (type, range, choices) and an unknown key: Conformance.
  // EverySettingRefusesABadValueNamingItsKey. Here what only this engine's rules say.
  {
    Scene s = dimensionless_scene();
    s.engines["mujoco"]["impratio"] = -1.0;  // out of range
    expect_setting_error(s, "impratio");
  }
  {
    Scene s = dimensionless_scene();
    s.engines["mujoco"]["solref"] = std::vector<double>{0.002};  // wrong length
    expect_setting_error(s, "solref");
  }
  {
    Scene s = dimensionless_scene();
    s.engines["mujoco"]["solimp"] = std::vector<double>{0.9, 1.5, 0.001, 0.5, 2.0};  // dmax > 1
    expect_setting_error(s, "solimp");
  }
  {
    Scene s = dimensionless_scene();
    s.engines["mujoco"]["condim"] = 2LL;  // in range but not a MuJoCo condim
    expect_setting_error(s, "condim");
  }
}

TEST(Mujoco, SettingsAreListedAndApplied) {
  Scene s = dimensionless_scene();
  s.engines["mujoco"]["timestep"] = 2e-4;
  s.engines["mujoco"]["integrator"] = std::string("Euler");
  s.engines["mujoco"]["iterations"] = 30LL;
  EXPECT_NO_THROW(validate_mujoco_settings(s));
  const auto sim = make_mujoco_simulator(s);
  const SettingsList list = sim->settings();
  EXPECT_EQ(setting_value(list, "timestep"), "0.0002");
  EXPECT_EQ(setting_value(list, "integrator"), "Euler");
  EXPECT_EQ(setting_value(list, "iterations"), "30");
  EXPECT_EQ(setting_value(list, "cone"), "elliptic");
  EXPECT_EQ(setting_value(list, "solref"), "[0.002, 1]");
  EXPECT_EQ(setting_value(list, "condim_used"), "3");
  EXPECT_EQ(setting_value(list, "friction_used"), "[0.3, 0, 0]");
  EXPECT_EQ(sim->version(), "mujoco 2.2.2");
  EXPECT_EQ(mujoco_model_readback(*sim).timestep, 2e-4);
  sim->advance_to(0.01);
  // 0.01 / 2e-4 = 50 steps.
  EXPECT_EQ(sim->work().steps, 50);
  EXPECT_EQ(sim->status(), RunStatus::Ok) << sim->status_detail();
}

TEST(Mujoco, CondimFollowsTheFrictionLaw) {
  auto condim = [](const Scene& s) { return setting_value(make_mujoco_simulator(s)->settings(), "condim_used"); };
  Scene s = dimensionless_scene();
  EXPECT_EQ(condim(s), "3");
  s.contact.drilling = 0.05;
  EXPECT_EQ(condim(s), "4");
  s.contact.drilling = 0.0;
  s.contact.friction = FrictionLaw::None;
  s.contact.mu = 0.0;
  EXPECT_EQ(condim(s), "1");
  s.contact.friction = FrictionLaw::Viscous;
  s.contact.k = 1.0;
  EXPECT_EQ(condim(s), "1");
  // Gliding friction is the bench's force too: MuJoCo's contact stays frictionless.
  s.contact.friction = FrictionLaw::Gliding;
  s.contact.k = 0.0;
  s.contact.mu = 0.3;
  EXPECT_EQ(condim(s), "1");
  s.contact.mu = 0.0;
  s.contact.friction = FrictionLaw::Rolling;
  s.contact.k = 0.0;
  const auto sim = make_mujoco_simulator(s);
  EXPECT_EQ(setting_value(sim->settings(), "condim_used"), "3");
  EXPECT_EQ(setting_value(sim->settings(), "noslip_iterations_used"), "10");
  bool noted = false;
  for (const auto& n : sim->notes()) noted = noted || n.find("rolling approximated") != std::string::npos;
  EXPECT_TRUE(noted);
}

TEST(Mujoco, BareBallHasNoStemGeom) {
  Scene s = dimensionless_scene();
  s.contact.stem = false;
  const std::string xml = mujoco_mjcf(s);
  EXPECT_EQ(xml.find("\"stem\""), std::string::npos);
  EXPECT_NE(xml.find("name=\"ball\""), std::string::npos);
  const auto sim = make_mujoco_simulator(s);
  sim->advance_to(0.1);
  EXPECT_EQ(sim->status(), RunStatus::Ok) << sim->status_detail();
  EXPECT_EQ(sim->work().steps, 1000);
}

TEST(Mujoco, EngineResetIsADivergedRun) {
  // |qvel| above mjMAXVAL = 1e10 makes mj_step reset mjData to qpos0 with zero velocity and
  // carry on: the adapter must not pass that off as the top's motion.
  Scene s = dimensionless_scene();
  s.initial.spin = 2e10;
  const auto sim = make_mujoco_simulator(s);
  sim->advance_to(0.01);
  EXPECT_EQ(sim->status(), RunStatus::Diverged);
  EXPECT_EQ(sim->work().steps, 1);
  EXPECT_FALSE(std::isfinite(sim->observe().state.w_B.z()));
}

TEST(Mujoco, FrictionlessUprightTopKeepsSpin) {
  Scene s = dimensionless_scene();
  s.contact.friction = FrictionLaw::None;
  s.contact.mu = 0.0;
  s.initial.tilt = 0.0;
  s.initial.spin = 5.0;
  // Stated here so that the expected depth below does not depend on the adapter's defaults.
  const double tc = 0.002, zeta = 1.0, dmin = 0.9, dmax = 0.95, width = 0.001;
  s.engines["mujoco"]["solref"] = std::vector<double>{tc, zeta};
  s.engines["mujoco"]["solimp"] = std::vector<double>{dmin, dmax, width, 0.5, 2.0};
  const auto sim = make_mujoco_simulator(s);
  const BodyModel m = BodyModel::from_scene(s);
  double worst_gap = 0.0;
  for (int k = 1; k <= 200; ++k) {
    sim->advance_to(0.01 * k);
    worst_gap = std::min(worst_gap, surface_gap(m, sim->observe().state, Surface::Ball));
  }
  ASSERT_EQ(sim->status(), RunStatus::Ok) << sim->status_detail();
  const Observation o = sim->observe();
  EXPECT_NEAR(o.state.t, 2.0, 1e-12);
  // Upright and frictionless, the contact force is vertical and passes through G: no torque,
  // and w x I w = 0 for w along the symmetry axis, so the equations conserve the spin exactly.
  // What remains is rounding in 2e4 RK4 steps of unit-size numbers (~1e-16 each, ~1e-12 in
  // all): 1e-9 relative leaves a wide margin and is far below any physical effect.
  EXPECT_NEAR(o.state.w_B.z(), 5.0, 5.0 * 1e-9);
  EXPECT_LE(o.state.w_B.head<2>().norm(), 1e-9);
  // MuJoCo's documented soft contact (Computation chapter): a1 + d (b v + k r) = (1 - d) a0
  // with k = d / (dmax^2 tc^2 zeta^2); at rest (a1 = v = 0, a0 = -g) the depth is
  // r = (1 - d) g dmax^2 tc^2 zeta^2 / d^2, with d = dmin to 1e-7 since r << width.
  const double depth = (1 - dmin) * s.gravity * dmax * dmax * tc * tc * zeta * zeta / (dmin * dmin);
  const double gap = surface_gap(m, o.state, Surface::Ball);
  // The spring is critically damped and starts at zero depth and zero normal velocity: it
  // settles without overshoot, within 2 units (1000 time constants). The impedance grows with
  // depth, d - dmin = (r/width)^2 / midpoint (dmax - dmin) ~ 2e-8, which shifts the depth by
  // ~3e-7 relative (measured 2.4e-7); 1e-5 leaves margin for that and nothing else.
  EXPECT_NEAR(-gap, depth, 1e-5 * depth);
  EXPECT_GT(worst_gap, -(1 + 1e-5) * depth);
  // Standing on the ball, the floor carries the weight M g: at rest the solved normal
  // acceleration is zero to the solver tolerance 1e-10 (measured 1.6e-11).
  EXPECT_NEAR(o.normal_force, s.mass.mass * s.gravity, 1e-9);
  EXPECT_TRUE(o.engine_contact_valid);
  EXPECT_LE(o.p_WC_engine.head<2>().norm(), 1e-9);
}

TEST(Mujoco, ViscousForceActsAtTheContactPoint) {
  // An upright, non-spinning top sliding at v0 along x: the bench's viscous force -k v_C e_x at
  // the contact point, (R - d) below G, decelerates G and tips the top forward about +y.
  Scene s = dimensionless_scene();
  s.contact.friction = FrictionLaw::Viscous;
  s.contact.mu = 0.0;
  s.contact.k = 1.0;
  s.initial.tilt = 0.0;
  s.initial.spin = 0.0;
  s.initial.velocity_given = true;
  s.initial.velocity = {0.1, 0.0};
  const auto sim = make_mujoco_simulator(s);
  const double h = mujoco_model_readback(*sim).timestep;
  const double k = 1.0, M = s.mass.mass, A = s.mass.inertia_transverse;
  const double arm = s.body.sphere_radius - s.mass.com_offset;
  // The ball starts exactly touching (depth 0): MuJoCo makes a contact only for depth > 0, so
  // the first step runs without one and the bench applies no viscous force in it.
  EXPECT_FALSE(sim->observe().normal_force > 0);
  sim->advance_to(h);
  const BodyState x1 = sim->observe().state;
  EXPECT_EQ(x1.v_WG.x(), 0.1);
  EXPECT_TRUE(sim->observe().engine_contact_valid);
  // From now on the contact exists: one step of the force computed from the state at its start.
  BodyState x = x1;
  for (int n = 2; n <= 3; ++n) {
    sim->advance_to(n * h);
    ASSERT_EQ(sim->work().steps, n);
    const BodyState y = sim->observe().state;
    const double v_C = x.v_WG.x() - arm * x.w_B.y();  // w x R_C = (0, w_y, 0) x (0, 0, -arm) = (-arm w_y, 0, 0)
    // A force constant over one step changes v and w by exactly F h / M and (R_C x F) h / A
    // (mj_applyFT at the geometric contact point); what differs is the body's rotation within
    // the step (w_y h ~ 1e-9 rad) and rounding (measured 5e-13 and 8e-9 relative): 1e-6.
    EXPECT_NEAR((y.v_WG.x() - x.v_WG.x()) / h, -k * v_C / M, 1e-6 * k * v_C / M) << n;
    EXPECT_NEAR((y.w_B.y() - x.w_B.y()) / h, arm * k * v_C / A, 1e-6 * arm * k * v_C / A) << n;
    EXPECT_LE(std::abs(y.w_B.x()) + std::abs(y.w_B.z()) + std::abs(y.v_WG.y()), 1e-15) << n;
    x = y;
  }
}

TEST(Mujoco, ExportedMjcfAloneReproducesTheRun) {
  const Scene scene = dimensionless_scene();
  const std::string xml = mujoco_mjcf(scene);
  ASSERT_FALSE(xml.empty());
  char path[] = "/tmp/tippe_mujoco_test_XXXXXX.xml";
  const int fd = mkstemps(path, 4);
  ASSERT_GE(fd, 0);
  FILE* f = fdopen(fd, "w");
  ASSERT_NE(f, nullptr);
  ASSERT_EQ(std::fwrite(xml.data(), 1, xml.size(), f), xml.size());
  std::fclose(f);
  char error[1024] = "";
  mjModel* m = mj_loadXML(path, nullptr, error, sizeof error);
  std::remove(path);
  ASSERT_NE(m, nullptr) << error;
  mjData* d = mj_makeData(m);
  ASSERT_EQ(m->nkey, 1);
  mj_resetDataKeyframe(m, d, 0);
  const int n = 1000;
  for (int i = 0; i < n; ++i) mj_step(m, d);
  const std::vector<double> qpos(d->qpos, d->qpos + m->nq), qvel(d->qvel, d->qvel + m->nv);
  const double dt = m->opt.timestep;
  mj_deleteData(d);
  mj_deleteModel(m);

  const auto sim = make_mujoco_simulator(scene);
  sim->advance_to(n * dt);
  ASSERT_EQ(sim->work().steps, n);
  ASSERT_EQ(sim->status(), RunStatus::Ok) << sim->status_detail();
  const std::vector<double> a = mujoco_qpos(*sim), b = mujoco_qvel(*sim);
  ASSERT_EQ(a.size(), qpos.size());
  ASSERT_EQ(b.size(), qvel.size());
  // Same model, same keyframe, same steps: bit for bit, no tolerance.
  for (size_t i = 0; i < a.size(); ++i) EXPECT_TRUE(bit_equal(a[i], qpos[i])) << "qpos " << i << ": " << a[i] << " vs " << qpos[i];
  for (size_t i = 0; i < b.size(); ++i) EXPECT_TRUE(bit_equal(b[i], qvel[i])) << "qvel " << i << ": " << b[i] << " vs " << qvel[i];
}

// solref below MuJoCo's stability rule (timeconst >= 2 timestep) is accepted as MuJoCo accepts
// it: MuJoCo raises it (refsafe), and the run says so and records the value used.
TEST(Mujoco, SolrefBelowTwoStepsIsRaisedAsMujocoDoes) {
  Scene s = dimensionless_scene();
  s.engines["mujoco"]["solref"] = std::vector<double>{1e-4, 1.0};
  const auto sim = make_mujoco_simulator(s);
  EXPECT_EQ(setting_value(sim->settings(), "solref"), "[0.0001, 1]");
  EXPECT_EQ(setting_value(sim->settings(), "solref_used"), "[0.0002, 1]");
  bool noted = false;
  for (const auto& n : sim->notes()) noted = noted || n.find("raised by MuJoCo") != std::string::npos;
  EXPECT_TRUE(noted);
  // Raised, it is the same model as solref = 2 timestep: the same run bit for bit.
  Scene t = dimensionless_scene();
  t.engines["mujoco"]["solref"] = std::vector<double>{2e-4, 1.0};
  const auto twin = make_mujoco_simulator(t);
  sim->advance_to(0.2);
  twin->advance_to(0.2);
  EXPECT_TRUE(bit_equal(sim->observe().state, twin->observe().state));
}

Scene with_frame(Scene s, const std::string& frame) {
  s.engines["mujoco"]["body_frame"] = frame;
  return s;
}

// With the frame at the ball's centre O the model holds the same body: the centre of mass at
// -d e_Z in the body frame, the same moments, and the same state of G at the start.
TEST(Mujoco, BallCentreFrameHoldsTheSameBodyAndStart) {
  const Scene scene = with_frame(dimensionless_scene(), "ball_centre");
  const auto sim = make_mujoco_simulator(scene);
  const MujocoModelReadback r = mujoco_model_readback(*sim);
  // 1e-12: as MassReadBackEqualsScene (17-digit decimals through MuJoCo's compiler).
  EXPECT_NEAR(r.ipos_B.z(), -scene.mass.com_offset, 1e-12);
  EXPECT_NEAR(std::hypot(r.ipos_B.x(), r.ipos_B.y()), 0.0, 1e-12);
  EXPECT_NEAR(r.inertia.z(), scene.mass.inertia_axial, 1e-12);
  const BodyState x0 = scene_initial_state(scene), y = sim->observe().state;
  // 1e-14 as InitialStateMatchesScene, plus the frame change's own rounding (d w of unit size).
  EXPECT_LE((y.p_WG - x0.p_WG).norm(), 1e-14);
  EXPECT_LE((y.v_WG - x0.v_WG).norm(), 1e-13);
  EXPECT_LE((y.w_B - x0.w_B).norm(), 1e-14);
}

// In free flight (no contact) a rigid body's motion does not depend on where its frame is: both
// frames give the same trajectory of G to the integrator's error. This tests the conversion of
// qpos/qvel to G and back; RK4 at 1e-4 over 1 time unit of a spin of 5: error ~ (w h)^4 ~ 1e-13
// per step, 1e-9 after 1e4 steps.
TEST(Mujoco, FrameDoesNotChangeFreeFlight) {
  Scene s = dimensionless_scene();
  s.contact.flight = true;
  s.initial.height = 1.0;
  s.gravity = 1.0;
  const auto a = make_mujoco_simulator(with_frame(s, "com"));
  const auto b = make_mujoco_simulator(with_frame(s, "ball_centre"));
  a->advance_to(1.0);
  b->advance_to(1.0);
  const BodyState x = a->observe().state, y = b->observe().state;
  EXPECT_LE((x.p_WG - y.p_WG).norm(), 1e-9);
  EXPECT_LE((x.v_WG - y.v_WG).norm(), 1e-9);
  EXPECT_LE(x.q_WB.angularDistance(y.q_WB), 1e-9);
  EXPECT_LE((x.w_B - y.w_B).norm(), 1e-9);
}

// On the floor it does (docs/findings/mujoco-body-frame.md): the setting must reach the model.
// After 0.5 time units of the sliding dimensionless top the two frames part by far more than the
// free-flight agreement above.
TEST(Mujoco, FrameChangesTheContactRun) {
  const Scene s = dimensionless_scene();
  const auto a = make_mujoco_simulator(with_frame(s, "com"));
  const auto b = make_mujoco_simulator(with_frame(s, "ball_centre"));
  a->advance_to(2.0);
  b->advance_to(2.0);
  const BodyState x = a->observe().state, y = b->observe().state;
  EXPECT_GT((x.p_WG - y.p_WG).norm() + (x.w_B - y.w_B).norm(), 1e-6);
  EXPECT_NE(setting_value(a->settings(), "body_frame"), setting_value(b->settings(), "body_frame"));
}

// The exported model of a ball-centre frame, run in plain MuJoCo, is the adapter's run bit for bit.
TEST(Mujoco, ExportedBallCentreModelReproducesTheRun) {
  const Scene scene = with_frame(dimensionless_scene(), "ball_centre");
  char error[1024] = "";
  const std::string xml = mujoco_mjcf(scene);
  // mjVFS holds 2000 names of 1000 bytes: on the heap.
  auto vfs = std::make_unique<mjVFS>();
  mj_defaultVFS(vfs.get());
  ASSERT_EQ(mj_makeEmptyFileVFS(vfs.get(), "top.xml", static_cast<int>(xml.size())), 0);
  std::memcpy(vfs->filedata[vfs->nfile - 1], xml.data(), xml.size());
  mjModel* m = mj_loadXML("top.xml", vfs.get(), error, sizeof error);
  mj_deleteVFS(vfs.get());
  ASSERT_NE(m, nullptr) << error;
  mjData* d = mj_makeData(m);
  mj_resetDataKeyframe(m, d, 0);
  for (int i = 0; i < 500; ++i) mj_step(m, d);
  const std::vector<double> qpos(d->qpos, d->qpos + m->nq);
  mj_deleteData(d);
  mj_deleteModel(m);
  const auto sim = make_mujoco_simulator(scene);
  sim->advance_to(500 * 1e-4);
  const std::vector<double> a = mujoco_qpos(*sim);
  ASSERT_EQ(a.size(), qpos.size());
  for (size_t i = 0; i < a.size(); ++i) EXPECT_TRUE(bit_equal(a[i], qpos[i])) << "qpos " << i;
}

// Measurement, not a check: run with --gtest_also_run_disabled_tests to see whether and when
// the dimensionless Coulomb top (mu 0.3, spin 5, tilt 0.1) inverts within 30 units at the
// default settings. Environment knobs for comparisons: TIPPE_MJ_ENGINE (e.g. analytic),
// TIPPE_MJ_INTEGRATOR, TIPPE_MJ_TIMESTEP, TIPPE_MJ_IMPRATIO, TIPPE_MJ_TC (solref timeconst),
// TIPPE_MJ_CONE, TIPPE_MJ_FRICTIONLESS, TIPPE_MJ_VERBOSE (samples of the first unit).
TEST(MujocoMeasure, DISABLED_CoulombInversionTime) {
  Scene s = dimensionless_scene();
  s.run.duration = 30.0;
  const std::string engine = std::getenv("TIPPE_MJ_ENGINE") ? std::getenv("TIPPE_MJ_ENGINE") : "mujoco";
  if (const char* o = std::getenv("TIPPE_MJ_INTEGRATOR")) s.engines["mujoco"]["integrator"] = std::string(o);
  if (const char* o = std::getenv("TIPPE_MJ_TIMESTEP")) s.engines["mujoco"]["timestep"] = std::atof(o);
  if (const char* o = std::getenv("TIPPE_MJ_IMPRATIO")) s.engines["mujoco"]["impratio"] = std::atof(o);
  if (const char* o = std::getenv("TIPPE_MJ_TC")) s.engines["mujoco"]["solref"] = std::vector<double>{std::atof(o), 1.0};
  if (const char* o = std::getenv("TIPPE_MJ_CONE")) s.engines["mujoco"]["cone"] = std::string(o);
  if (std::getenv("TIPPE_MJ_FRICTIONLESS")) {
    s.contact.friction = FrictionLaw::None;
    s.contact.mu = 0.0;
  }
  const auto sim = make_simulator(engine, s);
  int switches = 0;
  double first_switch = -1, last_switch = -1, min_fn = 1e300;
  size_t seen = 0;
  for (int k = 1; k <= 3000; ++k) {
    sim->advance_to(0.01 * k);
    const Observation o = sim->observe();
    min_fn = std::min(min_fn, o.normal_force);
    if (k % 100 == 0 || (std::getenv("TIPPE_MJ_VERBOSE") && k <= 100 && k % 5 == 0))
      std::cout << "t " << o.state.t << " theta " << o.theta << " Fn " << o.normal_force << " slip " << o.slip_speed
                << " E " << o.energy << " J " << o.jellett << " min Fn " << min_fn << "\n";
    const auto ev = sim->events();
    for (; seen < ev.size(); ++seen) {
      if (ev[seen].name == "switch") {
        ++switches;
        if (first_switch < 0) first_switch = ev[seen].time;
        last_switch = ev[seen].time;
      } else {
        std::cout << "event " << ev[seen].name << " t = " << ev[seen].time << " " << ev[seen].detail << "\n";
      }
    }
    if (sim->status() != RunStatus::Ok) break;
  }
  std::cout << "status " << to_string(sim->status()) << " at " << sim->status_time() << " " << sim->status_detail() << "\n";
  std::cout << "switch events " << switches << " first " << first_switch << " last " << last_switch << "\n";
  const Observation o = sim->observe();
  std::cout << "final t " << o.state.t << " theta " << o.theta << " energy " << o.energy << " steps " << sim->work().steps
            << " solver iterations " << sim->work().solver_iterations << " cpu " << sim->work().cpu_seconds << " s\n";
  for (const auto& n : sim->notes()) std::cout << "note " << n << "\n";
}

}  // namespace
}  // namespace tippe
