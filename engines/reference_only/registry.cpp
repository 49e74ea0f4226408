// make_simulator of a build configured with TIPPE_ENGINES=OFF: the analytic reference is the only simulator.
#include <stdexcept>

#include "../adapters.h"

namespace tippe {

std::vector<std::string> available_engines() { return {"analytic"}; }

// The [engines.NAME] tables configure engines this build does not have: the reference never
// reads them, and checking them needs the engines' own settings, so they are accepted unread
// (a scene file valid in the full build stays valid here).
void validate_engine_settings(const Scene&) {}

std::unique_ptr<Simulator> make_simulator(const std::string& engine, const Scene& scene) {
  if (engine == "analytic") return make_analytic_simulator(scene);
  throw std::invalid_argument("engine \"" + engine +
                              "\" is not built (configured with TIPPE_ENGINES=OFF: only analytic is available)");
}

}  // namespace tippe
