// Derives the reference's top from a user's checked MuJoCo model: mass properties and symmetry axis, stem geometry, the contact law read from probe contacts, and the exact start.
#include "engines/mujoco/mujoco_import_analyser.h"

#include <algorithm>
#include <cmath>
#include <memory>
#include <string>

namespace tippe::mjcf_import_detail {
namespace {

// Two principal moments are "equal" (an axisymmetric body) within 1e-9 of the largest. MuJoCo
// diagonalises the compiled inertia itself (body_inertia, body_iquat); for a body that is
// axisymmetric by construction the two transverse moments come out equal to rounding (the three
// test models: bit for bit), while a modelled asymmetry is orders larger (the tutorial top with
// its ballast box 0.1 % longer one way: 5.8e-4). Within the tolerance A is their mean.
constexpr double kInertiaTolerance = 1e-9;
// A centre of mass, ball centre or stem off the symmetry axis by more than 1e-9 R is a modelled
// offset, not rounding (positions compile to ~1e-16 R).
constexpr double kAxisTolerance = 1e-9;
// The stem's axis against the principal axis, in rad: the principal axis of an axisymmetric
// body is exact to rounding unless C and A nearly coincide, where the eigenvector loses digits
// as eps/|C - A|; 1e-6 rad moves the stem tip by 1e-6 l, below anything the comparison resolves.
constexpr double kAngleTolerance = 1e-6;
// Depth of the probe contacts that read the compiled ball-floor and stem-floor parameters.
constexpr double kProbeDepth = 1e-3;

Vec3 v3(const mjtNum* p) { return Vec3(p[0], p[1], p[2]); }
Quat q4(const mjtNum* p) { return Quat(p[0], p[1], p[2], p[3]); }

}  // namespace

void Analyser::mass_and_axis(MjcfTopImport& out) {
  const double M = m_->body_mass[body_];
  if (!(M > 0)) fail("mass " + g(M) + ": the top needs a positive mass");
  const Vec3 I = v3(m_->body_inertia + 3 * body_);
  const Eigen::Matrix3d R_FI = q4(m_->body_iquat + 4 * body_).normalized().toRotationMatrix();
  G_ = v3(m_->body_ipos + 3 * body_);
  O_ = v3(m_->geom_pos + 3 * ball_);
  R_ = m_->geom_size[3 * ball_];
  out.principal_moments = {I.x(), I.y(), I.z()};
  const double Imax = I.maxCoeff();
  auto same = [&](int i, int j) { return std::abs(I[i] - I[j]) <= kInertiaTolerance * Imax; };
  int axial = -1;
  if (same(0, 1) && same(1, 2) && same(0, 2)) axial = -1;  // isotropic: the axis comes from the geometry
  else if (same(0, 1)) axial = 2;
  else if (same(0, 2)) axial = 1;
  else if (same(1, 2)) axial = 0;
  else
    fail("not axisymmetric: principal moments " + g(I.x()) + ", " + g(I.y()) + ", " + g(I.z()) +
         " (no two agree to " + g(kInertiaTolerance) + " of the largest; the reference needs A = B)");
  Vec3 a;
  double A, C;
  if (axial >= 0) {
    a = R_FI.col(axial);
    C = I[axial];
    A = 0.5 * (I[(axial + 1) % 3] + I[(axial + 2) % 3]);
  } else {
    A = C = I.mean();
    if (stem_ >= 0) a = stem_direction();
    else if ((O_ - G_).norm() > kAxisTolerance * R_) a = (O_ - G_).normalized();
    else a = Vec3::UnitZ();
  }
  // e_Z: from the ball towards the stem; without one, from G towards O (d > 0) or the frame's +z.
  if (stem_ >= 0) {
    const Vec3 s = stem_direction();
    if (axial >= 0 && a.cross(s).norm() > kAngleTolerance)
      fail("the stem '" + name_of(m_, mjOBJ_GEOM, stem_) + "' is not along the symmetry axis of the inertia (" +
           g(std::asin(std::min(1.0, a.cross(s).norm()))) + " rad apart)");
    if (a.dot(s) < 0) a = -a;
  } else if ((O_ - G_).dot(a) < 0 || ((O_ - G_).dot(a) == 0 && a.z() < 0)) {
    a = -a;
  }
  e_ = a;
  const Vec3 off = (G_ - O_) - (G_ - O_).dot(e_) * e_;
  if (off.norm() > kAxisTolerance * R_)
    fail("the centre of mass is " + g(off.norm()) + " off the symmetry axis through the ball's centre (tolerance " +
         g(kAxisTolerance) + " R)");
  out.mass.mass = M;
  out.mass.com_offset = (O_ - G_).dot(e_);
  out.mass.inertia_transverse = A;
  out.mass.inertia_axial = C;
  out.p_FG_F = G_;
  // B's transverse axes: any pair normal to e_Z (A = B); the frame's own x when it is normal.
  Vec3 ex = Vec3::UnitX() - Vec3::UnitX().dot(e_) * e_;
  if (ex.norm() < 0.5) ex = Vec3::UnitY() - Vec3::UnitY().dot(e_) * e_;
  ex.normalize();
  Eigen::Matrix3d R_FB;
  R_FB.col(0) = ex;
  R_FB.col(1) = e_.cross(ex);
  R_FB.col(2) = e_;
  out.q_FB = e_ == Vec3::UnitZ() ? Quat::Identity() : Quat(R_FB).normalized();
}

// The stem's direction away from the ball's centre, in F.
Vec3 Analyser::stem_direction() const {
  const Vec3 c = v3(m_->geom_pos + 3 * stem_);
  if (m_->geom_type[stem_] == mjGEOM_SPHERE) return (c - O_).normalized();
  Vec3 s = q4(m_->geom_quat + 4 * stem_).normalized() * Vec3::UnitZ();
  return s.dot(c - O_) < 0 ? Vec3(-s) : s;
}

void Analyser::stem_geometry(MjcfTopImport& out) {
  BodyGeometry& b = out.geometry;
  b.sphere_radius = R_;
  b.truncation_height = R_;  // MuJoCo's ball is a full sphere
  b.mass_model = MassModel::Given;
  out.stem = stem_ >= 0;
  if (!out.stem) return;
  const Vec3 c = v3(m_->geom_pos + 3 * stem_);
  const Vec3 off = (c - O_) - (c - O_).dot(e_) * e_;
  const std::string name = name_of(m_, mjOBJ_GEOM, stem_);
  if (off.norm() > kAxisTolerance * R_)
    fail("the stem '" + name + "' is " + g(off.norm()) + " off the symmetry axis (tolerance " + g(kAxisTolerance) + " R)");
  const double r = m_->geom_size[3 * stem_], half = m_->geom_size[3 * stem_ + 1];
  const double zc = (c - O_).dot(e_);
  b.stem_radius = r;
  switch (m_->geom_type[stem_]) {
    case mjGEOM_SPHERE:
      out.stem_type = "sphere";
      b.stem_length = zc;
      break;
    case mjGEOM_CAPSULE:
      out.stem_type = "capsule";
      b.stem_length = zc + half;
      break;
    default: {
      out.stem_type = "cylinder";
      const double top = zc + half;
      b.stem_length = top - r;
      out.notes.push_back("stem '" + name + "': MuJoCo's flat-ended cylinder (radius " + g(r) + ", top face " + g(top) +
                          " above the ball's centre) approximated by the reference's rounded tip of the same height "
                          "(tip centre at l = " + g(b.stem_length) +
                          "); the rim touches the floor at another point once the stem tilts");
    }
  }
  if (!(b.stem_length > 0)) fail("the stem '" + name + "' does not reach beyond the ball's centre along the axis");
}

// Reads the compiled contact of `geom` with the floor: MuJoCo's own mixing of the two geoms'
// parameters (priority, max of condim and friction, solmix, explicit pairs, the override flag)
// applied by mj_collision at a probe pose where only `geom` dips kProbeDepth of its size into the floor.
mjContact Analyser::probe(int geom, bool upside_down) const {
  std::unique_ptr<mjData, DataDeleter> d(mj_makeData(m_));
  if (!d) fail("mj_makeData failed");
  const Quat q_WB = upside_down ? Quat(0, 1, 0, 0) : Quat::Identity();  // e_Z up, or down (pi about x)
  const Quat q_WF = q_WB * q_FB_inv();
  // The touching sphere's centre: O for the ball, the tip centre P for the stem.
  const double size = m_->geom_size[3 * geom];
  const Vec3 centre_F = geom == ball_ ? O_ : O_ + stem_length_ * e_;
  const Vec3 p_WF = Vec3(0, 0, size * (1 - kProbeDepth)) - q_WF * centre_F;
  mjtNum* q = d->qpos + m_->jnt_qposadr[joint_];
  q[0] = p_WF.x(), q[1] = p_WF.y(), q[2] = p_WF.z();
  q[3] = q_WF.w(), q[4] = q_WF.x(), q[5] = q_WF.y(), q[6] = q_WF.z();
  mj_fwdPosition(m_, d.get());
  for (int i = 0; i < d->ncon; ++i) {
    const mjContact& c = d->contact[i];
    if ((c.geom1 == geom && c.geom2 == floor_) || (c.geom2 == geom && c.geom1 == floor_)) return c;
  }
  fail("MuJoCo makes no contact between geom '" + name_of(m_, mjOBJ_GEOM, geom) + "' and the floor '" +
       name_of(m_, mjOBJ_GEOM, floor_) + "' when they touch");
}

void Analyser::contact(MjcfTopImport& out) {
  q_FB_ = out.q_FB;
  stem_length_ = out.geometry.stem_length;
  const mjContact c = probe(ball_, false);
  out.condim = c.dim;
  for (int i = 0; i < 5; ++i) out.contact_friction[i] = c.friction[i];
  out.contact_margin = c.includemargin;
  for (int i = 0; i < 2; ++i) out.contact_solref[i] = c.solref[i];
  for (int i = 0; i < 5; ++i) out.contact_solimp[i] = c.solimp[i];
  ContactSpec& s = out.contact;
  s.stem = out.stem;
  if (c.dim >= 3 && c.friction[0] != c.friction[1])
    fail("the ball-floor contact's sliding friction is anisotropic (" + g(c.friction[0]) + " and " + g(c.friction[1]) +
         ", a <pair>'s): the reference's Coulomb friction is isotropic");
  switch (c.dim) {
    case 1: s.friction = FrictionLaw::None; break;
    case 3: s.friction = FrictionLaw::Coulomb, s.mu = c.friction[0]; break;
    case 4: s.friction = FrictionLaw::Coulomb, s.mu = c.friction[0], s.drilling = c.friction[2]; break;
    default:
      fail("the ball-floor contact has condim " + std::to_string(c.dim) +
           ": rolling friction (condim 6) has no counterpart in the reference");
  }
  if (c.includemargin > 0)
    out.notes.push_back("ball-floor contact margin " + g(c.includemargin) +
                        ": MuJoCo's contact acts that far before the surfaces touch, the reference's at touching");
  if (out.stem) {
    const mjContact t = probe(stem_, true);
    bool same = t.dim == c.dim;
    for (int i = 0; i < 5; ++i) same = same && t.friction[i] == c.friction[i];
    if (!same)
      fail("the stem-floor contact (condim " + std::to_string(t.dim) + ", friction " + g(t.friction[0]) + " " +
           g(t.friction[2]) + ") differs from the ball-floor contact (condim " + std::to_string(c.dim) + ", friction " +
           g(c.friction[0]) + " " + g(c.friction[2]) + "): the reference has one contact law for both");
  }
}

void Analyser::start(MjcfTopImport& out, const std::string& key_name) {
  int k = -1;
  if (!key_name.empty()) {
    k = mj_name2id(m_, mjOBJ_KEY, key_name.c_str());
    if (k < 0) fail("no keyframe named '" + key_name + "'");
  } else if (m_->nkey > 0) {
    k = 0;
  }
  out.keyframe_index = k;
  out.keyframe = k >= 0 ? (mj_id2name(m_, mjOBJ_KEY, k) ? mj_id2name(m_, mjOBJ_KEY, k) : "") : "";
  const int qadr = m_->jnt_qposadr[joint_], vadr = m_->jnt_dofadr[joint_];
  const mjtNum* qpos = (k >= 0 ? m_->key_qpos + k * m_->nq : m_->qpos0) + qadr;
  // A start that is not a number is refused here, naming the keyframe, not later in the scene.
  const std::string where = k >= 0 ? "keyframe '" + out.keyframe + "'" : "the body's pos/quat (qpos0)";
  for (int i = 0; i < 7; ++i)
    if (!std::isfinite(qpos[i])) fail(where + ": qpos[" + std::to_string(qadr + i) + "] = " + g(qpos[i]) + " is not a finite number");
  if (k >= 0)
    for (int i = 0; i < 6; ++i)
      if (!std::isfinite(m_->key_qvel[k * m_->nv + vadr + i]))
        fail(where + ": qvel[" + std::to_string(vadr + i) + "] = " + g(m_->key_qvel[k * m_->nv + vadr + i]) +
             " is not a finite number");
  const Vec3 p_WF = v3(qpos);
  // MuJoCo normalises the free joint's quaternion before use (mj_kinematics).
  const Quat q_WF = q4(qpos + 3).normalized();
  // Free joint velocity (MuJoCo 2.2): qvel[0:3] the linear velocity of the body frame's origin
  // in the world frame, qvel[3:6] the angular velocity in the body frame.
  Vec3 v_WF = Vec3::Zero(), w_F = Vec3::Zero();
  if (k >= 0) {
    const mjtNum* qvel = m_->key_qvel + k * m_->nv + vadr;
    v_WF = v3(qvel);
    w_F = v3(qvel + 3);
  }
  BodyState& x = out.start;
  x.t = 0.0;
  x.q_WB = q_WF * out.q_FB;
  x.w_B = out.q_FB.conjugate() * w_F;
  const Vec3 r_FG_W = q_WF * G_, w_W = q_WF * w_F;
  x.p_WG = p_WF + r_FG_W;
  x.v_WG = v_WF + w_W.cross(r_FG_W);
  // How the start sits on the floor: the reference starts with the lower sphere touching it.
  const Vec3 p_WO = p_WF + q_WF * O_, v_WO = v_WF + w_W.cross(q_WF * O_);
  double gap = p_WO.z() - R_, vz = v_WO.z();
  const char* what = "ball";
  if (out.stem) {
    const Vec3 P_F = O_ + out.geometry.stem_length * e_;
    const Vec3 p_WP = p_WF + q_WF * P_F, v_WP = v_WF + w_W.cross(q_WF * P_F);
    if (p_WP.z() - out.geometry.stem_radius < gap) {
      gap = p_WP.z() - out.geometry.stem_radius;
      vz = v_WP.z();
      what = "stem tip";
    }
  }
  out.start_gap = gap;
  out.start_vz_centre = vz;
  const std::string from = k >= 0 ? "keyframe '" + out.keyframe + "'" : "qpos0";
  if (gap > kAxisTolerance * R_)
    out.notes.push_back(from + " starts the " + what + " " + g(gap) + " above the floor: the reference starts in flight from there");
  else if (gap < -kAxisTolerance * R_)
    out.notes.push_back(from + " starts the " + what + " " + g(-gap) +
                        " inside the floor: the reference starts it touching (G " + g(-gap) + " higher)");
  if (gap <= kAxisTolerance * R_ && std::abs(vz) > kAxisTolerance * R_ * (1 + w_W.norm()))
    out.notes.push_back(from + " gives the " + what + "'s centre a vertical velocity " + g(vz) +
                        ": the reference starts it at 0 (G's vertical velocity " + g(x.v_WG.z() - vz) + ")");
}

}  // namespace tippe::mjcf_import_detail
