// The analytic reference behind the common simulator interface.
#include <boost/version.hpp>
#include <sstream>

#include "analytic/reference_model.h"
#include "engines/core/adapters.h"
#include "engines/core/registry.h"
#include "engines/core/settings.h"
#include "engines/core/step_checks.h"

namespace tippe {

void adopt_reference_settings(Scene& scene);

namespace {

// The reference's settings, [engines.analytic]; the scene's [run] keys of the same names are
// their older spelling and still read (scene.run holds the values either way). Defaults are
// RunSpec's.
struct AnalyticSettings {
  std::string method = RunSpec{}.method;
  double rtol = RunSpec{}.rtol;
  double atol = RunSpec{}.atol;
  bool self_check = RunSpec{}.self_check;

  template <class V>
  void visit(V& v) {
    v("method", method, {"bulirsch_stoer", "dopri5", "rosenbrock4"});
    // The bounds of run.rtol and run.atol (harness/io/scene_io.cpp).
    v("rtol", rtol, 1e-15, 1e-2);
    v("atol", atol, 1e-300, 1.0);
    v("self_check", self_check);
  }
};

Scene adopted(Scene scene) {
  adopt_reference_settings(scene);
  return scene;
}

std::string reference_version() {
  return "reference (Boost.Odeint " + std::to_string(BOOST_VERSION / 100000) + "." +
         std::to_string(BOOST_VERSION / 100 % 1000) + ")";
}

std::string num(double v) { return round_trip_text(v); }

class AnalyticSimulator final : public Simulator {
 public:
  explicit AnalyticSimulator(const Scene& scene) : scene_(adopted(scene)), model_(std::make_unique<ReferenceModel>(scene_)) {}

  std::string engine() const override { return "analytic"; }
  std::string version() const override { return reference_version(); }
  void advance_to(double t) override { model_->advance_to(t); }
  Observation observe() const override {
    const BodyModel& b = model_->body();
    // The slip speed comes from the contact forces below, off the floor from the kinematics.
    Observation o = observe_kinematics(b, model_->state(), /*slip=*/false);
    const Surface s = model_->contact_surface();
    if (s == Surface::None) {
      o.slip_speed = contact_slip_speed(b, o.state, o.surface);
      return o;
    }
    const ContactForces f = model_->forces();
    const Surface primary = s == Surface::Stem ? Surface::Stem : Surface::Ball;
    const int slot = primary == Surface::Stem ? 1 : 0;
    // observe_kinematics took the contact point and J on the lower surface: the same calls
    // when that is the touching one (always for a body without a stem), so kept.
    if (o.surface != primary) {
      o.p_WC = o.state.p_WG + contact_offset_W(b, o.state.q_WB, primary);
      o.jellett = jellett(b, o.state, primary);
    }
    o.surface = s;
    o.normal_force = f.normal[0] + f.normal[1];
    o.engine_contact_valid = true;
    o.p_WC_engine = o.p_WC;
    o.slip_speed = f.slip_W[slot].norm();
    return o;
  }
  WorkCounters work() const override {
    WorkCounters w;
    w.steps = earlier_steps_ + model_->steps();
    w.rhs_evaluations = earlier_rhs_ + model_->rhs_evaluations();
    return w;
  }
  BodyState state() const override { return model_->state(); }
  void set_state(const BodyState& x) override {
    check_settable_state("analytic", x);
    // The reference restarts its integration from x at the current time (a new initial value
    // problem); the events found so far are kept.
    BodyState y = x;
    y.t = model_->time();
    y.q_WB.normalize();
    for (const auto& e : model_->events()) earlier_events_.push_back({e.name, e.time, e.detail, e.value});
    earlier_ledger_ = energy_ledger();
    earlier_steps_ += model_->steps();
    earlier_rhs_ += model_->rhs_evaluations();
    model_ = std::make_unique<ReferenceModel>(scene_, y);
  }
  MassReadback mass_properties() const override {
    // The body the reference integrates with: principal frame at G by construction.
    const BodyModel& b = model_->body();
    MassReadback mp;
    mp.mass = b.M;
    mp.I_G_B = Vec3(b.A, b.A, b.C).asDiagonal();
    return mp;
  }
  RunStatus status() const override {
    switch (model_->status()) {
      case ReferenceStatus::Ok: return RunStatus::Ok;
      case ReferenceStatus::ContactLost: return RunStatus::ContactLost;
      case ReferenceStatus::Failed: return RunStatus::Failed;
    }
    return RunStatus::Failed;
  }
  double status_time() const override { return model_->status_time(); }
  std::string status_detail() const override { return model_->status_detail(); }
  std::vector<Event> events() const override {
    std::vector<Event> out = earlier_events_;
    for (const auto& e : model_->events()) out.push_back({e.name, e.time, e.detail, e.value});
    return out;
  }
  size_t event_count() const override { return earlier_events_.size() + model_->events().size(); }
  // The reference's own ledger: its contact work split into the normal force's (the drift of a
  // held contact), the tangential force's and the drilling torque's; impacts, Zeno holds and
  // two-contact projections remove energy at events; a rigid contact stores none. Its drift
  // correction is left to the numerical remainder.
  EnergyLedgerTotals energy_ledger() const override {
    const EnergyLedger l = model_->energy_ledger();
    EnergyLedgerTotals t = earlier_ledger_;
    t.normal_work -= l.normal;
    t.friction_work -= l.tangential;
    t.drilling_work -= l.drilling;
    t.impact_energy += l.impacts + l.holds + l.projections;
    t.elastic_energy = 0.0;
    return t;
  }
  double friction_work() const override { return energy_ledger().friction_work; }
  std::vector<std::string> notes() const override {
    if (scene_.run.alias_keys.empty()) return {};
    std::string keys;
    for (const auto& k : scene_.run.alias_keys) keys += (keys.empty() ? "run." : ", run.") + k;
    return {keys + ": older spelling of the reference's settings, read as [engines.analytic] (deprecated; move them there)"};
  }
  SettingsList settings() const override {
    return {{"method", scene_.run.method},
            {"rtol", num(scene_.run.rtol)},
            {"atol", num(scene_.run.atol)},
            {"event_location", "TOMS 748 on dense output"}};
  }

 private:
  Scene scene_;
  std::unique_ptr<ReferenceModel> model_;
  std::vector<Event> earlier_events_;  // of the runs before the last set_state
  long long earlier_steps_ = 0, earlier_rhs_ = 0;
  EnergyLedgerTotals earlier_ledger_{0.0, 0.0, 0.0, 0.0, 0.0};  // of the runs before the last set_state
};

}  // namespace

std::unique_ptr<Simulator> make_analytic_simulator(const Scene& scene) {
  return std::make_unique<AnalyticSimulator>(scene);
}

void adopt_reference_settings(Scene& scene) {
  auto it = scene.engines.find("analytic");
  if (it == scene.engines.end()) return;
  // Starting from the [run] values, so that a key missing from [engines.analytic] keeps them.
  AnalyticSettings s;
  s.method = scene.run.method;
  s.rtol = scene.run.rtol;
  s.atol = scene.run.atol;
  s.self_check = scene.run.self_check;
  // A key in both places would leave one silently unused (a sweep laddering run.rtol over a
  // scene with [engines.analytic] rtol would run one tolerance only): refused.
  for (const std::string& k : scene.run.alias_keys)
    if (it->second.count(k))
      throw std::invalid_argument("engines.analytic." + k + ": also given as run." + k +
                                  " (its older spelling); give it once, in [engines.analytic]");
  SettingsReader r("analytic", it->second);
  s.visit(r);
  r.finish();
  scene.run.method = s.method;
  scene.run.rtol = s.rtol;
  scene.run.atol = s.atol;
  scene.run.self_check = s.self_check;
}

const EngineInfo& analytic_engine_info() {
  static const EngineInfo info = [] {
    // Okabe-Ito reddish purple (the plot colours are the colour-blind-safe palette's)
    EngineInfo e = engine_entry<AnalyticSettings>("analytic", EngineRole::Reference, make_analytic_simulator,
                                                  reference_version(), "#CC79A7");
    e.adopt = adopt_reference_settings;
    return e;
  }();
  return info;
}

}  // namespace tippe
