// The MuJoCo adapter's notes and settings list for a run of the bench's own MJCF: the options in force and what MuJoCo does to the scene's law.
#include "engines/mujoco/mujoco_notes.h"

#include <algorithm>
#include <sstream>
#include <string>
#include <vector>

#include "engines/core/settings.h"
#include "engines/mujoco/mujoco_mjcf.h"

namespace tippe::mujoco_detail {

SettingsList scene_model_settings(const MujocoSettings& s, const Scene& scene, int condim) {
  SettingsList list = list_settings(s);
  // The user-model keys are empty for the bench's own MJCF: left out, so that its records list
  // exactly the settings in force.
  list.erase(std::remove_if(list.begin(), list.end(),
                            [](const auto& kv) { return kv.first == "model" || kv.first == "body" || kv.first == "keyframe"; }),
             list.end());
  const Vec3 f = used_friction(s, scene);
  list.emplace_back("condim_used", std::to_string(condim));
  list.emplace_back("friction_used",
                    "[" + round_trip_text(f.x()) + ", " + round_trip_text(f.y()) + ", " + round_trip_text(f.z()) + "]");
  list.emplace_back("noslip_iterations_used", std::to_string(used_noslip_iterations(s, scene)));
  const std::vector<double> sr = used_solref(s);
  list.emplace_back("solref_used", "[" + round_trip_text(sr[0]) + ", " + round_trip_text(sr[1]) + "]");
  return list;
}

std::vector<std::string> scene_model_notes(const Scene& scene, const BodyModel& body, const MujocoSettings& s, int condim) {
  const ContactSpec& c = scene.contact;
  auto g = [](double v) {
    std::ostringstream os;
    os << v;
    return os.str();
  };
  std::vector<std::string> notes;
  if (c.friction == FrictionLaw::Coulomb && !(c.mu > 0) && s.condim == 0)
    notes.push_back("Coulomb friction with mu = 0 simulated as frictionless contact (condim 1)");
  if (condim >= 3 && (c.friction == FrictionLaw::Coulomb || c.friction == FrictionLaw::Rolling) &&
      s.cone == "pyramidal")
    notes.push_back("friction cone approximated by MuJoCo's pyramid (cone = pyramidal)");
  // The scene's drilling law against MuJoCo's cone: the elliptic cone with condim >= 4 is the
  // coupled law's ellipse itself (MuJoCo: f_n^2 >= sum f_i^2 / mu_i^2), so a coupled scene runs
  // natively and a decoupled one does not; the pyramid bounds them jointly too, by a polytope.
  const bool coupled = c.drilling_law == DrillingLaw::Coupled;
  if (condim >= 4 && c.drilling > 0 && s.cone == "elliptic" && !coupled)
    notes.push_back("drilling friction (condim " + std::to_string(condim) +
                    "): MuJoCo bounds the tangential force and the drilling torque jointly, (|F_t|/mu)^2 + (tau/mu_d)^2 <= F_n^2 (elliptic), not each alone");
  if (condim >= 4 && c.drilling > 0 && s.cone == "elliptic" && coupled)
    notes.push_back("drilling coupled natively (condim " + std::to_string(condim) +
                    ", elliptic cone): MuJoCo's cone (|F_t|/mu)^2 + (tau/mu_d)^2 <= F_n^2 is the scene's Leine-Glocker ellipse");
  if (condim >= 4 && c.drilling > 0 && s.cone == "pyramidal")
    notes.push_back(std::string("drilling ") + (coupled ? "coupled by a polytope, not the scene's ellipse" : "coupled, not each bounded alone") +
                    " (condim " + std::to_string(condim) +
                    ", cone = pyramidal): MuJoCo's pyramid bounds the tangential force and the drilling torque jointly by its edges n +- mu_i d_i");
  if (coupled && c.drilling > 0 && condim < 4)
    notes.push_back("drilling dropped (condim " + std::to_string(condim) + " has no torsional row): not the scene's coupled law");
  // MuJoCo raises every friction coefficient the contact uses to mjMINMU.
  const Vec3 f = used_friction(s, scene);
  const bool zero_used = (condim >= 3 && !(f.x() > 0)) || (condim >= 4 && !(f.y() > 0)) || condim == 6;
  if (zero_used)
    notes.push_back("a friction coefficient of 0 with condim " + std::to_string(condim) +
                    " acts as MuJoCo's minimum mjMINMU = 1e-5, not as frictionless");
  if (s.condim != 0 && s.condim != derived_condim(scene))
    notes.push_back("condim forced to " + std::to_string(s.condim) + " (the scene's law needs " +
                    std::to_string(derived_condim(scene)) + "): not the scene's contact law");
  if (used_solref(s)[0] != s.solref[0])
    notes.push_back("solref timeconst " + g(s.solref[0]) + " raised by MuJoCo to 2 timestep = " +
                    g(used_solref(s)[0]) + " (its refsafe rule)");
  notes.push_back(std::string("body frame at ") +
                  (s.body_frame == "com" ? "the centre of mass G" : "the ball's centre O") +
                  " (engines.mujoco.body_frame): MuJoCo's results depend on it");
  if (s.solref[0] > 0) {
    // Resting on the ball: d k r = (1 - d) g with k = d / (dmax^2 tc^2 zeta^2) and d ~ dmin
    // for r << width (MuJoCo's soft-constraint model).
    const double dmin = s.solimp[0], dmax = s.solimp[1];
    const double tc = used_solref(s)[0], zeta = s.solref[1];
    const double depth = (1 - dmin) / (dmin * dmin) * scene.gravity * dmax * dmax * tc * tc * zeta * zeta;
    notes.push_back("soft contact (solref, solimp): resting penetration about " + g(depth) + " = " +
                    g(depth / body.R) + " R" + (condim >= 3 ? "; sticking friction creeps" : ""));
  } else {
    notes.push_back("soft contact given as stiffness and damping (negative solref)");
  }
  // Documented for MuJoCo's convex model ("the only way to initiate slip is to generate some
  // motion in the normal direction") and seen here as contact on/off chatter while sliding.
  if (condim >= 3 && (c.friction == FrictionLaw::Coulomb || c.friction == FrictionLaw::Rolling))
    notes.push_back("while slipping, MuJoCo's convex contact pushes the ball off the floor: the contact hops (intermittent normal force, many switch events)");
  if (s.integrator != "RK4")
    notes.push_back("integrator " + s.integrator + ": first order in the timestep");
  return notes;
}

}  // namespace tippe::mujoco_detail
