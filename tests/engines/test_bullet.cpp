// Tests of the Bullet adapter: read-back of mass and shapes, determinism, settings errors, a frictionless top, failure status.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <iostream>
#include <stdexcept>
#include <string>
#include <thread>

#include "engines/core/adapters.h"
#include "engines/bullet/bullet_sim.h"
#include "analytic/initial_state.h"
#include "analytic/observables.h"
#include "harness/io/scene_io.h"
#include "harness/scene/resolve.h"
#include "engines/core/simulator.h"
#include "tests/support/fixtures.h"

namespace tippe::test_bullet {
namespace {

using namespace fixtures;

bool same_bits(const Observation& a, const Observation& b) {
  bool eq = bit_equal(a.state.t, b.state.t) && bit_equal(a.normal_force, b.normal_force) &&
            a.engine_contact_valid == b.engine_contact_valid;
  for (int i = 0; i < 3; ++i)
    eq = eq && bit_equal(a.state.p_WG[i], b.state.p_WG[i]) && bit_equal(a.state.v_WG[i], b.state.v_WG[i]) &&
         bit_equal(a.state.w_B[i], b.state.w_B[i]) && bit_equal(a.p_WC_engine[i], b.p_WC_engine[i]);
  for (int i = 0; i < 4; ++i) eq = eq && bit_equal(a.state.q_WB.coeffs()[i], b.state.q_WB.coeffs()[i]);
  return eq;
}

// Both entry points must throw std::invalid_argument naming engines.bullet.KEY.
void expect_setting_error(const Scene& scene, const std::string& key) {
  const std::string want = "engines.bullet." + key;
  expect_refusal_naming([&] { validate_bullet_settings(scene); }, "validate_bullet_settings", want);
  expect_refusal_naming([&] { make_simulator("bullet", scene); }, "make_simulator", want);
}

std::string setting(const Simulator& sim, const std::string& key) { return setting_value(sim.settings(), key); }

TEST(Bullet, MassAndShapesReadBackEqualScene) {
  const Scene scene = dimensionless_scene();
  const auto sim = make_simulator("bullet", scene);
  const BulletReadback r = bullet_readback(*sim);
  const double R = scene.body.sphere_radius, d = scene.mass.com_offset, l = scene.body.stem_length;
  // 1e-12 relative: mass and inertia pass through setMassProps as reciprocals (two roundings);
  // a calculateLocalInertia box approximation would be off by tens of percent.
  EXPECT_NEAR(r.mass, scene.mass.mass, 1e-12 * scene.mass.mass);
  EXPECT_NEAR(r.inertia_B.x(), scene.mass.inertia_transverse, 1e-12 * scene.mass.inertia_transverse);
  EXPECT_NEAR(r.inertia_B.y(), scene.mass.inertia_transverse, 1e-12 * scene.mass.inertia_transverse);
  EXPECT_NEAR(r.inertia_B.z(), scene.mass.inertia_axial, 1e-12 * scene.mass.inertia_axial);
  EXPECT_NEAR(r.inv_inertia_B.x() * scene.mass.inertia_transverse, 1.0, 1e-12);
  EXPECT_NEAR(r.inv_inertia_B.z() * scene.mass.inertia_axial, 1.0, 1e-12);
  // The body frame is the centre-of-mass frame: its transform is the initial p_WG, q_WB, and the
  // geometry sits relative to G: ball centre O at d e_Z, stem segment from O to P = (d + l) e_Z.
  const BodyState x0 = scene_initial_state(scene);
  EXPECT_LE((r.p_WG - x0.p_WG).norm(), 1e-12 * R);
  EXPECT_LE(r.q_WB.angularDistance(x0.q_WB), 1e-12);
  EXPECT_LE((r.ball_centre_B - Vec3(0, 0, d)).norm(), 1e-12 * R);
  EXPECT_NEAR(r.ball_radius, R, 1e-12 * R);
  ASSERT_TRUE(r.has_stem);
  EXPECT_LE((r.stem_axis_B - Vec3::UnitZ()).norm(), 1e-12);
  const Vec3 O_B = r.stem_centre_B - r.stem_half_length * r.stem_axis_B;
  const Vec3 P_B = r.stem_centre_B + r.stem_half_length * r.stem_axis_B;
  EXPECT_LE((O_B - Vec3(0, 0, d)).norm(), 1e-12 * R);
  EXPECT_LE((P_B - Vec3(0, 0, d + l)).norm(), 1e-12 * R);
  EXPECT_NEAR(r.stem_radius, scene.body.stem_radius, 1e-12 * R);
  // Coefficients: floor 1, body mu, no restitution, no rolling/spinning without drilling.
  EXPECT_EQ(r.floor_friction, 1.0);
  EXPECT_EQ(r.body_friction, scene.contact.mu);
  EXPECT_EQ(r.body_rolling_friction, 0.0);
  EXPECT_EQ(r.body_spinning_friction, 0.0);
  EXPECT_EQ(r.body_restitution, 0.0);
  EXPECT_EQ(r.floor_restitution, 0.0);
  EXPECT_EQ(r.gyroscopic, "implicit_body");
  EXPECT_EQ(sim->version(), "bullet 3.24");
}

TEST(Bullet, InitialStateMatchesScene) {
  const Scene scene = dimensionless_scene();
  const auto sim = make_simulator("bullet", scene);
  const BodyState x0 = scene_initial_state(scene);
  const BodyState x = sim->observe().state;
  // Through btTransform (rotation stored as a matrix) and back: a few ulp.
  EXPECT_EQ(x.t, 0.0);
  EXPECT_LE((x.p_WG - x0.p_WG).norm(), 1e-14);
  EXPECT_LE((x.v_WG - x0.v_WG).norm(), 1e-14);
  EXPECT_LE(x.q_WB.angularDistance(x0.q_WB), 1e-14);
  EXPECT_LE((x.w_B - x0.w_B).norm(), 1e-13 * x0.w_B.norm());
}

TEST(Bullet, SettingsErrorsNameTheKey) {
  // One bad value per setting (type, range, choices) and an unknown key: Conformance.
  // EverySettingRefusesABadValueNamingItsKey. Here what only this engine's rules say.
  // A spelling users write from other engines: "time_step".
  Scene unknown = dimensionless_scene();
  unknown.engines["bullet"]["time_step"] = 1e-4;
  expect_setting_error(unknown, "time_step");
  Scene out_of_range = dimensionless_scene();
  out_of_range.engines["bullet"]["timestep"] = -1e-3;
  expect_setting_error(out_of_range, "timestep");
  Scene bad_directions = dimensionless_scene();
  bad_directions.engines["bullet"]["friction_directions"] = 3LL;
  expect_setting_error(bad_directions, "friction_directions");
  Scene bad_unit = dimensionless_scene();
  bad_unit.engines["bullet"]["mass_unit"] = 0.0;
  expect_setting_error(bad_unit, "mass_unit");

  Scene good = dimensionless_scene();
  good.engines["bullet"]["timestep"] = 2e-4;
  good.engines["bullet"]["substeps"] = 2LL;
  good.engines["bullet"]["gyroscopic"] = std::string("implicit_world");
  good.engines["bullet"]["mass_unit"] = 1e-3;
  EXPECT_NO_THROW(validate_bullet_settings(good));
  const auto sim = make_simulator("bullet", good);
  EXPECT_EQ(setting(*sim, "timestep"), "0.0002");
  EXPECT_EQ(setting(*sim, "substeps"), "2");
  EXPECT_EQ(setting(*sim, "internal_step"), "0.0001");
  EXPECT_EQ(setting(*sim, "mass_unit"), "0.001");
  const BulletReadback r = bullet_readback(*sim);
  EXPECT_EQ(r.gyroscopic, "implicit_world");
  // Read back in the scene's units: Bullet holds M / mass_unit (rounding of two divisions).
  EXPECT_NEAR(r.mass, 1.0, 1e-15);
  EXPECT_NEAR(r.inertia_B.x(), 0.4, 1e-15);
  EXPECT_NEAR(r.inertia_B.z(), 0.45, 1e-15);
}

// An upright top (tilt 0) on a frictionless floor: the floor's force is vertical through the
// contact point, which lies on the symmetry axis below G, so it has no torque about G and
// omega = spin e_Z is a relative equilibrium with constant spin.
TEST(Bullet, FrictionlessUprightTopKeepsSpin) {
  Scene scene = dimensionless_scene();
  scene.contact.friction = FrictionLaw::None;
  scene.initial.tilt = 0.0;
  const auto sim = make_simulator("bullet", scene);
  const BodyModel m = BodyModel::from_scene(scene);
  sim->advance_to(2.0);
  ASSERT_EQ(sim->status(), RunStatus::Ok) << sim->status_detail();
  const Observation o = sim->observe();
  // The implicit gyroscopic step is exact for omega along a principal axis and the contact has
  // no lever arm, so only rounding changes the spin: 2e4 steps of a few ulp each, ~1e-12
  // relative; 1e-10 leaves a margin without hiding a real torque (a 1e-6 R lever arm would
  // already give 1e-7).
  EXPECT_NEAR(o.state.w_B.z(), 5.0, 1e-10 * 5.0);
  EXPECT_LE(std::hypot(o.state.w_B.x(), o.state.w_B.y()), 1e-10 * 5.0);
  // Resting penetration: one point contact's velocity row stops the approach exactly, so the
  // depth stays at rounding level (measured 0); at worst gravity closes g h^2 = 1e-8 R per step
  // and the split push removes 20 % of it. 1e-3 R is the bench's bound for a usable contact.
  const double gap = surface_gap(m, o.state, Surface::Ball);
  EXPECT_GT(gap, -1e-3 * m.R);
  EXPECT_LT(gap, 1e-3 * m.R);  // and it has not taken off
  // Normal force M g to the solver's accuracy (PGS converges exactly for one point contact).
  EXPECT_NEAR(o.normal_force, m.M * m.g, 1e-6);
  ASSERT_TRUE(o.engine_contact_valid);
  EXPECT_LE((o.p_WC_engine - o.p_WC).norm(), 1e-6 * m.R);
  // Forces are cleared by Bullet after each step.
  const BulletReadback r = bullet_readback(*sim);
  EXPECT_EQ(r.total_force_W.norm(), 0.0);
  EXPECT_EQ(r.total_torque_W.norm(), 0.0);
}

// The bench's force (viscous law) must be gone after the step it was applied for.
TEST(Bullet, ViscousForceActsForOneStepOnly) {
  Scene scene = dimensionless_scene();
  scene.contact.friction = FrictionLaw::Viscous;
  scene.contact.k = 1.0;
  scene.engines["bullet"]["substeps"] = 2LL;
  const auto sim = make_simulator("bullet", scene);
  const double e0 = sim->observe().energy;
  sim->advance_to(1.0);
  ASSERT_EQ(sim->status(), RunStatus::Ok) << sim->status_detail();
  const BulletReadback r = bullet_readback(*sim);
  EXPECT_EQ(r.total_force_W.norm(), 0.0);
  EXPECT_EQ(r.total_torque_W.norm(), 0.0);
  for (double mu : r.point_friction) EXPECT_EQ(mu, 0.0);
  // Viscous friction only removes energy; 1e-6 allows the first-order integrator's drift.
  EXPECT_LT(sim->observe().energy, e0 + 1e-6);
  bool noted = false;
  for (const auto& n : sim->notes()) noted = noted || n.find("viscous") != std::string::npos;
  EXPECT_TRUE(noted);
}

// Gliding friction is the bench's force as well: Bullet's contact points stay frictionless and
// the force is gone after its step.
TEST(Bullet, GlidingLeavesBulletContactsFrictionless) {
  Scene scene = dimensionless_scene();
  scene.contact.friction = FrictionLaw::Gliding;
  scene.contact.mu = 0.3;
  const auto sim = make_simulator("bullet", scene);
  const double e0 = sim->observe().energy;
  sim->advance_to(1.0);
  ASSERT_EQ(sim->status(), RunStatus::Ok) << sim->status_detail();
  const BulletReadback r = bullet_readback(*sim);
  EXPECT_EQ(r.total_force_W.norm(), 0.0);
  EXPECT_EQ(r.total_torque_W.norm(), 0.0);
  EXPECT_FALSE(r.point_friction.empty());
  for (double mu : r.point_friction) EXPECT_EQ(mu, 0.0);
  EXPECT_LT(sim->observe().energy, e0 + 1e-6);  // as for the viscous law above
}

// rolling_mu = 1e3 must reach the solver: Bullet's own combination would cap it at 10.
TEST(Bullet, RollingMuReachesTheContactPoints) {
  Scene scene = dimensionless_scene();
  scene.contact.friction = FrictionLaw::Rolling;
  const auto sim = make_simulator("bullet", scene);
  sim->advance_to(0.01);
  const BulletReadback r = bullet_readback(*sim);
  ASSERT_FALSE(r.point_friction.empty());
  for (double mu : r.point_friction) EXPECT_EQ(mu, 1e3);
  for (double rf : r.point_rolling_friction) EXPECT_EQ(rf, 0.0);
  for (double e : r.point_restitution) EXPECT_EQ(e, 0.0);
  bool noted = false;
  for (const auto& n : sim->notes()) noted = noted || n.find("rolling approximated") != std::string::npos;
  EXPECT_TRUE(noted);
}

// Drilling: an upright spinning top loses spin at mu_d F_n / C = mu_d M g / C.
TEST(Bullet, DrillingRemovesSpin) {
  Scene scene = dimensionless_scene();
  scene.initial.tilt = 0.0;
  scene.contact.drilling = 0.01;
  const auto sim = make_simulator("bullet", scene);
  sim->advance_to(1.0);
  ASSERT_EQ(sim->status(), RunStatus::Ok) << sim->status_detail();
  const double expected = 5.0 - scene.contact.drilling * 1.0 * 1.0 / scene.mass.inertia_axial * 1.0;
  // The torsional row is exact per step; 1e-9 covers rounding and the 1e-12 R rolling gate.
  EXPECT_NEAR(sim->observe().state.w_B.z(), expected, 1e-9);
  const BulletReadback r = bullet_readback(*sim);
  ASSERT_FALSE(r.point_spinning_friction.empty());
  for (double s : r.point_spinning_friction) EXPECT_EQ(s, 0.01);
  for (double rf : r.point_rolling_friction) EXPECT_EQ(rf, 1e-12);
}

// A step far beyond Bullet's rotation limit ends the run with a status, never a crash. The
// largest step any engine accepts (0.1, shared_settings::timestep) at spin 20: |omega| h = 2,
// far beyond Bullet's pi/4 (at spin 5 the step was 0.5 when Bullet still accepted it).
TEST(Bullet, HugeStepEndsAsClampedOrDiverged) {
  Scene scene = dimensionless_scene();
  scene.initial.spin = 20.0;
  scene.engines["bullet"]["timestep"] = 0.1;
  const auto sim = make_simulator("bullet", scene);
  sim->advance_to(scene.run.duration);
  const RunStatus s = sim->status();
  EXPECT_TRUE(s == RunStatus::Clamped || s == RunStatus::Diverged) << to_string(s) << ": " << sim->status_detail();
  EXPECT_GT(sim->status_time(), 0.0);
  EXPECT_LE(sim->status_time(), scene.run.duration);
  EXPECT_FALSE(sim->status_detail().empty());
}

// The harness may run engines on worker threads: Bullet keeps no shared mutable state that
// changes results (profiling and statistics counters aside), so two at once match a serial run.
TEST(Bullet, TwoThreadsAtOnceMatchSerial) {
  const Scene scene = dimensionless_scene();
  const auto serial = make_simulator("bullet", scene);
  serial->advance_to(0.5);
  Observation a, b;
  auto run = [&scene](Observation* out) {
    const auto sim = make_simulator("bullet", scene);
    sim->advance_to(0.5);
    *out = sim->observe();
  };
  std::thread ta(run, &a), tb(run, &b);
  ta.join();
  tb.join();
  EXPECT_TRUE(same_bits(a, serial->observe()));
  EXPECT_TRUE(same_bits(b, serial->observe()));
}

// The SI toy top (A^2 C = 1.2e-18 kg^3 m^6) thrown 1 m above the floor, spinning about a tilted
// axis: torque-free about G until it lands (after 0.45 s), so Euler's equations hold exactly.
Scene si_toy_in_flight(double mass_unit, const std::string& gyroscopic) {
  Scene s = load_scene(std::string(TIPPE_SOURCE_DIR) + "/harness/scenes/toy_viscous.toml");
  s.contact.friction = FrictionLaw::None;
  s.contact.flight = true;
  s.initial.height = 1.0;
  s.initial.omega_given = true;
  s.initial.omega_B = {5.0, 0.0, 150.0};
  s.engines["bullet"]["mass_unit"] = mass_unit;
  s.engines["bullet"]["gyroscopic"] = gyroscopic;
  return s;
}

bool has_note_containing(const Simulator& sim, const std::string& text) {
  for (const std::string& n : sim.notes())
    if (n.find(text) != std::string::npos) return true;
  return false;
}

// Bullet's implicit gyroscopic step (its default) solves a 3x3 system with btMatrix3x3::solve33,
// which inverts the determinant only above SIMD_EPSILON = 2.2e-16: for the SI toy top the
// determinant is ~A^2 C = 1.2e-18 kg^3 m^6, so w x I w vanishes and the run is the one without
// the gyroscopic term (to rounding). That is Bullet's behaviour in SI units (kept, with a note);
// mass_unit = 1e-3 (grams) gives Bullet det ~ 1.2e-9 and the term back.
TEST(Bullet, GyroscopicTermVanishesBelowSolve33GuardAndMassUnitRestoresIt) {
  const double T = 0.2;
  auto run = [T](double mass_unit, const std::string& gyroscopic) {
    auto sim = make_simulator("bullet", si_toy_in_flight(mass_unit, gyroscopic));
    sim->advance_to(T);
    EXPECT_EQ(sim->status(), RunStatus::Ok) << sim->status_detail();
    return sim;
  };
  const auto si = run(1.0, "implicit_body");
  const auto si_none = run(1.0, "none");
  const auto grams = run(1e-3, "implicit_body");
  // Not bit for bit: Bullet still adds R (R^T w - 0) - w, rounding of the frame round trip.
  const BodyState a = si->observe().state, b = si_none->observe().state;
  std::cout << "SI implicit_body - none after " << T << " s: |dw| " << (a.w_B - b.w_B).norm() << ", |dp| "
            << (a.p_WG - b.p_WG).norm() << "\n";
  // Measured 1e-13 of |w| = 150 rad/s; 1e-10 is rounding's bound over 2000 steps, far below the
  // gyroscopic term's effect (the phase below turns by 0.9 rad).
  EXPECT_LE((a.w_B - b.w_B).norm(), 1e-10 * 150.0);
  EXPECT_TRUE(has_note_containing(*si, "gyroscopic term w x I w dropped"));
  EXPECT_FALSE(has_note_containing(*grams, "gyroscopic term w x I w dropped"));
  EXPECT_FALSE(has_note_containing(*si_none, "gyroscopic term w x I w dropped"));  // nothing to drop

  // Euler's equations of the free symmetric top: w_3 stays, (w_1, w_2) turns in the body at
  // -(A - C) w_3 / A = -4.58 rad/s, i.e. by -0.915 rad in 0.2 s. Without w x I w the body turns
  // about a fixed w_W, so w_B does not turn at all.
  const BodyModel m = BodyModel::from_scene(si_toy_in_flight(1.0, "none"));
  const double want = -(m.A - m.C) / m.A * 150.0 * T;
  auto phase = [](const Simulator& sim) {
    const Vec3 w = sim.observe().state.w_B;
    return std::atan2(w.y(), w.x());
  };
  std::cout.precision(10);
  std::cout << "w_B phase after " << T << " s: exact " << want << ", grams " << phase(*grams) << ", SI " << phase(*si) << "\n";
  // Bullet's one Newton step of implicit Euler per step has a phase error below lambda^2 h T =
  // 4e-4 rad (measured 6e-8); 1e-3 rad is a tenth of a percent of the turn.
  EXPECT_NEAR(phase(*grams), want, 1e-3);
  EXPECT_NEAR(phase(*si), 0.0, 1e-3);
}

// mass_unit is a unit and nothing else: Bullet's answer for the same top must not move with it
// once the gyroscopic guard is out of reach, nor between the SI top and the same top in a unit
// of length of 15 mm (every dimensionless number the same), which is the scaled scene.
TEST(Bullet, MassUnitAndLengthUnitLeaveTheAnswerAlone) {
  auto inversion = [](const std::string& file, double mass_unit) {
    Scene s = load_scene(std::string(TIPPE_SOURCE_DIR) + "/harness/scenes/" + file);
    s.engines["bullet"]["mass_unit"] = mass_unit;
    auto sim = make_simulator("bullet", s);
    sim->advance_to(s.run.duration);
    EXPECT_EQ(sim->status(), RunStatus::Ok) << sim->status_detail();
    for (const Event& e : sim->events())
      if (e.name == "inversion") return e.time;
    ADD_FAILURE() << file << " at mass_unit " << mass_unit << " did not invert";
    return -1.0;
  };
  const double grams = inversion("toy_viscous.toml", 1e-3);
  const double milligrams = inversion("toy_viscous.toml", 1e-6);
  const double unit_length = inversion("scaled/toy_viscous_unit_length.toml", 1.0);
  // The runs differ by rounding only (the same numbers times powers of ten): measured equal to
  // 12 digits. 1e-6 relative (4e-6 s, a twentieth of a step) leaves room for rounding over 43000
  // steps and still tells the gyroscopic term's loss, which moves the inversion by 0.98 s.
  std::cout.precision(12);
  std::cout << "toy_viscous inversion: grams " << grams << ", milligrams " << milligrams << ", 15 mm unit of length "
            << unit_length << "\n";
  EXPECT_NEAR(milligrams, grams, 1e-6 * grams);
  EXPECT_NEAR(unit_length, grams, 1e-6 * grams);
}

// Not a test: the inversion time at the default settings (run with --gtest_also_run_disabled_tests).
TEST(Bullet, DISABLED_MeasureInversion) {
  Scene scene = dimensionless_scene();
  scene.run.duration = 30.0;
  for (long long dirs : {2LL, 1LL}) {
    Scene s = scene;
    if (dirs == 1) s.engines["bullet"]["friction_directions"] = dirs;
    const auto sim = make_simulator("bullet", s);
    sim->advance_to(s.run.duration);
    std::cout << "friction_directions " << dirs << ": status " << to_string(sim->status()) << " "
              << sim->status_detail() << ", t = " << sim->observe().state.t << ", theta = " << sim->observe().theta
              << ", cpu " << sim->work().cpu_seconds << " s\n";
    int switches = 0;
    for (const Event& e : sim->events()) {
      if (e.name == "switch") ++switches;
      else std::cout << "  " << e.name << " at " << e.time << " " << e.detail << "\n";
    }
    std::cout << "  " << switches << " contact switches\n";
  }
}

}  // namespace
}  // namespace tippe
