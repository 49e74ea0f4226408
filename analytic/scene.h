// Plain description of one tippe-top scene: body, contact law, start and run settings (no file I/O).
#pragma once

#include <array>
#include <map>
#include <string>
#include <variant>
#include <vector>

namespace tippe {

enum class FrictionLaw { Rolling, Viscous, Coulomb, None, Gliding };
enum class MassModel { Seed, Solid, Given };
// How the drilling torque of a Coulomb contact relates to its tangential force: each bounded
// on its own (|F_t| <= mu F_n, |tau| <= mu_d F_n), or jointly by the ellipse of Leine and
// Glocker's approximation of the Coulomb-Contensou law (contact_dynamics.cpp).
enum class DrillingLaw { Decoupled, Coupled };

const char* to_string(FrictionLaw law);
const char* to_string(DrillingLaw law);
const char* to_string(MassModel model);

// Geometry of the sphere+stem body. l is measured from the ball centre O to the centre P of the
// stem's tip hemisphere; h is the height above O where the ball is cut.
struct BodyGeometry {
  double sphere_radius = 0.0;      // R
  double stem_radius = 0.0;        // r
  double stem_length = 0.0;        // l
  double truncation_height = 0.0;  // h
  double density = 0.0;
  MassModel mass_model = MassModel::Solid;
};

// Mass properties about the centre of mass G; G sits a distance com_offset (d) below the ball
// centre O along the symmetry axis, i.e. O = G + d e_Z.
struct MassProperties {
  double mass = 0.0;                // M
  double com_offset = 0.0;          // d
  double inertia_transverse = 0.0;  // A = B
  double inertia_axial = 0.0;       // C
};

struct ContactSpec {
  FrictionLaw friction = FrictionLaw::Coulomb;
  double mu = 0.0;        // Coulomb coefficient; gliding (Rutstam 2012): F_t = -mu F_n v_C, mu in s/m
  double k = 0.0;         // viscous coefficient, F_t = -k v_C
  double drilling = 0.0;  // torsional friction length mu_d: |tau| <= mu_d F_n
  // Coupled (Coulomb law only): (|F_t| / (mu F_n))^2 + (tau / (mu_d F_n))^2 <= 1.
  DrillingLaw drilling_law = DrillingLaw::Decoupled;
  bool stem = true;       // false: a bare eccentric ball
  bool flight = false;    // true: free flight after loss of contact instead of ending the run
};

struct InitialSpec {
  double tilt = 0.0;                       // rad, rotation of the body about the lab x axis
  // A general orientation instead of tilt (an imported keyframe): q_WB as w, x, y, z (unit).
  bool orientation_given = false;
  std::array<double, 4> orientation{1, 0, 0, 0};
  std::array<double, 2> position{0, 0};    // horizontal position of G (x, y)
  bool omega_given = false;                // omega_B given instead of spin
  double spin = 0.0;                       // rad/s about the symmetry axis e_Z
  std::array<double, 3> omega_B{0, 0, 0};  // body-frame angular velocity when omega_given
  bool velocity_given = false;
  std::array<double, 2> velocity{0, 0};    // horizontal velocity of G
  bool omega_along_contact = false;        // omega parallel to R_C so that v_C = v_G
  double height = 0.0;                     // lowest point of the ball above the floor (> 0: start in flight)
};

// The values RunSpec::energy_gain_rule may take, the default first (harness/measure/metrics.h's
// EnergyGainRule, in this order): "stored" (the rise of E plus the elastic energy the engine's
// contact law stores, where it gives one), "total" (the rise of E itself) and "ledger" (the energy
// the run's ledger says was created, not released from a contact's store).
inline const std::vector<std::string>& energy_gain_rule_names() {
  static const std::vector<std::string> names = {"stored", "total", "ledger"};
  return names;
}

struct RunSpec {
  double duration = 1.0;
  double sample_interval = 1e-3;
  double rtol = 1e-10;
  double atol = 1e-12;
  // Reference integrator: "bulirsch_stoer" (extrapolation, high order: the default), "dopri5"
  // (Dormand-Prince 5(4)) or "rosenbrock4" (linearly implicit, order 4, for stiff runs such as
  // the viscous law at large k); all with dense output for event location.
  std::string method = "bulirsch_stoer";
  // The harness runs a second, independent reference over the same scene and says from which
  // time on the two part (the reference's self-check, harness/measure/self_check.h); false skips it.
  bool self_check = true;
  // How the bench counts an energy rise in a dissipative scene (harness/measure/metrics.h,
  // docs/energy-ledger.md): one of energy_gain_rule_names(), by default the first, "stored"
  // (kDefaultEnergyGainRule). A choice of the bench, not physics: it moves no run, only the class
  // and the gain metrics, and is named beside them (energy_gain_rule in every comparison and
  // sweep record).
  std::string energy_gain_rule = energy_gain_rule_names().front();
  // Which of rtol, atol, method, self_check the scene file gave in [run], their older spelling
  // (they are the reference's settings, [engines.analytic]); the reference notes them.
  std::vector<std::string> alias_keys{};
};

// One value of an engine setting as written in a scene or on the command line.
using SettingValue = std::variant<bool, long long, double, std::string, std::vector<double>>;
// engine name -> key -> value, e.g. settings["mujoco"]["timestep"] = 1e-4.
using EngineSettingTable = std::map<std::string, std::map<std::string, SettingValue>>;

struct Scene {
  std::string name;
  std::string description;
  std::string source_file;   // where it was read from (for messages and provenance)
  std::string content_hash;  // hash of the file's bytes and overrides, for caches and provenance
  double gravity = 9.81;
  BodyGeometry body;
  MassProperties mass;  // always filled: computed from body, or given directly
  ContactSpec contact;
  InitialSpec initial;
  RunSpec run;
  EngineSettingTable engines;
  // What a scene's maker approximated (e.g. `tippe import-mjcf`: "stem cylinder approximated by
  // ..."): carried into every record and shown at the top of reports.
  std::vector<std::string> notes;
};

}  // namespace tippe
