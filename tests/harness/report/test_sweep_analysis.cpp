// Tests of the sweep analysis on synthetic records (harness/report/sweep_analysis.h): orders of convergence, the cheapest setting below each bound, the regime along the step, the modelling choices that move the verdict, and the sweep report's Markdown.
#include <gtest/gtest.h>

#include <cmath>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "harness/report/sweep_analysis.h"
#include "tests/support/sweep_points.h"

namespace test_sweep_analysis {

using namespace tippe;

namespace {

using fixtures::point;

// A grid point of the Modelling-choices fixtures: scene s, the setup's choice at `dt`.
SweepRecord choice_point(const std::string& setup, long long grid_index, const std::string& choice, long long ladder_index,
                         double dt, std::optional<double> inversion) {
  SweepRecord r = point("mujoco", setup, dt, 1e-3 / dt, std::nullopt);
  r.scene = "s";
  r.point_id = setup + choice + std::to_string(ladder_index);
  r.ladder_index = ladder_index;
  r.grid_key = "engines.mujoco." + setup;
  r.grid_label = choice;
  r.grid_index = grid_index;
  r.inversion_time = inversion;
  if (inversion) {
    r.metrics.inversion_event = "both";
    r.metrics.inversion_time_rel_error = *inversion / 10.0 - 1;
  }
  return r;
}

}  // namespace

// ---- analysis ---------------------------------------------------------------------------------

TEST(SweepAnalysis, ExactPowerLawGivesItsOrderOverEveryPoint) {
  const std::vector<double> h = {1e-2, 3e-3, 1e-3, 3e-4, 1e-4, 3e-5};
  for (double order : {1.0, 2.0, 4.0}) {
    std::vector<double> e;
    for (double x : h) e.push_back(7.0 * std::pow(x, order));
    const ConvergenceFit f = convergence_order(h, e);
    ASSERT_TRUE(f.ok) << f.note;
    EXPECT_NEAR(f.order, order, 1e-9);
    EXPECT_EQ(f.used, (std::vector<size_t>{5, 4, 3, 2, 1, 0})) << "every point, in increasing h";
  }
}

TEST(SweepAnalysis, FloorAndSaturationAreLeftOutOfTheAsymptoticRange) {
  // Error 1000 h^2 above a floor of 1e-7 at the fine end and saturated at 0.5 at the coarse end.
  const std::vector<double> h = {3e-1, 1e-1, 3e-2, 1e-2, 3e-3, 1e-3, 3e-4, 1e-4, 1e-5, 1e-6};
  std::vector<double> e;
  for (double x : h) e.push_back(std::min(0.5, 1000 * x * x) + 1e-7);
  const ConvergenceFit f = convergence_order(h, e);
  ASSERT_TRUE(f.ok) << f.note;
  EXPECT_NEAR(f.order, 2.0, 0.1);
  std::set<double> used;
  for (size_t i : f.used) used.insert(h[i]);
  EXPECT_FALSE(used.count(1e-6)) << "on the floor";
  EXPECT_FALSE(used.count(1e-1)) << "saturated";
  EXPECT_FALSE(used.count(3e-1)) << "saturated";
  for (double x : {1e-2, 1e-3, 1e-4}) EXPECT_TRUE(used.count(x)) << x;
}

TEST(SweepAnalysis, NoConvergenceIsSaid) {
  EXPECT_FALSE(convergence_order({1e-2, 1e-3, 1e-4}, {0.1, 0.1, 0.1}).ok);
  EXPECT_FALSE(convergence_order({1e-2}, {0.1}).ok);
  // Non-finite and zero errors do not count.
  const ConvergenceFit f = convergence_order({1e-2, 1e-3, 1e-4}, {1e-4, std::nan(""), 0.0});
  EXPECT_FALSE(f.ok);
  const ConvergenceFit two = convergence_order({1e-2, 1e-3, 1e-4}, {1e-2, 1e-3, std::nan("")});
  ASSERT_TRUE(two.ok);
  EXPECT_NEAR(two.order, 1.0, 1e-12);
  EXPECT_EQ(two.note, "only 2 points");
}

TEST(SweepAnalysis, CheapestSettingBelowEachBound) {
  // Two setups of engine A and one of B; errors of either sign; a diverged run never counts.
  std::vector<SweepRecord> a = {point("a", "a-euler", 1e-2, 1.0, 0.2), point("a", "a-euler", 1e-3, 2.0, -0.05),
                                point("a", "a-euler", 1e-4, 4.0, 0.005), point("a", "a-rk4", 1e-2, 3.0, 0.004),
                                point("a", "a-rk4", 1e-3, 6.0, 0.0002)};
  EXPECT_EQ(cheapest_below(a, 0.1), 1);
  EXPECT_EQ(cheapest_below(a, 0.01), 3) << "the RK4 setup is cheaper than Euler at 1e-4";
  EXPECT_EQ(cheapest_below(a, 0.001), 4);
  EXPECT_EQ(cheapest_below(a, 1e-5), -1);

  std::vector<SweepRecord> b = {point("b", "b", 1e-2, 0.5, 0.08), point("b", "b", 1e-3, 3.0, 0.0005, "diverged"),
                                point("b", "b", 1e-4, 5.0, -0.0009), point("b", "b", 1e-5, 9.0, std::nullopt)};
  EXPECT_EQ(cheapest_below(b, 0.1), 0);
  EXPECT_EQ(cheapest_below(b, 0.01), 2) << "the diverged point is skipped";
  EXPECT_EQ(cheapest_below(b, 0.001), 2);
  EXPECT_EQ(cheapest_below(b, 0.0009), 2) << "the bound is inclusive, as every criterion's |METRIC| <= BOUND";
  EXPECT_EQ(cheapest_below(b, 0.00089), -1);

  // The analytic side: the cheapest point at least as accurate.
  std::vector<SweepRecord> an = {point("analytic", "bs", 1e-4, 0.002, 1e-5), point("analytic", "bs", 1e-8, 0.004, 1e-9),
                                 point("analytic", "dp", 1e-4, 0.003, 3e-6)};
  EXPECT_EQ(cheapest_at_least_as_accurate(an, 0.005), 0);
  EXPECT_EQ(cheapest_at_least_as_accurate(an, 5e-6), 2);
  EXPECT_EQ(cheapest_at_least_as_accurate(an, 1e-9), 1) << "equal accuracy counts";
  EXPECT_EQ(cheapest_at_least_as_accurate(an, 1e-10), -1);
}

// Points safe by the same criterion within 10 % of the cheapest's CPU time are named beside it,
// cheapest first; an unsafe point, a point outside the bound or one 10.1 % dearer is not.
TEST(SweepAnalysis, CostTiesAreTheSafePointsWithinTenPercent) {
  std::vector<SweepRecord> a = {point("a", "a-euler", 1e-3, 1.00, 0.005), point("a", "a-rk4", 1e-2, 1.08, 0.004),
                                point("a", "a-euler", 1e-4, 1.05, 0.002), point("a", "a-rk4", 1e-3, 1.101, 0.0002),
                                point("a", "a-bad", 1e-3, 1.02, 0.001, "diverged"),
                                point("a", "a-late", 1e-3, 1.03, 0.05)};
  const SearchCriterion c = setting_criterion(true, 0.01);
  const long long best = cheapest_safe(a, c);
  ASSERT_EQ(best, 0);
  EXPECT_EQ(cost_ties(a, best, c), (std::vector<size_t>{2, 1}));
  // Under the 10 % bound the late point qualifies, and is within 10 %.
  EXPECT_EQ(cost_ties(a, cheapest_safe(a, setting_criterion(true, 0.1)), setting_criterion(true, 0.1)),
            (std::vector<size_t>{5, 2, 1}));
  EXPECT_TRUE(cost_ties(a, -1, c).empty());
  EXPECT_TRUE(cost_ties({a[0]}, 0, c).empty());
}

TEST(SweepAnalysis, SoftestSettingInTheReferencesRegime) {
  // The reference rolls (no inversion): a point agrees when it finishes without inverting.
  auto rolling = [](double dt, std::optional<double> inversion, const std::string& status = "ok") {
    SweepRecord r;
    r.ladder_key = "engines.ode.timestep";
    r.ladder_value = dt;
    r.inversion_time = inversion;
    r.status = status;
    return r;
  };
  std::vector<SweepRecord> s = {rolling(1e-2, 3.0), rolling(3e-3, std::nullopt), rolling(1e-3, std::nullopt),
                                rolling(1e-4, std::nullopt)};
  EXPECT_FALSE(agrees_with_reference_regime(s[0]));
  EXPECT_TRUE(agrees_with_reference_regime(s[1]));
  EXPECT_EQ(softest_agreeing(s), 1);
  // Walking from the finest: a diverged run at 3e-3 stops the walk although 1e-2 agrees again.
  s = {rolling(1e-2, std::nullopt), rolling(3e-3, std::nullopt, "diverged"), rolling(1e-3, std::nullopt)};
  EXPECT_EQ(softest_agreeing(s), 2);
  s = {rolling(1e-3, 1.0), rolling(1e-4, 1.0)};
  EXPECT_EQ(softest_agreeing(s), -1);

  // An inverting reference: a run that inverts agrees, even if it diverges later.
  SweepRecord inv = rolling(1e-3, 4.0, "diverged");
  inv.reference_inversion_time = 4.3;
  EXPECT_TRUE(agrees_with_reference_regime(inv));

  // Iterations: fewer is softer.
  EXPECT_TRUE(larger_is_softer("engines.mujoco.timestep"));
  EXPECT_TRUE(larger_is_softer("run.rtol"));
  EXPECT_FALSE(larger_is_softer("engines.bullet.solver_iterations"));
  EXPECT_FALSE(larger_is_softer("engines.ode.iterations"));
  std::vector<SweepRecord> it = {rolling(5, 2.0), rolling(10, std::nullopt), rolling(50, std::nullopt)};
  for (auto& r : it) r.ladder_key = "engines.ode.iterations";
  EXPECT_EQ(softest_agreeing(it), 1);
}

// Leaving the reference's rolling regime, as the step shrinks: gone at the finest steps, moved
// later, or staying; a diverged run is left out; "mixed" when the regime comes and goes.
TEST(SweepAnalysis, RegimeTrendAlongTheStep) {
  auto point = [](double dt, std::optional<double> inversion, const std::string& status = "ok") {
    SweepRecord r;
    r.ladder_key = "engines.ode.timestep";
    r.ladder_value = dt;
    r.inversion_time = inversion;
    r.status = status;
    return r;
  };
  // ODE on toy to 30 s as measured (4.87 s at 3e-4, 13.2 s at 1e-4, none at 3e-5).
  RegimeTrend tr = regime_trend({point(1e-3, 1.84), point(3e-4, 4.87), point(1e-4, 13.2), point(3e-5, std::nullopt)});
  EXPECT_EQ(tr.verdict, "goes away");
  ASSERT_TRUE(tr.in_regime_from);
  EXPECT_EQ(*tr.in_regime_from, 3e-5);
  ASSERT_EQ(tr.inversion_by_step.size(), 3u);
  EXPECT_EQ(tr.inversion_by_step.front().first, 1e-3) << "coarsest first";
  // Every finished run inverts, later as the step falls: the departure only moves (ODE on the
  // Leine-Glocker twin: 0.899, 2.02, 4.84, 14.4 s).
  tr = regime_trend({point(1e-4, 9.0), point(1e-3, 2.0), point(3e-4, 5.0), point(3e-2, 0.1, "diverged")});
  EXPECT_EQ(tr.verdict, "moves later") << "sorted by step, the diverged run left out";
  EXPECT_FALSE(tr.in_regime_from);
  // The two finest within 1 %: converged (MuJoCo on toy: 16.6, 17.0, 17.02, 17.01 s).
  EXPECT_EQ(regime_trend({point(1e-3, 16.58), point(3e-4, 16.98), point(1e-4, 17.02), point(3e-5, 17.01)}).verdict,
            "converges");
  EXPECT_EQ(regime_trend({point(1e-3, 1.309), point(1e-4, 1.309), point(2e-5, 1.31)}).verdict, "converges");
  // Earlier at a finer step, the two apart: neither.
  EXPECT_EQ(regime_trend({point(1e-3, 5.0), point(1e-4, 2.0)}).verdict, "earlier at a finer step");
  EXPECT_EQ(regime_trend({point(1e-3, std::nullopt), point(1e-4, std::nullopt)}).verdict, "none");
  EXPECT_EQ(regime_trend({point(1e-3, 2.0), point(3e-4, std::nullopt), point(1e-4, 3.0), point(3e-5, std::nullopt)}).verdict,
            "mixed");
  // Not answerable: one finished run; the reference inverts; not a time step.
  EXPECT_EQ(regime_trend({point(1e-3, 2.0), point(1e-4, 2.0, "diverged")}).verdict, "-");
  SweepRecord inv = point(1e-3, 4.0);
  inv.reference_inversion_time = 4.3;
  EXPECT_EQ(regime_trend({inv, inv}).verdict, "-");
  SweepRecord iters = point(10, 2.0);
  iters.ladder_key = "engines.ode.iterations";
  EXPECT_EQ(regime_trend({iters, iters}).verdict, "-");
}

TEST(SweepReport, MarkdownNamesTheCheapestPointsAndOrders) {
  std::vector<SweepRecord> recs;
  const std::vector<double> h = {1e-2, 1e-3, 1e-4};
  long long k = 0;
  for (double dt : h) {
    SweepRecord r = point("ode", "ode", dt, 1e-3 / dt, 3.0 * dt * dt);
    r.scene = "fixture";
    r.metrics.tilt_rms_error = 0.1 * dt;
    r.ladder_index = k++;
    r.point_id = "p" + std::to_string(k);
    recs.push_back(r);
  }
  const std::string md = render_sweep_markdown(recs);
  EXPECT_NE(md.find("| ode | 1 % | ode | engines.ode.timestep = 0.01 |"), std::string::npos) << md;
  EXPECT_NE(md.find("| 2.00 | dt = 0.0001, 0.001, 0.01 | 1.00 |"), std::string::npos) << md;
  // Duplicated point ids (a line written twice) count once.
  recs.push_back(recs.front());
  EXPECT_EQ(render_sweep_markdown(recs), md);
}

// ---- modelling choices -----------------------------------------------------------------------

TEST(SweepLadders, ModellingChoicesFindWhatMovesTheVerdict) {
  std::vector<SweepRecord> recs;
  long long setup_index = 0;
  const std::vector<double> steps = {1e-3, 5e-4};
  // body_frame: at the coarse step ball_centre does not invert (the regime moves); cone:
  // pyramidal inverts 5 % later; noslip_iterations: 0.5 % apart, within the 1 % threshold.
  const struct {
    std::string setup, a, b;
    std::vector<std::optional<double>> ta, tb;
  } fixtures[] = {
      {"body_frame", "com", "ball_centre", {4.0, 4.0}, {std::nullopt, 4.01}},
      {"cone", "elliptic", "pyramidal", {4.0, 4.0}, {4.1, 4.2}},
      {"noslip_iterations", "0", "10", {4.0, 4.0}, {4.01, 4.02}},
  };
  for (const auto& f : fixtures) {
    for (long long k = 0; k < 2; ++k) {
      SweepRecord a = choice_point(f.setup, 0, f.a, k, steps[k], f.ta[k]);
      SweepRecord b = choice_point(f.setup, 1, f.b, k, steps[k], f.tb[k]);
      if (f.setup == "noslip_iterations") a.grid_value = 0, b.grid_value = 10;
      a.setup_index = b.setup_index = setup_index;
      recs.push_back(a);
      recs.push_back(b);
    }
    ++setup_index;
  }
  const std::vector<ChoiceEffect> effects = modelling_choices(recs);
  ASSERT_EQ(effects.size(), 3u);
  const ChoiceEffect& frame = effects[0];
  EXPECT_EQ(frame.key, "engines.mujoco.body_frame");
  EXPECT_EQ(frame.values, (std::vector<std::string>{"com", "ball_centre"}));
  EXPECT_EQ(frame.steps, 2u);
  EXPECT_TRUE(frame.regime_moves);
  EXPECT_EQ(frame.regime_at, "timestep = 0.001");
  EXPECT_EQ(frame.regime_steps, 1u);
  EXPECT_EQ(frame.regime_outcomes,
            (std::vector<std::string>{"com: inverts at 4 (the reference's regime)", "ball_centre: does not invert"}));
  EXPECT_TRUE(frame.moves());
  const ChoiceEffect& cone = effects[1];
  EXPECT_FALSE(cone.regime_moves);
  ASSERT_TRUE(cone.largest_spread);
  EXPECT_NEAR(*cone.largest_spread, 0.05, 1e-12);
  EXPECT_EQ(cone.spread_at, "timestep = 0.0005");
  EXPECT_TRUE(cone.time_moves());
  const ChoiceEffect& noslip = effects[2];
  EXPECT_FALSE(noslip.regime_moves);
  ASSERT_TRUE(noslip.largest_spread);
  EXPECT_NEAR(*noslip.largest_spread, 0.005, 1e-12);
  EXPECT_FALSE(noslip.moves());

  const std::string md = render_sweep_markdown(recs);
  EXPECT_NE(md.find("## Modelling choices"), std::string::npos) << md;
  EXPECT_NE(md.find("mujoco: body_frame moves it (s (body_frame): the regime at timestep = 0.001 (1 of 2 steps)). cone moves it (s "
                    "(cone): the inversion time by 5 % at timestep = 0.0005). noslip_iterations does not move the "
                    "verdict (s (noslip_iterations): within 0.5 %)."),
            std::string::npos)
      << md;
  EXPECT_NE(md.find("| mujoco | s | inverts at 10 | body_frame | engines.mujoco.body_frame | com, ball_centre | moves the regime | at "
                    "timestep = 0.001 (1 of 2 steps): com: inverts at 4 (the reference's regime); ball_centre: does not invert;"),
            std::string::npos)
      << md;
  EXPECT_NE(md.find("| moves the inversion time by 5 % | largest: inversion times 5 % apart at timestep = 0.0005 "
                    "(elliptic 4, pyramidal 4.2) |"),
            std::string::npos)
      << md;
  EXPECT_NE(md.find("| noslip_iterations | engines.mujoco.noslip_iterations | 0, 10 | does not move the verdict |"),
            std::string::npos)
      << md;
  // One line per grid value wherever the report walks a ladder.
  EXPECT_NE(md.find("| cone cone=pyramidal | mujoco |"), std::string::npos) << md;
  EXPECT_NE(md.find("| s, cone=pyramidal |"), std::string::npos) << md;
  // A sweep without choices has no such section.
  std::vector<SweepRecord> plain = {point("ode", "ode", 1e-3, 1, 0.01)};
  plain[0].scene = "s";
  EXPECT_EQ(render_sweep_markdown(plain).find("Modelling choices"), std::string::npos);
}

TEST(SweepAnalysis, ThePageNamesTheEnergyItsGainRuleCounted) {
  // The page's one "safe" says how its records counted a gain: the one rule they share, with the
  // energy it counts; every rule when they differ; records from before the rule was named, total.
  std::vector<SweepRecord> rs = {point("ode", "ode", 1e-3, 1, 0.01), point("ode", "ode", 1e-4, 1, 0.01)};
  for (SweepRecord& r : rs) r.metrics.energy_gain_rule = "stored";
  EXPECT_EQ(energy_gain_rules_text(rs),
            "counting E plus the elastic energy the contact stores where the engine's contact law gives it "
            "(energy_gain_rule = stored)");
  rs[1].metrics.energy_gain_rule = "ledger";
  EXPECT_EQ(energy_gain_rules_text(rs), "counting energy by each record's energy_gain_rule (ledger, stored)");
  rs[0].metrics.energy_gain_rule.clear();
  rs[1].metrics.energy_gain_rule.clear();
  EXPECT_EQ(energy_gain_rules_text(rs), "counting E itself (energy_gain_rule = total)");
  for (SweepRecord& r : rs) {
    r.scene = "s";
    r.metrics.energy_gain_rule = "stored";
  }
  EXPECT_NE(render_sweep_markdown(rs).find("(energy_gain_rule = stored)"), std::string::npos) << render_sweep_markdown(rs);
}

}  // namespace test_sweep_analysis
