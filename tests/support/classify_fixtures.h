// The synthetic scene, run record and expectation the classification tests share (test_classify, test_energy_gain_rule).
#pragma once

#include <gtest/gtest.h>

#include <cmath>

#include "analytic/scene.h"
#include "harness/measure/classify.h"
#include "harness/records/records.h"
#include "tests/support/run_records.h"

namespace tippe {

// A viscous top: energy must not rise, J must hold.
inline Scene viscous_scene() {
  Scene s;
  s.name = "synthetic";
  s.body.sphere_radius = 1.0;
  s.contact.friction = FrictionLaw::Viscous;
  s.contact.k = 1.0;
  s.run.duration = 1.0;
  s.run.sample_interval = 0.1;
  return s;
}

inline RunRecord ok_run() { return fixtures::ok_record("fake"); }

inline void expect_ok(const RunClass& c) {
  EXPECT_EQ(c.kind, RunClassKind::Ok) << c.reason;
  EXPECT_TRUE(std::isnan(c.time));
  EXPECT_TRUE(c.reason.empty()) << c.reason;
}

}  // namespace tippe
