// `tippe advise SCENE.toml --out DIR`: each engine's cheapest safe settings for a scene, searched on the sweep machinery, and the gate that keeps them.
#include <cstdio>
#include <memory>
#include <stdexcept>

#include "harness/advise/advise.h"
#include "harness/cli/cli.h"
#include "harness/io/progress.h"

namespace tippe::cli {

namespace {

int advise(const AdviseOptions& o, const std::string& engines, const std::string& tolerance) {
  AdviseOptions opts = o;
  if (!engines.empty()) {
    size_t start = 0;
    for (;;) {
      const size_t at = engines.find(',', start);
      opts.engines.push_back(engines.substr(start, at == std::string::npos ? std::string::npos : at - start));
      if (at == std::string::npos) break;
      start = at + 1;
    }
  }
  if (!tolerance.empty()) {
    std::string t = tolerance;
    bool pct = !t.empty() && t.back() == '%';
    if (pct) t.pop_back();
    char* end = nullptr;
    const double v = std::strtod(t.c_str(), &end);
    if (t.empty() || end != t.c_str() + t.size() || !(v > 0))
      throw UsageError("--tolerance " + tolerance + ": expected a positive number or percentage (1%, 0.01)");
    opts.tolerance = pct ? v / 100 : v;
  }
  opts.progress = progress_mode() != ProgressMode::Quiet;
  AdviceResult r;
  try {
    r = run_advise(opts);
  } catch (const SweepInputError& e) {
    throw UsageError(e.what());
  } catch (const std::invalid_argument& e) {
    throw UsageError(e.what());
  }
  for (const AdviceEngine& e : r.engines) {
    if (e.chosen)
      std::printf("%s: %s, %s %g (largest safe %g; %.3g CPU s)\n", e.engine.c_str(), e.configs[*e.chosen].text().c_str(),
                  e.knob.c_str(), e.step, e.boundary, e.cpu_seconds);
    else
      std::printf("%s: no advice: %s\n", e.engine.c_str(), e.reason.c_str());
  }
  std::printf("runs: %zu\n", r.runs);
  std::printf("report: %s/index.html\n", o.out.c_str());
  if (r.gate_written) std::printf("gate: %s/advice.toml\n", o.out.c_str());
  else std::printf("gate: none (no engine has advice)\n");
  return 0;
}

}  // namespace

Command setup_advise(CLI::App& app) {
  auto o = std::make_shared<AdviseOptions>();
  auto engines = std::make_shared<std::string>();
  auto tolerance = std::make_shared<std::string>();
  auto duration = std::make_shared<double>(0);
  CLI::App* sub = app.add_subcommand(
      "advise", "Each engine's cheapest settings that keep a scene safe (the reference's regime, its inversion "
                "time within a tolerance, no energy gain): a boundary search of the time step in every "
                "configuration of the engine's declared axes; DIR/index.html and the gate DIR/advice.toml");
  sub->add_option("scene", o->scene, "Scene file (TOML), e.g. one `tippe import-mjcf` wrote")->required();
  sub->add_option("--out", o->out, "Output directory (rerun to resume)")->required();
  sub->add_option("--engines", *engines, "Comma-separated engines (default: every engine)");
  sub->add_option("--criterion", o->criterion,
                  "What safe means beyond the run's class: terms \"regime\", \"inversion within TOL\", "
                  "\"METRIC <= BOUND\" joined by \" and \" (default: regime and inversion within --tolerance)");
  sub->add_option("--tolerance", *tolerance, "Inversion-time tolerance of the default criterion (default 1%)");
  sub->add_option("--max-runs", o->max_runs, "Budget of search runs over all engines (default 400)")
      ->check(CLI::PositiveNumber);
  sub->add_option("--jobs,-j", o->jobs, "Runs in parallel (default 1)")->check(CLI::PositiveNumber);
  sub->add_option("--repeats", o->repeats,
                  "Runs of each configuration's confirming point, interleaved; its CPU time, which chooses the "
                  "cheapest, is their least (default 3)")
      ->check(CLI::Range(1, kMaxRepeats));
  sub->add_option("--from", o->from, "Smallest time step searched (default 1e-5)");
  sub->add_option("--to", o->to, "Largest time step searched (default 0.1)");
  sub->add_option("--resolution", o->resolution, "Search resolution in log10 units (default 0.05)");
  sub->add_option("--duration", *duration, "Override the scene's run.duration (seconds of scene time)")
      ->check(CLI::PositiveNumber);
  sub->add_option("--axis", o->axis_overrides,
                  "ENGINE.KEY=V1,V2: search these values of a declared axis (one value fixes it); repeatable")
      ->allow_extra_args(false)
      ->take_all();
  sub->add_flag("--restart", o->restart, "Begin DIR's searches again (needed when the scene changed)");
  sub->add_flag_function("--no-plots", [o](int64_t) { o->plots = false; }, "Skip the gnuplot SVGs of the sweep report");
  return {sub, [o, engines, tolerance, duration] {
            AdviseOptions opts = *o;
            if (*duration > 0) opts.duration = *duration;
            return advise(opts, *engines, *tolerance);
          }};
}

}  // namespace tippe::cli
