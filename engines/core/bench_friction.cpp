// The viscous and gliding laws the bench applies at each contact an engine reports.
#include "engines/core/bench_friction.h"

#include <algorithm>

namespace tippe {

double native_mu(const ContactSpec& contact, double rolling_mu) {
  switch (contact.friction) {
    case FrictionLaw::Coulomb: return contact.mu;
    case FrictionLaw::Rolling: return rolling_mu;
    case FrictionLaw::Viscous:
    case FrictionLaw::Gliding:
    case FrictionLaw::None: return 0.0;
  }
  return 0.0;
}

BenchFrictionForces bench_friction_forces(const BodyModel& body, const ContactSpec& contact, const BodyState& x,
                                          const ContactReport& c) {
  BenchFrictionForces out;
  if (!bench_applies_friction(contact.friction)) return out;
  const Vec3 w_W = x.q_WB * x.w_B;
  for (const Surface s : {Surface::Ball, Surface::Stem}) {
    if (!(s == Surface::Ball ? c.ball : c.stem && body.stem)) continue;
    const Vec3 R_C = contact_offset_W(body, x.q_WB, s);
    Vec3 v_C = x.v_WG + w_W.cross(R_C);
    v_C.z() = 0.0;
    if (contact.friction == FrictionLaw::Viscous) {
      out.f_W[out.n] = -contact.k * v_C;
    } else {
      const double f_n = std::max(0.0, s == Surface::Ball ? c.normal_force_ball : c.normal_force_stem);
      out.f_W[out.n] = -contact.mu * f_n * v_C;
    }
    out.r_GC_W[out.n] = R_C;
    out.stem[out.n] = s == Surface::Stem;
    ++out.n;
  }
  return out;
}

namespace {

// Adds weight times f's force i, and its moment about the centre of mass at the force's lever
// arm, to b: the bench's part of the friction, which the ledger books at the bench's point.
void add_bench_wrench(BenchWrench& b, const BenchFrictionForces& f, int i, double weight) {
  const Vec3 force = weight * f.f_W[i];
  (f.stem[i] ? b.f_stem_W : b.f_ball_W) += force;
  (f.stem[i] ? b.m_stem_W : b.m_ball_W) += f.r_GC_W[i].cross(force);
}

}  // namespace

void add_bench_friction(ContactReport& r, const BenchFrictionForces& f) {
  for (int i = 0; i < f.n; ++i) {
    (f.stem[i] ? r.friction_stem_W : r.friction_ball_W) += f.f_W[i];
    add_bench_wrench(r.bench, f, i, 1.0);
  }
  // The bench's force acts over the whole step: in the step's mean as it is (1 * f is f exactly).
  if (r.step_mean.set) add_bench_friction_mean(r.step_mean, f, 1.0);
}

void add_bench_friction_mean(StepMeanForces& mean, const BenchFrictionForces& f, double weight) {
  for (int i = 0; i < f.n; ++i) {
    (f.stem[i] ? mean.friction_stem_W : mean.friction_ball_W) += weight * f.f_W[i];
    add_bench_wrench(mean.bench, f, i, weight);
  }
}

}  // namespace tippe
