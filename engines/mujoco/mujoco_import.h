// A user's MuJoCo model (MJCF) read as a tippe top: body, contact, gravity and start as MuJoCo compiled them.
#pragma once

#include <array>
#include <stdexcept>
#include <string>
#include <vector>

#include "analytic/scene.h"
#include "analytic/state.h"

namespace tippe {

// A model the reference cannot represent, or one MuJoCo cannot load: the message is
// "MODEL.xml: body 'top': reason" (or "MODEL.xml: reason" before a body is chosen).
class MjcfImportError : public std::invalid_argument {
 public:
  using std::invalid_argument::invalid_argument;
};

// What `tippe import-mjcf` takes from a compiled mjModel. Frames: W the world (the floor is the
// plane z = 0, +z up); B the principal frame at the centre of mass G with e_Z along the symmetry
// axis, from the ball towards the stem (the bench's body frame); F the model's own body frame.
struct MjcfTopImport {
  std::string file;             // the path as given
  std::string body;             // the top's body name
  std::string keyframe;         // the keyframe's name ("" when the start is qpos0 with zero velocity)
  int keyframe_index = -1;      // -1: qpos0, zero velocity
  std::string mujoco_version;   // of the library that compiled it
  double gravity = 0.0;         // -opt.gravity.z
  double timestep = 0.0;        // opt.timestep
  BodyGeometry geometry;        // R, r, l; h = R (MuJoCo's ball is a full sphere); mass_model Given
  bool stem = false;
  std::string stem_type;        // "capsule", "cylinder", "sphere" or ""
  MassProperties mass;          // M, d, A, C from body_mass, body_ipos, body_inertia, body_iquat
  std::array<double, 3> principal_moments{0, 0, 0};  // body_inertia as compiled
  ContactSpec contact;          // from the compiled ball-floor contact
  int condim = 0;               // of the ball-floor contact
  std::array<double, 5> contact_friction{0, 0, 0, 0, 0};  // mjContact.friction of the ball-floor contact
  double contact_margin = 0.0;  // mjContact.includemargin (margin - gap)
  std::array<double, 2> contact_solref{0, 0};              // mjContact.solref, as given (before refsafe)
  std::array<double, 5> contact_solimp{0, 0, 0, 0, 0};     // mjContact.solimp
  BodyState start;              // exact state of G at the start (t = 0)
  double start_gap = 0.0;       // lowest point of the body above the floor at the start (< 0: inside)
  double start_vz_centre = 0.0; // vertical velocity of the centre of the sphere that touches (O or P)
  Quat q_FB = Quat::Identity(); // principal frame B in the model's body frame F
  Vec3 p_FG_F = Vec3::Zero();   // G in F (body_ipos)
  std::vector<std::string> notes;  // what the reference approximates of this model
};

// Loads `path` with mj_loadXML and reads the top: the body with a free joint (or `body`), its
// colliding sphere (the ball) and optional capsule, cylinder or smaller sphere on the symmetry
// axis (the stem), the keyframe `keyframe` (default: the first; none: qpos0). Throws
// MjcfImportError for what cannot be loaded or represented.
MjcfTopImport import_mjcf_top(const std::string& path, const std::string& body = "",
                              const std::string& keyframe = "");

// Where a scene differs from the imported model (mass properties, geometry, gravity, contact law),
// one sentence each; empty when the scene is the model's. The start is not compared.
std::vector<std::string> mjcf_scene_mismatches(const MjcfTopImport& top, const Scene& scene);

}  // namespace tippe
