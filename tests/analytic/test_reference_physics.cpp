// Physics of the analytic reference: invariants, dissipation, limits and published cases.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <optional>

#include "analytic/initial_state.h"
#include "analytic/reference_model.h"
#include "tests/support/fixtures.h"
#include "analytic/contact_dynamics.h"

namespace tippe::test_reference_physics {
namespace {

// The source's dimensionless top (REFERENCE_VALUES.md): g = 1, M = 1, A = 0.4, C = 0.45, d = 0.3.
Scene seed_top(FrictionLaw law, double coeff, double spin, double duration, double rtol = 1e-10) {
  Scene s;
  s.name = "seed";
  s.gravity = 1.0;
  s.body = {1.0, 0.25, 1.2, 0.9, 0.0, MassModel::Given};
  s.mass = {1.0, 0.3, 0.4, 0.45};
  s.contact.friction = law;
  s.contact.k = law == FrictionLaw::Viscous ? coeff : 0.0;
  s.contact.mu = law == FrictionLaw::Coulomb ? coeff : 0.0;
  s.initial.tilt = 0.1;
  s.initial.spin = spin;
  s.run = {duration, 0.01, rtol, rtol * 1e-2};
  return s;
}

// Leine and Glocker (2003), top of C. Friedl: m = 6 g, R = 15 mm, d = 3 mm, tip radius 5 mm
// centred 16 mm from G (l = 13 mm from the ball centre), A = 8e-7, C = 7e-7 kg m^2.
Scene leine_glocker(double A, double drilling, double duration) {
  Scene s;
  s.name = "leine_glocker";
  s.gravity = 9.81;
  s.body = {0.015, 0.005, 0.013, 0.012, 0.0, MassModel::Given};
  s.mass = {0.006, 0.003, A, 7e-7};
  s.contact.friction = FrictionLaw::Coulomb;
  s.contact.mu = 0.3;
  s.contact.drilling = drilling;
  s.initial.tilt = 0.1;
  s.initial.spin = 180.0;
  s.run = {duration, 1e-3, 1e-10, 1e-14};
  return s;
}

std::optional<double> first_event(const ReferenceModel& m, const std::string& name) {
  for (const auto& e : m.events())
    if (e.name == name) return e.time;
  return std::nullopt;
}

struct Trace {
  double max_energy_rise = 0;   // largest E(t_k) - E(t_{k-1}), relative to E0
  double max_power = -1e300;    // largest F . v_C over the samples (must be <= 0)
  double jellett_drift = 0;     // largest relative change of J within one surface phase
  double max_quat_error = 0;    // largest | |q| - 1 | of the observed attitude
  double max_quat_drift = 0;    // largest | |q| - 1 | of the integrated quaternion at a step end
  double max_tilt = 0;
};

// Samples a run every dt and measures the invariants.
Trace trace(ReferenceModel& m, double duration, double dt) {
  Trace tr;
  const BodyModel& b = m.body();
  double e_prev = energy(b, m.state());
  const double e0 = e_prev;
  Surface phase = m.contact_surface();
  size_t n_events = m.events().size();
  double j0 = jellett(b, m.state(), phase == Surface::Stem ? Surface::Stem : Surface::Ball);
  for (double t = dt; t <= duration + 1e-12 && m.status() == ReferenceStatus::Ok; t += dt) {
    m.advance_to(t);
    const BodyState x = m.state();
    const double e = energy(b, x);
    tr.max_energy_rise = std::max(tr.max_energy_rise, (e - e_prev) / e0);
    e_prev = e;
    const ContactForces f = m.forces();
    double power = 0;
    for (int s = 0; s < 2; ++s) power += f.force_W[s].dot(f.slip_W[s]) + f.drill_torque[s] * (x.q_WB * x.w_B).z();
    tr.max_power = std::max(tr.max_power, power);
    tr.max_quat_error = std::max(tr.max_quat_error, std::abs(x.q_WB.norm() - 1.0));
    tr.max_quat_drift = std::max(tr.max_quat_drift, std::abs(m.raw_quaternion_norm() - 1.0));
    tr.max_tilt = std::max(tr.max_tilt, tilt(x.q_WB));
    const Surface s = m.contact_surface();
    const Surface which = s == Surface::Stem ? Surface::Stem : Surface::Ball;
    const double j = jellett(b, x, which);
    // A new phase starts at every surface change or impact; J is compared within a phase
    // on a single surface only (two-contact phases have two contact torques).
    bool new_phase = s != phase;
    for (size_t k = n_events; k < m.events().size(); ++k)
      if (m.events()[k].name == "impact" || m.events()[k].name == "switch") new_phase = true;
    n_events = m.events().size();
    if (new_phase) {
      phase = s;
      j0 = j;
    } else if (s == Surface::Ball || s == Surface::Stem) {
      tr.jellett_drift = std::max(tr.jellett_drift, std::abs(j - j0) / std::max(std::abs(j0), 1e-300));
    }
  }
  return tr;
}

TEST(ReferencePhysics, ViscousDissipatesAndKeepsJellettOnEachSurface) {
  Scene s = seed_top(FrictionLaw::Viscous, 1.0, 5.0, 40.0, 1e-11);
  ReferenceModel m(s);
  const Trace tr = trace(m, 40.0, 0.01);
  std::printf("viscous: max rise %.3g, max power %.3g, J drift %.3g, |q| err %.3g, step drift %.3g\n", tr.max_energy_rise,
              tr.max_power, tr.jellett_drift, tr.max_quat_error, tr.max_quat_drift);
  EXPECT_TRUE(first_event(m, "stem_contact"));  // it reaches the stem, so both surfaces are checked
  // dE/dt = F_t . v_C <= 0: exactly <= 0 pointwise (round-off allowance 1e-12 of |F||v|).
  EXPECT_LE(tr.max_power, 1e-12);
  // E never rises between samples beyond the integration error (rtol 1e-11 -> 1e-9 of E0).
  EXPECT_LE(tr.max_energy_rise, 1e-9);
  // Jellett's integral holds for any friction law on one surface (NOTES.md), to 1e-9 as asked.
  EXPECT_LT(tr.jellett_drift, 1e-9);
  // The attitude is a unit quaternion to 1e-12 (renormalized between steps and when observed).
  EXPECT_LT(tr.max_quat_error, 1e-12);
}

TEST(ReferencePhysics, CoulombDissipatesAndKeepsJellett) {
  Scene s = seed_top(FrictionLaw::Coulomb, 0.3, 5.0, 40.0, 1e-11);
  ReferenceModel m(s);
  const Trace tr = trace(m, 40.0, 0.01);
  std::printf("coulomb: max rise %.3g, max power %.3g, J drift %.3g, |q| err %.3g, inversion %s\n", tr.max_energy_rise,
              tr.max_power, tr.jellett_drift, tr.max_quat_error, first_event(m, "inversion") ? "yes" : "no");
  EXPECT_LE(tr.max_power, 1e-12);
  EXPECT_LE(tr.max_energy_rise, 1e-9);
  EXPECT_LT(tr.jellett_drift, 1e-9);
  EXPECT_LT(tr.max_quat_error, 1e-12);
}

TEST(ReferencePhysics, DrillingFrictionBreaksJellett) {
  // Drilling friction applies a torque about the vertical through C: L . R_C changes at the
  // rate -mu_d F_n sign(w_z) (e_z . R_C) = mu_d F_n sign(w_z) z_G, so J must drift.
  Scene s = seed_top(FrictionLaw::Coulomb, 0.3, 5.0, 5.0, 1e-11);
  s.contact.drilling = 0.05;
  ReferenceModel m(s);
  const Trace tr = trace(m, 5.0, 0.01);
  std::printf("drilling: J drift %.3g, max power %.3g\n", tr.jellett_drift, tr.max_power);
  EXPECT_GT(tr.jellett_drift, 1e-3);
  EXPECT_LE(tr.max_power, 1e-12);
}

TEST(ReferencePhysics, QuaternionStaysUnitOverLongRolling) {
  for (const char* method : {"bulirsch_stoer", "dopri5"}) {
    Scene s = seed_top(FrictionLaw::Rolling, 0.0, 20.0, 200.0, 1e-11);
    s.run.method = method;
    ReferenceModel m(s);
    const Trace tr = trace(m, 200.0, 0.5);
    std::printf("%s: |q| error %.3g, largest drift within one step %.3g\n", method, tr.max_quat_error, tr.max_quat_drift);
    EXPECT_LT(tr.max_quat_error, 1e-12) << method;
    // The integrated |q| drifts by at most a step's local error (bounded by the tolerance,
    // 10 rtol with the extrapolation method's long steps): renormalizing between steps keeps
    // it from accumulating over the ~640 spin periods of this run.
    EXPECT_LT(tr.max_quat_drift, 10 * s.run.rtol) << method;
  }
}

TEST(ReferencePhysics, VerticalSpinStaysVertical) {
  for (FrictionLaw law : {FrictionLaw::Coulomb, FrictionLaw::Viscous, FrictionLaw::Rolling, FrictionLaw::None}) {
    Scene s = seed_top(law, 0.3, 5.0, 20.0);
    s.initial.tilt = 0.0;
    ReferenceModel m(s);
    const Trace tr = trace(m, 20.0, 0.1);
    // The upright spinning top is an equilibrium: every force is vertical and the slip is
    // zero, so the tilt stays zero to round-off.
    EXPECT_LT(tr.max_tilt, 1e-12) << to_string(law);
    EXPECT_NEAR(m.state().w_B.z(), 5.0, 1e-12) << to_string(law);
  }
}

TEST(ReferencePhysics, ViscousTendsToRollingAsKGrows) {
  // Same start as the rolling run (v_G = R_C x omega), so only the law differs.
  Scene roll = seed_top(FrictionLaw::Rolling, 0.0, 20.0, 10.0);
  const BodyState x0 = scene_initial_state(roll);
  ReferenceModel ref(roll);
  std::vector<double> ref_tilt;
  for (int k = 1; k <= 100; ++k) {
    ref.advance_to(0.1 * k);
    ref_tilt.push_back(tilt(ref.state().q_WB));
  }
  double previous = 1e300;
  // From k = 10 up (at k = 1 the slip is so weak that the top hardly tilts in 10 time units,
  // so its tilt stays close to the rolling one for another reason).
  for (double k : {10.0, 100.0, 1000.0, 10000.0}) {
    Scene s = seed_top(FrictionLaw::Viscous, k, 20.0, 10.0);
    s.initial.velocity_given = true;
    s.initial.velocity = {x0.v_WG.x(), x0.v_WG.y()};
    ReferenceModel m(s);
    double worst = 0;
    for (int i = 1; i <= 100; ++i) {
      m.advance_to(0.1 * i);
      worst = std::max(worst, std::abs(tilt(m.state().q_WB) - ref_tilt[i - 1]));
    }
    std::printf("k = %6g: max |theta - theta_rolling| = %.3g rad (steps %lld)\n", k, worst, m.steps());
    EXPECT_LT(worst, previous) << "k = " << k;
    previous = worst;
  }
  // At k = 1e4 the slip relaxes in M/k = 1e-4 time units: the tilt follows rolling closely.
  EXPECT_LT(previous, 1e-4);
}

TEST(ReferencePhysics, InvertsUnderViscousNeverUnderRolling) {
  ReferenceModel viscous(seed_top(FrictionLaw::Viscous, 1.0, 5.0, 25.0));
  viscous.advance_to(25.0);
  EXPECT_TRUE(first_event(viscous, "inversion"));
  ReferenceModel rolling(seed_top(FrictionLaw::Rolling, 0.0, 5.0, 100.0));
  rolling.advance_to(100.0);
  EXPECT_FALSE(first_event(rolling, "inversion"));
}

TEST(ReferencePhysics, TopOutsideTheInversionWindowDoesNotInvert) {
  const BodyModel b = BodyModel::from_scene(seed_top(FrictionLaw::Viscous, 1.0, 5.0, 1.0));
  const double switch_tilt = std::acos(b.switch_cos);
  // A/C = 0.6/0.45 = 1.33 > 1 + alpha = 1.3: the top rises to an intermediate tilted state
  // (it does pass 90 deg, at about 115 deg) but never turns over onto its stem.
  {
    Scene s = seed_top(FrictionLaw::Viscous, 1.0, 5.0, 300.0);
    s.mass.inertia_transverse = 0.6;
    ReferenceModel m(s);
    const Trace tr = trace(m, 300.0, 0.1);
    std::printf("A/C = 1.33: max tilt %.2f deg, final %.2f deg\n", tr.max_tilt * 180 / M_PI, tilt(m.state().q_WB) * 180 / M_PI);
    EXPECT_FALSE(first_event(m, "stem_contact"));
    EXPECT_LT(tr.max_tilt, switch_tilt);
  }
  // A/C = 0.3/0.45 = 0.67 < 1 - alpha = 0.7: the upright spin is stable, the tilt decays.
  {
    Scene s = seed_top(FrictionLaw::Viscous, 1.0, 5.0, 300.0);
    s.mass.inertia_transverse = 0.3;
    ReferenceModel m(s);
    m.advance_to(300.0);
    EXPECT_FALSE(first_event(m, "inversion"));
    EXPECT_LT(tilt(m.state().q_WB), s.initial.tilt);
  }
}

TEST(ReferencePhysics, BareEccentricBallFinalSpin) {
  // Rutstam 2012: m = 0.02 kg, R = 0.02 m, alpha = 0.3, A = 131/350 m R^2, C = 2/5 m R^2,
  // theta0 = 0.1, spin 155 rad/s, gliding friction ~ viscous k = 0.0589 N s/m, no stem.
  Scene s;
  s.name = "rutstam";
  s.gravity = 9.81;
  const double m = 0.02, R = 0.02;
  s.body = {R, 0.0, 0.0, R, 0.0, MassModel::Given};
  s.mass = {m, 0.3 * R, 131.0 / 350.0 * m * R * R, 0.4 * m * R * R};
  s.contact.friction = FrictionLaw::Viscous;
  s.contact.k = 0.0589;
  s.contact.stem = false;
  s.initial.tilt = 0.1;
  s.initial.spin = 155.0;
  s.run = {20.0, 0.01, 1e-10, 1e-14};
  ReferenceModel model(s);
  model.advance_to(20.0);
  const BodyState x = model.state();
  const double w_vertical = std::abs((x.q_WB * x.w_B).z());
  // Jellett: J0 = C w0 (d - R cos theta0) upright, J = -C w (R + d) upside down, so
  // w = w0 (cos theta0 - alpha) / (1 + alpha); Rutstam's w0 (1 - alpha)/(1 + alpha) is its
  // theta0 -> 0 limit (0.7 % higher at theta0 = 0.1).
  const double expected = 155.0 * (std::cos(0.1) - 0.3) / (1 + 0.3);
  const double rutstam = 155.0 * (1 - 0.3) / (1 + 0.3);
  std::printf("rutstam: status %d, tilt %.4f rad, |w_z| = %.6f, Jellett %.6f, omega0 (1-a)/(1+a) = %.4f, inversion at %.4f\n",
              static_cast<int>(model.status()), tilt(x.q_WB), w_vertical, expected, rutstam,
              first_event(model, "inversion").value_or(-1));
  ASSERT_EQ(model.status(), ReferenceStatus::Ok);
  EXPECT_GT(tilt(x.q_WB), M_PI - 0.05);
  // After 20 s the residual tilt is ~1e-4 rad: its cosine differs from 1 by ~1e-8.
  EXPECT_NEAR(w_vertical, expected, 1e-6 * expected);
  EXPECT_NEAR(w_vertical, rutstam, 0.01 * rutstam);
}

TEST(ReferencePhysics, ToleranceLadderConverges) {
  std::vector<double> inv, stem;
  for (double rtol : {1e-8, 1e-10, 1e-12}) {
    ReferenceModel m(seed_top(FrictionLaw::Viscous, 1.0, 5.0, 21.0, rtol));
    m.advance_to(21.0);
    inv.push_back(first_event(m, "inversion").value_or(NAN));
    stem.push_back(first_event(m, "stem_contact").value_or(NAN));
    std::printf("rtol %g: inversion %.12f stem %.12f steps %lld\n", rtol, inv.back(), stem.back(), m.steps());
  }
  // Each tolerance promises about -log10(rtol) digits of the event times, with a factor 100
  // for the growth of the global error over ~20 time units of a tilting instability.
  EXPECT_NEAR(inv[0], inv[2], 100 * 1e-8 * inv[2]);
  EXPECT_NEAR(inv[1], inv[2], 100 * 1e-10 * inv[2]);
  EXPECT_NEAR(stem[0], stem[2], 100 * 1e-8 * stem[2]);
  EXPECT_NEAR(stem[1], stem[2], 100 * 1e-10 * stem[2]);
}

TEST(ReferencePhysics, LeineGlockerTop) {
  // Regime of the published top under a point contact. Leine and Glocker report the stem
  // touching at about 1.5 s with a contact patch that couples friction and drilling. With
  // Coulomb friction at a point the slip dies out: the top rolls, conserves its energy up to
  // drilling losses, and stops inverting. The slip history is the evidence.
  for (double drilling : {0.0, 1e-4}) {
    ReferenceModel m(leine_glocker(8e-7, drilling, 4.0));
    double max_slip = 0, final_slip = 0;
    for (int k = 1; k <= 400; ++k) {
      m.advance_to(0.01 * k);
      if (m.status() != ReferenceStatus::Ok) break;
      final_slip = m.forces().slip_W[m.contact_surface() == Surface::Stem ? 1 : 0].norm();
      max_slip = std::max(max_slip, final_slip);
    }
    const auto stick = first_event(m, "stick");
    std::printf("leine-glocker drilling %g: status %d, inversion %.4f, stem %.4f, stick %.4f, slip max %.3g final %.3g\n",
                drilling, static_cast<int>(m.status()), first_event(m, "inversion").value_or(-1),
                first_event(m, "stem_contact").value_or(-1), stick.value_or(-1), max_slip, final_slip);
    EXPECT_EQ(m.status(), ReferenceStatus::Ok);
    // Initial slip w0 R sin(theta0) = 0.27 m/s; a sliding ball stops slipping after about
    // 2 v0 / (7 mu g) = 0.026 s. The top's contact stops slipping on the same time scale.
    ASSERT_TRUE(stick);
    EXPECT_LT(*stick, 0.2);
    if (!first_event(m, "inversion")) {
      EXPECT_LT(final_slip, 1e-6 * max_slip);
    }
  }
  ReferenceModel twin(leine_glocker(9e-7, 0.0, 4.0));
  twin.advance_to(4.0);
  // A/C = 9/7 = 1.29 > 1 + alpha = 1.2: the twin cannot turn over.
  EXPECT_FALSE(first_event(twin, "stem_contact"));
}

// ---- The reference's right-hand side at t = 0, against hand-derived values -------------------------

struct Rhs {
  StateVector dydt;
  ContactForces f;
};

Rhs reference_rhs(const Scene& s, const BodyState& x, bool stick) {
  const ContactDynamics dyn(BodyModel::from_scene(s), s.contact);
  ContactMode mode;
  mode.slot[0].active = true;
  mode.slot[0].stick = stick;
  Rhs r;
  r.f = dyn.evaluate(pack(x), mode, &r.dydt);
  return r;
}

TEST(ReferenceRightHandSide, UprightAtRestHasZeroAccelerationAndWeightOnTheBall) {
  Scene s = fixtures::dimensionless_scene();
  s.initial.tilt = 0.0;
  s.initial.spin = 0.0;
  const BodyState x = scene_initial_state(s);
  const Rhs r = reference_rhs(s, x, true);
  // State order: p (0-2), v (3-5), q (6-9), w (10-12). At rest every derivative is 0 and the
  // floor carries the weight: F_n = M g. Round-off of one linear solve: 1e-14.
  for (int i = 0; i < 13; ++i) EXPECT_NEAR(r.dydt[static_cast<size_t>(i)], 0.0, 1e-14) << "component " << i;
  EXPECT_NEAR(r.f.normal[0], s.mass.mass * s.gravity, 1e-14);
}

TEST(ReferenceRightHandSide, SpinningUprightTopOnlyTurns) {
  // w_B = n e_Z about the vertical: the contact lies on the axis, below G, so v_C = w x R_C = 0,
  // no friction; w x I w = 0 for w along a principal axis. Hence dv/dt = 0, dw/dt = 0,
  // F_n = M g, and dq/dt = q (0, w_B) / 2 = (0, 0, 0, n / 2) for q = 1. With zero slip the
  // Coulomb contact sticks (the mode the reference settles into at this state).
  Scene s = fixtures::dimensionless_scene();
  s.initial.tilt = 0.0;
  const double n = s.initial.spin;
  const BodyState x = scene_initial_state(s);
  const Rhs r = reference_rhs(s, x, true);
  const double expected[13] = {0, 0, 0, 0, 0, 0, 0, 0, 0, n / 2, 0, 0, 0};
  for (int i = 0; i < 13; ++i) EXPECT_NEAR(r.dydt[static_cast<size_t>(i)], expected[i], 1e-14) << "component " << i;
  EXPECT_NEAR(r.f.normal[0], s.mass.mass * s.gravity, 1e-14);
  EXPECT_NEAR(r.f.slip_W[0].norm(), 0.0, 1e-15);
}

TEST(ReferenceRightHandSide, TiltedSpinningTopSlidesAgainstItsSlip) {
  // Tilt theta about the lab x axis: e_Z = (0, -sin theta, cos theta). With w = n e_Z and
  // v_G = 0, v_C = w x R_C with R_C = z_O e_Z - R e_z: v_C = -n R e_Z x e_z = (n R sin theta, 0, 0).
  // Coulomb sliding: F_t = -mu F_n v_C / |v_C|, so dv/dt = (-mu F_n / M, 0, F_n / M - g), and
  // the power balance at v_G = 0: d/dt (w.I w / 2) = n C dw_Z/dt = F_t . v_C = -mu F_n n R sin theta.
  Scene s = fixtures::dimensionless_scene();
  const double n = s.initial.spin, th = s.initial.tilt, R = s.body.sphere_radius, mu = s.contact.mu;
  const double M = s.mass.mass, C = s.mass.inertia_axial;
  const BodyState x = scene_initial_state(s);
  ASSERT_NEAR(x.w_B.z(), n, 1e-15);
  const Rhs r = reference_rhs(s, x, false);
  const double f_n = r.f.normal[0];
  ASSERT_GT(f_n, 0.0);
  EXPECT_NEAR((r.f.slip_W[0] - Vec3(n * R * std::sin(th), 0, 0)).norm(), 0.0, 1e-14);
  EXPECT_NEAR(r.dydt[3], -mu * f_n / M, 1e-14);
  EXPECT_NEAR(r.dydt[4], 0.0, 1e-14);
  EXPECT_NEAR(r.dydt[5], f_n / M - s.gravity, 1e-14);
  EXPECT_NEAR(n * C * r.dydt[12], -mu * f_n * n * R * std::sin(th), 1e-13);
}

}  // namespace
}  // namespace tippe
