// The gliding friction law F_t = -mu F_n v_C (Rutstam 2012; mu in s/m): the reference's energy
// ledger, its two methods, a closed form, the published inversion time and the engines.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <optional>
#include <string>

#include "analytic/initial_state.h"
#include "analytic/reference_model.h"
#include "engines/core/adapters.h"
#include "engines/core/registry.h"
#include "harness/io/scene_io.h"
#include "harness/scene/resolve.h"
#include "engines/core/simulator.h"
#include "tests/support/reference_runs.h"

namespace tippe::test_gliding {
namespace {

Scene gliding_ball() { return load_scene(std::string(TIPPE_SOURCE_DIR) + "/harness/scenes/rutstam_gliding_ball.toml"); }

using fixtures::first_event;

double reference_inversion(const Scene& scene) {
  ReferenceModel m(scene);
  m.advance_to(scene.run.duration);
  EXPECT_EQ(m.status(), ReferenceStatus::Ok) << m.status_detail();
  const auto t = first_event(m.events(), "inversion");
  EXPECT_TRUE(t.has_value());
  return t.value_or(-1.0);
}

// The scene starts with zero contact slip, as published (v_G = -w x R_GC, see its header).
TEST(Gliding, ScenesStartWithoutSlip) {
  const Scene s = gliding_ball();
  ASSERT_EQ(s.contact.friction, FrictionLaw::Gliding);
  const BodyModel b = BodyModel::from_scene(s);
  const BodyState x = scene_initial_state(s);
  Vec3 v_C = x.v_WG + (x.q_WB * x.w_B).cross(contact_offset_W(b, x.q_WB, Surface::Ball));
  EXPECT_LT(v_C.norm(), 1e-15) << v_C.transpose();
}

// Friction work booked in the ledger equals the energy lost, to 1e-9 E0 along the whole run
// (the ledger integrates F_t . v_C on the dense output; the law has no impacts here).
TEST(Gliding, EnergyLedgerCloses) {
  const Scene s = gliding_ball();
  ReferenceModel m(s);
  const BodyModel& b = m.body();
  const double e0 = energy(b, m.state());
  double worst = 0.0;
  for (int k = 1; k <= 80; ++k) {
    m.advance_to(s.run.duration * k / 80);
    ASSERT_EQ(m.status(), ReferenceStatus::Ok) << m.status_detail();
    const EnergyLedger l = m.energy_ledger();
    worst = std::max(worst, std::abs(energy(b, m.state()) + l.total() - e0) / e0);
    EXPECT_EQ(l.impacts, 0.0);
  }
  const EnergyLedger l = m.energy_ledger();
  std::printf("gliding ball: friction work %.6g of E0 = %.6g, ledger residual %.3g E0\n", l.friction / e0, e0, worst);
  EXPECT_GT(l.friction, 0.5 * e0);  // it loses most of its energy while it inverts
  EXPECT_LT(worst, 1e-9);
}

// The inversion time is a property of the law, not of the method: Bulirsch-Stoer and
// Dormand-Prince agree to 1e-7 relative. Against the publication: Rutstam gives t(theta = pi/2)
// as about 5.88 s at mu = 0.3, i.e. to three digits; the reference must round to it (within
// half a unit of the last digit, 0.005 s).
TEST(Gliding, InversionTimeByBothMethodsAndThePublishedValue) {
  Scene s = gliding_ball();
  s.run.duration = 6.5;
  const double t_bs = reference_inversion(s);
  s.run.method = "dopri5";
  const double t_dp = reference_inversion(s);
  std::printf("gliding ball: t(theta = pi/2) bulirsch_stoer %.10f s, dopri5 %.10f s (published ~5.88 s)\n", t_bs, t_dp);
  EXPECT_NEAR(t_dp, t_bs, 1e-7 * t_bs);
  EXPECT_NEAR(t_bs, 5.88, 0.005);
}

// A ball with its centre of mass at its centre (d = 0), not spinning, slides upright on the
// plane: F_n = M g exactly (its gap acceleration is zero whatever it rotates), so the gliding
// force is -mu M g u with u the contact slip. Then dv/dt = -mu g u and I dw/dt = R_GC x F give
// du/dt = -mu g (1 + M R^2 / I) u: the slip decays exponentially with lambda = mu g (1 + M R^2/I),
// and v_G(t) = v0 - mu g v0 (1 - exp(-lambda t)) / lambda, which tends to the rolling limit
// v0 (M R^2 / I) / (1 + M R^2 / I) (5/7 v0 for a solid ball).
TEST(Gliding, SlidingBallMatchesTheClosedForm) {
  const double R = 0.02, M = 0.02, I = 0.4 * M * R * R, g = 9.81, mu = 0.3, v0 = 0.5;
  Scene s;
  s.name = "gliding_slide";
  s.gravity = g;
  s.body = {R, 0.0, 0.0, R, 0.0, MassModel::Given};
  s.mass = {M, 0.0, I, I};
  s.contact.friction = FrictionLaw::Gliding;
  s.contact.mu = mu;
  s.contact.stem = false;
  s.initial.tilt = 0.0;
  s.initial.spin = 0.0;
  s.initial.velocity_given = true;
  s.initial.velocity = {v0, 0.0};
  s.run = {3.0, 1e-2, 1e-11, 1e-15};
  const double lambda = mu * g * (1 + M * R * R / I);
  ReferenceModel m(s);
  const double e0 = energy(m.body(), m.state());
  double worst_u = 0.0, worst_v = 0.0;
  for (int k = 1; k <= 30; ++k) {
    const double t = 0.1 * k;
    m.advance_to(t);
    ASSERT_EQ(m.status(), ReferenceStatus::Ok) << m.status_detail();
    const BodyState x = m.state();
    const Vec3 w_W = x.q_WB * x.w_B;
    const Vec3 u = x.v_WG + w_W.cross(Vec3(0, 0, -R));
    const double u_exact = v0 * std::exp(-lambda * t);
    const double v_exact = v0 - mu * g * v0 * (1 - std::exp(-lambda * t)) / lambda;
    worst_u = std::max(worst_u, std::abs(u.x() - u_exact) / v0);
    worst_v = std::max(worst_v, std::abs(x.v_WG.x() - v_exact) / v0);
    EXPECT_NEAR(u.y(), 0.0, 1e-12 * v0);
    EXPECT_NEAR(m.forces().normal[0], M * g, 1e-9 * M * g);
  }
  std::printf("sliding ball: slip and v_G against the closed form, worst %.3g and %.3g of v0; final v_G / v0 %.12f "
              "(rolling limit 5/7 = %.12f)\n",
              worst_u, worst_v, m.state().v_WG.x() / v0, 5.0 / 7.0);
  EXPECT_LT(worst_u, 1e-8);
  EXPECT_LT(worst_v, 1e-8);
  // Friction work is the energy lost (no impacts, no drift beyond the tolerance).
  EXPECT_NEAR(energy(m.body(), m.state()) + m.energy_ledger().total(), e0, 1e-9 * e0);
}

// A contact whose load vanishes lifts (it never grazes: the friction vanishes with F_n). The
// reference records no graze with the gliding law.
TEST(Gliding, NoGrazeAndNoSlipEvents) {
  const Scene s = gliding_ball();
  ReferenceModel m(s);
  m.advance_to(s.run.duration);
  for (const auto& e : m.events()) {
    EXPECT_NE(e.name, "graze");
    EXPECT_NE(e.name, "stick");
  }
  EXPECT_EQ(m.graze_fraction_range().first, std::numeric_limits<double>::infinity());
}

// The toy top under the gliding law (mu = 0.46 s/m, about k / (M g) of toy_viscous): it inverts,
// touches down on its stem, passes the cascade of impacts to a hold and a phase on both
// contacts. The ledger (friction work at each contact, impacts, hold, projections) closes to
// 1e-9 E0 through all of it, and both methods touch down at the same time.
TEST(Gliding, StemTouchdownAndTwoContactsKeepTheLedger) {
  const std::vector<std::string> set = {"contact.friction=\"gliding\"", "contact.k=0", "contact.mu=0.46"};
  Scene s = load_scene(std::string(TIPPE_SOURCE_DIR) + "/harness/scenes/toy_viscous.toml", set);
  ASSERT_EQ(s.contact.friction, FrictionLaw::Gliding);
  std::optional<double> touchdown[2];
  for (int method = 0; method < 2; ++method) {
    if (method == 1) s.run.method = "dopri5";
    ReferenceModel m(s);
    const BodyModel& b = m.body();
    const double e0 = energy(b, m.state());
    double worst = 0.0;
    for (int k = 1; k <= 120; ++k) {
      m.advance_to(s.run.duration * k / 120);
      ASSERT_EQ(m.status(), ReferenceStatus::Ok) << m.status_detail();
      worst = std::max(worst, std::abs(energy(b, m.state()) + m.energy_ledger().total() - e0) / e0);
    }
    touchdown[method] = first_event(m.events(), "stem_contact");
    ASSERT_TRUE(touchdown[method].has_value());
    EXPECT_TRUE(first_event(m.events(), "two_contact").has_value());
    EXPECT_FALSE(first_event(m.events(), "graze").has_value());
    const EnergyLedger l = m.energy_ledger();
    std::printf("toy top, gliding, %s: stem touchdown %.10f s, ledger residual %.3g E0 (friction %.4f, impacts %.4f, "
                "holds %.4f, projections %.3g E0)\n",
                s.run.method.c_str(), *touchdown[method], worst, l.friction / e0, l.impacts / e0, l.holds / e0,
                l.projections / e0);
    EXPECT_LT(worst, 1e-9);
  }
  EXPECT_NEAR(*touchdown[1], *touchdown[0], 1e-7 * *touchdown[0]);
}

// ---- the engines, with the bench's explicit gliding force (F_n of the previous step) ---------

double engine_inversion(const std::string& engine, const Scene& scene) {
  const auto sim = make_simulator(engine, scene);
  bool noted = false;
  for (const auto& n : sim->notes()) noted = noted || n.find("gliding friction") != std::string::npos;
  EXPECT_TRUE(noted) << engine << " has no note on the gliding law";
  sim->advance_to(scene.run.duration);
  EXPECT_EQ(sim->status(), RunStatus::Ok) << sim->status_detail();
  for (const auto& e : sim->events())
    if (e.name == "inversion") return e.time;
  return -1.0;
}

// "Within a few per cent" (the issue): 2 %. The bench's explicit normal force is one step
// (1e-4 s) late, a first-order error of ~dt / 5.9 s; on the viscous stand-in of the same body
// (rutstam_ball, BENCHMARKS.md) MuJoCo is 0.018 % from the reference, Bullet -20 %, ODE +14 %.
constexpr double kEngineTolerance = 0.02;

void expect_engine_inverts_like_the_reference(const std::string& engine, double bullet_mass_unit = 1.0) {
  Scene s = gliding_ball();
  s.run.duration = 7.0;
  if (bullet_mass_unit != 1.0) s.engines["bullet"]["mass_unit"] = bullet_mass_unit;
  const double t_ref = reference_inversion(s);
  const double t = engine_inversion(engine, s);
  std::printf("gliding ball: %s inverts at %.6f s, reference %.6f s (%+.3f %%)\n", engine.c_str(), t, t_ref,
              100 * (t - t_ref) / t_ref);
  EXPECT_NEAR(t, t_ref, kEngineTolerance * t_ref);
}

TEST(GlidingEngines, MujocoInvertsLikeTheReference) { expect_engine_inverts_like_the_reference("mujoco"); }

// Finding, kept disabled: at its default settings (dt 1e-4, masses in kg) Bullet inverts at
// 4.7148 s, -19.8 % from the reference's 5.8788 s, and 4.7134 s at dt 1e-5, as on the viscous
// stand-in (rutstam_ball: -20 %), not an error of the explicit law (the sliding ball below is
// right to 5e-5). In kg and m this ball's inertia determinant (A^2 C = 2.9e-17 kg^3 m^6) is below
// the DBL_EPSILON guard of Bullet's implicit gyroscopic solve, so Bullet drops w x I w
// (docs/findings/bullet-length-scale.md). In grams it does not: the test below.
TEST(GlidingEngines, DISABLED_BulletInvertsLikeTheReference) { expect_engine_inverts_like_the_reference("bullet"); }

// The same in grams (engines.bullet.mass_unit = 1e-3): Bullet keeps its gyroscopic term and
// inverts at 5.87956 s (+0.013 %), as the same ball does in a unit of length of 20 mm.
TEST(GlidingEngines, BulletInGramsInvertsLikeTheReference) { expect_engine_inverts_like_the_reference("bullet", 1e-3); }

// Finding, kept disabled: ODE (dt 1e-4) inverts at 6.6873 s, +13.8 % from the reference's
// 5.8788 s; at dt 1e-5 at 5.9568 s (+1.3 %): its first-order error in the step, as on the
// viscous stand-in (rutstam_ball: +14 % at dt 1e-4, BENCHMARKS.md); in a 20 mm unit of length
// it is unchanged (6.6874 s).
TEST(GlidingEngines, DISABLED_OdeInvertsLikeTheReference) { expect_engine_inverts_like_the_reference("ode"); }

// The sliding ball of SlidingBallMatchesTheClosedForm in each engine: v_G(t) against
// v0 - mu g v0 (1 - exp(-lambda t)) / lambda. The bench's F_n is one step late and the engines'
// contact is soft: 1e-3 of v0, the explicit law's own error lambda dt at dt = 1e-4 (measured:
// Bullet and ODE 5.1e-5, MuJoCo 1.9e-5). All three apply the law right here, where Bullet and
// ODE are 20 % and 14 % off on Rutstam's ball.
class GlidingEngineSlide : public ::testing::TestWithParam<std::string> {};
TEST_P(GlidingEngineSlide, MatchesTheClosedForm) {
  const double R = 0.02, M = 0.02, I = 0.4 * M * R * R, g = 9.81, mu = 0.3, v0 = 0.5;
  Scene s;
  s.name = "gliding_slide";
  s.gravity = g;
  s.body = {R, 0.0, 0.0, R, 0.0, MassModel::Given};
  s.mass = {M, 0.0, I, I};
  s.contact.friction = FrictionLaw::Gliding;
  s.contact.mu = mu;
  s.contact.stem = false;
  s.initial.velocity_given = true;
  s.initial.velocity = {v0, 0.0};
  s.run = {1.0, 1e-2, 1e-10, 1e-14};
  const double lambda = mu * g * (1 + M * R * R / I);
  const auto sim = make_simulator(GetParam(), s);
  double worst = 0.0;
  for (int k = 1; k <= 10; ++k) {
    const double t = 0.1 * k;
    sim->advance_to(t);
    ASSERT_EQ(sim->status(), RunStatus::Ok) << sim->status_detail();
    const double v_exact = v0 - mu * g * v0 * (1 - std::exp(-lambda * t)) / lambda;
    worst = std::max(worst, std::abs(sim->observe().state.v_WG.x() - v_exact) / v0);
  }
  std::printf("sliding ball, %s: v_G against the closed form, worst %.3g of v0\n", GetParam().c_str(), worst);
  EXPECT_LT(worst, 1e-3);
}
// Every registered engine (engines/core/registry.h).
INSTANTIATE_TEST_SUITE_P(Engines, GlidingEngineSlide, ::testing::ValuesIn(engine_names()),
                         [](const auto& info) { return info.param; });

// MuJoCo's own model cannot carry the law (the bench applies it): export-mjcf names it.
TEST(GlidingEngines, MjcfExportNamesTheMissingLaw) {
  const auto missing = mujoco_mjcf_missing(gliding_ball());
  ASSERT_EQ(missing.size(), 1u);
  EXPECT_NE(missing[0].find("gliding friction"), std::string::npos) << missing[0];
  EXPECT_NE(missing[0].find("mu = 0.3 s/m"), std::string::npos) << missing[0];
}

}  // namespace
}  // namespace tippe
