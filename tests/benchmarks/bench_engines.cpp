// Google Benchmark: step cost of each engine on the toy scene, and the adapter's overhead.
#include <benchmark/benchmark.h>

#include "../../engines/fixed_step.h"
#include "scene_io.h"

namespace tippe {
namespace {

Scene toy() { return load_scene(std::string(TIPPE_SOURCE_DIR) + "/harness/scenes/toy.toml"); }

constexpr long long kSteps = 2000;  // 0.2 s of the toy at the engines' default 1e-4 step

// Through the adapter: advance_to with the shared loop's events, failure checks and forces.
void BM_AdapterSteps(benchmark::State& state, const char* engine) {
  const Scene scene = toy();
  for (auto _ : state) {
    state.PauseTiming();
    auto sim = make_simulator(engine, scene);
    state.ResumeTiming();
    sim->advance_to(kSteps * 1e-4);  // the toy leaves every engine at its default step, 1e-4
    benchmark::DoNotOptimize(sim->observe());
    if (sim->work().steps != kSteps) state.SkipWithError("the engine's step is not the default 1e-4");
  }
  state.SetItemsProcessed(state.iterations() * kSteps);
}

// The same engine world stepped bare: the engine's own cost.
void BM_BareSteps(benchmark::State& state, const char* engine) {
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

BENCHMARK_CAPTURE(BM_AdapterSteps, bullet, "bullet")->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_BareSteps, bullet, "bullet")->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_AdapterSteps, ode, "ode")->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_BareSteps, ode, "ode")->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_AdapterSteps, mujoco, "mujoco")->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_BareSteps, mujoco, "mujoco")->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace tippe

BENCHMARK_MAIN();
