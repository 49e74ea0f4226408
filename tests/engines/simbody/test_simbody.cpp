// The Simbody adapter's own physics: the Hertz contact's rest depth, the gliding law as Simbody's viscous friction, the accuracy knob, its settings.
#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>
#include <string>

#include "engines/core/registry.h"
#include "tests/support/fixtures.h"

namespace tippe {
namespace {

TEST(Simbody, RestsAtTheHertzDepthOfItsStiffness) {
  // At rest upright the Hertz force carries the weight: M g = (4/3) E_eff sqrt(R) x^(3/2) with
  // E_eff = E / 2^(3/2) (top and floor of the same material, combined in series as k^(2/3)), so
  // G sinks by x = (3 M g 2^(3/2) / (4 E sqrt(R)))^(2/3). A large dissipation damps the ringing
  // of the zero-depth start; the force law's stiffness part alone sets the depth. 1e-3 of x:
  // the ringing left after 3 time units (damping ratio 0.4 at c = 500) is far below it.
  Scene s = fixtures::dimensionless_scene();
  s.initial.tilt = 0.0;
  s.initial.spin = 0.0;
  const double E = 1e6;
  s.engines["simbody"]["stiffness"] = E;
  s.engines["simbody"]["dissipation"] = 500.0;
  auto sim = make_simulator("simbody", s);
  const double z0 = sim->state().p_WG.z();
  sim->advance_to(3.0);
  const double W = s.mass.mass * s.gravity, R = s.body.sphere_radius;
  const double x = std::pow(3 * W * std::pow(2.0, 1.5) / (4 * E * std::sqrt(R)), 2.0 / 3.0);
  EXPECT_NEAR(z0 - sim->state().p_WG.z(), x, 1e-3 * x);
  EXPECT_NEAR(sim->observe().normal_force, W, 1e-3 * W);
}

TEST(Simbody, GlidingLawIsSimbodysViscousFriction) {
  // A uniform ball launched sliding without spin under F_t = -mu F_n v_C: with F_n = M g,
  // dv_G/dt = -mu g v_C and R dw/dt = -mu g v_C M R^2 / A, so the slip v_C = v_G - w R decays as
  // exp(-mu g (1 + M R^2 / A) t) = exp(-3.5 mu g t). Mapped onto Simbody's viscous coefficient
  // (static and dynamic 0), its own contact force gives that law. 2e-3 relative: the Hertz
  // ringing of the normal force (damped here by c = 500) and the creep of the friction's
  // regularization (none: uv has no transition).
  Scene s = fixtures::dimensionless_scene();
  s.contact.friction = FrictionLaw::Gliding;
  s.contact.mu = 1.0;
  s.contact.stem = false;
  s.mass = {1.0, 0.0, 0.4, 0.4};
  s.initial.tilt = 0.0;
  s.initial.spin = 0.0;
  s.initial.velocity_given = true;
  s.initial.velocity = {1.0, 0.0};
  s.engines["simbody"]["dissipation"] = 500.0;
  auto sim = make_simulator("simbody", s);
  const double t = 0.4;
  sim->advance_to(t);
  const double expected = std::exp(-3.5 * s.contact.mu * s.gravity * t);
  EXPECT_NEAR(sim->observe().slip_speed, expected, 2e-3 * expected);
}

// The precession of a torque-free top after 2 time units against Euler's closed form, at a
// given accuracy (the conformance suite's check, here as a function of the knob).
double precession_error(double accuracy) {
  Scene s = fixtures::dimensionless_scene();
  s.gravity = 0.0;
  s.contact.flight = true;
  s.initial.height = 1.0;
  s.initial.tilt = 0.3;
  s.initial.omega_given = true;
  s.initial.omega_B = {1.0, 0.0, 5.0};
  s.engines["simbody"]["accuracy"] = accuracy;
  auto sim = make_simulator("simbody", s);
  sim->advance_to(2.0);
  const double A = s.mass.inertia_transverse, C = s.mass.inertia_axial, lambda = (C - A) * 5.0 / A;
  const Vec3 expected(std::cos(lambda * 2.0), std::sin(lambda * 2.0), 5.0);
  return (sim->state().w_B - expected).norm() / expected.norm();
}

TEST(Simbody, TighterAccuracyBuysPrecision) {
  // Away from contact the only error is the integrator's: 100x tighter accuracy must cut the
  // error of a contact-free motion by at least 10x (RK-Merson, order 4: about 40x per 100x).
  const double loose = precession_error(1e-4), tight = precession_error(1e-6);
  EXPECT_GT(loose, 0.0);
  EXPECT_LT(tight, 0.1 * loose) << "accuracy 1e-4: " << loose << ", 1e-6: " << tight;
}

TEST(Simbody, RejectsStaticFrictionBelowDynamic) {
  Scene s = fixtures::dimensionless_scene();
  s.engines["simbody"]["static_friction"] = 0.2;  // dynamic from the scene: mu = 0.3
  try {
    make_simulator("simbody", s);
    FAIL() << "accepted static friction below dynamic";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("engines.simbody.static_friction"), std::string::npos) << e.what();
  }
  s.engines["simbody"].clear();
  s.engines["simbody"]["integrator"] = std::string("rk45");
  EXPECT_THROW(make_simulator("simbody", s), std::invalid_argument);
}

TEST(Simbody, DrillingIsNotedAsNotModelled) {
  Scene s = fixtures::dimensionless_scene();
  s.contact.drilling = 0.01;
  auto sim = make_simulator("simbody", s);
  bool noted = false;
  for (const std::string& n : sim->notes()) noted = noted || n.find("drilling friction NOT modelled") != std::string::npos;
  EXPECT_TRUE(noted);
}

}  // namespace
}  // namespace tippe
