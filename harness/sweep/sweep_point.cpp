// One point of a sweep: the engine's run(s) at the point's settings, compared with the scene's reference into a record.
#include "harness/sweep/sweep_detail.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
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

// The point's first run (the runs are deterministic: its status, metrics and class are every
// repeat's); its times are this run's until set_repeat_times folds in the later repeats'.
FirstRun run_point_first(const SweepPlan& plan, const SweepPoint& p, const Reference& ref) {
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
  FirstRun out;
  if (!ref.failure.empty()) {
    out.record = reference_failed_record(std::move(r), p.scene, ref);
    out.timed = false;
    return out;
  }

  RunRecord first;
  TrajectorySink sink;
  std::unique_ptr<Simulator> sim;
  try {
    sim = make_simulator(setup.engine, p.scene);
    first = run_simulator(*sim, p.scene, &sink);
  } catch (const Interrupted&) {
    throw;  // a signal is not a result of the point
  } catch (...) {
    // An engine that refuses the scene or throws mid-run is a failed point, not a failed sweep.
    first = RunRecord{};
    first.engine = setup.engine;
    first.status = to_string(RunStatus::Failed);
    first.status_time = sink.trajectory.size() ? sink.trajectory.t.back() : 0.0;
    first.status_detail = "exception: " + exception_text(std::current_exception());
    if (sim) {
      first.engine_version = sim->version();
      first.settings = sim->settings();
      first.work = sim->work();
    }
  }

  r.status = first.status;
  r.status_time = first.status_time;
  r.status_detail = first.status_detail;
  r.inversion_time = first.inversion_time;
  r.stem_contact_time = first.stem_contact_time;
  // Against the reference only as far as its self-check says it is converged (as a comparison does).
  r.metrics = compare_runs(ref.record, ref.trajectory, first, sink.trajectory, p.scene,
                           ref.self_check ? ref.self_check->converged_until : std::nullopt);
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
  out.final_time = first.final_time;
  out.reference_cpu = ref.record.work.cpu_seconds;
  out.record = std::move(r);
  set_repeat_times(out, {RepeatTime{first.work.cpu_seconds, first.work.wall_seconds}});
  return out;
}

std::optional<RepeatTime> time_point(const SweepPlan& plan, const SweepPoint& p, const Reference& ref) {
  if (!ref.failure.empty()) return std::nullopt;
  try {
    const std::unique_ptr<Simulator> sim = make_simulator(plan.spec.setups[p.setup_index].engine, p.scene);
    const RunRecord run = run_simulator(*sim, p.scene, nullptr);
    return RepeatTime{run.work.cpu_seconds, run.work.wall_seconds};
  } catch (const Interrupted&) {
    throw;
  } catch (...) {
    return std::nullopt;  // as its first run did (deterministic): that run's record says why
  }
}

// The CPU time is the minimum over the repeats, so that a busy machine inflates it least.
void set_repeat_times(FirstRun& f, const std::vector<RepeatTime>& times) {
  if (!f.timed || times.empty()) return;
  SweepRecord& r = f.record;
  double cpu_min = std::numeric_limits<double>::infinity(), wall_min = cpu_min;
  r.cpu_seconds_repeats.clear();
  for (const RepeatTime& t : times) {
    cpu_min = std::min(cpu_min, t.cpu);
    wall_min = std::min(wall_min, t.wall);
    r.cpu_seconds_repeats.push_back(t.cpu);
  }
  r.cpu_seconds = cpu_min;
  r.wall_seconds = wall_min;
  r.metrics.cpu_seconds = cpu_min;
  r.metrics.wall_seconds = wall_min;
  r.metrics.cost_ratio = f.reference_cpu > 0 ? cpu_min / f.reference_cpu : 0.0;
  r.metrics.real_time_factor = wall_min > 0 && std::isfinite(f.final_time) ? f.final_time / wall_min : 0.0;
}

std::string first_run_text(const FirstRun& f) {
  char buf[3][32];
  std::snprintf(buf[0], sizeof buf[0], "%.17g", f.final_time);
  std::snprintf(buf[1], sizeof buf[1], "%.17g", f.reference_cpu);
  std::snprintf(buf[2], sizeof buf[2], "%d", f.timed ? 1 : 0);
  return pack_texts({to_jsonl(f.record), buf[0], buf[1], buf[2]});
}

FirstRun read_first_run_text(const std::string& text) {
  size_t pos = 0;
  const std::vector<std::string> t = unpack_texts(text, pos, 4);
  FirstRun f;
  f.record = sweep_record_from_json(json::parse(t[0]));
  f.final_time = std::strtod(t[1].c_str(), nullptr);
  f.reference_cpu = std::strtod(t[2].c_str(), nullptr);
  f.timed = t[3] == "1";
  return f;
}

std::string repeat_time_text(const std::optional<RepeatTime>& t) {
  if (!t) return "-";
  char buf[80];
  std::snprintf(buf, sizeof buf, "%.17g %.17g", t->cpu, t->wall);
  return buf;
}

std::optional<RepeatTime> read_repeat_time_text(const std::string& text) {
  if (text == "-") return std::nullopt;
  RepeatTime t;
  char* end = nullptr;
  t.cpu = std::strtod(text.c_str(), &end);
  t.wall = std::strtod(end, nullptr);
  return t;
}

std::vector<SweepTask> repeat_schedule(size_t points, int repeats, size_t block) {
  std::vector<SweepTask> tasks;
  tasks.reserve(points * static_cast<size_t>(std::max(repeats, 1)));
  block = std::max<size_t>(block, 1);
  for (size_t b = 0; b < points; b += block)
    for (int round = 0; round < std::max(repeats, 1); ++round)
      for (size_t j = b; j < std::min(points, b + block); ++j) tasks.push_back(SweepTask{j, round});
  return tasks;
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
