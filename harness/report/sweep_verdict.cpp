// The sweep page's opening verdict: one sentence per engine from the records alone (its regime, its inversion-time error, the setting to use).
#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "harness/report/sweep_groups.h"
#include "harness/report/sweep_analysis.h"

namespace tippe::sweep_report_detail {

namespace {
constexpr double kInfinity = std::numeric_limits<double>::infinity();
}  // namespace

std::vector<std::string> engines_of(const std::vector<SceneGroup>& scenes) {
  std::vector<std::string> engines;
  for (const SceneGroup& s : scenes)
    for (const SetupGroup& u : s.setups)
      if (std::find(engines.begin(), engines.end(), u.engine) == engines.end()) engines.push_back(u.engine);
  return engines;
}

// The one criterion of "safe" (is_safe, through cheapest_safe): the boundary search's, the gates'
// and advise's, so the same records can give no other setting here.
SettingToUse setting_to_use(const SceneGroup& s, const std::string& e) {
  SettingToUse out;
  std::vector<SweepRecord> mine;
  for (const SetupGroup& u : s.setups)
    if (u.engine == e) mine.insert(mine.end(), u.points.begin(), u.points.end());
  out.found = !mine.empty();
  if (!out.found) return out;
  // The answer under criterion c, and the points the machine's noise could have chosen instead.
  const auto choose = [&](const SearchCriterion& c) {
    const long long i = cheapest_safe(mine, c);
    if (i < 0) return false;
    out.point = mine[static_cast<size_t>(i)];
    for (size_t k : cost_ties(mine, i, c)) out.ties.push_back(mine[k]);
    return true;
  };
  if (s.reference_inversion) {
    if (choose(setting_criterion(true, 0.01))) {
      out.tier = "1pct";
      out.why = "the cheapest safe within 1 %: " + pct(std::abs(*out.point->metrics.inversion_time_rel_error));
    } else if (choose(setting_criterion(true, 0.1))) {
      out.tier = "10pct";
      out.why = "none safe within 1 %; the cheapest safe within 10 %: " +
                pct(std::abs(*out.point->metrics.inversion_time_rel_error));
    } else {
      out.why = "no safe point within 10 % of the reference's inversion time";
    }
  } else {
    if (choose(setting_criterion(false, 0))) {
      out.tier = "regime";
      out.why = "the cheapest safe: in the reference's regime";
    } else {
      out.why = "no safe point in the reference's regime";
    }
  }
  return out;
}

std::string ties_text(const std::vector<SweepRecord>& ties) {
  if (ties.empty()) return "";
  std::vector<std::string> names;
  for (const SweepRecord& r : ties) names.push_back(r.setup + " " + short_setting(r) + " " + g3(r.cpu_seconds) + " s");
  return " (within " + pct(kCostResolution) + " of its CPU time, not told apart: " + join_list(names, "; ") + ")";
}

// sweep_groups.h says what each sentence holds.
std::vector<std::string> sweep_verdicts(const std::vector<SceneGroup>& scenes) {
  std::vector<std::string> out;
  for (const std::string& e : engines_of(scenes)) {
    size_t agree = 0, total = 0;
    double lo = kInfinity, hi = -kInfinity;
    std::vector<std::string> per_scene, use;
    for (const SceneGroup& s : scenes) {
      std::vector<SweepRecord> mine;
      for (const SetupGroup& u : s.setups)
        if (u.engine == e) mine.insert(mine.end(), u.points.begin(), u.points.end());
      if (mine.empty()) continue;
      // Every count and choice below is the one criterion of "safe" (is_safe), the boundary
      // search's and the gates': the same records can give no other answer here.
      const SearchCriterion regime = setting_criterion(false, 0);
      size_t a = 0;
      for (const SweepRecord& r : mine) {
        a += is_safe(regime, r);
        if (r.metrics.inversion_event == "both" && r.metrics.inversion_time_rel_error &&
            std::isfinite(*r.metrics.inversion_time_rel_error)) {
          lo = std::min(lo, std::abs(*r.metrics.inversion_time_rel_error));
          hi = std::max(hi, std::abs(*r.metrics.inversion_time_rel_error));
        }
      }
      agree += a;
      total += mine.size();
      per_scene.push_back(s.name + " " + std::to_string(a) + "/" + std::to_string(mine.size()));
      const SettingToUse u = setting_to_use(s, e);
      if (u.point)
        use.push_back("on " + s.name + " " + u.point->setup + " " + short_setting(*u.point) + " (" + u.why + ", " +
                      g3(u.point->cpu_seconds) + " CPU s)" + ties_text(u.ties));
      else
        use.push_back("on " + s.name + " none (" + u.why + ")");
    }
    std::string t = e + ": safe in the reference's regime at " + std::to_string(agree) + " of " + std::to_string(total) +
                    " points (" + join_list(per_scene, ", ") + "); ";
    t += lo <= hi ? "inversion-time error " + (lo == hi ? pct(lo) : pct(lo) + " to " + pct(hi)) + " where both invert"
                  : "no point where both invert";
    t += "; setting to use: " + join_list(use, "; ") + ".";
    out.push_back(t);
  }
  return out;
}

}  // namespace tippe::sweep_report_detail
