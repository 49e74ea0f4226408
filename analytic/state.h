// The common body state and observables that every simulator reports, in named frames.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <limits>

namespace tippe {

using Vec3 = Eigen::Vector3d;
using Quat = Eigen::Quaterniond;

// W: lab (world) frame, z up, floor z = 0. B: body frame at G, e_Z along the symmetry axis
// pointing from the ball towards the stem.
struct BodyState {
  double t = 0.0;
  Vec3 p_WG = Vec3::Zero();  // position of G
  Vec3 v_WG = Vec3::Zero();  // velocity of G
  Quat q_WB = Quat::Identity();  // body -> lab
  Vec3 w_B = Vec3::Zero();   // angular velocity, body components
};

enum class Surface { None = 0, Ball = 1, Stem = 2, Both = 3 };
const char* to_string(Surface s);

struct Observation {
  BodyState state;
  double theta = 0.0;              // tilt: angle between e_Z and the lab vertical
  Surface surface = Surface::Ball; // the lower of ball and stem tip; Both while the simulator has both on the floor
  Vec3 p_WC = Vec3::Zero();        // geometric floor contact point (lowest point of the lower surface)
  bool engine_contact_valid = false;
  Vec3 p_WC_engine = Vec3::Zero(); // contact point as the engine reports it
  double normal_force = 0.0;       // F_n (sum over contacts)
  double slip_speed = 0.0;         // |v_C| horizontal, material point at the geometric contact
  double energy = 0.0;             // E = M v_G^2/2 + w.I w/2 + M g z_G
  double jellett = 0.0;            // J = L_G . R_C
  double contact_latitude = 0.0;   // angle on the ball from its south pole (-e_Z) to the contact
  // The run's energy ledger at this sample (Simulator::energy_ledger, filled by the harness's run
  // loop; NaN where the simulator cannot give a term): work of the normal force, of the friction
  // force and of the drilling torque on the top, energy removed at impacts, elastic energy in
  // the contact, and the numerical remainder E - E0 - work + impacts.
  double normal_work = std::numeric_limits<double>::quiet_NaN();
  double friction_work = std::numeric_limits<double>::quiet_NaN();
  double drilling_work = std::numeric_limits<double>::quiet_NaN();
  double impact_energy = std::numeric_limits<double>::quiet_NaN();
  double elastic_energy = std::numeric_limits<double>::quiet_NaN();
  double numerical_energy = std::numeric_limits<double>::quiet_NaN();
};

}  // namespace tippe
