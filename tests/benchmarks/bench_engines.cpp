// Google Benchmark: step cost of each engine on the toy scene, and the adapter's overhead.
#include <benchmark/benchmark.h>

#include "engines/core/fixed_step.h"
#include "engines/core/registry.h"
#include "harness/io/scene_io.h"
#include "harness/scene/resolve.h"

namespace tippe {

Scene toy() { return load_scene(std::string(TIPPE_SOURCE_DIR) + "/harness/scenes/toy.toml"); }

constexpr long long kSteps = 2000;  // 0.2 s of the toy at the engines' default 1e-4 step

// Through the adapter: advance_to with the shared loop's events, failure checks and forces.
void BM_AdapterSteps(benchmark::State& state, const std::string& engine) {
  const Scene scene = toy();
  long long steps = 0;
  for (auto _ : state) {
    state.PauseTiming();
    auto sim = make_simulator(engine, scene);
    state.ResumeTiming();
    sim->advance_to(kSteps * 1e-4);  // the toy leaves every engine at its default step, 1e-4
    benchmark::DoNotOptimize(sim->observe());
    steps += sim->work().steps;
    // A variable-step engine (Simbody) takes the steps its accuracy needs over the same 0.2 s.
    if (dynamic_cast<FixedStepSimulator*>(sim.get()) && sim->work().steps != kSteps)
      state.SkipWithError("the engine's step is not the default 1e-4");
  }
  state.SetItemsProcessed(steps);
}

// The same engine world stepped bare: the engine's own cost.
void BM_BareSteps(benchmark::State& state, const std::string& engine) {
  const Scene scene = toy();
  for (auto _ : state) {
    state.PauseTiming();
    auto sim = make_simulator(engine, scene);
    auto* fixed = dynamic_cast<FixedStepSimulator*>(sim.get());
    state.ResumeTiming();
    fixed->bare_steps(kSteps);
    benchmark::DoNotOptimize(sim.get());
  }
  state.SetItemsProcessed(state.iterations() * kSteps);
}

// The engine library's step call alone (DART: World::step without the adapter's lock, its
// process-wide contact parameters and its contact read); the same as bare for the other engines.
void BM_LibrarySteps(benchmark::State& state, const std::string& engine) {
  const Scene scene = toy();
  for (auto _ : state) {
    state.PauseTiming();
    auto sim = make_simulator(engine, scene);
    auto* fixed = dynamic_cast<FixedStepSimulator*>(sim.get());
    state.ResumeTiming();
    fixed->library_steps(kSteps);
    benchmark::DoNotOptimize(sim.get());
  }
  state.SetItemsProcessed(state.iterations() * kSteps);
}

}  // namespace tippe

// The three benchmarks for every registered engine (engines/core/registry.h): a new engine is measured
// without an edit here.
int main(int argc, char** argv) {
  for (const std::string& e : tippe::engine_names()) {
    benchmark::RegisterBenchmark(("BM_AdapterSteps/" + e).c_str(), tippe::BM_AdapterSteps, e)->Unit(benchmark::kMillisecond);
    // Bare and library steps exist for the engines stepped by the shared fixed-step loop only.
    if (!dynamic_cast<tippe::FixedStepSimulator*>(tippe::make_simulator(e, tippe::toy()).get())) continue;
    benchmark::RegisterBenchmark(("BM_BareSteps/" + e).c_str(), tippe::BM_BareSteps, e)->Unit(benchmark::kMillisecond);
    benchmark::RegisterBenchmark(("BM_LibrarySteps/" + e).c_str(), tippe::BM_LibrarySteps, e)->Unit(benchmark::kMillisecond);
  }
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
