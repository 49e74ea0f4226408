// Boundary searches in sweeps (`ladder.search`): the file form, the coarse grid, the bisection replayed from records, and the boundaries found.
#pragma once

#include <functional>
#include <optional>
#include <string>
#include <vector>

#include <toml++/toml.h>

#include "harness/sweep/sweep.h"

namespace tippe {

// ---- the file form ----------------------------------------------------------------------------

// The bisection points of a search's b-th crossing bracket have ladder indices
// coarse + b * kSearchIndexStride + step: fixed by the bracket and the step, whatever the order in
// which brackets finish, so that a resumed or sharded search gives every point the same index. A
// bracket is at most one coarse interval, 1 decade: ceil(log2(1 / 1e-3)) = 10 steps.
constexpr long long kSearchIndexStride = 64;

// Reads `where` = {key, from, to, criterion, resolution, per_decade} (resolution 0.05 and
// per_decade 1 by default) into a search and its key; throws SceneError "FILE: KEY: reason".
// Rules: key a string; 0 < from < to finite, at most kMaxSearchDecades decades apart; criterion
// "regime" or "METRIC <= BOUND" (parse_threshold_text, the gate's [check.max] rules);
// kMinSearchResolution <= resolution <= kMaxSearchResolution; 1 <= per_decade <= kMaxSearchPerDecade.
SweepSearch read_search(const toml::node& node, const std::string& file, const std::string& where, std::string& key);

// ---- the search, replayed ---------------------------------------------------------------------

// A value as a search writes it: 6 significant digits, so that every run of the search (resumed,
// on another rank, with another libm's pow) lands on the very same values and point ids.
double search_round(double v);
std::string search_value_text(double v);  // as the ladder's text and label (JSON's shortest form)
// from, then equal steps in log10 up to to, at least per_decade per decade; from and to exact.
std::vector<double> search_coarse_grid(const SweepSearch& s);

struct SearchStep {
  double value = 0;
  long long ladder_index = 0;
};
// A change of the criterion between two neighbouring values, narrowed by bisection.
struct SearchCrossing {
  double lo = 0, hi = 0;  // lo < hi
  bool lo_passes = false;  // the criterion at lo; at hi it is the opposite
  bool resolved = false;   // log10(hi / lo) < resolution: the bisection is done
  size_t steps = 0;        // bisection points run in this bracket
};
struct SearchReplay {
  std::vector<double> coarse;
  std::vector<std::optional<bool>> coarse_passes;  // nullopt: not run yet
  std::vector<SearchStep> known;  // points with an outcome that the search used, coarse first
  std::vector<SearchStep> next;   // points to run next (one per open bracket, or the missing coarse ones)
  std::vector<SearchCrossing> crossings;  // increasing in value; complete only when coarse_complete()
  bool coarse_complete() const;
  bool finished() const { return next.empty(); }
};
// The search from what is known: `outcome(value_text)` is the criterion at that value, nullopt when
// not run. Every crossing of the coarse grid is bisected (in log10, midpoints rounded by
// search_round) until narrower than the resolution; a pure function, so that a resumed search
// replays to the same points.
SearchReplay replay_search(const SweepSearch& s, const std::function<std::optional<bool>(const std::string&)>& outcome);

// ---- planning waves ---------------------------------------------------------------------------

// A bisection point a search needs and the plan does not have yet.
struct SearchPoint {
  size_t scene_index = 0, setup_index = 0, grid_index = 0;
  long long ladder_index = 0;
  double value = 0;
};
bool has_search(const SweepPlan& plan);
// The points every search of `plan` needs next given `records` (those of the plan's points; others
// are ignored), that `plan` does not have: the replay of each search from its records. Pure.
std::vector<SearchPoint> search_frontier(const SweepPlan& plan, const std::vector<SweepRecord>& records);
// Adds them to plan.points (scene loaded with every override), after the planned points.
void add_search_points(SweepPlan& plan, const std::vector<SearchPoint>& points);
// Text form of a wave, as the coordinator sends it to every rank.
std::string encode_search_points(const std::vector<SearchPoint>& points);
std::vector<SearchPoint> decode_search_points(const std::string& text);
// search_frontier then add_search_points until nothing is added: the plan a directory's records
// imply (a resumed search, a merged one). Returns the number of points added.
size_t extend_search_plan(SweepPlan& plan, const std::vector<SweepRecord>& records);

// ---- boundaries (pure functions of records) ---------------------------------------------------

// "max_safe_timestep" for a key whose larger values are softer (larger_is_softer), else
// "min_safe_ITERATIONS": the last part of the key after the prefix.
std::string boundary_quantity(const std::string& key);

// One search's result: the safe side is walked from the finest setting towards softer ones; the
// boundary is the last safe value before the first crossing (with the first unsafe value beyond
// it: the bracket). Every crossing is listed: more than one means the criterion is not monotonic
// in the setting (a regime that comes and goes), and the boundary is then the first from the fine
// end, which is the conservative one.
struct SearchBoundary {
  std::string scene, setup, engine, key, grid_key, grid_label, criterion;
  long long scene_index = 0, setup_index = 0, grid_index = 0;
  SweepSearch search;
  SearchReplay replay;
  size_t runs = 0;
  // found: a boundary inside the range; all_safe: every value passes (the boundary is at least the
  // range's soft end); none_safe: even the finest fails; incomplete: the search has not finished;
  // not_applicable: a criterion on the inversion where the reference does not invert.
  std::string status;
  std::optional<double> boundary, beyond;  // the last safe value; the first unsafe one after it
  std::optional<double> cpu_seconds;       // of the run at the boundary
  std::string quantity;                    // boundary_quantity(key)
  bool monotonic() const { return replay.crossings.size() <= 1; }
};
// One per search (scene, setup, grid value) with records, in sweep order.
std::vector<SearchBoundary> search_boundaries(const std::vector<SweepRecord>& records);
// The report's section, as parts the sweep report renders (Markdown and HTML): "Largest safe
// setting per engine" across scenes, then each search with its bracket, runs, cost and crossings.
// Empty when the records hold no search.
struct ReportPart {
  enum Kind { H2, H3, Para, Tab } kind = Para;
  std::string text;
  std::vector<std::string> header;
  std::vector<std::vector<std::string>> rows;
};
std::vector<ReportPart> boundary_report(const std::vector<SweepRecord>& records);

// ---- running ----------------------------------------------------------------------------------

// A sweep with boundary searches, wave by wave: extend the plan from the records in OUT (the
// coordinator decides, every rank gets the same points), run what is missing (run_sweep, no
// report), until no search needs another point; then the report. Without a search it is run_sweep.
// Resumes like any sweep: the records replay to the same plan.
SweepOutcome run_search_sweep(SweepPlan plan, const SweepOptions& options, TaskFarm& farm);
SweepOutcome run_search_sweep(SweepPlan plan, const SweepOptions& options);

}  // namespace tippe
