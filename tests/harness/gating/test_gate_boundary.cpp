// Tests of gates on a boundary search (harness/gating/gate_boundary.cpp): a [[boundary]] check judged from a synthetic search's records.
#include <gtest/gtest.h>

#include <vector>

#include "harness/gating/gate.h"
#include "harness/gating/gate_boundary.h"
#include "harness/sweep/sweep_search.h"
#include "tests/support/sweep_searches.h"

namespace test_gate_boundary {

using namespace tippe;

namespace {

using namespace tippe::fixtures;

}  // namespace

// ---- gates on a boundary --------------------------------------------------------------------

TEST(SweepSearchGate, BoundaryCheckJudgesTheSearchFromRecords) {
  const SweepSearch s = search(1e-6, 1e-1, 0.05);
  const std::vector<SweepRecord> records = synthetic_records(s, [](double v) { return v <= 3.7e-3; }, "toy_viscous", 0);
  BoundaryCheck c;
  c.name = "ode-step";
  c.setup = "ode-regime";
  c.scene = "toy_viscous";
  c.require = parse_bound_text("max_safe_timestep >= 1e-3");
  CheckResult r = evaluate_boundary(c, records);
  EXPECT_TRUE(r.passed) << render_table({r});
  c.require = parse_bound_text("max_safe_timestep >= 1e-2");
  r = evaluate_boundary(c, records);
  EXPECT_FALSE(r.passed);
  const std::string table = render_table({r});
  EXPECT_NE(table.find("max_safe_timestep 0.00"), std::string::npos) << table;
  EXPECT_NE(table.find(" < 0.01 (regime; bracket "), std::string::npos) << table;
  // A criterion that comes and goes fails unless allowed.
  const std::vector<SweepRecord> wavy =
      synthetic_records(s, [](double v) { return v < 3e-5 || (v > 2e-3 && v < 4e-2); }, "toy_viscous", 0);
  c.require = parse_bound_text("max_safe_timestep >= 1e-5");
  r = evaluate_boundary(c, wavy);
  EXPECT_FALSE(r.passed);
  EXPECT_NE(render_table({r}).find("monotonic"), std::string::npos);
  c.allow_non_monotonic = true;
  EXPECT_TRUE(evaluate_boundary(c, wavy).passed);
  // Nothing safe, or no record of the search: fails.
  EXPECT_FALSE(evaluate_boundary(c, synthetic_records(s, [](double) { return false; }, "toy_viscous", 0)).passed);
  c.scene = "toy";
  EXPECT_FALSE(evaluate_boundary(c, records).passed);
}

}  // namespace test_gate_boundary
