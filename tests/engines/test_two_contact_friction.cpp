// A friction law the bench applies itself acts at every contact the engine has: ball and stem down together lose energy as in the reference.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <string>

#include "records/records.h"
#include "registry.h"
#include "io/scene_io.h"

namespace tippe {
namespace {

const std::string kScene = std::string(TIPPE_SOURCE_DIR) + "/harness/scenes/extremes/tilt_near_pi.toml";

// The fraction of E0 a run has lost by its end.
double energy_lost(const RunRecord& r) { return (r.energy_initial - r.energy_final) / r.energy_initial; }

class TwoContactFriction : public ::testing::TestWithParam<std::string> {};

// extremes/tilt_near_pi starts inverted with ball and stem both on the floor under the viscous law
// (k = 0.05): over 2 s the reference loses 88 % of E0 (0.886 on Bulirsch-Stoer, 0.879 on
// dopri5). With the viscous force at the lower contact only, the engines lost 0.30 (ODE), 0.29
// (Bullet) and 0.20 (MuJoCo) at this step, and no better at 1e-6: the other contact slid
// freely. The tolerance, 0.03 of E0, covers the reference's own spread between methods (0.007)
// and each engine's step error at 2e-5 (the change from 1e-4 to 2e-5 is below 0.005 on all
// three); friction at one contact misses it by 0.6.
TEST_P(TwoContactFriction, EnergyLostWithBallAndStemDownMatchesTheReference) {
  const std::string engine = GetParam();
  const Scene reference_scene = load_scene(kScene);
  const RunRecord ref = run_scene(reference_scene, "analytic", nullptr);
  ASSERT_EQ(ref.status, "ok") << ref.status_detail;
  const Scene scene = load_scene(kScene, {"engines." + engine + ".timestep=2e-5"});
  const RunRecord run = run_scene(scene, engine, nullptr);
  ASSERT_EQ(run.status, "ok") << run.status_detail;
  EXPECT_GT(energy_lost(ref), 0.8) << "the scene no longer tests two contacts";
  EXPECT_NEAR(energy_lost(run), energy_lost(ref), 0.03)
      << engine << " loses " << energy_lost(run) << " of E0, the reference " << energy_lost(ref);
}

// Engine-native laws act at the contacts the engine makes: a top put down at the switching tilt,
// where ball and stem touch the floor together (the stem tip's centre P at height r with O at
// height R: cos(theta_s) = (r - R) / l), must have a contact on each in every engine, under
// Coulomb friction as under the bench's own laws.
class TwoContactsTouch : public ::testing::TestWithParam<std::string> {};
TEST_P(TwoContactsTouch, BothContactsAreMadeWhenBothTouch) {
  const std::string engine = GetParam();
  const Scene base = load_scene(kScene);
  const double theta_s =
      std::acos((base.body.stem_radius - base.body.sphere_radius) / base.body.stem_length);
  char tilt[64];
  std::snprintf(tilt, sizeof tilt, "initial.tilt=%.17g", theta_s);
  const Scene scene = load_scene(kScene, {"contact.friction=\"coulomb\"", "contact.k=0", "contact.mu=0.3",
                                          "initial.spin=0", tilt, "run.duration=0.002"});
  const RunRecord run = run_scene(scene, engine, nullptr);
  ASSERT_EQ(run.status, "ok") << run.status_detail;
  bool both = false;
  for (const Event& e : run.events)
    both = both || (e.name == "switch" && e.detail.size() >= 4 && e.detail.compare(e.detail.size() - 4, 4, "both") == 0);
  EXPECT_TRUE(both) << engine << " never reports ball and stem contacts together";
}

// Every registered engine (engines/registry.h).
INSTANTIATE_TEST_SUITE_P(Engines, TwoContactFriction, ::testing::ValuesIn(engine_names()),
                         [](const auto& info) { return info.param; });

INSTANTIATE_TEST_SUITE_P(Engines, TwoContactsTouch, ::testing::Values("ode", "bullet", "mujoco"),
                         [](const auto& info) { return info.param; });
// Finding, kept disabled: DART's detectors have no contact margin (a contact exists at a gap
// <= 0 only) and at the exact switching tilt the stem tip's gap comes out round-off above 0, so
// DART never reports it; with the ball carrying the weight the top then turns off the stem. At
// a tilt 1e-12 rad larger (a gap of ~-1e-14 m) DART reports ball -> stem -> both -> ball within
// 0.3 ms. ODE counts contacts within its surface layer, Bullet within its contact breaking
// threshold, MuJoCo's soft contact within its margin.
INSTANTIATE_TEST_SUITE_P(DISABLED_Dart, TwoContactsTouch, ::testing::Values("dart"),
                         [](const auto& info) { return info.param; });

}  // namespace
}  // namespace tippe
