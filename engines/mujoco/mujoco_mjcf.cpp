// The bench's MJCF of a scene: engines.mujoco settings checked, the contact as MuJoCo will use it, the model text and its compilation, and export-mjcf's text.
#include "engines/mujoco/mujoco_mjcf.h"

#include <mujoco/mujoco.h>
#include <algorithm>
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
#include "engines/core/adapters.h"
#include "engines/core/fixed_step.h"
#include "engines/mujoco/mujoco_settings.h"
#include "engines/mujoco/mujoco_top.h"
#include "engines/mujoco/mujoco_user_model.h"
#include "engines/core/registry.h"
#include "engines/core/settings.h"

namespace tippe::mujoco_detail {

namespace {

[[noreturn]] void setting_error(const std::string& key, const std::string& why) {
  throw std::invalid_argument("engines.mujoco." + key + ": " + why);
}

std::string num(double v) { return round_trip_text(v); }

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

}  // namespace

MujocoSettings read_checked_settings(const Scene& scene) {
  MujocoSettings s = read_settings<MujocoSettings>("mujoco", scene);
  check_combination(s);
  if (!s.model.empty()) {
    // These shape the bench's own MJCF only; the user's model decides them.
    for (const char* k : {"body_frame", "stem_shape", "margin", "condim", "rolling_mu", "noslip_iterations_rolling"})
      if (mujoco_setting_given(scene, k))
        setting_error(k, "not used with engines.mujoco.model (the model decides it: edit the model instead)");
  } else {
    for (const char* k : {"body", "keyframe"})
      if (mujoco_setting_given(scene, k)) setting_error(k, "only used with engines.mujoco.model");
  }
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
     << "\" margin=\"" << num(s.margin) << "\" gap=\"0\"/>\n";
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
  if (m.stem && s.stem_shape == "tip_sphere")
    os << "      <geom name=\"stem\" type=\"sphere\" size=\"" << num(m.r) << "\" pos=\""
       << vec({0.0, 0.0, m.z_P() - z0}) << "\" contype=\"2\" conaffinity=\"1\"/>\n";
  else if (m.stem)
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

// Compiles MJCF text through a one-file VFS (no temporary file). Throws std::runtime_error
// with MuJoCo's message; compiler warnings of a successful load go to `warning`.
mjModel* compile_mjcf(const std::string& xml, std::string& warning) {
  std::lock_guard<std::mutex> lock(mujoco_load_mutex());
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

}  // namespace tippe::mujoco_detail

namespace tippe {

using namespace mujoco_detail;

// `tippe export-mjcf` (adapters.h): the bench's own MJCF of a scene, and what it cannot carry.
std::string mujoco_mjcf(const Scene& scene) {
  const MujocoSettings s = read_checked_settings(scene);
  if (!s.model.empty())
    throw std::invalid_argument("engines.mujoco.model: the scene runs the user's model " + s.model +
                                "; that file is its MuJoCo model (export-mjcf writes the bench's own)");
  return build_mjcf(scene, s);
}

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
