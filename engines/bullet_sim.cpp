// bullet adapter (placeholder until the adapter lands).
#include <stdexcept>

#include "adapters.h"

namespace tippe {

std::unique_ptr<Simulator> make_bullet_simulator(const Scene&) {
  throw std::runtime_error("bullet adapter not built");
}

void validate_bullet_settings(const Scene&) {}

}  // namespace tippe
