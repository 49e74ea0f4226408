// A plain Boost.Odeint RKF78 solver of rutstam_ball (the viscous eccentric ball), the yardstick of
// the reference's whole-process cost in BENCHMARKS.md: no harness, no events, no scene file.
//
// The body and start are harness/scenes/rutstam_ball.toml's (m 20 g, R 20 mm, G 6 mm below the
// ball's centre O on the axis, A = 131/350 m R^2, C = 2/5 m R^2, F_t = -k v_C with k = 0.0589,
// tilt 0.1 rad about the lab x axis, spin 155 rad/s about the axis, G at rest), the ball always on
// the floor (z_O = R, the normal force solved from the constraint's second derivative at every
// evaluation). Lab-frame Newton, body-frame Euler, quaternion attitude.
//
// Usage: plain_viscous_ball [DURATION [SAMPLE_INTERVAL [OUT.csv]]]   (default 12 s, 1 ms, no file)
// With OUT.csv every sample is written (t, G, v_G, q_WB, w_B at 17 digits), as `tippe run` writes
// its trajectory; on stdout the final state and the first time the axis passes horizontal.
#include <Eigen/Dense>
#include <array>
#include <boost/numeric/odeint.hpp>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <vector>

namespace {

using State = std::array<double, 13>;  // p_WG (3), v_WG (3), q_WB (w, x, y, z), w_B (3)

constexpr double kG = 9.81, kM = 0.02, kR = 0.02, kD = 0.006, kK = 0.0589;
constexpr double kA = 131.0 / 350.0 * kM * kR * kR, kC = 0.4 * kM * kR * kR;

void rhs(const State& x, State& dx, double /*t*/) {
  const Eigen::Vector3d v(x[3], x[4], x[5]);
  const Eigen::Quaterniond q(x[6], x[7], x[8], x[9]);
  const Eigen::Vector3d wB(x[10], x[11], x[12]);
  const Eigen::Matrix3d R = q.normalized().toRotationMatrix();
  const Eigen::Vector3d ez = Eigen::Vector3d::UnitZ();
  const Eigen::Vector3d a = R.col(2);  // the symmetry axis; O = G + d a, C = O - R ez
  const Eigen::Vector3d r = kD * a - kR * ez;
  const Eigen::Vector3d w = R * wB;
  const Eigen::Vector3d I(kA, kA, kC);
  Eigen::Vector3d vC = v + w.cross(r);
  vC.z() = 0.0;
  const Eigen::Vector3d Ft = -kK * vC;
  // Angular acceleration (lab) = alpha0 + N alpha1; body-frame Euler equations.
  auto alpha_of = [&](const Eigen::Vector3d& torque_W, bool gyro) {
    Eigen::Vector3d tB = R.transpose() * torque_W;
    if (gyro) tB -= wB.cross(I.cwiseProduct(wB));
    return Eigen::Vector3d(R * tB.cwiseQuotient(I));
  };
  const Eigen::Vector3d alpha0 = alpha_of(r.cross(Ft), true);
  const Eigen::Vector3d alpha1 = alpha_of(r.cross(ez), false);
  // z_G + d a_z = R: a_Gz + d (alpha x a + w x (w x a))_z = 0, a_Gz = N / m - g.
  const double wwa = w.cross(w.cross(a)).z();
  const double N = (kG - kD * (alpha0.cross(a).z() + wwa)) / (1.0 / kM + kD * alpha1.cross(a).z());
  const Eigen::Vector3d acc = (Ft + N * ez) / kM - kG * ez;
  const Eigen::Vector3d alpha = alpha0 + N * alpha1;
  const Eigen::Vector3d dwB = R.transpose() * alpha;
  const Eigen::Quaterniond dq(0.0, 0.5 * wB.x(), 0.5 * wB.y(), 0.5 * wB.z());
  const Eigen::Quaterniond qd = q * dq;
  dx = {v.x(), v.y(), v.z(), acc.x(), acc.y(), acc.z(), qd.w(), qd.x(), qd.y(), qd.z(), dwB.x(), dwB.y(), dwB.z()};
}

}  // namespace

int main(int argc, char** argv) {
  namespace odeint = boost::numeric::odeint;
  const double T = argc > 1 ? std::atof(argv[1]) : 12.0;
  const double dt = argc > 2 ? std::atof(argv[2]) : 1e-3;
  std::FILE* out = argc > 3 ? std::fopen(argv[3], "w") : nullptr;
  if (argc > 3 && !out) {
    std::perror(argv[3]);
    return 2;
  }
  const double tilt = 0.1, spin = 155.0;
  const Eigen::Quaterniond q0(Eigen::AngleAxisd(tilt, Eigen::Vector3d::UnitX()));
  const Eigen::Vector3d a0 = q0 * Eigen::Vector3d::UnitZ();
  const Eigen::Vector3d G0 = Eigen::Vector3d(0, 0, kR) - kD * a0;
  State x = {G0.x(), G0.y(), G0.z(), 0, 0, 0, q0.w(), q0.x(), q0.y(), q0.z(), 0, 0, spin};

  std::vector<double> times;
  const long n = static_cast<long>(std::floor(T / dt + 1e-9));
  for (long k = 0; k <= n; ++k) times.push_back(static_cast<double>(k) * dt);
  double inversion = -1.0, last_az = std::cos(tilt);
  if (out) std::fputs("t,x,y,z,vx,vy,vz,qw,qx,qy,qz,wx,wy,wz\n", out);
  auto observe = [&](const State& s, double t) {
    const Eigen::Quaterniond q(s[6], s[7], s[8], s[9]);
    const double az = (q.normalized() * Eigen::Vector3d::UnitZ()).z();
    if (inversion < 0 && last_az > 0 && az <= 0) inversion = t;
    last_az = az;
    if (!out) return;
    std::fprintf(out, "%.17g", t);
    for (double c : s) std::fprintf(out, ",%.17g", c);
    std::fputc('\n', out);
  };
// g++ 12 warns that the default-constructed stepper's scratch arrays are copied before being
// written (they are scratch: every step writes them before reading).
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
  auto stepper = odeint::make_controlled(1e-14, 1e-10, odeint::runge_kutta_fehlberg78<State>());
#pragma GCC diagnostic pop
  const size_t steps = odeint::integrate_times(stepper, rhs, x, times.begin(), times.end(), dt, observe);
  if (out) std::fclose(out);
  std::printf("t %.6g steps %zu first axis-horizontal sample %.6f z_G %.12g w_z(body) %.12g\n", T, steps, inversion,
              x[2], x[12]);
  return 0;
}
