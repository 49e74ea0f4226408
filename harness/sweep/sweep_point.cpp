// One point of a sweep: the engine's run(s) at the point's settings, compared with the scene's reference into a record.
#include "harness/sweep/sweep_detail.h"

#include <cmath>
#include <exception>
#include <limits>
#include <memory>

#include "engines/core/registry.h"
#include "harness/io/interrupt.h"
#include "harness/io/text.h"
#include "harness/io/provenance.h"
#include "harness/measure/classify.h"
#include "harness/records/records.h"
#include "harness/measure/run.h"

namespace tippe::sweep_detail {

using nlohmann::json;

namespace {

json settings_object(const SettingsList& s) {
  json o = json::object();
  for (const auto& [k, v] : s) o[k] = v;
  return o;
}

}  // namespace

// Runs one point `repeats` times on the calling thread; errors come from the first run (the
// runs are deterministic), the CPU time is the minimum, so that a busy machine inflates it least.
SweepRecord run_point(const SweepPlan& plan, const SweepPoint& p, const Reference& ref) {
  const SweepSetup& setup = plan.spec.setups[p.setup_index];
  SweepRecord r;
  r.point_id = p.id;
  r.scene = p.scene.name;
  r.scene_file = plan.spec.scenes[p.scene_index].file;
  r.physics_hash = plan.physics_hashes[p.scene_index];
  r.scene_index = static_cast<long long>(p.scene_index);
  r.setup = setup.name;
  r.engine = setup.engine;
  r.set = setup.set;
  r.ladder_key = setup.ladder_key;
  r.ladder_value = p.ladder_value;
  r.ladder_label = p.ladder_label;
  r.search = setup.search;
  r.setup_index = static_cast<long long>(p.setup_index);
  r.ladder_index = static_cast<long long>(p.ladder_index);
  if (setup.has_grid()) {
    r.grid_key = setup.grid_key;
    r.grid_value = setup.grid_values[p.grid_index];
    r.grid_label = setup.grid_labels[p.grid_index];
    r.grid_index = static_cast<long long>(p.grid_index);
  }
  r.repeats = plan.spec.repeats;
  r.duration = p.scene.run.duration;
  r.reference_inversion_time = ref.record.inversion_time;
  r.reference_stem_contact_time = ref.record.stem_contact_time;
  r.git_commit = build_info().git_commit;
  if (!ref.failure.empty()) return reference_failed_record(std::move(r), p.scene, ref);

  RunRecord first;
  TrajectorySink sink;
  double cpu_min = std::numeric_limits<double>::infinity(), wall_min = cpu_min;
  for (int k = 0; k < plan.spec.repeats; ++k) {
    RunRecord run;
    std::unique_ptr<Simulator> sim;
    try {
      sim = make_simulator(setup.engine, p.scene);
      run = run_simulator(*sim, p.scene, k == 0 ? &sink : nullptr);
    } catch (const Interrupted&) {
      throw;  // a signal is not a result of the point
    } catch (...) {
      // An engine that refuses the scene or throws mid-run is a failed point, not a failed sweep.
      run = RunRecord{};
      run.engine = setup.engine;
      run.status = to_string(RunStatus::Failed);
      run.status_time = sink.trajectory.size() ? sink.trajectory.t.back() : 0.0;
      run.status_detail = "exception: " + exception_text(std::current_exception());
      if (sim) {
        run.engine_version = sim->version();
        run.settings = sim->settings();
        run.work = sim->work();
      }
      if (k == 0) first = run;
      break;
    }
    cpu_min = std::min(cpu_min, run.work.cpu_seconds);
    wall_min = std::min(wall_min, run.work.wall_seconds);
    r.cpu_seconds_repeats.push_back(run.work.cpu_seconds);
    if (k == 0) first = std::move(run);
  }
  if (r.cpu_seconds_repeats.empty()) {
    cpu_min = first.work.cpu_seconds;
    wall_min = first.work.wall_seconds;
    r.cpu_seconds_repeats.push_back(cpu_min);
  }

  r.status = first.status;
  r.status_time = first.status_time;
  r.status_detail = first.status_detail;
  r.inversion_time = first.inversion_time;
  r.stem_contact_time = first.stem_contact_time;
  // Against the reference only as far as its self-check says it is converged (as a comparison does).
  r.metrics = compare_runs(ref.record, ref.trajectory, first, sink.trajectory, p.scene,
                           ref.self_check ? ref.self_check->converged_until : std::nullopt);
  r.cpu_seconds = cpu_min;
  r.wall_seconds = wall_min;
  r.metrics.cpu_seconds = cpu_min;
  r.metrics.wall_seconds = wall_min;
  r.metrics.cost_ratio = ref.record.work.cpu_seconds > 0 ? cpu_min / ref.record.work.cpu_seconds : 0.0;
  r.metrics.real_time_factor = wall_min > 0 && std::isfinite(first.final_time) ? first.final_time / wall_min : 0.0;
  r.steps = first.work.steps;
  r.rhs_evaluations = first.work.rhs_evaluations;
  r.solver_iterations = first.work.solver_iterations;
  r.engine_version = first.engine_version.empty() ? "unknown" : first.engine_version;
  r.settings = settings_object(first.settings);
  const RunClass c = classify_run(p.scene, first, &r.metrics, sink.trajectory);
  r.run_class = to_string(c.kind);
  r.class_time = c.time;
  r.class_reason = c.reason;
  r.reference = ref.summary;
  return r;
}

// A priori cost of a point in arbitrary units: steps for a time-step ladder; per setup, the
// progress line scales it by the seconds per unit measured on that setup's finished points.
double point_weight(const SweepPlan& plan, const SweepPoint& p) {
  const SweepSetup& s = plan.spec.setups[p.setup_index];
  const auto is_step = [](const std::string& k) {
    return k.size() >= 8 && k.compare(k.size() - 8, 8, "timestep") == 0;
  };
  // The time step may be either axis of a grid.
  double v = is_step(s.ladder_key) ? p.ladder_value : std::nan("");
  if (s.has_grid() && is_step(s.grid_key)) v = s.grid_values[p.grid_index];
  const double per_time = v > 0 ? 1.0 / v : (s.engine == reference_engine().name ? 100.0 : 1e4);
  return plan.spec.repeats * p.scene.run.duration * per_time;
}

}  // namespace tippe::sweep_detail
