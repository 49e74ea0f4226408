// Tests of the scene's resolve step (harness/scene/resolve.h): io/ reads [engines.*] raw, the resolve step checks them, applies the reference's settings and reads and hashes an engine's files.
#include <gtest/gtest.h>

#include <filesystem>
#include <functional>
#include <string>
#include <variant>
#include <vector>

#include "harness/io/scene_io.h"
#include "engines/core/registry.h"
#include "harness/scene/resolve.h"
#include "tests/support/files.h"
#include "tests/support/fixtures.h"
#include "tests/support/process.h"

namespace tippe::test_resolve {
namespace {

using fixtures::edit;
using fixtures::kBase;

std::string scene_error(const std::function<void()>& call) {
  try {
    call();
  } catch (const SceneError& e) {
    return e.what();
  }
  return "<accepted>";
}

TEST(SceneResolve, IoKeepsEngineTablesRawAndResolveChecksThem) {
  // An engine no build has: the file layer copies its table, the resolve step refuses it.
  const std::string text = std::string(kBase) + "[engines.nosuch]\nx = 1\n";
  const SceneFile raw = parse_scene_file(text, "base.toml");
  ASSERT_EQ(raw.scene.engines.count("nosuch"), 1u);
  EXPECT_EQ(std::get<long long>(raw.scene.engines.at("nosuch").at("x")), 1);
  EXPECT_EQ(scene_error([&] { resolve_scene(raw); }).rfind("base.toml: engines.nosuch: unknown engine", 0), 0u);
  EXPECT_EQ(scene_error([&] { parse_scene_text(text, "base.toml"); }), scene_error([&] { resolve_scene(raw); }));
}

TEST(SceneResolve, AppliesTheReferencesSettings) {
  // [engines.analytic] rtol reaches scene.run only through the reference's adopt, one layer up.
  const std::string text =
      edit(edit(kBase, "rtol = 1e-10\n", ""), "atol = 1e-12\n", "") + "[engines.analytic]\nrtol = 1e-8\n";
  const SceneFile raw = parse_scene_file(text, "base.toml");
  EXPECT_EQ(raw.scene.run.rtol, 1e-10);  // RunSpec's default: the table is not read yet
  EXPECT_EQ(resolve_scene(raw).run.rtol, 1e-8);
}

TEST(SceneIo, ReferenceSettingsInEnginesAnalyticAndTheirOlderSpelling) {
  // [engines.analytic] is where the reference's settings live; [run]'s older keys are still read
  // and listed (the reference notes them as deprecated); a key in both is refused (bad_scenes).
  TempDir dir{"tippe-test"};
  const std::string path =
      dir.write("ref.toml", edit(edit(kBase, "rtol = 1e-10\n", ""), "atol = 1e-12\n", "") +
                                "[engines.analytic]\nrtol = 1e-8\nmethod = \"dopri5\"\nself_check = false\n");
  const Scene s = load_scene(path);
  EXPECT_EQ(s.run.rtol, 1e-8);
  EXPECT_EQ(s.run.method, "dopri5");
  EXPECT_FALSE(s.run.self_check);
  EXPECT_TRUE(make_simulator("analytic", s)->notes().empty());
  const Scene old = load_scene(dir.write("old.toml", kBase));
  ASSERT_FALSE(old.run.alias_keys.empty());
  const auto notes = make_simulator("analytic", old)->notes();
  ASSERT_EQ(notes.size(), 1u);
  EXPECT_NE(notes[0].find("run.rtol"), std::string::npos) << notes[0];
  EXPECT_NE(notes[0].find("deprecated"), std::string::npos) << notes[0];
  const Scene fresh = load_scene(dir.write("new.toml", edit(edit(kBase, "rtol = 1e-10\n", ""), "atol = 1e-12\n", "")));
  EXPECT_TRUE(fresh.run.alias_keys.empty());
}

TEST(SceneResolve, ContentHashFormulaIsTheOnePublishedRecordsKeyOn) {
  // FNV-1a 64 over the file's bytes, each input file as '\0' KEY '\0' BYTES, each override as
  // '\0' OVERRIDE: the values are the formula's, computed independently (FNV-1a 64 by hand);
  // published records and reference caches key on them, so they must never move.
  EXPECT_EQ(scene_content_hash("gravity = 1\n", {"run.duration=2"}), "265784cdf6603445");
  EXPECT_EQ(scene_content_hash("gravity = 1\n", {"run.duration=2"}, {{"engines.mujoco.model", "<mujoco/>"}}),
            "4fc50a133a3d1b7c");
  // A scene without engine files keeps the file layer's hash.
  const std::string path = fixtures::kScenesDir + "toy.toml";
  EXPECT_EQ(load_scene(path).content_hash, scene_content_hash(slurp(path), {}));
}

TEST(SceneResolve, ReadsAnEnginesFileRelativeToTheSceneAndHashesIt) {
  // The bench's own MJCF of a scene, as the scene's MuJoCo model: resolved relative to the scene
  // file, listed as an input and hashed under its key.
  TempDir dir;
  // Coulomb: the bench's own MJCF carries it (the viscous law of kBase the bench applies itself).
  const std::string base = edit(kBase, "friction = \"viscous\"\nk = 1.0\n", "friction = \"coulomb\"\nmu = 0.3\n");
  const std::string scene = dir.write("top.toml", base);
  const std::string xml = (dir.path() / "models" / "top.xml").string();
  std::filesystem::create_directories(dir.path() / "models");
  const pid_t pid = spawn_process({fixtures::kTippeBinary, "export-mjcf", scene, "--out", xml},
                                  dir.path() / "export.log", dir.path() / "export.log");
  ASSERT_EQ(wait_process(pid).code, 0) << slurp(dir.path() / "export.log");
  const std::string text = base + "[engines.mujoco]\nmodel = \"models/top.xml\"\n";
  const std::string with_model = dir.write("with_model.toml", text);

  const SceneFile raw = read_scene_file(with_model, {"run.duration=2"});
  EXPECT_EQ(std::get<std::string>(raw.scene.engines.at("mujoco").at("model")), "models/top.xml");
  EXPECT_EQ(raw.scene.content_hash, scene_content_hash(text, {"run.duration=2"}));

  const Scene s = load_scene(with_model, {"run.duration=2"});
  EXPECT_EQ(std::get<std::string>(s.engines.at("mujoco").at("model")), xml);
  EXPECT_EQ(s.content_hash, scene_content_hash(text, {"run.duration=2"}, {{"engines.mujoco.model", slurp(xml)}}));
  const std::vector<std::filesystem::path> inputs = scene_input_files(s);
  ASSERT_EQ(inputs.size(), 2u);
  EXPECT_EQ(inputs[0], with_model);
  EXPECT_EQ(inputs[1], xml);

  // A missing file names the scene, the key and the path tried.
  const std::string missing = dir.write("missing.toml", base + "[engines.mujoco]\nmodel = \"nope.xml\"\n");
  EXPECT_EQ(scene_error([&] { load_scene(missing); }),
            missing + ": engines.mujoco.model: " + (dir.path() / "nope.xml").string() +
                ": cannot read: No such file or directory");
}

}  // namespace
}  // namespace tippe
