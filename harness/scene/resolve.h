// A scene's resolve step: a scene file's [engines.*] tables checked through the registry, the reference's settings applied, engines' files read.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "harness/io/scene_io.h"
#include "analytic/scene.h"

namespace tippe {

// The Scene every run, sweep, gate and command uses, from what io/ read (which knows no engine):
//  - each engine's file settings (engine_list.h's TIPPE_ENGINE_FILE, e.g. engines.mujoco.model, a
//    user's MJCF) given in the scene are resolved relative to the scene file's directory, must be
//    readable (at most kMaxInputFileBytes) and are replaced by their normalised path; their bytes
//    join Scene::content_hash (scene_content_hash), so a changed model is a changed scene;
//  - every [engines.NAME] table is checked by validate_engine_settings (an unknown engine, key,
//    type or value; MuJoCo compiles a user's model), then the reference's adopt writes its
//    [engines.NAME] table into scene.run.
// Throws SceneError "FILE: KEY: reason" (as io/scene_io.h words it), FILE the scene's source_file;
// an engine whose module cannot be loaded is "FILE: " and the loader's reason.
Scene resolve_scene(SceneFile file);

// read_scene_file then resolve_scene: a scene file as every command reads it.
Scene load_scene(const std::string& path, const std::vector<std::string>& overrides = {});

// parse_scene_file then resolve_scene. Touches no file but the engines' files a scene names;
// SceneError is the only exception it throws for any input (the fuzz target
// tests/fuzz/fuzz_scene.cpp holds it to that).
Scene parse_scene_text(const std::string& text, const std::string& file_label,
                       const std::vector<std::string>& overrides = {});

// The files a resolved scene was read from: its own, and each engine file setting it gives (an
// output must never be written over, or around, one of them).
std::vector<std::filesystem::path> scene_input_files(const Scene& scene);

}  // namespace tippe
