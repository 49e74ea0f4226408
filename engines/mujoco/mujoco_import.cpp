// Reads a user's MuJoCo model as a tippe top: loading the file, finding the body and checking what the reference can represent, and comparing a scene with it.
#include "engines/mujoco/mujoco_top.h"

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

#include "engines/mujoco/mujoco_import_analyser.h"
#include "engines/mujoco/mujoco_settings.h"
#include "engines/core/settings.h"

namespace tippe {

namespace mjcf_import_detail {

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

namespace {

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

}  // namespace

void Analyser::fail(const std::string& why) const {
  throw MjcfImportError(label_ + ": " + (body_ >= 0 ? "body '" + name_of(m_, mjOBJ_BODY, body_) + "': " : "") + why);
}

MjcfTopImport Analyser::run(const std::string& body_name, const std::string& key_name, MjTopIds* ids) {
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

void Analyser::find_body(const std::string& wanted) {
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

void Analyser::check_model() {
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
  check_options();
  const mjtNum* gr = m_->opt.gravity;
  if (!(std::isfinite(gr[2]) && gr[0] == 0 && gr[1] == 0 && gr[2] < 0))
    fail("gravity " + g(gr[0]) + " " + g(gr[1]) + " " + g(gr[2]) + " does not point along -z (the floor's normal is +z)");
}

// The model's own options pass the bounds of the [engines.mujoco] keys that stand for them, one
// range check whichever source a setting comes from: a timestep of 0 or 1e-300 never ends, nan
// runs no step and a negative one runs backwards.
void Analyser::check_options() const {
  const mjOption& o = m_->opt;
  const std::map<std::string, SettingValue> options = {
      {"timestep", static_cast<double>(o.timestep)},
      {"impratio", static_cast<double>(o.impratio)},
      {"iterations", static_cast<long long>(o.iterations)},
      {"tolerance", static_cast<double>(o.tolerance)},
      {"noslip_iterations", static_cast<long long>(o.noslip_iterations)},
      {"noslip_tolerance", static_cast<double>(o.noslip_tolerance)}};
  MujocoSettings bounds;
  SettingsReader reader("mujoco", options);
  try {
    bounds.visit(reader);
  } catch (const std::invalid_argument& e) {
    // "engines.mujoco.KEY: why" -> "FILE: <option KEY>: why (the bounds of engines.mujoco.KEY)"
    const std::string text = e.what();
    const size_t colon = text.find(": ");
    const std::string key = text.substr(0, colon), why = colon == std::string::npos ? text : text.substr(colon + 2);
    const std::string attribute = key.substr(key.rfind('.') + 1);
    throw MjcfImportError(label_ + ": <option " + attribute + ">: " + why + " (the bounds of " + key + ")");
  }
}

void Analyser::find_geoms(MjcfTopImport& out) {
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

}  // namespace mjcf_import_detail

using namespace mjcf_import_detail;

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
