// The scene's initial state, shared by the reference and every engine so that all start alike.
#pragma once

#include "analytic/observables.h"
#include "analytic/scene.h"
#include "analytic/state.h"

namespace tippe {

// Body tilted by initial.tilt about the lab x axis (or turned by initial.orientation), G above
// (initial.position[0], initial.position[1]), resting on its lower surface (the ball, or
// beyond the switching tilt the stem tip; G above the origin at the height that puts it on the floor), angular velocity from spin, omega_B or
// omega_along_contact, horizontal velocity of G as given (rolling: R_C x omega), vertical
// velocity of G such that the ball's lowest point does not move vertically. With
// initial.height > 0 the body starts that much higher, with no vertical velocity (free flight).
BodyState scene_initial_state(const Scene& scene);

}  // namespace tippe
