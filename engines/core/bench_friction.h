// The friction laws the bench applies itself as external forces (viscous, gliding), the same for
// every engine whose own contact is then frictionless.
#pragma once

#include "analytic/initial_state.h"
#include "engines/core/step_checks.h"

namespace tippe {

// The laws the bench applies (the engine's own contact is then frictionless).
inline bool bench_applies_friction(FrictionLaw law) { return law == FrictionLaw::Viscous || law == FrictionLaw::Gliding; }

// The friction coefficient an engine's own contact carries for the scene's law: mu for Coulomb,
// the engine's stand-in rolling_mu for rolling, 0 for none and for the laws the bench applies
// itself (viscous, gliding: the engine's contact must then be frictionless).
double native_mu(const ContactSpec& contact, double rolling_mu);

// At most one force per contact surface (ball, stem), each with its point of application
// relative to G in the lab frame.
struct BenchFrictionForces {
  int n = 0;
  bool stem[2] = {false, false};  // the surface of each force
  Vec3 f_W[2];
  Vec3 r_GC_W[2];
};

// The viscous law F_t = -k v_C or the gliding law F_t = -mu F_n v_C at every contact the engine
// reports in c, each at its own geometric contact point with its own horizontal velocity, from
// the state x at the start of the step; none for the other laws. With ball and stem both down,
// friction at one of them only would let the other slide freely: the reference applies the law
// at each contact, so the engines must too. The gliding law's F_n is the engine's from the
// previous step (c describes the step just taken): an explicit law, first order in dt, as an
// engine's solve cannot carry a friction proportional to the force it is solving for. Before the
// first step c is the report of the initial state (0 where the engine has not solved yet: one
// step without friction).
BenchFrictionForces bench_friction_forces(const BodyModel& body, const ContactSpec& contact, const BodyState& x,
                                          const ContactReport& c);

// Adds the forces f the bench applied over the step to r's per-surface friction forces (the
// engine's own contact is frictionless under these laws, so they are the friction of the step),
// and to its step mean where the adapter set one (add_bench_friction_mean, weight 1); each force
// with its moment about the centre of mass in `bench`, which the ledger books at the bench's point.
void add_bench_friction(ContactReport& r, const BenchFrictionForces& f);

// Adds weight * f to the step mean's per-surface friction forces, force by force: 1 where the
// bench's force acted over the whole step as it is, an integrator's weight where the engine
// applied it as a blend of several (Siconos' Moreau-Jean: theta and 1 - theta).
void add_bench_friction_mean(StepMeanForces& mean, const BenchFrictionForces& f, double weight);

// The engine's contacts r with the bench's friction f of the step added: the contacts of the
// step as the checks, the work and contact_forces() read them (add_bench_friction on a copy).
inline ContactReport with_bench_friction(ContactReport r, const BenchFrictionForces& f) {
  add_bench_friction(r, f);
  return r;
}

}  // namespace tippe
