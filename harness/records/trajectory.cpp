// A run's sampled trajectory in memory: filled from observations or from a trajectory.csv.
#include "harness/records/trajectory.h"

#include <cmath>
#include <filesystem>
#include <nlohmann/json.hpp>

namespace tippe {

namespace fs = std::filesystem;
using nlohmann::json;

Trajectory Trajectory::from_csv(const CsvTrajectory& csv) {
  Trajectory tr;
  tr.t = csv.column("t");
  tr.theta = csv.column("theta");
  tr.energy = csv.column("energy");
  tr.jellett = csv.column("jellett");
  tr.normal_force = csv.column("normal_force");
  tr.slip_speed = csv.column("slip_speed");
  tr.contact_latitude = csv.column("contact_latitude");
  tr.x_C = csv.column("x_C");
  tr.y_C = csv.column("y_C");
  tr.x_G = csv.column("x_G");
  tr.y_G = csv.column("y_G");
  tr.surface = csv.surface;
  auto optional_column = [&](const char* name) {
    return csv.values.count(name) ? csv.column(name) : std::vector<double>(tr.t.size(), std::nan(""));
  };
  tr.normal_work = optional_column("normal_work");
  tr.friction_work = optional_column("friction_work");
  tr.drilling_work = optional_column("drilling_work");
  tr.impact_energy = optional_column("impact_energy");
  tr.elastic_energy = optional_column("elastic_energy");
  tr.numerical_energy = optional_column("numerical_energy");
  return tr;
}

void Trajectory::append(const Observation& o) {
  t.push_back(o.state.t);
  theta.push_back(o.theta);
  energy.push_back(o.energy);
  jellett.push_back(o.jellett);
  normal_force.push_back(o.normal_force);
  slip_speed.push_back(o.slip_speed);
  contact_latitude.push_back(o.contact_latitude);
  x_C.push_back(o.p_WC.x());
  y_C.push_back(o.p_WC.y());
  x_G.push_back(o.state.p_WG.x());
  y_G.push_back(o.state.p_WG.y());
  surface.push_back(static_cast<int>(o.surface));
  normal_work.push_back(o.normal_work);
  friction_work.push_back(o.friction_work);
  drilling_work.push_back(o.drilling_work);
  impact_energy.push_back(o.impact_energy);
  elastic_energy.push_back(o.elastic_energy);
  numerical_energy.push_back(o.numerical_energy);
}

void TrajectorySink::write(const Observation& o) {
  trajectory.append(o);
  for (SampleSink* s : next_) s->write(o);
}

}  // namespace tippe
