// mujoco adapter (placeholder until the adapter lands).
#include <stdexcept>

#include "adapters.h"

namespace tippe {

std::unique_ptr<Simulator> make_mujoco_simulator(const Scene&) {
  throw std::runtime_error("mujoco adapter not built");
}

void validate_mujoco_settings(const Scene&) {}

}  // namespace tippe
namespace tippe {
std::string mujoco_mjcf(const Scene&) { return {}; }
}  // namespace tippe
