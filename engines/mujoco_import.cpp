// Reads a user's compiled MuJoCo model as a tippe top: finds the body, checks what the reference can represent, converts the start exactly.
#include "mujoco_top.h"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <locale>
#include <memory>
#include <sstream>
#include <vector>

#include "../analytic/mass_properties.h"

namespace tippe {
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

std::string g(double v) {
  std::ostringstream os;
  os.imbue(std::locale::classic());
  os.precision(12);
  os << v;
  return os.str();
}

std::string name_of(const mjModel* m, mjtObj type, int id) {
  const char* n = mj_id2name(m, type, id);
  return n && *n ? std::string(n) : std::string("#") + std::to_string(id);
}

const char* geom_type_name(int type) {
  switch (type) {
    case mjGEOM_PLANE: return "plane";
    case mjGEOM_HFIELD: return "height field";
    case mjGEOM_SPHERE: return "sphere";
    case mjGEOM_CAPSULE: return "capsule";
    case mjGEOM_ELLIPSOID: return "ellipsoid";
    case mjGEOM_CYLINDER: return "cylinder";
    case mjGEOM_BOX: return "box";
    case mjGEOM_MESH: return "mesh";
    default: return "geom";
  }
}

Vec3 v3(const mjtNum* p) { return Vec3(p[0], p[1], p[2]); }
Quat q4(const mjtNum* p) { return Quat(p[0], p[1], p[2], p[3]); }

struct DataDeleter {
  void operator()(mjData* d) const { mj_deleteData(d); }
};

// Whether MuJoCo would test geoms a and b for contact: an explicit <pair>, or the
// contype/conaffinity filter without an <exclude> of their bodies.
bool can_collide(const mjModel* m, int a, int b) {
  for (int p = 0; p < m->npair; ++p)
    if ((m->pair_geom1[p] == a && m->pair_geom2[p] == b) || (m->pair_geom1[p] == b && m->pair_geom2[p] == a))
      return true;
  const int ba = m->geom_bodyid[a], bb = m->geom_bodyid[b];
  const int sig1 = ((std::min(ba, bb) + 1) << 16) + std::max(ba, bb) + 1;
  const int sig2 = ((std::max(ba, bb) + 1) << 16) + std::min(ba, bb) + 1;
  for (int e = 0; e < m->nexclude; ++e)
    if (m->exclude_signature[e] == sig1 || m->exclude_signature[e] == sig2) return false;
  return (m->geom_contype[a] & m->geom_conaffinity[b]) || (m->geom_contype[b] & m->geom_conaffinity[a]);
}

class Analyser {
 public:
  Analyser(const mjModel* m, std::string label) : m_(m), label_(std::move(label)) {}

  [[noreturn]] void fail(const std::string& why) const {
    throw MjcfImportError(label_ + ": " + (body_ >= 0 ? "body '" + name_of(m_, mjOBJ_BODY, body_) + "': " : "") + why);
  }

  MjcfTopImport run(const std::string& body_name, const std::string& key_name, MjTopIds* ids) {
    MjcfTopImport out;
    out.file = label_;
    out.mujoco_version = mj_versionString();
    find_body(body_name);
    out.body = name_of(m_, mjOBJ_BODY, body_);
    check_model();
    out.gravity = -m_->opt.gravity[2];
    out.timestep = m_->opt.timestep;
    find_geoms(out);
    mass_and_axis(out);
    stem_geometry(out);
    contact(out);
    start(out, key_name);
    if (ids) {
      ids->body = body_;
      ids->joint = joint_;
      ids->qadr = m_->jnt_qposadr[joint_];
      ids->vadr = m_->jnt_dofadr[joint_];
      ids->ball = ball_;
      ids->stem = stem_;
      ids->floor = floor_;
      ids->key = out.keyframe_index;
    }
    return out;
  }

 private:
  void find_body(const std::string& wanted) {
    std::vector<int> free;
    for (int b = 1; b < m_->nbody; ++b)
      for (int j = m_->body_jntadr[b]; j >= 0 && j < m_->body_jntadr[b] + m_->body_jntnum[b]; ++j)
        if (m_->jnt_type[j] == mjJNT_FREE) free.push_back(b);
    if (!wanted.empty()) {
      const int b = mj_name2id(m_, mjOBJ_BODY, wanted.c_str());
      if (b < 0) fail("no body named '" + wanted + "'");
      body_ = b;
      if (std::find(free.begin(), free.end(), b) == free.end()) fail("has no free joint (the top must be a free body)");
    } else {
      if (free.empty()) fail("no body with a free joint (the top must be a free body)");
      if (free.size() > 1) {
        std::string list;
        for (int b : free) list += (list.empty() ? "'" : ", '") + name_of(m_, mjOBJ_BODY, b) + "'";
        fail("several free bodies (" + list + "): choose the top with --body");
      }
      body_ = free.front();
    }
    joint_ = m_->body_jntadr[body_];
    if (m_->body_jntnum[body_] != 1) fail("has " + std::to_string(m_->body_jntnum[body_]) + " joints (the top has one free joint)");
  }

  void check_model() {
    if (m_->nv != 6)
      fail("the model has " + std::to_string(m_->nv - 6) +
           " degrees of freedom besides the top's free joint (the reference has the top alone)");
    for (int b = 1; b < m_->nbody; ++b)
      if (b != body_ && m_->body_parentid[b] == body_)
        fail("has child body '" + name_of(m_, mjOBJ_BODY, b) +
             "' (its mass is not in body_mass: merge its geoms into the top's body)");
    if (m_->neq > 0) fail("the model has " + std::to_string(m_->neq) + " equality constraint(s): the reference has none");
    if (m_->nu > 0) fail(std::to_string(m_->nu) + " actuator(s) act on the top: the reference has no actuation");
    if (m_->ntendon > 0) fail("the model has " + std::to_string(m_->ntendon) + " tendon(s): the reference has none");
    // Joint properties of the free joint change the dynamics (armature adds inertia, damping and
    // frictionloss add forces) and have no counterpart in the reference.
    for (int v = m_->jnt_dofadr[joint_]; v < m_->jnt_dofadr[joint_] + 6; ++v) {
      if (m_->dof_armature[v] != 0) fail("the free joint has armature " + g(m_->dof_armature[v]) + ": the reference has none");
      if (m_->dof_damping[v] != 0) fail("the free joint has damping " + g(m_->dof_damping[v]) + ": the reference has none");
      if (m_->dof_frictionloss[v] != 0)
        fail("the free joint has frictionloss " + g(m_->dof_frictionloss[v]) + ": the reference has none");
    }
    if (m_->opt.disableflags & (mjDSBL_CONSTRAINT | mjDSBL_CONTACT))
      fail("contacts are disabled (option flag): the top would fall through the floor");
    if (m_->opt.disableflags & mjDSBL_GRAVITY) fail("gravity is disabled (option flag): the reference needs g > 0");
    if (m_->opt.density > 0 || m_->opt.viscosity > 0)
      fail("option density " + g(m_->opt.density) + ", viscosity " + g(m_->opt.viscosity) +
           ": the reference has no fluid forces");
    const mjtNum* gr = m_->opt.gravity;
    if (!(gr[0] == 0 && gr[1] == 0 && gr[2] < 0))
      fail("gravity " + g(gr[0]) + " " + g(gr[1]) + " " + g(gr[2]) + " does not point along -z (the floor's normal is +z)");
  }

  void find_geoms(MjcfTopImport& out) {
    std::vector<int> own, statics;
    for (int i = 0; i < m_->ngeom; ++i) {
      if (m_->geom_bodyid[i] == body_) own.push_back(i);
      else if (m_->body_weldid[m_->geom_bodyid[i]] == 0) statics.push_back(i);
    }
    // The floor: the one static geom any of the top's geoms can touch.
    std::vector<int> touching;
    for (int f : statics)
      for (int i : own)
        if (can_collide(m_, i, f)) {
          touching.push_back(f);
          break;
        }
    if (touching.empty()) fail("no floor: no static geom can touch the top");
    if (touching.size() > 1)
      fail("several static geoms can touch the top ('" + name_of(m_, mjOBJ_GEOM, touching[0]) + "', '" +
           name_of(m_, mjOBJ_GEOM, touching[1]) + "'): the reference has one floor");
    floor_ = touching.front();
    if (m_->geom_type[floor_] != mjGEOM_PLANE)
      fail("the floor '" + name_of(m_, mjOBJ_GEOM, floor_) + "' is a " + geom_type_name(m_->geom_type[floor_]) +
           ", not a plane: the reference's floor is the plane z = 0");
    // The floor's pose in the world: kinematics of the model at qpos0.
    std::unique_ptr<mjData, DataDeleter> d(mj_makeData(m_));
    if (!d) fail("mj_makeData failed");
    mj_kinematics(m_, d.get());
    const mjtNum* xm = d->geom_xmat + 9 * floor_;
    const double z = d->geom_xpos[3 * floor_ + 2];
    // Exact: a floor placed or turned in MJCF is a modelling choice the bench's world (z = 0, +z
    // up) would silently change.
    if (!(xm[2] == 0 && xm[5] == 0 && xm[8] == 1 && z == 0))
      fail("the floor plane '" + name_of(m_, mjOBJ_GEOM, floor_) + "' is not z = 0 with normal +z (normal " + g(xm[2]) +
           " " + g(xm[5]) + " " + g(xm[8]) + ", height " + g(z) + ")");

    std::vector<int> spheres, sticks;
    std::string mass_only;
    for (int i : own) {
      if (!can_collide(m_, i, floor_)) {
        mass_only += (mass_only.empty() ? "'" : ", '") + name_of(m_, mjOBJ_GEOM, i) + "'";
        continue;
      }
      const int t = m_->geom_type[i];
      if (t == mjGEOM_SPHERE) spheres.push_back(i);
      else if (t == mjGEOM_CAPSULE || t == mjGEOM_CYLINDER) sticks.push_back(i);
      else
        fail("geom '" + name_of(m_, mjOBJ_GEOM, i) + "' (" + geom_type_name(t) +
             ") can touch the floor: the reference's top touches it only with a sphere (the ball) and a capsule, "
             "cylinder or smaller sphere on its axis (the stem)");
    }
    if (spheres.empty()) fail("no sphere geom that touches the floor (the ball)");
    if (spheres.size() > 2) fail(std::to_string(spheres.size()) + " sphere geoms touch the floor: the reference has one ball");
    if (spheres.size() == 2) {
      std::sort(spheres.begin(), spheres.end(), [&](int a, int b) { return m_->geom_size[3 * a] > m_->geom_size[3 * b]; });
      if (m_->geom_size[3 * spheres[0]] == m_->geom_size[3 * spheres[1]])
        fail("two sphere geoms of the same radius touch the floor ('" + name_of(m_, mjOBJ_GEOM, spheres[0]) + "', '" +
             name_of(m_, mjOBJ_GEOM, spheres[1]) + "'): the reference has one ball");
      sticks.push_back(spheres[1]);
    }
    if (sticks.size() > 1)
      fail("several stem geoms touch the floor ('" + name_of(m_, mjOBJ_GEOM, sticks[0]) + "', '" +
           name_of(m_, mjOBJ_GEOM, sticks[1]) + "'): the reference has one stem");
    ball_ = spheres[0];
    stem_ = sticks.empty() ? -1 : sticks[0];
    if (!mass_only.empty()) out.notes.push_back("geoms " + mass_only + " cannot touch the floor: they carry mass only");
  }

  void mass_and_axis(MjcfTopImport& out) {
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
  Vec3 stem_direction() const {
    const Vec3 c = v3(m_->geom_pos + 3 * stem_);
    if (m_->geom_type[stem_] == mjGEOM_SPHERE) return (c - O_).normalized();
    Vec3 s = q4(m_->geom_quat + 4 * stem_).normalized() * Vec3::UnitZ();
    return s.dot(c - O_) < 0 ? Vec3(-s) : s;
  }

  void stem_geometry(MjcfTopImport& out) {
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
  mjContact probe(int geom, bool upside_down) const {
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

  Quat q_FB_inv() const { return q_FB_.conjugate(); }

  void contact(MjcfTopImport& out) {
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

  void start(MjcfTopImport& out, const std::string& key_name) {
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

  const mjModel* m_;
  std::string label_;
  int body_ = -1, joint_ = -1, ball_ = -1, stem_ = -1, floor_ = -1;
  Vec3 G_ = Vec3::Zero(), O_ = Vec3::Zero(), e_ = Vec3::UnitZ();
  double R_ = 0.0, stem_length_ = 0.0;
  Quat q_FB_ = Quat::Identity();
};

}  // namespace

std::mutex& mujoco_load_mutex() {
  static std::mutex mutex;
  return mutex;
}

// MuJoCo's messages span lines (the XML parser's); a message of the bench is one line.
std::string one_line(const char* text) {
  std::string out;
  for (const char* c = text; *c; ++c) {
    const bool space = *c == '\n' || *c == '\r' || *c == '\t' || *c == ' ';
    if (space && (out.empty() || out.back() == ' ')) continue;
    out += space ? ' ' : *c;
  }
  while (!out.empty() && out.back() == ' ') out.pop_back();
  return out;
}

mjModel* load_mjcf_file(const std::string& path, std::string& warning) {
  // The file's own failure first, in the words every other input file uses.
  {
    std::error_code ec;
    if (std::filesystem::is_directory(path, ec)) throw MjcfImportError(path + ": cannot read: is a directory");
    std::ifstream in(path);
    if (!in) throw MjcfImportError(path + ": cannot read: " + std::strerror(errno));
  }
  std::lock_guard<std::mutex> lock(mujoco_load_mutex());
  char error[1024] = "";
  mjModel* m = mj_loadXML(path.c_str(), nullptr, error, sizeof error);
  if (!m) throw MjcfImportError(path + ": MuJoCo cannot load it: " + (*error ? one_line(error) : "unknown error"));
  warning = one_line(error);
  return m;
}

MjcfTopImport analyse_mjcf_top(const mjModel* m, const std::string& label, const std::string& body,
                               const std::string& keyframe, MjTopIds* ids) {
  return Analyser(m, label).run(body, keyframe, ids);
}

MjcfTopImport import_mjcf_top(const std::string& path, const std::string& body, const std::string& keyframe) {
  std::string warning;
  struct ModelDeleter {
    void operator()(mjModel* m) const { mj_deleteModel(m); }
  };
  std::unique_ptr<mjModel, ModelDeleter> m(load_mjcf_file(path, warning));
  MjcfTopImport out = analyse_mjcf_top(m.get(), path, body, keyframe);
  if (!warning.empty()) out.notes.push_back("MuJoCo's compiler warned: " + warning);
  return out;
}

std::vector<std::string> mjcf_scene_mismatches(const MjcfTopImport& top, const Scene& scene) {
  std::vector<std::string> out;
  // The scene's numbers are the model's written with 17 significant digits (exact); 1e-12 admits a
  // scene written by hand with 13.
  auto check = [&](const char* key, double scene_value, double model_value) {
    if (!(std::abs(scene_value - model_value) <= 1e-12 * std::max(std::abs(model_value), 1e-300)) &&
        !(scene_value == model_value))
      out.push_back(std::string(key) + " = " + g(scene_value) + " but the model has " + g(model_value));
  };
  check("gravity", scene.gravity, top.gravity);
  check("body.mass", scene.mass.mass, top.mass.mass);
  check("body.com_offset", scene.mass.com_offset, top.mass.com_offset);
  check("body.inertia_transverse", scene.mass.inertia_transverse, top.mass.inertia_transverse);
  check("body.inertia_axial", scene.mass.inertia_axial, top.mass.inertia_axial);
  check("body.sphere_radius", scene.body.sphere_radius, top.geometry.sphere_radius);
  if (scene.contact.stem != top.stem)
    out.push_back(std::string("contact.stem = ") + (scene.contact.stem ? "true" : "false") + " but the model " +
                  (top.stem ? "has" : "has no") + " stem");
  if (top.stem && scene.contact.stem) {
    check("body.stem_radius", scene.body.stem_radius, top.geometry.stem_radius);
    check("body.stem_length", scene.body.stem_length, top.geometry.stem_length);
  }
  if (scene.contact.friction != top.contact.friction)
    out.push_back(std::string("contact.friction = \"") + to_string(scene.contact.friction) + "\" but the model's contact is \"" +
                  to_string(top.contact.friction) + "\" (condim " + std::to_string(top.condim) + ")");
  else {
    check("contact.mu", scene.contact.mu, top.contact.mu);
    check("contact.drilling", scene.contact.drilling, top.contact.drilling);
  }
  return out;
}

}  // namespace tippe
