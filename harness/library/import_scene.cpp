// `tippe import-mjcf`'s scene: a user's MuJoCo model (MJCF) as a scene file's text, checked by reading it back.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <locale>
#include <sstream>

#include "harness/io/output_dir.h"
#include "harness/io/scene_io.h"
#include "harness/io/text.h"
#include "harness/scene/resolve.h"
#include "harness/library/verbs.h"
#include "engines/mujoco/mujoco_api.h"
#include "engines/core/settings.h"

namespace tippe {

namespace {

namespace fs = std::filesystem;

// A TOML float that reads back to the same double (round_trip_text, always with a point or an
// exponent).
std::string tf(double v) {
  std::string s = round_trip_text(v);
  if (s.find_first_of(".e") == std::string::npos) s += ".0";
  return s;
}


// A TOML basic string: the text is UTF-8 (checked), quotes, backslashes and controls escaped.
std::string ts(const std::string& text) {
  std::string out = "\"";
  for (unsigned char c : text) {
    if (c == '"' || c == '\\') {
      out += '\\';
      out += static_cast<char>(c);
    } else if (c < 0x20 || c == 0x7f) {
      char buf[8];
      std::snprintf(buf, sizeof buf, "\\u%04x", c);
      out += buf;
    } else {
      out += static_cast<char>(c);
    }
  }
  return out + "\"";
}

std::string array(std::initializer_list<double> xs) {
  std::string out = "[";
  for (double x : xs) out += (out.size() > 1 ? ", " : "") + tf(x);
  return out + "]";
}

std::string scene_text(const MjcfTopImport& top, const MjcfSceneRequest& o, const std::string& model_path,
                       const std::string& name, double sample_interval) {
  const std::string file = fs::path(top.file).filename().string();
  const std::string from = top.keyframe_index >= 0 ? "keyframe '" + top.keyframe + "'" : "qpos0";
  std::vector<std::string> notes;
  notes.push_back("imported from " + file + " (body '" + top.body + "', " + from + ") as MuJoCo " + top.mujoco_version +
                  " compiled it: mass properties, geometry, contact, gravity and start");
  notes.insert(notes.end(), top.notes.begin(), top.notes.end());
  // The reference starts touching the floor, or in flight from where the keyframe puts it.
  const double tol = 1e-9 * top.geometry.sphere_radius;
  const bool flight = top.start_gap > tol;

  std::ostringstream t;
  t << "# Imported from " << file << " by `tippe import-mjcf`: the body, contact, gravity and start as MuJoCo\n"
    << "# compiled them. [engines.mujoco] model runs that file as written (its options, its frame, its\n"
    << "# keyframe); the reference and the other engines get the body below. Import again after editing the\n"
    << "# model: the MuJoCo run refuses a scene whose body, contact or gravity no longer match it.\n";
  t << "name = " << ts(name) << "\n";
  t << "description = " << ts("Imported from " + file + ", body '" + top.body + "', " + from) << "\n";
  t << "gravity = " << tf(top.gravity) << "\n";
  t << "notes = [\n";
  for (const auto& n : notes) t << "  " << ts(n) << ",\n";
  t << "]\n\n[body]\n";
  const BodyGeometry& b = top.geometry;
  t << "sphere_radius = " << tf(b.sphere_radius) << "\n";
  if (top.stem) t << "stem_radius = " << tf(b.stem_radius) << "\nstem_length = " << tf(b.stem_length) << "\n";
  t << "truncation_height = " << tf(b.truncation_height) << "  # MuJoCo's ball is a full sphere\n";
  t << "mass = " << tf(top.mass.mass) << "\n";
  t << "com_offset = " << tf(top.mass.com_offset) << "\n";
  t << "inertia_transverse = " << tf(top.mass.inertia_transverse) << "\n";
  t << "inertia_axial = " << tf(top.mass.inertia_axial) << "\n\n[contact]\n";
  t << "# condim " << top.condim << ", friction " << g6(top.contact_friction[0]) << " "
    << g6(top.contact_friction[2]) << " " << g6(top.contact_friction[3])
    << " (MuJoCo's mixing of the ball's and the floor's)\n";
  t << "friction = " << ts(to_string(top.contact.friction)) << "\n";
  if (top.contact.friction == FrictionLaw::Coulomb) t << "mu = " << tf(top.contact.mu) << "\n";
  if (top.contact.drilling > 0) t << "drilling = " << tf(top.contact.drilling) << "\n";
  t << "stem = " << (top.stem ? "true" : "false") << "\n";
  t << "flight = " << (flight ? "true" : "false") << "\n\n[initial]\n";
  const BodyState& x = top.start;
  t << "# The " << from << " of the model, as the state of G in the principal frame (e_Z from the ball to the stem).\n";
  t << "orientation = " << array({x.q_WB.w(), x.q_WB.x(), x.q_WB.y(), x.q_WB.z()}) << "\n";
  t << "position = " << array({x.p_WG.x(), x.p_WG.y()}) << "\n";
  t << "omega = " << array({x.w_B.x(), x.w_B.y(), x.w_B.z()}) << "\n";
  t << "velocity = " << array({x.v_WG.x(), x.v_WG.y()}) << "\n";
  if (flight) t << "height = " << tf(top.start_gap) << "\n";
  t << "\n[run]\nduration = " << tf(o.duration) << "\nsample_interval = " << tf(sample_interval) << "\n\n";
  t << "[engines.mujoco]\n";
  t << "model = " << ts(model_path) << "\n";
  t << "body = " << ts(top.body) << "\n";
  if (top.keyframe_index >= 0) t << "keyframe = " << ts(top.keyframe) << "\n";
  return t.str();
}

}  // namespace

MjcfScene import_mjcf_scene(const MjcfSceneRequest& o) {
  if (!is_valid_utf8(o.model) || !is_valid_utf8(o.out))
    throw InputError("import-mjcf: the paths must be valid UTF-8 (the scene and its records are text)");
  if (!(o.duration > 0 && std::isfinite(o.duration))) throw InputError("--duration: must be a positive number");
  if (!o.out.empty()) {
    if (const std::string why = result_file_problem(o.out); !why.empty()) throw InputError(o.out + ": " + why);
    // The scene written over the model would replace it (and name itself as its model).
    refuse_output_over_inputs(o.out, {o.model});
  }
  MjcfScene s;
  try {
    s.top = mujoco_api().import_top(o.model, o.body, o.keyframe);  // the MuJoCo module, loaded on first use
  } catch (const MjcfImportError& e) {
    throw InputError(e.what());
  }
  const MjcfTopImport& top = s.top;
  // The model as the scene names it: relative to the scene's directory (absolute without one).
  const fs::path model_abs = fs::absolute(o.model).lexically_normal();
  std::string model_path = model_abs.string();
  std::string name = fs::path(o.model).stem().string();
  if (!o.out.empty()) {
    const fs::path out_dir = fs::absolute(o.out).lexically_normal().parent_path();
    model_path = model_abs.lexically_relative(out_dir).string();
    if (model_path.empty()) model_path = model_abs.string();
    name = fs::path(o.out).stem().string();
  }
  if (!is_valid_name(name)) name = "imported";
  // Not finer than MuJoCo's step: samples between two steps would repeat a state.
  const double sample_interval = o.sample_interval > 0 ? o.sample_interval : std::max(1e-3, top.timestep);
  s.text = scene_text(top, o, model_path, name, sample_interval);
  // The scene must read back (every check of a scene file, and the MuJoCo run's check that it is
  // the model's top) before anything is written.
  const std::string label = o.out.empty() ? name + ".toml" : o.out;
  try {
    (void)parse_scene_text(s.text, label);
  } catch (const SceneError& e) {
    throw InputError(o.model + ": body '" + top.body + "': the imported scene is not one the bench can run (" + label +
                     " not written): " + e.what());
  }
  return s;
}

}  // namespace tippe
