// One conformance suite for every simulator behind the common interface, the reference included.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "../analytic/initial_state.h"
#include "../engines/bullet_sim.h"
#include "../engines/mujoco_sim.h"
#include "../engines/ode_sim.h"
#include "records.h"

namespace tippe {
namespace {

// The dimensionless body of the source (REFERENCE_VALUES.md).
Scene base_scene() {
  Scene s;
  s.name = "conformance";
  s.gravity = 1.0;
  s.body = {1.0, 0.25, 1.2, 0.9, 0.0, MassModel::Given};
  s.mass = {1.0, 0.3, 0.4, 0.45};
  s.contact.friction = FrictionLaw::Coulomb;
  s.contact.mu = 0.3;
  s.initial.tilt = 0.1;
  s.initial.spin = 5.0;
  s.run = {2.0, 0.01, 1e-10, 1e-12};
  return s;
}

// Mass properties as the simulator holds them: mass, centre of mass in B, principal moments.
struct Held {
  double mass;
  Vec3 com_B;
  Vec3 inertia;
};

// Test-only: each engine exposes its own read-back (the harness itself never needs this).
Held held_mass(const std::string& engine, const Simulator& sim, const Scene& s) {
  if (engine == "ode") {
    const OdeMassReadback r = ode_mass_readback(sim);
    return {r.mass, r.c_B, r.I_B.diagonal()};
  }
  if (engine == "mujoco") {
    const MujocoModelReadback r = mujoco_model_readback(sim);
    // The centre of mass about G: MuJoCo's body_ipos is about the body frame's origin.
    return {r.mass, r.ipos_B + r.frame_origin_G, r.inertia};
  }
  if (engine == "bullet") {
    const BulletReadback r = bullet_readback(sim);
    return {r.mass, Vec3::Zero(), r.inertia_B};
  }
  // The reference holds the scene's numbers by construction.
  return {s.mass.mass, Vec3::Zero(), Vec3(s.mass.inertia_transverse, s.mass.inertia_transverse, s.mass.inertia_axial)};
}

// Per-engine tolerances at the engine's default time step, each with its origin.
struct Tolerances {
  double rest_drift;       // |p_G - p_G0| / R after 2 time units at rest upright
  double spin_rel;         // relative change of a frictionless upright spin over 2 time units
  double precession;       // |w_B - closed form| / |w| after 2 time units of free flight
  double roll_time_rel;    // sliding -> rolling time of a ball against 2 v0 / (7 mu g)
  double roll_speed_rel;   // rolling speed against 5 v0 / 7
};

Tolerances tolerances(const std::string& engine) {
  // analytic: integration at rtol 1e-10 (errors 1e-9 at most); the stick event is located on
  // dense output, so the rolling time is exact to the same order.
  if (engine == "analytic") return {1e-9, 1e-9, 1e-8, 1e-8, 1e-9};
  // Engines step at 1e-4 with first-order (ODE, Bullet) or RK4/semi-implicit (MuJoCo)
  // integration; a step of 1e-4 on a 1 s process gives ~1e-4 relative errors, and soft contacts
  // settle by ~1e-6 R. The roll time is read off sampled slip speeds (interval 0.01 of ~1 s):
  // 2 % covers one sample plus the engines' contact softness.
  return {1e-3, 1e-3, 1e-3, 0.02, 0.005};
}

class Conformance : public ::testing::TestWithParam<std::string> {};

TEST_P(Conformance, MassPropertiesReadBack) {
  Scene s = base_scene();
  auto sim = make_simulator(GetParam(), s);
  const Held h = held_mass(GetParam(), *sim, s);
  // Set explicitly from the scene, never computed from shapes: equal to round-off (1e-12).
  EXPECT_NEAR(h.mass, s.mass.mass, 1e-12 * s.mass.mass);
  EXPECT_NEAR(h.com_B.norm(), 0.0, 1e-12 * s.body.sphere_radius);
  EXPECT_NEAR(h.inertia.x(), s.mass.inertia_transverse, 1e-12 * s.mass.inertia_transverse);
  EXPECT_NEAR(h.inertia.y(), s.mass.inertia_transverse, 1e-12 * s.mass.inertia_transverse);
  EXPECT_NEAR(h.inertia.z(), s.mass.inertia_axial, 1e-12 * s.mass.inertia_axial);
}

TEST_P(Conformance, RestingUprightStaysPut) {
  Scene s = base_scene();
  s.initial.tilt = 0.0;
  s.initial.spin = 0.0;
  auto sim = make_simulator(GetParam(), s);
  const BodyState x0 = sim->observe().state;
  sim->advance_to(2.0);
  const Observation o = sim->observe();
  ASSERT_EQ(sim->status(), RunStatus::Ok) << sim->status_detail();
  std::printf("[%s] rest drift %.3g R, tilt %.3g\n", GetParam().c_str(), (o.state.p_WG - x0.p_WG).norm(), o.theta);
  EXPECT_LT((o.state.p_WG - x0.p_WG).norm() / s.body.sphere_radius, tolerances(GetParam()).rest_drift);
  EXPECT_LT(o.theta, 1e-6);
}

TEST_P(Conformance, FrictionlessUprightKeepsSpin) {
  Scene s = base_scene();
  s.contact.friction = FrictionLaw::None;
  s.contact.mu = 0.0;
  s.initial.tilt = 0.0;
  auto sim = make_simulator(GetParam(), s);
  sim->advance_to(2.0);
  const Observation o = sim->observe();
  ASSERT_EQ(sim->status(), RunStatus::Ok) << sim->status_detail();
  const double rel = std::abs(o.state.w_B.z() - 5.0) / 5.0;
  std::printf("[%s] spin change %.3g, tilt %.3g\n", GetParam().c_str(), rel, o.theta);
  EXPECT_LT(rel, tolerances(GetParam()).spin_rel);
  EXPECT_LT(o.theta, 1e-6);
}

TEST_P(Conformance, TorqueFreePrecession) {
  // Gravity off, the body in the air: w_B turns about e_Z at lambda = (C - A) w3 / A
  // (Euler's equations of an axisymmetric body).
  Scene s = base_scene();
  s.gravity = 0.0;
  s.contact.flight = true;
  s.initial.height = 1.0;
  s.initial.tilt = 0.3;
  s.initial.omega_given = true;
  s.initial.omega_B = {1.0, 0.0, 5.0};
  auto sim = make_simulator(GetParam(), s);
  const double T = 2.0;
  sim->advance_to(T);
  ASSERT_EQ(sim->status(), RunStatus::Ok) << sim->status_detail();
  const double A = s.mass.inertia_transverse, C = s.mass.inertia_axial;
  const double lambda = (C - A) * 5.0 / A;
  const Vec3 expected(std::cos(lambda * T), std::sin(lambda * T), 5.0);
  const Vec3 got = sim->observe().state.w_B;
  const double err = (got - expected).norm() / expected.norm();
  std::printf("[%s] precession error %.3g\n", GetParam().c_str(), err);
  EXPECT_LT(err, tolerances(GetParam()).precession);
  EXPECT_GT(sim->observe().state.p_WG.z(), s.body.sphere_radius);  // never touched the floor
}

TEST_P(Conformance, SlidingBallStartsRolling) {
  // A uniform ball launched sliding at v0 rolls from t = 2 v0 / (7 mu g) at speed 5 v0 / 7.
  Scene s = base_scene();
  s.contact.stem = false;
  s.mass = {1.0, 0.0, 0.4, 0.4};
  s.initial.tilt = 0.0;
  s.initial.spin = 0.0;
  s.initial.velocity_given = true;
  s.initial.velocity = {1.0, 0.0};
  const double v0 = 1.0, mu = s.contact.mu, g = s.gravity;
  const double t_roll = 2 * v0 / (7 * mu * g);
  auto sim = make_simulator(GetParam(), s);
  double t_stop = -1;
  for (int k = 1; k <= 200; ++k) {
    sim->advance_to(0.01 * k);
    if (t_stop < 0 && sim->observe().slip_speed < 1e-3 * v0) t_stop = 0.01 * k;
  }
  ASSERT_EQ(sim->status(), RunStatus::Ok) << sim->status_detail();
  for (const Event& e : sim->events())
    if (e.name == "stick") t_stop = e.time;  // the reference locates it exactly
  const double speed = std::hypot(sim->observe().state.v_WG.x(), sim->observe().state.v_WG.y());
  std::printf("[%s] rolling from %.6f (theory %.6f), speed %.6f (theory %.6f)\n", GetParam().c_str(), t_stop, t_roll,
              speed, 5 * v0 / 7);
  const Tolerances tol = tolerances(GetParam());
  EXPECT_NEAR(t_stop, t_roll, tol.roll_time_rel * t_roll);
  EXPECT_NEAR(speed, 5 * v0 / 7, tol.roll_speed_rel * 5 * v0 / 7);
}

std::string run_bytes(const std::string& engine, const Scene& s, const std::string& path) {
  {
    CsvTrajectoryWriter w(path);
    run_scene(s, engine, &w);
    w.commit();
  }
  std::ifstream in(path, std::ios::binary);
  std::ostringstream os;
  os << in.rdbuf();
  std::filesystem::remove(path);
  return os.str();
}

TEST_P(Conformance, Deterministic) {
  Scene s = base_scene();
  s.run.duration = 1.0;
  const std::string dir = ::testing::TempDir();
  const std::string a = run_bytes(GetParam(), s, dir + "/det_a_" + GetParam() + ".csv");
  const std::string b = run_bytes(GetParam(), s, dir + "/det_b_" + GetParam() + ".csv");
  ASSERT_GT(a.size(), 1000u);
  EXPECT_TRUE(a == b) << "two runs of the same scene differ";
}

INSTANTIATE_TEST_SUITE_P(Engines, Conformance, ::testing::Values("analytic", "ode", "mujoco", "bullet"),
                         [](const auto& info) { return info.param; });

}  // namespace
}  // namespace tippe
