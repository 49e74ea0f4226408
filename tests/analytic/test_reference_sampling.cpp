// A reference run's cost per sample: the energy ledger each sample carries takes no contact solve of its own.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <string>

#include "harness/io/scene_io.h"
#include "harness/scene/resolve.h"
#include "harness/measure/run.h"

namespace tippe::test_reference_sampling {
namespace {

RunRecord run_at(const std::string& scene, double duration, double interval) {
  Scene s = load_scene(std::string(TIPPE_SOURCE_DIR) + "/harness/scenes/" + scene + ".toml");
  s.run.duration = duration;
  s.run.sample_interval = interval;
  return run_scene(s, "analytic", nullptr, {});
}

TEST(ReferenceSampling, RhsEvaluationsDoNotGrowWithTheSamplingRate) {
  // The same run sampled every 100 ms and every 1 ms. The integration does not depend on the
  // samples (dense output: the steps are the same and a sample costs no right-hand side), and
  // the ledger at a sample comes from the contact power its step's booking evaluated
  // (ReferenceModel::energy_ledger). Before, each sample took a 5-point quadrature of the power
  // from its time to the step's end: five contact solves per sample, 9,900 more here. The bound
  // leaves room for the samples that still take that quadrature where the interpolated power is
  // not trusted (on toy: 8 of 30,001 samples over its 30 s).
  const double duration = 2.0;
  const RunRecord coarse = run_at("toy", duration, 0.1), fine = run_at("toy", duration, 0.001);
  ASSERT_EQ(coarse.status, "ok");
  ASSERT_EQ(fine.status, "ok");
  EXPECT_EQ(fine.work.steps, coarse.work.steps);
  const long long extra_samples = 2000 - 20;
  const long long extra_rhs = fine.work.rhs_evaluations - coarse.work.rhs_evaluations;
  std::printf("toy, %g s: %lld rhs at 100 ms samples, %lld at 1 ms (%lld steps)\n", duration,
              coarse.work.rhs_evaluations, fine.work.rhs_evaluations, fine.work.steps);
  EXPECT_LE(extra_rhs, extra_samples / 10);
  EXPECT_GE(extra_rhs, 0);
  // The ledger at the run's end is the same sum of the steps' bookings whatever the sampling.
  EXPECT_NEAR(fine.friction_work, coarse.friction_work, 1e-15 * std::abs(coarse.energy_initial));
}

TEST(ReferenceSampling, AStepPaysAtMostFifteenContactSolvesForItsSamples) {
  // A viscous ball, whose contact power varies over the long Bulirsch-Stoer steps faster than
  // the step's interpolant is trusted on: a step's first such sample takes the quadrature (five
  // solves), a second fits the step's halves (ten more) and its later samples are free, so the
  // samples of one step cost at most fifteen right-hand sides, however many there are. Before,
  // each paid five: 9,900 more at 1 ms than at 100 ms over these 2 s.
  const double duration = 2.0;
  const RunRecord coarse = run_at("rutstam_ball", duration, 0.1), fine = run_at("rutstam_ball", duration, 0.001);
  ASSERT_EQ(coarse.status, "ok");
  ASSERT_EQ(fine.status, "ok");
  EXPECT_EQ(fine.work.steps, coarse.work.steps);
  const long long extra_rhs = fine.work.rhs_evaluations - coarse.work.rhs_evaluations;
  std::printf("rutstam_ball, %g s: %lld rhs at 100 ms samples, %lld at 1 ms (%lld steps)\n", duration,
              coarse.work.rhs_evaluations, fine.work.rhs_evaluations, fine.work.steps);
  EXPECT_LE(extra_rhs, 15 * fine.work.steps);
  EXPECT_NEAR(fine.friction_work, coarse.friction_work, 1e-15 * std::abs(coarse.energy_initial));
}

}  // namespace
}  // namespace tippe
