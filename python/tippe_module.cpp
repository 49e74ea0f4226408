// The extension `tippe._tippe` (pybind11): each verb of the command line through the harness's one function for it, records as their JSON text, trajectories as numpy arrays; python/tippe/ makes the Python objects.
#include <pybind11/functional.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <algorithm>
#include <csignal>
#include <chrono>
#include <condition_variable>
#include <deque>
#include <exception>
#include <filesystem>
#include <fstream>
#include <memory>
#include <mutex>
#include <optional>
#include <set>
#include <sstream>
#include <string>
#include <thread>

#include "include/tippe/tippe.h"
#include <toml++/toml.h>

#include "harness/advise/advise.h"
#include "harness/advise/advice_record.h"
#include "harness/io/output_dir.h"
#include "harness/io/progress.h"
#include "harness/io/scene_io.h"
#include "harness/scene/resolve.h"
#include "harness/library/verbs.h"
#include "harness/measure/run.h"
#include "harness/records/sweep_record.h"
#include "engines/core/registry.h"
#include "harness/report/report.h"
#include "harness/report/sweep_analysis.h"
#include "analytic/stop_request.h"
#include "harness/sweep/sweep.h"
#include "harness/sweep/sweep_search.h"

namespace py = pybind11;
namespace fs = std::filesystem;

namespace {

// ---- a scene dict as a scene file's TOML ---------------------------------------------------
// A scene dict becomes the TOML document a scene file would be, so that it goes through the same
// reader with the same checks and messages (the label stands for the file).
toml::array to_toml_array(const py::handle& list, const std::string& key);

// The deepest dict a scene may be: a scene file's keys nest 3 deep, and the reader refuses keys of
// more than 64 parts (kMaxTomlKeyParts); deeper would recurse here without bound.
constexpr int kMaxDictDepth = 64;

// The dicts on the way from the root to the one being converted (by identity): a dict that
// contains itself is refused instead of recursing until the interpreter crashes.
using DictPath = std::set<const PyObject*>;

toml::table to_toml_table(const py::handle& d, const std::string& where, DictPath& open, int depth);

void insert_value(toml::table& t, const std::string& key, const py::handle& v, const std::string& where,
                  DictPath& open, int depth) {
  const std::string path = where.empty() ? key : where + "." + key;
  if (py::isinstance<py::bool_>(v)) {
    t.insert_or_assign(key, v.cast<bool>());
  } else if (py::isinstance<py::int_>(v)) {
    t.insert_or_assign(key, v.cast<long long>());
  } else if (py::isinstance<py::float_>(v)) {
    t.insert_or_assign(key, v.cast<double>());
  } else if (py::isinstance<py::str>(v)) {
    t.insert_or_assign(key, v.cast<std::string>());
  } else if (py::isinstance<py::dict>(v)) {
    if (open.count(v.ptr())) throw py::value_error(path + ": the dict contains itself (a cycle)");
    if (depth >= kMaxDictDepth)
      throw py::value_error(path.substr(0, 80) + "...: dicts nested deeper than " + std::to_string(kMaxDictDepth));
    open.insert(v.ptr());
    toml::table sub = to_toml_table(v, path, open, depth + 1);
    open.erase(v.ptr());
    t.insert_or_assign(key, std::move(sub));
  } else if (py::isinstance<py::list>(v) || py::isinstance<py::tuple>(v)) {
    t.insert_or_assign(key, to_toml_array(v, path));
  } else {
    throw py::type_error(path + ": unsupported value of type " + std::string(py::str(v.get_type().attr("__name__"))));
  }
}

toml::table to_toml_table(const py::handle& d, const std::string& where, DictPath& open, int depth) {
  toml::table t;
  for (const auto& kv : d.cast<py::dict>()) {
    if (!py::isinstance<py::str>(kv.first))
      throw py::type_error(where.empty() ? "keys must be strings" : where + ": keys must be strings");
    insert_value(t, kv.first.cast<std::string>(), kv.second, where, open, depth);
  }
  return t;
}

// Arrays of numbers, booleans and strings, and (a sweep's scenes and setups) of tables.
toml::array to_toml_array(const py::handle& list, const std::string& key) {
  toml::array a;
  size_t i = 0;
  for (const auto& item : list) {
    const std::string at = key + "[" + std::to_string(i++) + "]";
    if (py::isinstance<py::bool_>(item)) a.push_back(item.cast<bool>());
    else if (py::isinstance<py::int_>(item)) a.push_back(item.cast<long long>());
    else if (py::isinstance<py::float_>(item)) a.push_back(item.cast<double>());
    else if (py::isinstance<py::str>(item)) a.push_back(item.cast<std::string>());
    else if (py::isinstance<py::dict>(item)) {
      DictPath open = {item.ptr()};
      a.push_back(to_toml_table(item, at, open, 2));
    } else if (py::isinstance<py::list>(item) || py::isinstance<py::tuple>(item)) {
      a.push_back(to_toml_array(item, at));
    } else {
      throw py::type_error(key + ": arrays hold numbers, booleans, strings, tables or arrays");
    }
  }
  return a;
}

std::string dict_to_toml(const py::dict& d) {
  DictPath open = {d.ptr()};
  std::ostringstream os;
  os << to_toml_table(d, "", open, 1);
  return os.str();
}

// ---- the long calls: on a worker thread, the GIL released, Ctrl-C and progress on this one ----

struct ProgressEvent {
  std::string run;
  double t, duration;
};

// Runs `work` on a worker thread while this thread, without the GIL but for a moment every
// 0.1 s, hands the worker's progress events to `callback` and checks for signals. A signal
// (Ctrl-C: Python's handler has only set its flag) sets the harness's stop request, which every
// stepping loop polls (stop_request.h): the work ends with Interrupted, its staged output
// removed, and the signal's exception (KeyboardInterrupt) is raised here. An exception of the
// callback stops the work the same way and is raised.
class Runner {
 public:
  explicit Runner(py::object callback) : callback_(std::move(callback)) {}

  // For the worker: queue an event (the callback runs on the calling thread, with the GIL).
  void post(const std::string& run, double t, double duration) {
    if (callback_.is_none()) return;
    std::lock_guard<std::mutex> lock(m_);
    events_.push_back({run, t, duration});
  }
  bool has_callback() const { return !callback_.is_none(); }

  template <class F>
  void run(F work) {
    std::exception_ptr failure;
    std::thread worker([&] {
      try {
        work();
      } catch (...) {
        failure = std::current_exception();
      }
      std::lock_guard<std::mutex> lock(m_);
      done_ = true;
      cv_.notify_all();
    });
    std::optional<py::error_already_set> python_error;
    for (;;) {
      std::deque<ProgressEvent> events;
      bool finished = false;
      {
        py::gil_scoped_release release;
        std::unique_lock<std::mutex> lock(m_);
        cv_.wait_for(lock, std::chrono::milliseconds(100), [&] { return done_ || !events_.empty(); });
        finished = done_;
        events.swap(events_);
      }
      // A run's samples since the last look come as its latest (one call per run and 0.1 s).
      std::deque<ProgressEvent> latest;
      for (const ProgressEvent& e : events) {
        auto same = std::find_if(latest.begin(), latest.end(), [&](const ProgressEvent& l) { return l.run == e.run; });
        if (same == latest.end()) latest.push_back(e);
        else *same = e;
      }
      if (!python_error) {
        try {
          for (const ProgressEvent& e : latest) callback_(e.run, e.t, e.duration);
          if (PyErr_CheckSignals() != 0) throw py::error_already_set();
        } catch (py::error_already_set& e) {
          python_error = std::move(e);
          int none = 0;
          tippe::g_stop_request.compare_exchange_strong(none, SIGINT);
        }
      }
      if (finished) break;
    }
    worker.join();
    if (python_error) {
      tippe::g_stop_request.store(0);
      throw *python_error;
    }
    if (failure) std::rethrow_exception(failure);
  }

 private:
  py::object callback_;
  std::mutex m_;
  std::condition_variable cv_;
  std::deque<ProgressEvent> events_;
  bool done_ = false;
};

// ---- conversions -----------------------------------------------------------------------------

py::array_t<double> to_numpy(std::vector<double>&& v) {
  auto* owner = new std::vector<double>(std::move(v));
  py::capsule free_when_done(owner, [](void* p) { delete static_cast<std::vector<double>*>(p); });
  return py::array_t<double>(static_cast<py::ssize_t>(owner->size()), owner->data(), free_when_done);
}

// trajectory.csv's columns in file order: numbers as float arrays, surface as a list of names.
py::dict columns_to_python(tippe::TrajectoryColumns&& t) {
  py::dict out;
  for (const std::string& c : t.columns) {
    if (c == "surface") out[py::str(c)] = py::cast(t.surface);
    else out[py::str(c)] = to_numpy(std::move(t.values.at(c)));
  }
  return out;
}

// The metrics' columns of a comparison's run (records/trajectory.h), surface as names.
py::dict trajectory_to_python(tippe::Trajectory&& t) {
  py::dict out;
  out["t"] = to_numpy(std::move(t.t));
  out["x_G"] = to_numpy(std::move(t.x_G));
  out["y_G"] = to_numpy(std::move(t.y_G));
  out["theta"] = to_numpy(std::move(t.theta));
  std::vector<std::string> surface;
  surface.reserve(t.surface.size());
  for (int code : t.surface) surface.emplace_back(tippe::to_string(static_cast<tippe::Surface>(code)));
  out["surface"] = py::cast(surface);
  out["x_C"] = to_numpy(std::move(t.x_C));
  out["y_C"] = to_numpy(std::move(t.y_C));
  out["normal_force"] = to_numpy(std::move(t.normal_force));
  out["slip_speed"] = to_numpy(std::move(t.slip_speed));
  out["energy"] = to_numpy(std::move(t.energy));
  out["jellett"] = to_numpy(std::move(t.jellett));
  out["contact_latitude"] = to_numpy(std::move(t.contact_latitude));
  return out;
}

// A scene as the Python side hands it over: a file (with --set overrides) or TOML text with the
// label that stands for its file.
struct SceneSource {
  std::string path, text, label;
  std::vector<std::string> overrides;
  bool self_check = true;
};

tippe::Scene load(const SceneSource& s) {
  tippe::Scene scene = s.text.empty() && !s.path.empty() ? tippe::load_scene(s.path, s.overrides)
                                                         : tippe::parse_scene_text(s.text, s.label, s.overrides);
  if (!s.self_check) scene.run.self_check = false;
  return scene;
}

SceneSource source_of(const py::dict& d) {
  SceneSource s;
  s.path = d["path"].cast<std::string>();
  s.text = d["text"].cast<std::string>();
  s.label = d["label"].cast<std::string>();
  s.overrides = d["overrides"].cast<std::vector<std::string>>();
  return s;
}

std::string dump(const nlohmann::json& j) { return j.dump(2) + "\n"; }

// progress=False: the harness's own progress (boards, sweep lines) silent for the call, as --quiet.
class QuietUnless {
 public:
  explicit QuietUnless(bool progress) : saved_(tippe::progress_mode()) {
    if (!progress) tippe::set_progress_mode(tippe::ProgressMode::Quiet);
  }
  ~QuietUnless() { tippe::set_progress_mode(saved_); }

 private:
  tippe::ProgressMode saved_;
};

}  // namespace

PYBIND11_MODULE(_tippe, m) {
  m.doc() = "The tippe-top bench's verbs (the extension behind the Python package `tippe`).";
  m.attr("__version__") = tippe::version();
  // Bad input: the command line's message ("FILE: KEY: reason") as a ValueError.
  static py::exception<tippe::InputError> input_error(m, "InputError", PyExc_ValueError);
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const tippe::InputError& e) {
      PyErr_SetString(input_error.ptr(), e.what());
    } catch (const tippe::SceneError& e) {
      PyErr_SetString(input_error.ptr(), e.what());
    } catch (const tippe::SweepInputError& e) {
      PyErr_SetString(input_error.ptr(), e.what());
    } catch (const tippe::OutputError& e) {
      PyErr_SetString(PyExc_OSError, e.what());
    } catch (const tippe::Interrupted& e) {
      PyErr_SetString(PyExc_KeyboardInterrupt, e.what());
    }
  });

  m.def("dict_to_toml", [](const py::dict& d) { return dict_to_toml(d); },
        "A dict with a scene (or sweep) file's keys as the TOML text of that file.");

  m.def("summary_text", [](const std::string& comparison) { return tippe::comparison_summary_text(nlohmann::json::parse(comparison)); },
        "What `tippe compare` prints of comparison.json's text: scene notes, the table, the findings.");

  m.def("engines_json", [] { return dump(tippe::engines_to_json()); }, "The registry as JSON text.");

  m.def(
      "load_scene",
      [](const py::dict& source) {
        const tippe::Scene scene = load(source_of(source));
        return dump(tippe::scene_to_json(scene));
      },
      "Reads and checks a scene; its scene_to_json text.");

  m.def(
      "run",
      [](const py::dict& source, const std::string& engine, const py::object& callback) {
        const SceneSource src = source_of(source);
        Runner runner(callback);
        tippe::ColumnTrajectorySink sink;
        tippe::RunRecord record;
        runner.run([&] {
          const tippe::Scene scene = load(src);
          std::unique_ptr<tippe::Simulator> sim;
          try {
            sim = tippe::make_simulator(engine, scene);  // input errors before the run, as `tippe run`
          } catch (const std::invalid_argument& e) {
            throw tippe::InputError(e.what());
          }
          record = tippe::run_simulator(*sim, scene, &sink,
                                        [&](double t, double duration) { runner.post(engine, t, duration); });
        });
        return py::make_tuple(dump(tippe::to_json(record)), columns_to_python(std::move(sink.columns)));
      },
      py::arg("source"), py::arg("engine"), py::arg("callback"),
      "Runs one engine on a scene: (summary.json text, trajectory columns).");

  m.def(
      "compare",
      [](const py::dict& source, const std::vector<std::string>& engines, const std::string& out, int jobs,
         const std::string& cache, bool plots, bool self_check, bool board, const py::object& callback) {
        SceneSource src = source_of(source);
        src.self_check = self_check;
        Runner runner(callback);
        const QuietUnless quiet(board);
        std::map<std::string, tippe::Trajectory> trajectories;
        tippe::Comparison c;
        runner.run([&] {
          const tippe::Scene scene = load(src);
          tippe::CompareRequest request;
          if (!engines.empty()) request.engines = engines;
          request.out = out;
          request.jobs = jobs;
          request.cache = cache;
          request.plots = plots;
          request.progress = board;
          if (runner.has_callback())
            request.on_progress = [&](const std::string& run, double t, double d) { runner.post(run, t, d); };
          request.trajectories = &trajectories;
          c = tippe::compare_scene(scene, request);
        });
        py::dict runs;
        for (auto& [name, t] : trajectories) runs[py::str(name)] = trajectory_to_python(std::move(t));
        return py::make_tuple(dump(tippe::to_json(c)), runs);
      },
      py::arg("source"), py::arg("engines"), py::arg("out"), py::arg("jobs"), py::arg("cache"), py::arg("plots"),
      py::arg("self_check"), py::arg("board"), py::arg("callback"),
      "Runs the reference and engines on a scene: (comparison.json text, each run's columns).");

  m.def(
      "import_mjcf",
      [](const std::string& model, const std::string& body, const std::string& keyframe, const std::string& out,
         double duration, double sample_interval) {
        tippe::MjcfSceneRequest r;
        r.model = model;
        r.body = body;
        r.keyframe = keyframe;
        r.out = out;
        r.duration = duration;
        r.sample_interval = sample_interval;
        tippe::MjcfScene s;
        {
          py::gil_scoped_release release;
          s = tippe::import_mjcf_scene(r);
          if (!out.empty()) tippe::write_result_file(out, s.text);
        }
        py::dict top;
        top["body"] = s.top.body;
        top["keyframe"] = s.top.keyframe;
        top["mujoco_version"] = s.top.mujoco_version;
        top["timestep"] = s.top.timestep;
        top["notes"] = s.top.notes;
        return py::make_tuple(s.text, top);
      },
      "A scene from a MuJoCo model: (the scene file's text, facts of the import); written to `out` when given.");

  m.def(
      "sweep",
      [](const std::string& path, const std::string& out, int jobs, bool restart, bool plots, bool progress) {
        tippe::SweepOutcome r;
        const QuietUnless quiet(progress);
        Runner runner{py::none()};
        runner.run([&] {
          const tippe::SweepPlan plan = tippe::load_sweep(path);
          tippe::SweepOptions opts;
          opts.out_dir = out;
          opts.jobs = jobs > 0 ? jobs : std::max(1, static_cast<int>(std::thread::hardware_concurrency()));
          opts.restart = restart;
          opts.progress = progress;
          opts.write_report = [plots](const std::string& dir, const std::vector<tippe::SweepRecord>& records) {
            tippe::write_sweep_report(dir, records, plots);
          };
          r = tippe::run_search_sweep(plan, opts);
        });
        py::dict d;
        d["points"] = r.points;
        d["skipped"] = r.skipped;
        d["ran"] = r.ran;
        d["wall_seconds"] = r.wall_seconds;
        return d;
      },
      "Runs a sweep file into `out` (resumable): its outcome; the records are out/records.jsonl.");

  m.def(
      "advise",
      [](const std::string& scene, const std::string& out, const std::vector<std::string>& engines,
         const std::string& criterion, double tolerance, long long max_runs, int jobs, double from, double to,
         double resolution, std::optional<double> duration, const std::vector<std::string>& axis, bool restart,
         bool plots, bool progress, int repeats) {
        tippe::AdviseOptions o;
        o.scene = scene;
        o.out = out;
        o.engines = engines;
        o.criterion = criterion;
        o.tolerance = tolerance;
        o.max_runs = max_runs;
        o.jobs = jobs;
        o.from = from;
        o.to = to;
        o.resolution = resolution;
        o.duration = duration;
        o.axis_overrides = axis;
        o.restart = restart;
        o.plots = plots;
        o.progress = progress;
        o.repeats = repeats;
        tippe::AdviceResult r;
        const QuietUnless quiet(progress);
        Runner runner{py::none()};
        runner.run([&] {
          try {
            r = tippe::run_advise(o);
          } catch (const tippe::SweepInputError&) {
            throw;
          } catch (const std::invalid_argument& e) {
            throw tippe::InputError(e.what());
          }
        });
        return tippe::advice_json_text(tippe::advice_record(r));
      },
      "Each engine's cheapest safe settings for a scene file (`tippe advise`): advice.json's text.");

  m.def(
      "gate",
      [](const std::string& gates, int jobs, const std::string& cache, const std::string& boundary_out,
         bool self_check, bool progress) {
        std::vector<tippe::CheckResult> results;
        const QuietUnless quiet(progress);
        Runner runner{py::none()};
        runner.run([&] {
          const tippe::GatePlan plan = tippe::load_gate_plan(gates);
          tippe::GateRequest request;
          request.jobs = jobs;
          request.cache = cache;
          request.boundary_out = boundary_out;
          request.self_check = self_check;
          results = tippe::run_gate(plan, request);
        });
        nlohmann::json j = tippe::to_json(results);
        j["gate_file"] = gates;
        return py::make_tuple(dump(j), tippe::render_table(results), tippe::all_passed(results));
      },
      "Runs a gate file's checks (`tippe gate`): (the --json text, the table, whether all passed).");
}
