// A friction law the bench applies itself acts at every contact the engine has: ball and stem down together lose energy as in the reference.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <string>
#include <utility>
#include <vector>

#include "harness/records/records.h"
#include "harness/measure/run.h"
#include "engines/core/registry.h"
#include "harness/io/scene_io.h"
#include "harness/scene/resolve.h"

namespace tippe::test_two_contact_friction {
namespace {

const std::string kScene = std::string(TIPPE_SOURCE_DIR) + "/harness/scenes/extremes/tilt_near_pi.toml";

// The fraction of E0 a run has lost by its end.
double energy_lost(const RunRecord& r) { return (r.energy_initial - r.energy_final) / r.energy_initial; }

// "engines.E.timestep=dt" for an engine with a time step; nothing for one without (a
// variable-step engine such as Simbody chooses its own steps and runs at its defaults).
std::vector<std::string> step_override(const std::string& engine, const std::string& dt) {
  for (const auto& [key, value] : engine_info(engine).default_settings())
    if (key == "timestep") return {"engines." + engine + ".timestep=" + dt};
  return {};
}

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
  const Scene scene = load_scene(kScene, step_override(engine, "2e-5"));
  const RunRecord run = run_scene(scene, engine, nullptr);
  ASSERT_EQ(run.status, "ok") << run.status_detail;
  EXPECT_GT(energy_lost(ref), 0.8) << "the scene no longer tests two contacts";
  EXPECT_NEAR(energy_lost(run), energy_lost(ref), 0.03)
      << engine << " loses " << energy_lost(run) << " of E0, the reference " << energy_lost(ref);
}

// A sample taken while the engine has ball and stem on the floor is on both surfaces, as the
// reference's samples are in its two-contact phase: Jellett's J is conserved on one surface only,
// so the J check (SampleSummary) must not run across such samples. Labelled by the lower surface
// alone, the two-contact phase of this scene (0.334 to 0.391 s in the reference) was checked as a
// run on the stem, and every engine was classed unphysical for a J "drift" there (0.34 to 0.40
// of J at this step; beyond the 1e-3 tolerance within 2 ms of the phase's start), at every step
// down to 1e-6. The engine's own "switch" events say when it has both contacts; every
// sample between a switch to "both" and the next switch must say Both, and the J drift the
// record keeps for the stem must then be the drift of its runs on the stem alone: below the J
// check's tolerance (1e-3; measured at this step 1.7e-5 (DART) to 4.0e-4 (Bullet), whose drift grows
// to 9.4e-4 at 1e-5).
struct SurfaceSink : SampleSink {
  std::vector<std::pair<double, Surface>> samples;
  void write(const Observation& o) override { samples.emplace_back(o.state.t, o.surface); }
};
class TwoContactSamples : public ::testing::TestWithParam<std::string> {};
TEST_P(TwoContactSamples, SamplesWithBallAndStemDownAreOnBoth) {
  const std::string engine = GetParam();
  std::vector<std::string> overrides = step_override(engine, "1e-4");
  overrides.push_back("run.duration=0.45");
  const Scene scene = load_scene(kScene, overrides);
  SurfaceSink sink;
  const RunRecord run = run_scene(scene, engine, &sink);
  ASSERT_EQ(run.status, "ok") << run.status_detail;
  std::vector<std::pair<double, bool>> switches;  // time, to both
  for (const Event& e : run.events)
    if (e.name == "switch") switches.emplace_back(e.time, e.detail.size() >= 4 && e.detail.compare(e.detail.size() - 4, 4, "both") == 0);
  int on_both = 0, mislabelled = 0;
  for (const auto& [t, surface] : sink.samples) {
    bool both = false;  // the engine's contacts at t: those of the last switch at or before t
    for (const auto& [ts, to_both] : switches)
      if (ts <= t + 1e-12) both = to_both;
    on_both += both;
    mislabelled += both != (surface == Surface::Both);
  }
  std::printf("%s: %d of %zu samples with ball and stem down, %d mislabelled; J drift on the stem %.3g\n", engine.c_str(),
              on_both, sink.samples.size(), mislabelled, run.jellett_drift_stem.value_or(-1));
  EXPECT_GT(on_both, 10) << "the scene no longer has a two-contact phase";
  EXPECT_EQ(mislabelled, 0);
  ASSERT_TRUE(run.jellett_drift_stem.has_value());
  EXPECT_LT(*run.jellett_drift_stem, 1e-3);
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

// Every registered engine (engines/core/registry.h).
INSTANTIATE_TEST_SUITE_P(Engines, TwoContactFriction, ::testing::ValuesIn(engine_names()),
                         [](const auto& info) { return info.param; });

INSTANTIATE_TEST_SUITE_P(Engines, TwoContactsTouch, ::testing::Values("ode", "bullet", "mujoco"),
                         [](const auto& info) { return info.param; });

INSTANTIATE_TEST_SUITE_P(Engines, TwoContactSamples, ::testing::Values("ode", "bullet", "mujoco", "dart", "siconos"),
                         [](const auto& info) { return info.param; });
// Finding, kept disabled: Simbody's compliant contact (Hunt-Crossley, c = 0.5, its default) has
// no two-contact phase to label here. When the ball lands its stem at t = 0.2837 s, ball and stem
// are down together for 0.1 ms and the top then hops on its stem: contacts of ~0.25 ms every
// ~10 ms with none between (restitution ~1 at these landing speeds, where the reference's impact
// is plastic), so 0 of 451 samples have both down. The energy it loses over the 2 s (the test
// above) still matches the reference's within 0.03 of E0.
INSTANTIATE_TEST_SUITE_P(DISABLED_Simbody, TwoContactSamples, ::testing::Values("simbody"),
                         [](const auto& info) { return info.param; });
// Finding, kept disabled: DART's detectors have no contact margin (a contact exists at a gap
// <= 0 only) and at the exact switching tilt the stem tip's gap comes out round-off above 0, so
// DART never reports it; with the ball carrying the weight the top then turns off the stem. At
// a tilt 1e-12 rad larger (a gap of ~-1e-14 m) DART reports ball -> stem -> both -> ball within
// 0.3 ms. ODE counts contacts within its surface layer, Bullet within its contact breaking
// threshold, MuJoCo's soft contact within its margin.
INSTANTIATE_TEST_SUITE_P(DISABLED_Dart, TwoContactsTouch, ::testing::Values("dart"),
                         [](const auto& info) { return info.param; });
// Kept disabled, and not a fault: Siconos reports a contact that carries an impulse (rigid, no
// margin), and here the stem carries none. Put down at the switching tilt without spin the top
// tips back onto its ball: the reference stays on the ball, theta falling from 1.9298104 to
// 1.9297094 in 2 ms, and Siconos the same to 7e-11 rad. The engines with a margin count the
// stem's touching without force as a contact.
INSTANTIATE_TEST_SUITE_P(DISABLED_Siconos, TwoContactsTouch, ::testing::Values("siconos"),
                         [](const auto& info) { return info.param; });

}  // namespace
}  // namespace tippe
