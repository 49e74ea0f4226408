// Running one simulator on a scene into a run record, sample by sample.
#include "harness/measure/run.h"

#include <cmath>
#include <cstddef>
#include <limits>
#include <utility>
#include <vector>

#include "analytic/mass_properties.h"
#include "harness/io/interrupt.h"
#include "harness/io/scene_io.h"
#include "engines/core/timing.h"

namespace tippe {

RunRecord record_of_scene(const Scene& scene) {
  RunRecord r;
  r.provenance = current_provenance();
  r.scene_name = scene.name;
  r.scene_file = scene.source_file;
  r.scene_hash = scene.content_hash;
  r.scene_spec = scene_to_json(scene);
  r.mass = scene.mass;
  r.inversion_possible = inversion_possible(scene.mass, scene.body.sphere_radius);
  return r;
}

RunRecord run_simulator(Simulator& sim, const Scene& scene, SampleSink* sink, ProgressFn progress) {
  RunRecord r = record_of_scene(scene);
  r.engine = sim.engine();
  r.engine_version = sim.version();

  const double dt = scene.run.sample_interval, T = scene.run.duration;
  // The tolerance keeps e.g. 8 / 0.001 = 7999.999... from losing its last grid point.
  const long long n = static_cast<long long>(std::floor(T / dt + 1e-9));
  SampleSummary summary;
  double last_t = -std::numeric_limits<double>::infinity();
  size_t events_seen = 0;
  auto emit = [&](const Observation& o) {
    // The list is copied only when it grew: most samples see no new event.
    bool switched = false, inverted = false;
    if (sim.event_count() != events_seen) {
      const std::vector<Event> events = sim.events();
      for (size_t i = events_seen; i < events.size(); ++i) {
        switched = switched || events[i].name == "switch";
        inverted = inverted || events[i].name == "inversion";
      }
      events_seen = events.size();
    }
    if (inverted && !r.ledger_at_inversion && std::isfinite(o.numerical_energy))
      r.ledger_at_inversion = RunRecord::LedgerPoint{o.state.t,       o.energy,        o.normal_work,     o.friction_work,
                                                     o.drilling_work, o.impact_energy, o.numerical_energy};
    summary.add(o, switched);
    if (sink) sink->write(o);
    last_t = o.state.t;
    if (progress) progress(o.state.t, T);
    // Between samples a deferred SIGINT or SIGTERM ends the run (see interrupt.h).
    check_interrupted();
  };
  // The run's clocks: read here and after the loop only (see WorkCounters).
  const SpanTimer timer;
  // Every sample carries the energy ledger at its time (E0: the first sample's energy).
  double e0 = 0.0;
  auto observe = [&](bool first) {
    Observation o = sim.observe();
    if (first) e0 = o.energy;
    fill_ledger(o, sim.energy_ledger(), e0);
    return o;
  };
  emit(observe(true));
  for (long long k = 1; k <= n && sim.status() == RunStatus::Ok; ++k) {
    double t = static_cast<double>(k) * dt;
    if (k == n && std::abs(t - T) <= 1e-9 * dt) t = T;
    sim.advance_to(t);
    const Observation o = observe(false);
    // A simulator that stopped may report the state it stopped at, which can repeat the last sample.
    if (sim.status() == RunStatus::Ok || o.state.t > last_t) emit(o);
  }
  double wall = 0, cpu = 0;
  timer.stop(wall, cpu);
  summary.fill(r);

  r.status = to_string(sim.status());
  r.status_time = sim.status_time();
  r.status_detail = sim.status_detail();
  r.events = sim.events();
  r.settings = sim.settings();
  r.notes = sim.notes();
  r.work = sim.work();
  r.friction_work = sim.friction_work();
  r.work.wall_seconds = wall;
  r.work.cpu_seconds = cpu;
  for (const Event& e : r.events) {
    if (e.name == "inversion" && !r.inversion_time) r.inversion_time = e.time;
    if (e.name == "stem_contact" && !r.stem_contact_time) r.stem_contact_time = e.time;
  }
  return r;
}

RunRecord run_scene(const Scene& scene, const std::string& engine, SampleSink* sink, ProgressFn progress) {
  auto sim = make_simulator(engine, scene);
  return run_simulator(*sim, scene, sink, std::move(progress));
}

}  // namespace tippe
