// Side-by-side runs of the reference and engines on one scene: each on its worker, the reference cached and self-checked.
#include "harness/measure/compare.h"

#include <algorithm>
#include <array>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <exception>
#include <functional>
#include <filesystem>
#include <fstream>
#include <limits>
#include <memory>
#include <mutex>
#include <set>
#include <sstream>
#include <stdexcept>
#include <unistd.h>

#include "engines/core/adapters.h"
#include "harness/io/interrupt.h"
#include "harness/io/text.h"
#include "harness/io/progress.h"
#include "harness/io/provenance.h"
#include "harness/io/scene_io.h"
#include "harness/measure/task_farm.h"
#include "harness/measure/run.h"

namespace tippe {

namespace fs = std::filesystem;
using nlohmann::json;

namespace {


// Passes samples on to `inner`; remembers the first failure instead of losing it in the
// simulator's stack. `fatal` rethrows (the run is pointless without this output); otherwise the
// sink just stops forwarding (an optional copy, such as the cache).
class GuardedSink : public SampleSink {
 public:
  GuardedSink(SampleSink* inner, bool fatal) : inner_(inner), fatal_(fatal) {}
  void write(const Observation& o) override {
    if (error || !inner_) return;
    try {
      inner_->write(o);
    } catch (...) {
      error = std::current_exception();
      if (fatal_) throw;
    }
  }
  std::exception_ptr error;

 private:
  SampleSink* inner_;
  bool fatal_;
};

// What a run leaves when its simulator could not be built or threw: a record that says so.
RunRecord failed_record(const Scene& scene, const std::string& engine, const std::string& why,
                        const Trajectory& tr) {
  RunRecord r = record_of_scene(scene);
  r.engine = engine;
  r.engine_version = "unknown";
  r.status = to_string(RunStatus::Failed);
  r.status_time = tr.size() ? tr.t.back() : 0.0;
  r.status_detail = why;
  r.samples = static_cast<long long>(tr.size());
  r.final_time = tr.size() ? tr.t.back() : kNaN;
  r.final_tilt = tr.size() ? tr.theta.back() : kNaN;
  r.energy_initial = tr.size() ? tr.energy.front() : kNaN;
  r.energy_final = tr.size() ? tr.energy.back() : kNaN;
  r.jellett_initial = tr.size() ? tr.jellett.front() : kNaN;
  r.jellett_max_relative_drift = kNaN;
  r.min_normal_force = tr.size() ? *std::min_element(tr.normal_force.begin(), tr.normal_force.end()) : kNaN;
  return r;
}

// One line on stderr for all runs, redrawn in place.
class ProgressBoard {
 public:
  enum State { Waiting, Running, Done, Cached, Stopped };
  ProgressBoard(std::string scene, std::vector<std::string> names, double duration)
      : scene_(std::move(scene)), names_(std::move(names)), duration_(duration), t_(names_.size()),
        state_(names_.size()), why_(names_.size()) {
    for (size_t i = 0; i < names_.size(); ++i) {
      t_[i] = 0.0;
      state_[i] = Waiting;
    }
  }
  void set_time(size_t i, double t) { t_[i].store(t, std::memory_order_relaxed); }
  void set_state(size_t i, State s) { state_[i].store(s); }
  // A run that ended other than ok, with its status; the text is written before the state.
  void stopped(size_t i, const std::string& status) {
    why_[i] = status;
    state_[i].store(Stopped);
  }
  // final_line: the last state, ended with a newline. In Lines mode (not a terminal) a line at
  // most every kProgressLineSeconds, and the last; Quiet: nothing.
  void print(bool final_line = false) {
    const ProgressMode mode = progress_mode();
    if (mode == ProgressMode::Quiet) return;
    const auto now = std::chrono::steady_clock::now();
    if (mode == ProgressMode::Lines && !final_line && printed_ &&
        std::chrono::duration<double>(now - last_).count() < kProgressLineSeconds)
      return;
    printed_ = true;
    last_ = now;
    std::string line = "[compare " + scene_ + "]";
    for (size_t i = 0; i < names_.size(); ++i) {
      line += i ? " | " : " ";
      line += names_[i];
      char buf[64];
      switch (state_[i].load()) {
        case Waiting: line += " waiting"; break;
        case Done: line += " done"; break;
        case Cached: line += " cached"; break;
        case Stopped: line += " " + why_[i]; break;
        case Running:
          std::snprintf(buf, sizeof buf, " t=%.2f/%.2f", t_[i].load(std::memory_order_relaxed), duration_);
          line += buf;
          break;
      }
    }
    out_.write(std::move(line), final_line);
  }

 private:
  bool printed_ = false;
  std::chrono::steady_clock::time_point last_;
  std::string scene_;
  std::vector<std::string> names_;
  double duration_;
  std::vector<std::atomic<double>> t_;
  std::vector<std::atomic<int>> state_;
  std::vector<std::string> why_;
  ProgressLine out_{progress_mode() == ProgressMode::Lines};
};

struct Task {
  std::string engine;
  const Scene* scene = nullptr;  // the scene to run when not the comparison's (the self-check)
  std::string csv_path;  // "" = no file
  std::string cache_csv_path;  // reference only: a copy for the cache
  RunRecord record;
  Trajectory trajectory;
  std::function<void(double t, double duration)> progress;  // CompareOptions::on_progress for this run
  std::exception_ptr fatal;  // output failure: the comparison cannot be completed
};

void run_task(Task& task, const Scene& scene, ProgressBoard& board, size_t slot) {
  board.set_state(slot, ProgressBoard::Running);
  std::unique_ptr<Simulator> sim;
  try {
    sim = make_simulator(task.engine, scene);
  } catch (const std::exception& e) {
    // Settings were validated up front: what is left is an engine refusing this scene.
    task.record = failed_record(scene, task.engine, std::string("could not build the simulator: ") + e.what(), {});
    board.stopped(slot, task.record.status);
    return;
  }
  std::unique_ptr<CsvTrajectoryWriter> csv, cache_csv;
  try {
    if (!task.csv_path.empty()) csv = std::make_unique<CsvTrajectoryWriter>(task.csv_path);
  } catch (...) {
    task.fatal = std::current_exception();
    board.stopped(slot, "error");
    return;
  }
  try {
    if (!task.cache_csv_path.empty()) cache_csv = std::make_unique<CsvTrajectoryWriter>(task.cache_csv_path);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "\ntippe: warning: reference cache not written: %s\n", e.what());
    task.cache_csv_path.clear();
  }
  GuardedSink out(csv.get(), true), cache(cache_csv.get(), false);
  TrajectorySink sink({&out, &cache});
  try {
    task.record = run_simulator(*sim, scene, &sink, [&](double t, double duration) {
      board.set_time(slot, t);
      if (task.progress) task.progress(t, duration);
    });
  } catch (const Interrupted&) {
    // A signal ends the comparison, not this run: nothing of it is recorded.
    task.fatal = std::current_exception();
    board.stopped(slot, "interrupted");
    return;
  } catch (...) {
    if (out.error) {
      task.fatal = out.error;
      board.stopped(slot, "error");
      return;
    }
    // An adapter that throws is a failed run, not a failed comparison; its samples so far are kept.
    task.record = failed_record(scene, task.engine, "exception: " + exception_text(std::current_exception()),
                                sink.trajectory);
    task.record.engine_version = sim->version();
    task.record.settings = sim->settings();
    task.record.notes = sim->notes();
  }
  task.trajectory = std::move(sink.trajectory);
  sim.reset();
  try {
    if (csv) csv->commit();
  } catch (...) {
    task.fatal = std::current_exception();
  }
  if (cache_csv && !cache.error) {
    try {
      cache_csv->commit();
    } catch (const std::exception& e) {
      std::fprintf(stderr, "\ntippe: warning: reference cache not written: %s\n", e.what());
      cache.error = std::current_exception();
    }
  }
  if (cache.error) task.cache_csv_path.clear();
  if (task.record.status == "ok")
    board.set_state(slot, ProgressBoard::Done);
  else
    board.stopped(slot, task.record.status);
}


}  // namespace

void check_compare_input(const Scene& scene, const CompareOptions& options) {
  if (options.engines.empty()) throw std::invalid_argument("no engines to compare");
  if (options.jobs < 1) throw std::invalid_argument("jobs must be at least 1, got " + std::to_string(options.jobs));
  const std::vector<std::string> known = available_engines();
  std::set<std::string> seen;
  for (const std::string& e : options.engines) {
    if (std::find(known.begin(), known.end(), e) == known.end()) {
      std::string list;
      for (const auto& k : known) list += (list.empty() ? "" : ", ") + k;
      throw std::invalid_argument("unknown engine \"" + e + "\" (expected one of: " + list + ")");
    }
    if (!seen.insert(e).second) throw std::invalid_argument("engine \"" + e + "\" listed twice");
  }
  validate_engine_settings(scene);
}

Comparison run_comparison(const Scene& scene, const CompareOptions& options) {
  // Every check on the input comes before the first file is written.
  check_compare_input(scene, options);

  Comparison c;
  c.scene = scene_to_json(scene);
  c.provenance = current_provenance();
  const std::string hash = physics_hash(c.scene);
  const fs::path out = options.out_dir;
  if (!out.empty()) fs::create_directories(out);

  std::vector<Task> tasks(options.engines.size() + 1);
  tasks.reserve(tasks.size() + 1);  // room for the self-check: `ref` stays valid
  Task& ref = tasks[0];
  ref.engine = reference_engine().name;
  if (!out.empty()) ref.csv_path = (out / "reference.csv").string();
  fs::path cache_dir;
  if (!options.cache_dir.empty()) {
    cache_dir = fs::path(options.cache_dir) / hash;
    c.reference_cached = load_cached_reference(cache_dir, scene, hash, ref.record, ref.trajectory);
    if (c.reference_cached && !out.empty()) copy_file_atomic((cache_dir / "trajectory.csv").string(), ref.csv_path);
    if (!c.reference_cached) {
      std::error_code ec;
      fs::create_directories(cache_dir, ec);
      if (ec)
        std::fprintf(stderr, "tippe: warning: reference cache %s not usable: %s\n", cache_dir.string().c_str(),
                     ec.message().c_str());
      else
        ref.cache_csv_path = (cache_dir / "trajectory.csv").string();
    }
  }
  for (size_t i = 0; i < options.engines.size(); ++i) {
    tasks[i + 1].engine = options.engines[i];
    if (!out.empty()) tasks[i + 1].csv_path = (out / (options.engines[i] + ".csv")).string();
  }

  // The self-check: from the cache beside a cached reference, else a second reference run in
  // parallel with the engines (it needs nothing from the first until both are done).
  Scene check_scene = scene;
  const SelfCheckMethod plan = self_check_method(scene.run);
  check_scene.run.method = plan.method;
  check_scene.run.rtol = plan.rtol;
  check_scene.run.atol = plan.atol;
  size_t check_slot = 0;  // 0: no self-check run
  if (scene.run.self_check) {
    if (c.reference_cached) {
      if (auto cached = load_cached_self_check(cache_dir, hash, ref.record, plan)) {
        c.self_check = *cached;
        c.self_check_cached = true;
      }
    }
    if (!c.self_check) {
      check_slot = tasks.size();
      tasks.emplace_back();
      tasks.back().engine = reference_engine().name;
      tasks.back().scene = &check_scene;
    }
  }

  std::vector<std::string> names;
  for (size_t i = 0; i < tasks.size(); ++i) names.push_back(i && i == check_slot ? "self-check" : tasks[i].engine);
  if (options.on_progress)
    for (size_t i = 0; i < tasks.size(); ++i)
      tasks[i].progress = [&options, name = i == 0 ? std::string("reference") : names[i]](double t, double d) {
        options.on_progress(name, t, d);
      };
  ProgressBoard board(scene.name, names, scene.run.duration);
  std::vector<size_t> todo;
  for (size_t i = 0; i < tasks.size(); ++i) {
    if (i == 0 && c.reference_cached)
      board.set_state(0, ProgressBoard::Cached);
    else
      todo.push_back(i);
  }

  // Each simulator is built, run and destroyed on one worker thread (ODE's per-thread state).
  // run_task keeps a run's exception in its task (t.fatal), so every run is attempted.
  // Five redraws a second is enough to see motion without flooding a CI log.
  std::function<void()> redraw;
  if (options.progress) redraw = [&] { board.print(); };
  parallel_for(
      todo.size(), options.jobs,
      [&](size_t k) {
        Task& t = tasks[todo[k]];
        run_task(t, t.scene ? *t.scene : scene, board, todo[k]);
      },
      redraw);
  if (options.progress) board.print(true);

  for (const Task& t : tasks)
    if (t.fatal) std::rethrow_exception(t.fatal);
  if (ref.record.status == to_string(RunStatus::Failed) && ref.trajectory.size() == 0)
    throw std::runtime_error("reference run failed: " + ref.record.status_detail);

  if (!c.reference_cached && !ref.cache_csv_path.empty() && ref.record.status != to_string(RunStatus::Failed)) {
    // The summary goes last: its presence says the trajectory beside it is complete.
    try {
      write_file_atomic((cache_dir / "summary.json").string(), to_json(ref.record).dump(2) + "\n");
    } catch (const std::exception& e) {
      std::fprintf(stderr, "tippe: warning: reference cache not written: %s\n", e.what());
    }
  }

  if (check_slot) {
    const Task& t = tasks[check_slot];
    c.self_check = compare_reference_runs(ref.record, ref.trajectory, t.record, t.trajectory, scene);
    // Beside a reference that is in the cache (loaded, or just written there).
    if (!cache_dir.empty() && ref.record.status != to_string(RunStatus::Failed) &&
        (c.reference_cached || !ref.cache_csv_path.empty()))
      store_self_check(cache_dir, hash, ref.record, *c.self_check);
  }
  const std::optional<double> converged_until = c.self_check ? c.self_check->converged_until : std::nullopt;

  c.reference = ref.record;
  for (size_t i = 1; i < tasks.size(); ++i) {
    if (i == check_slot) continue;
    Metrics m = compare_runs(ref.record, ref.trajectory, tasks[i].record, tasks[i].trajectory, scene, converged_until);
    c.engines.push_back({std::move(tasks[i].record), m});
  }
  if (options.trajectories) {
    (*options.trajectories)["reference"] = ref.trajectory;
    for (size_t i = 1; i < tasks.size(); ++i)
      if (i != check_slot) (*options.trajectories)[tasks[i].engine] = std::move(tasks[i].trajectory);
  }

  if (!out.empty()) {
    const json j = to_json(c);
    write_file_atomic((out / "comparison.json").string(), j.dump(2) + "\n");
  }
  return c;
}

}  // namespace tippe
