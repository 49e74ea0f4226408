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

const std::vector<EngineInfo>& engine_registry() {
  static const std::vector<EngineInfo> registry = {
      analytic_engine_info(), bullet_engine_info(), ode_engine_info(), mujoco_engine_info(), dart_engine_info(),
  };
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
    if (!e) throw std::invalid_argument("engines." + kv.first + ": unknown engine (expected " +
                                        engine_list_text(available_engines()) + ")");
    e->validate(scene);
  }
}

std::unique_ptr<Simulator> make_simulator(const std::string& engine, const Scene& scene) {
  return engine_info(engine).make(scene);
}

}  // namespace tippe
