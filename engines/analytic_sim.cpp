// Analytic reference adapter (placeholder).
#include <stdexcept>

#include "adapters.h"

namespace tippe {

std::unique_ptr<Simulator> make_analytic_simulator(const Scene&) {
  throw std::runtime_error("analytic adapter not built");
}

}  // namespace tippe
