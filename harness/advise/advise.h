// `tippe advise`: from a user's scene to each engine's cheapest safe settings, searched over the engine's declared axes, and the gate that keeps them.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "harness/records/sweep_record.h"
#include "harness/sweep/sweep_search.h"

namespace tippe {

// The advised step is the boundary divided by this margin, and a run there confirms it: half
// the largest safe step, so that a first-order engine's error at the advice is half of what it
// is at the edge, and a boundary that moves by less than a factor 2 (an engine upgrade, a
// slightly different model) leaves the advice safe. A judgement, stated on every page.
constexpr double kAdviceMargin = 2.0;

struct AdviseOptions {
  std::string scene;                 // the user's scene file
  std::vector<std::string> engines;  // empty: every engine with a cost knob
  std::string criterion;             // empty: "regime and inversion within TOLERANCE"
  double tolerance = 0.01;           // of the inversion time, where the reference inverts
  long long max_runs = 400;          // the budget of search runs over all engines
  // Runs of each configuration's confirming point, interleaved with the other configurations'
  // (the sweep's `repeats`): its CPU time, which chooses the cheapest, is the least of them. One
  // run took 0.232-0.387 CPU s on the shared two-core machine (BENCHMARKS.md, "A point's repeats").
  int repeats = 3;
  int jobs = 1;
  std::string out;
  double from = 1e-5, to = 1e-1;  // the cost knob's range
  double resolution = 0.05;       // log10 units
  std::optional<double> duration;  // the scene's run.duration override
  // ENGINE.KEY=V1,V2: the values of one declared axis replaced (a subset, or one value to fix it).
  std::vector<std::string> axis_overrides;
  bool restart = false;
  bool plots = true;
  bool progress = true;
};

// One configuration of one engine: a value of each categorical axis.
struct AdviceConfig {
  std::string engine, setup;  // setup: the sweep's name of it
  std::vector<std::string> keys, values;  // the axes' keys (of [engines.NAME]) and TOML values
  std::vector<std::string> set() const;   // "engines.E.KEY=VALUE" each
  std::string text() const;               // "integrator = RK4, cone = elliptic"
};

struct AdviceEngine {
  std::string engine, knob;
  std::vector<AdviceConfig> configs;   // searched, in order
  std::vector<AdviceConfig> unsearched;  // left out by the budget
  std::vector<SearchBoundary> boundaries;  // one per searched config (same order), when found in the records
  // The advice: the cheapest configuration whose confirming run is safe.
  std::optional<size_t> chosen;  // index into configs
  double step = 0;               // the advised step (boundary / kAdviceMargin)
  double boundary = 0, beyond = 0;  // the chosen configuration's bracket (beyond 0: none in range)
  double cpu_seconds = 0;           // of the confirming run
  std::string confirm_point;        // its point id
  // The other configurations whose confirming run is safe at a CPU time within kCostResolution
  // (10 %) of the advised one's, cheapest first: (index into configs, its step, its CPU seconds).
  struct Tie {
    size_t config = 0;
    double step = 0, cpu_seconds = 0;
  };
  std::vector<Tie> ties;
  std::string reason;               // why there is no advice
  std::vector<std::string> sensitivity;  // one sentence per axis
  std::vector<std::vector<std::string>> sensitivity_rows;  // axis, value, best boundary, factor
};

struct AdviceResult {
  std::string scene_name, criterion;
  bool reference_inverts = false;
  std::optional<double> reference_inversion;
  double duration = 0;
  std::vector<AdviceEngine> engines;
  size_t runs = 0;      // search and confirming runs (each repeat of a confirming point counts)
  int repeats = 1;      // runs of each confirming point (AdviseOptions::repeats)
  bool gate_written = false;
};

// The configurations of an engine: every combination of its declared axes (with `overrides`
// applied), in order (the first axis slowest). Throws UsageError-like std::invalid_argument for an
// override naming no declared axis.
std::vector<AdviceConfig> advice_configs(const std::string& engine, const std::vector<std::string>& overrides);

// The choice from finished searches and confirming runs, a pure function of records (tested):
// per engine, among the configurations whose search found a boundary or is all safe, those whose
// confirming run (`confirm`, matched by setup name) is safe under `criterion`; the one whose
// confirming run costs the least CPU, and those within kCostResolution of it (ties). The sensitivity: per axis, the largest boundary over the
// configurations with each value, and the factor between the largest and smallest of those.
void choose_advice(AdviceEngine& e, const SearchCriterion& criterion, const std::vector<SweepRecord>& confirm);

// The ties as the page and the record say them: "CONFIGURATION, KNOB STEP (CPU CPU s)", cheapest first.
std::vector<std::string> advice_ties_text(const AdviceEngine& e);

// Runs everything: writes OUT/advise-sweep.toml and runs it into OUT/sweep (resumable), the
// confirming runs (OUT/confirm-sweep.toml into OUT/confirm), then OUT/advice.toml (when some
// engine has advice), OUT/gate-sweep.toml, OUT/index.md and OUT/index.html.
AdviceResult run_advise(const AdviseOptions& options);

}  // namespace tippe
