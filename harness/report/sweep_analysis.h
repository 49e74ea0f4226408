// The analysis of a sweep's records for its report: convergence orders, the cheapest and softest settings, regime trends, modelling choices.
#pragma once

#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "harness/records/sweep_record.h"

namespace tippe {

// Empirical order of convergence: least-squares slope of log(error) against log(h) over the
// asymptotic range, found as the longest run of consecutive points (in h) whose local slopes are
// all >= 0.5 (the error really falls with h: a floor or saturation is left out) and within
// max(0.25, 0.15 p) of the fitted slope p; ties go to the smaller residual, then the finer points.
struct ConvergenceFit {
  bool ok = false;  // at least two points in the range
  double order = 0;
  std::vector<size_t> used;  // indices into the input, in increasing h
  std::string note;          // why not, or "only 2 points"
};
// h and error of the same length; non-finite or non-positive pairs are ignored.
ConvergenceFit convergence_order(const std::vector<double>& h, const std::vector<double>& error);

// The cheapest point (least cpu_seconds; ties: fewer steps) among `records` that is_safe under
// `c` (the one criterion of "safe", sweep_record.h); -1 when none.
long long cheapest_safe(const std::vector<SweepRecord>& records, const SearchCriterion& c);
// Costs this bench does not tell apart: two CPU times (each a point's minimum over its repeats)
// within 10 % of each other. Measured: one run repeated alone 265 times took 0.232-0.387 CPU s
// (slow spells of 1.5x, seconds long); the minimum of three runs spread 30 s apart, as a sweep's
// interleaved repeats are, ranged 0.232-0.250 (7.8 %), that of three back to back 0.232-0.333
// (BENCHMARKS.md, "A point's repeats").
inline constexpr double kCostResolution = 0.10;
// Whether a CPU time is not told apart from the cheapest's: cpu <= cheapest * (1 + kCostResolution).
inline bool within_cost_resolution(double cpu, double cheapest) { return cpu <= cheapest * (1 + kCostResolution); }
// The other points of `records` safe under `c` whose CPU time is within kCostResolution of
// records[best]'s (best: cheapest_safe's answer), cheapest first; empty when best < 0. The
// cheapest is the answer; these are named beside it, as the machine's noise could have chosen them.
std::vector<size_t> cost_ties(const std::vector<SweepRecord>& records, long long best, const SearchCriterion& c);
// The criterion the sweep page's "setting to use" applies on a scene: where the reference inverts,
// the inversion within `tolerance`; where it does not, the reference's regime.
SearchCriterion setting_criterion(bool reference_inverts, double tolerance);
// cheapest_safe with the inversion within `threshold` (|inversion_time_rel_error| <= threshold,
// the run finished and classed ok); -1 when none.
long long cheapest_below(const std::vector<SweepRecord>& records, double threshold);
// The cheapest point with status ok and |inversion_time_rel_error| <= error; -1 when none.
long long cheapest_at_least_as_accurate(const std::vector<SweepRecord>& records, double error);

// One setup's points: walking from the finest setting to softer ones, the softest reached before
// the first point that is not safe in the reference's regime (is_safe, "regime"); -1 when even the finest disagrees or there are
// no points. Indices into `records`.
long long softest_agreeing(const std::vector<SweepRecord>& records);
// Where the reference does not invert and a time-step ladder's runs leave its regime (they
// invert): how that departure behaves as the step shrinks, read from the finished runs (status
// ok) finest last. "goes away": the finest runs are in the regime (from `in_regime_from` down);
// "converges": every finished run inverts and the two finest within 1 % of each other (the
// engine's model, not its step); "moves later": every finished run inverts, each finer one no
// earlier than 1 % before the next coarser, the two finest apart; "earlier at a finer step":
// neither; "none": no finished run leaves the regime; "mixed": the regime comes and goes along
// the ladder; "-": not a time-step ladder, the reference inverts, or
// fewer than two finished runs. The answer holds up to the runs' horizon only.
struct RegimeTrend {
  std::string verdict;
  std::optional<double> in_regime_from;                   // the coarsest step of the finest run of agreeing points
  std::vector<std::pair<double, double>> inversion_by_step;  // (step, inversion time), coarsest first
};
RegimeTrend regime_trend(const std::vector<SweepRecord>& records);

// "Modelling choices": what a choice axis (a setup's grid, or a ladder of non-numbers) does to the
// verdict on one scene. At each value of the other axis (the step; a one-axis setup has one), the
// choice's values are compared: the regime (inverts, does not invert, ends early) and, where
// two or more invert, the relative spread of their inversion times, (max - min) / min.
constexpr double kChoiceTimeThreshold = 0.01;  // a spread above this moves the verdict
struct ChoiceEffect {
  std::string scene, setup, engine;
  std::string key, at_key;          // the choice axis; the other one ("" without)
  std::vector<std::string> values;  // the choice's values, in sweep order
  std::optional<double> reference_inversion;  // the reference's, on this scene
  size_t steps = 0;                 // steps at which two or more values ran
  bool regime_moves = false;
  size_t regime_steps = 0;                    // steps at which the regime differs
  std::string regime_at;                      // the first of them
  std::vector<std::string> regime_outcomes;   // there, "VALUE: OUTCOME" for each value ("in the
                                              // reference's regime" added where it is)
  std::optional<double> largest_spread;       // over the steps where two or more invert
  std::string spread_at;                      // the step of the largest spread
  std::vector<std::string> spread_times;      // there, "VALUE T" for each value that inverts
  bool time_moves() const { return largest_spread && *largest_spread > kChoiceTimeThreshold; }
  bool moves() const { return regime_moves || time_moves(); }
};
// One entry per (scene, setup) with a choice axis, in sweep order.
std::vector<ChoiceEffect> modelling_choices(const std::vector<SweepRecord>& records);

// report.md, index.html and (when `plots`) the SVGs, into dir, from the records alone.
// How the records' classes counted an energy gain, for the page's statement of "safe": the
// energy counted and its energy_gain_rule when they share one, else each rule named (records
// written before the rule was named counted E itself).
std::string energy_gain_rules_text(const std::vector<SweepRecord>& records);

void write_sweep_report(const std::string& dir, const std::vector<SweepRecord>& records, bool plots);
std::string render_sweep_markdown(const std::vector<SweepRecord>& records);


}  // namespace tippe
