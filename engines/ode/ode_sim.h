// Test-only window into the ODE adapter: what its dBody holds, without exposing ODE types.
#pragma once

#include "engines/core/simulator.h"

namespace tippe {

// Mass properties as ODE stores them (dBodyGetMass), in the body frame B at the body origin.
struct OdeMassReadback {
  double mass = 0.0;
  Vec3 c_B = Vec3::Zero();                     // centre of mass relative to the body origin
  Eigen::Matrix3d I_B = Eigen::Matrix3d::Zero();  // inertia about the body origin
};

// Throws std::invalid_argument when sim is not an ODE simulator.
OdeMassReadback ode_mass_readback(const Simulator& sim);

}  // namespace tippe
