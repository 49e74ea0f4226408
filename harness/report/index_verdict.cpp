// The verdict the index of published comparisons opens with: one sentence per engine over every scene's comparison.json.
#include <algorithm>
#include <cmath>
#include <map>
#include <string>
#include <vector>

#include "report/report.h"
#include "report/report_text.h"

namespace tippe {

using namespace report_text;

std::vector<std::string> index_verdicts(const std::vector<nlohmann::json>& comparisons) {
  struct Tally {
    std::vector<std::string> in_regime, out_of_regime, ended_early;
    size_t both_invert = 0;
    double lo = INFINITY, hi = -INFINITY;
    std::string worst;
  };
  std::vector<std::string> order;
  std::map<std::string, Tally> tally;
  for (const nlohmann::json& c : comparisons) {
    const std::string scene = str(c, "scene_name");
    const bool ref_inverts = has_number(c.at("reference").at("summary"), "inversion_time");
    for (const nlohmann::json& e : c.at("engines")) {
      const std::string engine = str(e, "engine");
      if (!tally.count(engine)) order.push_back(engine);
      Tally& t = tally[engine];
      const nlohmann::json& s = e.at("summary");
      const bool inverts = has_number(s, "inversion_time");
      const bool ok = str(s, "status") == "ok";
      if (inverts == ref_inverts && (ok || inverts)) t.in_regime.push_back(scene);
      else if (!ok) t.ended_early.push_back(scene + " (" + str(s, "status") + ")");
      else t.out_of_regime.push_back(scene + (inverts ? " (inverts; the reference does not)" : " (does not invert)"));
      const double rel = num(e.at("metrics"), "inversion_time_rel_error");
      if (ref_inverts && inverts && std::isfinite(rel)) {
        ++t.both_invert;
        t.lo = std::min(t.lo, std::abs(rel));
        if (std::abs(rel) > t.hi) {
          t.hi = std::abs(rel);
          t.worst = scene;
        }
      }
    }
  }
  auto join = [](const std::vector<std::string>& v) {
    std::string s;
    for (const auto& x : v) s += (s.empty() ? "" : ", ") + x;
    return s;
  };
  auto pct = [](double v) { return fmt(100 * v, "%.3g") + " %"; };
  std::vector<std::string> out;
  for (const std::string& engine : order) {
    const Tally& t = tally[engine];
    const size_t n = t.in_regime.size() + t.out_of_regime.size() + t.ended_early.size();
    std::string s = engine + ": the reference's regime on " + std::to_string(t.in_regime.size()) + " of " +
                    std::to_string(n) + " scenes";
    if (!t.out_of_regime.empty()) s += "; the wrong regime on " + join(t.out_of_regime);
    if (!t.ended_early.empty()) s += "; ended early on " + join(t.ended_early);
    s += t.both_invert ? "; inversion-time error " + (t.both_invert == 1 ? pct(t.hi) : pct(t.lo) + " to " + pct(t.hi)) +
                             " on the " + std::to_string(t.both_invert) + " scene" + (t.both_invert == 1 ? "" : "s") +
                             " where both invert (largest on " + t.worst + ")"
                       : "; no scene where both invert";
    out.push_back(s + ".");
  }
  return out;
}

}  // namespace tippe
