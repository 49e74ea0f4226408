// MuJoCo 2.2.2 adapter: the scene as MJCF (one free body at G with a ball and a stem geom on a plane), or the user's own MJCF as written, stepped by the shared fixed-step loop.
#include "engines/mujoco/mujoco_sim.h"
#include "engines/mujoco/mujoco_rk4.h"

#include <mujoco/mujoco.h>

#include <cmath>
#include <cstring>
#include <limits>
#include <locale>
#include <memory>
#include <mutex>
#include <stdexcept>
#include <string>
#include <vector>

#include "engines/core/adapters.h"
#include "engines/core/fixed_step.h"
#include "engines/mujoco/mujoco_api.h"
#include "engines/mujoco/mujoco_mjcf.h"
#include "engines/mujoco/mujoco_notes.h"
#include "engines/mujoco/mujoco_settings.h"
#include "engines/mujoco/mujoco_top.h"
#include "engines/mujoco/mujoco_user_model.h"
#include "engines/core/registry.h"
#include "engines/core/settings.h"

namespace tippe {
namespace {

using namespace mujoco_detail;

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

  SettingsList settings() const override;

  MujocoModelReadback readback() const;
  std::vector<double> qpos() const { return std::vector<double>(d_->qpos, d_->qpos + m_->nq); }
  std::vector<double> qvel() const { return std::vector<double>(d_->qvel, d_->qvel + m_->nv); }
  std::vector<double> body_pose() const {
    std::vector<double> out(d_->xpos + 3 * body_id_, d_->xpos + 3 * body_id_ + 3);
    out.insert(out.end(), d_->xquat + 4 * body_id_, d_->xquat + 4 * body_id_ + 4);
    return out;
  }

 protected:
  void engine_step() override;
  BodyState engine_state() const override;
  void engine_set_state(const BodyState& x) override;
  void apply_force_W(const Vec3& f_W, const Vec3& p_W) override;

 public:
  MassReadback mass_properties() const override;

 private:
  ContactReport read_contacts() const { return read_contacts(d_); }
  ContactReport read_contacts(const mjData* d) const;
  void make_notes(const std::string& compiler_warning);
  void init_user_model(const Scene& scene);

  MujocoSettings settings_;
  int condim_ = 0;
  MujocoHandles mj_;
  // Aliases of mj_'s handles, for brevity.
  mjModel* m_ = nullptr;
  mjData* d_ = nullptr;
  int body_id_ = -1, floor_id_ = -1, ball_id_ = -1, stem_id_ = -1;
  int qadr_ = 0, vadr_ = 0;
  double frame_z_ = 0.0;  // the body frame's origin F = G + frame_z_ e_Z
  // The user's model: its body frame F is the model's own, turned by q_FB_ from the principal
  // frame B, with G at p_FG_F_ in it.
  bool user_ = false;
  MjcfTopImport top_;
  Quat q_FB_ = Quat::Identity();
  Vec3 p_FG_F_ = Vec3::Zero();
  bool keyframe_start_ = false;
  MjTopIds ids_;
  // MuJoCo met a NaN or |x| > mjMAXVAL in qpos, qvel or qacc and reset mjData to the model's
  // qpos0: the engine's state is lost, so it is reported as non-finite (a diverged run).
  std::string bad_state_;
};

MujocoSimulator::MujocoSimulator(const Scene& scene)
    : FixedStepSimulator(scene, mujoco_engine_info()), settings_(read_checked_settings(scene)) {
  install_warning_handler();
  if (!settings_.model.empty()) {
    init_user_model(scene);
    return;
  }
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

void MujocoSimulator::init_user_model(const Scene& scene) {
  user_ = true;
  std::string compiler_warning;
  MjTopIds& ids = ids_;
  check_user_model(scene, settings_, &mj_.model, &ids, &compiler_warning);
  m_ = mj_.model;
  const std::vector<std::string> overridden = apply_user_overrides(m_, scene, settings_, ids);
  // Read again: the contact as the overrides leave it (solref, solimp), for the notes and settings.
  top_ = analyse_mjcf_top(m_, settings_.model, settings_.body, settings_.keyframe);
  d_ = mj_.data = mj_makeData(m_);
  if (!d_) throw std::runtime_error("mujoco: mj_makeData failed");
  body_id_ = ids.body;
  floor_id_ = ids.floor;
  ball_id_ = ids.ball;
  stem_id_ = ids.stem;
  qadr_ = ids.qadr;
  vadr_ = ids.vadr;
  q_FB_ = top_.q_FB;
  p_FG_F_ = top_.p_FG_F;
  condim_ = top_.condim;

  const BodyState x0 = scene_initial_state(scene);
  keyframe_start_ = same_start(x0, top_.start, body().R);
  if (keyframe_start_) {
    // The keyframe's own numbers: the run is plain MuJoCo's from it, bit for bit.
    if (ids.key >= 0) mj_resetDataKeyframe(m_, d_, ids.key);
    else mj_resetData(m_, d_);
  } else {
    // The scene's start (e.g. a --set initial.spin), converted to the model's frame F.
    mj_resetData(m_, d_);
    const Quat q_WF = (x0.q_WB * q_FB_.conjugate()).normalized();
    const Vec3 r_FG_W = q_WF * p_FG_F_;
    const Vec3 w_W = x0.q_WB * x0.w_B;
    const Vec3 p_WF = x0.p_WG - r_FG_W, v_WF = x0.v_WG - w_W.cross(r_FG_W);
    const Vec3 w_F = q_FB_ * x0.w_B;
    mjtNum* q = d_->qpos + qadr_;
    mjtNum* v = d_->qvel + vadr_;
    q[0] = p_WF.x(), q[1] = p_WF.y(), q[2] = p_WF.z();
    q[3] = q_WF.w(), q[4] = q_WF.x(), q[5] = q_WF.y(), q[6] = q_WF.z();
    v[0] = v_WF.x(), v[1] = v_WF.y(), v[2] = v_WF.z();
    v[3] = w_F.x(), v[4] = w_F.y(), v[5] = w_F.z();
  }
  d_->time = 0.0;
  // Contacts at t = 0 for observe() before the first step, from a copy: an mj_forward on d_
  // itself changes the first Euler step in its last bits (even with qacc_warmstart kept), and
  // the steps must be plain MuJoCo's.
  {
    std::unique_ptr<mjData, void (*)(mjData*)> scratch(mj_makeData(m_), mj_deleteData);
    if (!scratch) throw std::runtime_error("mujoco: mj_makeData failed");
    mj_copyData(scratch.get(), m_, d_);
    mj_forward(m_, scratch.get());
    report_ = read_contacts(scratch.get());
  }
  notes_ = user_model_notes(m_, top_, settings_.model, keyframe_start_, overridden, compiler_warning);
  start(m_->opt.timestep);
}


SettingsList MujocoSimulator::settings() const {
  if (user_) return user_model_settings(m_, top_, settings_.model, keyframe_start_);
  return scene_model_settings(settings_, scene(), condim_);
}

void MujocoSimulator::make_notes(const std::string& compiler_warning) {
  notes_ = friction_law_notes({"MuJoCo", " (mj_applyFT)", "MuJoCo's previous step (mj_contactForce, explicit)",
                               " and " + std::to_string(settings_.noslip_iterations_rolling) + " noslip iterations"},
                              settings_.rolling_mu);
  const std::vector<std::string> mujoco = scene_model_notes(scene(), body(), settings_, condim_);
  notes_.insert(notes_.end(), mujoco.begin(), mujoco.end());
  if (!full_sphere_note().empty()) notes_.push_back(full_sphere_note());
  if (!compiler_warning.empty()) notes_.push_back("mujoco compiler: " + compiler_warning);
}

void MujocoSimulator::engine_step() {
  int before[mjNWARNING];
  for (int i = 0; i < mjNWARNING; ++i) before[i] = d_->warning[i].number;
  // RK4's velocity update is the weighted sum of its four stages' forces, of which MuJoCo keeps
  // the last: stepped stage by stage (the same arithmetic), the ledger books that sum.
  const bool stepwise = rk4_stepwise_supported(m_);
  StepMeanForces mean;
  // The bench's forces are a generalized force held over the step, whose rotational part MuJoCo's
  // free joint takes in the body frame: its work is its power on MuJoCo's own velocities, summed
  // as the integrator sums the step (see BenchWrench::work).
  double applied_work = 0.0;
  if (stepwise) {
    mean = rk4_step_mean_forces(m_, d_, body_id_, [this](const mjData* d) { return read_contacts(d); }, applied_work);
  } else {
    // Euler and implicit update the velocity once with the force held: work = h Q . (u0 + u1) / 2.
    const double p0 = mju_dot(d_->qfrc_applied, d_->qvel, m_->nv);
    mj_step(m_, d_);
    applied_work = 0.5 * (p0 + mju_dot(d_->qfrc_applied, d_->qvel, m_->nv)) * m_->opt.timestep;
  }
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
  if (stepwise) report_.step_mean = mean;
  report_.bench.work = applied_work;
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
  if (user_) {
    // F is the model's frame: B = F turned by q_FB, G at p_FG_F in F.
    const Quat q_WF = Quat(q[3], q[4], q[5], q[6]).normalized();
    const Vec3 w_F(v[3], v[4], v[5]);
    x.q_WB = q_WF * q_FB_;
    x.w_B = q_FB_.conjugate() * w_F;
    const Vec3 r_FG_W = q_WF * p_FG_F_;
    x.p_WG = Vec3(q[0], q[1], q[2]) + r_FG_W;
    x.v_WG = Vec3(v[0], v[1], v[2]) + (q_WF * w_F).cross(r_FG_W);
    return x;
  }
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

ContactReport MujocoSimulator::read_contacts(const mjData* data) const {
  ContactReport r;
  Vec3 moment = Vec3::Zero();
  double weight = 0.0;
  for (int i = 0; i < data->ncon; ++i) {
    const mjContact& c = data->contact[i];
    if (c.exclude != 0 || c.efc_address < 0) continue;
    const int g = c.geom1 == floor_id_ ? c.geom2 : (c.geom2 == floor_id_ ? c.geom1 : -1);
    if (g == ball_id_) r.ball = true;
    else if (g >= 0 && g == stem_id_) r.stem = true;
    else continue;
    mjtNum f[6];
    // In the contact frame, whose first axis is the normal (+z here): f[0] is the normal force.
    mj_contactForce(m_, data, i, f);
    r.normal_force += f[0];
    (g == ball_id_ ? r.normal_force_ball : r.normal_force_stem) += f[0];
    // The force on geom2 in the lab frame: the contact frame's rows (normal, two tangents) are
    // lab-frame axes, its normal pointing from geom1 to geom2; on the top when it is geom1, the
    // opposite. Its horizontal part is the friction force (the floor's normal is +z).
    Vec3 f_W = Vec3::Zero();
    for (int k = 0; k < 3; ++k) f_W += f[k] * Vec3(c.frame[3 * k], c.frame[3 * k + 1], c.frame[3 * k + 2]);
    if (c.geom1 == g) f_W = -f_W;
    add_surface_force(r, g == stem_id_, f[0], Vec3(f_W.x(), f_W.y(), 0.0), Vec3(c.pos[0], c.pos[1], c.pos[2]));
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
  finish_surface_points(r);
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
  r.frame_origin_G = user_ ? Vec3(q_FB_.conjugate() * (-p_FG_F_)) : Vec3(0.0, 0.0, frame_z_);
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
std::vector<double> mujoco_body_pose(const Simulator& sim) { return as_mujoco(sim, "mujoco_body_pose").body_pose(); }

std::unique_ptr<Simulator> make_mujoco_simulator(const Scene& scene) {
  return std::make_unique<MujocoSimulator>(scene);
}

void validate_mujoco_settings(const Scene& scene) {
  const MujocoSettings s = read_checked_settings(scene);
  if (!s.model.empty()) (void)check_user_model(scene, s, nullptr, nullptr, nullptr);
}

const EngineInfo& mujoco_engine_info() {
  static const EngineInfo info = [] {
    EngineInfo e = engine_entry<MujocoSettings>(  // Okabe-Ito bluish green
        "mujoco", EngineRole::Engine, make_mujoco_simulator, std::string("mujoco ") + mj_versionString(), "#009E73");
    // Its checks and, for the user's own model, MuJoCo compiling it.
    e.validate = validate_mujoco_settings;
    // The integrator decides how the gyroscopic term and the contact's stiffness are integrated
    // (Euler's energy rises scale with the step; RK4 is 4th order), the cone which friction law
    // is solved, noslip whether the soft friction's creep is removed.
    e.advice_axes = {{"integrator", {"\"RK4\"", "\"Euler\"", "\"implicit\""}},
                     {"cone", {"\"elliptic\"", "\"pyramidal\""}},
                     {"noslip_iterations", {"0", "10"}}};
    e.cost_knob = "timestep";
    // `tippe export-mjcf` and `tippe import-mjcf` (mujoco_api.h).
    static const MujocoApi api = {mujoco_mjcf, mujoco_mjcf_missing, import_mjcf_top, mjcf_scene_mismatches};
    e.extension = &api;
    return e;
  }();
  return info;
}

}  // namespace tippe

// The module's one exported symbol, tippe_engine_mujoco: the registry's way in (registry.h).
TIPPE_ENGINE_ENTRY_POINT(mujoco)
