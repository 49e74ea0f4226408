// The registry of simulators: the one list a new engine is added to (one line each).
#include "registry.h"

#include <stdexcept>

namespace tippe {

// Each adapter file defines its EngineInfo.
const EngineInfo& analytic_engine_info();
const EngineInfo& bullet_engine_info();
const EngineInfo& ode_engine_info();
const EngineInfo& mujoco_engine_info();
const EngineInfo& dart_engine_info();
const EngineInfo& simbody_engine_info();
const EngineInfo& siconos_engine_info();

const std::vector<EngineInfo>& engine_registry() {
#ifdef TIPPE_REFERENCE_ONLY
  // Configured with TIPPE_ENGINES=OFF: the reference alone.
  static const std::vector<EngineInfo> registry = {analytic_engine_info()};
#else
  static const std::vector<EngineInfo> registry = {
      analytic_engine_info(), bullet_engine_info(), ode_engine_info(), mujoco_engine_info(), dart_engine_info(), simbody_engine_info(),
      siconos_engine_info(),
  };
#endif
  return registry;
}

const EngineInfo* find_engine(const std::string& name) {
  for (const EngineInfo& e : engine_registry())
    if (e.name == name) return &e;
  return nullptr;
}

std::string engine_list_text(const std::vector<std::string>& names) {
  std::string s;
  for (size_t i = 0; i < names.size(); ++i) s += (i == 0 ? "" : i + 1 == names.size() ? " or " : ", ") + names[i];
  return s;
}

const EngineInfo& engine_info(const std::string& name) {
  if (const EngineInfo* e = find_engine(name)) return *e;
  throw std::invalid_argument("unknown engine \"" + name + "\" (expected " + engine_list_text(available_engines()) + ")");
}

const EngineInfo& reference_engine() {
  for (const EngineInfo& e : engine_registry())
    if (e.role == EngineRole::Reference) return e;
  throw std::logic_error("no reference simulator registered");
}

std::vector<std::string> available_engines() {
  std::vector<std::string> names;
  for (const EngineInfo& e : engine_registry()) names.push_back(e.name);
  return names;
}

std::vector<std::string> engine_names() {
  std::vector<std::string> names;
  for (const EngineInfo& e : engine_registry())
    if (e.role == EngineRole::Engine) names.push_back(e.name);
  return names;
}

std::string engine_plot_colour(const std::string& name) {
  const EngineInfo* e = find_engine(name);
  return e ? e->colour : "#7f7f7f";
}

void validate_engine_settings(const Scene& scene) {
  for (const auto& kv : scene.engines) {
    const EngineInfo* e = find_engine(kv.first);
#ifdef TIPPE_REFERENCE_ONLY
    // Tables of engines this build does not have: the reference never reads them, and checking
    // them needs those engines' settings, so they are accepted unread (a scene valid in the full
    // build stays valid here).
    if (!e) continue;
#endif
    if (!e) throw std::invalid_argument("engines." + kv.first + ": unknown engine (expected " +
                                        engine_list_text(available_engines()) + ")");
    e->validate(scene);
  }
}

std::unique_ptr<Simulator> make_simulator(const std::string& engine, const Scene& scene) {
#ifdef TIPPE_REFERENCE_ONLY
  if (!find_engine(engine))
    throw std::invalid_argument("engine \"" + engine +
                                "\" is not built (configured with TIPPE_ENGINES=OFF: only the reference is available)");
#endif
  return engine_info(engine).make(scene);
}

}  // namespace tippe
