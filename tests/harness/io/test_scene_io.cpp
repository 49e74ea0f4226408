// Tests of the harness layer: scene files and overrides, run records, CSV/JSON writers and the CLI exit codes.
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

#include "harness/records/records.h"
#include "harness/measure/run.h"
#include "harness/io/scene_io.h"
#include "harness/scene/resolve.h"
#include "tests/support/files.h"
#include "tests/support/fixtures.h"

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

// ---- records -------------------------------------------------------------------------------

Observation sample(double t, Surface s, double J, double fn = 1.0) {
  Observation o;
  o.state.t = t;
  o.surface = s;
  o.jellett = J;
  o.normal_force = fn;
  o.energy = 10.0 - t;
  o.theta = 0.1 * t;
  return o;
}

TEST(Records, JellettDriftPerSurface) {
  SampleSummary sum;
  sum.add(sample(0, Surface::Ball, 2.0));
  sum.add(sample(1, Surface::Ball, 2.002));  // 1e-3
  sum.add(sample(2, Surface::Ball, 1.999));
  sum.add(sample(3, Surface::Stem, -4.0));   // a new run: the jump is not drift
  sum.add(sample(4, Surface::Stem, -4.02));  // 5e-3
  sum.add(sample(5, Surface::Both, 7.0));    // not counted, ends the run
  sum.add(sample(6, Surface::Stem, 1.0));
  sum.add(sample(7, Surface::Stem, 1.001));  // 1e-3
  sum.add(sample(8, Surface::Ball, 3.0, 0.25));
  sum.add(sample(9, Surface::Ball, 3.0));
  sum.add(sample(10, Surface::Ball, 5.0, 0.5), /*contact_switched=*/true);  // a switch between samples
  sum.add(sample(11, Surface::Ball, 5.01));  // 2e-3
  RunRecord r;
  sum.fill(r);
  EXPECT_EQ(r.samples, 12);
  ASSERT_TRUE(r.jellett_drift_ball && r.jellett_drift_stem);
  EXPECT_NEAR(*r.jellett_drift_ball, 2e-3, 1e-12);
  EXPECT_NEAR(*r.jellett_drift_stem, 5e-3, 1e-12);
  EXPECT_NEAR(r.jellett_max_relative_drift, 5e-3, 1e-12);
  EXPECT_EQ(r.jellett_initial, 2.0);
  EXPECT_EQ(r.energy_initial, 10.0);
  EXPECT_EQ(r.energy_final, -1.0);
  EXPECT_EQ(r.final_time, 11.0);
  EXPECT_NEAR(r.final_tilt, 1.1, 1e-15);
  EXPECT_EQ(r.min_normal_force, 0.25);
}

TEST(Records, JellettDriftAbsentSurface) {
  SampleSummary sum;
  sum.add(sample(0, Surface::Ball, 0.0));
  sum.add(sample(1, Surface::Ball, 0.0));
  RunRecord r;
  sum.fill(r);
  EXPECT_FALSE(r.jellett_drift_stem.has_value());
  EXPECT_EQ(*r.jellett_drift_ball, 0.0);  // J = 0 throughout: no division by zero
}

bool same(double a, double b) { return a == b || (std::isnan(a) && std::isnan(b)); }

RunRecord example_record() {
  RunRecord r;
  r.scene_name = "toy";
  r.scene_file = "harness/scenes/toy.toml";
  r.scene_hash = "0123456789abcdef";
  r.scene_spec = {{"gravity", 9.81}};
  r.engine = "mujoco";
  r.engine_version = "mujoco 2.2.2";
  r.status = "diverged";
  r.status_time = 1.0 / 3.0;
  r.status_detail = "energy doubled";
  r.events = {{"inversion", 0.1 + 0.2, "theta crosses 90 deg", 0.0}, {"impact", 2.5, "stem", 1e-7}};
  r.settings = {{"cone", "elliptic"}, {"timestep", "0.0001"}};
  r.notes = {"rolling approximated by mu = 1e3"};
  r.work = {12345, 23456, 7, 1.25, 1.125};
  r.mass = {0.0123, 0.00123, 1.1e-6, 1.2e-6};
  r.inversion_possible = true;
  r.provenance = {"abc123", "GNU 12.2.0", "-O2", "2024-01-01T00:00:00Z", "host"};
  r.inversion_time = 0.30000000000000004;
  r.stem_contact_time = std::nullopt;
  r.samples = 8001;
  r.final_time = 8.0;
  r.final_tilt = 3.0;
  r.energy_initial = 1.0 / 7.0;
  r.energy_final = std::numeric_limits<double>::quiet_NaN();
  r.jellett_initial = -1.5637593718755574;
  r.jellett_max_relative_drift = 3e-12;
  r.jellett_drift_ball = 3e-12;
  r.jellett_drift_stem = std::nullopt;
  r.min_normal_force = -0.0;
  return r;
}

TEST(Records, JsonRoundTrip) {
  const RunRecord a = example_record();
  const nlohmann::json j = to_json(a);
  EXPECT_TRUE(j.at("stem_contact_time").is_null());
  EXPECT_TRUE(j.at("energy_final").is_null());
  for (const char* key : {"scene", "engine", "status", "inversion_time", "final_tilt", "energy_initial",
                          "jellett_initial", "jellett_max_relative_drift", "min_normal_force", "mass_properties",
                          "work", "events", "settings", "notes", "engine_version", "scene_file", "scene_hash",
                          "status_time", "status_detail", "inversion_possible", "provenance"})
    EXPECT_TRUE(j.contains(key)) << key;
  const RunRecord b = from_json(nlohmann::json::parse(j.dump(2)));
  EXPECT_EQ(b.scene_name, a.scene_name);
  EXPECT_EQ(b.scene_file, a.scene_file);
  EXPECT_EQ(b.scene_hash, a.scene_hash);
  EXPECT_EQ(b.scene_spec, a.scene_spec);
  EXPECT_EQ(b.engine, a.engine);
  EXPECT_EQ(b.engine_version, a.engine_version);
  EXPECT_EQ(b.status, a.status);
  EXPECT_EQ(b.status_time, a.status_time);
  EXPECT_EQ(b.status_detail, a.status_detail);
  ASSERT_EQ(b.events.size(), a.events.size());
  for (size_t i = 0; i < a.events.size(); ++i) {
    EXPECT_EQ(b.events[i].name, a.events[i].name);
    EXPECT_EQ(b.events[i].time, a.events[i].time);
    EXPECT_EQ(b.events[i].detail, a.events[i].detail);
    EXPECT_EQ(b.events[i].value, a.events[i].value);
  }
  EXPECT_EQ(b.settings, a.settings);  // already sorted by key
  EXPECT_EQ(b.notes, a.notes);
  EXPECT_EQ(b.work.steps, a.work.steps);
  EXPECT_EQ(b.work.rhs_evaluations, a.work.rhs_evaluations);
  EXPECT_EQ(b.work.solver_iterations, a.work.solver_iterations);
  EXPECT_EQ(b.work.wall_seconds, a.work.wall_seconds);
  EXPECT_EQ(b.work.cpu_seconds, a.work.cpu_seconds);
  EXPECT_EQ(b.mass.mass, a.mass.mass);
  EXPECT_EQ(b.mass.com_offset, a.mass.com_offset);
  EXPECT_EQ(b.mass.inertia_transverse, a.mass.inertia_transverse);
  EXPECT_EQ(b.mass.inertia_axial, a.mass.inertia_axial);
  EXPECT_EQ(b.inversion_possible, a.inversion_possible);
  EXPECT_EQ(b.provenance.git_commit, a.provenance.git_commit);
  EXPECT_EQ(b.provenance.compiler, a.provenance.compiler);
  EXPECT_EQ(b.provenance.cxx_flags, a.provenance.cxx_flags);
  EXPECT_EQ(b.provenance.date, a.provenance.date);
  EXPECT_EQ(b.provenance.hostname, a.provenance.hostname);
  EXPECT_EQ(b.inversion_time, a.inversion_time);
  EXPECT_EQ(b.stem_contact_time, a.stem_contact_time);
  EXPECT_EQ(b.samples, a.samples);
  EXPECT_EQ(b.final_time, a.final_time);
  EXPECT_EQ(b.final_tilt, a.final_tilt);
  EXPECT_EQ(b.energy_initial, a.energy_initial);
  EXPECT_TRUE(same(b.energy_final, a.energy_final));
  EXPECT_EQ(b.jellett_initial, a.jellett_initial);
  EXPECT_EQ(b.jellett_max_relative_drift, a.jellett_max_relative_drift);
  EXPECT_EQ(b.jellett_drift_ball, a.jellett_drift_ball);
  EXPECT_EQ(b.jellett_drift_stem, a.jellett_drift_stem);
  EXPECT_EQ(b.min_normal_force, a.min_normal_force);
  EXPECT_EQ(to_json(b), j);
}

// summary.json names its format; one written before it did is still read, another format is not.
TEST(Records, FormatIsWrittenAndOldSummariesAreRead) {
  nlohmann::json j = to_json(example_record());
  EXPECT_EQ(j.at("format"), kRunRecordFormat);
  j.erase("format");
  EXPECT_EQ(to_json(from_json(j)).at("final_tilt"), j.at("final_tilt"));
  j["format"] = "tippe-run-2";
  EXPECT_THROW(from_json(j), nlohmann::json::exception);
}

// friction_work (Simulator::friction_work) round-trips; a summary written before it existed is
// read as not reported (NaN), and not reported is written as null.
TEST(Records, FrictionWorkRoundTripsAndOldSummariesReadWithoutIt) {
  RunRecord r = example_record();
  r.friction_work = -0.0111;
  nlohmann::json j = to_json(r);
  EXPECT_EQ(from_json(j).friction_work, -0.0111);
  j.erase("friction_work");
  EXPECT_TRUE(std::isnan(from_json(j).friction_work));
  EXPECT_TRUE(to_json(from_json(j)).at("friction_work").is_null());
}

// The energy ledger's totals round-trip; a summary written before them reads them as not
// available (NaN, no list of missing terms).
TEST(Records, EnergyLedgerRoundTripsAndOldSummariesReadWithoutIt) {
  RunRecord r = example_record();
  r.normal_work = 1.5e-3;
  r.impact_energy = 0.25;
  r.elastic_energy_max = 2e-7;
  r.numerical_energy_max = 3e-6;
  r.numerical_energy_final = -2e-6;
  r.ledger_not_available = {"drilling_work"};
  nlohmann::json j = to_json(r);
  const RunRecord back = from_json(j);
  EXPECT_EQ(back.normal_work, 1.5e-3);
  EXPECT_EQ(back.impact_energy, 0.25);
  EXPECT_EQ(back.elastic_energy_max, 2e-7);
  EXPECT_EQ(back.numerical_energy_max, 3e-6);
  EXPECT_EQ(back.numerical_energy_final, -2e-6);
  EXPECT_TRUE(std::isnan(back.drilling_work));
  EXPECT_EQ(back.ledger_not_available, std::vector<std::string>{"drilling_work"});
  for (const char* k : {"normal_work", "drilling_work", "impact_energy", "elastic_energy_max", "numerical_energy_max",
                        "numerical_energy_final", "ledger_not_available"})
    j.erase(k);
  const RunRecord old = from_json(j);
  EXPECT_TRUE(std::isnan(old.normal_work));
  EXPECT_TRUE(std::isnan(old.numerical_energy_max));
  EXPECT_TRUE(old.ledger_not_available.empty());
}

bool has_temporaries(const fs::path& dir) {
  for (const auto& e : fs::directory_iterator(dir))
    if (e.path().filename().string().find(".tmp.") != std::string::npos) return true;
  return false;
}

TEST(Records, WriteFileAtomic) {
  TempDir dir{"tippe-test"};
  const std::string path = (dir.path() / "summary.json").string();
  write_file_atomic(path, "first\n");
  write_file_atomic(path, "second\n");
  std::ifstream in(path);
  std::stringstream ss;
  ss << in.rdbuf();
  EXPECT_EQ(ss.str(), "second\n");
  EXPECT_FALSE(has_temporaries(dir.path()));
  EXPECT_THROW(write_file_atomic((dir.path() / "no/such/dir/x").string(), "x"), std::runtime_error);
  EXPECT_FALSE(has_temporaries(dir.path()));
}

TEST(Records, CsvRoundTripAndCommit) {
  TempDir dir{"tippe-test"};
  const std::string path = (dir.path() / "trajectory.csv").string();
  Observation a = sample(0.1, Surface::Ball, -1.5637593718755574);
  a.state.p_WG = Vec3(1.0 / 3.0, -2e-17, 0.7);
  a.state.q_WB = Quat(Eigen::AngleAxisd(0.1, Vec3::UnitX()));
  a.state.w_B = Vec3(0, 0, 150);
  a.engine_contact_valid = true;
  a.p_WC_engine = Vec3(1, 2, 3);
  Observation b = sample(0.2, Surface::Both, 2.0);
  {
    CsvTrajectoryWriter w(path);
    w.write(a);
    w.write(b);
    EXPECT_FALSE(fs::exists(path));  // nothing visible before the commit
    w.commit();
  }
  EXPECT_FALSE(has_temporaries(dir.path()));
  const CsvTrajectory tr = read_trajectory_csv(path);
  EXPECT_EQ(tr.columns, trajectory_columns());
  ASSERT_EQ(tr.rows(), 2u);
  EXPECT_EQ(tr.surface[0], static_cast<int>(Surface::Ball));
  EXPECT_EQ(tr.surface[1], static_cast<int>(Surface::Both));
  EXPECT_EQ(tr.column("t")[1], 0.2);
  EXPECT_EQ(tr.column("x_G")[0], 1.0 / 3.0);
  EXPECT_EQ(tr.column("y_G")[0], -2e-17);
  EXPECT_EQ(tr.column("qx")[0], a.state.q_WB.x());
  EXPECT_EQ(tr.column("wz_B")[0], 150.0);
  EXPECT_EQ(tr.column("jellett")[0], a.jellett);
  EXPECT_EQ(tr.column("y_C_engine")[0], 2.0);
  EXPECT_TRUE(std::isnan(tr.column("y_C_engine")[1]));  // engine reported no contact point
  EXPECT_THROW(tr.column("no_such_column"), std::out_of_range);
}

TEST(Records, CsvWithoutCommitLeavesNothing) {
  TempDir dir{"tippe-test"};
  const std::string path = (dir.path() / "trajectory.csv").string();
  try {
    CsvTrajectoryWriter w(path);
    w.write(sample(0, Surface::Ball, 1));
    throw std::runtime_error("the run failed");
  } catch (const std::runtime_error&) {
  }
  EXPECT_TRUE(fs::is_empty(dir.path()));
}

// A scripted simulator: theta grows with time, an inversion at 0.25, diverges at t >= 0.35.
class FakeSimulator : public Simulator {
 public:
  std::string engine() const override { return "fake"; }
  std::string version() const override { return "fake 1.0"; }
  void advance_to(double t) override {
    if (status_ != RunStatus::Ok) return;
    t_ = std::min(t, 0.35);
    ++work_.steps;
    if (t_ >= 0.25 && events_.empty()) events_.push_back({"inversion", 0.25, "", 0});
    if (t_ >= 0.35) status_ = RunStatus::Diverged;
  }
  Observation observe() const override { return sample(t_, Surface::Ball, 1.0); }
  BodyState state() const override { return observe().state; }
  void set_state(const BodyState&) override {}
  MassReadback mass_properties() const override { return {}; }
  WorkCounters work() const override { return work_; }
  RunStatus status() const override { return status_; }
  double status_time() const override { return status_ == RunStatus::Ok ? 0.0 : 0.35; }
  std::string status_detail() const override { return status_ == RunStatus::Ok ? "" : "scripted"; }
  std::vector<Event> events() const override { return events_; }
  SettingsList settings() const override { return {{"timestep", "0.01"}}; }

 private:
  double t_ = 0.0;
  RunStatus status_ = RunStatus::Ok;
  std::vector<Event> events_;
  WorkCounters work_;
};

struct CollectSink : SampleSink {
  std::vector<double> times;
  void write(const Observation& o) override { times.push_back(o.state.t); }
};

TEST(Records, RunSimulatorSamplesTheGridAndStopsEarly) {
  Scene s;
  s.name = "fake";
  s.body.sphere_radius = 1.0;
  s.mass = {1.0, 0.3, 0.4, 0.45};
  s.run.duration = 1.0;
  s.run.sample_interval = 0.1;
  FakeSimulator sim;
  CollectSink sink;
  int calls = 0;
  const RunRecord r = run_simulator(sim, s, &sink, [&](double, double d) {
    ++calls;
    EXPECT_EQ(d, 1.0);
  });
  // 0, 0.1, 0.2, 0.3 on the grid, then the state at 0.35 where the run stopped.
  ASSERT_EQ(sink.times.size(), 5u);
  EXPECT_EQ(sink.times[3], 3 * 0.1);
  EXPECT_EQ(sink.times[4], 0.35);
  EXPECT_EQ(calls, 5);
  EXPECT_EQ(r.samples, 5);
  EXPECT_EQ(r.status, "diverged");
  EXPECT_EQ(r.status_time, 0.35);
  EXPECT_EQ(r.engine, "fake");
  ASSERT_TRUE(r.inversion_time.has_value());
  EXPECT_EQ(*r.inversion_time, 0.25);
  EXPECT_FALSE(r.stem_contact_time.has_value());
  EXPECT_TRUE(r.inversion_possible);
  EXPECT_EQ(r.settings.size(), 1u);
}

TEST(Records, RunSimulatorReachesDuration) {
  Scene s;
  s.body.sphere_radius = 1.0;
  s.mass = {1.0, 0.3, 0.4, 0.45};
  s.run.duration = 0.3;  // 0.3 / 0.1 = 2.9999999999999996
  s.run.sample_interval = 0.1;
  FakeSimulator sim;
  CollectSink sink;
  run_simulator(sim, s, &sink);
  ASSERT_EQ(sink.times.size(), 4u);
  EXPECT_EQ(sink.times.back(), 0.3);
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
