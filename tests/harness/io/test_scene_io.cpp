// Tests of reading scene files (harness/io/scene_io.cpp): malformed scenes named by file and key, valid ones and their overrides, the content hash, and the command's exit codes on a bad scene (run records: tests/harness/records/test_records.cpp).
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>

#include "harness/io/scene_io.h"
#include "harness/scene/resolve.h"
#include "tests/support/files.h"
#include "tests/support/fixtures.h"

namespace test_scene_io {

namespace fs = std::filesystem;
using namespace tippe;

namespace {

using namespace tippe::fixtures;

std::string load_error(const std::string& path, const std::vector<std::string>& overrides = {}) {
  try {
    load_scene(path, overrides);
  } catch (const SceneError& e) {
    return e.what();
  }
  return "(no error)";
}

struct BadScene {
  const char* name;
  std::string text;
  std::vector<std::string> overrides;
  std::vector<std::string> fragments;  // all must appear
  std::vector<std::string> any_of;     // at least one must appear (the key a check may name)
};

std::vector<BadScene> bad_scenes() {
  const std::string b = kBase;
  const std::string rolling = edit(b, "friction = \"viscous\"\nk = 1.0", "friction = \"rolling\"");
  return {
      {"missing_gravity", edit(b, "gravity = 1\n", ""), {}, {": gravity: missing"}, {}},
      {"missing_tilt", edit(b, "tilt = 0.1\n", ""), {}, {": initial.tilt: missing"}, {}},
      {"missing_run_table", edit(b, "[run]", "[runs]"), {}, {": runs: unknown key"}, {}},
      {"unknown_top", "colour = 1\n" + b, {}, {": colour: unknown key"}, {}},
      {"unknown_body", edit(b, "[body]\n", "[body]\ncolour = 1\n"), {}, {": body.colour: unknown key"}, {}},
      {"unknown_contact", edit(b, "[contact]\n", "[contact]\nmuu = 0.3\n"), {}, {": contact.muu: unknown key"}, {}},
      {"wrong_type_string", edit(b, "tilt = 0.1", "tilt = \"0.1\""), {}, {": initial.tilt: expected a number"}, {}},
      {"bool_is_not_number", edit(b, "gravity = 1", "gravity = true"), {}, {": gravity: expected a number"}, {}},
      {"wrong_type_table", "contact = 3\n" + edit(b, "[contact]\nfriction = \"viscous\"\nk = 1.0\n", ""), {},
       {": contact: expected a table"}, {}},
      {"nan", edit(b, "spin = 5.0", "spin = nan"), {}, {": initial.spin: must be a finite number"}, {}},
      {"inf", edit(b, "duration = 25.0", "duration = inf"), {}, {": run.duration: must be a finite number"}, {}},
      {"negative_radius", edit(b, "sphere_radius = 1.0", "sphere_radius = -1.0"), {}, {": body.sphere_radius: -1 is out of range (expected sphere_radius > 0)"}, {}},
      {"negative_stem_radius", edit(b, "stem_radius = 0.25", "stem_radius = -0.25"), {}, {": body.stem_radius: -0.25 is out of range (expected stem_radius > 0)"}, {}},
      {"stem_radius_ge_R", edit(b, "stem_radius = 0.25", "stem_radius = 1.5"), {}, {}, {": body.stem_radius: "}},
      {"tip_inside_ball", edit(b, "stem_length = 1.2", "stem_length = 0.5"), {}, {},
       {": body.stem_length: ", ": body.stem_radius: "}},
      {"no_switch", edit(b, "stem_length = 1.2", "stem_length = 0.75"), {}, {},
       {": body.stem_length: ", ": body.stem_radius: "}},
      {"truncation_too_small", edit(b, "truncation_height = 0.9", "truncation_height = 0.5"), {}, {},
       {": body.truncation_height: "}},
      {"truncation_above_ball", edit(b, "truncation_height = 0.9", "truncation_height = 1.5"), {},
       {": body.truncation_height: 1.5 is out of range (expected 0 < truncation_height <= sphere_radius = 1)"}, {}},
      {"partial_mass", edit(b, "inertia_axial = 0.45\n", ""), {}, {": body.inertia_axial: missing"}, {}},
      {"partial_mass_density", edit(edit(b, "inertia_axial = 0.45\n", ""), "mass = 1.0\n", "density = 1.0\nmass_model = \"solid\"\n"), {},
       {": body.mass: missing"}, {}},
      {"density_with_given_mass", edit(b, "[body]\n", "[body]\ndensity = 1.0\n"), {}, {": body.density: not used"}, {}},
      {"C_above_2A", edit(b, "inertia_axial = 0.45", "inertia_axial = 0.9"), {}, {": body.inertia_axial: ", "triangle"}, {}},
      {"com_outside_ball", edit(b, "com_offset = 0.3", "com_offset = 1.0"), {}, {": body.com_offset: 1 is out of range (expected -R < com_offset < R"}, {}},
      {"friction_unknown", edit(b, "\"viscous\"", "\"sticky\""), {}, {": contact.friction: unknown law \"sticky\""}, {}},
      {"viscous_without_k", edit(b, "k = 1.0\n", ""), {}, {": contact.k: missing"}, {}},
      {"coulomb_without_mu", edit(b, "\"viscous\"\nk = 1.0", "\"coulomb\""), {}, {": contact.mu: missing"}, {}},
      {"k_with_coulomb", edit(b, "\"viscous\"", "\"coulomb\"\nmu = 0.3"), {}, {": contact.k: does not apply"}, {}},
      // Gliding (F_t = -mu F_n v_C, mu in s/m) takes mu as Coulomb does and refuses k.
      {"gliding_without_mu", edit(b, "\"viscous\"\nk = 1.0", "\"gliding\""), {}, {": contact.mu: missing"}, {}},
      {"k_with_gliding", edit(b, "\"viscous\"", "\"gliding\"\nmu = 0.3"), {},
       {": contact.k: does not apply to friction = \"gliding\" (only 0 is accepted), got 1"}, {}},
      {"negative_gliding_mu", edit(b, "\"viscous\"\nk = 1.0", "\"gliding\"\nmu = -0.3"), {},
       {": contact.mu: -0.3 is out of range (expected mu >= 0)"}, {}},
      {"mu_with_viscous", edit(b, "k = 1.0", "k = 1.0\nmu = 0.3"), {}, {": contact.mu: does not apply to friction = \"viscous\""}, {}},
      {"rolling_with_velocity", rolling, {}, {": initial.velocity: ", "derived for rolling"}, {}},
      {"spin_and_omega", edit(b, "spin = 5.0", "spin = 5.0\nomega = [0.0, 0.0, 5.0]"), {}, {": initial.omega: ", "not both"}, {}},
      {"neither_spin_nor_omega", edit(b, "spin = 5.0\n", ""), {}, {": initial.spin: missing"}, {}},
      {"omega_wrong_length", edit(b, "spin = 5.0", "omega = [0.0, 5.0]"), {}, {": initial.omega: expected an array of 3"}, {}},
      {"tilt_out_of_range", edit(b, "tilt = 0.1", "tilt = 4.0"), {}, {": initial.tilt: 4 is out of range (expected 0 <= tilt <= pi"}, {}},
      {"duration_zero", edit(b, "duration = 25.0", "duration = 0"), {}, {": run.duration: 0 is out of range (expected duration > 0)"}, {}},
      {"sample_interval_above_duration", edit(b, "sample_interval = 0.01", "sample_interval = 30"), {},
       {": run.sample_interval: 30 is out of range (expected 0 < sample_interval <= duration = 25)"}, {}},
      {"rtol_too_large", edit(b, "rtol = 1e-10", "rtol = 0.1"), {}, {": run.rtol: "}, {}},
      {"override_unknown_key", b, {"contact.muu=0.5"}, {": contact.muu: unknown key", "--set"}, {}},
      {"override_malformed", b, {"contact.mu"}, {": --set: malformed override"}, {}},
      {"override_bad_key", b, {"contact..mu=1"}, {": --set: malformed key"}, {}},
      {"override_through_value", b, {"gravity.x=1"}, {": --set: ", "gravity is not a table"}, {}},
      {"override_bad_value", b, {"run.duration=-2"}, {": run.duration: -2 is out of range (expected duration > 0)"}, {}},
      {"engine_unknown", b + "[engines.foo]\nx = 1\n", {}, {": engines.foo"}, {}},
      {"engine_bad_type", b + "[engines.ode]\ntimestep = \"small\"\n", {}, {": engines.ode.timestep: "}, {}},
      {"engine_unsupported_value", b + "[engines.ode]\ntimestep = { a = 1 }\n", {}, {": engines.ode.timestep: unsupported value"}, {}},
      {"mujoco_unknown_setting", b + "[engines.mujoco]\nno_such_key = 1\n", {}, {": engines.mujoco.no_such_key: "}, {}},
      {"analytic_unknown_setting", b + "[engines.analytic]\nstep = 1\n", {}, {": engines.analytic.step: unknown setting"}, {}},
      {"analytic_bad_method", b + "[engines.analytic]\nmethod = \"euler\"\n", {}, {": engines.analytic.method: "}, {}},
      {"analytic_key_twice", b + "[engines.analytic]\nrtol = 1e-8\n", {}, {": engines.analytic.rtol: also given as run.rtol"}, {}},
      {"analytic_key_twice_by_override", edit(edit(b, "rtol = 1e-10\n", ""), "atol = 1e-12\n", "") + "[engines.analytic]\nrtol = 1e-8\n",
       {"run.rtol=1e-6"}, {": engines.analytic.rtol: also given as run.rtol"}, {}},
  };
}

void PrintTo(const BadScene& c, std::ostream* os) { *os << c.name; }

class BadSceneTest : public ::testing::TestWithParam<BadScene> {};

TEST_P(BadSceneTest, NamesFileAndKey) {
  TempDir dir{"tippe-test"};
  const BadScene& c = GetParam();
  const std::string path = dir.write(std::string(c.name) + ".toml", c.text);
  const std::string msg = load_error(path, c.overrides);
  EXPECT_EQ(msg.rfind(path + ": ", 0), 0u) << msg;
  for (const auto& f : c.fragments) EXPECT_NE(msg.find(f), std::string::npos) << "want \"" << f << "\" in: " << msg;
  if (!c.any_of.empty()) {
    bool found = false;
    for (const auto& f : c.any_of) found = found || msg.find(f) != std::string::npos;
    EXPECT_TRUE(found) << "want a key of the check in: " << msg;
  }
}

INSTANTIATE_TEST_SUITE_P(Malformed, BadSceneTest, ::testing::ValuesIn(bad_scenes()),
                         [](const ::testing::TestParamInfo<BadScene>& info) { return std::string(info.param.name); });

TEST(SceneIo, SyntaxErrorGivesLineAndColumn) {
  TempDir dir{"tippe-test"};
  const std::string base = kBase;
  const auto line = 1 + std::count(base.begin(), base.begin() + static_cast<long>(base.find("tilt = 0.1")), '\n');
  const std::string path = dir.write("syntax.toml", edit(base, "tilt = 0.1", "tilt = = 0.1"));
  const std::string msg = load_error(path);
  EXPECT_EQ(msg.rfind(path + ":" + std::to_string(line) + ":", 0), 0u) << msg;
}

TEST(SceneIo, UnreadableFile) {
  TempDir dir{"tippe-test"};
  const std::string path = (dir.path() / "missing.toml").string();
  EXPECT_EQ(load_error(path).rfind(path + ": cannot read", 0), 0u);
}

TEST(SceneIo, ValidSceneParses) {
  TempDir dir{"tippe-test"};
  const std::string text = edit(std::string(kBase), "name = \"base\"\n", "") +
                           "[engines.ode]\ntimestep = 1e-4\niterations = 20\nfinite_rotation = false\nstepper = \"quickstep\"\n";
  const std::string path = dir.write("my_scene.toml", text);
  const Scene s = load_scene(path);
  EXPECT_EQ(s.name, "my_scene");  // defaults to the file's stem
  EXPECT_EQ(s.description, "test scene");
  EXPECT_EQ(s.source_file, path);
  EXPECT_EQ(s.gravity, 1.0);  // integer accepted as a float
  EXPECT_EQ(s.body.sphere_radius, 1.0);
  EXPECT_EQ(s.body.stem_radius, 0.25);
  EXPECT_EQ(s.body.stem_length, 1.2);
  EXPECT_EQ(s.body.truncation_height, 0.9);
  EXPECT_EQ(s.body.mass_model, MassModel::Given);
  EXPECT_EQ(s.mass.mass, 1.0);
  EXPECT_EQ(s.mass.com_offset, 0.3);
  EXPECT_EQ(s.mass.inertia_transverse, 0.4);
  EXPECT_EQ(s.mass.inertia_axial, 0.45);
  EXPECT_EQ(s.contact.friction, FrictionLaw::Viscous);
  EXPECT_EQ(s.contact.k, 1.0);
  EXPECT_EQ(s.contact.mu, 0.0);
  EXPECT_TRUE(s.contact.stem);
  EXPECT_FALSE(s.contact.flight);
  EXPECT_EQ(s.initial.tilt, 0.1);
  EXPECT_EQ(s.initial.spin, 5.0);
  EXPECT_FALSE(s.initial.omega_given);
  EXPECT_TRUE(s.initial.velocity_given);
  EXPECT_FALSE(s.initial.omega_along_contact);
  EXPECT_EQ(s.run.duration, 25.0);
  EXPECT_EQ(s.run.sample_interval, 0.01);
  EXPECT_EQ(s.run.rtol, 1e-10);
  EXPECT_EQ(s.run.atol, 1e-12);
  const auto& ode = s.engines.at("ode");
  EXPECT_EQ(std::get<double>(ode.at("timestep")), 1e-4);
  EXPECT_EQ(std::get<long long>(ode.at("iterations")), 20);
  EXPECT_EQ(std::get<bool>(ode.at("finite_rotation")), false);
  EXPECT_EQ(std::get<std::string>(ode.at("stepper")), "quickstep");
  EXPECT_EQ(s.content_hash.size(), 16u);

  const auto j = scene_to_json(s);
  EXPECT_EQ(j.at("mass_properties").at("inertia_axial").get<double>(), 0.45);
  EXPECT_EQ(j.at("contact").at("friction").get<std::string>(), "viscous");
  EXPECT_EQ(j.at("engines").at("ode").at("iterations").get<long long>(), 20);
}

// The gliding law: mu (s/m) read, k = 0 accepted (a template may carry every key), the law named
// "gliding" in the JSON.
TEST(SceneIo, GlidingParses) {
  TempDir dir{"tippe-test"};
  const std::string text = edit(kBase, "friction = \"viscous\"\nk = 1.0", "friction = \"gliding\"\nmu = 0.3\nk = 0");
  const Scene s = load_scene(dir.write("gliding.toml", text));
  EXPECT_EQ(s.contact.friction, FrictionLaw::Gliding);
  EXPECT_EQ(s.contact.mu, 0.3);
  EXPECT_EQ(s.contact.k, 0.0);
  EXPECT_EQ(scene_to_json(s).at("contact").at("friction").get<std::string>(), "gliding");
  // mu = 0 is the frictionless limit, accepted as for Coulomb.
  EXPECT_EQ(load_scene(dir.write("gliding0.toml", edit(text, "mu = 0.3", "mu = 0"))).contact.mu, 0.0);
}

TEST(SceneIo, OptionalKeysAndOmega) {
  TempDir dir{"tippe-test"};
  std::string text = edit(kBase, "spin = 5.0", "omega = [0.1, 0.2, 5]");
  text = edit(text, "velocity = [0.0, 0.0]\n", "");
  text = edit(text, "rtol = 1e-10\natol = 1e-12\n", "");
  text = edit(text, "k = 1.0", "k = 1.0\nmu = 0\ndrilling = 0.01\nstem = true\nflight = true");
  const Scene s = load_scene(dir.write("opt.toml", text));
  EXPECT_TRUE(s.initial.omega_given);
  EXPECT_EQ(s.initial.omega_B[0], 0.1);
  EXPECT_EQ(s.initial.omega_B[2], 5.0);
  EXPECT_FALSE(s.initial.velocity_given);
  EXPECT_EQ(s.run.rtol, RunSpec{}.rtol);
  EXPECT_EQ(s.contact.drilling, 0.01);
  EXPECT_TRUE(s.contact.flight);
}

TEST(SceneIo, BareBallNeedsNoStem) {
  TempDir dir{"tippe-test"};
  std::string text = edit(kBase, "stem_radius = 0.25\nstem_length = 1.2\n", "");
  text = edit(text, "k = 1.0", "k = 1.0\nstem = false");
  const Scene s = load_scene(dir.write("ball.toml", text));
  EXPECT_FALSE(s.contact.stem);
  EXPECT_EQ(s.body.stem_radius, 0.0);
}

TEST(SceneIo, OverridesApply) {
  TempDir dir{"tippe-test"};
  const std::string path = dir.write("ovr.toml", edit(kBase, "\"viscous\"\nk = 1.0", "\"coulomb\"\nmu = 0.3"));
  const Scene s = load_scene(path, {"run.duration=2", "contact.mu = 0.5", "engines.ode.stepper=quickstep",
                                    "engines.ode.timestep=1e-4", "initial.omega_along_contact=true"});
  EXPECT_EQ(s.run.duration, 2.0);
  EXPECT_EQ(s.contact.mu, 0.5);
  EXPECT_TRUE(s.initial.omega_along_contact);
  EXPECT_EQ(std::get<std::string>(s.engines.at("ode").at("stepper")), "quickstep");  // bare word
  EXPECT_EQ(std::get<double>(s.engines.at("ode").at("timestep")), 1e-4);
  const Scene q = load_scene(path, {"engines.ode.stepper=\"step\""});
  EXPECT_EQ(std::get<std::string>(q.engines.at("ode").at("stepper")), "step");
}

TEST(SceneIo, HashIsStableAndSeesOverridesAndBytes) {
  TempDir dir{"tippe-test"};
  const std::string path = dir.write("h.toml", kBase);
  const std::string h0 = load_scene(path).content_hash;
  EXPECT_EQ(h0.size(), 16u);
  EXPECT_EQ(h0.find_first_not_of("0123456789abcdef"), std::string::npos);
  EXPECT_EQ(load_scene(path).content_hash, h0);
  const std::string h1 = load_scene(path, {"run.duration=2"}).content_hash;
  EXPECT_NE(h1, h0);
  EXPECT_EQ(load_scene(path, {"run.duration=2"}).content_hash, h1);
  EXPECT_NE(load_scene(path, {"run.duration=3"}).content_hash, h1);
  const std::string other = dir.write("h2.toml", std::string(kBase) + "# a comment\n");
  EXPECT_NE(load_scene(other).content_hash, h0);
  // FNV-1a 64 of the bytes alone: the hash is the same on every machine.
  std::uint64_t h = 0xcbf29ce484222325ULL;
  for (unsigned char c : std::string(kBase)) h = (h ^ c) * 0x100000001b3ULL;
  char buf[17];
  std::snprintf(buf, sizeof buf, "%016llx", static_cast<unsigned long long>(h));
  EXPECT_EQ(h0, buf);
}

TEST(SceneIo, ShippedScenesLoad) {
  // toy.toml uses the solid mass model: this needs compute_mass_properties.
  for (const char* name : {"toy", "source_dimensionless"}) {
    const std::string path = std::string(TIPPE_SOURCE_DIR) + "/harness/scenes/" + name + ".toml";
    const Scene s = load_scene(path);
    EXPECT_EQ(s.name, name);
    EXPECT_GT(s.mass.mass, 0.0) << name;
    EXPECT_FALSE(s.description.empty());
  }
}

// ---- command line ---------------------------------------------------------------------------

int run_tippe(const std::string& args, const fs::path& err_file) {
  const std::string cmd = std::string(TIPPE_BINARY_DIR) + "/tippe " + args + " >/dev/null 2>" + err_file.string();
  const int rc = std::system(cmd.c_str());
  return WIFEXITED(rc) ? WEXITSTATUS(rc) : -1;
}

TEST(Cli, MalformedSceneExitsWithTwoAndCreatesNothing) {
  ASSERT_TRUE(fs::exists(std::string(TIPPE_BINARY_DIR) + "/tippe")) << "build the tippe target first";
  TempDir dir{"tippe-test"};
  const std::string scene = dir.write("bad.toml", edit(kBase, "stem_radius = 0.25", "stem_radius = -0.25"));
  const fs::path out = dir.path() / "out";
  const fs::path err = dir.path() / "stderr.txt";
  EXPECT_EQ(run_tippe("run " + scene + " --engine analytic --out " + out.string(), err), 2);
  const std::string msg = slurp(err);
  EXPECT_EQ(msg.rfind("tippe: error: " + scene + ": body.stem_radius: ", 0), 0u) << msg;
  EXPECT_FALSE(fs::exists(out));

  EXPECT_EQ(run_tippe("run " + scene + " --set run.duration --out " + out.string(), err), 2);
  EXPECT_NE(slurp(err).find("--set"), std::string::npos);
  EXPECT_FALSE(fs::exists(out));
}

TEST(Cli, UnknownEngineAndMissingFileExitWithTwo) {
  TempDir dir{"tippe-test"};
  const std::string scene = dir.write("ok.toml", kBase);
  const fs::path out = dir.path() / "out";
  const fs::path err = dir.path() / "stderr.txt";
  EXPECT_EQ(run_tippe("run " + scene + " --engine nosuch --out " + out.string(), err), 2);
  EXPECT_EQ(slurp(err).rfind("tippe: error: ", 0), 0u);
  EXPECT_FALSE(fs::exists(out));
  EXPECT_EQ(run_tippe("info " + (dir.path() / "missing.toml").string(), err), 2);
  EXPECT_NE(slurp(err).find("missing.toml: cannot read"), std::string::npos);
}

}  // namespace

}  // namespace test_scene_io
