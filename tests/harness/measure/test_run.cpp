// Tests of running one simulator into a run record (harness/measure/run.cpp): a scripted simulator sampled on the scene's grid, stopping early or reaching the duration.
#include <gtest/gtest.h>

#include <algorithm>
#include <string>
#include <vector>

#include "engines/core/simulator.h"
#include "harness/measure/run.h"
#include "harness/records/records.h"
#include "tests/support/observations.h"

namespace test_run {

using namespace tippe;

namespace {

using namespace tippe::fixtures;

// A scripted simulator: theta grows with time, an inversion at 0.25, diverges at t >= 0.35.
class FakeSimulator : public Simulator {
 public:
  std::string engine() const override { return "fake"; }
  std::string version() const override { return "fake 1.0"; }
  void advance_to(double t) override {
    if (status_ != RunStatus::Ok) return;
    t_ = std::min(t, 0.35);
    ++work_.steps;
    if (t_ >= 0.25 && events_.empty()) events_.push_back({"inversion", 0.25, "", 0});
    if (t_ >= 0.35) status_ = RunStatus::Diverged;
  }
  Observation observe() const override { return sample(t_, Surface::Ball, 1.0); }
  BodyState state() const override { return observe().state; }
  void set_state(const BodyState&) override {}
  MassReadback mass_properties() const override { return {}; }
  WorkCounters work() const override { return work_; }
  RunStatus status() const override { return status_; }
  double status_time() const override { return status_ == RunStatus::Ok ? 0.0 : 0.35; }
  std::string status_detail() const override { return status_ == RunStatus::Ok ? "" : "scripted"; }
  std::vector<Event> events() const override { return events_; }
  SettingsList settings() const override { return {{"timestep", "0.01"}}; }

 private:
  double t_ = 0.0;
  RunStatus status_ = RunStatus::Ok;
  std::vector<Event> events_;
  WorkCounters work_;
};

struct CollectSink : SampleSink {
  std::vector<double> times;
  void write(const Observation& o) override { times.push_back(o.state.t); }
};

TEST(Records, RunSimulatorSamplesTheGridAndStopsEarly) {
  Scene s;
  s.name = "fake";
  s.body.sphere_radius = 1.0;
  s.mass = {1.0, 0.3, 0.4, 0.45};
  s.run.duration = 1.0;
  s.run.sample_interval = 0.1;
  FakeSimulator sim;
  CollectSink sink;
  int calls = 0;
  const RunRecord r = run_simulator(sim, s, &sink, [&](double, double d) {
    ++calls;
    EXPECT_EQ(d, 1.0);
  });
  // 0, 0.1, 0.2, 0.3 on the grid, then the state at 0.35 where the run stopped.
  ASSERT_EQ(sink.times.size(), 5u);
  EXPECT_EQ(sink.times[3], 3 * 0.1);
  EXPECT_EQ(sink.times[4], 0.35);
  EXPECT_EQ(calls, 5);
  EXPECT_EQ(r.samples, 5);
  EXPECT_EQ(r.status, "diverged");
  EXPECT_EQ(r.status_time, 0.35);
  EXPECT_EQ(r.engine, "fake");
  ASSERT_TRUE(r.inversion_time.has_value());
  EXPECT_EQ(*r.inversion_time, 0.25);
  EXPECT_FALSE(r.stem_contact_time.has_value());
  EXPECT_TRUE(r.inversion_possible);
  EXPECT_EQ(r.settings.size(), 1u);
}

TEST(Records, RunSimulatorReachesDuration) {
  Scene s;
  s.body.sphere_radius = 1.0;
  s.mass = {1.0, 0.3, 0.4, 0.45};
  s.run.duration = 0.3;  // 0.3 / 0.1 = 2.9999999999999996
  s.run.sample_interval = 0.1;
  FakeSimulator sim;
  CollectSink sink;
  run_simulator(sim, s, &sink);
  ASSERT_EQ(sink.times.size(), 4u);
  EXPECT_EQ(sink.times.back(), 0.3);
}

}  // namespace

}  // namespace test_run
