// Side-by-side runs of the reference and engines on one scene into a comparison record.
#pragma once

#include <functional>
#include <map>
#include <string>
#include <vector>

#include "harness/measure/metrics.h"
#include "harness/measure/reference_cache.h"
#include "harness/measure/self_check.h"
#include "harness/records/comparison.h"
#include "harness/records/trajectory.h"
#include "engines/core/registry.h"
#include "analytic/scene.h"

namespace tippe {

struct CompareOptions {
  std::vector<std::string> engines = engine_names();  // every registered engine (engines/core/registry.h)
  int jobs = 1;
  std::string out_dir;    // where comparison.json, trajectories and reports go ("" = none)
  std::string cache_dir;  // reference cache ("" = no cache)
  bool progress = true;   // progress line on stderr
  // Each run's time as it goes, called from the worker threads ("reference", "self-check" or
  // the engine's name), for a caller's own display (the Python module's callback).
  std::function<void(const std::string& run, double t, double duration)> on_progress;
  // When set: each run's sampled columns, by the same names (the self-check's not kept).
  std::map<std::string, Trajectory>* trajectories = nullptr;
};

// in parallel when jobs > 1, and (scene.run.self_check) the reference's self-check beside them;
// writes comparison.json and the trajectories (reference.csv, ENGINE.csv) when out_dir is set; the
// report made from them is the caller's (the command line joins running and reporting). An engine that fails to
// build (bad setting) throws std::invalid_argument before anything runs; an engine that
// diverges is a result.
// Invalid input (unknown or repeated engine, jobs < 1, a bad [engines.NAME] setting) throws
// before any file is written. A cache entry is used only when its summary has the same physics
// hash, git commit and reference version as this build; otherwise it is re-run and replaced.
// The self-check is cached beside it (self_check.json, keyed by the cached reference's
// provenance and the second method and tolerances); a cached reference without a matching one
// gets its self-check run now, never taken for a checked one.
Comparison run_comparison(const Scene& scene, const CompareOptions& options);
// The checks run_comparison makes before it writes anything (engines known and listed once, jobs,
// engine settings): throws std::invalid_argument as it does.
void check_compare_input(const Scene& scene, const CompareOptions& options);

}  // namespace tippe
