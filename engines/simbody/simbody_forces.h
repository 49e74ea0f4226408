// Simbody force elements the adapter adds: the bench's viscous law, and the contact forces' work integrated as state variables for the energy ledger.
#pragma once

#include <Simbody.h>

#include <functional>
#include <string>
#include <utility>
#include <vector>

namespace tippe {
namespace simbody_detail {

// The two contact spheres of the body, in the body frame at G: the ball about O = G + d e_Z and
// the stem tip about P = G + (d + l) e_Z (on a plane the tip sphere is the capsule O-P's contact:
// its O end lies inside the ball).
struct SphereSpec {
  SimTK::Vec3 centre_B;
  double radius = 0.0;
};

// The source's viscous law F_t = -k v_C at every sphere that penetrates the floor, each at its
// lowest point p with that material point's horizontal velocity v_C: f(i, p, v_C) for each
// (the body at X moving with V; one definition for the force, its report and its power).
template <class F>
void for_each_viscous(const SimTK::Transform& X, const SimTK::SpatialVec& V, const std::vector<SphereSpec>& spheres, F f) {
  for (size_t i = 0; i < spheres.size(); ++i) {
    const SimTK::Vec3 centre = X * spheres[i].centre_B;
    if (centre[2] - spheres[i].radius >= 0) continue;
    const SimTK::Vec3 p = centre - SimTK::Vec3(0, 0, spheres[i].radius);
    SimTK::Vec3 v_C = V[1] + V[0] % (p - X.p());
    v_C[2] = 0;
    f(i, p, v_C);
  }
}

// The viscous law as a force element in Simbody's right-hand side: evaluated at every stage of
// every step, so the integrator's accuracy covers it (the fixed-step engines can only hold it
// constant over a step).
class ViscousContactForce : public SimTK::Force::Custom::Implementation {
 public:
  ViscousContactForce(const SimTK::MobilizedBody& top, std::vector<SphereSpec> spheres, double k)
      : top_(top), spheres_(std::move(spheres)), k_(k) {}
  void calcForce(const SimTK::State& s, SimTK::Vector_<SimTK::SpatialVec>& body_forces, SimTK::Vector_<SimTK::Vec3>&,
                 SimTK::Vector&) const override {
    const SimTK::Transform& X = top_.getBodyTransform(s);
    for_each_viscous(X, top_.getBodyVelocity(s), spheres_, [&](size_t, const SimTK::Vec3& p, const SimTK::Vec3& v_C) {
      top_.applyForceToBodyPoint(s, ~X * p, -k_ * v_C, body_forces);
    });
  }
  SimTK::Real calcPotentialEnergy(const SimTK::State&) const override { return 0; }

 private:
  SimTK::MobilizedBody top_;
  std::vector<SphereSpec> spheres_;
  double k_;
};

// The power of the contact forces on the top at a state: the normal forces' and the tangential
// ones' (Simbody's friction and the bench's viscous law).
struct ContactPower {
  double normal = 0.0, friction = 0.0;
};

// The ledger's work as Simbody integrates it: two continuous state variables z (the normal and
// the tangential forces' work on the top) whose derivatives are the contact power at every stage
// of every step, so the integrator's own quadrature, of its own order, books the work of the
// forces it applied, and the ledger's remainder is Simbody's own energy error. The element
// applies no force, and its z's carry zero error weight: the explicit integrators' error norm
// (RK-Merson, RK3, RK2, Euler) is the largest of the q's, the u's and the z's norms, each over its
// own variables, so their steps and trajectory are bit-identical with and without it (measured:
// every state column of every sample, the step and right-hand-side counts, on leine_glocker and
// toy_viscous for 1 s with each). CPodes and Verlet do see the z's (CPodes' norm averages over all
// of y; Verlet's implicit iteration tests them): CPodes took 15690 steps on leine_glocker's first
// second instead of 15653 (final energy moved by 2.4e-7 E0), Verlet 8723 instead of 8651 (8.3e-4
// E0). With those the adapter leaves the element out and the ledger books the power at each
// step's end (StepChecks::set_smooth_forces), the trajectory untouched.
class LedgerWork : public SimTK::Force::Custom::Implementation {
 public:
  LedgerWork(SimTK::SubsystemIndex forces, std::function<ContactPower(const SimTK::State&)> power)
      : forces_(forces), power_(std::move(power)) {}
  void calcForce(const SimTK::State&, SimTK::Vector_<SimTK::SpatialVec>&, SimTK::Vector_<SimTK::Vec3>&,
                 SimTK::Vector&) const override {}
  SimTK::Real calcPotentialEnergy(const SimTK::State&) const override { return 0; }
  void realizeTopology(SimTK::State& s) const override { z_ = s.allocateZ(forces_, SimTK::Vector(2, 0.0)); }
  void realizeAcceleration(const SimTK::State& s) const override {
    const ContactPower p = power_(s);
    SimTK::Vector& zdot = s.updZDot(forces_);
    zdot[z_] = p.normal;
    zdot[z_ + 1] = p.friction;
  }
  SimTK::ZIndex z() const { return z_; }
  // Its z's out of the error norm: on a state realized to Model stage, before the integrator's
  // initialize (which copies the weights with the state).
  void zero_weights(SimTK::State& s) const {
    s.updZWeights(forces_)[z_] = 0.0;
    s.updZWeights(forces_)[z_ + 1] = 0.0;
  }

 private:
  SimTK::SubsystemIndex forces_;
  std::function<ContactPower(const SimTK::State&)> power_;
  mutable SimTK::ZIndex z_;
};

// Whether an integrator's step control leaves LedgerWork's zero-weight z's out (LedgerWork).
inline bool integrator_keeps_z_out_of_its_steps(const std::string& integrator) {
  return integrator != "cpodes" && integrator != "verlet";
}

}  // namespace simbody_detail
}  // namespace tippe
