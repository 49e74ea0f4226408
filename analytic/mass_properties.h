// Mass properties of the sphere+stem body under the named conventions, and geometry validation.
#pragma once

#include <string>
#include <vector>

#include "scene.h"

namespace tippe {

// M, d, A, C of the body about G under body.mass_model (Seed or Solid).
//  seed:  the source's formulas: truncated ball (-R..h about O) plus a cylinder of radius r
//         from O to O + l e_Z, overlap counted twice, tip hemisphere ignored.
//  solid: the exact solid: truncated ball, cylinder from O to P (the part outside the ball)
//         and the hemispherical tip of radius r centred at P, overlap counted once.
// Throws std::invalid_argument naming the offending quantity for impossible geometry.
MassProperties compute_mass_properties(const BodyGeometry& body);

// Problems with the geometry (empty when valid): r < R, tip outside the ball, switch exists
// ((R - r)/l < 1), ball contact stays on the solid part up to the switch (h >= R (R - r)/l).
// Each entry names the quantity ("stem_radius", ...) followed by ": " and the reason.
std::vector<std::string> geometry_problems(const BodyGeometry& body, bool stem);

// True when 1 - alpha < A/C < 1 + alpha, alpha = d/R (the top can invert).
bool inversion_possible(const MassProperties& m, double sphere_radius);

}  // namespace tippe
