// Tests of reading sweep files into plans (harness/sweep/sweep_file.cpp): the shipped sweeps, each point's overrides, invalid files named by file and key, and the points and ids of ladders and grids.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <set>
#include <string>
#include <vector>

#include "harness/io/scene_io.h"
#include "harness/sweep/sweep.h"
#include "tests/support/files.h"
#include "tests/support/fixtures.h"
#include "tests/support/sweep_files.h"

namespace test_sweep_file {

namespace fs = std::filesystem;
using namespace tippe;

namespace {

using namespace tippe::fixtures;

const std::string& kSource = fixtures::kSourceDir;
const std::string kSmoke = kSource + "/harness/sweeps/smoke.toml";
const std::string kScene = kSource + "/harness/scenes/source_dimensionless.toml";

std::string load_error(const fs::path& p) {
  try {
    load_sweep(p.string());
  } catch (const SceneError& e) {
    return e.what();
  }
  return "";
}

const std::string kMujocoFrameGrid =
    "[[setup]]\nname = \"mj\"\nengine = \"mujoco\"\n"
    "ladder = { key = \"engines.mujoco.timestep\", values = [1e-3, 5e-4, 2.5e-4] }\n"
    "grid = { key = \"engines.mujoco.body_frame\", values = [\"com\", \"ball_centre\"] }\n";

}  // namespace

TEST(SweepFiles, ShippedSweepsLoad) {
  const SweepPlan smoke = load_sweep(kSmoke);
  EXPECT_GE(smoke.points.size(), 6u);
  const SweepPlan def = load_sweep(kSource + "/harness/sweeps/default.toml");
  std::set<std::string> engines, scenes;
  size_t most_steps = 0;
  bool analytic_ladder = false;
  for (const SweepSetup& s : def.spec.setups) {
    engines.insert(s.engine);
    if (s.ladder_key.find("timestep") != std::string::npos) most_steps = std::max(most_steps, s.ladder_values.size());
    analytic_ladder = analytic_ladder || (s.engine == "analytic" && s.ladder_key == "engines.analytic.rtol");
  }
  for (const Scene& s : def.scenes) scenes.insert(s.name);
  EXPECT_GE(engines.size(), 4u) << "three engines and the analytic model";
  EXPECT_GE(most_steps, 6u);
  EXPECT_TRUE(analytic_ladder);
  EXPECT_TRUE(scenes.count("source_dimensionless") && scenes.count("toy_viscous"));
  EXPECT_GE(def.spec.repeats, 1);
  // Point ids are unique and stable.
  std::set<std::string> ids;
  for (const SweepPoint& p : def.points) ids.insert(p.id);
  EXPECT_EQ(ids.size(), def.points.size());
  EXPECT_EQ(load_sweep(kSource + "/harness/sweeps/default.toml").plan_hash, def.plan_hash);
}

TEST(SweepFiles, PointsCarryTheirOverrides) {
  TempDir dir{"tippe-sweep"};
  const fs::path p =
      write_sweep(dir.path(), kGoodHead +
                                  "[[setup]]\nname = \"mj\"\nengine = \"mujoco\"\n"
                                  "set = [\"engines.mujoco.integrator=\\\"RK4\\\"\"]\n"
                                  "ladder.key = \"engines.mujoco.iterations\"\nladder.values = [5, 50]\n");
  const SweepPlan plan = load_sweep(p.string());
  ASSERT_EQ(plan.points.size(), 2u);
  const Scene& s = plan.points[1].scene;
  EXPECT_EQ(s.run.duration, 0.5);
  EXPECT_EQ(std::get<std::string>(s.engines.at("mujoco").at("integrator")), "RK4");
  EXPECT_EQ(std::get<long long>(s.engines.at("mujoco").at("iterations")), 50) << "integers stay integers";
  EXPECT_NE(plan.points[0].id, plan.points[1].id);
}

TEST(SweepFiles, InvalidFilesNameFileAndKey) {
  TempDir dir{"tippe-sweep"};
  struct Case {
    std::string body, key;
  };
  const std::vector<Case> cases = {
      {kGoodHead + "repeat = 3\n" + kGoodSetup, ": repeat: unknown key"},
      {"repeats = 0\nscenes = [\"" + kScene + "\"]\n" + kGoodSetup, ": repeats: 0 is out of range (expected 1 <= repeats <= 100)"},
      {"repeats = 2.5\nscenes = [\"" + kScene + "\"]\n" + kGoodSetup, ": repeats: expected an integer"},
      {"duration = -1\nscenes = [\"" + kScene + "\"]\n" + kGoodSetup, ": duration: -1 is out of range (expected duration > 0)"},
      {"scenes = [\"nosuch.toml\"]\n" + kGoodSetup, ": scenes[0]: cannot read"},
      {"scenes = []\n" + kGoodSetup, ": scenes: must list at least one scene"},
      {kGoodHead, ": setup: missing"},
      {kGoodHead + "[[setup]]\nname = \"x\"\nengine = \"havok\"\nladder.key = \"k\"\nladder.values = [1]\n",
       ": setup[0].engine: unknown engine \"havok\""},
      {kGoodHead + kGoodSetup + kGoodSetup, ": setup[1].name: \"ode\" is already the name of setup[0]"},
      {kGoodHead + "[[setup]]\nname = \"x\"\nengine = \"ode\"\nladder.key = \"engines.ode.timestep\"\n"
                   "ladder.values = [1e-3, 0.5]\n",
       ": setup[0].ladder.values[1]: engines.ode.timestep: value 0.5 outside"},
      {kGoodHead + "[[setup]]\nname = \"x\"\nengine = \"ode\"\nladder.key = \"engines.ode.timestep\"\n"
                   "ladder.values = [\"fine\"]\n",
       ": setup[0].ladder.values[0]: engines.ode.timestep: expected a number"},
      {kGoodHead + "[[setup]]\nname = \"x\"\nengine = \"ode\"\nset = [\"engines.ode.nosuch=1\"]\n"
                   "ladder.key = \"engines.ode.timestep\"\nladder.values = [1e-3]\n",
       ": setup[0].set[0]: engines.ode.nosuch: unknown setting"},
      {kGoodHead + "[[setup]]\nname = \"x\"\nengine = \"ode\"\nset = [\"contact.k=2\"]\n"
                   "ladder.key = \"engines.ode.timestep\"\nladder.values = [1e-3]\n",
       ": setup[0].set[0]: \"contact.k\" is not a setting of ode"},
      {kGoodHead +
           "[[setup]]\nname = \"x\"\nengine = \"analytic\"\nladder.key = \"run.duration\"\nladder.values = [1]\n",
       ": setup[0].ladder.key: \"run.duration\" is not a setting of the analytic model"},
      {kGoodHead + "[[setup]]\nname = \"x\"\nengine = \"ode\"\nladder.key = \"engines.ode.timestep\"\n"
                   "ladder.values = [1e-3, 1e-3]\n",
       ": setup[0].ladder.values[1]: 0.001 repeats setup[0].ladder.values[0]"},
      {kGoodHead +
           "[[setup]]\nname = \"x\"\nengine = \"ode\"\nladder = { key = \"engines.ode.timestep\", values = [1e-3], "
           "step = 2 }\n",
       ": setup[0].ladder.step: unknown key"},
  };
  for (size_t i = 0; i < cases.size(); ++i) {
    const fs::path p = write_sweep(dir.path(), cases[i].body, "case" + std::to_string(i) + ".toml");
    const std::string msg = load_error(p);
    EXPECT_EQ(msg.rfind(p.string() + ":", 0), 0u) << "case " << i << ": " << msg;
    EXPECT_NE(msg.find(cases[i].key), std::string::npos) << "case " << i << ": " << msg;
  }
  const fs::path syntax = write_sweep(dir.path(), "repeats = = 3\n", "syntax.toml");
  EXPECT_EQ(load_error(syntax).rfind(syntax.string() + ":1:", 0), 0u) << load_error(syntax);
}

// ---- ladders: categorical values and grids ----------------------------------------------------

// Published sweep directories resume only while a one-axis point keeps its id: the value below
// was computed by the build before grids and categorical ladders existed.
TEST(SweepLadders, OneAxisPointIdsAreThoseOfEarlierBuilds) {
  SweepSetup u;
  u.name = "ode";
  u.engine = "ode";
  u.set = {"engines.ode.iterations=50"};
  u.ladder_key = "engines.ode.timestep";
  EXPECT_EQ(sweep_point_id("fedcba9876543210", u, "0.001", 3), "c8db2ce8901bf92f");
}

TEST(SweepLadders, OneAxisPlanIdsAreTheOneAxisFormula) {
  TempDir dir{"tippe-sweep"};
  const SweepPlan plan = load_sweep(write_sweep(dir.path(), kGoodHead + kGoodSetup).string());
  ASSERT_EQ(plan.points.size(), 2u);
  const SweepSetup& u = plan.spec.setups[0];
  EXPECT_FALSE(u.has_grid());
  for (size_t k = 0; k < 2; ++k) {
    EXPECT_EQ(plan.points[k].grid_index, 0u);
    EXPECT_EQ(plan.points[k].id, sweep_point_id(plan.physics_hashes[0], u, u.ladder_texts[k], 1));
  }
  EXPECT_EQ(u.ladder_labels, (std::vector<std::string>{"0.001", "0.0005"}));
}

TEST(SweepLadders, CategoricalLadderPlansOnePointPerValue) {
  TempDir dir{"tippe-sweep"};
  const fs::path p = write_sweep(dir.path(), kGoodHead +
                                                 "[[setup]]\nname = \"mj\"\nengine = \"mujoco\"\n"
                                                 "ladder.key = \"engines.mujoco.body_frame\"\n"
                                                 "ladder.values = [\"com\", \"ball_centre\"]\n"
                                                 "[[setup]]\nname = \"bt\"\nengine = \"bullet\"\n"
                                                 "ladder.key = \"engines.bullet.velocity_friction_direction\"\n"
                                                 "ladder.values = [true, false]\n");
  const SweepPlan plan = load_sweep(p.string());
  ASSERT_EQ(plan.points.size(), 4u);
  const SweepSetup& u = plan.spec.setups[0];
  EXPECT_EQ(u.ladder_texts, (std::vector<std::string>{"\"com\"", "\"ball_centre\""}));
  EXPECT_EQ(u.ladder_labels, (std::vector<std::string>{"com", "ball_centre"}));
  EXPECT_TRUE(std::isnan(u.ladder_values[0]) && std::isnan(u.ladder_values[1]));
  EXPECT_EQ(std::get<std::string>(plan.points[1].scene.engines.at("mujoco").at("body_frame")), "ball_centre");
  EXPECT_EQ(std::get<bool>(plan.points[3].scene.engines.at("bullet").at("velocity_friction_direction")), false);
  EXPECT_EQ(plan.spec.setups[1].ladder_labels, (std::vector<std::string>{"true", "false"}));
  std::set<std::string> ids;
  for (const SweepPoint& q : plan.points) ids.insert(q.id);
  EXPECT_EQ(ids.size(), 4u);
  EXPECT_EQ(plan.points[0].id, sweep_point_id(plan.physics_hashes[0], u, "\"com\"", 1));
  EXPECT_EQ(load_sweep(p.string()).plan_hash, plan.plan_hash) << "ids are stable";
}

TEST(SweepLadders, GridPlansEveryPairGridThenLadder) {
  TempDir dir{"tippe-sweep"};
  const fs::path p = write_sweep(dir.path(), kGoodHead + kMujocoFrameGrid + kGoodSetup);
  const SweepPlan plan = load_sweep(p.string());
  ASSERT_EQ(plan.points.size(), 6u + 2u);
  const SweepSetup& u = plan.spec.setups[0];
  ASSERT_TRUE(u.has_grid());
  EXPECT_EQ(u.point_count(), 6u);
  EXPECT_EQ(u.grid_labels, (std::vector<std::string>{"com", "ball_centre"}));
  const std::vector<std::pair<size_t, size_t>> order = {{0, 0}, {0, 1}, {0, 2}, {1, 0}, {1, 1}, {1, 2}};
  std::set<std::string> ids;
  for (size_t i = 0; i < 6; ++i) {
    const SweepPoint& q = plan.points[i];
    EXPECT_EQ(q.grid_index, order[i].first) << i;
    EXPECT_EQ(q.ladder_index, order[i].second) << i;
    const auto& mj = q.scene.engines.at("mujoco");
    EXPECT_EQ(std::get<std::string>(mj.at("body_frame")), u.grid_labels[q.grid_index]) << i;
    EXPECT_EQ(std::get<double>(mj.at("timestep")), u.ladder_values[q.ladder_index]) << i;
    EXPECT_EQ(q.id, sweep_point_id(plan.physics_hashes[0], u, u.ladder_texts[q.ladder_index], 1,
                                   u.grid_texts[q.grid_index]));
    ids.insert(q.id);
  }
  EXPECT_EQ(ids.size(), 6u);
  // The grid's points are not the one-axis points of the same ladder, and the one-axis setup
  // beside it keeps its ids.
  EXPECT_FALSE(ids.count(sweep_point_id(plan.physics_hashes[0], u, u.ladder_texts[0], 1)));
  const SweepPlan alone = load_sweep(write_sweep(dir.path(), kGoodHead + kGoodSetup, "alone.toml").string());
  EXPECT_EQ(plan.points[6].id, alone.points[0].id);
  EXPECT_EQ(plan.points[7].id, alone.points[1].id);
  EXPECT_EQ(load_sweep(p.string()).plan_hash, plan.plan_hash);
  // The shipped modelling sweep is a grid on every setup.
  const SweepPlan modelling = load_sweep(kSource + "/harness/sweeps/modelling.toml");
  for (const SweepSetup& s : modelling.spec.setups) EXPECT_TRUE(s.has_grid()) << s.name;
  EXPECT_GE(modelling.points.size(), 2u * 6 * 2);
}

TEST(SweepLadders, BadCategoricalValuesAreRefusedAtLoad) {
  TempDir dir{"tippe-sweep"};
  const std::string mj = "[[setup]]\nname = \"mj\"\nengine = \"mujoco\"\n";
  const std::string steps = "ladder = { key = \"engines.mujoco.timestep\", values = [1e-3, 5e-4] }\n";
  struct Case {
    std::string body, expected;
  };
  const std::vector<Case> cases = {
      {mj + steps + "grid = { key = \"engines.mujoco.cone\", values = [\"elliptic\", \"pyramid\"] }\n",
       ": setup[0].grid.values[1]: engines.mujoco.cone: value \"pyramid\" is not one of: elliptic, pyramidal"},
      {mj + "ladder = { key = \"engines.mujoco.body_frame\", values = [\"com\", \"middle\"] }\n",
       ": setup[0].ladder.values[1]: engines.mujoco.body_frame: value \"middle\" is not one of: com, ball_centre"},
      {mj + steps + "grid = { key = \"engines.mujoco.noslip_iterations\", values = [\"many\"] }\n",
       ": setup[0].grid.values[0]: engines.mujoco.noslip_iterations: expected an integer"},
      {mj + steps + "grid = { key = \"engines.mujoco.body_frame\", values = [\"com\", 1] }\n",
       ": setup[0].grid.values[1]: expected a string like setup[0].grid.values[0], got an integer 1 (an axis' values are all "
       "numbers, all strings or all booleans)"},
      {mj + steps + "grid = { key = \"engines.mujoco.body_frame\", values = [\"com\", \"com\"] }\n",
       ": setup[0].grid.values[1]: com repeats setup[0].grid.values[0]"},
      {mj + steps + "grid = { key = \"engines.mujoco.body_frame\", values = [\"a b\"] }\n",
       ": setup[0].grid.values[0]: \"a b\" is not a usable value"},
      {mj + steps + "grid = { key = \"engines.mujoco.timestep\", values = [1e-4] }\n",
       ": setup[0].grid.key: engines.mujoco.timestep is also setup[0]'s ladder key"},
      {mj + "set = [\"engines.mujoco.cone=\\\"pyramidal\\\"\"]\n" + steps +
           "grid = { key = \"engines.mujoco.cone\", values = [\"elliptic\"] }\n",
       ": setup[0].grid.key: engines.mujoco.cone is also fixed in setup[0].set"},
      {mj + steps + "grid = { key = \"contact.mu\", values = [0.1, 0.2] }\n",
       ": setup[0].grid.key: \"contact.mu\" is not a setting of mujoco"},
      {mj + steps + "grid = { key = \"engines.mujoco.cone\", values = [] }\n",
       ": setup[0].grid.values: must list at least one value"},
      {mj + steps + "grid = { key = \"engines.mujoco.cone\", values = [\"elliptic\"], by = 2 }\n",
       ": setup[0].grid.by: unknown key (expected one of: key, values)"},
      {mj + steps + "grid = { key = \"engines.mujoco.cone\", values = [{ a = 1 }] }\n",
       ": setup[0].grid.values[0]: expected a number, a string or a boolean, got"},
  };
  for (size_t i = 0; i < cases.size(); ++i) {
    const fs::path p = write_sweep(dir.path(), kGoodHead + cases[i].body, "bad" + std::to_string(i) + ".toml");
    const std::string msg = load_error(p);
    EXPECT_EQ(msg.rfind(p.string() + cases[i].expected, 0), 0u) << "case " << i << ": " << msg;
  }
}

}  // namespace test_sweep_file
