// DART's collision detectors: where each puts the contact of a ball pressed into the floor, what the Bullet backend's error does to toy's verdict, and that backend in one process with the Bullet adapter.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <ostream>
#include <random>
#include <string>
#include <utility>

#include "engines/core/registry.h"
#include "harness/io/scene_io.h"
#include "harness/scene/resolve.h"
#include "tests/support/fixtures.h"
#include "tests/support/mapped_files.h"

namespace tippe::test_dart {
namespace {

Scene with_detector(Scene s, const std::string& detector) {
  s.engines["dart"]["collision_detector"] = detector;
  return s;
}

// Built into the DART module only where engines are modules (CMakeLists.txt).
bool bullet_backend_built() { return engines_in_modules(); }

struct PressedBall {
  double horizontal = 0.0, vertical = 0.0;  // worst |engine's point - lowest point| / R
  int missed = 0;                           // queries that reported no contact
};

// The ball (R = 1) pressed 1e-4..5e-4 R into the floor at `count` places and attitudes (tilt up to
// 0.5 rad, so the ball and not the stem is lowest), its centre up to `reach` R from the origin,
// each for one step from rest: the contact the step's collision pass found (at its start: DART
// detects after the velocity update, before positions move) against the ball's lowest point.
PressedBall press(const std::string& detector, double reach, int count, double floor_width = 1e4) {
  Scene s = with_detector(fixtures::dimensionless_scene(), detector);
  s.engines["dart"]["floor_width"] = floor_width;
  s.initial.spin = 0.0;
  auto sim = make_simulator("dart", s);
  std::mt19937 rng(20261204);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  PressedBall out;
  for (int i = 0; i < count; ++i) {
    BodyState x = sim->state();
    const double tilt = 0.5 * unit(rng), heading = 2 * M_PI * unit(rng), depth = 1e-4 + 4e-4 * unit(rng);
    x.q_WB = Quat(Eigen::AngleAxisd(heading, Vec3::UnitZ()) * Eigen::AngleAxisd(tilt, Vec3::UnitX()));
    x.v_WG.setZero();
    x.w_B.setZero();
    const double r = reach * unit(rng), at = 2 * M_PI * unit(rng);
    // O = G + d e_Z (d = com_offset): the ball's centre placed, G follows.
    const Vec3 p_GO_W = x.q_WB * Vec3(0, 0, s.mass.com_offset);
    const Vec3 p_WO(r * std::cos(at), r * std::sin(at), s.body.sphere_radius - depth);
    x.p_WG = p_WO - p_GO_W;
    sim->set_state(x);
    const Vec3 lowest = sim->observe().p_WC;
    sim->advance_to(sim->state().t + 1e-4);  // one step at DART's default
    const Observation o = sim->observe();
    if (!o.engine_contact_valid) {
      ++out.missed;
      continue;
    }
    const Vec3 d = o.p_WC_engine - lowest;
    out.horizontal = std::max(out.horizontal, std::hypot(d.x(), d.y()) / s.body.sphere_radius);
    out.vertical = std::max(out.vertical, std::abs(d.z()) / s.body.sphere_radius);
  }
  return out;
}

// Per detector, the worst horizontal distance (in R) between the contact a step's collision pass
// reports and the ball's lowest point, with its centre within 1 R and within 1000 R of the origin
// (the floor is a box 1e4 R wide). Measured (50 places each, DART 6.12.1, FCL 0.7, Bullet 3.24):
// "dart" 1.1e-16 and 1.1e-13 R, "fcl" 1.1e-16 and 1.2e-13 R (round-off at the place's size),
// "bullet" 1.6e-3 and 1.2e-3 R (its single-precision test at the box's size: see
// ContactErrorScalesWithTheFloorsWidth). Bounds: ten times the measured value, floored at 1e-12 R.
struct DetectorBounds {
  const char* detector;
  double near, far;
};
const DetectorBounds kBounds[] = {
    {"dart", 1e-12, 1.1e-12},
    {"fcl", 1e-12, 1.2e-12},
    {"bullet", 1.6e-2, 1.2e-2},
};

// GoogleTest prints a parameter into the test's listed name (and CTest's): its detector's name,
// not the struct's bytes, which hold a pointer and differ between builds.
void PrintTo(const DetectorBounds& row, std::ostream* os) { *os << row.detector; }

class DartDetector : public ::testing::TestWithParam<DetectorBounds> {};

// The vertical part is where a detector puts the point inside the overlap, at most the depth
// (below 5e-4 R): measured, "dart" and "bullet" on the floor's face (the depth), "fcl" halfway.
TEST_P(DartDetector, FindsTheContactAtTheBallsLowestPoint) {
  const DetectorBounds& row = GetParam();
  if (std::string(row.detector) == "bullet" && !bullet_backend_built())
    GTEST_SKIP() << "engines linked in: no Bullet backend for DART";
  for (const auto& [reach, bound] : {std::pair{1.0, row.near}, std::pair{1000.0, row.far}}) {
    const PressedBall b = press(row.detector, reach, 50);
    std::printf("[%s] centre within %g R: horizontal %.2g R, vertical %.2g R, missed %d\n", row.detector, reach,
                b.horizontal, b.vertical, b.missed);
    EXPECT_EQ(b.missed, 0) << row.detector << " within " << reach << " R";
    EXPECT_LE(b.vertical, 5e-4) << row.detector << " within " << reach << " R";
    EXPECT_LE(b.horizontal, bound) << row.detector << " within " << reach << " R";
  }
}

// A uniform ball (R = 1, the stem left out) launched sliding at v0 = 1 and spinning about the
// vertical at 30 rad/s, 300 steps of 1e-3 on each floor (boxes 1e4 R and 100 R wide): each step's
// collision pass reports exactly one contact, none kept from an earlier step. This rules out a
// cached point as what moves the Bullet backend's runs (Bullet keeps a persistent manifold of up to
// four points per pair, and DART's backend reports every point in it): see
// docs/findings/dart-bullet-backend.md.
TEST_P(DartDetector, TouchesASpinningSlidingBallAtOnePointEachStep) {
  const DetectorBounds& row = GetParam();
  if (std::string(row.detector) == "bullet" && !bullet_backend_built())
    GTEST_SKIP() << "engines linked in: no Bullet backend for DART";
  for (const double width : {1e4, 100.0}) {
    Scene s = with_detector(fixtures::sliding_ball(1.0, 30.0), row.detector);
    s.engines["dart"]["floor_width"] = width;
    s.engines["dart"]["timestep"] = 1e-3;
    auto sim = make_simulator("dart", s);
    int fewest = 1 << 30, most = 0;
    for (int k = 1; k <= 300; ++k) {
      sim->advance_to(k * 1e-3);
      const int n = sim->contact_forces().ball.points;
      fewest = std::min(fewest, n);
      most = std::max(most, n);
    }
    std::printf("[%s] floor %g R: %d to %d contacts a step\n", row.detector, width, fewest, most);
    EXPECT_EQ(sim->status(), RunStatus::Ok) << sim->status_detail();
    EXPECT_EQ(fewest, 1) << row.detector << " on a floor " << width << " R wide";
    EXPECT_EQ(most, 1) << row.detector << " on a floor " << width << " R wide";
  }
}

INSTANTIATE_TEST_SUITE_P(Detectors, DartDetector, ::testing::ValuesIn(kBounds),
                         [](const auto& info) { return std::string(info.param.detector); });

// The Bullet backend's contact error comes from single-precision arithmetic at the floor box's
// size (dart_settings.h, floor_width): a box 100 R wide instead of 1e4 R puts the contact within
// about 1e-5 R of the lowest point. Measured (50 places within 1 R): 1.6e-3 R at 1e4 R, 9.3e-6 R
// at 100 R. Bounds: ten times the narrow floor's, and a tenth of the wide floor's as its floor (the
// effect is there).
TEST(DartBulletBackend, ContactErrorScalesWithTheFloorsWidth) {
  if (!bullet_backend_built()) GTEST_SKIP() << "engines linked in: no Bullet backend for DART";
  const PressedBall wide = press("bullet", 1.0, 50, 1e4), narrow = press("bullet", 1.0, 50, 100.0);
  std::printf("[bullet] floor 1e4 R: %.2g R, 100 R: %.2g R\n", wide.horizontal, narrow.horizontal);
  EXPECT_EQ(narrow.missed, 0);
  EXPECT_LE(narrow.horizontal, 9.3e-5);
  EXPECT_GE(wide.horizontal, 1.6e-4);
}

// What the contact's error does to a verdict (modelling.toml, setup dart-bullet-floor): on toy
// (Coulomb, the reference rolls to 8 s) at timestep 1.25e-4, DART on its Bullet backend inverts at
// 6.56 s on the default floor (1e4 R) and rolls to 8 s, as the reference does, on a 100 R floor
// (docs/findings/dart-bullet-backend.md). The two runs differ in the floor's width alone.
TEST(DartBulletBackend, FloorWidthMovesToysRegime) {
  if (!bullet_backend_built()) GTEST_SKIP() << "engines linked in: no Bullet backend for DART";
  auto inversions = [](const std::string& width) {
    const Scene s = load_scene(std::string(TIPPE_SOURCE_DIR) + "/harness/scenes/toy.toml",
                               {"run.duration=8", "engines.dart.collision_detector=\"bullet\"",
                                "engines.dart.timestep=1.25e-4", "engines.dart.floor_width=" + width});
    auto sim = make_simulator("dart", s);
    sim->advance_to(s.run.duration);
    EXPECT_EQ(sim->status(), RunStatus::Ok) << sim->status_detail();
    int n = 0;
    for (const Event& e : sim->events()) n += e.name == "inversion";
    return n;
  };
  EXPECT_GE(inversions("1e4"), 1) << "on the default floor the Bullet backend inverts toy";
  EXPECT_EQ(inversions("100"), 0) << "on a 100 R floor it rolls, as the reference does";
}

// The final state of `engine` on the viscous dimensionless top after 0.3 time units.
BodyState run_for(const std::string& engine, const Scene& s) {
  auto sim = make_simulator(engine, s);
  sim->advance_to(0.3);
  EXPECT_EQ(sim->status(), RunStatus::Ok) << engine << ": " << sim->status_detail();
  return sim->state();
}

bool same_bits(const BodyState& a, const BodyState& b) {
  auto eq = [](const auto& u, const auto& v) { return std::memcmp(u.data(), v.data(), sizeof(double) * u.size()) == 0; };
  return eq(a.p_WG, b.p_WG) && eq(a.v_WG, b.v_WG) && eq(a.q_WB.coeffs(), b.q_WB.coeffs()) && eq(a.w_B, b.w_B);
}

bool maps_library(const std::string& file) { return !mapped_lines({file}).empty(); }

// DART's Bullet backend links Debian's single-precision Bullet, the Bullet adapter the
// double-precision build; both export the same C++ symbols. Each adapter is a module opened with
// RTLD_LOCAL, so each must bind its own: the Bullet adapter's run is bit-identical before and after
// DART's Bullet is loaded, DART's with the Bullet backend repeats bit for bit, and it stays near
// DART's own exact detector (a backend bound to the other precision's code would read its
// structures with the wrong layout). Measured against DART's detector after 0.3 time units:
// |dp_G| 1.2e-4 R, |dw| 9.4e-4 (of |w| about 5); with a 100 R floor 1.1e-4 R and 9.7e-4, so the
// contact point's error is not what moves it. Bounds: ten times those.
TEST(DartBulletBackend, RunsBesideTheBulletAdapterInOneProcess) {
  if (!bullet_backend_built()) GTEST_SKIP() << "engines linked in: no Bullet backend for DART";
  Scene s = fixtures::dimensionless_scene(FrictionLaw::Viscous, 1.0);
  const BodyState bullet_before = run_for("bullet", s);
  ASSERT_TRUE(maps_library("libBulletCollision-float64.so.3.24"));
  const BodyState dart_bullet = run_for("dart", with_detector(s, "bullet"));
  EXPECT_TRUE(maps_library("libBulletCollision.so.3.24")) << "DART's backend maps the single-precision Bullet";
  EXPECT_TRUE(maps_library("libBulletCollision-float64.so.3.24"));
  EXPECT_TRUE(same_bits(run_for("bullet", s), bullet_before)) << "the Bullet adapter's run moved";
  EXPECT_TRUE(same_bits(run_for("dart", with_detector(s, "bullet")), dart_bullet)) << "DART's Bullet backend does not repeat";
  const BodyState dart_own = run_for("dart", s);
  const double dp = (dart_bullet.p_WG - dart_own.p_WG).norm(), dw = (dart_bullet.w_B - dart_own.w_B).norm();
  std::printf("dart: bullet backend against its own detector after 0.3: |dp_G| %.2g R, |dw| %.2g\n", dp, dw);
  EXPECT_LE(dp, 1.2e-3);
  EXPECT_LE(dw, 9.4e-3);
}

// What is left of the gap on a narrow floor: the Bullet backend's depth. On the viscous top (R = 1,
// steps of 1e-4 from t = 0.01 to 0.3), DART's own detector and FCL hold the ball 3.9e-9 R deep on
// average (at most 9.9e-9 R) and its normal force leaves M g +- M g / 2 at 46 of 2901 steps (23
// without any force). On its Bullet backend the ball sinks to 1.4e-7 R (at most 1.7e-7 R, about the
// spacing of single-precision numbers at the centre's height, z ~ R: 6e-8 to 1.2e-7 R) and the
// force leaves that band at 631-734 steps, 332-375 without any force, on a floor 10 R and 100 R
// wide alike: the box's size is not it (measured, DART 6.12.1, Bullet 3.24). Bounds: about a
// third of the measured ratios (37 and 14: 12 and 5), and the two floors' gaps after 0.3 within
// 10 % of each other (measured 1.11e-4 R both).
struct DepthAndChatter {
  double mean_depth = 0.0;
  int off = 0;  // steps with |F_n - M g| > M g / 2
  BodyState end;  // at t = 0.3
};

DepthAndChatter depth_and_chatter(const std::string& detector, double floor_width) {
  Scene s = with_detector(fixtures::dimensionless_scene(FrictionLaw::Viscous, 1.0), detector);
  s.engines["dart"]["floor_width"] = floor_width;
  auto sim = make_simulator("dart", s);
  const double W = s.mass.mass * s.gravity;
  DepthAndChatter out;
  int n = 0;
  for (int k = 1; k <= 3000; ++k) {
    sim->advance_to(k * 1e-4);
    if (k < 100) continue;  // the touchdown
    out.mean_depth += -sim->observe().p_WC.z();
    out.off += std::abs(sim->contact_forces().ball.f_n - W) > 0.5 * W;
    ++n;
  }
  out.mean_depth /= n;
  out.end = sim->state();
  EXPECT_EQ(sim->status(), RunStatus::Ok) << sim->status_detail();
  return out;
}

TEST(DartBulletBackend, TheBallSinksDeeperAndItsForceChattersWhateverTheFloorsWidth) {
  if (!bullet_backend_built()) GTEST_SKIP() << "engines linked in: no Bullet backend for DART";
  const DepthAndChatter own = depth_and_chatter("dart", 100.0);
  double gaps[2];
  int i = 0;
  for (const double width : {10.0, 100.0}) {
    const DepthAndChatter b = depth_and_chatter("bullet", width);
    gaps[i++] = (b.end.p_WG - own.end.p_WG).norm();
    std::printf("floor %g R: depth %.3g R (own detector %.3g R), force off at %d steps (own %d), gap after 0.3: %.3g R\n",
                width, b.mean_depth, own.mean_depth, b.off, own.off, gaps[i - 1]);
    EXPECT_GE(b.mean_depth, 12 * own.mean_depth) << "floor " << width << " R";
    EXPECT_GE(b.off, 5 * own.off) << "floor " << width << " R";
  }
  EXPECT_NEAR(gaps[0], gaps[1], 0.1 * gaps[1]) << "the gap does not depend on the floor's width";
}

}  // namespace
}  // namespace tippe
