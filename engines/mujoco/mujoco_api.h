// MuJoCo's MJCF export and import as the harness reaches them: through the registry's entry for "mujoco", never by linking the adapter.
#pragma once

#include <string>
#include <vector>

#include "analytic/scene.h"
#include "engines/mujoco/mujoco_import.h"
#include "engines/core/registry.h"

namespace tippe {

// What the MuJoCo module offers beyond the Simulator interface (EngineInfo::extension of its
// entry): `tippe export-mjcf` and `tippe import-mjcf` call these, which loads the module on
// first use and leaves every other command free of MuJoCo.
struct MujocoApi {
  std::string (*mjcf)(const Scene& scene);                        // mujoco_mjcf (adapters.h)
  std::vector<std::string> (*mjcf_missing)(const Scene& scene);   // mujoco_mjcf_missing (adapters.h)
  MjcfTopImport (*import_top)(const std::string& path, const std::string& body, const std::string& keyframe);
  std::vector<std::string> (*scene_mismatches)(const MjcfTopImport& top, const Scene& scene);
};

// The loaded module's MujocoApi; EngineLoadError when the module cannot be loaded.
inline const MujocoApi& mujoco_api() {
  const void* api = engine_info("mujoco").extension;
  if (!api) throw std::logic_error("the mujoco engine's entry carries no MujocoApi");
  return *static_cast<const MujocoApi*>(api);
}

}  // namespace tippe
