// An observation with only what a run's summary reads, for the tests of run records and of running a simulator.
#pragma once

#include "analytic/state.h"

namespace tippe::fixtures {

inline Observation sample(double t, Surface s, double J, double fn = 1.0) {
  Observation o;
  o.state.t = t;
  o.surface = s;
  o.jellett = J;
  o.normal_force = fn;
  o.energy = 10.0 - t;
  o.theta = 0.1 * t;
  return o;
}

}  // namespace tippe::fixtures
