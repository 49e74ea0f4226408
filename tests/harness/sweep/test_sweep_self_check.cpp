// The reference's self-check in sweeps: a sweep's points are compared with the reference only as far as it is converged, as a comparison's are.
#include <gtest/gtest.h>

#include <filesystem>
#include <string>

#include "io/scene_io.h"
#include "measure/compare.h"
#include "report/sweep_analysis.h"
#include "sweep/sweep.h"
#include "support/fixtures.h"

namespace fs = std::filesystem;
using namespace tippe;
using namespace tippe::fixtures;

namespace {

// The toy top to 2 s at the reference tolerance `rtol` (atol 100 times smaller, as shipped), and
// a sweep of one ODE point on it.
struct ToySweep {
  TempDir dir{"tippe-sweep-self-check"};
  std::string scene_path, sweep_path;
  explicit ToySweep(const std::string& rtol, const std::string& atol, bool self_check = true) {
    std::string text = slurp(kScenesDir + "toy.toml");
    text = edit(text, "rtol = 1e-10", "rtol = " + rtol);
    text = edit(text, "atol = 1e-12", "atol = " + atol + (self_check ? "" : "\nself_check = false"));
    scene_path = dir.write("toy.toml", text);
    sweep_path = dir.write("s.toml", R"(description = "one ODE point on the toy"
scenes = [{ file = "toy.toml", duration = 2.0 }]
[[setup]]
name = "ode"
engine = "ode"
ladder = { key = "engines.ode.timestep", values = [1e-3] }
)");
  }
  std::vector<SweepRecord> run() const {
    SweepOptions o;
    o.out_dir = (dir.path() / "out").string();
    o.progress = false;
    run_sweep(load_sweep(sweep_path), o);
    return read_records((dir.path() / "out" / "records.jsonl").string()).records;
  }
};

// The comparison's own self-check on the same scene, to which the sweep's must agree.
std::optional<double> comparison_converged_until(const std::string& scene_path) {
  CompareOptions o;
  o.engines = {"ode"};
  o.progress = false;
  const Comparison c = run_comparison(load_scene(scene_path, {"run.duration=2"}), o);
  EXPECT_TRUE(c.self_check);
  return c.self_check ? c.self_check->converged_until : std::nullopt;
}

// rtol 1e-3 on the toy: the two reference methods part within 0.1 s (SelfCheck.CatchesALoose-
// ToleranceOnTheToy), so the point's metrics stop where the comparison's do.
TEST(SweepSelfCheck, CutsThePointsMetricsWhereTheReferenceIsNotConverged) {
  const ToySweep s("1e-3", "1e-5");
  const std::vector<SweepRecord> records = s.run();
  ASSERT_EQ(records.size(), 1u);
  const Metrics& m = records[0].metrics;
  ASSERT_TRUE(m.reference_converged_until);
  EXPECT_LT(*m.reference_converged_until, 0.1);
  EXPECT_LE(m.compared_until, *m.reference_converged_until);
  const std::optional<double> c = comparison_converged_until(s.scene_path);
  ASSERT_TRUE(c);
  EXPECT_EQ(*m.reference_converged_until, *c);  // the same two runs, the same rule: the same time
  // The report says from when on the reference is not trusted.
  EXPECT_NE(render_sweep_markdown(records).find("parts from it at t ="), std::string::npos);
  // The self-check is cached beside the reference and a rerun reads it from there.
  EXPECT_TRUE(fs::exists(s.dir.path() / "out" / "reference" / records[0].physics_hash / "self_check.json"));
}

TEST(SweepSelfCheck, AConvergedReferenceLeavesTheMetricsWhole) {
  const ToySweep s("1e-10", "1e-12");
  const std::vector<SweepRecord> records = s.run();
  ASSERT_EQ(records.size(), 1u);
  EXPECT_FALSE(records[0].metrics.reference_converged_until);
  EXPECT_NEAR(records[0].metrics.compared_until, 2.0, 1e-9);
  EXPECT_EQ(render_sweep_markdown(records).find("parts from it at t ="), std::string::npos);
}

TEST(SweepSelfCheck, TurnedOffInTheSceneComparesTheWholeRun) {
  const ToySweep s("1e-3", "1e-5", /*self_check=*/false);
  const std::vector<SweepRecord> records = s.run();
  ASSERT_EQ(records.size(), 1u);
  EXPECT_FALSE(records[0].metrics.reference_converged_until);
  EXPECT_FALSE(fs::exists(s.dir.path() / "out" / "reference" / records[0].physics_hash / "self_check.json"));
}

}  // namespace
