// Google Benchmark: cost of the reference's right-hand side and of whole reference runs.
#include <benchmark/benchmark.h>

#include <sys/resource.h>

#include "analytic/contact_dynamics.h"
#include "analytic/initial_state.h"
#include "analytic/reference_model.h"
#include "harness/io/scene_io.h"
#include "harness/scene/resolve.h"

namespace tippe {
namespace {

Scene shipped(const char* name) { return load_scene(std::string(TIPPE_SOURCE_DIR) + "/harness/scenes/" + name); }

void BM_RightHandSide(benchmark::State& state) {
  const Scene scene = shipped("toy.toml");
  const BodyModel body = BodyModel::from_scene(scene);
  const ContactDynamics dyn(body, scene.contact);
  const StateVector y = pack(scene_initial_state(scene));
  ContactMode mode;
  mode.slot[0].active = true;  // sliding on the ball: the common case of a tippe-top run
  StateVector dy;
  for (auto _ : state) {
    dyn.evaluate(y, mode, &dy);
    benchmark::DoNotOptimize(dy);
  }
}
BENCHMARK(BM_RightHandSide);

// A whole run of a shipped scene to its end, sampled at its sample interval (no file output).
void BM_SceneRun(benchmark::State& state, const char* file, const char* method) {
  Scene scene = shipped(file);
  scene.run.method = method;
  long long steps = 0;
  for (auto _ : state) {
    ReferenceModel m(scene);
    const long long n = static_cast<long long>(scene.run.duration / scene.run.sample_interval + 0.5);
    for (long long k = 1; k <= n; ++k) {
      m.advance_to(k * scene.run.sample_interval);
      benchmark::DoNotOptimize(m.state());
    }
    steps = m.steps();
  }
  state.counters["steps"] = static_cast<double>(steps);
}
BENCHMARK_CAPTURE(BM_SceneRun, toy_bulirsch_stoer, "toy.toml", "bulirsch_stoer")->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_SceneRun, toy_dopri5, "toy.toml", "dopri5")->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_SceneRun, source_dimensionless, "source_dimensionless.toml", "bulirsch_stoer")
    ->Unit(benchmark::kMillisecond);

// Peak memory of a run against its length: the trajectory is streamed, so the resident set
// must not grow with the horizon (reported as a counter; compare 100 and 10000 time units).
void BM_LongRunMemory(benchmark::State& state) {
  Scene scene = shipped("source_dimensionless.toml");
  scene.contact.friction = FrictionLaw::None;
  scene.run.duration = static_cast<double>(state.range(0));
  for (auto _ : state) {
    ReferenceModel m(scene);
    for (double t = 1.0; t <= scene.run.duration; t += 1.0) m.advance_to(t);
    benchmark::DoNotOptimize(m.state());
  }
  rusage ru{};
  getrusage(RUSAGE_SELF, &ru);
  state.counters["peak_rss_MiB"] = static_cast<double>(ru.ru_maxrss) / 1024.0;
}
BENCHMARK(BM_LongRunMemory)->Arg(100)->Arg(10000)->Iterations(1)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace tippe

BENCHMARK_MAIN();
