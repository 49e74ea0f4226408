// Mass properties of the sphere+stem body (seed and exact-solid conventions) and geometry checks.
#include "analytic/mass_properties.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <stdexcept>

namespace tippe {
namespace {

constexpr double kPi = 3.14159265358979323846;

// Shortest decimal that reads back as the same double, so messages neither lose digits nor
// show binary noise such as 0.014999999999999999.
std::string num(double x) {
  char buf[40];
  for (int precision = 6; precision <= 17; ++precision) {
    std::snprintf(buf, sizeof buf, "%.*g", precision, x);
    if (std::strtod(buf, nullptr) == x) break;
  }
  return buf;
}

// Mass, first moment about O along e_Z, transverse moment about O and axial moment.
struct Moments {
  double mass = 0, first = 0, transverse_O = 0, axial = 0;
};

// Moments about G from moments about O, with O = G + d e_Z.
MassProperties about_centre(const Moments& m) {
  MassProperties p;
  p.mass = m.mass;
  const double zg = m.first / m.mass;
  p.com_offset = -zg;
  p.inertia_transverse = m.transverse_O - m.mass * zg * zg;
  p.inertia_axial = m.axial;
  return p;
}

// ---- seed convention: the source's closed forms, verbatim ----

struct Part {
  double mass, z, transverse_own, axial;  // transverse_own: about the part's own centre
};

Part seed_cylinder(double r, double l, double rho) {
  const double Ma = kPi * r * r * l * rho;
  return {Ma, 0.5 * l, Ma * r * r / 4 + Ma * l * l / 12, Ma * r * r / 2};
}

// The source's truncated-ball integrals; transverse_O is about O (as the source has it).
struct SeedBall {
  double mass, z, transverse_O, axial;
};

SeedBall seed_ball(double R, double h, double rho) {
  const double e = h / R, e2 = e * e, e3 = e2 * e, e4 = e2 * e2, e5 = e4 * e;
  const double k3 = kPi * R * R * R * rho, k5 = k3 * R * R;
  SeedBall b;
  b.mass = k3 * (e - e3 / 3 + 2.0 / 3);
  b.z = 0.25 * k3 / b.mass * R * (2 * e2 - e4 - 1);
  b.transverse_O = 0.25 * k5 * (e + 2.0 / 3 * e3 - 3.0 / 5 * e5 + 16.0 / 15);
  b.axial = 0.5 * k5 * (e - 2.0 / 3 * e3 + e5 / 5 + 8.0 / 15);
  return b;
}

MassProperties seed_mass_properties(const BodyGeometry& g) {
  const Part a = seed_cylinder(g.stem_radius, g.stem_length, g.density);
  const SeedBall s = seed_ball(g.sphere_radius, g.truncation_height, g.density);
  const double M = a.mass + s.mass;
  const double zg = (a.mass * a.z + s.mass * s.z) / M;
  MassProperties p;
  p.mass = M;
  p.com_offset = -zg;
  // The source's second line: I_X^s about O shifted to G is I_X^s + M_s Z_G (Z_G - 2 Z_s).
  p.inertia_transverse = a.transverse_own + a.mass * (a.z - zg) * (a.z - zg) + s.transverse_O +
                         s.mass * zg * (zg - 2 * s.z);
  p.inertia_axial = a.axial + s.axial;
  return p;
}

// ---- solid convention: union of solids of revolution about e_Z ----

// Squared radius q(Z) = c0 + c1 Z + c2 Z^2 of one component on [lo, hi].
struct Profile {
  double c0, c1, c2, lo, hi;
  double at(double z) const { return c0 + z * (c1 + z * c2); }
};

using Poly = std::array<double, 5>;  // coefficients of u^0..u^4

Poly mul(const Poly& a, const Poly& b) {
  Poly c{};
  for (int i = 0; i < 5; ++i)
    for (int j = 0; i + j < 5; ++j) c[i + j] += a[i] * b[j];
  return c;
}

// Integral over u in [-w, w]: odd powers cancel, which keeps each slice free of the
// cancellation that a Z-antiderivative F(b) - F(a) far from the origin would suffer.
double integrate_symmetric(const Poly& p, double w) {
  double s = 0, wk = w;  // w^(k+1)
  for (int k = 0; k < 5; ++k, wk *= w)
    if (k % 2 == 0) s += 2 * p[k] * wk / (k + 1);
  return s;
}

// Exact moments of the slab z0 <= Z <= z1 whose squared radius is the quadratic q.
Moments slab(const Profile& q, double z0, double z1, double rho) {
  const double m = 0.5 * (z0 + z1), w = 0.5 * (z1 - z0);
  const Poly qu{q.at(m), q.c1 + 2 * q.c2 * m, q.c2, 0, 0};  // q(m + u)
  const Poly z{m, 1, 0, 0, 0};                               // Z = m + u
  const Poly q2 = mul(qu, qu), qz = mul(qu, z), qz2 = mul(qz, z);
  Moments out;
  out.mass = rho * kPi * integrate_symmetric(qu, w);
  out.first = rho * kPi * integrate_symmetric(qz, w);
  // A disc of radius rho_: (pi rho_^4 / 4) about a diameter plus its area times Z^2.
  out.transverse_O = rho * kPi * (0.25 * integrate_symmetric(q2, w) + integrate_symmetric(qz2, w));
  out.axial = rho * kPi * 0.5 * integrate_symmetric(q2, w);
  return out;
}

Moments solid_moments(double R, double r, double l, double h, double rho) {
  std::vector<Profile> parts;
  parts.push_back({R * R, 0, -1, -R, h});                         // ball, cut at h
  if (r > 0 && l > 0) parts.push_back({r * r, 0, 0, 0, l});       // stem cylinder
  if (r > 0) parts.push_back({r * r - l * l, 2 * l, -1, l, l + r});  // tip hemisphere

  // Between consecutive breakpoints the set of present parts is fixed and no two of their
  // profiles cross, so one part is the outermost throughout: ends of every part, the
  // ball/cylinder crossing at sqrt(R^2 - r^2) and the ball/tip crossing where the (linear)
  // difference R^2 - r^2 + l^2 - 2 l Z vanishes. Cylinder and tip only touch at Z = l.
  std::vector<double> cuts;
  for (const Profile& p : parts) {
    cuts.push_back(p.lo);
    cuts.push_back(p.hi);
  }
  if (r < R) cuts.push_back(std::sqrt(R * R - r * r));
  if (l > 0) cuts.push_back((R * R - r * r + l * l) / (2 * l));
  const double zmin = -R, zmax = std::max(h, r > 0 ? l + r : h);
  cuts.erase(std::remove_if(cuts.begin(), cuts.end(), [&](double z) { return !(z >= zmin && z <= zmax); }),
             cuts.end());
  std::sort(cuts.begin(), cuts.end());
  cuts.erase(std::unique(cuts.begin(), cuts.end()), cuts.end());

  Moments total;
  for (size_t i = 0; i + 1 < cuts.size(); ++i) {
    const double z0 = cuts[i], z1 = cuts[i + 1], mid = 0.5 * (z0 + z1);
    const Profile* best = nullptr;
    for (const Profile& p : parts)
      if (mid > p.lo && mid < p.hi && (!best || p.at(mid) > best->at(mid))) best = &p;
    if (!best) continue;  // a gap (only when h < 0 and the stem starts at O above the cut)
    const Moments s = slab(*best, z0, z1, rho);
    total.mass += s.mass;
    total.first += s.first;
    total.transverse_O += s.transverse_O;
    total.axial += s.axial;
  }
  return total;
}

void require(bool ok, const std::string& what) {
  if (!ok) throw std::invalid_argument(what);
}

void check_for_mass(const BodyGeometry& g) {
  const double R = g.sphere_radius, h = g.truncation_height;
  require(std::isfinite(R) && R > 0, "sphere_radius: R = " + num(R) + " must be positive and finite");
  require(std::isfinite(g.density) && g.density > 0,
          "density: " + num(g.density) + " must be positive and finite");
  require(std::isfinite(h) && h > -R && h <= R,
          "truncation_height: h = " + num(h) + " must lie in (-R, R] = (" + num(-R) + ", " + num(R) + "]");
  // Zero means "no stem" (a bare ball scene that gives no stem size).
  require(std::isfinite(g.stem_radius) && g.stem_radius >= 0,
          "stem_radius: r = " + num(g.stem_radius) + " must be >= 0 and finite");
  require(std::isfinite(g.stem_length) && g.stem_length >= 0,
          "stem_length: l = " + num(g.stem_length) + " must be >= 0 and finite");
}

}  // namespace

MassProperties truncated_ball_mass_properties(double R, double h, double density) {
  BodyGeometry g;
  g.sphere_radius = R;
  g.truncation_height = h;
  g.density = density;
  check_for_mass(g);
  return about_centre(solid_moments(R, 0, 0, h, density));
}

MassProperties compute_mass_properties(const BodyGeometry& body) {
  if (body.mass_model == MassModel::Given)
    throw std::invalid_argument("mass_model: \"given\" mass properties are not computed from the geometry");
  check_for_mass(body);
  if (body.mass_model == MassModel::Seed) return seed_mass_properties(body);
  return about_centre(solid_moments(body.sphere_radius, body.stem_radius, body.stem_length,
                                    body.truncation_height, body.density));
}

std::vector<std::string> geometry_problems(const BodyGeometry& body, bool stem) {
  std::vector<std::string> out;
  const double R = body.sphere_radius, r = body.stem_radius, l = body.stem_length, h = body.truncation_height;
  const bool R_ok = std::isfinite(R) && R > 0;
  if (!R_ok) out.push_back("sphere_radius: R = " + num(R) + " must be positive and finite");
  if (!std::isfinite(body.density) || body.density < 0)
    out.push_back("density: " + num(body.density) + " must be positive and finite");
  if (!R_ok) return out;  // every other test is relative to R
  const bool h_ok = std::isfinite(h) && h > -R && h <= R;
  if (!h_ok)
    out.push_back("truncation_height: h = " + num(h) + " must lie in (-R, R] = (" + num(-R) + ", " + num(R) + "]");
  if (!stem) {
    if (!(std::isfinite(r) && r >= 0)) out.push_back("stem_radius: r = " + num(r) + " must be >= 0 and finite");
    if (!(std::isfinite(l) && l >= 0)) out.push_back("stem_length: l = " + num(l) + " must be >= 0 and finite");
    return out;
  }
  if (!(std::isfinite(r) && r > 0)) {
    out.push_back("stem_radius: r = " + num(r) + " must be positive and finite");
    return out;
  }
  if (r >= R) {
    out.push_back("stem_radius: r = " + num(r) + " must be smaller than sphere_radius R = " + num(R));
    return out;
  }
  if (!(std::isfinite(l) && l > 0)) {
    out.push_back("stem_length: l = " + num(l) + " must be positive and finite");
    return out;
  }
  // l + r > R and (R - r)/l < 1 are the same condition (for l > 0): a tip inside the ball is a
  // stem that can never reach the floor. Both are tested so rounding at equality cannot split them.
  const double slope = (R - r) / l;
  if (l + r <= R || slope >= 1) {
    out.push_back("stem_length: (R - r)/l = " + num(slope) +
                  " must be < 1 for the stem to reach the floor (the tip top l + r = " + num(l + r) +
                  " must stick out of the ball, beyond R = " + num(R) + ")");
    return out;
  }
  // At the switch e_z . e_Z = -(R - r)/l the ball touches the floor at Z' = R (R - r)/l above O.
  if (h_ok && h < R * slope)
    out.push_back("truncation_height: h = " + num(h) + " must be >= R (R - r)/l = " + num(R * slope) +
                  " so that the ball contact stays on the solid part up to the switch to the stem");
  return out;
}

bool inversion_possible(const MassProperties& m, double R) {
  const double alpha = m.com_offset / R, ratio = m.inertia_transverse / m.inertia_axial;
  return 1 - alpha < ratio && ratio < 1 + alpha;
}

MassProperties mujoco_tutorial_mass_properties() {
  // Geoms as in the tutorial XML: sphere size .02; cylinder pos 0 0 .02, size .004 .008;
  // box pos 0 0 -.015, size (half-lengths) .023 .023 .005; MuJoCo's default density 1000.
  const double rho = 1000, R = 0.02, rc = 0.004, hc = 0.008, zc = 0.02, bx = 0.023, bz = 0.005, zb = -0.015;
  const double Mb = 4.0 / 3 * kPi * R * R * R * rho;
  const double Mc = kPi * rc * rc * 2 * hc * rho;
  const double Mx = (2 * bx) * (2 * bx) * (2 * bz) * rho;
  Moments m;
  m.mass = Mb + Mc + Mx;
  m.first = Mc * zc + Mx * zb;
  m.transverse_O = 0.4 * Mb * R * R + Mc * (3 * rc * rc + 4 * hc * hc) / 12 + Mc * zc * zc +
                   Mx * (4 * bx * bx + 4 * bz * bz) / 12 + Mx * zb * zb;
  m.axial = 0.4 * Mb * R * R + 0.5 * Mc * rc * rc + Mx * (8 * bx * bx) / 12;
  return about_centre(m);
}

}  // namespace tippe
