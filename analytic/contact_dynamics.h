// Equations of motion of the top under a given contact mode: the contact forces solved as a
// linear system from the acceleration constraints, for every friction law and both surfaces.
#pragma once

#include <array>

#include "analytic/observables.h"
#include "analytic/scene.h"
#include "analytic/state.h"

namespace tippe {

// Integration state: p_WG (3), v_WG (3), q_WB as w,x,y,z (4), w_B (3).
using StateVector = std::array<double, 13>;

StateVector pack(const BodyState& x);
BodyState unpack(const StateVector& y, double t);

// What one contact (ball = 0, stem = 1) does in the current mode.
struct ContactSlot {
  bool active = false;  // held on the floor (normal constraint in force)
  bool stick = false;   // tangential velocity held at zero (rolling law, or Coulomb sticking)
  bool drill_stick = false;  // spin about the vertical held at zero (drilling friction sticking)
  // Viscous law only: the contact touches with zero normal force and carries the fraction
  // `graze_fraction` in [0, 1] of its viscous force that keeps it on the floor (Filippov's
  // sliding mode between "held" and "lifted", see reference_events.cpp). The motion is the
  // convex combination (1 - f) "lifted" + f "loaded": lifted has no force at the contact,
  // loaded its full viscous force and no normal force, the other contacts held in both; f
  // makes the contact's gap acceleration zero. Both fields are solved on their own, so the
  // fraction is defined (and clamped to [0, 1]) where its own linear system would be singular
  // (the slip passing through 0, where both fields meet).
  bool graze = false;
  Vec3 slip_dir_W = Vec3::UnitX();  // Coulomb sliding direction used while |v_C| is ~0
  // Decoupled drilling law only: the sign of the spin about the vertical that the sliding
  // drilling torque opposes (+1 or -1; 0: the sign of the spin itself). Kept through a zero of
  // the spin within a step, as slip_dir_W is, so that the integrator never steps over the jump
  // of sign(w_z): on Bulirsch-Stoer that jump inside a step made the step's dense output miss
  // its own starting state by 3.5e-2 rad/s in w_z, and the spin restarted there (leine_glocker_drilling
  // at mu = 0.002: E rose by 3.5e-8 E0 at the drill_stick event).
  double drill_dir = 0.0;
  // Coupled drilling law only: the sliding direction in the generalised slip space
  // (mu v_x, mu v_y, mu_d w_z) (lab axes), a unit vector, used while that slip is ~0 (as
  // slip_dir_W). `stick` and `drill_stick` are then set together: the law sticks only as a whole.
  Vec3 coupled_dir = Vec3::UnitX();
  // Coupled law: below this generalised slip |(mu v, mu_d w_z)| the direction is coupled_dir
  // (a slip zeroed at a restart is round-off, whose direction means nothing).
  double coupled_floor = 0.0;
  // Coulomb law (either drilling law), sliding: the slip is small (it has just started from
  // zero, or fallen below half of the reference's threshold). Its direction is then not the
  // slip's own but the one along which the slip grows or shrinks: the unit n (slip_dir_W, or
  // coupled_dir under the coupled law) with d(slip)/dt = lambda n, solved at every evaluation
  // (the slow manifold of the direction, whose own relaxation rate mu F_n |W| / |slip| has no
  // bound as the slip starts or ends; integrated as it is, that stiff phase stalled every
  // method). slip_dir_W or coupled_dir is the starting guess of the solve.
  bool slip_start = false;
};

struct ContactMode {
  std::array<ContactSlot, 2> slot;  // [0] ball, [1] stem
  bool any_active() const { return slot[0].active || slot[1].active; }
};

// Forces found for one state and mode.
struct ContactForces {
  std::array<double, 2> normal{0, 0};           // F_n per slot
  std::array<Vec3, 2> force_W{Vec3::Zero(), Vec3::Zero()};  // total force at each contact
  std::array<double, 2> drill_torque{0, 0};     // torque about +e_z at each contact
  std::array<double, 2> graze_fraction{1, 1};   // share of the viscous force of a grazing contact
  std::array<Vec3, 2> slip_W{Vec3::Zero(), Vec3::Zero()};   // horizontal velocity of the material point at C
  // Grazing contacts only: the gap acceleration (of the contact sphere's centre) under the
  // lifted and the loaded field, and the fraction a0 / (a0 - a1) before clamping. The graze
  // is consistent while a0 <= 0 <= a1.
  std::array<double, 2> graze_lifted_accel{0, 0};
  std::array<double, 2> graze_loaded_accel{0, 0};
  std::array<double, 2> graze_fraction_raw{1, 1};
  // Slip-start contacts only (ContactSlot::slip_start): the direction n solved (lab x, y and,
  // under the coupled law, the drilling component) and the slip's growth rate lambda along it
  // (generalised slip units per second: m/s^2 for the decoupled law, those of coupled_slip()
  // per second for the coupled one).
  std::array<Vec3, 2> start_dir{Vec3::UnitX(), Vec3::UnitX()};
  std::array<double, 2> start_rate{0, 0};
  bool solvable = true;
};

struct ContactGeometry {
  Vec3 r_GO_W;  // G -> sphere centre (O or P)
  Vec3 r_GC_W;  // G -> lowest point of that sphere (R_C)
  double radius;
};

class ContactDynamics {
 public:
  ContactDynamics(const BodyModel& body, const ContactSpec& contact) : m_(body), c_(contact) {}

  ContactGeometry geometry(const BodyState& x, int slot) const;
  // Derivative of the state and the contact forces for a mode. dydt may be null.
  ContactForces evaluate(const StateVector& y, const ContactMode& mode, StateVector* dydt) const;
  // evaluate() by the general solve whatever the mode. evaluate() takes a closed form for one
  // sliding contact under the viscous law (a viscous run's common mode), which must give bit
  // for bit what this gives (tests/analytic/test_contact_dynamics.cpp).
  ContactForces evaluate_general(const StateVector& y, const ContactMode& mode, StateVector* dydt) const;
  // Velocity of the material point at the lowest point of a surface (lab frame).
  Vec3 contact_velocity(const BodyState& x, int slot) const;

  // What the impulses of impact() may do.
  enum class Impulses {
    // A touchdown: inelastic impact of the contacts in `touching`, tangential impulses by the
    // friction law, normal impulses >= 0 (the first of {ball}, {stem}, {both} that leaves no
    // touching contact approaching the floor).
    Impact,
    // Unilateral projection onto the contacts in `touching`: normal impulses >= 0 only, that
    // remove every approaching normal velocity and leave separating ones alone (the
    // complementarity solution; no impulse at all when nothing approaches).
    Unilateral,
    // Bilateral projection onto the contacts in `touching`: normal impulses of either sign that
    // zero their normal velocities with the smallest change of kinetic energy. Only for closing a Zeno
    // cascade of impacts (see reference_events.cpp): there the pulling part stands for the
    // finite forces acting over the skipped bounces, not for a contact force.
    Bilateral,
  };
  // Post-impact state (positions unchanged). `kept` (may be null): the contacts whose normal
  // velocity is ~0 afterwards; `normal_impulse`: the normal impulse per slot.
  BodyState impact(const BodyState& x, std::array<bool, 2> touching, std::array<bool, 2>* kept,
                   std::array<double, 2>* normal_impulse, Impulses kind = Impulses::Impact) const;

  // The state with the material point at the contact of `slot` at rest (and, with `spin`, the
  // spin about the vertical stopped too), by the impulse (and angular impulse about the
  // vertical) at the contact that does it with the smallest change of kinetic energy: a
  // projection in the mass metric, so it can only remove energy (positions unchanged).
  BodyState stop_contact(const BodyState& x, int slot, bool spin) const;

  // For a Jacobian by differences: per state component j, the change of y_j over which the
  // friction direction of a sliding Coulomb contact of `mode` turns by O(1) (+inf for a
  // component no such direction depends on). A contact sliding along its own slip s / |s|
  // (u / |u| under the coupled law) has a direction that varies on the scale of the slip
  // itself, so the scale is |s| / |ds/dy_j|, the smallest over such contacts. A starting
  // slip's solved direction (slip_start), a stuck contact and a direction held below
  // coupled_floor do not depend on |s|.
  void slip_scale(const StateVector& y, const ContactMode& mode, StateVector& scale) const;

  // Acceleration of the centre of the contact sphere of `slot` along z, from a state derivative.
  double gap_acceleration(const StateVector& y, const StateVector& dydt, int slot) const;

  const BodyModel& body() const { return m_; }
  const ContactSpec& contact() const { return c_; }

  // The coupled Coulomb-Contensou law is in force (Coulomb friction, drilling_law = coupled).
  bool coupled() const {
    return c_.friction == FrictionLaw::Coulomb && c_.drilling_law == DrillingLaw::Coupled;
  }
  // Coupled law: the generalised slip (mu v_x, mu v_y, mu_d w_z) of slot s (lab axes; v the
  // horizontal velocity of the material point at C, w_z the spin about the vertical); its norm
  // over F_n's coefficient is the dissipation rate per unit normal force.
  Vec3 coupled_slip(const BodyState& x, int slot) const;
  // Coupled law: the normal force the friction of slot s needs to lie on the ellipse,
  // sqrt((|F_t| / mu)^2 + (tau / mu_d)^2): the contact sticks while it is <= F_n.
  double coupled_demand(const ContactForces& f, int slot) const;

 private:
  // evaluate() with the slip-start contacts' directions solved (ContactSlot::slip_start).
  ContactForces evaluate_slip_start(const StateVector& y, const ContactMode& mode, StateVector* dydt) const;
  // Rate of the generalised slip of slot s (lab x, y of the contact point's velocity, times mu
  // under the coupled law, and mu_d dw_z/dt there) from a state derivative.
  Vec3 slip_rate(const StateVector& y, const StateVector& dy, int s) const;
  // evaluate() with every grazing contact carrying the fixed share `share` of its viscous force.
  ContactForces evaluate_fixed(const StateVector& y, const ContactMode& mode, StateVector* dydt, double share) const;
  // evaluate() for one active contact `s` under the viscous law, neither sticking nor grazing.
  ContactForces evaluate_viscous_one(const StateVector& y, int s, const ContactSlot& slot, StateVector* dydt) const;
  BodyModel m_;
  ContactSpec c_;
};

}  // namespace tippe
