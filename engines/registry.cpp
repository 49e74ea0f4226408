// make_simulator: the one place that maps an engine name to its adapter.
#include <stdexcept>

#include "adapters.h"

namespace tippe {

std::vector<std::string> available_engines() { return {"analytic", "bullet", "ode", "mujoco"}; }

void validate_engine_settings(const Scene& scene) {
  for (const auto& kv : scene.engines) {
    if (kv.first == "bullet") validate_bullet_settings(scene);
    else if (kv.first == "ode") validate_ode_settings(scene);
    else if (kv.first == "mujoco") validate_mujoco_settings(scene);
    else throw std::invalid_argument("engines." + kv.first + ": unknown engine (expected bullet, ode or mujoco)");
  }
}

std::unique_ptr<Simulator> make_simulator(const std::string& engine, const Scene& scene) {
  if (engine == "analytic") return make_analytic_simulator(scene);
  if (engine == "bullet") return make_bullet_simulator(scene);
  if (engine == "ode") return make_ode_simulator(scene);
  if (engine == "mujoco") return make_mujoco_simulator(scene);
  throw std::invalid_argument("unknown engine \"" + engine + "\" (expected analytic, bullet, ode or mujoco)");
}

}  // namespace tippe
