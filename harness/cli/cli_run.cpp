// `tippe run`: one scene on one simulator, writing summary.json and trajectory.csv to a directory.
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <memory>

#include "harness/cli/cli.h"
#include "harness/io/progress.h"
#include "engines/core/registry.h"
#include "harness/records/records.h"
#include "harness/measure/run.h"
#include "harness/io/scene_io.h"
#include "harness/scene/resolve.h"

namespace tippe::cli {

namespace {

namespace fs = std::filesystem;

struct RunOptions {
  std::string scene;
  std::string engine = reference_engine().name;
  std::string out;
  std::vector<std::string> sets;
};

// "[engine] t = 1.234 / 8.000 (15%)" on stderr: on a terminal redrawn at most ten times a
// second, in a log one line every kProgressLineSeconds and the last, with --quiet nothing.
class ProgressLine {
 public:
  explicit ProgressLine(std::string engine) : engine_(std::move(engine)), mode_(progress_mode()) {}
  void update(double t, double duration) {
    t_ = t;
    duration_ = duration;
    if (mode_ == ProgressMode::Quiet) return;
    const auto now = std::chrono::steady_clock::now();
    const auto gap = mode_ == ProgressMode::Redraw ? std::chrono::duration<double>(0.1)
                                                   : std::chrono::duration<double>(kProgressLineSeconds);
    if (shown_ && now - last_ < gap) return;
    shown_ = true;
    last_ = now;
    print();
  }
  void finish() {
    if (!shown_) return;
    print();
    if (mode_ == ProgressMode::Redraw) std::fputc('\n', stderr);
    shown_ = false;
  }
  ~ProgressLine() {
    // Ends the line so that an error message does not land after the carriage return.
    if (shown_ && mode_ == ProgressMode::Redraw) std::fputc('\n', stderr);
  }

 private:
  void print() const {
    const int pct = duration_ > 0 ? static_cast<int>(100.0 * t_ / duration_) : 100;
    std::fprintf(stderr, mode_ == ProgressMode::Redraw ? "\r[%s] t = %.3f / %.3f (%d%%)" : "[%s] t = %.3f / %.3f (%d%%)\n",
                 engine_.c_str(), t_, duration_, pct);
    std::fflush(stderr);
  }
  std::string engine_;
  ProgressMode mode_;
  double t_ = 0, duration_ = 0;
  bool shown_ = false;
  std::chrono::steady_clock::time_point last_;
};

std::string opt_time(const std::optional<double>& t) {
  if (!t) return "none";
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.10g", *t);
  return buf;
}

std::string opt_num(const std::optional<double>& v) {
  if (!v) return "-";
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.3g", *v);
  return buf;
}

void print_summary(const RunRecord& r, const fs::path& dir) {
  std::printf("scene          %s (%s, hash %s)\n", r.scene_name.c_str(), r.scene_file.c_str(), r.scene_hash.c_str());
  std::printf("engine         %s (%s)\n", r.engine.c_str(), r.engine_version.c_str());
  if (r.status == "ok") {
    std::printf("status         ok\n");
  } else {
    std::printf("status         %s at t = %.10g: %s\n", r.status.c_str(), r.status_time, r.status_detail.c_str());
  }
  std::printf("inversion      %s\n", opt_time(r.inversion_time).c_str());
  std::printf("stem contact   %s\n", opt_time(r.stem_contact_time).c_str());
  const double de = (r.energy_final - r.energy_initial) / std::abs(r.energy_initial);
  std::printf("energy         initial %.10g, final %.10g (relative change %.3g)\n", r.energy_initial, r.energy_final,
              de);
  std::printf("Jellett        J0 = %.10g, max relative drift on one surface %.3g (ball %s, stem %s)\n",
              r.jellett_initial, r.jellett_max_relative_drift, opt_num(r.jellett_drift_ball).c_str(),
              opt_num(r.jellett_drift_stem).c_str());
  std::printf("final          t = %.10g, tilt %.6g rad, %lld samples\n", r.final_time, r.final_tilt, r.samples);
  std::printf("work           %lld steps, %lld rhs evaluations, wall %.3f s, cpu %.3f s\n", r.work.steps,
              r.work.rhs_evaluations, r.work.wall_seconds, r.work.cpu_seconds);
  for (const auto& n : r.scene_spec.value("notes", nlohmann::json::array()))
    if (n.is_string()) std::printf("scene note     %s\n", n.get<std::string>().c_str());
  for (const auto& n : r.notes) std::printf("note           %s\n", n.c_str());
  std::printf("output         %s\n", dir.string().c_str());
}

int run(const RunOptions& o) {
  // Everything that can be wrong with the input is found before the output directory exists.
  const Scene scene = load_scene(o.scene, o.sets);
  std::unique_ptr<Simulator> sim;
  try {
    sim = make_simulator(o.engine, scene);
  } catch (const std::invalid_argument& e) {
    throw UsageError(e.what());
  }
  const fs::path dir = o.out.empty() ? fs::path("out") / (scene.name + "-" + o.engine) : fs::path(o.out);

  // The run's files are one unit: written beside DIR and swapped in whole, so that an
  // interrupted rerun (a signal, a full disk) leaves the earlier run's files as they were.
  const InterruptGuard interrupts;
  OutputDir out(dir, OutputKind::Run, scene_input_files(scene));
  const fs::path stage = out.stage(false);
  CsvTrajectoryWriter csv((stage / "trajectory.csv").string());
  ProgressLine progress(o.engine);
  const RunRecord record =
      run_simulator(*sim, scene, &csv, [&progress](double t, double duration) { progress.update(t, duration); });
  progress.finish();
  csv.commit();
  write_file_atomic((stage / "summary.json").string(), to_json(record).dump(2) + "\n");
  out.commit();
  print_summary(record, dir);
  return 0;
}

}  // namespace

Command setup_run(CLI::App& app) {
  auto o = std::make_shared<RunOptions>();
  CLI::App* sub = app.add_subcommand("run", "Run a scene on one engine; write summary.json and trajectory.csv");
  add_scene_options(sub, o->scene, o->sets);
  sub->add_option("--engine", o->engine, engine_list_text(available_engines()))
      ->check(CLI::IsMember(available_engines()))
      ->capture_default_str();
  sub->add_option("--out", o->out, "Output directory (default out/<scene name>-<engine>)");
  return {sub, [o] { return run(*o); }};
}

}  // namespace tippe::cli
