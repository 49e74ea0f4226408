// Equations of motion of the top under a given contact mode: the contact forces solved as a
// linear system from the acceleration constraints, for every friction law and both surfaces.
#pragma once

#include <array>

#include "observables.h"
#include "scene.h"
#include "state.h"

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
  // sliding mode between "held" and "lifted", see reference_model.cpp).
  bool graze = false;
  Vec3 slip_dir_W = Vec3::UnitX();  // Coulomb sliding direction used while |v_C| is ~0
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
  // Velocity of the material point at the lowest point of a surface (lab frame).
  Vec3 contact_velocity(const BodyState& x, int slot) const;

  // With both_normal_only, the impulses act at both contacts along the normal only and may have
  // either sign: a projection of the velocity onto the two-contact constraint.
  // Inelastic impact: impulses at the contacts in `touching` (slot flags) that leave no
  // contact approaching the floor, with tangential impulses by the friction law. Returns the
  // post-impact state (positions unchanged) and fills `post_mode_hint` with the contacts whose
  // normal velocity is ~0 afterwards and that received an impulse.
  BodyState impact(const BodyState& x, std::array<bool, 2> touching, std::array<bool, 2>* kept,
                   std::array<double, 2>* normal_impulse, bool both_normal_only = false) const;

  const BodyModel& body() const { return m_; }
  const ContactSpec& contact() const { return c_; }

 private:
  BodyModel m_;
  ContactSpec c_;
};

}  // namespace tippe
