// The reference's energy ledger: the contact power, its Gauss-Legendre booking per step, and the contact work at a sample from the power the booking evaluated.
#include <algorithm>
#include <array>
#include <cmath>

#include "analytic/detail/reference_impl.h"

namespace tippe {

using namespace reference_detail;

// Power of the contact forces and torques on the body (<= 0 for a dissipative law; the
// normal force's share is its work on the drift of a held contact, tolerance-sized).
// Per part: (normal force along +z, tangential force, drilling torque), for the energy ledger's split.
Vec3 ReferenceModel::Impl::contact_power(const StateVector& y) { return contact_power(y, forces_at(y, mode)); }

Vec3 ReferenceModel::Impl::contact_power(const StateVector& y, const ContactForces& f) const {
  const BodyState x = unpack(y, 0);
  const double wz = (x.q_WB.normalized() * x.w_B).z();
  Vec3 p = Vec3::Zero();
  for (int s = 0; s < 2; ++s) {
    if (!mode.slot[s].active) continue;
    const Vec3 v = dyn.contact_velocity(x, s);
    const Vec3& F = f.force_W[s];
    p += Vec3(F.z() * v.z(), F.x() * v.x() + F.y() * v.y(), f.drill_torque[s] * wz);
  }
  return p;
}

// Friction work over [a, b] inside the last step (dense output), 5-point Gauss-Legendre
// (exact to degree 9). Every mode change ends an interval, so the power is smooth on it;
// measured against E(t) the ledger closes to ~1e-11 E0 (dopri5) and ~7e-10 E0 (bulirsch_stoer,
// whose own energy error near the end of a graze is that size, see GrazePinch).
namespace {
constexpr double kGaussX[5] = {-0.9061798459386640, -0.5384693101056831, 0.0, 0.5384693101056831, 0.9061798459386640};
constexpr double kGaussW[5] = {0.2369268850561891, 0.4786286704993665, 0.5688888888888889, 0.4786286704993665, 0.2369268850561891};
}  // namespace

Vec3 ReferenceModel::Impl::gauss5(double a, double b, std::array<Vec3, 5>* nodes) {
  const double half = 0.5 * (b - a), mid = 0.5 * (a + b);
  Vec3 sum = Vec3::Zero();
  for (int i = 0; i < 5; ++i) {
    const Vec3 p = contact_power(state_at(mid + half * kGaussX[i]));
    if (nodes) (*nodes)[i] = p;
    sum += kGaussW[i] * p;
  }
  return half * sum;
}

Vec3 ReferenceModel::Impl::friction_work(double a, double b, std::array<Vec3, 5>* nodes) {
  if (!(b > a) || !mode.any_active()) {
    if (nodes) nodes->fill(Vec3::Zero());
    return Vec3::Zero();
  }
  return -gauss5(a, b, nodes);
}

// The interpolants of the power through its values at a, the five Gauss nodes of [a, b] and b
// (degree 6, in x = (t - mid) / half on [-1, 1]), and through the last six (degree 5),
// integrated from t to b. Over the whole of [a, b] either gives the booking's Gauss-Legendre sum
// (the ends' weights vanish: their Lagrange polynomials are P5(x) times a linear factor,
// orthogonal to constants), so the ledger is continuous at step ends; inside a step they
// replace a 5-point quadrature of [t, b] that cost five contact solves per sample.
namespace {
template <int N>
struct LagrangeTable {
  // Per node j, the coefficients (lowest first) of the antiderivative of its Lagrange
  // polynomial, divided by x: A_j(x) = x sum_k anti[j][k] x^k.
  std::array<std::array<double, N>, N> anti{};
  // Per node, A_j(1): its coefficients summed highest first, once here instead of per call.
  std::array<double, N> at_one{};
  explicit LagrangeTable(const double* xs) {
    for (int j = 0; j < N; ++j) {
      std::array<double, N> c{};
      c[0] = 1.0;
      int deg = 0;
      for (int m = 0; m < N; ++m) {
        if (m == j) continue;
        const double d = xs[j] - xs[m];
        // c *= (x - xs[m]) / d
        for (int k = deg + 1; k >= 0; --k) c[k] = ((k > 0 ? c[k - 1] : 0.0) - xs[m] * (k <= deg ? c[k] : 0.0)) / d;
        ++deg;
      }
      for (int k = 0; k < N; ++k) anti[j][k] = c[k] / (k + 1);
      for (int k = N - 1; k >= 0; --k) at_one[j] += anti[j][k];
    }
  }
  // The work of the interpolant through values p[0..N) from x to 1, per unit half-length.
  Vec3 work_to_end(double x, const Vec3* p) const {
    Vec3 sum = Vec3::Zero();
    for (int j = 0; j < N; ++j) {
      double at_x = 0.0;
      for (int k = N - 1; k >= 0; --k) at_x = at_x * x + anti[j][k];
      sum += (at_one[j] - x * at_x) * p[j];
    }
    return sum;
  }
};
constexpr double kFitNodes[7] = {-1.0, kGaussX[0], kGaussX[1], kGaussX[2], kGaussX[3], kGaussX[4], 1.0};
}  // namespace

Vec3 ReferenceModel::Impl::PowerFit::work_to_end(double t, bool with_start) const {
  static const LagrangeTable<7> all(kFitNodes);
  static const LagrangeTable<6> no_start(kFitNodes + 1);
  if (!(b > a)) return Vec3::Zero();
  const double half = 0.5 * (b - a), mid = 0.5 * (a + b);
  const double x = std::clamp((t - mid) / half, -1.0, 1.0);
  return half * (with_start ? all.work_to_end(x, p.data()) : no_start.work_to_end(x, p.data() + 1));
}

bool ReferenceModel::Impl::PowerFit::trusted_work_to_end(double t, double tolerance, Vec3& work) const {
  work = work_to_end(t, true);
  return (work - work_to_end(t, false)).cwiseAbs().maxCoeff() <= tolerance;
}

void ReferenceModel::Impl::refine_power_fit() {
  const PowerFit& f = power_fit;
  const double mid = 0.5 * (f.a + f.b);  // the whole interval's middle Gauss node (x = 0)
  const double ends[3] = {f.a, mid, f.b};
  const Vec3 at[3] = {f.p[0], f.p[3], f.p[6]};
  for (int h = 0; h < 2; ++h) {
    PowerFit& half = power_halves[h];
    std::array<Vec3, 5> nodes;
    (void)friction_work(ends[h], ends[h + 1], &nodes);
    half.valid = true;
    half.a = ends[h];
    half.b = ends[h + 1];
    half.p[0] = at[h];
    std::copy(nodes.begin(), nodes.end(), half.p.begin() + 1);
    half.p[6] = at[h + 1];
  }
}

bool ReferenceModel::Impl::fitted_work_to_end(double t, Vec3& work) {
  if (power_fit.trusted_work_to_end(t, fit_tolerance, work)) return true;
  if (!power_halves[0].valid) {
    if (fit_misses++ == 0) return false;
    refine_power_fit();
  }
  const PowerFit& late = power_halves[1];
  if (t >= late.a) return late.trusted_work_to_end(t, fit_tolerance, work);
  Vec3 rest;
  if (!late.trusted_work_to_end(late.a, fit_tolerance, rest)) return false;
  if (!power_halves[0].trusted_work_to_end(t, fit_tolerance, work)) return false;
  work += rest;
  return true;
}

void EnergyLedger::add_contact_work(const Vec3& against) {
  friction += against.sum();
  normal += against.x();
  tangential += against.y();
  drilling += against.z();
}

void ReferenceModel::Impl::accumulate_friction_work(double a, double b) {
  std::array<Vec3, 5> nodes;
  ledger.add_contact_work(friction_work(a, b, &nodes));
  ledger_t = b;
  // The end's power is filled in by close_power_fit, once step() has it (the check point or the
  // event at b).
  power_fit.valid = false;
  power_fit.a = a;
  power_fit.b = b;
  power_halves[0].valid = power_halves[1].valid = false;
  fit_misses = 0;
  power_fit.p[0] = p_start;
  std::copy(nodes.begin(), nodes.end(), power_fit.p.begin() + 1);
}

void ReferenceModel::Impl::close_power_fit(const Vec3& p_end) {
  power_fit.p[6] = p_end;
  power_fit.valid = true;
}

EnergyLedger ReferenceModel::energy_ledger() const {
  // On demand: the contact work from the observed time to the end of what is booked, from the
  // power the booking evaluated (PowerFit): no contact solve per observation.
  Impl& m = *impl_;
  if (!m.ledger_obs_valid) {
    m.ledger_obs = m.ledger;
    if (status_ == ReferenceStatus::Ok && t_obs_ < m.ledger_t) {
      const Impl::PowerFit& fit = m.power_fit;
      // The observed time lies in the last booked interval (advance_to stops in it); the
      // quadrature of [t_obs, ledger_t] stays as the fallback should it ever not.
      Vec3 w;
      if (fit.valid && fit.b == m.ledger_t && fit.a <= t_obs_ && m.fitted_work_to_end(t_obs_, w))
        m.ledger_obs.add_contact_work(w);
      else
        m.ledger_obs.add_contact_work(-m.friction_work(t_obs_, m.ledger_t));
    }
    m.ledger_obs_valid = true;
  }
  return m.ledger_obs;
}

}  // namespace tippe
