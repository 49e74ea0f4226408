// The reference checked live against Siconos: its events and energies on Coulomb tops converge to the reference's at first order, within their own spread.
//
// Siconos (Moreau-Jean time-stepping, rigid unilateral contacts, Coulomb's cone, Newton impacts
// with restitution 0) is an implementation of the same physics independent of the reference's
// (event-driven, smooth phases by an error-controlled integrator, impacts and stick-slip located
// on dense output). Its error is first order in the step h: a quantity Q measured at h and at 3h
// gives the estimate |Q(h) - Q(3h)| / 2 of Q(h)'s error. Each check below runs a ladder of three
// steps (9h, 3h, h), and asks that
//   - the error to the reference shrinks down the ladder (convergence, not a lucky crossing), and
//   - the finest rung's error is within kSpreadFactor of its first-order estimate.
// A disagreement beyond that is a finding about one of the two, never a tolerance to widen.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <limits>
#include <string>
#include <thread>
#include <vector>

#include "harness/io/scene_io.h"
#include "harness/scene/resolve.h"
#include "engines/core/registry.h"

namespace tippe::test_siconos {
namespace {

// The first-order estimate is a model of the error, not a bound: its constant drifts between
// rungs. Measured (Release build, GCC 12; printed by the tests as "ratio"): the finest error
// over its estimate is 1.00 (inversion, error 7.7e-4 at h = 1e-4), 1.11 (stem contact, 1.6e-3),
// 1.00 (energy before the stem impact, 1.9e-4 of 2.66) on the Coulomb top and 1.06 (energy,
// 3.0e-9 of 0.012), 0.99 (tilt, 3.0e-5 rad) on leine_glocker. 2 passes them all and still
// fails an error twice the first-order expectation.
constexpr double kSpreadFactor = 2.0;

const double kNaN = std::numeric_limits<double>::quiet_NaN();

struct Measured {
  double inversion = kNaN, stem = kNaN;
  double energy_probe = kNaN;  // energy at the probe time
  double tilt_probe = kNaN;
  double impact_loss = kNaN;   // energy removed by the first stem touchdown
};

double event_time(const std::vector<Event>& events, const std::string& name) {
  for (const Event& e : events)
    if (e.name == name) return e.time;
  return kNaN;
}

// The reference: its located events, its impact event's energy, the state at the probe time.
Measured run_reference(const Scene& scene, double probe, double t_end) {
  auto sim = make_simulator("analytic", scene);
  const BodyModel m = BodyModel::from_scene(scene);
  Measured r;
  sim->advance_to(probe);
  r.energy_probe = energy(m, sim->state());
  r.tilt_probe = tilt(sim->state().q_WB);
  sim->advance_to(t_end);
  const std::vector<Event> ev = sim->events();
  r.inversion = event_time(ev, "inversion");
  r.stem = event_time(ev, "stem_contact");
  for (const Event& e : ev)
    if (e.name == "impact" && std::isfinite(r.stem) && std::abs(e.time - r.stem) < 1e-9) r.impact_loss = e.value;
  return r;
}

// Siconos at step h, one step at a time: the impact's loss is the energy the step that first
// reports the stem contact removes (that step's smooth part is O(h) of it: in the spread).
Measured run_siconos(Scene scene, double h, double probe, double t_end) {
  scene.engines["siconos"]["timestep"] = h;
  auto sim = make_simulator("siconos", scene);
  const BodyModel m = BodyModel::from_scene(scene);
  Measured r;
  double e_prev = energy(m, sim->state());
  size_t n_events = 0;
  const long long n = std::llround(t_end / h), n_probe = std::llround(probe / h);
  for (long long k = 1; k <= n && sim->status() == RunStatus::Ok; ++k) {
    sim->advance_to(static_cast<double>(k) * h);
    const BodyState x = sim->state();
    const double e = energy(m, x);
    if (k == n_probe) {
      r.energy_probe = e;
      r.tilt_probe = tilt(x.q_WB);
    }
    const std::vector<Event> ev = sim->events();
    if (ev.size() != n_events) {
      n_events = ev.size();
      if (!std::isfinite(r.stem) && std::isfinite(event_time(ev, "stem_contact"))) r.impact_loss = e_prev - e;
      r.inversion = event_time(ev, "inversion");
      r.stem = event_time(ev, "stem_contact");
    }
    e_prev = e;
  }
  EXPECT_EQ(sim->status(), RunStatus::Ok) << "h = " << h << ": " << sim->status_detail();
  return r;
}

// The ladder's verdict on one quantity: q[0..2] at 9h, 3h, h; ref the reference's value.
void expect_first_order(const char* what, const double q[3], double ref) {
  ASSERT_TRUE(std::isfinite(ref)) << what << ": the reference has none";
  for (int i = 0; i < 3; ++i) ASSERT_TRUE(std::isfinite(q[i])) << what << ": rung " << i << " has none";
  const double err_mid = std::abs(q[1] - ref), err = std::abs(q[2] - ref);
  const double estimate = std::abs(q[1] - q[2]) / 2;
  std::printf("[siconos] %s: reference %.10g; ladder %.10g %.10g %.10g; errors %.3g %.3g %.3g; estimate %.3g; ratio %.2f\n",
              what, ref, q[0], q[1], q[2], std::abs(q[0] - ref), err_mid, err, estimate, err / estimate);
  EXPECT_LT(err, err_mid) << what << ": no convergence towards the reference";
  EXPECT_LE(err, kSpreadFactor * estimate) << what << ": Siconos at the finest step is " << err
                                           << " from the reference, its first-order spread " << estimate;
}

std::string scene_path(const char* name) { return std::string(TIPPE_SOURCE_DIR) + "/harness/scenes/" + name; }

// The source's dimensionless body under Coulomb friction (mu 0.3), started at tilt 1.5 rad so
// that it inverts (t = 2.58) and its stem touches down (t = 6.08, a plastic impact) within a
// short horizon; before that it rolls without slip from t ~ 4, a plateau of energy.
Scene coulomb_top() {
  return load_scene(scene_path("source_dimensionless.toml"),
                    {"contact.friction=\"coulomb\"", "contact.k=0", "contact.mu=0.3", "initial.tilt=1.5", "run.duration=6.2"});
}
constexpr double kCoulombProbe = 6.0;  // rolling, before the stem touches down
constexpr double kCoulombEnd = 6.2;

TEST(SiconosCrossCheck, CoulombTopInversionStemContactAndEnergyConvergeToTheReference) {
  const Scene s = coulomb_top();
  const Measured ref = run_reference(s, kCoulombProbe, kCoulombEnd);
  const double h[3] = {9e-4, 3e-4, 1e-4};
  Measured q[3];
  for (int i = 0; i < 3; ++i) q[i] = run_siconos(s, h[i], kCoulombProbe, kCoulombEnd);
  const double inv[3] = {q[0].inversion, q[1].inversion, q[2].inversion};
  const double stem[3] = {q[0].stem, q[1].stem, q[2].stem};
  const double e[3] = {q[0].energy_probe, q[1].energy_probe, q[2].energy_probe};
  expect_first_order("inversion time", inv, ref.inversion);
  expect_first_order("stem contact time", stem, ref.stem);
  expect_first_order("energy before the stem impact", e, ref.energy_probe);
}

// FINDING (disabled until the impact laws are reconciled): the energy the stem touchdown removes
// converges in Siconos (0.02183, 0.02235, 0.02251 at h = 9e-4, 3e-4, 1e-4: first order, limit
// ~0.0226) to 9.6 % more than the reference's impact removes (0.020609): the error grows down
// the ladder, and at h = 1e-4 it is 24 times the first-order spread. Both are plastic impacts
// with Coulomb friction, but with different frictional impact laws: the reference's impulse
// slides along the PRE-impact slip where it cannot stick (analytic/contact_impacts.cpp), Moreau-Jean's Coulomb cone acts on the POST-impact
// velocity (Moreau's law, maximal dissipation): from the same state the two impacts agree when
// frictionless or sticking and differ by exactly this where the impulse slides (the tests on the
// impact from the reference's state, below). The energies after the impact differ accordingly
// (2.5965 against 2.5969 at t = 8, once rolling again), while every event before it agrees.
TEST(SiconosCrossCheck, DISABLED_CoulombTopStemImpactLossConvergesToTheReference) {
  const Scene s = coulomb_top();
  const Measured ref = run_reference(s, kCoulombProbe, kCoulombEnd);
  const double h[3] = {9e-4, 3e-4, 1e-4};
  double loss[3];
  for (int i = 0; i < 3; ++i) loss[i] = run_siconos(s, h[i], kCoulombProbe, kCoulombEnd).impact_loss;
  expect_first_order("energy removed by the stem impact", loss, ref.impact_loss);
}

// leine_glocker (Coulomb mu 0.3 at a point contact, SI): the slip dies within 0.04 s and the top
// rolls on without slip, its energy constant; at 0.3 s both the energy plateau and the tilt
// (nutating) are checked. No inversion and no stem contact in the reference (30 s): this
// horizon cannot see Siconos's late inversion at h = 1e-4 (t = 16.4, BENCHMARKS.md), which the
// fixed-step engines share.
TEST(SiconosCrossCheck, LeineGlockerRollingEnergyAndTiltConvergeToTheReference) {
  const Scene s = load_scene(scene_path("leine_glocker.toml"), {"run.duration=0.3"});
  const double probe = 0.3;
  const Measured ref = run_reference(s, probe, probe);
  const double h[3] = {9e-5, 3e-5, 1e-5};
  Measured q[3];
  for (int i = 0; i < 3; ++i) q[i] = run_siconos(s, h[i], probe, probe);
  const double e[3] = {q[0].energy_probe, q[1].energy_probe, q[2].energy_probe};
  const double th[3] = {q[0].tilt_probe, q[1].tilt_probe, q[2].tilt_probe};
  expect_first_order("leine_glocker energy at 0.3 s", e, ref.energy_probe);
  expect_first_order("leine_glocker tilt at 0.3 s", th, ref.tilt_probe);
  for (int i = 0; i < 3; ++i) EXPECT_FALSE(std::isfinite(q[i].inversion)) << "h = " << h[i];
}

// The stem touchdown of the Coulomb top alone, from the reference's own state 1e-9 before it (the
// stem 1.9e-10 above the floor, approaching; the ball rolling): the reference locates and applies
// its impact, Siconos takes one step of 1e-8 (whose smooth part is ~1e-8 of the energy).
struct ImpactLosses {
  double reference = kNaN, siconos = kNaN;
};
ImpactLosses stem_impact_from_the_same_state(double mu) {
  const Scene s = coulomb_top();
  const BodyModel m = BodyModel::from_scene(s);
  auto run = make_simulator("analytic", s);
  run->advance_to(6.2);
  const double t_touchdown = event_time(run->events(), "stem_contact");
  auto to_pre = make_simulator("analytic", s);
  to_pre->advance_to(t_touchdown - 1e-9);
  const BodyState pre = to_pre->state();
  Scene at_mu = s;
  at_mu.contact.mu = mu;
  at_mu.engines["siconos"]["timestep"] = 1e-8;
  ImpactLosses r;
  for (const char* engine : {"analytic", "siconos"}) {
    auto sim = make_simulator(engine, at_mu);
    sim->set_state(pre);
    sim->advance_to(1e-8);
    (std::string(engine) == "analytic" ? r.reference : r.siconos) = energy(m, pre) - energy(m, sim->state());
  }
  return r;
}

// Frictionless (mu = 0) and sticking (mu = 1: the impulse stays inside the cone) impacts are the
// same law in both: a plastic impact projecting the approaching normal velocity (and, sticking,
// the slip) to zero. Measured: the losses agree to 1.6e-8 (mu = 0, loss 0.0093872) and 1.0e-8
// (mu = 1, 0.050412) relative, the work of gravity and of the rolling ball over Siconos's step
// of 1e-8 and the reference's 1e-9 to the touchdown; 1e-7 is 6 times the larger.
TEST(SiconosCrossCheck, StemImpactFromTheSameStateMatchesWhenFrictionlessOrSticking) {
  for (const double mu : {0.0, 1.0}) {
    const ImpactLosses l = stem_impact_from_the_same_state(mu);
    std::printf("[siconos] stem impact from the reference's state, mu %g: reference %.10g, Siconos %.10g (%.2g relative)\n", mu,
                l.reference, l.siconos, std::abs(l.siconos - l.reference) / l.reference);
    EXPECT_GT(l.reference, 0.005) << "mu " << mu << ": the scene no longer has a stem impact";
    EXPECT_NEAR(l.siconos, l.reference, 1e-7 * l.reference) << "mu " << mu;
  }
}

// FINDING (disabled: the frictional impact laws differ where the impulse slides): from the same
// state, at mu = 0.3 (the scene's) the reference's impact removes 0.020609 and Siconos's 0.022587
// (9.6 % more); at mu = 0.05, 0.011468 and 0.011625 (1.4 % more). The reference's tangential
// impulse slides along the PRE-impact slip where it cannot stick (analytic/contact_impacts.cpp);
// Moreau-Jean's Coulomb cone acts on the POST-impact slip (Moreau's law, maximal dissipation).
// Neither is Darboux-Keller's integration of the slip over the impact, which lies between where
// the slip turns during it. This is the whole of the test above's stem-impact difference.
TEST(SiconosCrossCheck, DISABLED_SlidingStemImpactFromTheSameStateMatches) {
  const ImpactLosses l = stem_impact_from_the_same_state(0.3);
  EXPECT_NEAR(l.siconos, l.reference, 1e-7 * l.reference);
}

// Sweeps and compare run simulators in threads: two Siconos runs side by side give, to the bit,
// the state of one run alone (Siconos' numerics keep no shared state a run depends on).
TEST(Siconos, RunsInThreadsAsAlone) {
  const Scene s = coulomb_top();
  auto final_state = [&s] {
    auto sim = make_simulator("siconos", s);
    sim->advance_to(0.5);
    return sim->state();
  };
  const BodyState alone = final_state();
  BodyState a, b;
  std::thread ta([&] { a = final_state(); }), tb([&] { b = final_state(); });
  ta.join();
  tb.join();
  for (const BodyState* x : {&a, &b}) {
    EXPECT_EQ(x->p_WG, alone.p_WG);
    EXPECT_EQ(x->v_WG, alone.v_WG);
    EXPECT_EQ(x->w_B, alone.w_B);
    EXPECT_EQ(x->q_WB.coeffs(), alone.q_WB.coeffs());
  }
}

TEST(Siconos, RejectsAnUnknownSolverNamingTheKey) {
  Scene s = coulomb_top();
  s.engines["siconos"]["solver"] = std::string("lemke");
  try {
    make_simulator("siconos", s);
    FAIL() << "an unknown solver was accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("engines.siconos.solver"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace tippe
