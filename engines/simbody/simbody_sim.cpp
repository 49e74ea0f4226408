// Simbody 3.7 adapter: one free MobilizedBody at G with the ball and the stem tip as Hunt-Crossley spheres on a half-space, integrated with error control.
//
// Unlike the fixed-step engines (engines/core/fixed_step.h), Simbody has no step to set: its
// integrators choose their own steps to an accuracy. advance_to(t) integrates to exactly t, and
// the checks every engine gets (events, divergence, penetration) run after each accepted internal
// step, as the shared fixed-step loop runs them after each fixed step.
#include <Simbody.h>

#include <algorithm>
#include <cmath>
#include <exception>
#include <functional>
#include <memory>
#include <sstream>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "analytic/initial_state.h"
#include "analytic/stop_request.h"
#include "engines/core/step_checks.h"
#include "engines/core/registry.h"
#include "engines/core/settings.h"
#include "engines/simbody/simbody_forces.h"
#include "engines/simbody/simbody_settings.h"

namespace tippe {
namespace {

std::string simbody_version() {
  // Debian's libsimbody-dev 3.7; the headers carry no version macro of their own.
  return "simbody 3.7";
}

Eigen::Vector3d to_eigen(const SimTK::Vec3& v) { return {v[0], v[1], v[2]}; }
SimTK::Vec3 to_simtk(const Eigen::Vector3d& v) { return SimTK::Vec3(v.x(), v.y(), v.z()); }

using simbody_detail::ContactPower;
using simbody_detail::LedgerWork;
using simbody_detail::SphereSpec;
using simbody_detail::ViscousContactForce;
using simbody_detail::for_each_viscous;
using simbody_detail::integrator_keeps_z_out_of_its_steps;

class SimbodySimulator : public CheckedSimulator {
 public:
  explicit SimbodySimulator(const Scene& scene);

  std::string engine() const override { return "simbody"; }
  std::string version() const override { return simbody_version(); }
  void advance_to(double t) override;
  Observation observe() const override;
  BodyState state() const override { return read_state(integ_->getState()); }
  void set_state(const BodyState& x) override;
  MassReadback mass_properties() const override;
  WorkCounters work() const override;
  SettingsList settings() const override { return list_settings(settings_); }
  EngineContactForces contact_forces() const override { return tippe::contact_forces(report_); }
  std::vector<std::string> notes() const override { return notes_; }

 private:
  BodyState read_state(const SimTK::State& s) const;
  ContactReport read_contacts(const SimTK::State& s) const;
  // f(force, its spatial force on the top at its contact point, on the stem) for each contact
  // force Simbody reports at s.
  template <class F>
  void for_each_contact_force(const SimTK::State& s, F f) const;
  ContactPower contact_power(const SimTK::State& s) const;
  // The ledger's work so far (normal, tangential) as LedgerWork's z's hold it.
  std::pair<double, double> ledger_work(const SimTK::State& s) const;
  void after_step();
  void make_integrator();
  void make_notes();

  Scene scene_;
  BodyModel body_;
  SimbodySettings settings_;
  SimbodyFriction friction_;
  std::vector<std::string> notes_;

  SimTK::MultibodySystem system_;
  SimTK::SimbodyMatterSubsystem matter_;
  SimTK::GeneralForceSubsystem forces_;
  SimTK::ContactTrackerSubsystem tracker_;
  SimTK::CompliantContactSubsystem contact_;
  SimTK::MobilizedBody::Free top_;
  SimTK::ContactSurfaceIndex ball_surface_, stem_surface_;
  std::unique_ptr<SimTK::Integrator> integ_;

  WorkCounters work_;
  long long realizations_before_ = 0, iterations_before_ = 0;  // of integrators replaced by set_state
  ContactReport report_;
  std::vector<SphereSpec> spheres_;  // ball, then stem: for the bench's viscous force in reports
  const LedgerWork* ledger_ = nullptr;  // owned by forces_
  std::pair<double, double> ledger_last_{0.0, 0.0};  // its z's at the last step's end
};

SimbodySimulator::SimbodySimulator(const Scene& scene)
    : CheckedSimulator(scene),
      scene_(scene),
      body_(BodyModel::from_scene(scene)),
      settings_(read_settings<SimbodySettings>("simbody", scene)),
      friction_(simbody_friction(settings_, scene.contact)),
      matter_(system_),
      forces_(system_),
      tracker_(system_),
      contact_(system_, tracker_) {
  using namespace SimTK;
  const BodyModel& m = body_;
  if (!(m.M > 0 && m.A > 0 && m.C > 0 && m.R > 0) || (m.stem && !(m.r > 0 && m.l >= 0)))
    throw std::invalid_argument("simbody: needs M, A, C, R > 0 (and r > 0, l >= 0 with a stem)");
  // The scales as used, in the settings the run lists.
  if (settings_.length_scale == 0) settings_.length_scale = m.R;
  if (settings_.time_scale == 0) settings_.time_scale = scene.gravity > 0 ? std::sqrt(m.R / scene.gravity) : 1.0;
  settings_.static_friction = friction_.us;
  settings_.dynamic_friction = friction_.ud;
  settings_.viscous_friction = friction_.uv;
  system_.setDefaultLengthScale(settings_.length_scale);
  system_.setDefaultTimeScale(settings_.time_scale);

  Force::UniformGravity(forces_, matter_, SimTK::Vec3(0, 0, -scene.gravity));
  contact_.setTransitionVelocity(settings_.transition_velocity);
  const ContactMaterial material(settings_.stiffness, settings_.dissipation, friction_.us, friction_.ud, friction_.uv);

  // The floor z = 0: Simbody's half-space is x > 0 of its frame (outward normal -x), so its
  // frame is Ground turned by pi/2 about y (x -> -z).
  matter_.Ground().updBody().addContactSurface(Transform(Rotation(Pi / 2, YAxis), SimTK::Vec3(0)),
                                               ContactSurface(ContactGeometry::HalfSpace(), material));

  // The top: one body whose frame is the principal frame at G, its mass properties the scene's
  // (never computed from the shapes). Ball and tip in one clique: they never touch each other.
  Body::Rigid body(SimTK::MassProperties(m.M, SimTK::Vec3(0), Inertia(m.A, m.A, m.C)));
  const ContactCliqueId clique = ContactSurface::createNewContactClique();
  std::vector<SphereSpec> spheres{{SimTK::Vec3(0, 0, m.z_O()), m.R}};
  const int ball = body.addContactSurface(Transform(spheres[0].centre_B),
                                          ContactSurface(ContactGeometry::Sphere(m.R), material).joinClique(clique));
  int stem = -1;
  if (m.stem) {
    spheres.push_back({SimTK::Vec3(0, 0, m.z_P()), m.r});
    stem = body.addContactSurface(Transform(spheres[1].centre_B),
                                  ContactSurface(ContactGeometry::Sphere(m.r), material).joinClique(clique));
  }
  top_ = MobilizedBody::Free(matter_.Ground(), Transform(), body, Transform());
  if (friction_.bench_viscous) Force::Custom(forces_, new ViscousContactForce(top_, spheres, scene.contact.k));
  spheres_ = spheres;
  if (integrator_keeps_z_out_of_its_steps(settings_.integrator)) {
    auto* ledger = new LedgerWork(forces_.getMySubsystemIndex(), [this](const SimTK::State& st) { return contact_power(st); });
    Force::Custom(forces_, ledger);
    ledger_ = ledger;
  }

  system_.realizeTopology();
  ball_surface_ = tracker_.getContactSurfaceIndex(top_, ball);
  if (stem >= 0) stem_surface_ = tracker_.getContactSurfaceIndex(top_, stem);
  State s = system_.getDefaultState();
  const BodyState x0 = scene_initial_state(scene);
  top_.setQToFitTransform(s, Transform(Rotation(Quaternion(x0.q_WB.w(), x0.q_WB.x(), x0.q_WB.y(), x0.q_WB.z())),
                                       to_simtk(x0.p_WG)));
  top_.setUToFitVelocity(s, SpatialVec(to_simtk(x0.q_WB * x0.w_B), to_simtk(x0.v_WG)));
  system_.realize(s, Stage::Velocity);
  if (ledger_) ledger_->zero_weights(s);
  make_integrator();
  integ_->initialize(s);
  ledger_last_ = ledger_work(integ_->getState());

  // Hertz's law F_n = (4/3) E_eff sqrt(R_s) x^(3/2) without its Hunt-Crossley damping: the
  // elastic energy of the energy ledger (simbody_settings.h gives E_eff).
  const double E_eff = settings_.stiffness / std::pow(2.0, 1.5);
  ContactPotential hertz;
  hertz.k_ball = 4.0 / 3.0 * E_eff * std::sqrt(m.R);
  hertz.k_stem = m.stem ? 4.0 / 3.0 * E_eff * std::sqrt(m.r) : 0.0;
  hertz.exponent = 1.5;
  checks_.set_contact_potential(hertz);
  if (!ledger_) checks_.set_smooth_forces();
  checks_.start(read_state(integ_->getState()));
  report_ = read_contacts(integ_->getState());
  make_notes();
}

void SimbodySimulator::make_integrator() {
  using namespace SimTK;
  const std::string& k = settings_.integrator;
  if (k == "rk_merson") integ_ = std::make_unique<RungeKuttaMersonIntegrator>(system_);
  else if (k == "rk3") integ_ = std::make_unique<RungeKutta3Integrator>(system_);
  else if (k == "rk2") integ_ = std::make_unique<RungeKutta2Integrator>(system_);
  else if (k == "euler") integ_ = std::make_unique<ExplicitEulerIntegrator>(system_);
  else if (k == "verlet") integ_ = std::make_unique<VerletIntegrator>(system_);
  else integ_ = std::make_unique<CPodesIntegrator>(system_, CPodes::BDF, CPodes::Newton);
  integ_->setAccuracy(settings_.accuracy);
  if (settings_.max_step > 0) integ_->setMaximumStepSize(settings_.max_step);
  // Every state the bench sees is the end of an accepted step: no interpolated report states
  // (a report time ends a step), and control comes back after each step for the checks.
  integ_->setAllowInterpolation(false);
  integ_->setReturnEveryInternalStep(true);
}

void SimbodySimulator::make_notes() {
  std::ostringstream os;
  os << "Hunt-Crossley compliant contact (Simbody's Hertz sphere-on-half-space force, stiffness " << settings_.stiffness
     << ", dissipation " << settings_.dissipation << ") on top and floor alike";
  notes_.push_back(os.str());
  // The Hertz depth that carries the weight on the ball: the start is at zero depth, so the top
  // drops onto it and rings (Hunt-Crossley damping is proportional to the small depth rate).
  const double E_eff = settings_.stiffness / std::pow(2.0, 1.5);
  const double x0 = std::pow(3 * body_.M * scene_.gravity / (4 * E_eff * std::sqrt(body_.R)), 2.0 / 3.0);
  os.str("");
  os << "compliant contact: the top rests " << x0 / body_.R << " R deep on its ball and starts at zero depth";
  notes_.push_back(os.str());
  os.str("");
  os << "variable-step " << settings_.integrator << " integration to relative accuracy " << settings_.accuracy
     << " (Simbody's own step control; no time step)";
  notes_.push_back(os.str());
  const ContactSpec& c = scene_.contact;
  os.str("");
  switch (c.friction) {
    case FrictionLaw::Coulomb:
      os << "Coulomb friction as Simbody's law with static = dynamic = mu = " << c.mu
         << ", regularized below the transition velocity " << settings_.transition_velocity
         << ": a rolling contact creeps instead of sticking";
      break;
    case FrictionLaw::Gliding:
      os << "gliding friction -mu F_n v_C as Simbody's viscous friction coefficient " << c.mu
         << " (static and dynamic 0), F_n the Hunt-Crossley normal force, in Simbody's own contact force";
      break;
    case FrictionLaw::Viscous:
      os << "viscous friction applied by the bench as a force element (Force::Custom, in Simbody's right-hand side) at "
            "the lowest point of each penetrating sphere; Simbody's contact friction 0";
      break;
    case FrictionLaw::Rolling:
      os << "rolling approximated by Coulomb friction with mu = " << settings_.rolling_mu << ", regularized below "
         << settings_.transition_velocity;
      break;
    case FrictionLaw::None: break;
  }
  if (!os.str().empty()) notes_.push_back(os.str());
  SimbodySettings unset = settings_;
  unset.static_friction = unset.dynamic_friction = unset.viscous_friction = -1.0;
  const SimbodyFriction law = simbody_friction(unset, c);
  if (law.us != friction_.us || law.ud != friction_.ud || law.uv != friction_.uv) {
    os.str("");
    os << "friction coefficients set in [engines.simbody] in place of the scene's law: static " << friction_.us
       << ", dynamic " << friction_.ud << ", viscous " << friction_.uv;
    notes_.push_back(os.str());
  }
  if (c.drilling > 0)
    notes_.push_back("drilling friction NOT modelled: Simbody's Hertz contact has no torsional friction, so this run "
                     "is of the scene without it (contact.drilling ignored)");
  const BodyModel& m = body_;
  if (m.stem && scene_.body.truncation_height > 0 && scene_.body.truncation_height / m.R < (m.R - m.r) / m.l)
    notes_.push_back("ball modelled as a full sphere although its cut cap can reach the floor before the stem tip");
}

BodyState SimbodySimulator::read_state(const SimTK::State& s) const {
  BodyState x;
  x.t = s.getTime();
  const SimTK::Transform& X = top_.getBodyTransform(s);
  x.p_WG = to_eigen(X.p());
  const SimTK::Quaternion q = X.R().convertRotationToQuaternion();
  x.q_WB = Quat(q[0], q[1], q[2], q[3]).normalized();
  // The body origin is G: the spatial velocity's linear part is v_G.
  const SimTK::SpatialVec& V = top_.getBodyVelocity(s);
  x.v_WG = to_eigen(V[1]);
  x.w_B = x.q_WB.conjugate() * to_eigen(V[0]);
  return x;
}

template <class F>
void SimbodySimulator::for_each_contact_force(const SimTK::State& s, F f) const {
  const int n = contact_.getNumContactForces(s);
  const SimTK::ContactSnapshot& active = tracker_.getActiveContacts(s);
  for (int i = 0; i < n; ++i) {
    const SimTK::ContactForce& cf = contact_.getContactForce(s, i);
    const SimTK::Contact& c = active.getContactById(cf.getContactId());
    // The force on the top: on surface 2 as reported, or its negative when the top is surface 1.
    const bool top_second = c.getSurface2() == ball_surface_ || (stem_surface_.isValid() && c.getSurface2() == stem_surface_);
    const SimTK::ContactSurfaceIndex mine = top_second ? c.getSurface2() : c.getSurface1();
    f(cf, SimTK::SpatialVec((top_second ? 1.0 : -1.0) * cf.getForceOnSurface2()), stem_surface_.isValid() && mine == stem_surface_);
  }
}

ContactReport SimbodySimulator::read_contacts(const SimTK::State& s) const {
  ContactReport r;
  Eigen::Vector3d moment = Eigen::Vector3d::Zero();
  for_each_contact_force(s, [&](const SimTK::ContactForce& f, const SimTK::SpatialVec& F, bool on_stem) {
    const double f_n = F[1][2];
    (on_stem ? r.stem : r.ball) = true;
    r.normal_force += f_n;
    (on_stem ? r.normal_force_stem : r.normal_force_ball) += f_n;
    moment += f_n * to_eigen(f.getContactPoint());
    // The compliant force law's force at the state (Ground frame = lab): its horizontal part is
    // the friction force.
    add_surface_force(r, on_stem, f_n, Vec3(F[1][0], F[1][1], 0.0), to_eigen(f.getContactPoint()));
  });
  finish_surface_points(r);
  if (friction_.bench_viscous)  // the bench's viscous force as ViscousContactForce evaluates it at this state
    for_each_viscous(top_.getBodyTransform(s), top_.getBodyVelocity(s), spheres_,
                     [&](size_t i, const SimTK::Vec3&, const SimTK::Vec3& v_C) {
                       (i == 1 ? r.friction_stem_W : r.friction_ball_W) += to_eigen(-scene_.contact.k * v_C);
                     });
  if (r.normal_force > 0) {
    r.point_valid = true;
    r.p_WC = moment / r.normal_force;
  }
  return r;
}

ContactPower SimbodySimulator::contact_power(const SimTK::State& s) const {
  ContactPower p;
  const SimTK::Transform& X = top_.getBodyTransform(s);
  const SimTK::SpatialVec& V = top_.getBodyVelocity(s);
  for_each_contact_force(s, [&](const SimTK::ContactForce& f, const SimTK::SpatialVec& F, bool) {
    const SimTK::Vec3 v_C = V[1] + V[0] % (f.getContactPoint() - X.p());
    p.normal += F[1][2] * v_C[2];
    p.friction += F[1][0] * v_C[0] + F[1][1] * v_C[1] + ~F[0] * V[0];
  });
  if (friction_.bench_viscous)  // ViscousContactForce's F = -k v_C at its point: power -k |v_C|^2
    for_each_viscous(X, V, spheres_, [&](size_t, const SimTK::Vec3&, const SimTK::Vec3& v_C) {
      p.friction += -scene_.contact.k * (~v_C * v_C);
    });
  return p;
}

std::pair<double, double> SimbodySimulator::ledger_work(const SimTK::State& s) const {
  if (!ledger_) return {0.0, 0.0};
  const SimTK::Vector& z = s.getZ(forces_.getMySubsystemIndex());
  return {z[ledger_->z()], z[ledger_->z() + 1]};
}

void SimbodySimulator::advance_to(double t) {
  while (checks_.ok() && integ_->getTime() < t) {
    // A signal ends the run within one of its steps (one relaxed atomic load each).
    poll_stop();
    const double before = integ_->getTime();
    try {
      const auto why = integ_->stepTo(t);
      if (why == SimTK::Integrator::EndOfSimulation) {
        checks_.fail(RunStatus::Failed, integ_->getTime(), "Simbody ended the integration");
        return;
      }
    } catch (const std::exception& e) {
      // Simbody throws when it cannot reach its accuracy (step below its minimum, a
      // realization that fails): a run that ends, not a crash.
      checks_.fail(RunStatus::Failed, integ_->getTime(), std::string("Simbody: ") + e.what());
      return;
    }
    if (integ_->getTime() > before) after_step();
  }
}

// The checks every engine gets (engines/core/step_checks.h), after each accepted step.
void SimbodySimulator::after_step() {
  ++work_.steps;
  const SimTK::State& s = integ_->getState();
  report_ = read_contacts(s);
  const std::pair<double, double> w = ledger_work(s);
  report_.step_work.set = ledger_ != nullptr;
  report_.step_work.normal = w.first - ledger_last_.first;
  report_.step_work.friction = w.second - ledger_last_.second;
  ledger_last_ = w;
  checks_.after_step(s.getTime(), read_state(s), report_);
}

Observation SimbodySimulator::observe() const { return observe_with_contacts(body_, state(), report_); }

void SimbodySimulator::set_state(const BodyState& x) {
  check_settable_state("simbody", x);
  using namespace SimTK;
  const Quat q = x.q_WB.normalized();
  State s = integ_->getState();
  top_.setQToFitTransform(s, Transform(Rotation(Quaternion(q.w(), q.x(), q.y(), q.z())), to_simtk(x.p_WG)));
  top_.setUToFitVelocity(s, SpatialVec(to_simtk(q * x.w_B), to_simtk(x.v_WG)));
  system_.realize(s, Stage::Velocity);
  // A new initial value problem from here: the integrator restarts (its counters with it, so
  // they are carried over).
  realizations_before_ += integ_->getNumRealizations();
  iterations_before_ += integ_->getNumIterations();
  if (ledger_) ledger_->zero_weights(s);
  integ_->initialize(s);
  report_ = read_contacts(integ_->getState());
  ledger_last_ = ledger_work(integ_->getState());
  checks_.restart(read_state(integ_->getState()));
}

WorkCounters SimbodySimulator::work() const {
  WorkCounters w = work_;
  w.rhs_evaluations = realizations_before_ + integ_->getNumRealizations();
  w.solver_iterations = iterations_before_ + integ_->getNumIterations();
  return w;
}

MassReadback SimbodySimulator::mass_properties() const {
  const SimTK::MassProperties& mp = top_.getBodyMassProperties(integ_->getState());
  MassReadback r;
  r.mass = mp.getMass();
  r.p_GCm_B = to_eigen(mp.getMassCenter());
  // Simbody's inertia is about the body origin, G.
  const SimTK::Mat33 I = mp.calcInertia().toMat33();
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) r.I_G_B(i, j) = I(i, j);
  return r;
}

void check_combination(const SimbodySettings& s, const Scene& scene) {
  const SimbodyFriction f = simbody_friction(s, scene.contact);
  if (f.us < f.ud)
    throw std::invalid_argument("engines.simbody.static_friction: " + round_trip_text(f.us) +
                                " below the dynamic friction " + round_trip_text(f.ud) + " (Simbody needs static >= dynamic)");
}

}  // namespace

std::unique_ptr<Simulator> make_simbody_simulator(const Scene& scene) {
  check_combination(read_settings<SimbodySettings>("simbody", scene), scene);
  return std::make_unique<SimbodySimulator>(scene);
}

const EngineInfo& simbody_engine_info() {
  static const EngineInfo info = [] {
    EngineInfo e;
    e.name = "simbody";
    e.role = EngineRole::Engine;
    e.make = make_simbody_simulator;
    set_settings_struct<SimbodySettings>(e, [](const SimbodySettings& s, const Scene& scene) { check_combination(s, scene); });
    e.version = simbody_version();
    e.colour = "#56B4E9";  // Okabe-Ito sky blue
    // Simbody's cost knob is its error control's accuracy, not a step; the integrator decides
    // what that accuracy buys (RK-Merson and RK3 explicit, CPodes implicit for a stiff contact).
    e.advice_axes = {{"integrator", {"\"rk_merson\"", "\"rk3\"", "\"cpodes\""}}};
    e.cost_knob = "accuracy";
    return e;
  }();
  return info;
}

}  // namespace tippe

// The module's one exported symbol, tippe_engine_simbody: the registry's way in (registry.h).
TIPPE_ENGINE_ENTRY_POINT(simbody)
