// The contact solve's closed form for one sliding viscous contact against its general solve: bit for bit, on random states, either contact, with and without drilling friction.
#include <gtest/gtest.h>

#include <cstring>
#include <ostream>
#include <random>
#include <string>

#include "analytic/contact_dynamics.h"
#include "harness/scene/resolve.h"

namespace tippe::test_contact_dynamics {
namespace {

Scene shipped(const std::string& name) { return load_scene(std::string(TIPPE_SOURCE_DIR) + "/harness/scenes/" + name + ".toml"); }

// Exact equality, as bits: the closed form must do the general solve's arithmetic, not a close
// approximation of it (the reference's trajectories must not move by a rounding).
bool same_bits(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; }

void expect_same(const Vec3& a, const Vec3& b, const char* what, int slot) {
  for (int i = 0; i < 3; ++i) EXPECT_TRUE(same_bits(a[i], b[i])) << what << "[" << slot << "](" << i << "): " << a[i] << " vs " << b[i];
}

void expect_same(const ContactForces& a, const ContactForces& b) {
  EXPECT_EQ(a.solvable, b.solvable);
  for (int s = 0; s < 2; ++s) {
    EXPECT_TRUE(same_bits(a.normal[s], b.normal[s])) << "normal[" << s << "]: " << a.normal[s] << " vs " << b.normal[s];
    EXPECT_TRUE(same_bits(a.drill_torque[s], b.drill_torque[s])) << "drill_torque[" << s << "]";
    EXPECT_TRUE(same_bits(a.graze_fraction[s], b.graze_fraction[s])) << "graze_fraction[" << s << "]";
    EXPECT_TRUE(same_bits(a.graze_lifted_accel[s], b.graze_lifted_accel[s])) << "graze_lifted_accel[" << s << "]";
    EXPECT_TRUE(same_bits(a.graze_loaded_accel[s], b.graze_loaded_accel[s])) << "graze_loaded_accel[" << s << "]";
    EXPECT_TRUE(same_bits(a.graze_fraction_raw[s], b.graze_fraction_raw[s])) << "graze_fraction_raw[" << s << "]";
    EXPECT_TRUE(same_bits(a.start_rate[s], b.start_rate[s])) << "start_rate[" << s << "]";
    expect_same(a.force_W[s], b.force_W[s], "force_W", s);
    expect_same(a.slip_W[s], b.slip_W[s], "slip_W", s);
    expect_same(a.start_dir[s], b.start_dir[s], "start_dir", s);
  }
}

// A state anywhere near the floor: any attitude (|q| a little off 1, as the integrator leaves
// it), velocities and spins of either sign up to the shipped scenes' scale.
StateVector random_state(std::mt19937_64& rng, const BodyModel& m) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  StateVector y{};
  y[0] = m.R * u(rng);
  y[1] = m.R * u(rng);
  y[2] = m.R * (1.0 + 0.5 * u(rng));
  for (int i = 3; i < 6; ++i) y[i] = 0.5 * u(rng);
  Quat q(u(rng), u(rng), u(rng), u(rng));
  q.normalize();
  const double scale = 1.0 + 1e-9 * u(rng);
  y[6] = scale * q.w(); y[7] = scale * q.x(); y[8] = scale * q.y(); y[9] = scale * q.z();
  for (int i = 10; i < 13; ++i) y[i] = 200.0 * u(rng);
  return y;
}

struct Case {
  const char* scene;
  double drilling;  // mu_d (0: no drilling friction)
};
void PrintTo(const Case& c, std::ostream* os) { *os << c.scene << " mu_d=" << c.drilling; }

class ViscousClosedForm : public ::testing::TestWithParam<Case> {};

TEST_P(ViscousClosedForm, EqualsTheGeneralSolveBitForBit) {
  Scene scene = shipped(GetParam().scene);
  ASSERT_EQ(scene.contact.friction, FrictionLaw::Viscous);
  scene.contact.drilling = GetParam().drilling;
  const BodyModel body = BodyModel::from_scene(scene);
  const ContactDynamics dyn(body, scene.contact);
  std::mt19937_64 rng(20261205);
  int compared = 0;
  for (int trial = 0; trial < 400; ++trial) {
    StateVector y = random_state(rng, body);
    if (trial % 50 == 0) y[12] = 0.0;  // no spin about the body axis: w_z of either sign or 0
    for (int s = 0; s < 2; ++s) {
      for (double drill_dir : {0.0, 1.0, -1.0}) {
        ContactMode mode;
        mode.slot[s].active = true;
        mode.slot[s].drill_dir = drill_dir;
        StateVector fast{}, general{};
        const ContactForces a = dyn.evaluate(y, mode, &fast), b = dyn.evaluate_general(y, mode, &general);
        SCOPED_TRACE("trial " + std::to_string(trial) + ", slot " + std::to_string(s) + ", drill_dir " + std::to_string(drill_dir));
        expect_same(a, b);
        for (int i = 0; i < 13; ++i) ASSERT_TRUE(same_bits(fast[i], general[i])) << "dydt[" << i << "]: " << fast[i] << " vs " << general[i];
        // Without a derivative asked for, the forces are the same.
        expect_same(dyn.evaluate(y, mode, nullptr), b);
        ++compared;
      }
    }
  }
  EXPECT_EQ(compared, 400 * 2 * 3);
}

// toy_viscous: a ball with a stem; rutstam_ball: the eccentric ball of the process benchmark.
INSTANTIATE_TEST_SUITE_P(Scenes, ViscousClosedForm,
                         ::testing::Values(Case{"toy_viscous", 0.0}, Case{"toy_viscous", 2e-4}, Case{"rutstam_ball", 0.0}),
                         [](const ::testing::TestParamInfo<Case>& info) {
                           return std::string(info.param.scene) + (info.param.drilling > 0 ? "_drilling" : "");
                         });

// The modes the closed form does not take (sticking, grazing, both contacts) go to the general
// solve: evaluate() and evaluate_general() are one computation there.
TEST(ViscousClosedForm, OtherModesAreTheGeneralSolve) {
  const Scene scene = shipped("toy_viscous");
  const BodyModel body = BodyModel::from_scene(scene);
  const ContactDynamics dyn(body, scene.contact);
  std::mt19937_64 rng(7);
  for (int trial = 0; trial < 50; ++trial) {
    const StateVector y = random_state(rng, body);
    for (int variant = 0; variant < 3; ++variant) {
      ContactMode mode;
      mode.slot[0].active = true;
      if (variant == 0) mode.slot[0].stick = true;
      if (variant == 1) mode.slot[1].active = true;
      if (variant == 2) mode.slot[0].drill_stick = true;
      StateVector fast{}, general{};
      expect_same(dyn.evaluate(y, mode, &fast), dyn.evaluate_general(y, mode, &general));
      for (int i = 0; i < 13; ++i) EXPECT_TRUE(same_bits(fast[i], general[i]));
    }
  }
}

}  // namespace
}  // namespace tippe::test_contact_dynamics
