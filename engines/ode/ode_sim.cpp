// ODE 0.16 (double) adapter: one dBody at G carrying a ball and a stem geom on a plane, stepped by the shared fixed-step loop.
#include "engines/ode/ode_sim.h"
#include "engines/ode/ode_settings.h"

#include <ode/ode.h>
#include <ode/version.h>

#include <climits>
#include <cstdarg>
#include <cstdio>
#include <limits>
#include <mutex>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "engines/core/adapters.h"
#include "engines/core/fixed_step.h"
#include "engines/core/registry.h"
#include "engines/core/settings.h"

// LeakSanitizer (part of ASan): present in sanitizer builds (scripts/sanitize.sh) only.
#if defined(__SANITIZE_ADDRESS__)
#define TIPPE_HAVE_LSAN 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer) || __has_feature(leak_sanitizer)
#define TIPPE_HAVE_LSAN 1
#endif
#endif
#ifdef TIPPE_HAVE_LSAN
#include <sanitizer/lsan_interface.h>
#endif

namespace tippe {
namespace {

// ODE reports internal errors through dError/dDebug, which exit(1) or abort() after the
// handler returns: the whole harness, with every other run in it, would die with one engine.
// The handler throws instead; engine_step turns that into a diverged run.
struct OdeInternalError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

void throw_ode_error(int num, const char* msg, va_list ap) {
  char text[512];
  std::vsnprintf(text, sizeof text, msg, ap);
  throw OdeInternalError("ODE internal error " + std::to_string(num) + ": " + text);
}

// dInitODE2 once per process; per-thread ODE data in every thread that touches a world.
// Without dInitFlagManualThreadCleanup ODE frees thread data itself on thread exit (and
// forbids dCleanupODEAllDataForThread), so nothing is released here.
void ode_thread_init() {
  static std::once_flag once;
  std::call_once(once, [] {
    if (!dInitODE2(0)) throw std::runtime_error("ode: dInitODE2 failed");
    dSetErrorHandler(&throw_ode_error);
    dSetDebugHandler(&throw_ode_error);
  });
  thread_local bool allocated = false;
  if (!allocated) {
    if (!dAllocateODEDataForThread(dAllocateMaskAll))
      throw std::runtime_error("ode: dAllocateODEDataForThread failed");
    allocated = true;
  }
}

void keep_deliberately_leaked(const void* p) {
#ifdef TIPPE_HAVE_LSAN
  if (p) __lsan_ignore_object(p);
#else
  (void)p;
#endif
}

// Owns one simulator's ODE objects; a member, so that they are released even when the
// simulator's constructor throws half way.
struct OdeWorld {
  dWorldID world = nullptr;
  dSpaceID space = nullptr;
  dJointGroupID contact_group = nullptr;
  dBodyID body = nullptr;
  // ODE's process-wide default threading object is not safe for worlds stepped in parallel
  // (observed: "ODE INTERNAL ERROR 1: assertion current_job->m_prev_job_next_ptr == NULL" with
  // two simulators on two threads; objects.h warns the same): each world gets its own.
  dThreadingImplementationID threading = nullptr;
  // After an internal error thrown through a step, ODE's job lists are left mid-use and its
  // destructors assert (observed: "m_job_list == NULL" in ~dxtemplateJobListContainer, fatal
  // because it fires inside a destructor): such a world is leaked (~150 kB, mostly its step
  // memory arena) instead.
  bool leak = false;

  OdeWorld() = default;
  OdeWorld(const OdeWorld&) = delete;
  OdeWorld& operator=(const OdeWorld&) = delete;
  ~OdeWorld() {
    if (leak) {
      // The leak is the decision above, not a bug: the leak checker is told so (it treats what
      // these objects reach as reachable), and still reports any world leaked by mistake.
      for (const void* p : {static_cast<const void*>(world), static_cast<const void*>(space),
                            static_cast<const void*>(contact_group), static_cast<const void*>(body),
                            static_cast<const void*>(threading)})
        keep_deliberately_leaked(p);
      return;
    }
    try {
      ode_thread_init();  // in case the simulator dies on another thread than it was built on
    } catch (...) {
    }
    if (contact_group) dJointGroupDestroy(contact_group);
    // Destroying the space destroys the geoms it holds (its cleanup mode is on by default).
    if (space) dSpaceDestroy(space);
    if (body) dBodyDestroy(body);
    if (world) {
      dWorldSetStepThreadingImplementation(world, nullptr, nullptr);
      dWorldDestroy(world);
    }
    if (threading) dThreadingFreeImplementation(threading);
  }
};

class OdeSimulator : public FixedStepSimulator {
 public:
  explicit OdeSimulator(const Scene& scene);
  OdeSimulator(const OdeSimulator&) = delete;
  OdeSimulator& operator=(const OdeSimulator&) = delete;

  SettingsList settings() const override { return list_settings(settings_); }

  OdeMassReadback mass_readback() const;
  MassReadback mass_properties() const override {
    const OdeMassReadback r = mass_readback();
    // dMass's c is the centre of mass relative to the body origin, which is built at G.
    return {r.mass, r.c_B, r.I_B};
  }

 protected:
  void engine_step() override;
  BodyState engine_state() const override;
  void engine_set_state(const BodyState& x) override;
  void apply_force_W(const Vec3& f_W, const Vec3& p_W) override;

 private:
  struct ContactRecord {
    dJointFeedback feedback{};
    Vec3 p_W = Vec3::Zero();
    bool stem = false;
  };
  static void near_callback(void* self, dGeomID a, dGeomID b);
  void collide_pair(dGeomID a, dGeomID b);
  dSurfaceParameters make_surface() const;
  void make_notes();

  OdeSettings settings_;
  OdeWorld ode_;
  // Aliases of ode_'s handles, for brevity.
  dWorldID world_ = nullptr;
  dSpaceID space_ = nullptr;
  dJointGroupID contact_group_ = nullptr;
  dBodyID body_ = nullptr;
  dGeomID floor_ = nullptr, ball_ = nullptr, stem_ = nullptr;
  dSurfaceParameters surface_{};
  // Sized once so that the dJointFeedback addresses handed to ODE stay valid during a step.
  std::vector<ContactRecord> contacts_;
  size_t n_contacts_ = 0;
  std::vector<dContactGeom> scratch_;
  bool failed_ = false;  // ODE raised an internal error: the state is reported as NaN
};

OdeSimulator::OdeSimulator(const Scene& scene)
    : FixedStepSimulator(scene, ode_engine_info()), settings_(read_settings<OdeSettings>("ode", scene)) {
  check_combination(settings_, scene);
  ode_thread_init();
  // dReal is double by this build's headers; the library must agree or every call is garbage.
  if (!dCheckConfiguration("ODE_double_precision"))
    throw std::runtime_error(std::string("ode: library is not double precision: ") + dGetConfiguration());
  const BodyModel& m = body();

  dRandSetSeed(static_cast<unsigned long>(settings_.seed));
  world_ = ode_.world = dWorldCreate();
  ode_.threading = dThreadingAllocateSelfThreadedImplementation();
  if (!ode_.threading) throw std::runtime_error("ode: dThreadingAllocateSelfThreadedImplementation failed");
  dWorldSetStepThreadingImplementation(world_, dThreadingImplementationGetFunctions(ode_.threading), ode_.threading);
  dWorldSetGravity(world_, 0, 0, -scene.gravity);
  dWorldSetERP(world_, settings_.erp);
  dWorldSetCFM(world_, settings_.cfm);
  dWorldSetQuickStepNumIterations(world_, settings_.iterations);
  // Set before dBodyCreate, which copies the world's auto-disable and damping defaults.
  dWorldSetAutoDisableFlag(world_, 0);
  dWorldSetLinearDamping(world_, 0);
  dWorldSetAngularDamping(world_, 0);
  dWorldSetMaxAngularSpeed(world_, dInfinity);
  dWorldSetContactSurfaceLayer(world_, settings_.surface_layer);
  // ODE's default, stated because a cap would change the contact law: no limit on the ERP
  // push-out speed.
  dWorldSetContactMaxCorrectingVel(world_, dInfinity);

  // A simple space collides in insertion order: deterministic and enough for three geoms.
  space_ = ode_.space = dSimpleSpaceCreate(nullptr);
  contact_group_ = ode_.contact_group = dJointGroupCreate(0);
  floor_ = dCreatePlane(space_, 0, 0, 1, 0);

  body_ = ode_.body = dBodyCreate(world_);
  dMass mass;
  dMassSetZero(&mass);
  // From the scene's mass properties, never from the geoms; ODE wants G at the body origin.
  dMassSetParameters(&mass, m.M, 0, 0, 0, m.A, m.A, m.C, 0, 0, 0);
  dBodySetMass(body_, &mass);
  dBodySetAutoDisableFlag(body_, 0);
  dBodySetMaxAngularSpeed(body_, dInfinity);
  dBodySetGyroscopicMode(body_, settings_.gyroscopic ? 1 : 0);
  dBodySetFiniteRotationMode(body_, settings_.finite_rotation ? 1 : 0);
  if (settings_.finite_rotation) dBodySetFiniteRotationAxis(body_, 0, 0, 0);

  // The ball is a full sphere about O = G + d e_Z: the cap cut at h is not modelled. Its lowest
  // point enters the cap only for cos(theta) < -h/R, where the stem tip is already lower
  // whenever h/R >= (R - r)/l; otherwise say so.
  ball_ = dCreateSphere(space_, m.R);
  dGeomSetBody(ball_, body_);
  dGeomSetOffsetPosition(ball_, 0, 0, m.z_O());
  if (m.stem) {
    if (settings_.stem_shape == "tip_sphere") {
      stem_ = dCreateSphere(space_, m.r);
      dGeomSetBody(stem_, body_);
      dGeomSetOffsetPosition(stem_, 0, 0, m.z_P());
    } else {
      // ODE capsules lie along local Z with `length` between the cap centres: O to P.
      stem_ = dCreateCapsule(space_, m.r, m.l);
      dGeomSetBody(stem_, body_);
      dGeomSetOffsetPosition(stem_, 0, 0, m.z_O() + 0.5 * m.l);
    }
  }

  const BodyState x0 = scene_initial_state(scene);
  // ODE's contact rests surface_layer deep: starting there, not at zero depth, spares the ~13
  // one-step contact losses (ball -> none -> ball) of the first 0.4 time units in which the
  // ball would otherwise sink into the layer by falling through them. A height change of
  // surface_layer (1e-6) against the shared initial state.
  dBodySetPosition(body_, x0.p_WG.x(), x0.p_WG.y(), x0.p_WG.z() - settings_.surface_layer);
  const Quat q = x0.q_WB.normalized();
  const dQuaternion q_ode = {q.w(), q.x(), q.y(), q.z()};
  dBodySetQuaternion(body_, q_ode);
  dBodySetLinearVel(body_, x0.v_WG.x(), x0.v_WG.y(), x0.v_WG.z());
  const Vec3 w_W = q * x0.w_B;
  dBodySetAngularVel(body_, w_W.x(), w_W.y(), w_W.z());

  surface_ = make_surface();
  make_notes();
  const size_t n_geoms = m.stem ? 2 : 1;
  contacts_.resize(n_geoms * static_cast<size_t>(settings_.max_contacts));
  scratch_.resize(static_cast<size_t>(settings_.max_contacts));

  // The contact normal row's spring (ODE's equivalence k_p = erp / (h cfm), acting on the depth
  // beyond the surface layer) is the elastic energy of the energy ledger only where the step
  // resolves it (omega h = sqrt(k_p / M) h <= 1): ODE integrates the equivalent spring-damper
  // implicitly, and a spring far stiffer than the step (the defaults: k_p = 2e12 M g / R, omega h
  // ~ 140) never holds k_p d^2 / 2; measured on toy_viscous, that formula gave 107 E0 at the stem's
  // touchdown while the top's energy fell by a fraction of E0. There the energy is not available.
  const double k_p = settings_.soft_erp / (settings_.timestep * settings_.soft_cfm);
  if (std::sqrt(k_p / m.M) * settings_.timestep <= 1.0) {
    ContactPotential spring;
    spring.k_ball = spring.k_stem = k_p;
    spring.exponent = 1.0;
    spring.offset = settings_.surface_layer;
    checks_.set_contact_potential(spring);
  }
  start(settings_.timestep);
}

dSurfaceParameters OdeSimulator::make_surface() const {
  const ContactSpec& c = scene().contact;
  dSurfaceParameters s{};
  const bool approx1 = settings_.friction_model == "approx1";
  s.mu = native_mu(settings_.rolling_mu);
  s.mode = dContactSoftERP | dContactSoftCFM;
  if (approx1) s.mode |= dContactApprox1_1 | dContactApprox1_2;
  s.soft_erp = settings_.soft_erp;
  s.soft_cfm = settings_.soft_cfm;
  s.bounce = 0;
  s.bounce_vel = 0;
  if (c.drilling > 0) {
    // ODE 0.16 (ode/src/joints/contact.cpp): rho2 and rhoN are read only with
    // dContactAxisDep (== dContactMu2); otherwise rho is used for all three angular rows.
    // Each row with rho_i > 0 bounds the torque about its axis (t1, t2, normal) by +-rho_i;
    // with dContactApprox1_N the spin bound becomes rhoN times the contact's normal force,
    // i.e. |tau| <= mu_d F_n with rhoN a length, the scene's drilling law. Rows with rho = 0
    // are not filled by getInfo2, so rolling resistance stays off.
    s.mode |= dContactRolling | dContactAxisDep | dContactApprox1_N;
    s.mu2 = s.mu;
    s.rho = 0;
    s.rho2 = 0;
    s.rhoN = c.drilling;
  }
  return s;
}

void OdeSimulator::make_notes() {
  const Scene& sc = scene();
  const bool approx1 = settings_.friction_model == "approx1";
  notes_ = friction_law_notes({"ODE", "", "ODE's previous step (joint feedback, explicit)",
                               approx1 ? " (coefficient, approx1)" : " (force bound, box)"},
                              settings_.rolling_mu);
  if (sc.contact.drilling > 0 && sc.contact.drilling_law == DrillingLaw::Coupled)
    notes_.push_back("drilling decoupled: ODE bounds the spin torque (rhoN, |tau| <= mu_d F_n) and the friction force in rows of "
                     "their own; the scene's coupled law bounds them jointly (Leine-Glocker ellipse), which ODE cannot "
                     "represent: this run is the decoupled law");
  if (!approx1 && (sc.contact.friction == FrictionLaw::Coulomb || sc.contact.friction == FrictionLaw::Rolling))
    notes_.push_back("friction_model = box: mu is a constant force bound per friction direction, not a coefficient");
  if (approx1 && sc.contact.friction == FrictionLaw::Coulomb)
    notes_.push_back("Coulomb friction as a box in two tangent directions (pyramid, not cone), bounds mu F_n from the same solve");
  if (settings_.stepper == "quickstep")
    notes_.push_back("quickstep: iterative solver, " + std::to_string(settings_.iterations) +
                     " iterations, random row order from ODE's process-wide seed");
  if (!settings_.finite_rotation) notes_.push_back("infinitesimal orientation update (finite_rotation = false)");
  if (!settings_.gyroscopic) notes_.push_back("gyroscopic term off (gyroscopic = false): not the top's physics");
  if (!full_sphere_note().empty()) notes_.push_back(full_sphere_note());
}

void OdeSimulator::near_callback(void* self, dGeomID a, dGeomID b) {
  static_cast<OdeSimulator*>(self)->collide_pair(a, b);
}

void OdeSimulator::collide_pair(dGeomID a, dGeomID b) {
  // Only body geom against floor: ball and stem share the body and never collide.
  dGeomID g = nullptr;
  if (a == floor_ && b != floor_) g = b;
  else if (b == floor_ && a != floor_) g = a;
  if (!g || (g != ball_ && g != stem_)) return;
  // Body geom first: ODE's normal then points into body 1, i.e. +z out of the floor, and
  // feedback f1 is the force on the top.
  const int n = dCollide(g, floor_, settings_.max_contacts, scratch_.data(), sizeof(dContactGeom));
  for (int i = 0; i < n && n_contacts_ < contacts_.size(); ++i) {
    dContact contact{};
    contact.surface = surface_;
    contact.geom = scratch_[static_cast<size_t>(i)];
    ContactRecord& rec = contacts_[n_contacts_++];
    rec.feedback = dJointFeedback{};
    rec.p_W = Vec3(contact.geom.pos[0], contact.geom.pos[1], contact.geom.pos[2]);
    rec.stem = g == stem_;
    const dJointID j = dJointCreateContact(world_, contact_group_, &contact);
    dJointAttach(j, body_, nullptr);
    dJointSetFeedback(j, &rec.feedback);
  }
}

void OdeSimulator::engine_step() {
  ode_thread_init();
  if (failed_) return;
  n_contacts_ = 0;
  const bool quick = settings_.stepper == "quickstep";
  int ok = 1;
  try {
    dSpaceCollide(space_, this, &OdeSimulator::near_callback);
    ok = quick ? dWorldQuickStep(world_, dt()) : dWorldStep(world_, dt());
  } catch (const OdeInternalError& e) {
    // Typically a NaN state (e.g. "!bSafeNormalize4Fault"): the base class sees the NaN
    // state and ends the run as diverged; the message is kept as a note.
    failed_ = true;
    ode_.leak = true;
    notes_.push_back(std::string(e.what()) + " at t = " + std::to_string(time() + dt()));
    report_ = ContactReport{};
    n_contacts_ = 0;
    return;
  }
  if (!ok && limit_.empty()) limit_ = std::string(quick ? "dWorldQuickStep" : "dWorldStep") + " failed (out of memory)";
  if (quick) solver_iterations_ += settings_.iterations;

  ContactReport r;
  Vec3 moment = Vec3::Zero();
  for (size_t i = 0; i < n_contacts_; ++i) {
    const ContactRecord& c = contacts_[i];
    (c.stem ? r.stem : r.ball) = true;
    // The floor normal is +z and the tangent rows are horizontal: f1.z is the normal force.
    const double f_n = c.feedback.f1[2];
    r.normal_force += f_n;
    (c.stem ? r.normal_force_stem : r.normal_force_ball) += f_n;
    moment += f_n * c.p_W;
    // f1 is in the lab frame: its horizontal part is the friction force of the tangent rows.
    add_surface_force(r, c.stem, f_n, Vec3(c.feedback.f1[0], c.feedback.f1[1], 0.0), c.p_W);
  }
  finish_surface_points(r);
  if (r.normal_force > 0) {
    r.point_valid = true;
    r.p_WC = moment / r.normal_force;
  }
  report_ = r;
  dJointGroupEmpty(contact_group_);
}

BodyState OdeSimulator::engine_state() const {
  BodyState x;
  x.t = time();
  if (failed_) {
    const double nan = std::numeric_limits<double>::quiet_NaN();
    x.p_WG = x.v_WG = x.w_B = Vec3::Constant(nan);
    x.q_WB = Quat(nan, nan, nan, nan);
    return x;
  }
  const dReal* p = dBodyGetPosition(body_);
  const dReal* v = dBodyGetLinearVel(body_);
  const dReal* q = dBodyGetQuaternion(body_);
  const dReal* w = dBodyGetAngularVel(body_);
  x.p_WG = Vec3(p[0], p[1], p[2]);
  x.v_WG = Vec3(v[0], v[1], v[2]);
  x.q_WB = Quat(q[0], q[1], q[2], q[3]).normalized();
  x.w_B = x.q_WB.conjugate() * Vec3(w[0], w[1], w[2]);
  return x;
}

void OdeSimulator::engine_set_state(const BodyState& x) {
  if (failed_) return;  // ODE's internal error left the world unusable: the state stays NaN
  dBodySetPosition(body_, x.p_WG.x(), x.p_WG.y(), x.p_WG.z());
  const dQuaternion q_ode = {x.q_WB.w(), x.q_WB.x(), x.q_WB.y(), x.q_WB.z()};
  dBodySetQuaternion(body_, q_ode);
  dBodySetLinearVel(body_, x.v_WG.x(), x.v_WG.y(), x.v_WG.z());
  const Vec3 w_W = x.q_WB * x.w_B;
  dBodySetAngularVel(body_, w_W.x(), w_W.y(), w_W.z());
}

void OdeSimulator::apply_force_W(const Vec3& f_W, const Vec3& p_W) {
  // ODE zeroes the force accumulators after each step: this acts for the next step only.
  dBodyAddForceAtPos(body_, f_W.x(), f_W.y(), f_W.z(), p_W.x(), p_W.y(), p_W.z());
}

OdeMassReadback OdeSimulator::mass_readback() const {
  dMass mass;
  dBodyGetMass(body_, &mass);
  OdeMassReadback r;
  r.mass = mass.mass;
  r.c_B = Vec3(mass.c[0], mass.c[1], mass.c[2]);
  // dMatrix3 is row-major with a row stride of 4.
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) r.I_B(i, j) = mass.I[4 * i + j];
  return r;
}

}  // namespace

OdeMassReadback ode_mass_readback(const Simulator& sim) {
  const auto* ode = dynamic_cast<const OdeSimulator*>(&sim);
  if (!ode) throw std::invalid_argument("ode_mass_readback: not an ODE simulator");
  return ode->mass_readback();
}

std::unique_ptr<Simulator> make_ode_simulator(const Scene& scene) {
  auto sim = std::make_unique<OdeSimulator>(scene);
  return sim;
}

void validate_ode_settings(const Scene& scene) { check_combination(read_settings<OdeSettings>("ode", scene), scene); }

const EngineInfo& ode_engine_info() {
  static const EngineInfo info = [] {
    EngineInfo e = engine_entry<OdeSettings>(  // Okabe-Ito blue
        "ode", EngineRole::Engine, make_ode_simulator, std::string("ode ") + dODE_VERSION, "#0072B2",
        [](const OdeSettings& s, const Scene& scene) { check_combination(s, scene); });
    // The step function (dWorldStep's exact LCP against quickstep's iterations) and the
    // orientation update (finite rotation, exact for a constant spin, or ODE's infinitesimal one).
    e.advice_axes = {{"stepper", {"\"step\"", "\"quickstep\""}}, {"finite_rotation", {"true", "false"}}};
    e.cost_knob = "timestep";
    return e;
  }();
  return info;
}

}  // namespace tippe

// The module's one exported symbol, tippe_engine_ode: the registry's way in (registry.h).
TIPPE_ENGINE_ENTRY_POINT(ode)
