// Siconos 4.4 adapter: the top as a Newton-Euler body with unilateral Coulomb contacts (ball, stem tip) on the floor, Moreau-Jean time-stepping.
//
// Event-capturing nonsmooth time-stepping: each step of h solves one friction contact problem
// on the impulses (Signorini, Newton's impact law with restitution 0 as the reference's plastic
// impacts, Coulomb's cone), with no compliance and no regularization: a contact sticks exactly,
// an impact is an impulse. The contacts are the kernel's own NewtonEuler3DR relations
// (siconos_contact.h), not Siconos' mechanics library (whose single-precision Bullet would meet
// the Bullet adapter's double-precision one in this binary). The checks every engine gets
// (events, divergence, penetration) run after each step, as for every engine (engines/core/step_checks.h).
#include <SiconosKernel.hpp>
#include <SolverOptions.h>
#include <Friction_cst.h>

#include <dlfcn.h>

#include <algorithm>
#include <cmath>
#include <exception>
#include <memory>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "analytic/initial_state.h"
#include "analytic/stop_request.h"
#include "engines/core/bench_friction.h"
#include "engines/core/step_checks.h"
#include "engines/core/registry.h"
#include "engines/core/settings.h"
#include "engines/siconos/siconos_contact.h"
#include "engines/siconos/siconos_settings.h"

namespace tippe {
namespace {

// Debian's libsiconos-kernel-dev 4.4.0; the headers carry no version macro.
std::string siconos_version() { return "siconos 4.4.0"; }

// Siconos' numerics calls BLAS and LAPACK on the contact problem's few-by-few blocks. Debian's
// OpenBLAS (pthread build) starts a thread team for them: a step of this body then costs 2.5 to
// 5 times its single-thread wall time (1 s of leine_glocker at h = 1e-4: 0.95 s wall with one
// thread, 4.8 s with the default, on two busy cores). One thread, set once, through the symbol
// when the BLAS in the process is OpenBLAS (process-wide; only the speed of BLAS calls changes).
void single_threaded_blas() {
  static const bool done = [] {
    using SetThreads = void (*)(int);
    if (auto f = reinterpret_cast<SetThreads>(dlsym(RTLD_DEFAULT, "openblas_set_num_threads"))) f(1);
    return true;
  }();
  (void)done;
}

int solver_id(const std::string& s) {
  if (s == "nsn_ac") return SICONOS_FRICTION_3D_NSN_AC;
  if (s == "prox") return SICONOS_FRICTION_3D_PROX;
  return SICONOS_FRICTION_3D_NSGS;
}

class SiconosSimulator : public CheckedSimulator {
 public:
  explicit SiconosSimulator(const Scene& scene);
  // Siconos' integrators and one-step problems hold the simulation that holds them, and the
  // integrator the graph of dynamical systems whose properties hold the integrator (shared_ptr
  // cycles; Simulation.hpp documents the first): without breaking them every run leaked its
  // whole Siconos world (32 KB in 664 allocations per run under LeakSanitizer).
  ~SiconosSimulator() override;

  std::string engine() const override { return "siconos"; }
  std::string version() const override { return siconos_version(); }
  void advance_to(double t) override;
  Observation observe() const override;
  BodyState state() const override { return read_state(); }
  void set_state(const BodyState& x) override;
  MassReadback mass_properties() const override;
  WorkCounters work() const override { return work_; }
  SettingsList settings() const override { return list_settings(settings_); }
  EngineContactForces contact_forces() const override { return tippe::contact_forces(report_); }
  std::vector<std::string> notes() const override;

 private:
  double time() const { return static_cast<double>(n_steps_) * settings_.timestep; }
  BodyState read_state() const;
  ContactReport read_contacts() const;
  void bench_forces();
  void step_once();
  void make_notes();

  Scene scene_;
  BodyModel body_;
  SiconosSettings settings_;
  std::vector<std::string> notes_;

  SP::NewtonEulerDS top_;
  SP::SiconosVector f_ext_, m_ext_;  // lab frame: gravity plus the bench's forces of the step
  SP::Interaction ball_, stem_;
  SP::FrictionContact osnspb_;
  SP::TimeStepping sim_;

  long long n_steps_ = 0;
  WorkCounters work_;
  // Steps whose one-step problem ended above its tolerance, or whose Newton loop ended at its
  // iteration limit: Siconos goes on with the last iterate, so the run says how often.
  long long solver_unconverged_ = 0, newton_unconverged_ = 0;
  double worst_residual_ = 0.0;
  ContactReport report_;
  BenchFrictionForces bench_applied_;  // the bench's viscous or gliding force of the last step
  BenchFrictionForces bench_before_;   // ... of the step before (Moreau-Jean's f(t_n))
};

SiconosSimulator::SiconosSimulator(const Scene& scene)
    : CheckedSimulator(scene),
      scene_(scene),
      body_(BodyModel::from_scene(scene)),
      settings_(read_settings<SiconosSettings>("siconos", scene)) {
  const BodyModel& m = body_;
  if (!(m.M > 0 && m.A > 0 && m.C > 0 && m.R > 0) || (m.stem && !(m.r > 0 && m.l >= 0)))
    throw std::invalid_argument("siconos: needs M, A, C, R > 0 (and r > 0, l >= 0 with a stem)");
  const BodyState x0 = scene_initial_state(scene);
  single_threaded_blas();

  // The body: coordinates (G; quaternion w, x, y, z of B in W), twist (v_G in W; w in B, Siconos'
  // convention for NewtonEulerDS), the scene's mass and principal inertia about G (never computed
  // from shapes).
  auto q = std::make_shared<SiconosVector>(7);
  auto v = std::make_shared<SiconosVector>(6);
  const Quat q0 = x0.q_WB.normalized();
  const double qv[7] = {x0.p_WG.x(), x0.p_WG.y(), x0.p_WG.z(), q0.w(), q0.x(), q0.y(), q0.z()};
  for (int i = 0; i < 7; ++i) q->setValue(i, qv[i]);
  for (int i = 0; i < 3; ++i) {
    v->setValue(i, x0.v_WG(i));
    v->setValue(3 + i, x0.w_B(i));
  }
  auto inertia = std::make_shared<SimpleMatrix>(3, 3);
  inertia->zero();
  inertia->setValue(0, 0, m.A);
  inertia->setValue(1, 1, m.A);
  inertia->setValue(2, 2, m.C);
  top_ = std::make_shared<NewtonEulerDS>(q, v, m.M, inertia);
  f_ext_ = std::make_shared<SiconosVector>(3);
  m_ext_ = std::make_shared<SiconosVector>(3);
  f_ext_->zero();
  m_ext_->zero();
  f_ext_->setValue(2, -m.M * scene.gravity);
  top_->setFExtPtr(f_ext_);
  top_->setMExtPtr(m_ext_);
  top_->setIsMextExpressedInInertialFrame(true);

  auto nsds = std::make_shared<NonSmoothDynamicalSystem>(0.0, 1e300);
  nsds->insertDynamicalSystem(top_);
  // Newton's impact law with restitution 0 (normal and tangential): the reference's impacts are
  // plastic. One law for both contacts, Coulomb's cone of the scene's mu (0 for the laws the bench
  // applies itself).
  auto law = std::make_shared<NewtonImpactFrictionNSL>(0.0, 0.0, native_mu(scene.contact, settings_.rolling_mu), 3);
  ball_ = std::make_shared<Interaction>(law, std::make_shared<SphereOnFloorR>(0.0, 0.0, m.z_O(), m.R));
  nsds->link(ball_, top_);
  if (m.stem) {
    stem_ = std::make_shared<Interaction>(law, std::make_shared<SphereOnFloorR>(0.0, 0.0, m.z_P(), m.r));
    nsds->link(stem_, top_);
  }

  auto osi = settings_.gamma >= 0 ? std::make_shared<MoreauJeanOSI>(settings_.theta, settings_.gamma)
                                  : std::make_shared<MoreauJeanOSI>(settings_.theta);
  osi->setConstraintActivationThreshold(settings_.activation_margin * m.R);
  auto td = std::make_shared<TimeDiscretisation>(0.0, settings_.timestep);
  osnspb_ = std::make_shared<FrictionContact>(3, solver_id(settings_.solver));
  osnspb_->numericsSolverOptions()->iparam[SICONOS_IPARAM_MAX_ITER] = settings_.max_iterations;
  osnspb_->numericsSolverOptions()->dparam[SICONOS_DPARAM_TOL] = settings_.tolerance;
  sim_ = std::make_shared<TimeStepping>(nsds, td, osi, osnspb_);
  sim_->setNewtonTolerance(settings_.newton_tolerance);
  sim_->setNewtonMaxIteration(settings_.newton_max_iterations);
  sim_->initialize();

  // Moreau-Jean's impulse acts through the relations evaluated at q_n+1, whose contact points
  // read_contacts reports.
  checks_.set_impulse_at_step_end();
  checks_.start(read_state());
  make_notes();
}

SiconosSimulator::~SiconosSimulator() {
  if (!sim_) return;
  for (const SP::OneStepIntegrator& osi : *sim_->oneStepIntegrators()) {
    osi->setSimulationPtr(SP::Simulation());
    osi->setDynamicalSystemsGraph(SP::DynamicalSystemsGraph());
  }
  if (osnspb_) osnspb_->setSimulationPtr(SP::Simulation());
  sim_->clear();
}

void SiconosSimulator::make_notes() {
  std::ostringstream os;
  os << "nonsmooth Moreau-Jean time-stepping, h = " << settings_.timestep << ", theta = " << settings_.theta
     << ": rigid unilateral contacts, Newton impacts with restitution 0, one friction contact problem per step ("
     << settings_.solver << ", tolerance " << settings_.tolerance << ")";
  notes_.push_back(os.str());
  const ContactSpec& c = scene_.contact;
  os.str("");
  switch (c.friction) {
    case FrictionLaw::Coulomb: os << "Coulomb friction mu = " << c.mu << " in Siconos' 3D cone (exact sticking)"; break;
    case FrictionLaw::Rolling:
      os << "rolling approximated by Coulomb friction with mu = " << settings_.rolling_mu << " (exact sticking below the cone)";
      break;
    case FrictionLaw::Viscous:
      os << "viscous friction applied by the bench as an external force (NewtonEulerDS fExt, mExt) at the geometric "
            "contact point, held over each step from the state at its start; Siconos contacts frictionless";
      break;
    case FrictionLaw::Gliding:
      os << "gliding friction -mu F_n v_C applied by the bench as an external force (NewtonEulerDS fExt, mExt) at each "
            "geometric contact point, F_n per contact from Siconos' previous step (its impulse / h, explicit); "
            "Siconos contacts frictionless";
      break;
    case FrictionLaw::None: break;
  }
  if (!os.str().empty()) notes_.push_back(os.str());
  if (c.drilling > 0)
    notes_.push_back("drilling friction NOT modelled: Siconos' 3D friction contact has no torsional friction (its 5D "
                     "rolling-friction contact adds rolling resistance, not drilling), so this run is of the scene "
                     "without it (contact.drilling ignored)");
  const BodyModel& m = body_;
  if (m.stem && scene_.body.truncation_height > 0 && scene_.body.truncation_height / m.R < (m.R - m.r) / m.l)
    notes_.push_back("ball modelled as a full sphere although its cut cap can reach the floor before the stem tip");
}

std::vector<std::string> SiconosSimulator::notes() const {
  std::vector<std::string> n = notes_;
  if (solver_unconverged_ > 0) {
    std::ostringstream os;
    os << "the one-step problem did not reach its tolerance " << settings_.tolerance << " in " << solver_unconverged_
       << " of " << n_steps_ << " steps (largest residual " << worst_residual_ << "; raise max_iterations or the tolerance)";
    n.push_back(os.str());
  }
  if (newton_unconverged_ > 0) {
    std::ostringstream os;
    os << "the Newton loop stopped at newton_max_iterations = " << settings_.newton_max_iterations << " in "
       << newton_unconverged_ << " of " << n_steps_ << " steps";
    n.push_back(os.str());
  }
  return n;
}

BodyState SiconosSimulator::read_state() const {
  const SiconosVector& q = *top_->q();
  const SiconosVector& v = *top_->twist();
  BodyState x;
  x.t = time();
  x.p_WG = Vec3(q.getValue(0), q.getValue(1), q.getValue(2));
  x.q_WB = Quat(q.getValue(3), q.getValue(4), q.getValue(5), q.getValue(6)).normalized();
  x.v_WG = Vec3(v.getValue(0), v.getValue(1), v.getValue(2));
  x.w_B = Vec3(v.getValue(3), v.getValue(4), v.getValue(5));
  return x;
}

// A contact is what carried an impulse in the last step (Siconos resets every multiplier at the
// start of a step; an inactive or separating contact ends it at 0). Force = impulse / h.
ContactReport SiconosSimulator::read_contacts() const {
  ContactReport r;
  if (n_steps_ == 0) return r;
  Vec3 moment = Vec3::Zero();
  for (const SP::Interaction& inter : {ball_, stem_}) {
    if (!inter) continue;
    const double p_n = inter->lambda(1) ? inter->lambda(1)->getValue(0) : 0.0;
    if (!(p_n > 0)) continue;
    const double f_n = p_n / settings_.timestep;
    const bool on_stem = inter == stem_;
    (on_stem ? r.stem : r.ball) = true;
    (on_stem ? r.normal_force_stem : r.normal_force_ball) += f_n;
    r.normal_force += f_n;
    const auto rel = std::static_pointer_cast<NewtonEuler1DR>(inter->relation());
    const SiconosVector& pc = *rel->pc1();
    moment += f_n * Vec3(pc.getValue(0), pc.getValue(1), pc.getValue(2));
    // The impulse in the contact frame (normal, two tangents) over h, turned into the lab frame by
    // the transpose of the relation's lab-to-contact rotation; its horizontal part is friction.
    const SiconosVector& p = *inter->lambda(1);
    const SimpleMatrix& R = std::static_pointer_cast<SphereOnFloorR>(inter->relation())->abs_to_contact();
    Vec3 f_W = Vec3::Zero();
    for (int i = 0; i < 3; ++i)
      for (int k = 0; k < 3; ++k) f_W(i) += R.getValue(k, i) * p.getValue(k) / settings_.timestep;
    add_surface_force(r, on_stem, f_n, Vec3(f_W.x(), f_W.y(), 0.0), Vec3(pc.getValue(0), pc.getValue(1), pc.getValue(2)));
  }
  finish_surface_points(r);
  if (r.normal_force > 0) {
    r.point_valid = true;
    r.p_WC = moment / r.normal_force;
  }
  return r;
}

// The bench's viscous and gliding laws (engines/core/bench_friction.h), held over the step from
// the state at its start, as the fixed-step engines apply them; gravity is the rest of fExt.
void SiconosSimulator::bench_forces() {
  if (!bench_applies_friction(scene_.contact.friction)) return;
  const BenchFrictionForces bf = bench_friction_forces(body_, scene_.contact, checks_.last_state(), report_);
  bench_applied_ = bf;
  Vec3 f = Vec3::Zero(), mo = Vec3::Zero();
  for (int i = 0; i < bf.n; ++i) {
    f += bf.f_W[i];
    mo += bf.r_GC_W[i].cross(bf.f_W[i]);
  }
  f_ext_->setValue(0, f.x());
  f_ext_->setValue(1, f.y());
  f_ext_->setValue(2, f.z() - body_.M * scene_.gravity);
  for (int i = 0; i < 3; ++i) m_ext_->setValue(i, mo(i));
}

void SiconosSimulator::advance_to(double t) {
  // The same step budget as the fixed-step engines (kMaxEngineSteps): a run that would take more
  // steps ends failed before it starts them.
  if (!checks_.within_budget(std::max(t, scene_.run.duration), settings_.timestep, time())) return;
  // Steps whose end lies within half a step of t count as reaching t (as the fixed-step engines);
  // a signal ends the run within kStepsPerStopPoll steps.
  while (checks_.ok() && (static_cast<double>(n_steps_) + 0.5) * settings_.timestep <= t) {
    if (n_steps_ % kStepsPerStopPoll == 0) poll_stop();
    step_once();
  }
}

void SiconosSimulator::step_once() {
  bench_forces();
  try {
    sim_->computeOneStep();
    sim_->nextStep();
  } catch (const Siconos::exception& e) {
    // A singular matrix or a failed solve inside Siconos: a run that ends, not a crash.
    const std::string* why = boost::get_error_info<Siconos::exception::extra_message>(e);
    return checks_.fail(RunStatus::Failed, time(), "Siconos: " + (why ? *why : std::string(e.what())));
  } catch (const std::exception& e) {
    return checks_.fail(RunStatus::Failed, time(), std::string("Siconos: ") + e.what());
  }
  ++n_steps_;
  work_.steps = work_.rhs_evaluations = n_steps_;
  const SolverOptions& so = *osnspb_->numericsSolverOptions();
  work_.solver_iterations += so.iparam[SICONOS_IPARAM_ITER_DONE];
  // The residual of the last solve (0 when no contact was active).
  if (so.dparam[SICONOS_DPARAM_RESIDU] > settings_.tolerance) {
    ++solver_unconverged_;
    worst_residual_ = std::max(worst_residual_, so.dparam[SICONOS_DPARAM_RESIDU]);
  }
  if (sim_->getNewtonNbIterations() >= static_cast<unsigned>(settings_.newton_max_iterations)) ++newton_unconverged_;
  const double t = time();
  report_ = with_bench_friction(read_contacts(), bench_applied_);
  // Moreau-Jean integrates the external forces as theta f(t_n+1) + (1 - theta) f(t_n), f(t_n) the
  // one held over the previous step: the bench's force acted as that mean, which the ledger books.
  // (Booked as this step's force alone, the stem's first viscous force after its touchdown on
  // toy_viscous was twice the energy it removed: 3.6e-3 E0 in one step.)
  StepMeanForces& mean = report_.step_mean;
  add_stage_forces(mean, report_, 1.0, Vec3::Zero());
  finish_stage_forces(mean);
  // The report holds this step's force once (weight 1): theta - 1 more of it makes theta.
  add_bench_friction_mean(mean, bench_applied_, settings_.theta - 1.0);
  add_bench_friction_mean(mean, bench_before_, 1.0 - settings_.theta);
  bench_before_ = bench_applied_;
  checks_.after_step(t, read_state(), report_);
}

Observation SiconosSimulator::observe() const { return observe_with_contacts(body_, state(), report_); }

void SiconosSimulator::set_state(const BodyState& x) {
  check_settable_state("siconos", x);
  const Quat q = x.q_WB.normalized();
  SiconosVector& qs = *top_->q();
  SiconosVector& vs = *top_->twist();
  const double qv[7] = {x.p_WG.x(), x.p_WG.y(), x.p_WG.z(), q.w(), q.x(), q.y(), q.z()};
  for (int i = 0; i < 7; ++i) qs.setValue(i, qv[i]);
  for (int i = 0; i < 3; ++i) {
    vs.setValue(i, x.v_WG(i));
    vs.setValue(3 + i, x.w_B(i));
  }
  // Moreau-Jean starts each step from the body's memory of the last step end: the new state
  // replaces it (and the quaternion's kinematic matrix T follows q). The contacts' gaps and
  // normal velocities, and from them the set of contacts the next step activates, are those of
  // the old state until recomputed: without this the first step after a jump onto the floor
  // would not see the contact (measured: an impact state set and stepped once kept its energy).
  top_->computeT();
  top_->swapInMemory();
  try {
    sim_->updateOutput(0);
    sim_->updateOutput(1);
    for (const SP::Interaction& inter : {ball_, stem_})
      if (inter) inter->swapInMemory();
    sim_->updateIndexSets();
  } catch (const std::exception& e) {
    throw std::invalid_argument(std::string("siconos: set_state: ") + e.what());
  }
  checks_.restart(read_state());
}

MassReadback SiconosSimulator::mass_properties() const {
  MassReadback r;
  r.mass = top_->scalarMass();
  // NewtonEulerDS's body frame is at G (its q is G's position): no offset.
  const SiconosMatrix& I = *top_->inertia();
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) r.I_G_B(i, j) = I.getValue(i, j);
  return r;
}

}  // namespace

std::unique_ptr<Simulator> make_siconos_simulator(const Scene& scene) { return std::make_unique<SiconosSimulator>(scene); }

const EngineInfo& siconos_engine_info() {
  static const EngineInfo info = [] {
    EngineInfo e;
    e.name = "siconos";
    e.role = EngineRole::Engine;
    e.make = make_siconos_simulator;
    set_settings_struct<SiconosSettings>(e);
    e.version = siconos_version();
    e.colour = "#000000";  // Okabe-Ito black (its other colours are taken)
    // The one-step problem's solver (nonsmooth Gauss-Seidel, semismooth Newton, proximal point)
    // and Moreau-Jean's theta (0.5 trapezoidal, 1 implicit Euler); the step is the cost knob.
    e.advice_axes = {{"solver", {"\"nsgs\"", "\"nsn_ac\""}}, {"theta", {"0.5", "1"}}};
    e.cost_knob = "timestep";
    return e;
  }();
  return info;
}

}  // namespace tippe

// The module's one exported symbol, tippe_engine_siconos: the registry's way in (registry.h).
TIPPE_ENGINE_ENTRY_POINT(siconos)
