// ode adapter (placeholder until the adapter lands).
#include <stdexcept>

#include "adapters.h"

namespace tippe {

std::unique_ptr<Simulator> make_ode_simulator(const Scene&) {
  throw std::runtime_error("ode adapter not built");
}

void validate_ode_settings(const Scene&) {}

}  // namespace tippe
