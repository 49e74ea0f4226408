// The reference's dense-output integrators: Boost.Odeint's Bulirsch-Stoer and Dormand-Prince 5(4), and Rosenbrock4 on ublas vectors.
#include "analytic/detail/dense_stepper.h"

#include "analytic/boost_binomial.h"  // first: it must precede every Boost.Math and Odeint header
#include <boost/numeric/odeint.hpp>

#include <algorithm>
#include <cmath>
#include <limits>
#include <tuple>
#include <utility>

namespace tippe {
namespace reference_detail {

namespace odeint = boost::numeric::odeint;

namespace {

using Dopri = odeint::runge_kutta_dopri5<StateVector>;

template <class S>
struct DenseStepperOf final : DenseStepper {
  explicit DenseStepperOf(S s) : stepper(std::move(s)) {}
  void initialize(const StateVector& y, double t, double dt) override { stepper.initialize(y, t, dt); }
  std::pair<double, double> do_step(const System& sys) override { return stepper.do_step(sys); }
  void calc_state(double t, StateVector& y) override { stepper.calc_state(t, y); }
  const StateVector& current_state() const override { return stepper.current_state(); }
  double current_time() const override { return stepper.current_time(); }
  double current_time_step() const override { return stepper.current_time_step(); }
  S stepper;
};

// Rosenbrock4 (L-stable, order 4, dense output of order 3) for stiff runs: the viscous law's
// slip relaxes at the rate ~k/M, which limits the explicit methods' step to ~M/k however
// smooth the motion. Boost's stepper works on ublas vectors; this converts at the interface.
class RosenbrockStepper final : public DenseStepper {
 public:
  using UVector = boost::numeric::ublas::vector<double>;
  using UMatrix = boost::numeric::ublas::matrix<double>;
  using Stepper = odeint::rosenbrock4_dense_output<odeint::rosenbrock4_controller<odeint::rosenbrock4<double>>>;

  RosenbrockStepper(double atol, double rtol, double max_dt, SmoothScale smooth)
      : stepper_(odeint::rosenbrock4_controller<odeint::rosenbrock4<double>>(atol, rtol, max_dt)),
        u_(kN),
        jac_(kN, kN),
        smooth_(std::move(smooth)) {}

  void initialize(const StateVector& y, double t, double dt) override {
    to_ublas(y, u_);
    stepper_.initialize(u_, t, dt);
    y_ = y;
  }

  std::pair<double, double> do_step(const System& sys) override {
    auto rhs = [&](const UVector& x, UVector& dxdt, double t) {
      StateVector xs, fs;
      from_ublas(x, xs);
      sys(xs, fs, t);
      to_ublas(fs, dxdt);
    };
    // The controller retries a rejected step from the same state, in the same mode: the
    // Jacobian is kept for those retries.
    bool have_jac = false;
    StateVector x_jac{};
    auto jacobian = [&](const UVector& x, UMatrix& J, const double& t, UVector& dfdt) {
      // The right-hand side does not depend on t (an autonomous system).
      for (size_t i = 0; i < kN; ++i) dfdt[i] = 0.0;
      StateVector x0;
      from_ublas(x, x0);
      if (!have_jac || x0 != x_jac) {
        fill_jacobian(sys, smooth_, x0, t, jac_);
        x_jac = x0;
        have_jac = true;
      }
      J = jac_;
    };
    const auto span = stepper_.do_step(std::make_pair(rhs, jacobian));
    from_ublas(stepper_.current_state(), y_);
    return span;
  }

  void calc_state(double t, StateVector& y) override {
    stepper_.calc_state(t, u_);
    from_ublas(u_, y);
  }
  const StateVector& current_state() const override { return y_; }
  double current_time() const override { return stepper_.current_time(); }
  double current_time_step() const override { return stepper_.current_time_step(); }

 private:
  static constexpr size_t kN = std::tuple_size<StateVector>::value;

  // Central differences, h_j = cbrt(eps) * scale_j: truncation O(h^2) balances round-off
  // O(eps / h), so J is right to ~1e-10 relative. Forward differences (~1e-8) do not do: the
  // embedded error estimate uses the same J, so an error in J escapes the step control (it
  // made the tilt error 50x larger at rtol 1e-10). scale_j is the larger of |y_j| and the norm
  // of its group (p, v, q, omega; 1 if that is 0), so a zero component is not perturbed at
  // the scale of round-off; and at most the scale over which the right-hand side itself turns
  // (`smooth`, ContactDynamics::slip_scale): a sliding Coulomb direction s / |s| turns on the
  // scale of the slip, so the perturbation must be small against |s| as it is against |y_j|
  // (the same cbrt(eps) balance, with |s| the scale), and it never carries the slip across
  // zero. Without that bound, just past a slip start (|s| = 2.7e-7 m/s on leine_glocker at mu
  // 0.02, tilt 1 rad) the perturbations of v, q and w moved the slip by 2 to 50 times |s|
  // (w: 5.6e-6 m/s, q: 1.4e-5 m/s), so the differences spanned up to a half-turn of the
  // direction: J's largest eigenvalue was 3.0e5 /s
  // where the bounded differences give 1.5e6 /s (the direction's relaxation rate, ~mu F_n |W|
  // / |s|), and the steps, whose error estimate is built on J, fell from 1.3e-4 s to 2e-9 s
  // (a stall; likewise on leine_glocker_twin_coupled). With the bound: 3e-7 s there, growing
  // with the slip. Bulirsch-Stoer and dopri5 do not use J and are unaffected.
  static void fill_jacobian(const System& sys, const SmoothScale& smooth, const StateVector& x0, double t, UMatrix& J) {
    static constexpr size_t kGroups[5] = {0, 3, 6, 10, kN};
    const double eps = std::numeric_limits<double>::epsilon();
    const double cbrt_eps = std::cbrt(eps);
    StateVector bound;
    bound.fill(std::numeric_limits<double>::infinity());
    if (smooth) smooth(x0, bound);
    for (int grp = 0; grp < 4; ++grp) {
      double norm = 0.0;
      for (size_t i = kGroups[grp]; i < kGroups[grp + 1]; ++i) norm += x0[i] * x0[i];
      norm = std::sqrt(norm);
      for (size_t j = kGroups[grp]; j < kGroups[grp + 1]; ++j) {
        // The bound no finer than a few ulp of the component: the step must be representable.
        const double own = std::max({std::abs(x0[j]), norm, norm > 0 ? 0.0 : 1.0});
        const double scale = std::max(std::min(own, bound[j]), 4 * eps * std::abs(x0[j]) / cbrt_eps);
        StateVector xp = x0, xm = x0, fp, fm;
        xp[j] = x0[j] + cbrt_eps * scale;
        const double h = xp[j] - x0[j];  // the step as represented
        xm[j] = x0[j] - h;
        sys(xp, fp, t);
        sys(xm, fm, t);
        for (size_t i = 0; i < kN; ++i) J(i, j) = (fp[i] - fm[i]) / (2 * h);
      }
    }
  }
  static void to_ublas(const StateVector& y, UVector& u) {
    for (size_t i = 0; i < kN; ++i) u[i] = y[i];
  }
  static void from_ublas(const UVector& u, StateVector& y) {
    for (size_t i = 0; i < kN; ++i) y[i] = u[i];
  }
  Stepper stepper_;
  UVector u_;  // scratch for calc_state and initialize
  UMatrix jac_;
  SmoothScale smooth_;
  StateVector y_{};
};

}  // namespace

std::unique_ptr<DenseStepper> make_stepper(const RunSpec& run, SmoothScale scale) {
  const double max_dt = run.duration / 64.0;
  if (run.method == "rosenbrock4") return std::make_unique<RosenbrockStepper>(run.atol, run.rtol, max_dt, std::move(scale));
  if (run.method == "dopri5") {
    auto s = odeint::make_dense_output(run.atol, run.rtol, max_dt, Dopri());
    return std::make_unique<DenseStepperOf<decltype(s)>>(std::move(s));
  }
  // Gragg-Bulirsch-Stoer extrapolation: high and adaptive order, so few, long steps at the
  // tight tolerances a reference needs; its dense output is a Hermite polynomial of high order.
  odeint::bulirsch_stoer_dense_out<StateVector> s(run.atol, run.rtol, 1.0, 1.0, max_dt);
  return std::make_unique<DenseStepperOf<decltype(s)>>(std::move(s));
}

}  // namespace reference_detail
}  // namespace tippe
