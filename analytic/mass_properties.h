// Mass properties of the sphere+stem body under the named conventions, and geometry validation.
#pragma once

#include <string>
#include <vector>

#include "analytic/scene.h"

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
// density == 0 is taken as "not given" (mass given directly, or not read yet: the scene reader
// validates the geometry before it reads the density); a negative or non-finite one is reported.
std::vector<std::string> geometry_problems(const BodyGeometry& body, bool stem);

// The uniform ball of radius R cut at height h above its centre O (solid for -R <= Z' <= h):
// mass, com_offset = distance of its own centre of mass below O, and A, C about that centre.
MassProperties truncated_ball_mass_properties(double sphere_radius, double truncation_height,
                                              double density);

// The tippe top of MuJoCo's Python tutorial, with MuJoCo's own mass bookkeeping (each geom's
// mass added independently, overlaps counted twice): ball R = 0.02 m, stem cylinder of radius
// 0.004 m and half-length 0.008 m centred 0.02 m above O, non-colliding ballast box of full size
// 0.046 x 0.046 x 0.01 m centred 0.015 m below O, density 1000 kg/m^3 throughout.
//
// Stem-tip model for our capsule geometry: the tutorial's stem ends in a flat face at 0.028 m
// above O whose rim touches the floor. Our stem ends in a hemisphere of radius r centred at
// P = O + l e_Z; keeping the stem radius r = 0.004 m and putting the top of the hemisphere at
// the height of the flat face gives l = 0.028 - 0.004 = 0.024 m (and h = R = 0.02 m, full ball).
// That top then passes geometry_problems: l + r = 0.028 > R, (R - r)/l = 2/3 < 1, h = R.
// The rim of the flat face and the hemisphere touch the floor at different points once the
// stem tilts, so stem-contact phases are comparable, not identical.
MassProperties mujoco_tutorial_mass_properties();

// True when 1 - alpha < A/C < 1 + alpha, alpha = d/R (the top can invert).
bool inversion_possible(const MassProperties& m, double sphere_radius);

}  // namespace tippe
