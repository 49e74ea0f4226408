// A Siconos kernel relation: the gap and contact frame of a sphere fixed in a Newton-Euler body on the floor z = 0.
//
// Siconos' mechanics library has such relations (and collision detection), but it links Debian's
// single-precision Bullet, whose C++ symbols are those of the double-precision Bullet the Bullet
// adapter links: both in one binary is an ODR violation. The kernel's NewtonEuler3DR (Coulomb
// contact in a local frame: normal gap, two tangential directions) needs only the contact point on
// the body, the point on the floor and the normal, which for a sphere on a plane are closed-form:
// this relation computes them, the kernel derives the Jacobians from them.
#pragma once

#include <SiconosKernel.hpp>

#include <cmath>

namespace tippe {

class SphereOnFloorR : public NewtonEuler3DR {
 public:
  // centre_B: the sphere's centre in the body frame (origin at G); radius: the sphere's.
  SphereOnFloorR(double cx, double cy, double cz, double radius) : cx_(cx), cy_(cy), cz_(cz), radius_(radius) {}

  // q0: the body's coordinates (x, y, z of G; the unit quaternion w, x, y, z of B in W).
  void computeh(double, const BlockVector& q0, SiconosVector& y) override {
    const double px = q0.getValue(0), py = q0.getValue(1), pz = q0.getValue(2);
    const double w = q0.getValue(3), x = q0.getValue(4), yq = q0.getValue(5), z = q0.getValue(6);
    // The rotation of the body-frame offset into W (the unit quaternion's matrix).
    const double ox = (1 - 2 * (yq * yq + z * z)) * cx_ + 2 * (x * yq - w * z) * cy_ + 2 * (x * z + w * yq) * cz_;
    const double oy = 2 * (x * yq + w * z) * cx_ + (1 - 2 * (x * x + z * z)) * cy_ + 2 * (yq * z - w * x) * cz_;
    const double oz = 2 * (x * z - w * yq) * cx_ + 2 * (yq * z + w * x) * cy_ + (1 - 2 * (x * x + yq * yq)) * cz_;
    const double centre_z = pz + oz;
    y.setValue(0, centre_z - radius_);
    // The sphere's lowest point, on the body, and its projection on the floor: the normal is +z
    // (from the floor towards the body) wherever the sphere is.
    _Pc1->setValue(0, px + ox);
    _Pc1->setValue(1, py + oy);
    _Pc1->setValue(2, centre_z - radius_);
    _Pc2->setValue(0, px + ox);
    _Pc2->setValue(1, py + oy);
    _Pc2->setValue(2, 0.0);
    _Nc->setValue(0, 0.0);
    _Nc->setValue(1, 0.0);
    _Nc->setValue(2, 1.0);
  }

 // The lab-to-contact-frame rotation of the last Jacobian (rows: normal, two tangents).
  const SimpleMatrix& abs_to_contact() const { return *_rotationAbsoluteToContactFrame; }

 private:
  double cx_, cy_, cz_, radius_;
};

}  // namespace tippe
