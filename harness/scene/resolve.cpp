// A scene's resolve step: engines' files read and hashed, [engines.*] checked through the registry, the reference's settings applied.
#include "harness/scene/resolve.h"

#include <set>
#include <stdexcept>
#include <utility>
#include <variant>

#include "engines/core/adapters.h"
#include "harness/io/files.h"
#include "engines/core/registry.h"

namespace tippe {

namespace {

[[noreturn]] void fail(const Scene& s, const EngineFileSetting& f, const std::string& why) {
  throw SceneError(s.source_file + ": engines." + f.engine + "." + f.key + ": " + why);
}

// Resolves one file setting in place (relative to the scene file) and returns the file's bytes.
std::string resolve_file(const Scene& s, const EngineFileSetting& f, SettingValue& value) {
  const auto* path = std::get_if<std::string>(&value);
  if (!path) fail(s, f, "expected a string (a path to " + f.what + ", relative to the scene file)");
  if (path->empty()) fail(s, f, "is empty (expected a path to " + f.what + ")");
  std::filesystem::path p(*path);
  if (p.is_relative()) p = std::filesystem::path(s.source_file).parent_path() / p;
  // Read where the runs will read (the value is stored normalized), so that "out/../model.xml"
  // of a scene checked before its directory out/ exists (import-mjcf --out out/top.toml) is read.
  p = p.lexically_normal();
  std::error_code ec;
  if (std::filesystem::is_directory(p, ec)) fail(s, f, p.string() + ": is a directory");
  std::string bytes;
  try {
    bytes = read_file_text(p.string(), kMaxInputFileBytes);
  } catch (const std::runtime_error& e) {
    fail(s, f, e.what());
  }
  value = p.string();
  return bytes;
}

// Calls fn(setting, value) for every engine file setting (engine_file_settings) the scene gives,
// in the registry's order; S is Scene or const Scene.
template <class S, class F>
void for_each_engine_file(S& s, F&& fn) {
  for (const EngineFileSetting& f : engine_file_settings()) {
    const auto engine = s.engines.find(f.engine);
    if (engine == s.engines.end()) continue;
    const auto it = engine->second.find(f.key);
    if (it != engine->second.end()) fn(f, it->second);
  }
}

}  // namespace

Scene resolve_scene(SceneFile file) {
  Scene& s = file.scene;
  // An engine's files first: its checks (MuJoCo compiling a user's model) read the resolved path.
  std::vector<std::pair<std::string, std::string>> inputs;
  for_each_engine_file(s, [&](const EngineFileSetting& f, SettingValue& value) {
    inputs.emplace_back("engines." + f.engine + "." + f.key, resolve_file(s, f, value));
  });
  // The file layer hashed the scene's bytes and overrides (parse_scene_file), all there is to a
  // scene without engine files; it reads no engine's file, so the hash that covers them is made
  // here, over the same text and overrides (scene_content_hash with no inputs is the file
  // layer's: the published records' hashes stay as they were).
  if (!inputs.empty()) s.content_hash = scene_content_hash(file.text, file.overrides, inputs);
  try {
    validate_engine_settings(s);
    if (reference_engine().adopt) reference_engine().adopt(s);
  } catch (const std::invalid_argument& e) {
    // The shipped scenes give the reference's settings in [engines.analytic], so an override
    // in the older spelling (--set run.rtol=...) meets them there: say which spelling to use.
    std::string hint;
    const std::string table = "engines." + reference_engine().name + ".";
    const std::set<std::string> overridden = overridden_keys(file.overrides);
    for (const std::string& k : s.run.alias_keys)
      if (overridden.count("run." + k) && std::string(e.what()).rfind(table + k + ":", 0) == 0)
        hint = "; run." + k + " was set with --set: set " + table + k + " instead";
    throw SceneError(s.source_file + ": " + e.what() + hint);
  } catch (const EngineLoadError& e) {
    // A table whose engine's module cannot be loaded cannot be checked: the scene is refused
    // with the loader's reason (SceneError stays the only exception a scene's reading throws).
    throw SceneError(s.source_file + ": " + e.what());
  }
  return std::move(file.scene);
}

Scene load_scene(const std::string& path, const std::vector<std::string>& overrides) {
  return resolve_scene(read_scene_file(path, overrides));
}

Scene parse_scene_text(const std::string& text, const std::string& file_label,
                       const std::vector<std::string>& overrides) {
  return resolve_scene(parse_scene_file(text, file_label, overrides));
}

std::vector<std::filesystem::path> scene_input_files(const Scene& scene) {
  std::vector<std::filesystem::path> files;
  if (!scene.source_file.empty()) files.emplace_back(scene.source_file);
  for_each_engine_file(scene, [&](const EngineFileSetting&, const SettingValue& value) {
    if (const auto* path = std::get_if<std::string>(&value)) files.emplace_back(*path);
  });
  return files;
}

}  // namespace tippe
