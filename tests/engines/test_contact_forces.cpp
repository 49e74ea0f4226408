// The contact forces each engine reports through the simulator interface (contact_forces), against a top at rest and a sliding ball.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

#include "engines/core/bench_friction.h"
#include "harness/io/scene_io.h"
#include "harness/scene/resolve.h"
#include "engines/core/registry.h"
#include "engines/core/simulator.h"
#include "tests/support/fixtures.h"

namespace tippe::test_contact_forces {
namespace {

// One row per engine: the bound of each check and where it comes from. A row that fails a check
// physics demands is instantiated under DISABLED_ (kKnownDeviations) with its measured numbers.
struct ForceRow {
  const char* engine;
  double rest_fn;   // |mean F_n - M g| / (M g) at rest upright on the ball, t in 0.5..1.5
  double rest_ft;   // max |F_t| / (M g) at rest upright
  double slide_ratio;  // max | |F_t| / (mu F_n) - 1 | while the ball slides (F_n > M g / 2)
  double slide_angle;  // max (1 + cos) of the angle between F_t and the slip velocity (0: opposed)
  double viscous_work;  // |W_t - W_bench| / |W_bench| on toy_viscous to 2 s
  const char* why;     // the origin of the bounds
};

void PrintTo(const ForceRow& r, std::ostream* os) { *os << r.engine; }

// The dimensionless body of the source (REFERENCE_VALUES.md): M = 1, g = 1, R = 1.
Scene base_scene() {
  Scene s = fixtures::dimensionless_scene();
  s.name = "contact_forces";
  s.initial.tilt = 0.0;
  s.initial.spin = 0.0;
  return s;
}

class ContactForcesTest : public ::testing::TestWithParam<ForceRow> {
 protected:
  const ForceRow& row() const { return GetParam(); }
};

TEST_P(ContactForcesTest, RestingUprightCarriesItsWeightWithoutFriction) {
  // Upright at rest on the ball: F_n = M g on the ball, no friction, no stem contact. The mean of
  // F_n over a window is M g up to M dv_z / T (momentum balance), so a soft contact that still
  // rings is checked by its mean; the friction must vanish at every sample.
  const Scene s = base_scene();
  const double W = s.mass.mass * s.gravity;
  auto sim = make_simulator(row().engine, s);
  double sum = 0.0, worst_ft = 0.0;
  int n = 0;
  for (int k = 0; k <= 1000; ++k) {
    sim->advance_to(0.5 + 1e-3 * k);
    const EngineContactForces f = sim->contact_forces();
    EXPECT_FALSE(f.stem.active) << row().engine << " reports a stem contact at rest upright";
    sum += f.ball.f_n;
    ++n;
    worst_ft = std::max(worst_ft, (f.ball.f_t_W.norm() + f.stem.f_t_W.norm()) / W);
    if (k == 1000) {
      ASSERT_TRUE(f.ball.active && f.ball.point_valid) << row().engine << ": no ball contact at rest";
      EXPECT_LT(std::hypot(f.ball.p_WC.x(), f.ball.p_WC.y()), 1e-6) << row().engine << ": contact point off the axis";
    }
  }
  const double rest_fn = std::abs(sum / n - W) / W;
  std::printf("[%s] rest F_n/Mg - 1 = %.3g (bound %.2g), max |F_t|/Mg = %.3g (bound %.2g)\n", row().engine, rest_fn,
              row().rest_fn, worst_ft, row().rest_ft);
  EXPECT_LE(rest_fn, row().rest_fn) << row().why;
  EXPECT_LE(worst_ft, row().rest_ft) << row().why;
}

// A uniform ball launched sliding at v0 = 1 along x without spin slides until t = 2 v0 / (7 mu g)
// = 0.95: all that time |F_t| = mu F_n, opposite to the contact point's slip velocity. Sampled
// every 1e-3 over t in 0.1..0.8, well inside the slide.
struct SlideSamples {
  int samples = 0, with_force = 0;
  double worst_ratio = 0.0, worst_angle = 0.0, sum_ratio = 0.0, min_slip = 1e300;
};

SlideSamples sample_slide(const std::string& engine) {
  const Scene s = fixtures::sliding_ball(1.0);
  const double mu = s.contact.mu;
  auto sim = make_simulator(engine, s);
  SlideSamples out;
  for (int k = 1; k <= 700; ++k) {
    sim->advance_to(0.1 + 1e-3 * k);
    ++out.samples;
    const EngineContactForces f = sim->contact_forces();
    if (!(f.ball.f_n > 0)) continue;  // no force this step (a soft contact that hops)
    const BodyState x = sim->state();
    Vec3 v_C = x.v_WG + (x.q_WB * x.w_B).cross(Vec3(0, 0, -s.body.sphere_radius));
    v_C.z() = 0.0;
    out.min_slip = std::min(out.min_slip, v_C.norm());
    const double ft = f.ball.f_t_W.norm();
    const double ratio = ft / (mu * f.ball.f_n);
    out.sum_ratio += ratio;
    out.worst_ratio = std::max(out.worst_ratio, std::abs(ratio - 1.0));
    out.worst_angle = std::max(out.worst_angle, ft > 0 ? 1.0 + f.ball.f_t_W.dot(v_C) / (ft * v_C.norm()) : 2.0);
    ++out.with_force;
  }
  std::printf("[%s] sliding: F_n > 0 at %d of %d samples; there mean |F_t|/(mu F_n) = %.6g, max ||F_t|/(mu F_n) - 1| = "
              "%.3g, max 1 + cos(F_t, v_C) = %.3g, min slip speed %.3g\n",
              engine.c_str(), out.with_force, out.samples, out.with_force ? out.sum_ratio / out.with_force : 0.0,
              out.worst_ratio, out.worst_angle, out.min_slip);
  return out;
}

TEST_P(ContactForcesTest, SlidingBallFeelsCoulombFrictionAgainstItsSlip) {
  const SlideSamples r = sample_slide(row().engine);
  ASSERT_GE(r.with_force, 1) << row().engine << ": no contact force while the ball slides";
  EXPECT_GT(r.min_slip, 1e-2) << row().engine << ": the ball stopped sliding";
  EXPECT_LE(r.worst_ratio, row().slide_ratio) << row().why;
  EXPECT_LE(r.worst_angle, row().slide_angle) << row().why;
}

// The sliding ball stays on the floor: a contact force at (nearly) every sample.
TEST_P(ContactForcesTest, SlidingBallCarriesItsWeightAtEverySample) {
  if (std::string(row().engine) == "mujoco") GTEST_SKIP() << "known deviation: DISABLED_MujocoSlidingBallCarriesItsWeight";
  const SlideSamples r = sample_slide(row().engine);
  EXPECT_EQ(r.with_force, r.samples) << row().engine << ": the sliding ball leaves the floor";
}

// MuJoCo 2.2 (the adapter's defaults: RK4, elliptic cone, solref 0.002 1): its convex soft
// contact pushes a slipping ball off the floor ("the only way to initiate slip is to generate
// some motion in the normal direction", MuJoCo's documentation): F_n > 0 at 4 of 700 samples
// (measured), the ball hops. At those 4, |F_t| = mu F_n to round-off and opposes the slip, as
// SlidingBallFeelsCoulombFrictionAgainstItsSlip checks.
TEST(ContactForcesKnown, DISABLED_MujocoSlidingBallCarriesItsWeight) {
  const SlideSamples r = sample_slide("mujoco");
  EXPECT_EQ(r.with_force, r.samples) << "mujoco: the sliding ball leaves the floor";
}

// The bounds. At rest the one contact's solve carries the weight exactly: F_n = M g and F_t = 0
// to round-off (1e-9 and 1e-12 leave orders of magnitude above the measured 0 to 4e-15 and far
// below any physical error), for rigid and soft contacts alike once settled (MuJoCo settles by
// 4.5e-7 R by t = 0.5, the conformance suite's rest drift). Simbody's Hertz contact still rings at
// t = 0.5..1.5 (amplitude 0.58 M g, damping ratio 4e-4: the conformance suite's F_n row), and
// 1001 point samples of that ring average it only to about amplitude / N = 6e-4: bound 1e-3
// (measured 1.4e-4). Sliding, every engine clamps the friction to its bound mu F_n exactly:
// 1e-9 (measured 0 to 4.4e-16). The slip is along x, a tangent direction of the engines whose
// friction is a box or pyramid (ODE, DART, Bullet): a slip at 45 deg to their axes would give
// up to sqrt(2) mu F_n there, which this scene does not test.
// Viscous work: the engine's friction work and the bench's applied work differ by
// sum F_t . (v_C at the step's end - at its start) h, first order in the step h: measured at
// h = 1e-4 (the default) and 5e-5, Bullet 8.2e-3 and 4.1e-3, ODE 6.9e-3 and 3.5e-3, DART 7.2e-3
// and 3.6e-3, MuJoCo 1.3e-3 and 7.1e-4, Siconos 1.1e-3 and 5.6e-4 (halving with h); bound: twice
// the value at h = 1e-4, rounded up. Simbody evaluates the law inside its error-controlled
// steps and its integrator books the work (its stages integrate the power): what is left is the
// error of the test's own sum of the power sampled every 1e-4 s, nearly all of it in the first
// millisecond (the top's fall onto its Hertz contact from zero depth, the viscous force
// switching on at t = 0+): 1.14e-3 at 1e-4, 2.2e-4 at 2e-5, 4.4e-5 at 5e-6 (first order), the
// booked work moving by 3e-7, so the test's sum converges on it; bound 3e-3. (The power at the
// step's end times the step, booked before, matched the test's sum to 1.1e-5: every report time
// ends a Simbody step, 20004 steps for 20000 reports, and both sum the power at the same
// instants. The trapezoid of the steps' two ends, 1.06e-3 from the test's sum, was 8e-5 from
// the integrated work.)
const ForceRow kRows[] = {
    {"bullet", 1e-9, 1e-12, 1e-9, 1e-9, 0.02, "rigid contact: round-off"},
    {"ode", 1e-9, 1e-12, 1e-9, 1e-9, 0.015, "rigid contact: round-off"},
    {"mujoco", 1e-9, 1e-12, 1e-9, 1e-9, 3e-3, "soft contact, settled: round-off"},
    {"dart", 1e-9, 1e-12, 1e-9, 1e-9, 0.015, "rigid contact: round-off"},
    {"simbody", 1e-3, 1e-12, 1e-9, 1e-9, 3e-3, "Hertz contact ringing at rest: sampled mean to ~6e-4"},
    {"siconos", 1e-9, 1e-12, 1e-9, 1e-9, 3e-3, "rigid contact: round-off"},
};

// ---- Friction work (Simulator::friction_work) --------------------------------------------------

TEST_P(ContactForcesTest, FrictionlessRunDoesNoFrictionWork) {
  // The spinning tilted top on a frictionless floor: no friction force, so no friction work,
  // whatever the engine's energy does.
  Scene s = base_scene();
  s.contact.friction = FrictionLaw::None;
  s.contact.mu = 0.0;
  s.initial.tilt = 0.1;
  s.initial.spin = 5.0;
  auto sim = make_simulator(row().engine, s);
  sim->advance_to(2.0);
  const double e0 = s.mass.mass * s.gravity * s.body.sphere_radius;  // M g R: the energy scale
  std::printf("[%s] frictionless: friction work %.3g M g R\n", row().engine, sim->friction_work() / e0);
  // Round-off: a frictionless contact's force has a horizontal part only as round-off of its
  // normal (Simbody's: -6e-17 M g R measured).
  EXPECT_LE(std::abs(sim->friction_work()), 1e-12 * e0) << row().engine;
}

// The step the test samples at: the engine's own fixed step, or 1e-4 s for an engine that
// chooses its steps (Simbody).
double sampling_step(const Simulator& sim) {
  for (const auto& [k, v] : sim.settings())
    if (k == "timestep") return std::stod(v);
  return 1e-4;
}

TEST_P(ContactForcesTest, ViscousFrictionWorkIsTheWorkTheBenchApplied) {
  // toy_viscous over its first 2 s (the rise starts; 2e4 steps of 1e-4 s): the bench's law
  // F_t = -k v_C at each contact the engine reports, applied over each step from the state at
  // its start, does the work sum F_t(x_k) . v_C(x_k) h. The engine's friction work takes the
  // velocity at the step's end, the force's point where the engine puts its contact: the two
  // differ by sum F_t . (v_C(x_k+1) - v_C(x_k)) h, first order in h (bound below).
  Scene s = load_scene(std::string(TIPPE_SOURCE_DIR) + "/harness/scenes/toy_viscous.toml");
  s.run.duration = 2.0;
  const BodyModel body = BodyModel::from_scene(s);
  auto sim = make_simulator(row().engine, s);
  const double h = sampling_step(*sim);
  double applied = 0.0;
  const long long n = static_cast<long long>(std::llround(s.run.duration / h));
  for (long long k = 0; k < n; ++k) {
    const BodyState x = sim->state();
    const EngineContactForces f = sim->contact_forces();
    ContactReport c;
    c.ball = f.ball.active;
    c.stem = f.stem.active;
    const BenchFrictionForces b = bench_friction_forces(body, s.contact, x, c);
    const Vec3 w_W = x.q_WB * x.w_B;
    for (int i = 0; i < b.n; ++i) applied += b.f_W[i].dot(x.v_WG + w_W.cross(b.r_GC_W[i])) * h;
    sim->advance_to(static_cast<double>(k + 1) * h);
  }
  ASSERT_EQ(sim->status(), RunStatus::Ok) << sim->status_detail();
  const double engine = sim->friction_work();
  const double rel = std::abs(engine - applied) / std::abs(applied);
  std::printf("[%s] toy_viscous to 2 s: friction work %.9g J, bench applied %.9g J, relative difference %.3g (bound %.2g)\n",
              row().engine, engine, applied, rel, row().viscous_work);
  EXPECT_LT(applied, 0.0) << "viscous friction removes energy";
  EXPECT_LE(rel, row().viscous_work) << row().why;
}

// A uniform ball (the stem left out) launched sliding at v0 = 1 and spinning about the vertical at
// 30 rad/s (R = 1, g = 1): a sphere on a plane touches at one point, so each step's report holds
// one engine point on the ball, whatever the engine's contact model (a persistent manifold that
// kept an earlier step's points, or a box floor's detector reporting several, would show here).
// Read at every step of the engine (its own fixed step; 1e-4 s for Simbody), 300 steps.
struct PointCounts {
  int steps = 0, with_contact = 0, fewest = 1 << 30, most = 0;
};

PointCounts count_points(const std::string& engine, const Scene& s) {
  auto sim = make_simulator(engine, s);
  const double h = sampling_step(*sim);
  PointCounts c;
  for (int k = 1; k <= 300; ++k) {
    sim->advance_to(k * h);
    const EngineContactForces f = sim->contact_forces();
    ++c.steps;
    if (f.stem.points > 0) ADD_FAILURE() << engine << ": a stem point on a ball without a stem";
    if (!f.ball.active) continue;
    ++c.with_contact;
    c.fewest = std::min(c.fewest, f.ball.points);
    c.most = std::max(c.most, f.ball.points);
  }
  EXPECT_EQ(sim->status(), RunStatus::Ok) << engine << ": " << sim->status_detail();
  return c;
}

TEST_P(ContactForcesTest, ASpinningSlidingBallTouchesAtOnePointEachStep) {
  const PointCounts c = count_points(row().engine, fixtures::sliding_ball(1.0, 30.0));
  std::printf("[%s] spinning, sliding ball: a ball contact at %d of %d steps, %d to %d points each\n", row().engine,
              c.with_contact, c.steps, c.with_contact ? c.fewest : 0, c.most);
  ASSERT_GT(c.with_contact, 0) << row().engine << ": no contact";
  EXPECT_EQ(c.fewest, 1) << row().engine;
  EXPECT_EQ(c.most, 1) << row().engine;
}

INSTANTIATE_TEST_SUITE_P(Engines, ContactForcesTest, ::testing::ValuesIn(kRows),
                         [](const ::testing::TestParamInfo<ForceRow>& info) { return std::string(info.param.engine); });

TEST(BenchFrictionMean, AddsEachForceByItsWeightToItsSurface) {
  BenchFrictionForces f;
  f.n = 2;
  f.stem[0] = false;
  f.stem[1] = true;
  f.f_W[0] = Vec3(0.1, -0.3, 0.0);
  f.f_W[1] = Vec3(-0.7, 0.2, 0.0);
  StepMeanForces mean;
  mean.friction_ball_W = Vec3(1.0, 2.0, 0.0);
  add_bench_friction_mean(mean, f, 0.25);
  EXPECT_EQ(mean.friction_ball_W, Vec3(1.0, 2.0, 0.0) + 0.25 * f.f_W[0]);
  EXPECT_EQ(mean.friction_stem_W, 0.25 * f.f_W[1]);
  // The report's step mean, where an adapter set one, gets the force as it is (weight 1),
  // bit for bit what a plain sum gives; an unset one is left alone.
  ContactReport r;
  r.step_mean.set = true;
  r.step_mean.friction_ball_W = Vec3(1.0 / 3.0, 0.1, 0.0);
  add_bench_friction(r, f);
  EXPECT_EQ(r.step_mean.friction_ball_W, Vec3(1.0 / 3.0, 0.1, 0.0) + f.f_W[0]);
  EXPECT_EQ(r.step_mean.friction_stem_W, f.f_W[1]);
  EXPECT_EQ(r.friction_stem_W, f.f_W[1]);
  ContactReport unset;
  add_bench_friction(unset, f);
  EXPECT_EQ(unset.step_mean.friction_ball_W, Vec3::Zero());
  EXPECT_EQ(unset.friction_ball_W, f.f_W[0]);
}

}  // namespace
}  // namespace tippe
