// The MuJoCo adapter's user-model mode (engines.mujoco.model): the model checked against the scene, the scene's overrides on it, its notes and settings.
#include "engines/mujoco/mujoco_user_model.h"

#include "engines/core/settings.h"

#include <algorithm>
#include <sstream>
#include <stdexcept>

namespace tippe {
namespace {

std::string num(double v) { return round_trip_text(v); }

struct ModelOwner {
  mjModel* m = nullptr;
  ~ModelOwner() {
    if (m) mj_deleteModel(m);
  }
};

const char* integrator_name(int i) { return i == mjINT_EULER ? "Euler" : i == mjINT_RK4 ? "RK4" : "implicit"; }
const char* solver_name(int i) { return i == mjSOL_PGS ? "PGS" : i == mjSOL_CG ? "CG" : "Newton"; }
const char* cone_name(int i) { return i == mjCONE_ELLIPTIC ? "elliptic" : "pyramidal"; }


}  // namespace

bool mujoco_setting_given(const Scene& scene, const char* key) {
  const auto e = scene.engines.find("mujoco");
  return e != scene.engines.end() && e->second.count(key) > 0;
}

// The user's model, compiled, with the top found and checked against the scene: a scene whose
// body, contact or gravity differ from the model's would compare the reference with another
// top. Throws std::invalid_argument "engines.mujoco.model: ...".
MjcfTopImport check_user_model(const Scene& scene, const MujocoSettings& s, mjModel** keep, MjTopIds* ids,
                              std::string* warning) {
  ModelOwner owner;
  std::string w;
  try {
    owner.m = load_mjcf_file(s.model, w);
    MjcfTopImport top = analyse_mjcf_top(owner.m, s.model, s.body, s.keyframe, ids);
    const auto mismatches = mjcf_scene_mismatches(top, scene);
    if (!mismatches.empty()) {
      std::string why;
      for (const auto& x : mismatches) why += (why.empty() ? "" : "; ") + x;
      throw MjcfImportError(s.model + ": the scene is not this model's top (" + why +
                           "): MuJoCo would run another body than the reference");
    }
    if (keep) std::swap(*keep, owner.m);
    if (warning) *warning = w;
    return top;
  } catch (const MjcfImportError& e) {
    throw std::invalid_argument(std::string("engines.mujoco.model: ") + e.what());
  }
}

// The keys given in [engines.mujoco], applied on the compiled model; returns their names.
std::vector<std::string> apply_user_overrides(mjModel* m, const Scene& scene, const MujocoSettings& s,
                                             const MjTopIds& ids) {
  std::vector<std::string> keys;
  auto mark = [&](const char* k) {
    if (!mujoco_setting_given(scene, k)) return false;
    keys.push_back(k);
    return true;
  };
  if (mark("timestep")) m->opt.timestep = s.timestep;
  if (mark("integrator"))
    m->opt.integrator = s.integrator == "Euler" ? mjINT_EULER : s.integrator == "RK4" ? mjINT_RK4 : mjINT_IMPLICIT;
  if (mark("cone")) m->opt.cone = s.cone == "elliptic" ? mjCONE_ELLIPTIC : mjCONE_PYRAMIDAL;
  if (mark("impratio")) m->opt.impratio = s.impratio;
  if (mark("solver")) m->opt.solver = s.solver == "Newton" ? mjSOL_NEWTON : s.solver == "CG" ? mjSOL_CG : mjSOL_PGS;
  if (mark("iterations")) m->opt.iterations = s.iterations;
  if (mark("tolerance")) m->opt.tolerance = s.tolerance;
  if (mark("noslip_iterations")) m->opt.noslip_iterations = s.noslip_iterations;
  if (mark("noslip_tolerance")) m->opt.noslip_tolerance = s.noslip_tolerance;
  // solref and solimp on every geom of the top's contacts and on <pair>s among them, so that
  // MuJoCo's mixing (solmix, priority) yields exactly the given values.
  const bool ref = mark("solref"), imp = mark("solimp");
  auto ours = [&](int g) { return g >= 0 && (g == ids.ball || g == ids.stem || g == ids.floor); };
  for (int g = 0; g < m->ngeom; ++g) {
    if (!ours(g)) continue;
    if (ref) std::copy(s.solref.begin(), s.solref.end(), m->geom_solref + mjNREF * g);
    if (imp) std::copy(s.solimp.begin(), s.solimp.end(), m->geom_solimp + mjNIMP * g);
  }
  for (int p = 0; p < m->npair; ++p) {
    if (!ours(m->pair_geom1[p]) || !ours(m->pair_geom2[p])) continue;
    if (ref) std::copy(s.solref.begin(), s.solref.end(), m->pair_solref + mjNREF * p);
    if (imp) std::copy(s.solimp.begin(), s.solimp.end(), m->pair_solimp + mjNIMP * p);
  }
  return keys;
}

// Whether the scene's start is the keyframe's (the import's): orientation, angular velocity and
// G's horizontal position and velocity. The vertical ones the reference derives from the floor
// contact, so they are not compared. 1e-12: the import writes 17 significant digits, so its
// round trip through the scene text and scene_initial_state is exact to a few ulp; any
// deliberate change (--set initial.spin=...) is far larger.
bool same_start(const BodyState& scene, const BodyState& model, double R) {
  constexpr double tol = 1e-12;
  const double dq = std::min((scene.q_WB.coeffs() - model.q_WB.coeffs()).norm(),
                            (scene.q_WB.coeffs() + model.q_WB.coeffs()).norm());
  const double w = model.w_B.norm();
  auto h = [](const Vec3& v) { return Vec3(v.x(), v.y(), 0.0); };
  return dq <= tol && (scene.w_B - model.w_B).norm() <= tol * w &&
         (h(scene.p_WG) - h(model.p_WG)).norm() <= tol * (R + h(model.p_WG).norm()) &&
         (h(scene.v_WG) - h(model.v_WG)).norm() <= tol * (h(model.v_WG).norm() + w * R);
}


std::vector<std::string> user_model_notes(const mjModel* m, const MjcfTopImport& top, const std::string& model,
                                         bool keyframe_start, const std::vector<std::string>& overridden,
                                         const std::string& compiler_warning) {
  std::vector<std::string> notes;
  const int condim = top.condim;
  const Quat q_FB = top.q_FB;
  const Vec3 p_FG_F = top.p_FG_F;
  auto g = [](double v) {
    std::ostringstream os;
    os << v;
    return os.str();
  };
  const mjOption& o = m->opt;
  const std::string from = top.keyframe_index >= 0 ? "keyframe '" + top.keyframe + "'" : "qpos0";
  notes.push_back("MuJoCo runs the model " + model + " as written (body '" + top.body + "'), not the bench's MJCF");
  notes.push_back(keyframe_start ? "start: " + from + " of the model, as written"
                                 : "start: the scene's initial state, not " + from + " of the model (the scene changes it)");
  notes.push_back("model options: timestep " + g(o.timestep) + ", integrator " + integrator_name(o.integrator) + ", cone " +
                  cone_name(o.cone) + ", solver " + solver_name(o.solver) + " (iterations " + std::to_string(o.iterations) +
                  ", tolerance " + g(o.tolerance) + "), impratio " + g(o.impratio) + ", noslip_iterations " +
                  std::to_string(o.noslip_iterations));
  if (!overridden.empty()) {
    std::string keys;
    for (const auto& k : overridden) keys += (keys.empty() ? "" : ", ") + k;
    notes.push_back("overridden by the scene (engines.mujoco): " + keys);
  }
  const mjtNum* fr = top.contact_friction.data();
  notes.push_back("ball-floor contact as compiled: condim " + std::to_string(top.condim) + ", friction " + g(fr[0]) + " " +
                  g(fr[2]) + " " + g(fr[3]) + ", margin " + g(top.contact_margin));
  // The body frame's origin F relative to G, in the principal frame B.
  const Vec3 f_B = q_FB.conjugate() * (-p_FG_F);
  notes.push_back("body frame: the model's own, origin at (" + g(f_B.x()) + ", " + g(f_B.y()) + ", " + g(f_B.z()) +
                  ") from G in the principal frame: MuJoCo's results depend on it");
  // MuJoCo's refsafe rule on the contact's solref (engine_core_constraint.c, getsolparam).
  const double tc = top.contact_solref[0];
  if (tc > 0 && tc < 2 * o.timestep && !(o.disableflags & mjDSBL_REFSAFE))
    notes.push_back("contact solref timeconst " + g(tc) + " raised by MuJoCo to 2 timestep = " + g(2 * o.timestep) +
                   " (its refsafe rule)");
  if (condim >= 4)
    notes.push_back("drilling friction (condim " + std::to_string(condim) +
                    "): MuJoCo bounds the tangential force and the drilling torque jointly, not each alone");
  // MuJoCo raises every friction coefficient the contact uses to mjMINMU.
  if ((condim >= 3 && !(top.contact_friction[0] >= mjMINMU)) || (condim >= 4 && !(top.contact_friction[2] >= mjMINMU)))
    notes.push_back("a friction coefficient below MuJoCo's minimum mjMINMU = 1e-5 acts as that minimum, not as frictionless");
  if (condim >= 3 && o.cone == mjCONE_PYRAMIDAL) notes.push_back("friction cone approximated by MuJoCo's pyramid (cone pyramidal)");
  if (condim >= 3)
    notes.push_back("while slipping, MuJoCo's convex contact pushes the ball off the floor: the contact hops (intermittent normal force, many switch events)");
  if (o.integrator != mjINT_RK4) notes.push_back(std::string("integrator ") + integrator_name(o.integrator) + ": first order in the timestep");
  if (!compiler_warning.empty()) notes.push_back("mujoco compiler: " + compiler_warning);
  return notes;
}

SettingsList user_model_settings(const mjModel* m, const MjcfTopImport& top, const std::string& model,
                                bool keyframe_start) {
  const mjOption& o = m->opt;
  auto n17 = [](const double* v, int n) {
    std::string out = "[";
    for (int i = 0; i < n; ++i) out += (i ? ", " : "") + num(v[i]);
    return out + "]";
  };
  SettingsList list;
  list.emplace_back("model", model);
  list.emplace_back("body", top.body);
  list.emplace_back("keyframe", top.keyframe_index >= 0 ? top.keyframe : "(qpos0)");
  list.emplace_back("start", keyframe_start ? "keyframe" : "scene");
  list.emplace_back("timestep", num(o.timestep));
  list.emplace_back("integrator", integrator_name(o.integrator));
  list.emplace_back("cone", cone_name(o.cone));
  list.emplace_back("impratio", num(o.impratio));
  list.emplace_back("solver", solver_name(o.solver));
  list.emplace_back("iterations", std::to_string(o.iterations));
  list.emplace_back("tolerance", num(o.tolerance));
  list.emplace_back("noslip_iterations", std::to_string(o.noslip_iterations));
  list.emplace_back("noslip_tolerance", num(o.noslip_tolerance));
  // The ball-floor contact as MuJoCo builds it (mixed from the two geoms, or a <pair>).
  list.emplace_back("condim_used", std::to_string(top.condim));
  list.emplace_back("friction_used", n17(top.contact_friction.data(), 5));
  list.emplace_back("solref_used", n17(top.contact_solref.data(), 2));
  list.emplace_back("solimp_used", n17(top.contact_solimp.data(), 5));
  list.emplace_back("margin_used", num(top.contact_margin));
  return list;
}

}  // namespace tippe
