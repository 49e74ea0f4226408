// The analytic reference: adaptive Dormand-Prince integration of the contact dynamics with
// events (inversion, touchdown impacts, stick/slip, loss of contact) located on dense output.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "contact_dynamics.h"
#include "scene.h"
#include "state.h"

namespace tippe {

struct ReferenceEvent {
  std::string name;  // inversion, reversion, stem_contact, impact, switch, two_contact, stick,
                     // slip, drill_stick, drill_slip, contact_lost, touchdown, flight
  double time = 0.0;
  std::string detail;
  double value = 0.0;  // impact: energy removed; switch: new surface code
};

enum class ReferenceStatus { Ok, ContactLost, Failed };

class ReferenceModel {
 public:
  explicit ReferenceModel(const Scene& scene);
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
  long long steps() const { return steps_; }
  long long rhs_evaluations() const { return rhs_evals_; }
  const BodyModel& body() const { return body_; }

 private:
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
