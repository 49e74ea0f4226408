// The settings of the Siconos model that decide accuracy, read from [engines.siconos].
#pragma once

#include <string>

#include "engines/core/settings.h"  // shared_settings: the bounds every engine gives the same key

namespace tippe {

// Every accuracy-relevant setting of the Siconos adapter (one field list: `visit`). Units are the
// scene's (SI for the toy scenes, M = g = R = 1 for the dimensionless ones).
struct SiconosSettings {
  // Moreau-Jean's time step h. 1e-4, as every fixed-step engine of the bench by default: the
  // scheme is first order (positions and velocities at the step ends; impulses over the step),
  // so the error of a run scales with h, and the bench compares engines at the same step.
  double timestep = 1e-4;
  // Moreau-Jean's theta: the smooth forces (gravity, gyroscopic moment, the bench's forces) are
  // taken at (1 - theta) of the step start plus theta of its end. 0.5 (Siconos' own default)
  // is the trapezoidal weighting that adds no numerical dissipation to a rolling or spinning
  // top, whose energy the reference conserves; 1 is the implicit Euler of dissipative stability.
  double theta = 0.5;
  // Moreau-Jean's gamma: the contact is activated when the gap predicted at t + gamma h is
  // closed. Negative: Siconos' default (the gap at the step start plus h/2 of its rate).
  double gamma = -1.0;
  // MoreauJeanOSI's constraint activation threshold, in units of R: a contact whose predicted gap
  // is below it takes part in the step's problem. Siconos' default is 0, so a contact at a gap
  // of round-off above 0 (a top set down on the floor exactly, both contacts at the switching
  // tilt) is left out and the body falls free for a step. 1e-9 R counts it; an active contact
  // that is not closed can only stop an approach early, by at most this gap.
  double activation_margin = 1e-9;
  // The one-step nonsmooth problem (a 3D friction contact problem per step: Signorini and
  // Coulomb on the impulses) is solved by Siconos' numerics: "nsgs" (nonsmooth Gauss-Seidel
  // over the contacts, each solved by a local Newton: Siconos' default for FrictionContact),
  // "nsn_ac" (a global nonsmooth Newton on the Alart-Curnier function) or "prox" (proximal point).
  std::string solver = "nsgs";
  // The solver's tolerance on its own residual (Siconos' default is 1e-4, for granular flows of
  // thousands of contacts): with one or two contacts the problem costs little, and 1e-10
  // leaves the error of a step to h, not to the solver.
  double tolerance = 1e-10;
  int max_iterations = 1000;
  // The Newton loop of TimeStepping on the nonlinear body (quaternion kinematics, gyroscopic
  // moment, contact geometry that moves with the body): iterated to newton_tolerance, at most
  // newton_max_iterations per step. Siconos' defaults, 1e-6 and 50; 1e-10 for the same reason.
  double newton_tolerance = 1e-10;
  int newton_max_iterations = 50;
  // The stand-in friction coefficient for the scene's rolling law, as the fixed-step engines'
  // rolling_mu: a nonsmooth Coulomb law sticks exactly below its cone, so a large mu is rolling.
  double rolling_mu = 1e3;

  template <class V>
  void visit(V& v) {
    shared_settings::timestep(v, timestep);
    v("theta", theta, 0.0, 1.0);
    v("gamma", gamma, -1.0, 1.0);
    v("activation_margin", activation_margin, 0.0, 1e-3);
    v("solver", solver, {"nsgs", "nsn_ac", "prox"});
    v("tolerance", tolerance, 1e-16, 1.0);
    shared_settings::iterations(v, "max_iterations", max_iterations);
    v("newton_tolerance", newton_tolerance, 1e-16, 1.0);
    v("newton_max_iterations", newton_max_iterations, 1, 10000);
    shared_settings::rolling_mu(v, rolling_mu);
  }
};

}  // namespace tippe
