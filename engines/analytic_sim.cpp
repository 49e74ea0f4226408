// The analytic reference behind the common simulator interface.
#include <boost/version.hpp>
#include <sstream>

#include "../analytic/reference_model.h"
#include "adapters.h"
#include "settings.h"
#include "timing.h"

namespace tippe {

namespace {

std::string num(double v) { return round_trip_text(v); }

class AnalyticSimulator final : public Simulator {
 public:
  explicit AnalyticSimulator(const Scene& scene) : scene_(scene), model_(scene) {}

  std::string engine() const override { return "analytic"; }
  std::string version() const override {
    return "reference (Boost.Odeint " + std::to_string(BOOST_VERSION / 100000) + "." +
           std::to_string(BOOST_VERSION / 100 % 1000) + ")";
  }
  void advance_to(double t) override {
    WorkTimer timer(work_.wall_seconds, work_.cpu_seconds);
    model_.advance_to(t);
  }
  Observation observe() const override {
    const BodyModel& b = model_.body();
    Observation o = observe_kinematics(b, model_.state());
    const Surface s = model_.contact_surface();
    if (s == Surface::None) return o;
    const ContactForces f = model_.forces();
    o.surface = s;
    o.normal_force = f.normal[0] + f.normal[1];
    const Surface primary = s == Surface::Stem ? Surface::Stem : Surface::Ball;
    const int slot = primary == Surface::Stem ? 1 : 0;
    o.p_WC = o.state.p_WG + contact_offset_W(b, o.state.q_WB, primary);
    o.engine_contact_valid = true;
    o.p_WC_engine = o.p_WC;
    o.slip_speed = f.slip_W[slot].norm();
    o.jellett = jellett(b, o.state, primary);
    return o;
  }
  WorkCounters work() const override {
    WorkCounters w = work_;
    w.steps = model_.steps();
    w.rhs_evaluations = model_.rhs_evaluations();
    return w;
  }
  RunStatus status() const override {
    switch (model_.status()) {
      case ReferenceStatus::Ok: return RunStatus::Ok;
      case ReferenceStatus::ContactLost: return RunStatus::ContactLost;
      case ReferenceStatus::Failed: return RunStatus::Failed;
    }
    return RunStatus::Failed;
  }
  double status_time() const override { return model_.status_time(); }
  std::string status_detail() const override { return model_.status_detail(); }
  std::vector<Event> events() const override {
    std::vector<Event> out;
    for (const auto& e : model_.events()) out.push_back({e.name, e.time, e.detail, e.value});
    return out;
  }
  SettingsList settings() const override {
    return {{"method", scene_.run.method},
            {"rtol", num(scene_.run.rtol)},
            {"atol", num(scene_.run.atol)},
            {"event_location", "TOMS 748 on dense output"}};
  }

 private:
  Scene scene_;
  ReferenceModel model_;
  WorkCounters work_;
};

}  // namespace

std::unique_ptr<Simulator> make_analytic_simulator(const Scene& scene) {
  return std::make_unique<AnalyticSimulator>(scene);
}

}  // namespace tippe
