// The decoupled Coulomb law through stick -> slip starts, drilling stick and cascade holds: the energy ledger closes and friction never adds energy.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "analytic/initial_state.h"
#include "analytic/reference_model.h"
#include "harness/io/scene_io.h"
#include "harness/scene/resolve.h"
#include "tests/support/fixtures.h"
#include "tests/support/reference_runs.h"

namespace tippe::test_reference_slip_start {
namespace {

Scene shipped(const std::string& name) { return load_scene(std::string(TIPPE_SOURCE_DIR) + "/harness/scenes/" + name + ".toml"); }

using fixtures::count;
using fixtures::decoupled_slip_start;
using fixtures::Ledger;
using fixtures::run_ledger;

// The Leine-Glocker top at mu = 0.02 from a tilt of 1 rad sticks and slips again three times
// (7.44 s to 14.6 s). Before the slip start zeroed the stuck drift, the drift of the third slip
// start lay against the stuck forces' direction: the continued law flipped the force to the
// drift's side, the force drove the slip, and E rose to 3.4 E0 by 21.9 s (friction work -2.40 E0,
// the ledger closing all along), where the floor let go. Bounds: the ledger to 1e-9 E0 as the
// other ledger tests ask (rtol 1e-10 over ~30 s and a few events); the friction work may fall
// only by the work of a stuck contact's force on its tolerance-sized drift, either sign
// (measured 3e-13 E0), bounded by 1e-10 E0 (rtol times E0); E may rise between samples only
// by the tolerance-sized drift corrections at restarts, likewise 1e-9 E0. Both explicit
// methods: before a starting slip's direction was solved (ContactSlot::slip_start) dopri5
// stalled 6 ms after the first slip start ("no progress" at 7.46335 s, last step 5.7e-11 s).
// Their events agree to 1e-6 s up to the inversion (measured 1.2e-9 s); the stick after it,
// where the slip dies out slowly, is ill-conditioned (14.6405 s against 14.6411 s) and left out.
TEST(ReferenceSlipStart, DecoupledSlipStartNeverDrivesTheSlip) {
  const auto bs = decoupled_slip_start("bulirsch_stoer");
  const auto dp = decoupled_slip_start("dopri5");
  fixtures::expect_same_events(bs, dp, 1e-6);
}

// The decoupled drilling torque -mu_d F_n sign(w_z) jumps where the spin about the vertical
// passes 0. Without a continuation through that zero the jump fell inside a Bulirsch-Stoer
// step, whose dense output then missed its own starting state by 3.5e-2 rad/s in w_z; the
// spin restarted there at the drill_stick event and E rose by 3.5e-8 E0 (7.4e-7 E0 before the
// slip start's fix). Leine-Glocker top with mu_d = 1e-4 m at mu = 0.002: stick, slip start
// (18.65 s), drilling stick (21.23 s), stick. Bounds as above; both methods (dopri5 stalled
// at the slip start before, 18.64989 s).
TEST(ReferenceSlipStart, DecoupledDrillingStickWithoutEnergyGain) {
  for (const char* method : {"bulirsch_stoer", "dopri5"}) {
    Scene s = shipped("leine_glocker_drilling");
    s.contact.mu = 0.002;
    s.run.method = method;
    const Ledger l = run_ledger(s);
    std::printf("leine_glocker_drilling mu 0.002, %s: ledger %.3g E0, friction work drop %.3g E0, E rise %.3g E0\n", method, l.worst,
                l.worst_drop, l.worst_rise);
    ASSERT_EQ(l.status, ReferenceStatus::Ok) << method << ": " << l.detail;
    EXPECT_EQ(count(l.events, "drill_stick"), 1);
    EXPECT_GE(count(l.events, "slip"), 1);
    EXPECT_LT(l.worst, 1e-9);
    EXPECT_LT(l.worst_drop, 1e-10);
    EXPECT_LT(l.worst_rise, 1e-9);
  }
}

// A slip that ends without meeting zero head on: leine_glocker_drilling at mu = 0.02 slips at
// 15.19 s and its slip, grown to 4.5e-6 m/s, shrinks again while its direction turns. Before a
// small slip's direction was solved too (below slip_eps / 2), both methods stalled there
// (15.2128 s bulirsch_stoer, 15.2123 s dopri5, steps of 2e-9 and 4e-11 s). Now 6 sticks and 6
// slips by 20 s, the ledger as above.
TEST(ReferenceSlipStart, ShrinkingSlipEndsWithoutStalling) {
  for (const char* method : {"bulirsch_stoer", "dopri5"}) {
    Scene s = shipped("leine_glocker_drilling");
    s.contact.mu = 0.02;
    s.run.method = method;
    s.run.duration = 20.0;
    const Ledger l = run_ledger(s);
    std::printf("leine_glocker_drilling mu 0.02, %s: %d sticks, %d slips, ledger %.3g E0\n", method, count(l.events, "stick"),
                count(l.events, "slip"), l.worst);
    ASSERT_EQ(l.status, ReferenceStatus::Ok) << method << ": " << l.detail;
    EXPECT_GE(count(l.events, "stick"), 2);
    EXPECT_LT(l.worst, 1e-9);
    EXPECT_LT(l.worst_drop, 1e-10);
  }
}

// A cascade closed by a hold under Coulomb friction (the shipped hold scenes are viscous, whose
// impacts carry no friction impulse): tilt_near_pi with Coulomb mu = 0.2 (ball impact at
// 0.3717 s held with the stem). The hold's projection removes energy only (value >= 0 to the
// round-off of two energies), and the ledger closes across it.
TEST(ReferenceSlipStart, CoulombHoldClosesTheLedger) {
  Scene s = shipped("extremes/tilt_near_pi");
  s.contact.friction = FrictionLaw::Coulomb;
  s.contact.mu = 0.2;
  const Ledger l = run_ledger(s);
  const double e0 = energy(BodyModel::from_scene(s), scene_initial_state(s));
  std::printf("tilt_near_pi coulomb 0.2: %d holds, %d impacts, ledger %.3g E0\n", count(l.events, "hold"), count(l.events, "impact"), l.worst);
  ASSERT_EQ(l.status, ReferenceStatus::Ok) << l.detail;
  EXPECT_GE(count(l.events, "hold"), 1);
  EXPECT_LT(l.worst, 1e-9);
  for (const auto& e : l.events)
    if (e.name == "impact" || e.name == "hold" || e.name == "projection") {
      EXPECT_GE(e.value, -4e-15 * e0) << e.name << " at " << e.time;
    }
}

}  // namespace
}  // namespace tippe
