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

std::vector<std::string> engines_of(const std::vector<SceneGroup>& scenes) {
  std::vector<std::string> engines;
  for (const SceneGroup& s : scenes)
    for (const SetupGroup& u : s.setups)
      if (std::find(engines.begin(), engines.end(), u.engine) == engines.end()) engines.push_back(u.engine);
  return engines;
}

SettingToUse setting_to_use(const SceneGroup& s, const std::string& e) {
  SettingToUse out;
  std::vector<SweepRecord> usable_points;
  for (const SetupGroup& u : s.setups)
    if (u.engine == e)
      for (const SweepRecord& r : u.points) {
        out.found = true;
        if (recommendable(r)) usable_points.push_back(r);
      }
  if (!out.found) return out;
  if (s.reference_inversion) {
    long long i = cheapest_below(usable_points, 0.01);
    if (i >= 0) {
      out.point = usable_points[static_cast<size_t>(i)];
      out.tier = "1pct";
      out.why = "the cheapest below 1 %: " + pct(std::abs(*out.point->metrics.inversion_time_rel_error));
    } else if ((i = cheapest_below(usable_points, 0.1)) >= 0) {
      out.point = usable_points[static_cast<size_t>(i)];
      out.tier = "10pct";
      out.why = "none reaches 1 %; the cheapest below 10 %: " + pct(std::abs(*out.point->metrics.inversion_time_rel_error));
    } else {
      out.why = "no point within 10 % of the reference's inversion time";
    }
  } else {
    const SweepRecord* best = nullptr;
    for (const SweepRecord& r : usable_points)
      if (r.status == "ok" && agrees_with_reference_regime(r) && std::isfinite(r.cpu_seconds) &&
          (!best || r.cpu_seconds < best->cpu_seconds))
        best = &r;
    if (best) {
      out.point = *best;
      out.tier = "regime";
      out.why = "the cheapest in the reference's regime";
    } else {
      out.why = "no finished point in the reference's regime";
    }
  }
  return out;
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
        if (u.engine == e)
          for (const SweepRecord& r : u.points) mine.push_back(r);
      if (mine.empty()) continue;
      size_t a = 0;
      for (const SweepRecord& r : mine) {
        a += agrees_with_reference_regime(r) && recommendable(r);
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
                      g3(u.point->cpu_seconds) + " CPU s)");
      else
        use.push_back("on " + s.name + " none (" + u.why + ")");
    }
    std::string t = e + ": in the reference's regime at " + std::to_string(agree) + " of " + std::to_string(total) +
                    " points (" + join_list(per_scene, ", ") + "); ";
    t += lo <= hi ? "inversion-time error " + (lo == hi ? pct(lo) : pct(lo) + " to " + pct(hi)) + " where both invert"
                  : "no point where both invert";
    t += "; setting to use: " + join_list(use, "; ") + ".";
    out.push_back(t);
  }
  return out;
}

}  // namespace tippe::sweep_report_detail
