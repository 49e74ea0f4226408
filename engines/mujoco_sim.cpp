// MuJoCo 2.2.2 adapter: the scene as MJCF (one free body at G with a ball and a stem geom on a plane), stepped by the shared fixed-step loop.
#include "mujoco_sim.h"

#include <mujoco/mujoco.h>

#include <cmath>
#include <cstring>
#include <limits>
#include <locale>
#include <memory>
#include <mutex>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "adapters.h"
#include "fixed_step.h"
#include "registry.h"
#include "settings.h"

namespace tippe {
namespace {

// Every setting of the MuJoCo model that decides accuracy, read from [engines.mujoco].
struct MujocoSettings {
  // Small against the spin period (2 pi / 5 ~ 1.3 dimensionless, 0.04 s for the toy) and
  // 20 steps per contact time constant (solref[0] = 0.002).
  double timestep = 1e-4;
  // "RK4": 4th order, so the explicit gyroscopic term w x I w of a fast spinning body causes
  // no visible energy drift; "Euler" (MuJoCo's default, semi-implicit, 1st order) grows the
  // nutation energy by O((w h)^2) per step; "implicit" (2.2: velocity-implicit with the RNE
  // derivatives) is 1st order and numerically damped. RK4 costs 4 forward passes a step.
  std::string integrator = "RK4";
  // "elliptic" is the Coulomb cone itself (|F_t| <= mu F_n, isotropic); "pyramidal" is
  // MuJoCo's default polyhedral approximation of it.
  std::string cone = "elliptic";
  // Friction-to-normal impedance ratio; MuJoCo's default: friction exactly as soft as the normal.
  double impratio = 1.0;
  // Newton: MuJoCo's default, converges quadratically; exact for a handful of constraint rows.
  std::string solver = "Newton";
  // A cap Newton does not reach at this tolerance for one body with at most 3 contacts.
  int iterations = 100;
  // Below MuJoCo's 1e-8 default so that solver error stays far below the compared quantities;
  // it costs an iteration or two.
  double tolerance = 1e-10;
  // MuJoCo's default: no post-pass; the soft contact's own friction is the law being tested.
  int noslip_iterations = 0;
  // friction = rolling: the noslip pass removes the creep that soft friction allows, so the
  // contact point really sticks.
  int noslip_iterations_rolling = 10;
  // Same order as the main tolerance (MuJoCo's default is 1e-6); used only when noslip runs.
  double noslip_tolerance = 1e-10;
  // [timeconst, dampratio]: MuJoCo's default 0.02 s leaves the toy top resting 2.6 % of R deep;
  // 0.002 gives 2.6e-4 R there (4.5e-7 R for the dimensionless top), is critically damped, and
  // keeps MuJoCo's stability rule timeconst >= 2 timestep for every timestep up to 1e-3.
  std::vector<double> solref = {0.002, 1.0};
  // [dmin, dmax, width, midpoint, power]: MuJoCo's default impedance profile.
  std::vector<double> solimp = {0.9, 0.95, 0.001, 0.5, 2.0};
  // 0: derived from the scene's friction law (1 none/viscous/gliding, 3 coulomb/rolling, 4 with
  // drilling); 1, 3, 4 or 6 force that contact dimensionality (diagnostic).
  int condim = 0;
  // Friction coefficient that stands in for the rolling constraint (friction = rolling).
  double rolling_mu = 1e3;
  // Where the free body's frame (and so its joint) has its origin: a modelling choice, not
  // physics, yet MuJoCo 2.2.2's answer depends on it (BENCHMARKS.md, "MuJoCo's body frame").
  // MuJoCo applies its soft-constraint law to J qacc and never computes J-dot qvel
  // (mj_fwdConstraint: efc_b = J qacc_smooth - aref); for a free joint that omitted term depends
  // on the frame origin. "ball_centre" (the default): the origin at the ball's centre O, where the
  // term is exactly zero for a sphere on a plane, so MuJoCo's contact law acts on the true gap and
  // slip; it is also the frame of MuJoCo's tutorial top and of most hand-written models.
  // "com": the origin at the centre of mass G (the bench's first choice), where the omitted
  // term, d w3 |w_perp| in the friction rows (1.8 m/s^2 on the toy top), holds a false slip that
  // turns Coulomb tops over ten times early.
  std::string body_frame = "ball_centre";

  template <class V>
  void visit(V& v) {
    v("timestep", timestep, 1e-8, 0.1);
    v("integrator", integrator, {"Euler", "RK4", "implicit"});
    v("cone", cone, {"elliptic", "pyramidal"});
    v("impratio", impratio, 1e-6, 1e6);
    v("solver", solver, {"Newton", "CG", "PGS"});
    v("iterations", iterations, 1, 1000000);
    v("tolerance", tolerance, 0.0, 1.0);
    v("noslip_iterations", noslip_iterations, 0, 1000000);
    v("noslip_iterations_rolling", noslip_iterations_rolling, 0, 1000000);
    v("noslip_tolerance", noslip_tolerance, 0.0, 1.0);
    v("solref", solref, 2);
    v("solimp", solimp, 5);
    v("condim", condim, 0, 6);
    v("rolling_mu", rolling_mu, 0.0, 1e15);
    v("body_frame", body_frame, {"com", "ball_centre"});
  }
};

[[noreturn]] void setting_error(const std::string& key, const std::string& why) {
  throw std::invalid_argument("engines.mujoco." + key + ": " + why);
}

std::string num(double v) {
  if (v == 0.0) v = 0.0;  // "-0" reads as 0 anyway; keep the text plain
  std::ostringstream os;
  os.imbue(std::locale::classic());
  os.precision(17);
  os << v;
  return os.str();
}

// Settings that are valid one by one but not together (MuJoCo would silently clamp them).
void check_combination(const MujocoSettings& s) {
  const double tc = s.solref[0], zeta = s.solref[1];
  if (tc > 0 || zeta > 0) {
    if (!(tc > 0 && zeta > 0))
      setting_error("solref", "expected [timeconst > 0, dampratio > 0] or [-stiffness < 0, -damping <= 0]");
    // Below 2 timestep MuJoCo itself accepts it and raises it (its refsafe rule): so does the
    // bench, with a note and the raised value in the run's settings (solref_used).
  } else if (!(tc < 0 && zeta <= 0)) {
    setting_error("solref", "expected [timeconst > 0, dampratio > 0] or [-stiffness < 0, -damping <= 0]");
  }
  const auto& im = s.solimp;
  // MuJoCo clamps impedances into [mjMINIMP, mjMAXIMP]: values outside would not be the used ones.
  for (int i = 0; i < 2; ++i)
    if (!(im[i] >= mjMINIMP && im[i] <= mjMAXIMP))
      setting_error("solimp", "dmin and dmax must lie in [" + num(mjMINIMP) + ", " + num(mjMAXIMP) + "]");
  if (!(im[2] > 0)) setting_error("solimp", "width must be > 0");
  if (!(im[3] > 0 && im[3] < 1)) setting_error("solimp", "midpoint must lie in (0, 1)");
  if (!(im[4] >= 1)) setting_error("solimp", "power must be >= 1");
  if (s.condim != 0 && s.condim != 1 && s.condim != 3 && s.condim != 4 && s.condim != 6)
    setting_error("condim", "value " + std::to_string(s.condim) + " is not one of: 0, 1, 3, 4, 6");
}

MujocoSettings read_checked_settings(const Scene& scene) {
  MujocoSettings s = read_settings<MujocoSettings>("mujoco", scene);
  check_combination(s);
  return s;
}

// The contact dimensionality the scene's law needs (MuJoCo has no torsional row without the
// two tangential ones, hence 4 whenever drilling is on).
int derived_condim(const Scene& scene) {
  const ContactSpec& c = scene.contact;
  if (c.drilling > 0) return 4;
  switch (c.friction) {
    case FrictionLaw::Coulomb: return c.mu > 0 ? 3 : 1;
    case FrictionLaw::Rolling: return 3;
    // Viscous and gliding: the base class applies F_t = -k v_C or -mu F_n v_C through
    // apply_force_W, so the engine's own contact must be frictionless.
    case FrictionLaw::Viscous:
    case FrictionLaw::Gliding:
    case FrictionLaw::None: return 1;
  }
  return 1;
}

int used_condim(const MujocoSettings& s, const Scene& scene) {
  return s.condim != 0 ? s.condim : derived_condim(scene);
}

// The solref MuJoCo uses: with refsafe (on by default in 2.2.2) a positive timeconst below
// 2 timestep is raised to 2 timestep (engine_core_constraint.c, getsolparam).
std::vector<double> used_solref(const MujocoSettings& s) {
  std::vector<double> r = s.solref;
  if (r[0] > 0 && r[0] < 2 * s.timestep) r[0] = 2 * s.timestep;
  return r;
}

// The body frame's origin in the principal frame at G (along e_Z): 0 for "com", z_O for "ball_centre".
double frame_origin_z(const MujocoSettings& s, const BodyModel& m) { return s.body_frame == "com" ? 0.0 : m.z_O(); }

// Geom friction [tangential, torsional, rolling]; MuJoCo reads only the first condim/2 of them.
Vec3 used_friction(const MujocoSettings& s, const Scene& scene) {
  const ContactSpec& c = scene.contact;
  double mu = 0.0;
  if (c.friction == FrictionLaw::Coulomb) mu = c.mu;
  else if (c.friction == FrictionLaw::Rolling) mu = s.rolling_mu;
  // MuJoCo's torsional coefficient is a length: the drilling torque is bounded by it times
  // the normal force, the scene's |tau| <= mu_d F_n.
  return Vec3(mu, c.drilling, 0.0);
}

int used_noslip_iterations(const MujocoSettings& s, const Scene& scene) {
  return scene.contact.friction == FrictionLaw::Rolling ? s.noslip_iterations_rolling : s.noslip_iterations;
}

std::string xml_escape(const std::string& text) {
  std::string out;
  for (char ch : text) {
    switch (ch) {
      case '&': out += "&amp;"; break;
      case '<': out += "&lt;"; break;
      case '>': out += "&gt;"; break;
      case '"': out += "&quot;"; break;
      case '\'': out += "&apos;"; break;
      default: out += ch;
    }
  }
  return out;
}

// The whole model, initial state included (keyframe "initial"), so that the text alone
// reproduces a run: load, mj_resetDataKeyframe(m, d, 0), mj_step.
std::string build_mjcf(const Scene& scene, const MujocoSettings& s) {
  const BodyModel m = BodyModel::from_scene(scene);
  const BodyState x0 = scene_initial_state(scene);
  const Quat q_WB = x0.q_WB.normalized();
  const int condim = used_condim(s, scene);
  const Vec3 friction = used_friction(s, scene);
  const double floor_half = 100.0 * (m.R + (m.stem ? m.l : 0.0));
  auto vec = [](std::initializer_list<double> xs) {
    std::string out;
    for (double x : xs) out += (out.empty() ? "" : " ") + num(x);
    return out;
  };

  std::ostringstream os;
  os.imbue(std::locale::classic());
  os << "<mujoco model=\"" << xml_escape(scene.name.empty() ? std::string("tippe_top") : scene.name) << "\">\n";
  const double z0 = frame_origin_z(s, m);
  const char* origin = s.body_frame == "com" ? "the centre of mass G" : "the ball's centre O";
  // The frame origin F = G + z0 e_Z, its velocity v_F = v_G + w x (F - G).
  const Vec3 r_GF_W = q_WB * Vec3(0.0, 0.0, z0);
  const Vec3 p_WF = x0.p_WG + r_GF_W, v_WF = x0.v_WG + (q_WB * x0.w_B).cross(r_GF_W);
  os << "  <!-- Tippe-top bench scene. Body frame: origin at " << origin << " (engines.mujoco.body_frame),\n"
        "       principal axes, e_Z the symmetry axis from the ball towards the stem. Mass properties are\n"
        "       the scene's, never inferred from the geoms. Start: keyframe \"initial\" (free joint qvel:\n"
        "       linear velocity of the frame origin in the world frame, angular velocity in the body frame). -->\n";
  os << "  <compiler angle=\"radian\" inertiafromgeom=\"false\"/>\n";
  os << "  <option timestep=\"" << num(s.timestep) << "\" gravity=\"" << vec({0.0, 0.0, -scene.gravity})
     << "\" density=\"0\" viscosity=\"0\" integrator=\"" << s.integrator << "\" cone=\"" << s.cone
     << "\" impratio=\"" << num(s.impratio) << "\" solver=\"" << s.solver << "\" iterations=\"" << s.iterations
     << "\" tolerance=\"" << num(s.tolerance) << "\" noslip_iterations=\"" << used_noslip_iterations(s, scene)
     << "\" noslip_tolerance=\"" << num(s.noslip_tolerance) << "\"/>\n";
  os << "  <default>\n";
  os << "    <geom condim=\"" << condim << "\" friction=\"" << vec({friction.x(), friction.y(), friction.z()})
     << "\" solref=\"" << vec({s.solref[0], s.solref[1]}) << "\" solimp=\""
     << vec({s.solimp[0], s.solimp[1], s.solimp[2], s.solimp[3], s.solimp[4]})
     << "\" margin=\"0\" gap=\"0\"/>\n";
  os << "  </default>\n";
  os << "  <worldbody>\n";
  // contype/conaffinity: floor (1, 2) against body geoms (2, 1) collide; body geoms never
  // with each other.
  os << "    <geom name=\"floor\" type=\"plane\" size=\"" << vec({floor_half, floor_half, 1.0})
     << "\" contype=\"1\" conaffinity=\"2\"/>\n";
  os << "    <body name=\"top\" pos=\"" << vec({p_WF.x(), p_WF.y(), p_WF.z()}) << "\" quat=\""
     << vec({q_WB.w(), q_WB.x(), q_WB.y(), q_WB.z()}) << "\">\n";
  os << "      <freejoint name=\"free\"/>\n";
  os << "      <inertial pos=\"" << vec({0.0, 0.0, -z0}) << "\" mass=\"" << num(m.M) << "\" diaginertia=\"" << vec({m.A, m.A, m.C}) << "\"/>\n";
  // The ball is a full sphere about O = G + d e_Z: the cap cut at h is not modelled.
  os << "      <geom name=\"ball\" type=\"sphere\" size=\"" << num(m.R) << "\" pos=\"" << vec({0.0, 0.0, m.z_O() - z0})
     << "\" contype=\"2\" conaffinity=\"1\"/>\n";
  if (m.stem)
    os << "      <geom name=\"stem\" type=\"capsule\" size=\"" << num(m.r) << "\" fromto=\""
       << vec({0.0, 0.0, m.z_O() - z0, 0.0, 0.0, m.z_P() - z0}) << "\" contype=\"2\" conaffinity=\"1\"/>\n";
  os << "    </body>\n";
  os << "  </worldbody>\n";
  os << "  <keyframe>\n";
  os << "    <key name=\"initial\" time=\"0\" qpos=\""
     << vec({p_WF.x(), p_WF.y(), p_WF.z(), q_WB.w(), q_WB.x(), q_WB.y(), q_WB.z()}) << "\" qvel=\""
     << vec({v_WF.x(), v_WF.y(), v_WF.z(), x0.w_B.x(), x0.w_B.y(), x0.w_B.z()}) << "\"/>\n";
  os << "  </keyframe>\n";
  os << "</mujoco>\n";
  return os.str();
}

// MuJoCo's default warning handler prints to stdout (where the harness may write records) and
// appends to MUJOCO_LOG.TXT in the working directory; warnings that matter are read from
// mjData.warning after each step instead.
thread_local std::string last_warning;
void record_warning(const char* message) { last_warning = message ? message : ""; }

void install_warning_handler() {
  static std::once_flag once;
  std::call_once(once, [] {
    if (!mju_user_warning) mju_user_warning = record_warning;
  });
}

// Compiles MJCF text through a one-file VFS (no temporary file). Throws std::runtime_error
// with MuJoCo's message; compiler warnings of a successful load go to `warning`.
mjModel* compile_mjcf(const std::string& xml, std::string& warning) {
  // mj_loadXML keeps process-wide "last model" state in 2.2: one load at a time.
  static std::mutex mutex;
  std::lock_guard<std::mutex> lock(mutex);
  // mjVFS holds 2000 file names of 1000 bytes: too large for the stack.
  auto vfs = std::make_unique<mjVFS>();
  mj_defaultVFS(vfs.get());
  const char* name = "tippe_top.xml";
  const int size = static_cast<int>(xml.size()) + 1;  // with the terminating NUL
  if (mj_makeEmptyFileVFS(vfs.get(), name, size) != 0) throw std::runtime_error("mujoco: cannot create the VFS file");
  const int id = mj_findFileVFS(vfs.get(), name);
  if (id < 0) {
    mj_deleteVFS(vfs.get());
    throw std::runtime_error("mujoco: VFS file not found after creation");
  }
  std::memcpy(vfs->filedata[id], xml.c_str(), static_cast<size_t>(size));
  char error[1024] = "";
  mjModel* model = mj_loadXML(name, vfs.get(), error, sizeof error);
  mj_deleteVFS(vfs.get());
  if (!model) throw std::runtime_error(std::string("mujoco: cannot compile the scene's MJCF: ") + error);
  warning = error;
  return model;
}

// Owns one simulator's MuJoCo objects; a member, so that they are released even when the
// simulator's constructor throws half way.
struct MujocoHandles {
  mjModel* model = nullptr;
  mjData* data = nullptr;
  MujocoHandles() = default;
  MujocoHandles(const MujocoHandles&) = delete;
  MujocoHandles& operator=(const MujocoHandles&) = delete;
  ~MujocoHandles() {
    if (data) mj_deleteData(data);
    if (model) mj_deleteModel(model);
  }
};

}  // namespace

class MujocoSimulator : public FixedStepSimulator {
 public:
  explicit MujocoSimulator(const Scene& scene);
  MujocoSimulator(const MujocoSimulator&) = delete;
  MujocoSimulator& operator=(const MujocoSimulator&) = delete;

  std::string engine() const override { return "mujoco"; }
  std::string version() const override { return std::string("mujoco ") + mj_versionString(); }
  SettingsList settings() const override;
  std::vector<std::string> notes() const override { return notes_; }

  MujocoModelReadback readback() const;
  std::vector<double> qpos() const { return std::vector<double>(d_->qpos, d_->qpos + m_->nq); }
  std::vector<double> qvel() const { return std::vector<double>(d_->qvel, d_->qvel + m_->nv); }

 protected:
  void engine_step() override;
  BodyState engine_state() const override;
  void engine_set_state(const BodyState& x) override;
  ContactReport engine_contacts() const override { return report_; }
  void apply_force_W(const Vec3& f_W, const Vec3& p_W) override;
  std::string engine_limit_hit() const override { return limit_; }
  long long engine_solver_iterations() const override { return solver_iterations_; }

 public:
  MassReadback mass_properties() const override;

 private:
  ContactReport read_contacts() const;
  void make_notes(const std::string& compiler_warning);

  MujocoSettings settings_;
  int condim_ = 0;
  std::vector<std::string> notes_;
  MujocoHandles mj_;
  // Aliases of mj_'s handles, for brevity.
  mjModel* m_ = nullptr;
  mjData* d_ = nullptr;
  int body_id_ = -1, floor_id_ = -1, ball_id_ = -1, stem_id_ = -1;
  int qadr_ = 0, vadr_ = 0;
  double frame_z_ = 0.0;  // the body frame's origin F = G + frame_z_ e_Z
  ContactReport report_;
  std::string limit_;
  // MuJoCo met a NaN or |x| > mjMAXVAL in qpos, qvel or qacc and reset mjData to the model's
  // qpos0: the engine's state is lost, so it is reported as non-finite (a diverged run).
  std::string bad_state_;
  long long solver_iterations_ = 0;
};

MujocoSimulator::MujocoSimulator(const Scene& scene)
    : FixedStepSimulator(scene), settings_(read_checked_settings(scene)) {
  install_warning_handler();
  condim_ = used_condim(settings_, scene);
  frame_z_ = frame_origin_z(settings_, body());
  std::string compiler_warning;
  m_ = mj_.model = compile_mjcf(build_mjcf(scene, settings_), compiler_warning);
  d_ = mj_.data = mj_makeData(m_);
  if (!d_) throw std::runtime_error("mujoco: mj_makeData failed");

  body_id_ = mj_name2id(m_, mjOBJ_BODY, "top");
  floor_id_ = mj_name2id(m_, mjOBJ_GEOM, "floor");
  ball_id_ = mj_name2id(m_, mjOBJ_GEOM, "ball");
  stem_id_ = body().stem ? mj_name2id(m_, mjOBJ_GEOM, "stem") : -1;
  const int joint = mj_name2id(m_, mjOBJ_JOINT, "free");
  if (body_id_ < 0 || floor_id_ < 0 || ball_id_ < 0 || (body().stem && stem_id_ < 0) || joint < 0 ||
      m_->nq != 7 || m_->nv != 6 || m_->nkey != 1)
    throw std::runtime_error("mujoco: compiled model does not have the expected structure");
  qadr_ = m_->jnt_qposadr[joint];
  vadr_ = m_->jnt_dofadr[joint];

  mj_resetDataKeyframe(m_, d_, 0);
  // Contacts and forces at t = 0, for observe() before the first step; mj_forward leaves the
  // integration state (qpos, qvel, qacc_warmstart) untouched.
  mj_forward(m_, d_);
  report_ = read_contacts();
  make_notes(compiler_warning);
  start(settings_.timestep);
}

SettingsList MujocoSimulator::settings() const {
  SettingsList list = list_settings(settings_);
  const Vec3 f = used_friction(settings_, scene());
  list.emplace_back("condim_used", std::to_string(condim_));
  list.emplace_back("friction_used", "[" + num(f.x()) + ", " + num(f.y()) + ", " + num(f.z()) + "]");
  list.emplace_back("noslip_iterations_used", std::to_string(used_noslip_iterations(settings_, scene())));
  const std::vector<double> sr = used_solref(settings_);
  list.emplace_back("solref_used", "[" + num(sr[0]) + ", " + num(sr[1]) + "]");
  return list;
}

void MujocoSimulator::make_notes(const std::string& compiler_warning) {
  const Scene& sc = scene();
  const BodyModel& m = body();
  const ContactSpec& c = sc.contact;
  auto g = [](double v) {
    std::ostringstream os;
    os << v;
    return os.str();
  };
  notes_ = friction_law_notes({"MuJoCo", " (mj_applyFT)", "MuJoCo's previous step (mj_contactForce, explicit)",
                               " and " + std::to_string(settings_.noslip_iterations_rolling) + " noslip iterations"},
                              settings_.rolling_mu);
  if (c.friction == FrictionLaw::Coulomb && !(c.mu > 0) && settings_.condim == 0)
    notes_.push_back("Coulomb friction with mu = 0 simulated as frictionless contact (condim 1)");
  if (condim_ >= 3 && (c.friction == FrictionLaw::Coulomb || c.friction == FrictionLaw::Rolling) &&
      settings_.cone == "pyramidal")
    notes_.push_back("friction cone approximated by MuJoCo's pyramid (cone = pyramidal)");
  if (condim_ >= 4 && c.drilling > 0)
    notes_.push_back("drilling friction (condim " + std::to_string(condim_) +
                     "): MuJoCo bounds the tangential force and the drilling torque jointly, (|F_t|/mu)^2 + (tau/mu_d)^2 <= F_n^2 (elliptic), not each alone");
  // MuJoCo raises every friction coefficient the contact uses to mjMINMU.
  const Vec3 f = used_friction(settings_, scene());
  const bool zero_used = (condim_ >= 3 && !(f.x() > 0)) || (condim_ >= 4 && !(f.y() > 0)) || condim_ == 6;
  if (zero_used)
    notes_.push_back("a friction coefficient of 0 with condim " + std::to_string(condim_) +
                     " acts as MuJoCo's minimum mjMINMU = 1e-5, not as frictionless");
  if (settings_.condim != 0 && settings_.condim != derived_condim(sc))
    notes_.push_back("condim forced to " + std::to_string(settings_.condim) + " (the scene's law needs " +
                     std::to_string(derived_condim(sc)) + "): not the scene's contact law");
  if (used_solref(settings_)[0] != settings_.solref[0])
    notes_.push_back("solref timeconst " + g(settings_.solref[0]) + " raised by MuJoCo to 2 timestep = " +
                     g(used_solref(settings_)[0]) + " (its refsafe rule)");
  notes_.push_back(std::string("body frame at ") +
                   (settings_.body_frame == "com" ? "the centre of mass G" : "the ball's centre O") +
                   " (engines.mujoco.body_frame): MuJoCo's results depend on it");
  if (settings_.solref[0] > 0) {
    // Resting on the ball: d k r = (1 - d) g with k = d / (dmax^2 tc^2 zeta^2) and d ~ dmin
    // for r << width (MuJoCo's soft-constraint model).
    const double dmin = settings_.solimp[0], dmax = settings_.solimp[1];
    const double tc = used_solref(settings_)[0], zeta = settings_.solref[1];
    const double depth = (1 - dmin) / (dmin * dmin) * sc.gravity * dmax * dmax * tc * tc * zeta * zeta;
    notes_.push_back("soft contact (solref, solimp): resting penetration about " + g(depth) + " = " +
                     g(depth / m.R) + " R" + (condim_ >= 3 ? "; sticking friction creeps" : ""));
  } else {
    notes_.push_back("soft contact given as stiffness and damping (negative solref)");
  }
  // Documented for MuJoCo's convex model ("the only way to initiate slip is to generate some
  // motion in the normal direction") and seen here as contact on/off chatter while sliding.
  if (condim_ >= 3 && (c.friction == FrictionLaw::Coulomb || c.friction == FrictionLaw::Rolling))
    notes_.push_back("while slipping, MuJoCo's convex contact pushes the ball off the floor: the contact hops (intermittent normal force, many switch events)");
  if (settings_.integrator != "RK4")
    notes_.push_back("integrator " + settings_.integrator + ": first order in the timestep");
  if (!full_sphere_note().empty()) notes_.push_back(full_sphere_note());
  if (!compiler_warning.empty()) notes_.push_back("mujoco compiler: " + compiler_warning);
}

void MujocoSimulator::engine_step() {
  int before[mjNWARNING];
  for (int i = 0; i < mjNWARNING; ++i) before[i] = d_->warning[i].number;
  mj_step(m_, d_);
  // apply_force_W acts for one step only.
  mju_zero(d_->qfrc_applied, m_->nv);
  // With RK4 this is the last of the four solves of the step (MuJoCo keeps no total).
  solver_iterations_ += d_->solver_iter;
  auto fired = [&](int w) { return d_->warning[w].number > before[w]; };
  static const char* const bad_names[] = {"qpos", "qvel", "qacc"};
  const int bad_warnings[] = {mjWARN_BADQPOS, mjWARN_BADQVEL, mjWARN_BADQACC};
  for (int i = 0; i < 3 && bad_state_.empty(); ++i)
    if (fired(bad_warnings[i]))
      bad_state_ = last_warning.empty() ? std::string("mujoco: bad ") + bad_names[i] + ", state reset by MuJoCo"
                                        : "mujoco: " + last_warning;
  if (limit_.empty()) {
    if (fired(mjWARN_CONTACTFULL)) limit_ = "mujoco: contact list full (nconmax " + std::to_string(m_->nconmax) + "), contacts dropped";
    else if (fired(mjWARN_CNSTRFULL)) limit_ = "mujoco: constraint rows full (njmax " + std::to_string(m_->njmax) + "), contacts dropped";
    else if (fired(mjWARN_INERTIA)) limit_ = "mujoco: (near) singular inertia matrix";
  }
  report_ = read_contacts();
}

BodyState MujocoSimulator::engine_state() const {
  BodyState x;
  x.t = time();
  if (!bad_state_.empty()) {
    const double nan = std::numeric_limits<double>::quiet_NaN();
    x.p_WG = x.v_WG = x.w_B = Vec3::Constant(nan);
    x.q_WB = Quat(nan, nan, nan, nan);
    return x;
  }
  const mjtNum* q = d_->qpos + qadr_;
  const mjtNum* v = d_->qvel + vadr_;
  x.q_WB = Quat(q[3], q[4], q[5], q[6]).normalized();
  // MuJoCo's free joint angular velocity is in the body (local) frame.
  x.w_B = Vec3(v[3], v[4], v[5]);
  // qpos and the linear qvel are the frame origin F's; G = F - z0 e_Z, v_G = v_F + w x (G - F).
  const Vec3 r_FG_W = x.q_WB * Vec3(0.0, 0.0, -frame_z_);
  x.p_WG = Vec3(q[0], q[1], q[2]) + r_FG_W;
  x.v_WG = Vec3(v[0], v[1], v[2]) + (x.q_WB * x.w_B).cross(r_FG_W);
  return x;
}

void MujocoSimulator::engine_set_state(const BodyState& x) {
  // The inverse of engine_state: F = G + z0 e_Z, v_F = v_G + w x (F - G); w in the body frame.
  mjtNum* q = d_->qpos + qadr_;
  mjtNum* v = d_->qvel + vadr_;
  const Vec3 r_GF_W = x.q_WB * Vec3(0.0, 0.0, frame_z_);
  const Vec3 p_F = x.p_WG + r_GF_W;
  const Vec3 v_F = x.v_WG + (x.q_WB * x.w_B).cross(r_GF_W);
  for (int i = 0; i < 3; ++i) {
    q[i] = p_F[i];
    v[i] = v_F[i];
    v[3 + i] = x.w_B[i];
  }
  q[3] = x.q_WB.w();
  q[4] = x.q_WB.x();
  q[5] = x.q_WB.y();
  q[6] = x.q_WB.z();
  bad_state_.clear();
  // Contacts and forces of the new state, as after construction.
  mj_forward(m_, d_);
  report_ = read_contacts();
}

MassReadback MujocoSimulator::mass_properties() const {
  const MujocoModelReadback r = readback();
  MassReadback mp;
  mp.mass = r.mass;
  // body_ipos is about the body frame's origin F = G + frame_origin_G.
  mp.p_GCm_B = r.ipos_B + r.frame_origin_G;
  const Eigen::Matrix3d R = r.iquat_B.normalized().toRotationMatrix();
  // Principal moments about the centre of mass; shifted to G (parallel axis) when it is not at G.
  const Eigen::Matrix3d I_cm = R * r.inertia.asDiagonal() * R.transpose();
  const Vec3 c = mp.p_GCm_B;
  mp.I_G_B = I_cm + r.mass * (c.squaredNorm() * Eigen::Matrix3d::Identity() - c * c.transpose());
  return mp;
}

void MujocoSimulator::apply_force_W(const Vec3& f_W, const Vec3& p_W) {
  // mj_applyFT's Jacobian uses xpos, xmat, subtree_com and cdof, which after mj_step still
  // describe the start (Euler) or last stage (RK4) of the previous step: bring them to now.
  mj_kinematics(m_, d_);
  mj_comPos(m_, d_);
  const mjtNum force[3] = {f_W.x(), f_W.y(), f_W.z()};
  const mjtNum torque[3] = {0.0, 0.0, 0.0};
  const mjtNum point[3] = {p_W.x(), p_W.y(), p_W.z()};
  mj_applyFT(m_, d_, force, torque, point, body_id_, d_->qfrc_applied);
}

ContactReport MujocoSimulator::read_contacts() const {
  ContactReport r;
  Vec3 moment = Vec3::Zero();
  double weight = 0.0;
  for (int i = 0; i < d_->ncon; ++i) {
    const mjContact& c = d_->contact[i];
    if (c.exclude != 0 || c.efc_address < 0) continue;
    const int g = c.geom1 == floor_id_ ? c.geom2 : (c.geom2 == floor_id_ ? c.geom1 : -1);
    if (g == ball_id_) r.ball = true;
    else if (g >= 0 && g == stem_id_) r.stem = true;
    else continue;
    mjtNum f[6];
    // In the contact frame, whose first axis is the normal (+z here): f[0] is the normal force.
    mj_contactForce(m_, d_, i, f);
    r.normal_force += f[0];
    (g == ball_id_ ? r.normal_force_ball : r.normal_force_stem) += f[0];
    if (f[0] > 0) {
      // c.pos lies midway between the two surfaces: within the penetration depth of the floor.
      moment += f[0] * Vec3(c.pos[0], c.pos[1], c.pos[2]);
      weight += f[0];
    }
  }
  if (weight > 0) {
    r.point_valid = true;
    r.p_WC = moment / weight;
  }
  return r;
}

MujocoModelReadback MujocoSimulator::readback() const {
  MujocoModelReadback r;
  const int b = body_id_;
  r.mass = m_->body_mass[b];
  r.ipos_B = Vec3(m_->body_ipos[3 * b], m_->body_ipos[3 * b + 1], m_->body_ipos[3 * b + 2]);
  r.inertia = Vec3(m_->body_inertia[3 * b], m_->body_inertia[3 * b + 1], m_->body_inertia[3 * b + 2]);
  r.iquat_B = Quat(m_->body_iquat[4 * b], m_->body_iquat[4 * b + 1], m_->body_iquat[4 * b + 2], m_->body_iquat[4 * b + 3]);
  r.timestep = m_->opt.timestep;
  r.frame_origin_G = Vec3(0.0, 0.0, frame_z_);
  r.nq = m_->nq;
  r.nv = m_->nv;
  return r;
}

namespace {
const MujocoSimulator& as_mujoco(const Simulator& sim, const char* caller) {
  const auto* mj = dynamic_cast<const MujocoSimulator*>(&sim);
  if (!mj) throw std::invalid_argument(std::string(caller) + ": not a MuJoCo simulator");
  return *mj;
}
}  // namespace

MujocoModelReadback mujoco_model_readback(const Simulator& sim) {
  return as_mujoco(sim, "mujoco_model_readback").readback();
}
std::vector<double> mujoco_qpos(const Simulator& sim) { return as_mujoco(sim, "mujoco_qpos").qpos(); }
std::vector<double> mujoco_qvel(const Simulator& sim) { return as_mujoco(sim, "mujoco_qvel").qvel(); }

std::unique_ptr<Simulator> make_mujoco_simulator(const Scene& scene) {
  return std::make_unique<MujocoSimulator>(scene);
}

void validate_mujoco_settings(const Scene& scene) { (void)read_checked_settings(scene); }

const EngineInfo& mujoco_engine_info() {
  static const EngineInfo info = [] {
    EngineInfo e;
    e.name = "mujoco";
    e.role = EngineRole::Engine;
    e.make = make_mujoco_simulator;
    e.validate = validate_mujoco_settings;
    e.default_settings = [] { return list_settings(MujocoSettings{}); };
    e.version = std::string("mujoco ") + mj_versionString();
    e.colour = "#2ca02c";
    return e;
  }();
  return info;
}

std::string mujoco_mjcf(const Scene& scene) { return build_mjcf(scene, read_checked_settings(scene)); }

std::vector<std::string> mujoco_mjcf_missing(const Scene& scene) {
  std::vector<std::string> out;
  const ContactSpec& c = scene.contact;
  if (c.friction == FrictionLaw::Viscous && c.k > 0) {
    std::ostringstream k;
    k.imbue(std::locale::classic());
    k << c.k;
    out.push_back("the viscous friction F_t = -k v_C (k = " + k.str() +
                  ") that the bench applies each step as an external force at every contact: the model's contacts "
                  "are frictionless, so in plain MuJoCo the top only spins");
  }
  if (c.friction == FrictionLaw::Gliding && c.mu > 0) {
    std::ostringstream mu;
    mu.imbue(std::locale::classic());
    mu << c.mu;
    out.push_back("the gliding friction F_t = -mu F_n v_C (mu = " + mu.str() +
                  " s/m) that the bench applies each step as an external force at every contact, with the engine's "
                  "previous normal force: the model's contacts are frictionless, so in plain MuJoCo the top only spins");
  }
  return out;
}

}  // namespace tippe
