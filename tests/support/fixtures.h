// The fixtures the test programs share: the dimensionless test top as a Scene and as scene-file text, bit-exact comparisons, paths.
#pragma once

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <functional>
#include <stdexcept>
#include <string>
#include <vector>

#include "analytic/reference_model.h"
#include "analytic/scene.h"
#include "engines/core/simulator.h"
#include "tests/support/files.h"
#include "tests/support/process.h"
#include "tests/support/records.h"

namespace tippe::fixtures {

// The source tree, the build tree and the `tippe` binary the tests run.
// `static`, one copy per program, and not `inline`: an inline variable's initialization is only
// partially ordered, and under clang with the precompiled header (the sanitized build) a test
// file's own constants built from these (`kSource + "/harness/sweeps/smoke.toml"`) were
// initialized first, from an empty string. The support headers' other string constants follow.
static const std::string kSourceDir = TIPPE_SOURCE_DIR;
static const std::string kTippeBinary = std::string(TIPPE_BINARY_DIR) + "/tippe";
static const std::string kScenesDir = std::string(TIPPE_SOURCE_DIR) + "/harness/scenes/";

// The source's dimensionless top (REFERENCE_VALUES.md): g = R = M = 1, r = 0.25, l = 1.2, h = 0.9,
// d = 0.3, A = 0.4, C = 0.45 given directly, tilt 0.1 rad, spin 5, 2 time units sampled every 0.01.
// `law` takes `coefficient` as its own (mu for coulomb and gliding, k for viscous; rolling and none
// have none): Coulomb mu = 0.3, the source's, by default. Every test of this body starts here.
inline Scene dimensionless_scene(FrictionLaw law = FrictionLaw::Coulomb, double coefficient = 0.3) {
  Scene s;
  s.name = "dimensionless";
  s.gravity = 1.0;
  s.body = {1.0, 0.25, 1.2, 0.9, 0.0, MassModel::Given};
  s.mass = {1.0, 0.3, 0.4, 0.45};
  s.contact.friction = law;
  if (law == FrictionLaw::Coulomb || law == FrictionLaw::Gliding) s.contact.mu = coefficient;
  if (law == FrictionLaw::Viscous) s.contact.k = coefficient;
  s.contact.stem = true;
  s.initial.tilt = 0.1;
  s.initial.spin = 5.0;
  s.run = {2.0, 0.01, 1e-10, 1e-12};
  return s;
}

// A uniform ball on the dimensionless scene's floor (the stem left out, I = 2/5 M R^2, G at the
// ball's centre), upright, launched sliding along x at v0 and spinning about the vertical at `spin`.
inline Scene sliding_ball(double v0 = 1.0, double spin = 0.0) {
  Scene s = dimensionless_scene();
  s.contact.stem = false;
  s.mass = {1.0, 0.0, 0.4, 0.4};
  s.initial.tilt = 0.0;
  s.initial.spin = spin;
  s.initial.velocity_given = true;
  s.initial.velocity = {v0, 0.0};
  return s;
}

// The same top as a scene file (given mass properties, so nothing depends on the
// mass-properties code): a valid file the input tests edit one key at a time.
inline const char* const kBase = R"(name = "base"
description = "test scene"
gravity = 1
[body]
sphere_radius = 1.0
stem_radius = 0.25
stem_length = 1.2
truncation_height = 0.9
mass = 1.0
com_offset = 0.3
inertia_transverse = 0.4
inertia_axial = 0.45
[contact]
friction = "viscous"
k = 1.0
[initial]
tilt = 0.1
spin = 5.0
velocity = [0.0, 0.0]
[run]
duration = 25.0
sample_interval = 0.01
rtol = 1e-10
atol = 1e-12
)";

// Replaces the one occurrence of `from` in `text` (the test fails if there is none).
inline std::string edit(const std::string& text, const std::string& from, const std::string& to) {
  const auto pos = text.find(from);
  EXPECT_NE(pos, std::string::npos) << "fixture text not found: " << from;
  if (pos == std::string::npos) return text;
  return text.substr(0, pos) + to + text.substr(pos + from.size());
}

inline bool bit_equal(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; }

// Two states equal to the last bit (determinism, round trips).
inline bool bit_equal(const BodyState& a, const BodyState& b) {
  bool eq = bit_equal(a.t, b.t);
  for (int i = 0; i < 3; ++i)
    eq = eq && bit_equal(a.p_WG[i], b.p_WG[i]) && bit_equal(a.v_WG[i], b.v_WG[i]) && bit_equal(a.w_B[i], b.w_B[i]);
  for (int i = 0; i < 4; ++i) eq = eq && bit_equal(a.q_WB.coeffs()[i], b.q_WB.coeffs()[i]);
  return eq;
}

// A simulator's setting as it lists it, or "<missing>".
inline std::string setting_value(const SettingsList& list, const std::string& key) {
  for (const auto& kv : list)
    if (kv.first == key) return kv.second;
  return "<missing>";
}

// Expects `call` (an engine's entry point, named `what` in the failure) to throw
// std::invalid_argument whose message names `want` (e.g. "engines.ode.timestep").
inline void expect_refusal_naming(const std::function<void()>& call, const std::string& what, const std::string& want) {
  try {
    call();
    ADD_FAILURE() << what << " accepted " << want;
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find(want), std::string::npos) << e.what();
  }
}

// Expects two reference runs' events to be the same: names in the same order, times within
// `tol` s (prints the largest difference).
inline void expect_same_events(const std::vector<ReferenceEvent>& a, const std::vector<ReferenceEvent>& b, double tol) {
  ASSERT_EQ(a.size(), b.size());
  double largest = 0.0;
  for (size_t i = 0; i < a.size(); ++i) largest = std::max(largest, std::abs(a[i].time - b[i].time));
  std::printf("%zu events, largest time difference between the methods %.3g s\n", a.size(), largest);
  for (size_t i = 0; i < a.size(); ++i) {
    EXPECT_EQ(a[i].name, b[i].name) << i;
    EXPECT_NEAR(a[i].time, b[i].time, tol) << a[i].name << " " << i;
  }
}

}  // namespace tippe::fixtures
