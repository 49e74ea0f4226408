// The settings of the Simbody model that decide accuracy, read from [engines.simbody], and the friction law's mapping.
#pragma once

#include <string>

#include "analytic/scene.h"

namespace tippe {

// Every accuracy-relevant setting of the Simbody adapter (one field list: `visit`). Units are the
// scene's (SI for the toy scenes, M = g = R = 1 for the dimensionless ones).
struct SimbodySettings {
  // Simbody's error-controlled integrators: "rk_merson" (Runge-Kutta-Merson 4(5), Simbody's
  // usual choice and the one its examples and OpenSim default to), "rk3" (3(2)), "rk2"
  // (Heun 2(1)), "euler" (explicit Euler with an error estimate, first order: for comparison),
  // "verlet" (semi-explicit, 2nd order, error-controlled), "cpodes" (implicit BDF with Newton
  // iterations, for stiff contact).
  std::string integrator = "rk_merson";
  // Integrator::setAccuracy: the relative local error allowed per step (weighted RMS norm of
  // the state; absolute below the unit weights set by length_scale and time_scale). Simbody's
  // default is 1e-3, what interactive and biomechanics users run; a user who wants a rigid top's
  // motion to the bench's 1e-3 .. 1e-2 agreement over tens of periods tightens it: 1e-6 (one
  // step of the RK-Merson pair then carries ~1e-6 relative error, about what a 1e-4 fixed step
  // gives the first-order engines over a run).
  double accuracy = 1e-6;
  // Integrator::setMaximumStepSize; 0: none (Simbody's default). Report times (every
  // advance_to) end steps anyway, the integrator not interpolating (see the adapter).
  double max_step = 0.0;
  // System::setDefaultLengthScale / setDefaultTimeScale: Simbody's "unit" length and time from
  // which it derives the error weights of positions and velocities and its first step. 0: from
  // the scene, R and sqrt(R / g) (Simbody's own defaults, 1 length unit and 0.1 time units, are
  // 67 R and 2.6 sqrt(R / g) for the 15 mm toy: position errors of 1e-6 m would pass as 1e-6).
  double length_scale = 0.0;
  double time_scale = 0.0;
  // Hunt-Crossley contact (CompliantContactSubsystem, HertzCircular generator): the normal force
  // of a sphere of radius R pressed x into the floor is
  //   F_n = (4/3) E_eff sqrt(R) x^(3/2) (1 + (3/2) c xdot),
  // with E_eff = stiffness / 2^(3/2) since the floor carries the same material as the top
  // (Simbody combines two materials' k^(2/3) in series). A rigid top: hard plastic or wood,
  // E = 1e9 Pa (ABS 2e9, PS 3e9, oak 1e10). In SI the toy then rests 1.8e-6 m (1.2e-4 R) deep;
  // in a dimensionless scene 1e9 is 1e9 M g / R^2 and it rests 1.6e-6 R deep.
  double stiffness = 1e9;
  // Hunt-Crossley dissipation c (1 / velocity): restitution e ~ 1 - c v at low impact speed v.
  // 0.5 is the value of Simbody's contact examples and a usual choice for plastic on a table.
  double dissipation = 0.5;
  // Simbody's friction law (per contact, F_t = F_n mu(v_slip) opposing the slip):
  //   mu(v) = us step5(v / vt)                                      v < vt
  //         = us - (us - ud) step5((v / vt - 1) / 2)                vt <= v < 3 vt
  //         = ud                                                    v >= 3 vt
  //         + uv v
  // (step5: the quintic from 0 to 1 with two zero derivatives at both ends). Negative: from the
  // scene's law (the mapping below); >= 0 overrides it (noted in the run).
  //   coulomb mu:  us = ud = mu, uv = 0  (Coulomb regularized below vt: no true sticking)
  //   gliding mu:  us = ud = 0, uv = mu  (F_t = -mu F_n v_C exactly, F_n the Hunt-Crossley force)
  //   viscous k:   us = ud = uv = 0, and the bench applies F_t = -k v_C at every contact
  //                (Simbody's law has no friction independent of F_n)
  //   rolling:     us = ud = rolling_mu, uv = 0 (a stand-in, as for the other engines)
  //   none:        0
  double static_friction = -1.0;
  double dynamic_friction = -1.0;
  double viscous_friction = -1.0;
  // CompliantContactSubsystem::setTransitionVelocity: the slip speed below which friction is
  // regularized. Simbody's default is 0.01 (m/s); 1e-3 is OpenSim's and what a user keeps the
  // creep of a rolling contact small with: 4e-4 of the toy's rim speed (2.25 m/s), 2e-4 of the
  // dimensionless top's (5). Smaller makes the tangential law stiffer (time constant ~ vt / (mu g)).
  double transition_velocity = 1e-3;
  // The stand-in friction for the rolling law. Not the 1e3 of the rigid engines: a regularized
  // friction's slope mu F_n / vt is a damper, and at mu = 1e3 its time constant is 1e-6 time
  // units (every explicit integrator crawls); 10 already holds rolling to creep ~ vt.
  double rolling_mu = 10.0;

  template <class V>
  void visit(V& v) {
    v("integrator", integrator, {"rk_merson", "rk3", "rk2", "euler", "verlet", "cpodes"});
    v("accuracy", accuracy, 1e-14, 1.0);
    v("max_step", max_step, 0.0, 1e300);
    v("length_scale", length_scale, 0.0, 1e300);
    v("time_scale", time_scale, 0.0, 1e300);
    v("stiffness", stiffness, 1e-300, 1e300);
    v("dissipation", dissipation, 0.0, 1e300);
    v("static_friction", static_friction, -1.0, 1e15);
    v("dynamic_friction", dynamic_friction, -1.0, 1e15);
    v("viscous_friction", viscous_friction, -1.0, 1e15);
    v("transition_velocity", transition_velocity, 1e-300, 1e300);
    v("rolling_mu", rolling_mu, 0.0, 1e15);
  }
};

// Simbody's friction coefficients for a scene (the mapping above, then the overrides).
struct SimbodyFriction {
  double us = 0.0, ud = 0.0, uv = 0.0;
  bool bench_viscous = false;  // the bench adds F_t = -k v_C at every contact
};

inline SimbodyFriction simbody_friction(const SimbodySettings& s, const ContactSpec& c) {
  SimbodyFriction f;
  switch (c.friction) {
    case FrictionLaw::Coulomb: f.us = f.ud = c.mu; break;
    case FrictionLaw::Gliding: f.uv = c.mu; break;
    case FrictionLaw::Viscous: f.bench_viscous = true; break;
    case FrictionLaw::Rolling: f.us = f.ud = s.rolling_mu; break;
    case FrictionLaw::None: break;
  }
  if (s.static_friction >= 0) f.us = s.static_friction;
  if (s.dynamic_friction >= 0) f.ud = s.dynamic_friction;
  if (s.viscous_friction >= 0) f.uv = s.viscous_friction;
  return f;
}

}  // namespace tippe
