// One conformance suite for every registered simulator (the reference included), each with its own measured tolerances.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>

#include "analytic/contact_dynamics.h"
#include "analytic/initial_state.h"
#include "harness/records/records.h"
#include "harness/measure/run.h"
#include "engines/core/registry.h"
#include "tests/support/fixtures.h"

namespace tippe::test_conformance {
namespace {

// ---- Tolerances -----------------------------------------------------------------------------
//
// One row per simulator: the residual each check MEASURED at the simulator's default settings,
// on this suite's scenes. A check passes below kToleranceScale times its row's value, so the
// suite catches a regression of one order of magnitude, not only catastrophes. Values are
// floored at kRoundOff (a residual of exactly 0 would otherwise allow nothing).
//
// Recipe (recalibrating after an engine or default-setting change, or for a new engine):
//   TIPPE_CONFORMANCE_SCALE=1e12 ./build/tests/test_engines --gtest_filter='Engines/*NEW*' | grep residual
// prints every residual (the huge scale lets every check pass); enter each, rounded UP to two
// significant digits, in the engine's row. TIPPE_CONFORMANCE_SCALE (default 10) is the knob:
// e.g. 2 shows how close each engine runs to its calibration.
constexpr double kToleranceScale = 10.0;
constexpr double kRoundOff = 1e-15;

struct EngineRow {
  const char* engine;
  double rest_drift;      // |p_G - p_G0| / R after 2 time units at rest upright
  double spin_rel;        // relative change of a frictionless upright spin over 2 time units
  double precession;      // |w_B - closed form| / |w| after 2 time units of torque-free flight
  double roll_time_rel;   // sliding -> rolling time of a ball against 2 v0 / (7 mu g), relative (sampled every 1e-3)
  double roll_speed_rel;  // rolling speed against 5 v0 / 7, relative
  double set_get;         // |state() - x| after set_state(x) (lengths / R, velocities / scale)
  double resume;          // the same run continued 0.3 time units after set_state(state()), vs without
  double start_accel;     // |dv/dt| / g and |dw/dt| R / g over the first 1e-3 time units at rest upright
  double contact_point;   // |engine's contact point - lowest point of the ball| / R, spinning tilted top (viscous), t in 0.1..0.3
  double normal_force;    // |F_n - M g| / (M g) at rest upright after 0.5 time units
};

// Measured at the defaults (Release build, GCC 12; the recipe above). Adding an engine: one row
// here (its instantiation) and nothing else in this file. Notes on the values: roll_t of every
// engine is the 1e-3 sampling (t_roll = 0.952), the reference's is its located stick event;
// MuJoCo's soft contact settles by 4.5e-7 R and starts with a 7.8e-2 g transient (the
// penetration it rests at); the reference's resume is the cost of restarting its integrator;
// Simbody's compliant contact starts at zero depth, so its top falls freely for the first 1e-3
// (0.96 g: it rests 1.6e-6 R deep, reached after 1.8e-3) and then rings on the Hertz spring
// (about 150 oscillations per time unit, Hunt-Crossley damping ratio 4e-4 at c = 0.5): F_n at
// t = 0.5 is 0.57 M g off and the rest drift is that bounce; its precession, resume and roll
// speed are the 1e-6 accuracy (its resume, 9.6e-5, also the restart of its step control, as the
// reference's), its roll time the friction regularized below 1e-3;
// Bullet's, ODE's and DART's contact point is that of their collision pass at the start of the
// step, so it trails the body by one step's motion (9.4e-6 R here), MuJoCo's lies half its
// penetration deep.
const EngineRow kEngines[] = {
    // name       rest     spin     precess  roll_t   roll_v   set_get  resume   accel    point    F_n
    {"analytic", 0.0,     5.3e-16, 2.2e-15, 1.1e-14, 1.3e-14, 4.4e-16, 4.0e-14, 1.1e-16, 0.0,     0.0},
    {"bullet",   0.0,     4.9e-14, 7.7e-06, 4.0e-04, 2.8e-13, 1.8e-16, 2.1e-14, 0.0,     9.4e-06, 0.0},
    {"ode",      5.0e-13, 7.5e-13, 1.3e-04, 4.0e-04, 2.0e-13, 1.8e-16, 8.5e-15, 1.3e-07, 9.4e-06, 0.0},
    {"mujoco",   4.5e-07, 0.0,     5.7e-16, 4.0e-04, 8.9e-08, 0.0,     0.0,     7.8e-02, 2.2e-07, 0.0},
    {"dart",     1.0e-11, 0.0,     7.7e-06, 4.0e-04, 5.6e-12, 5.6e-17, 5.1e-15, 9.1e-07, 9.4e-06, 0.0},
    {"simbody",  1.4e-06, 0.0,     5.2e-06, 1.5e-03, 2.3e-06, 1.9e-16, 9.6e-05, 9.7e-01, 1.5e-06, 5.8e-01},
    // Siconos (h = 1e-4, theta = 0.5): rigid contact, so no rest drift, start transient or contact
    // offset beyond round-off (F_n is the step's impulse / h); precession 8e-11 is Moreau-Jean's
    // trapezoidal smooth part at h = 1e-4; roll_t is the 1e-3 sampling, as for the other engines.
    {"siconos",  0.0,     0.0,     8.1e-11, 4.0e-04, 3.7e-13, 1.3e-16, 3.2e-13, 0.0,     3.0e-13, 1.2e-13},
};

double scale() {
  if (const char* s = std::getenv("TIPPE_CONFORMANCE_SCALE")) return std::atof(s);
  return kToleranceScale;
}
double tol(double measured) { return scale() * std::max(measured, kRoundOff); }

// Prints a residual in the recipe's format and checks it against the row's tolerance.
void check(const EngineRow& row, const char* what, double residual, double measured) {
  std::printf("[%s] residual %s %.2g (tolerance %.2g)\n", row.engine, what, residual, tol(measured));
  EXPECT_LE(residual, tol(measured)) << row.engine << ": " << what << " " << residual << " beyond "
                                     << scale() << " x its measured " << measured;
}

// ---- Scenes and helpers -----------------------------------------------------------------------

// A quaternion and its negative are the same attitude.
double quat_distance(const Quat& a, const Quat& b) {
  return std::min((a.coeffs() - b.coeffs()).norm(), (a.coeffs() + b.coeffs()).norm());
}

// Largest difference of two states: lengths relative to R, velocities relative to v_scale,
// angular velocities relative to v_scale / R, attitude as a quaternion distance up to sign.
double state_distance(const BodyState& a, const BodyState& b, double R, double v_scale) {
  return std::max({(a.p_WG - b.p_WG).norm() / R, (a.v_WG - b.v_WG).norm() / v_scale,
                   (a.w_B - b.w_B).norm() * R / v_scale, quat_distance(a.q_WB, b.q_WB)});
}

// What signals trouble in a run: a status other than ok, a failure event, or a note that
// reports an engine warning or error (informational notes about modelling choices pass).
void expect_no_trouble(const Simulator& sim) {
  EXPECT_EQ(sim.status(), RunStatus::Ok) << sim.engine() << ": " << sim.status_detail();
  for (const Event& e : sim.events())
    EXPECT_TRUE(e.name != "diverged" && e.name != "clamped" && e.name != "failed" && e.name != "unphysical")
        << sim.engine() << ": event " << e.name << " at " << e.time << ": " << e.detail;
  for (const std::string& n : sim.notes()) {
    std::string low = n;
    std::transform(low.begin(), low.end(), low.begin(), [](unsigned char c) { return std::tolower(c); });
    for (const char* bad : {"warning", "error", "failed", "compiler", "raised by", "not the scene", "deprecated"})
      EXPECT_EQ(low.find(bad), std::string::npos) << sim.engine() << " note signals trouble: " << n;
  }
}

void PrintTo(const EngineRow& r, std::ostream* os) { *os << r.engine; }

class Conformance : public ::testing::TestWithParam<EngineRow> {
 protected:
  const EngineRow& row() const { return GetParam(); }
  std::unique_ptr<Simulator> make(const Scene& s) const { return make_simulator(row().engine, s); }
};

// ---- The suite ------------------------------------------------------------------------------------

TEST_P(Conformance, MassPropertiesReadBack) {
  Scene s = fixtures::dimensionless_scene();
  auto sim = make(s);
  const MassReadback h = sim->mass_properties();
  // Set explicitly from the scene, never computed from shapes: equal to round-off (1e-12).
  const double A = s.mass.inertia_transverse, C = s.mass.inertia_axial;
  EXPECT_NEAR(h.mass, s.mass.mass, 1e-12 * s.mass.mass);
  EXPECT_NEAR(h.p_GCm_B.norm(), 0.0, 1e-12 * s.body.sphere_radius);
  EXPECT_NEAR((h.I_G_B - Eigen::Matrix3d(Vec3(A, A, C).asDiagonal())).norm(), 0.0, 1e-12 * C);
  expect_no_trouble(*sim);
}

TEST_P(Conformance, RestingUprightStaysPut) {
  Scene s = fixtures::dimensionless_scene();
  s.initial.tilt = 0.0;
  s.initial.spin = 0.0;
  auto sim = make(s);
  const BodyState x0 = sim->state();
  sim->advance_to(2.0);
  const Observation o = sim->observe();
  check(row(), "rest_drift", (o.state.p_WG - x0.p_WG).norm() / s.body.sphere_radius, row().rest_drift);
  EXPECT_LT(o.theta, 1e-6);
  expect_no_trouble(*sim);
}

TEST_P(Conformance, RestingUprightStartsWithoutAcceleration) {
  // At rest upright on the ball, gravity and the normal force cancel: v and w stay 0. A finite
  // difference over the first 1e-3 time units measures each simulator's start-up transient.
  Scene s = fixtures::dimensionless_scene();
  s.initial.tilt = 0.0;
  s.initial.spin = 0.0;
  auto sim = make(s);
  const double h = 1e-3;
  sim->advance_to(h);
  const BodyState x = sim->state();
  const double g = s.gravity, R = s.body.sphere_radius;
  const double accel = std::max(x.v_WG.norm() / h / g, x.w_B.norm() / h * R / g);
  check(row(), "start_accel", accel, row().start_accel);
  expect_no_trouble(*sim);
}

TEST_P(Conformance, ContactPointAndNormalForce) {
  // Where the engine puts the contact (its own report) against the exact geometry, and the
  // weight it carries at rest: what the collision shapes and the contact solve make of the body.
  Scene s = fixtures::dimensionless_scene();
  const double R = s.body.sphere_radius, W = s.mass.mass * s.gravity;
  // The spinning tilted top under the viscous law (with Coulomb friction MuJoCo's contact hops
  // while the ball slips and reports no force at most samples), sampled over 0.1..0.3.
  s.contact.friction = FrictionLaw::Viscous;
  s.contact.mu = 0.0;
  s.contact.k = 1.0;
  auto sim = make(s);
  double worst = 0.0;
  int valid = 0;
  for (int k = 0; k <= 20; ++k) {
    sim->advance_to(0.1 + 0.01 * k);
    const Observation o = sim->observe();
    if (!o.engine_contact_valid) continue;
    ++valid;
    worst = std::max(worst, (o.p_WC_engine - o.p_WC).norm() / R);
  }
  ASSERT_GE(valid, 10) << "contact reported at fewer than half of the samples of a top on its ball";
  check(row(), "contact_point", worst, row().contact_point);
  Scene rest = s;
  rest.initial.tilt = 0.0;
  rest.initial.spin = 0.0;
  auto still = make(rest);
  still->advance_to(0.5);
  check(row(), "normal_force", std::abs(still->observe().normal_force - W) / W, row().normal_force);
  expect_no_trouble(*sim);
}

TEST_P(Conformance, FrictionlessUprightKeepsSpin) {
  Scene s = fixtures::dimensionless_scene();
  s.contact.friction = FrictionLaw::None;
  s.contact.mu = 0.0;
  s.initial.tilt = 0.0;
  auto sim = make(s);
  sim->advance_to(2.0);
  const Observation o = sim->observe();
  check(row(), "spin_rel", std::abs(o.state.w_B.z() - 5.0) / 5.0, row().spin_rel);
  EXPECT_LT(o.theta, 1e-6);
  expect_no_trouble(*sim);
}

TEST_P(Conformance, TorqueFreePrecession) {
  // Gravity off, the body in the air: w_B turns about e_Z at lambda = (C - A) w3 / A
  // (Euler's equations of an axisymmetric body).
  Scene s = fixtures::dimensionless_scene();
  s.gravity = 0.0;
  s.contact.flight = true;
  s.initial.height = 1.0;
  s.initial.tilt = 0.3;
  s.initial.omega_given = true;
  s.initial.omega_B = {1.0, 0.0, 5.0};
  auto sim = make(s);
  const double T = 2.0;
  sim->advance_to(T);
  const double A = s.mass.inertia_transverse, C = s.mass.inertia_axial;
  const double lambda = (C - A) * 5.0 / A;
  const Vec3 expected(std::cos(lambda * T), std::sin(lambda * T), 5.0);
  check(row(), "precession", (sim->state().w_B - expected).norm() / expected.norm(), row().precession);
  EXPECT_GT(sim->state().p_WG.z(), s.body.sphere_radius);  // never touched the floor
  expect_no_trouble(*sim);
}

TEST_P(Conformance, SlidingBallStartsRolling) {
  // A uniform ball launched sliding at v0 rolls from t = 2 v0 / (7 mu g) at speed 5 v0 / 7.
  Scene s = fixtures::sliding_ball(1.0);
  const double v0 = 1.0, mu = s.contact.mu, g = s.gravity;
  const double t_roll = 2 * v0 / (7 * mu * g);
  auto sim = make(s);
  double t_stop = -1;
  // Sampled every 1e-3 (1e-3 of t_roll): finer than every engine's own roll-time error.
  for (int k = 1; k <= 2000; ++k) {
    sim->advance_to(1e-3 * k);
    if (t_stop < 0 && sim->observe().slip_speed < 1e-3 * v0) t_stop = 1e-3 * k;
  }
  for (const Event& e : sim->events())
    if (e.name == "stick") t_stop = e.time;  // located exactly where the simulator finds it
  const double speed = std::hypot(sim->state().v_WG.x(), sim->state().v_WG.y());
  check(row(), "roll_time_rel", std::abs(t_stop - t_roll) / t_roll, row().roll_time_rel);
  check(row(), "roll_speed_rel", std::abs(speed - 5 * v0 / 7) / (5 * v0 / 7), row().roll_speed_rel);
  expect_no_trouble(*sim);
}

TEST_P(Conformance, AdvanceToNowChangesNothing) {
  Scene s = fixtures::dimensionless_scene();
  auto sim = make(s);
  sim->advance_to(0.5);
  const BodyState a = sim->state();
  const long long steps = sim->work().steps;
  const size_t events = sim->events().size();
  sim->advance_to(a.t);
  sim->advance_to(0.5);
  const BodyState b = sim->state();
  EXPECT_EQ(b.t, a.t);
  EXPECT_EQ(state_distance(a, b, 1.0, 1.0), 0.0);
  EXPECT_EQ(sim->work().steps, steps);
  EXPECT_EQ(sim->events().size(), events);
  expect_no_trouble(*sim);
}

TEST_P(Conformance, StateRoundTripsThroughSetState) {
  // A state of the same motion at another time, written into a second simulator: state()
  // returns it (attitude up to the quaternion's sign), at the simulator's own time.
  Scene s = fixtures::dimensionless_scene();
  const double R = s.body.sphere_radius, v_scale = 5.0 * R;
  auto a = make(s);
  a->advance_to(0.2);
  const BodyState x = a->state();
  auto b = make(s);
  b->advance_to(0.5);
  const double t_b = b->state().t;
  BodyState flipped = x;
  flipped.q_WB.coeffs() = -x.q_WB.coeffs();  // the other sign of the same attitude
  b->set_state(flipped);
  const BodyState y = b->state();
  EXPECT_EQ(y.t, t_b);
  check(row(), "set_get", state_distance(x, y, R, v_scale), row().set_get);
  EXPECT_THROW(b->set_state(BodyState{0.0, Vec3::Constant(std::nan("")), Vec3::Zero(), Quat::Identity(), Vec3::Zero()}),
               std::invalid_argument);
  expect_no_trouble(*b);
}

TEST_P(Conformance, SetStateOfItsOwnStateResumesTheRun) {
  // set_state(state()) in the middle of a run: the run goes on as without it, up to what a
  // restart costs the simulator (the reference restarts its integrator; engines lose nothing).
  Scene s = fixtures::dimensionless_scene();
  const double R = s.body.sphere_radius, v_scale = 5.0 * R;
  auto a = make(s);
  auto b = make(s);
  a->advance_to(0.3);
  b->advance_to(0.3);
  b->set_state(b->state());
  a->advance_to(0.6);
  b->advance_to(0.6);
  check(row(), "resume", state_distance(a->state(), b->state(), R, v_scale), row().resume);
  expect_no_trouble(*b);
}

std::string run_bytes(const std::string& engine, const Scene& s, const std::string& path) {
  {
    CsvTrajectoryWriter w(path);
    run_scene(s, engine, &w);
    w.commit();
  }
  std::ifstream in(path, std::ios::binary);
  std::ostringstream os;
  os << in.rdbuf();
  std::filesystem::remove(path);
  return os.str();
}

TEST_P(Conformance, Deterministic) {
  Scene s = fixtures::dimensionless_scene();
  s.run.duration = 1.0;
  const std::string dir = ::testing::TempDir(), name = row().engine;
  const std::string a = run_bytes(name, s, dir + "/det_a_" + name + ".csv");
  const std::string b = run_bytes(name, s, dir + "/det_b_" + name + ".csv");
  ASSERT_GT(a.size(), 1000u);
  EXPECT_TRUE(a == b) << "two runs of the same scene differ";
}

// Every setting the engine declares (its settings struct's `visit`, as docs/engines.md lists
// them) refuses a value of the wrong type, a number or count outside its range and a name outside
// its choices, and an unknown key is refused: each with an error naming engines.NAME.KEY, from
// the registry's validation and from making the simulator. A new engine's settings are checked
// here without a test of its own.
TEST_P(Conformance, EverySettingRefusesABadValueNamingItsKey) {
  const std::string name = row().engine;
  const EngineInfo& info = engine_info(name);
  auto expect_refused = [&](const std::string& key, const SettingValue& bad, const char* what) {
    Scene s = fixtures::dimensionless_scene();
    s.engines[name][key] = bad;
    const std::string want = "engines." + name + "." + key + ":";
    for (int via = 0; via < 2; ++via) {
      try {
        if (via == 0) info.validate(s);
        else make(s);
        ADD_FAILURE() << want << " accepted " << what << (via ? " (make_simulator)" : " (validate)");
      } catch (const std::invalid_argument& e) {
        EXPECT_NE(std::string(e.what()).find(want), std::string::npos) << what << ": " << e.what();
      }
    }
  };
  expect_refused("no_such_setting", 1.0, "an unknown key");
  const std::vector<SettingDoc> docs = info.describe_settings();
  ASSERT_FALSE(docs.empty()) << name << " declares no settings";
  for (const SettingDoc& d : docs) {
    if (d.type == "number") {
      expect_refused(d.key, std::string("1e-3"), "a string for a number");
      expect_refused(d.key, std::nan(""), "NaN");  // outside every range, both bounds included
    } else if (d.type == "integer") {
      expect_refused(d.key, 0.5, "a fraction for an integer");
      expect_refused(d.key, 1LL << 40, "a count past every int range");
    } else if (d.type == "boolean") {
      expect_refused(d.key, 1LL, "1 for a boolean");
    } else if (d.type == "string") {
      expect_refused(d.key, 1.0, "a number for a string");
      if (d.allowed != "any string") expect_refused(d.key, std::string("no_such_choice"), "a name outside the choices");
    } else if (d.type == "array") {
      expect_refused(d.key, 1.0, "a number for an array");
    } else {
      ADD_FAILURE() << d.key << ": a setting type this test does not know: " << d.type;
    }
  }
}

TEST_P(Conformance, NameAndVersionAreTheRegistrys) {
  auto sim = make(fixtures::dimensionless_scene());
  EXPECT_EQ(sim->engine(), row().engine);
  EXPECT_EQ(sim->version(), engine_info(row().engine).version);
}

TEST_P(Conformance, TheRunReadsItsClocksNotTheSimulator) {
  // The run's wall and CPU time come from run_simulator, read at its loop's two ends; a
  // simulator leaves them 0 (a thread CPU clock read around each advance_to, a system call,
  // cost more than a sample).
  Scene s = fixtures::dimensionless_scene();
  s.run.duration = 0.5;
  auto sim = make(s);
  const RunRecord r = run_simulator(*sim, s, nullptr);
  EXPECT_EQ(sim->work().wall_seconds, 0.0);
  EXPECT_EQ(sim->work().cpu_seconds, 0.0);
  EXPECT_GT(r.work.wall_seconds, 0.0);
  EXPECT_GT(r.work.cpu_seconds, 0.0);
  EXPECT_EQ(r.work.steps, sim->work().steps);
  EXPECT_EQ(sim->event_count(), sim->events().size());
}

INSTANTIATE_TEST_SUITE_P(Engines, Conformance, ::testing::ValuesIn(kEngines),
                         [](const ::testing::TestParamInfo<EngineRow>& info) { return std::string(info.param.engine); });

// Every registered simulator has its row (and so its instantiation), and every row an engine.
TEST(ConformanceTable, CoversTheRegistry) {
  std::set<std::string> rows;
  for (const EngineRow& r : kEngines) rows.insert(r.engine);
  for (const std::string& e : available_engines()) EXPECT_TRUE(rows.count(e)) << e << " has no row in kEngines";
  EXPECT_EQ(rows.size(), available_engines().size());
}

// A key engines share has one bound for all of them (shared_settings in engines/core/settings.h):
// every engine with a `timestep` takes 0.1 and refuses the next value up.
TEST(ConformanceTable, SharedKeysHaveOneBound) {
  int engines_with_timestep = 0;
  for (const std::string& name : engine_names()) {
    const SettingsList defaults = engine_info(name).default_settings();
    if (std::none_of(defaults.begin(), defaults.end(), [](const auto& kv) { return kv.first == "timestep"; })) continue;
    ++engines_with_timestep;
    Scene s = fixtures::dimensionless_scene();
    s.engines[name]["timestep"] = 0.1;
    EXPECT_NO_THROW(engine_info(name).validate(s)) << name;
    s.engines[name]["timestep"] = 0.11;
    try {
      engine_info(name).validate(s);
      ADD_FAILURE() << name << " accepted timestep = 0.11";
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find("outside [1e-08, 0.1]"), std::string::npos) << name << ": " << e.what();
    }
  }
  EXPECT_GE(engines_with_timestep, 1);
}

}  // namespace
}  // namespace tippe
