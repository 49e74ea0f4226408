// The analytic reference: adaptive Dormand-Prince integration of the contact dynamics with
// events (inversion, touchdown impacts, stick/slip, loss of contact) located on dense output.
#pragma once

#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "analytic/contact_dynamics.h"
#include "analytic/scene.h"
#include "analytic/state.h"

namespace tippe {

struct ReferenceEvent {
  std::string name;  // inversion, reversion, stem_contact, impact, hold, projection, unresolved, switch,
                     // two_contact, graze, lift, press, stick, slip, drill_stick, drill_slip,
                     // contact_lost, touchdown, flight, failed
  double time = 0.0;
  std::string detail;
  double value = 0.0;  // impact, hold, projection: energy removed; switch: new surface code;
                       // unresolved: the highest gap of the excursion
};

// Where the energy E0 - E(t) went, each term integrated or summed by the reference as it runs,
// so that E(t) + total() = E0 up to the integration error.
struct EnergyLedger {
  double friction = 0.0;     // work done against the contact forces: -int sum_s F_s . v_C + tau_s w_z dt
  // Its parts: the normal force (F_z v_C.z, the drift of a held contact), the tangential force
  // and the drilling torque; friction = normal + tangential + drilling.
  double normal = 0.0, tangential = 0.0, drilling = 0.0;
  double impacts = 0.0;      // removed by touchdown impacts (the impact events' values)
  double holds = 0.0;        // removed where a Zeno cascade of impacts is closed (hold events)
  double projections = 0.0;  // removed by the two-contact projection at restarts (projection events)
  double drift = 0.0;        // changed by the one-contact drift correction at restarts (tolerance-sized)
  double total() const { return friction + impacts + holds + projections + drift; }
  // Books work done against the contact forces, per part (normal, tangential, drilling).
  void add_contact_work(const Vec3& against);
};

enum class ReferenceStatus { Ok, ContactLost, Failed };

class ReferenceModel {
 public:
  explicit ReferenceModel(const Scene& scene);
  // Starts from x_start at time x_start.t instead of the scene's initial state (the scene gives
  // body, contact law and run settings): what Simulator::set_state restarts from.
  ReferenceModel(const Scene& scene, const BodyState& x_start);
  ~ReferenceModel();
  ReferenceModel(const ReferenceModel&) = delete;
  ReferenceModel& operator=(const ReferenceModel&) = delete;

  // Integrates to time t (events on the way are located and handled). Stops early when the
  // status leaves Ok; the state then stays at the status time.
  void advance_to(double t);
  double time() const { return t_obs_; }
  BodyState state() const;
  // |q| of the integrated quaternion at the last accepted step, before normalization (the
  // observed state is normalized; dense output between steps interpolates q component-wise).
  double raw_quaternion_norm() const;
  // Contact forces, surface in contact and slip at the current time.
  ContactForces forces() const;
  Surface contact_surface() const;
  const std::vector<ReferenceEvent>& events() const { return events_; }
  ReferenceStatus status() const { return status_; }
  double status_time() const { return status_time_; }
  const std::string& status_detail() const { return status_detail_; }
  // The ledger at the observed time.
  EnergyLedger energy_ledger() const;
  // Smallest and largest graze fraction (as the motion uses it) met while a contact grazed, at
  // every point of the motion the reference evaluated (check points up to an event, event
  // times, restarts); {+inf, -inf} when no contact grazed.
  std::pair<double, double> graze_fraction_range() const;
  // Largest amount, at those points, by which a grazing contact's neighbouring fields were
  // consistent themselves: max(a0, -a1) (gap accelerations of the lifted and the loaded
  // field), 0 while the graze is a true sliding mode. The fraction a0 / (a0 - a1) before
  // clamping leaves [0, 1] exactly where this is > 0.
  double graze_violation() const;
  long long steps() const { return steps_; }
  long long rhs_evaluations() const { return rhs_evals_; }
  const BodyModel& body() const { return body_; }

 private:
  void start(const Scene& scene, const BodyState& x0, bool in_flight);
  struct Impl;
  std::unique_ptr<Impl> impl_;
  BodyModel body_;
  double t_obs_ = 0.0;
  std::vector<ReferenceEvent> events_;
  ReferenceStatus status_ = ReferenceStatus::Ok;
  double status_time_ = 0.0;
  std::string status_detail_;
  long long steps_ = 0, rhs_evals_ = 0;
};

}  // namespace tippe
