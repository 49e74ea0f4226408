// The engine registry: one EngineInfo per simulator (name, role, factory, settings, version, colour), each engine's loaded from its module on first use.
#pragma once

#include <functional>
#include <memory>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "engines/core/settings.h"
#include "engines/core/simulator.h"

namespace tippe {

// The reference is what every engine is measured against; there is exactly one.
enum class EngineRole { Reference, Engine };

// One accuracy-relevant setting of an engine that `tippe advise` searches over: a key of the
// engine's [engines.NAME] table and its admissible values, each written as a TOML value
// ("\"RK4\"", "10", "true"), the engine's default first.
struct SettingAxis {
  std::string key;
  std::vector<std::string> values;
};

struct EngineInfo {
  std::string name;      // as in --engine, [engines.NAME] and records
  EngineRole role = EngineRole::Engine;
  std::function<std::unique_ptr<Simulator>(const Scene&)> make;
  // Reads the scene's [engines.NAME] table into the engine's settings struct (its `visit`) and
  // checks combinations; throws std::invalid_argument naming the key.
  std::function<void(const Scene&)> validate;
  // The settings struct's defaults as key=value (what `tippe info` lists).
  std::function<SettingsList()> default_settings;
  // Every setting's key, type, default and accepted values (docs/engines.md, `tippe info --markdown`).
  std::function<std::vector<SettingDoc>()> describe_settings;
  // The reference only: writes its [engines.NAME] table into scene.run (the values the
  // reference and the harness read), so that [run]'s older keys and the table agree.
  std::function<void(Scene&)> adopt;
  // What `tippe advise` searches: the categorical axes (every combination is one configuration)
  // and the cost knob, a key of [engines.NAME] whose larger values are cheaper and softer (the
  // time step), searched for its boundary in each configuration. Each adapter declares its own
  // next to its registration; an engine without axes is searched in its defaults alone, and one
  // without a cost knob is not advised.
  std::vector<SettingAxis> advice_axes;
  std::string cost_knob;
  std::string version;   // library version, as Simulator::version() reports it
  std::string colour;    // plot colour (#rrggbb) in every report
  // An engine's own interface beyond Simulator, for the one command that is about that engine
  // (MuJoCo's MJCF export and import: engines/mujoco/mujoco_api.h says its type); nullptr for most.
  const void* extension = nullptr;
};

// Builds the `validate` and `default_settings` members from a settings struct with `visit`.
template <class Settings>
void set_settings_struct(EngineInfo& info, std::function<void(const Settings&, const Scene&)> check = nullptr) {
  const std::string name = info.name;
  info.validate = [name, check](const Scene& scene) {
    const Settings s = read_settings<Settings>(name, scene);
    if (check) check(s, scene);
  };
  info.default_settings = [] { return list_settings(Settings{}); };
  info.describe_settings = [] { return describe_settings(Settings{}); };
}

// One registry entry from a settings struct with `visit` (validate and default_settings as
// set_settings_struct makes them); `check` adds checks of combinations beyond each key's bounds.
// An adapter's NAME_engine_info() returns one of these, made once.
template <class Settings>
EngineInfo engine_entry(std::string name, EngineRole role, std::function<std::unique_ptr<Simulator>(const Scene&)> make,
                        std::string version, std::string colour,
                        std::function<void(const Settings&, const Scene&)> check = nullptr) {
  EngineInfo e;
  e.name = std::move(name);
  e.role = role;
  e.make = std::move(make);
  set_settings_struct<Settings>(e, std::move(check));
  e.version = std::move(version);
  e.colour = std::move(colour);
  return e;
}

// Each simulator's entry, defined in its folder: the reference's, linked into the registry, and
// one per line of engine_list.h, which its module hands over through its entry point.
const EngineInfo& analytic_engine_info();
#define TIPPE_ENGINE(name) const EngineInfo& name##_engine_info();
#include "engines/core/engine_list.h"
#undef TIPPE_ENGINE

// An engine's entry point, one line at the end of its NAME_sim.cpp: the only symbol its module
// exports for the registry, `tippe_engine_NAME`, returns its entry. The same function is what a
// build with the engines linked statically (TIPPE_ENGINE_MODULES=OFF) calls directly.
#define TIPPE_ENGINE_ENTRY_POINT(name)                                                                        \
  extern "C" __attribute__((visibility("default"))) const ::tippe::EngineInfo* tippe_engine_##name() { \
    return &::tippe::name##_engine_info();                                                               \
  }

// A setting of an engine whose value names a file relative to the scene file (engine_list.h's
// TIPPE_ENGINE_FILE lines): the scene's resolve step reads the file with the scene, puts its
// normalised path in the setting and hashes its bytes under "engines.ENGINE.KEY".
struct EngineFileSetting {
  std::string engine;
  std::string key;
  std::string what;  // the file as messages name it: "an MJCF file"
};
// Every engine's file settings, in engine_list.h's order; known in every build, loads nothing.
const std::vector<EngineFileSetting>& engine_file_settings();

// An engine's module could not be loaded (not found, or dlopen/dlsym failed): the message names
// the engine, the module and the paths tried or the loader's own error.
class EngineLoadError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
  ~EngineLoadError() override;  // key function in registry.cpp: one typeinfo, in the shared runtime
};

// Where the registry looks for an engine's module, in order: the directories of the environment
// variable TIPPE_ENGINE_PATH (':'-separated; for tests and relocated trees) when it is set and not
// empty, otherwise DIR/tippe/engines where DIR holds the library the registry itself is in (the
// build tree's lib/, or the installed lib/). Empty when the engines are linked in (no modules).
std::vector<std::string> engine_module_dirs();
// Whether this build loads its engines from modules (TIPPE_ENGINE_MODULES=ON) rather than linking them.
bool engines_in_modules();
// The file name of an engine's module (libtippe_engine_NAME.so).
std::string engine_module_file(const std::string& name);

// Every registered simulator, the reference first, then the engines in registration order. Loads
// every engine's module: what needs only the names asks available_engines() or engine_names().
const std::vector<EngineInfo>& engine_registry();
// nullptr for an unknown name; an engine's module is loaded on its first request (EngineLoadError
// when it cannot be).
const EngineInfo* find_engine(const std::string& name);
// Throws std::invalid_argument naming the known engines for an unknown name (and loads as find_engine).
const EngineInfo& engine_info(const std::string& name);
// Whether an engine's module is loaded already (the reference always is); loads nothing.
bool engine_loaded(const std::string& name);
const EngineInfo& reference_engine();
// The names with role Engine (the default engine list of compare and gates).
std::vector<std::string> engine_names();
// "a, b, c or d": the names for messages and CLI help.
std::string engine_list_text(const std::vector<std::string>& names);
// A colour for any name (registered: its own; otherwise grey), for reports of old records.
std::string engine_plot_colour(const std::string& name);

}  // namespace tippe
