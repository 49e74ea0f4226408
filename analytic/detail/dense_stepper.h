// The reference's dense-output integrators (Bulirsch-Stoer, dopri5, Rosenbrock4) behind one interface (internal, not installed).
#pragma once

#include <functional>
#include <memory>
#include <utility>

#include "analytic/contact_dynamics.h"
#include "analytic/scene.h"

namespace tippe {
namespace reference_detail {

using System = std::function<void(const StateVector&, StateVector&, double)>;

// The dense-output steppers behind one interface, so that the method is a run setting.
struct DenseStepper {
  virtual ~DenseStepper() = default;
  virtual void initialize(const StateVector& y, double t, double dt) = 0;
  virtual std::pair<double, double> do_step(const System& sys) = 0;
  virtual void calc_state(double t, StateVector& y) = 0;
  virtual const StateVector& current_state() const = 0;
  virtual double current_time() const = 0;
  virtual double current_time_step() const = 0;
};

// Per state component, the change over which the right-hand side turns by O(1) where that is
// shorter than the component's own size (+inf elsewhere): ContactDynamics::slip_scale for the
// current mode. Only a stepper that differentiates the right-hand side (Rosenbrock4) uses it.
using SmoothScale = std::function<void(const StateVector&, StateVector&)>;

// The stepper of run.method ("bulirsch_stoer", "dopri5" or "rosenbrock4") at run.rtol and
// run.atol, its largest step duration / 64; `scale` bounds Rosenbrock4's Jacobian differences.
std::unique_ptr<DenseStepper> make_stepper(const RunSpec& run, SmoothScale scale = nullptr);

}  // namespace reference_detail
}  // namespace tippe
