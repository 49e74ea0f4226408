// The scene's initial state, shared by the reference and every engine so that all start alike.
#include "analytic/initial_state.h"

namespace tippe {

BodyState scene_initial_state(const Scene& scene) {
  const BodyModel m = BodyModel::from_scene(scene);
  BodyState x;
  x.t = 0.0;
  const InitialSpec& in = scene.initial;
  x.q_WB = in.orientation_given
               ? Quat(in.orientation[0], in.orientation[1], in.orientation[2], in.orientation[3]).normalized()
               : Quat(Eigen::AngleAxisd(in.tilt, Vec3::UnitX()));
  // The body rests on whichever surface is lower at this tilt: the ball, or beyond the
  // switching tilt the stem tip (a top that starts already inverted).
  const Surface low = lower_surface(m, x.q_WB);
  const Vec3 R_C_W = contact_offset_W(m, x.q_WB, low);
  const Vec3 R_C_B = x.q_WB.conjugate() * R_C_W;
  if (scene.initial.omega_along_contact) {
    // R_C points down the axis (R_C . e_Z = d - R cos(tilt) < 0 for a top with d < R), so
    // -spin R_C/|R_C| spins counter-clockwise about e_Z for positive spin.
    x.w_B = -scene.initial.spin * R_C_B.normalized();
  } else if (scene.initial.omega_given) {
    x.w_B = Vec3(scene.initial.omega_B[0], scene.initial.omega_B[1], scene.initial.omega_B[2]);
  } else {
    x.w_B = Vec3(0, 0, scene.initial.spin);
  }
  const Vec3 w_W = x.q_WB * x.w_B;
  x.p_WG = Vec3(in.position[0], in.position[1], -R_C_W.z());
  if (scene.contact.friction == FrictionLaw::Rolling) {
    x.v_WG = R_C_W.cross(w_W);
  } else {
    x.v_WG = Vec3(scene.initial.velocity[0], scene.initial.velocity[1], 0.0);
  }
  // The centre of the touching sphere (O for the ball, P for the stem tip) moves horizontally
  // while it touches the floor. A start above the floor (free flight) keeps v_Gz = 0 instead.
  const Vec3 e_Z = x.q_WB * Vec3::UnitZ();
  if (scene.initial.height > 0) {
    x.p_WG.z() += scene.initial.height;
    x.v_WG.z() = 0.0;
  } else {
    const double z_centre = low == Surface::Stem ? m.z_P() : m.z_O();
    x.v_WG.z() = -(w_W.cross(z_centre * e_Z)).z();
  }
  return x;
}

}  // namespace tippe
