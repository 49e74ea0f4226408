// The sweep report's "Modelling choices" section: which choice axes move each engine's verdict on each scene.
#include "harness/report/sweep_choices.h"

#include <algorithm>
#include <string>
#include <vector>

#include "harness/report/sweep_analysis.h"
#include "harness/report/sweep_groups.h"

namespace tippe {

using namespace sweep_report_detail;

namespace {

// A spread as a percentage; one below 1e-5 % of a time is rounding, said as such.
std::string spread_text(double v) {
  if (v == 0) return "0 %";
  if (v < 1e-7) return "< 1e-5 %";
  return pct(v);
}

std::string choice_verdict(const ChoiceEffect& e) {
  if (e.regime_moves) return "moves the regime";
  if (e.time_moves()) return "moves the inversion time by " + spread_text(*e.largest_spread);
  if (e.steps == 0) return "not compared (no step at which two of its values ran)";
  return "does not move the verdict";
}

// "at STEP" of the first step at which the regime differs, and at how many it does.
std::string regime_where(const ChoiceEffect& e) {
  if (e.regime_at.empty()) return "";
  if (e.steps > 1 && e.regime_steps == e.steps) return "at every step (" + std::to_string(e.steps) + ")";
  return "at " + e.regime_at +
         (e.steps > 1 ? " (" + std::to_string(e.regime_steps) + " of " + std::to_string(e.steps) + " steps)" : "");
}

std::string choice_detail(const ChoiceEffect& e) {
  const std::string at_regime = e.regime_at.empty() ? "" : regime_where(e) + ": ";
  const std::string at_spread = e.spread_at.empty() ? "" : " at " + e.spread_at;
  std::string spread = e.largest_spread ? "inversion times " + spread_text(*e.largest_spread) + " apart" + at_spread + " (" +
                                              join_list(e.spread_times, ", ") + ")"
                                        : std::string();
  if (e.regime_moves) return at_regime + join_list(e.regime_outcomes, "; ") + (spread.empty() ? "" : "; " + spread);
  if (!spread.empty()) return (e.time_moves() ? "largest: " : "the same regime at every step; largest: ") + spread;
  if (e.steps == 0) return "-";
  return "the same regime at every step; no step at which two of its values invert";
}

}  // namespace

// Which choices (grid values, or a ladder of non-numbers) move the verdict on each scene.
void choices_section(const std::vector<SweepRecord>& records, Document& doc) {
  const std::vector<ChoiceEffect> effects = modelling_choices(records);
  if (effects.empty()) return;
  doc.heading(2, "Modelling choices");
  doc.para("For each setup with a choice axis (its grid, or a ladder of non-numbers) on each scene: its values "
                 "compared at the same value of the other axis (the time step). A choice moves the verdict when, at "
                 "some step, its values give different regimes (one inverts, another does not, or a run ends early) "
                 "or inversion times more than " +
                     pct(kChoiceTimeThreshold) +
                     " apart; the spread is (largest - smallest) / smallest of the inversion times at that step, the "
                     "largest over the steps.");
  // Per engine: every choice key, and what it does on each scene.
  std::vector<std::string> engines;
  for (const ChoiceEffect& e : effects)
    if (std::find(engines.begin(), engines.end(), e.engine) == engines.end()) engines.push_back(e.engine);
  for (const std::string& engine : engines) {
    std::vector<std::string> keys;
    for (const ChoiceEffect& e : effects)
      if (e.engine == engine && std::find(keys.begin(), keys.end(), e.key) == keys.end()) keys.push_back(e.key);
    std::vector<std::string> parts;
    for (const std::string& key : keys) {
      std::vector<std::string> moves, stays;
      for (const ChoiceEffect& e : effects) {
        if (e.engine != engine || e.key != key) continue;
        const std::string where = e.scene + (e.setup.empty() ? "" : " (" + e.setup + ")");
        if (e.regime_moves)
          moves.push_back(where + ": the regime" + (e.regime_at.empty() ? "" : " " + regime_where(e)) +
                          (e.time_moves() ? ", and the inversion time by " + spread_text(*e.largest_spread) : ""));
        else if (e.time_moves())
          moves.push_back(where + ": the inversion time by " + spread_text(*e.largest_spread) +
                          (e.spread_at.empty() ? "" : " at " + e.spread_at));
        else
          stays.push_back(where + (e.largest_spread ? ": within " + spread_text(*e.largest_spread)
                                   : e.steps ? ": the same regime, never two inversions to compare"
                                             : ": not compared"));
      }
      std::string t = last_part(key) + " ";
      if (moves.empty())
        t += "does not move the verdict (" + join_list(stays, "; ") + ")";
      else
        t += "moves it (" + join_list(moves, "; ") + ")" +
             (stays.empty() ? "" : "; not on " + join_list(stays, "; "));
      parts.push_back(t);
    }
    doc.para(engine + ": " + join_list(parts, ". ") + ".");
  }
  DocTable t;
  t.header = {"engine", "scene", "reference", "setup", "choice", "values", "verdict", "detail"};
  for (const ChoiceEffect& e : effects) {
    const std::vector<std::string> cells = {
        e.engine, e.scene, e.reference_inversion ? "inverts at " + fmt("%.5g", *e.reference_inversion) : "does not invert",
        e.setup,  e.key,   join_list(e.values, ", "), choice_verdict(e), choice_detail(e)};
    std::vector<DocCell> row;
    for (const std::string& c : cells) row.push_back({c, std::string()});
    t.rows.push_back(row);
  }
  doc.table(t);
}


}  // namespace tippe
