// The comparison tests' fixtures: a scene built in code, trajectories from one function of t per column, and run records with chosen events and costs.
#pragma once

#include <cstddef>
#include <functional>
#include <optional>
#include <string>

#include "analytic/scene.h"
#include "harness/io/scene_io.h"
#include "harness/measure/compare.h"
#include "harness/records/records.h"

namespace tippe::fixtures {

// A scene built in code: R = 2 so that path errors divided by R are told apart from raw ones.
inline Scene test_scene() {
  Scene s;
  s.name = "fixture";
  s.description = "fixture <scene> & \"quotes\"";
  s.source_file = "fixture.toml";
  s.content_hash = "0123456789abcdef";
  s.gravity = 9.81;
  s.body.sphere_radius = 2.0;
  s.body.stem_radius = 0.5;
  s.body.stem_length = 2.4;
  s.body.truncation_height = 1.8;
  s.body.mass_model = MassModel::Given;
  s.mass = {1.0, 0.6, 1.6, 1.8};
  s.contact.friction = FrictionLaw::Viscous;
  s.contact.k = 1.0;
  s.initial.tilt = 0.1;
  s.initial.spin = 5.0;
  s.run.duration = 2.0;
  s.run.sample_interval = 0.01;
  return s;
}

// Samples t_k = k dt, k = 0..n-1, with every column from one function of t.
struct Columns {
  std::function<double(double)> theta = [](double) { return 0.1; };
  std::function<double(double)> energy = [](double) { return 10.0; };
  std::function<double(double)> jellett = [](double) { return -1.5; };
  std::function<double(double)> normal_force = [](double) { return 9.81; };
  std::function<double(double)> x_C = [](double) { return 0.0; };
  std::function<double(double)> y_C = [](double) { return 0.0; };
  std::function<double(double)> x_G = [](double) { return 0.0; };
  std::function<double(double)> y_G = [](double) { return 0.0; };
  std::function<double(double)> latitude = [](double) { return 0.1; };
};

inline Observation observation_at(double t, const Columns& c) {
  Observation o;
  o.state.t = t;
  o.state.p_WG = Vec3(c.x_G(t), c.y_G(t), 1.0);
  o.theta = c.theta(t);
  o.surface = Surface::Ball;
  o.p_WC = Vec3(c.x_C(t), c.y_C(t), 0.0);
  o.normal_force = c.normal_force(t);
  o.energy = c.energy(t);
  o.jellett = c.jellett(t);
  o.contact_latitude = c.latitude(t);
  return o;
}

inline Trajectory make_traj(size_t n, double dt, const Columns& c, double t0 = 0.0) {
  Trajectory tr;
  for (size_t k = 0; k < n; ++k) tr.append(observation_at(t0 + static_cast<double>(k) * dt, c));
  return tr;
}

inline RunRecord make_record(const std::string& engine, std::optional<double> inversion, std::optional<double> stem,
                      double cpu = 1.0) {
  RunRecord r;
  r.scene_name = "fixture";
  r.scene_file = "fixture.toml";
  r.scene_hash = "0123456789abcdef";
  r.scene_spec = scene_to_json(test_scene());
  r.engine = engine;
  r.engine_version = engine + " 1.0";
  r.inversion_time = inversion;
  r.stem_contact_time = stem;
  if (inversion) r.events.push_back({"inversion", *inversion, "theta crosses 90 deg", 0.0});
  if (stem) r.events.push_back({"stem_contact", *stem, "first stem contact", 0.0});
  r.settings = {{"timestep", "0.0001"}, {"note<&>", "value with <tags> & ampersands"}};
  r.work.steps = 1000;
  r.work.cpu_seconds = cpu;
  r.work.wall_seconds = cpu;
  r.samples = 201;
  r.final_time = 2.0;
  r.energy_initial = 10.0;
  r.energy_final = 9.0;
  r.jellett_initial = -1.5;
  r.jellett_max_relative_drift = 1e-6;
  r.jellett_drift_ball = 1e-6;
  r.provenance = current_provenance();
  return r;
}

}  // namespace tippe::fixtures
