// The sweep page's opening verdict: one sentence per engine from the records alone (its regime, its inversion-time error, the setting to use).
#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "report/sweep_groups.h"
#include "report/sweep_analysis.h"

namespace tippe::sweep_report_detail {

namespace {
constexpr double kInfinity = std::numeric_limits<double>::infinity();
}  // namespace

// sweep_groups.h says what each sentence holds.
std::vector<std::string> sweep_verdicts(const std::vector<SceneGroup>& scenes) {
  std::vector<std::string> engines;
  for (const SceneGroup& s : scenes)
    for (const SetupGroup& u : s.setups)
      if (std::find(engines.begin(), engines.end(), u.engine) == engines.end()) engines.push_back(u.engine);
  std::vector<std::string> out;
  for (const std::string& e : engines) {
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
      const auto pick = [&](const SweepRecord& r, const std::string& why) {
        use.push_back("on " + s.name + " " + r.setup + " " + short_setting(r) + " (" + why + ", " + g3(r.cpu_seconds) +
                      " CPU s)");
      };
      if (s.reference_inversion) {
        long long i = cheapest_safe(mine, setting_criterion(true, 0.01));
        if (i >= 0) {
          const SweepRecord& r = mine[static_cast<size_t>(i)];
          pick(r, "the cheapest safe within 1 %: " + pct(std::abs(*r.metrics.inversion_time_rel_error)));
        } else if ((i = cheapest_safe(mine, setting_criterion(true, 0.1))) >= 0) {
          const SweepRecord& r = mine[static_cast<size_t>(i)];
          pick(r, "none safe within 1 %; the cheapest safe within 10 %: " +
                      pct(std::abs(*r.metrics.inversion_time_rel_error)));
        } else {
          use.push_back("on " + s.name + " none (no safe point within 10 % of the reference's inversion time)");
        }
      } else {
        const long long i = cheapest_safe(mine, regime);
        if (i >= 0) pick(mine[static_cast<size_t>(i)], "the cheapest safe: in the reference's regime");
        else use.push_back("on " + s.name + " none (no safe point in the reference's regime)");
      }
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
