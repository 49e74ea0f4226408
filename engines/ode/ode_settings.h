// The ODE adapter's settings ([engines.ode]): every choice that decides accuracy, each default with its reason.
#pragma once

#include <climits>
#include <stdexcept>
#include <string>

#include "engines/core/settings.h"

namespace tippe {

// Every setting of the ODE model that decides accuracy, read from [engines.ode].
struct OdeSettings {
  // ODE's stepper is first order. On the dimensionless top (spin 5, 30 time units) theta(30)
  // is 0.0536 / 0.0525 / 0.0524 at 1e-3 / 1e-4 / 1e-5, and at 1e-3 the per-step drift
  // already outgrows surface_layer (the contact drops out once per time unit); 1e-4 is
  // converged to 2e-3 relative at 0.4 s wall time.
  double timestep = 1e-4;
  // "step" (dWorldStep): exact big-matrix LCP (Dantzig), no iteration error, cheap for one body.
  // "quickstep" (dWorldQuickStep): iterative PGS, for comparison only.
  std::string stepper = "step";
  // Quickstep sweeps per step; unused by "step". ODE's default is 20, 50 converges a
  // one-body, few-contact system well.
  int iterations = 50;
  // World ERP/CFM: used by the friction rows (the normal row has its own soft values). ODE's
  // double-precision defaults; cfm only regularizes the LCP.
  double erp = 0.2;
  double cfm = 1e-10;
  // Contact normal row. With ODE's spring equivalence k_p = erp / (h cfm), the compliance adds
  // M g h cfm / erp = 1 * 1e-4 * 1e-9 / 0.2 = 5e-13 R of penetration (dimensionless scene) to
  // surface_layer: a hard contact. erp 0.2 (ODE's default) removes 20 % of any depth beyond
  // the layer per step without the overshoot that erp near 1 gives.
  double soft_erp = 0.2;
  double soft_cfm = 1e-9;
  // dWorldSetContactSurfaceLayer, scene length units: depth ERP leaves alone. With 0 (ODE's
  // default) the push-out plus the second-order drift of a rolling, spinning ball over a step
  // lifts the ball to a gap of ~1e-9 every ~20 steps: the contact vanishes for one step (normal
  // force 0, a spurious ball -> none -> ball switch, 12000 of them in 30 time units). Resting at
  // 1e-6 deep keeps those ~1e-9 fluctuations inside the contact; 1e-6 is below 1e-4 R for any
  // top down to R = 1 cm in SI units.
  double surface_layer = 1e-6;
  // ODE's default infinitesimal orientation update (q += h/2 w q, renormalized) is wrong for a
  // fast-spinning top; the full finite rotation (axis 0,0,0) is exact for constant w.
  bool finite_rotation = true;
  // The w x I w term is the physics of the top; switching it off is only a diagnostic.
  bool gyroscopic = true;
  // dRandSetSeed before each world build: quickstep reorders rows randomly.
  int seed = 0;
  // Per geom pair: sphere-plane gives 1 contact, capsule-plane at most 2; 4 leaves headroom.
  int max_contacts = 4;
  // The stem's collision shape: a capsule from O to P (what a user models as the stem), or the
  // sphere of radius r at P alone (the reference's stem contact). Their lowest points are the
  // same at every tilt (the capsule's other end lies inside the ball), so the physics is the
  // same; ODE's capsule-plane and sphere-plane routines are not, hence a choice to sweep.
  std::string stem_shape = "capsule";
  // "approx1": mu is a coefficient (|F_t| <= mu F_n, from the normal force of the same solve).
  // "box": mu is a constant force bound (ODE's plain default), a different law; diagnostic.
  std::string friction_model = "approx1";
  // Friction coefficient that stands in for the rolling constraint (friction = rolling): a
  // rolling top needs |F_t| / F_n of order 1, so 1e3 never lets the contact slip.
  double rolling_mu = 1e3;

  template <class V>
  void visit(V& v) {
    shared_settings::timestep(v, timestep);
    v("stepper", stepper, {"step", "quickstep"});
    shared_settings::iterations(v, "iterations", iterations);
    shared_settings::fraction(v, "erp", erp);
    shared_settings::fraction(v, "cfm", cfm);
    shared_settings::fraction(v, "soft_erp", soft_erp);
    shared_settings::fraction(v, "soft_cfm", soft_cfm);
    v("surface_layer", surface_layer, 0.0, 1.0);
    v("finite_rotation", finite_rotation);
    v("gyroscopic", gyroscopic);
    v("seed", seed, 0, INT_MAX);
    v("max_contacts", max_contacts, 1, 64);
    shared_settings::stem_shape(v, stem_shape);
    v("friction_model", friction_model, {"approx1", "box"});
    shared_settings::rolling_mu(v, rolling_mu);
  }
};

// Settings that are valid one by one but not together with the scene.
inline void check_combination(const OdeSettings& s, const Scene& scene) {
  // ODE 0.16's contact joint counts a constraint row for every rho, rho2, rhoN that is >= 0
  // under dContactAxisDep but fills only those > 0: the two empty rows (rho = rho2 = 0) are
  // singular unless the world CFM regularizes them (cfm = 0 aborts in dxNormalize4 on NaN).
  if (scene.contact.drilling > 0 && !(s.cfm > 0))
    throw std::invalid_argument("engines.ode.cfm: must be > 0 with drilling friction (ODE 0.16 adds empty constraint rows)");
}

}  // namespace tippe
