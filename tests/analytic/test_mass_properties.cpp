// Tests of the mass-properties module: seed and solid conventions, geometry checks, MuJoCo's tutorial top.
#include <gtest/gtest.h>
#include <mujoco/mujoco.h>

#include <algorithm>
#include <array>
#include <boost/math/quadrature/tanh_sinh.hpp>
#include <boost/math/tools/roots.hpp>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <limits>
#include <sstream>
#include <string>
#include <vector>

#include <unistd.h>

#include "analytic/mass_properties.h"

namespace tippe::test_mass_properties {
namespace {

constexpr double kPi = 3.14159265358979323846;

BodyGeometry body(double R, double r, double l, double h, double rho, MassModel model) {
  BodyGeometry b;
  b.sphere_radius = R;
  b.stem_radius = r;
  b.stem_length = l;
  b.truncation_height = h;
  b.density = rho;
  b.mass_model = model;
  return b;
}

BodyGeometry toy(MassModel model) { return body(0.015, 0.002, 0.037, 0.0054, 1000.0, model); }

// Geometries covering every arrangement of the solid's breakpoints.
std::vector<BodyGeometry> geometries(MassModel model) {
  return {
      toy(model),
      body(1.0, 0.25, 1.2, 0.9, 1.0, model),   // source_dimensionless: h < sqrt(R^2 - r^2) < l
      body(1.0, 0.5, 1.2, 0.95, 2.5, model),   // cylinder leaves the ball below the cut
      body(1.0, 0.25, 0.8, 0.95, 1.0, model),  // cut above P: the tip starts inside the ball
      body(1.0, 0.4, 0.7, 1.0, 1.0, model),    // full ball; ball and tip profiles cross inside the tip
      body(1.0, 0.4, 0.7, 0.93, 1.0, model),   // the same, cut before the crossing
      body(1.0, 0.5, 0.9, 1.0, 1.0, model),    // cylinder pokes out of the full ball below P
  };
}

// Relative difference, for quantities that are never near zero.
double rel(double a, double b) { return std::abs(a - b) / std::abs(b); }

// ---- the source's printed closed forms, transcribed from tippe_top_equations_ja.md ----

struct Printed {
  double Ms, Zs, IXs_O, IZs;  // truncated ball; IXs_O about the ball centre O
  double Ma, Za, IXa, IZa;    // cylinder; IXa about its own centre
};

Printed printed(const BodyGeometry& b) {
  const double R = b.sphere_radius, r = b.stem_radius, l = b.stem_length, rho = b.density;
  const double x = b.truncation_height / R;
  Printed p;
  p.Ms = kPi * std::pow(R, 3) * rho * (x - std::pow(x, 3) / 3 + 2.0 / 3);
  p.Zs = 0.25 * kPi * std::pow(R, 3) * rho / p.Ms * R * (2 * x * x - std::pow(x, 4) - 1);
  p.IXs_O = 0.25 * kPi * std::pow(R, 5) * rho * (x + 2.0 / 3 * std::pow(x, 3) - 3.0 / 5 * std::pow(x, 5) + 16.0 / 15);
  p.IZs = 0.5 * kPi * std::pow(R, 5) * rho * (x - 2.0 / 3 * std::pow(x, 3) + 1.0 / 5 * std::pow(x, 5) + 8.0 / 15);
  p.Ma = kPi * r * r * l * rho;
  p.Za = 0.5 * l;
  p.IXa = 0.25 * p.Ma * r * r + p.Ma * l * l / 12;
  p.IZa = 0.5 * p.Ma * r * r;
  return p;
}

// The source's "コマ全体" block, first line of I_X: each part about its own centre plus M (Z - Z_G)^2
// (the implementation uses the second line, so the two algebraic routes are compared).
MassProperties printed_seed(const BodyGeometry& b) {
  const Printed p = printed(b);
  const double M = p.Ma + p.Ms, ZG = (p.Ma * p.Za + p.Ms * p.Zs) / M;
  const double IXs_own = p.IXs_O - p.Ms * p.Zs * p.Zs;
  return {M, -ZG, p.IXa + p.Ma * (p.Za - ZG) * (p.Za - ZG) + IXs_own + p.Ms * (p.Zs - ZG) * (p.Zs - ZG),
          p.IZa + p.IZs};
}

// ---- independent quadrature: cylindrical shells at distance s from the axis ----
// The implementation slices along Z; here each shell's extent in Z is the union (solid) or the
// plain sum (seed) of the parts' Z-intervals at that s, and s is integrated with tanh-sinh, which
// copes with the square-root ends of each piece (s -> r, s -> R).

struct Interval {
  double lo, hi;
};

std::vector<Interval> parts_at(const BodyGeometry& b, double s, bool with_tip) {
  const double R = b.sphere_radius, r = b.stem_radius, l = b.stem_length, h = b.truncation_height;
  std::vector<Interval> v;
  if (s < R) {
    const double a = std::sqrt(std::max(0.0, R * R - s * s));
    if (std::min(h, a) > -a) v.push_back({-a, std::min(h, a)});
  }
  if (s < r) {
    v.push_back({0, l});
    if (with_tip) v.push_back({l, l + std::sqrt(std::max(0.0, r * r - s * s))});
  }
  return v;
}

std::vector<Interval> merged(std::vector<Interval> v) {
  std::sort(v.begin(), v.end(), [](const Interval& a, const Interval& b) { return a.lo < b.lo; });
  std::vector<Interval> out;
  for (const Interval& i : v) {
    if (!out.empty() && i.lo <= out.back().hi) out.back().hi = std::max(out.back().hi, i.hi);
    else out.push_back(i);
  }
  return out;
}

MassProperties shell_quadrature(const BodyGeometry& b) {
  const bool solid = b.mass_model == MassModel::Solid;
  const double R = b.sphere_radius, r = b.stem_radius, l = b.stem_length, h = b.truncation_height;
  // [int dZ, int Z dZ, int Z^2 dZ] over the shell's Z-set.
  auto zints = [&](double s) {
    auto v = parts_at(b, s, solid);
    if (solid) v = merged(v);
    std::array<double, 3> m{0, 0, 0};
    for (const Interval& i : v) {
      m[0] += i.hi - i.lo;
      m[1] += (i.hi * i.hi - i.lo * i.lo) / 2;
      m[2] += (std::pow(i.hi, 3) - std::pow(i.lo, 3)) / 3;
    }
    return m;
  };
  // Kinks of the shell integrand in s: r, the rim of the cut sqrt(R^2 - h^2), and (solid) the
  // radius where the top of the ball's interval meets the top of the stem's, located by bisection.
  std::vector<double> cuts{0.0, R};
  if (r < R) cuts.push_back(r);
  if (std::abs(h) < R) cuts.push_back(std::sqrt(R * R - h * h));
  if (solid) {
    auto g = [&](double s) { return std::min(h, std::sqrt(R * R - s * s)) - (l + std::sqrt(r * r - s * s)); };
    const int n = 4000;
    for (int i = 0; i < n; ++i) {
      const double s0 = r * i / n, s1 = r * (i + 1) / n;
      if ((g(s0) < 0) != (g(s1) < 0)) {
        auto tol = [](double a, double c) { return std::abs(c - a) <= 4 * std::numeric_limits<double>::epsilon() * c; };
        const auto root = boost::math::tools::bisect(g, s0, s1, tol);
        cuts.push_back(0.5 * (root.first + root.second));
      }
    }
  }
  std::sort(cuts.begin(), cuts.end());
  cuts.erase(std::unique(cuts.begin(), cuts.end()), cuts.end());

  boost::math::quadrature::tanh_sinh<double> ts;
  std::array<double, 4> q{0, 0, 0, 0};  // M, first moment, I_X about O, I_Z
  for (size_t i = 0; i + 1 < cuts.size(); ++i) {
    const double a = cuts[i], c = cuts[i + 1];
    auto piece = [&](int k) {
      return ts.integrate(
          [&](double s) {
            const auto m = zints(s);
            const double w = 2 * kPi * s * b.density;
            switch (k) {
              case 0: return w * m[0];
              case 1: return w * m[1];
              case 2: return w * (0.5 * s * s * m[0] + m[2]);  // a ring's mean Y^2 is s^2/2
              default: return w * s * s * m[0];
            }
          },
          a, c, 1e-14);
    };
    for (int k = 0; k < 4; ++k) q[k] += piece(k);
  }
  const double ZG = q[1] / q[0];
  return {q[0], -ZG, q[2] - q[0] * ZG * ZG, q[3]};
}

std::string describe(const BodyGeometry& b) {
  std::ostringstream o;
  o << std::setprecision(6) << "R=" << b.sphere_radius << " r=" << b.stem_radius << " l=" << b.stem_length
    << " h=" << b.truncation_height << " rho=" << b.density;
  return o.str();
}

// Checks M, d, A, C to a relative tolerance and returns the largest discrepancy found. d may be
// zero (full ball), so it is compared as the first moment M d on the body's length scale sqrt(C/M).
double expect_close(const MassProperties& got, const MassProperties& want, double tol, const std::string& what) {
  const double scale = want.mass * std::sqrt(want.inertia_axial / want.mass);
  const double e[4] = {rel(got.mass, want.mass), std::abs(got.mass * got.com_offset - want.mass * want.com_offset) / scale,
                       rel(got.inertia_transverse, want.inertia_transverse), rel(got.inertia_axial, want.inertia_axial)};
  EXPECT_LT(e[0], tol) << what << ": M " << got.mass << " vs " << want.mass;
  EXPECT_LT(e[1], tol) << what << ": d " << got.com_offset << " vs " << want.com_offset;
  EXPECT_LT(e[2], tol) << what << ": A " << got.inertia_transverse << " vs " << want.inertia_transverse;
  EXPECT_LT(e[3], tol) << what << ": C " << got.inertia_axial << " vs " << want.inertia_axial;
  return *std::max_element(e, e + 4);
}

void print(const std::string& label, const MassProperties& m, double R) {
  std::cout << std::setprecision(12) << label << ": M = " << m.mass << " kg, d = " << m.com_offset
            << " m, A = " << m.inertia_transverse << " kg m^2, C = " << m.inertia_axial
            << " kg m^2, alpha = d/R = " << m.com_offset / R << ", A/C = " << m.inertia_transverse / m.inertia_axial
            << ", inversion possible: " << (inversion_possible(m, R) ? "yes" : "no") << "\n";
}

// ---- tests ----

TEST(MassProperties, SeedReproducesPrintedClosedForms) {
  // Same formulas through a different algebraic route: only rounding separates them (a few ulp,
  // times the cancellation in A = sum - M Z_G^2, which is below 10 for these bodies).
  double worst = 0;
  for (const BodyGeometry& b : geometries(MassModel::Seed))
    worst = std::max(worst, expect_close(compute_mass_properties(b), printed_seed(b), 1e-13, describe(b)));
  std::cout << "seed: largest relative discrepancy from the printed closed forms " << worst << "\n";
}

TEST(MassProperties, SeedMatchesShellQuadrature) {
  // Tolerance: the 1e-10 the mass properties are required to; tanh-sinh at 1e-14 termination delivers ~1e-14 on these
  // piecewise-smooth integrands once the kinks are integration ends.
  double worst = 0;
  for (const BodyGeometry& b : geometries(MassModel::Seed))
    worst = std::max(worst, expect_close(compute_mass_properties(b), shell_quadrature(b), 1e-10, describe(b)));
  std::cout << "seed: largest relative discrepancy from the shell quadrature " << worst << "\n";
}

TEST(MassProperties, SolidMatchesShellQuadrature) {
  // Tolerance: as above; the shells merge the parts' Z-intervals, an independent way to count
  // the overlap once.
  double worst = 0;
  for (const BodyGeometry& b : geometries(MassModel::Solid))
    worst = std::max(worst, expect_close(compute_mass_properties(b), shell_quadrature(b), 1e-10, describe(b)));
  std::cout << "solid: largest relative discrepancy from the shell quadrature " << worst << "\n";
}

TEST(MassProperties, UniformFullBall) {
  const double R = 0.7, rho = 3.0, M = 4.0 / 3 * kPi * R * R * R * rho;
  const MassProperties want{M, 0.0, 0.4 * M * R * R, 0.4 * M * R * R};
  // Tolerance 1e-14: exact polynomial integrals, rounding only.
  const MassProperties ball = truncated_ball_mass_properties(R, R, rho);
  EXPECT_LT(rel(ball.mass, M), 1e-14);
  EXPECT_LT(std::abs(ball.com_offset), 1e-14 * R);
  EXPECT_LT(rel(ball.inertia_transverse, want.inertia_transverse), 1e-14);
  EXPECT_LT(rel(ball.inertia_axial, want.inertia_axial), 1e-14);
  // A stem of radius 1e-7 R adds a relative mass of order (r/R)^2 l/R ~ 1e-14, within 1e-12.
  for (MassModel model : {MassModel::Seed, MassModel::Solid}) {
    const MassProperties m = compute_mass_properties(body(R, 1e-7 * R, 1.2 * R, R, rho, model));
    EXPECT_LT(rel(m.mass, M), 1e-12);
    EXPECT_LT(std::abs(m.com_offset), 1e-12 * R);
    EXPECT_LT(rel(m.inertia_transverse, want.inertia_transverse), 1e-12);
    EXPECT_LT(rel(m.inertia_axial, want.inertia_axial), 1e-12);
  }
  // No stem at all (a bare-ball scene that gives no stem size): the same ball, to rounding.
  for (MassModel model : {MassModel::Seed, MassModel::Solid})
    expect_close(compute_mass_properties(body(R, 0, 0, R, rho, model)), want, 1e-14, "bare ball");
}

TEST(MassProperties, TruncatedBallMatchesPrintedClosedForms) {
  // The source's ball integrals (moments moved from O to the ball's own centre) against the
  // piecewise slab integrals; rounding only, amplified by A = I_O - M Z_s^2 (< 10x here).
  const double R = 1.3, rho = 0.8;
  for (double x : {-0.9, -0.5, 0.0, 0.3, 0.36, 0.9, 1.0}) {
    BodyGeometry b = body(R, 0, 0, x * R, rho, MassModel::Seed);
    const Printed p = printed(b);
    const MassProperties want{p.Ms, -p.Zs, p.IXs_O - p.Ms * p.Zs * p.Zs, p.IZs};
    expect_close(truncated_ball_mass_properties(R, x * R, rho), want, 1e-13, "h/R = " + std::to_string(x));
  }
}

// Volume of cylinder (radius r, 0 <= Z <= l) inside the ball cut at h: radius min(r, sqrt(R^2 - Z^2)).
double overlap_volume(double R, double r, double l, double h) {
  const double top = std::min(h, l), s = std::sqrt(R * R - r * r);
  if (top <= 0) return 0;
  if (top <= s) return kPi * r * r * top;
  return kPi * r * r * s + kPi * ((R * R * top - top * top * top / 3) - (R * R * s - s * s * s / 3));
}

TEST(MassProperties, SeedMinusSolidIsOverlapMinusTip) {
  // Valid when the tip hemisphere lies wholly above the cut (h <= l): then solid = seed - overlap + tip.
  // Tolerance: both masses are rounding-exact (~1e-16 M); 1e-13 M leaves room for the difference.
  for (const BodyGeometry& g : geometries(MassModel::Seed)) {
    if (g.truncation_height > g.stem_length) continue;
    BodyGeometry s = g;
    s.mass_model = MassModel::Solid;
    const double Mseed = compute_mass_properties(g).mass, Msolid = compute_mass_properties(s).mass;
    const double r = g.stem_radius;
    const double want = g.density * (overlap_volume(g.sphere_radius, r, g.stem_length, g.truncation_height) -
                                     2.0 / 3 * kPi * r * r * r);
    EXPECT_NEAR(Mseed - Msolid, want, 1e-13 * Mseed) << describe(g);
  }
}

TEST(MassProperties, ToyTop) {
  const double R = 0.015;
  const MassProperties seed = compute_mass_properties(toy(MassModel::Seed));
  const MassProperties solid = compute_mass_properties(toy(MassModel::Solid));
  print("toy top, seed ", seed, R);
  print("toy top, solid", solid, R);
  for (auto [name, m] : {std::pair{"seed", seed}, std::pair{"solid", solid}}) {
    RecordProperty(std::string(name) + "_M", std::to_string(m.mass));
    RecordProperty(std::string(name) + "_alpha", std::to_string(m.com_offset / R));
    RecordProperty(std::string(name) + "_A_over_C", std::to_string(m.inertia_transverse / m.inertia_axial));
  }
  // The values expected of the seed convention ("alpha near 0.13, A/C near 1.0").
  EXPECT_NEAR(seed.com_offset / R, 0.13, 0.01);
  EXPECT_NEAR(seed.inertia_transverse / seed.inertia_axial, 1.0, 0.02);
  EXPECT_TRUE(inversion_possible(seed, R));
}

// ---- geometry checks ----

bool has_key(const std::vector<std::string>& problems, const std::string& key, const std::string& fragment = "") {
  for (const std::string& p : problems)
    if (p.rfind(key + ": ", 0) == 0 && p.find(fragment) != std::string::npos) return true;
  return false;
}

std::string joined(const std::vector<std::string>& v) {
  std::string s;
  for (const auto& x : v) s += "[" + x + "] ";
  return s;
}

TEST(MassProperties, GeometryProblems) {
  const double nan = std::numeric_limits<double>::quiet_NaN(), inf = std::numeric_limits<double>::infinity();
  const BodyGeometry ok = toy(MassModel::Solid);
  EXPECT_TRUE(geometry_problems(ok, true).empty()) << joined(geometry_problems(ok, true));
  EXPECT_TRUE(geometry_problems(ok, false).empty());
  BodyGeometry no_density = ok;  // density not read yet / mass given directly
  no_density.density = 0;
  EXPECT_TRUE(geometry_problems(no_density, true).empty());

  struct Case {
    const char* name;
    void (*edit)(BodyGeometry&);
    const char* key;
    const char* fragment;
  };
  const Case cases[] = {
      {"R zero", [](BodyGeometry& b) { b.sphere_radius = 0; }, "sphere_radius", ""},
      {"R negative", [](BodyGeometry& b) { b.sphere_radius = -0.015; }, "sphere_radius", "-0.015"},
      {"R nan", [](BodyGeometry& b) { b.sphere_radius = std::numeric_limits<double>::quiet_NaN(); }, "sphere_radius", ""},
      {"density negative", [](BodyGeometry& b) { b.density = -1000; }, "density", "-1000"},
      {"density inf", [](BodyGeometry& b) { b.density = std::numeric_limits<double>::infinity(); }, "density", ""},
      {"h below ball", [](BodyGeometry& b) { b.truncation_height = -0.015; }, "truncation_height", "(-0.015, 0.015]"},
      {"h above ball", [](BodyGeometry& b) { b.truncation_height = 0.016; }, "truncation_height", "0.016"},
      {"r zero", [](BodyGeometry& b) { b.stem_radius = 0; }, "stem_radius", ""},
      {"r >= R", [](BodyGeometry& b) { b.stem_radius = 0.015; },
       "stem_radius", "r = 0.015 must be smaller than sphere_radius R = 0.015"},
      {"tip inside ball", [](BodyGeometry& b) { b.stem_length = 0.012; }, "stem_length", "stick out of the ball"},
      {"no switch", [](BodyGeometry& b) { b.stem_length = b.sphere_radius - b.stem_radius; }, "stem_length",
       "(R - r)/l = 1 must be < 1 for the stem to reach the floor"},
      {"cut below the switch contact", [](BodyGeometry& b) { b.truncation_height = 0.0052; },
       "truncation_height", "0.0052"},
  };
  for (const Case& c : cases) {
    BodyGeometry b = ok;
    c.edit(b);
    const auto p = geometry_problems(b, true);
    EXPECT_TRUE(has_key(p, c.key, c.fragment)) << c.name << ": " << joined(p);
  }
  // Numbers keep all their digits: the bound printed reads back as the very double compared.
  BodyGeometry b = ok;
  b.truncation_height = 0.005;
  const auto p = geometry_problems(b, true);
  ASSERT_EQ(p.size(), 1u) << joined(p);
  const std::string marker = "R (R - r)/l = ";
  const auto at = p[0].find(marker);
  ASSERT_NE(at, std::string::npos) << p[0];
  EXPECT_EQ(std::strtod(p[0].c_str() + at + marker.size(), nullptr), ok.sphere_radius *
            ((ok.sphere_radius - ok.stem_radius) / ok.stem_length)) << p[0];
  // Without stem contact only the ball matters.
  b = ok;
  b.stem_radius = 0;
  b.stem_length = 0;
  b.truncation_height = 0.001;
  EXPECT_TRUE(geometry_problems(b, false).empty()) << joined(geometry_problems(b, false));
  b.truncation_height = nan;
  EXPECT_TRUE(has_key(geometry_problems(b, false), "truncation_height"));
  b.truncation_height = 0.001;
  b.stem_radius = -inf;
  EXPECT_TRUE(has_key(geometry_problems(b, false), "stem_radius"));
}

TEST(MassProperties, ComputeRejectsImpossibleBodies) {
  auto key_of = [](BodyGeometry b) -> std::string {
    try {
      compute_mass_properties(b);
    } catch (const std::invalid_argument& e) {
      const std::string w = e.what();
      return w.substr(0, w.find(": "));
    }
    return "(no throw)";
  };
  BodyGeometry b = toy(MassModel::Given);
  EXPECT_EQ(key_of(b), "mass_model");
  b = toy(MassModel::Solid);
  b.density = 0;
  EXPECT_EQ(key_of(b), "density");
  b = toy(MassModel::Seed);
  b.sphere_radius = -1;
  EXPECT_EQ(key_of(b), "sphere_radius");
  b = toy(MassModel::Seed);
  b.truncation_height = 0.02;
  EXPECT_EQ(key_of(b), "truncation_height");
  b = toy(MassModel::Solid);
  b.stem_length = -0.01;
  EXPECT_EQ(key_of(b), "stem_length");
}

// ---- MuJoCo's tutorial top ----

TEST(MassProperties, MujocoTutorialTop) {
  const MassProperties m = mujoco_tutorial_mass_properties();
  print("MuJoCo tutorial top (MuJoCo's bookkeeping)", m, 0.02);
  RecordProperty("mujoco_M", std::to_string(m.mass));
  RecordProperty("mujoco_d", std::to_string(m.com_offset));
  RecordProperty("mujoco_A", std::to_string(m.inertia_transverse));
  RecordProperty("mujoco_C", std::to_string(m.inertia_axial));

  // Independent check: MuJoCo's own compiler on the tutorial's body (geoms verbatim from the
  // tutorial). It adds geoms' masses and parallel-axis inertias in double precision and then
  // diagonalises; 1e-12 covers the eigen-solver's rounding.
  const char* xml = R"(<mujoco model="tippe top">
  <worldbody>
    <geom size=".2 .2 .01" type="plane"/>
    <body name="top" pos="0 0 .02">
      <freejoint/>
      <geom name="ball" type="sphere" size=".02" />
      <geom name="stem" type="cylinder" pos="0 0 .02" size="0.004 .008"/>
      <geom name="ballast" type="box" size=".023 .023 0.005"  pos="0 0 -.015"
       contype="0" conaffinity="0" group="3"/>
    </body>
  </worldbody>
</mujoco>
)";
  const auto path = std::filesystem::temp_directory_path() /
                    ("tippe_mass_mujoco_" + std::to_string(::getpid()) + ".xml");
  std::ofstream(path) << xml;
  char err[1000] = "";
  mjModel* model = mj_loadXML(path.c_str(), nullptr, err, sizeof err);
  std::filesystem::remove(path);
  ASSERT_NE(model, nullptr) << err;
  const int top = mj_name2id(model, mjOBJ_BODY, "top");
  ASSERT_GE(top, 0);
  std::array<double, 3> I{model->body_inertia[3 * top], model->body_inertia[3 * top + 1],
                          model->body_inertia[3 * top + 2]};
  std::sort(I.begin(), I.end());
  // The repeated principal moment is the transverse one.
  const bool low_pair = I[1] - I[0] < I[2] - I[1];
  const MassProperties mj{model->body_mass[top], -model->body_ipos[3 * top + 2], low_pair ? I[0] : I[2],
                          low_pair ? I[2] : I[0]};
  print("MuJoCo tutorial top (MuJoCo 2.2 compiler)  ", mj, 0.02);
  EXPECT_LT(std::abs(model->body_ipos[3 * top]) + std::abs(model->body_ipos[3 * top + 1]), 1e-15);
  mj_deleteModel(model);
  expect_close(m, mj, 1e-12, "MuJoCo compiler");
}

}  // namespace
}  // namespace tippe
