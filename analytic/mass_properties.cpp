// Mass properties (placeholder).
#include "mass_properties.h"

#include <stdexcept>

namespace tippe {
MassProperties compute_mass_properties(const BodyGeometry&) { throw std::runtime_error("not built"); }
std::vector<std::string> geometry_problems(const BodyGeometry&, bool) { return {}; }
bool inversion_possible(const MassProperties& m, double R) {
  const double alpha = m.com_offset / R, ratio = m.inertia_transverse / m.inertia_axial;
  return 1 - alpha < ratio && ratio < 1 + alpha;
}
}  // namespace tippe
