// The engines' modelling choices that are not physics (stem collision shape, Bullet's contact breaking threshold): applied, and what they move.
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "engines/core/adapters.h"
#include "engines/bullet/bullet_sim.h"
#include "harness/io/scene_io.h"
#include "harness/scene/resolve.h"

namespace tippe::test_modelling_choices {
namespace {

const std::string kScenes = std::string(TIPPE_SOURCE_DIR) + "/harness/scenes/";

struct Outcome {
  std::vector<Event> events;
  BodyState final_state;
  double energy = 0;
  RunStatus status = RunStatus::Ok;
};

Outcome run(const std::string& engine, const std::string& scene_file, std::vector<std::string> sets) {
  const Scene scene = load_scene(kScenes + scene_file, sets);
  auto sim = make_simulator(engine, scene);
  sim->advance_to(scene.run.duration);
  Outcome o;
  o.events = sim->events();
  o.status = sim->status();
  const Observation ob = sim->observe();
  o.energy = ob.energy;
  return o;
}

class StemShape : public ::testing::TestWithParam<std::string> {};

// Ball and stem both down from the start (tilt near pi: the two-contact phase). The capsule from
// O to P and the sphere at P have the same lowest point at every tilt (the capsule's other end
// lies inside the ball), so the runs are the same physics computed by two collision routines.
// Measured: final energies agree to 1e-15 relative in all three engines, the events to the
// sample. 1e-9 leaves a millionfold margin for rounding that compounds over 5000 steps.
TEST_P(StemShape, CapsuleAndTipSphereAreTheSameContact) {
  const std::string e = GetParam();
  const std::vector<std::string> base = {"run.duration=0.5"};
  auto with = [&](const std::string& shape) {
    auto s = base;
    s.push_back("engines." + e + ".stem_shape=\"" + shape + "\"");
    return run(e, "extremes/tilt_near_pi.toml", s);
  };
  const Outcome capsule = with("capsule"), sphere = with("tip_sphere");
  ASSERT_EQ(capsule.status, RunStatus::Ok);
  ASSERT_EQ(sphere.status, RunStatus::Ok);
  ASSERT_EQ(capsule.events.size(), sphere.events.size());
  bool stem_contact = false;
  for (size_t i = 0; i < capsule.events.size(); ++i) {
    EXPECT_EQ(capsule.events[i].name, sphere.events[i].name) << i;
    EXPECT_NEAR(capsule.events[i].time, sphere.events[i].time, 1e-12) << capsule.events[i].name;
    stem_contact = stem_contact || capsule.events[i].name == "stem_contact";
  }
  EXPECT_TRUE(stem_contact) << "the stem must touch, or the shape was never tested";
  EXPECT_NEAR(sphere.energy / capsule.energy, 1.0, 1e-9);
}

INSTANTIATE_TEST_SUITE_P(Engines, StemShape, ::testing::Values("bullet", "ode", "mujoco"));

TEST(StemShapeApplied, BulletBuildsASphereAtP) {
  const Scene scene = load_scene(kScenes + "toy.toml", {"engines.bullet.stem_shape=\"tip_sphere\""});
  const BulletReadback r = bullet_readback(*make_simulator("bullet", scene));
  const BodyModel m = BodyModel::from_scene(scene);
  ASSERT_TRUE(r.has_stem);
  EXPECT_EQ(r.stem_half_length, 0.0);
  EXPECT_DOUBLE_EQ(r.stem_radius, m.r);
  EXPECT_NEAR((r.stem_centre_B - Vec3(0, 0, m.z_P())).norm(), 0.0, 1e-15);
}

TEST(StemShapeApplied, MujocoWritesASphereGeom) {
  const Scene capsule = load_scene(kScenes + "toy.toml");
  const Scene sphere = load_scene(kScenes + "toy.toml", {"engines.mujoco.stem_shape=\"tip_sphere\""});
  EXPECT_NE(mujoco_mjcf(capsule).find("name=\"stem\" type=\"capsule\""), std::string::npos);
  EXPECT_NE(mujoco_mjcf(sphere).find("name=\"stem\" type=\"sphere\""), std::string::npos);
}

// MuJoCo's contact margin reaches its model: the floor's and the body's geoms carry it (MuJoCo
// adds the two geoms' margins), and 0 writes the rigid contact.
TEST(MujocoMargin, ReachesTheModel) {
  EXPECT_NE(mujoco_mjcf(load_scene(kScenes + "toy.toml")).find("margin=\"0\" gap=\"0\""), std::string::npos);
  const Scene m = load_scene(kScenes + "toy.toml", {"engines.mujoco.margin=0.001"});
  EXPECT_NE(mujoco_mjcf(m).find("margin=\"0.001\" gap=\"0\""), std::string::npos);
  // A margin makes the contact act before touching: the resting top sits higher (the soft
  // constraint's equilibrium moves out by about the margin).
  auto rest_height = [](const Scene& s) {
    auto sim = make_simulator("mujoco", s);
    sim->advance_to(0.2);
    return sim->state().p_WG.z();
  };
  Scene rest = load_scene(kScenes + "toy.toml", {"initial.spin=0", "initial.tilt=0", "run.duration=0.2"});
  Scene rest_m = load_scene(kScenes + "toy.toml",
                            {"initial.spin=0", "initial.tilt=0", "run.duration=0.2", "engines.mujoco.margin=0.001"});
  EXPECT_GT(rest_height(rest_m) - rest_height(rest), 5e-4);
}

// Bullet keeps a manifold point, and its warm-start impulses, while the next step's point lies
// within the breaking threshold. With Coulomb friction the friction rows start from those
// impulses, so the threshold moves the result (measured on toy over 3 s: the final tilt 0.0744
// at Bullet's 0.02, 0.0759 at 0.0002); with the viscous law (frictionless contacts, one normal
// row solved exactly) it does not (toy_viscous inverts at 5.30835007 s at both).
TEST(BulletContactBreakingThreshold, MovesCoulombNotViscous) {
  auto final_tilt = [](const std::string& scene, const std::string& factor) {
    const Scene s = load_scene(kScenes + scene, {"run.duration=1", "engines.bullet.contact_breaking_threshold=" + factor});
    auto sim = make_simulator("bullet", s);
    sim->advance_to(s.run.duration);
    return sim->observe().theta;
  };
  EXPECT_GT(std::abs(final_tilt("toy.toml", "0.02") - final_tilt("toy.toml", "0.0002")), 1e-6);
  // A lone normal row is solved exactly from any warm start: equal to rounding.
  EXPECT_NEAR(final_tilt("toy_viscous.toml", "0.02"), final_tilt("toy_viscous.toml", "0.0002"), 1e-12);
}

}  // namespace
}  // namespace tippe
