// What the sweep report's files share: the records grouped by scene and setup, the text of settings, and the charts (sweep_charts.cpp).
#pragma once

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "harness/sweep/sweep.h"

namespace tippe::sweep_report_detail {

inline std::string fmt(const char* f, double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, f, v);
  return buf;
}
// A value a log axis can show: finite and positive.
inline bool usable(double v) { return std::isfinite(v) && v > 0; }
inline std::string last_part(const std::string& key) { return key.substr(key.rfind('.') + 1); }
inline std::string g3(double v) { return std::isfinite(v) ? fmt("%.3g", v) : "-"; }
inline std::string pct(double v) { return std::isfinite(v) ? fmt("%.3g", 100 * v) + " %" : "-"; }
inline std::string pct(const std::optional<double>& v) { return v ? pct(*v) : "-"; }
inline std::string time_text(const std::optional<double>& t) { return t ? fmt("%.6g", *t) : "none"; }
inline std::string join_list(const std::vector<std::string>& v, const char* sep) {
  std::string t;
  for (const auto& x : v) t += (t.empty() ? "" : sep) + x;
  return t;
}
inline std::string setting_text(const SweepRecord& r) {
  return r.ladder_key + " = " + ladder_text(r) + (r.grid_key.empty() ? "" : ", " + r.grid_key + " = " + grid_text(r));
}
inline std::string short_setting(const SweepRecord& r) {
  return last_part(r.ladder_key) + " = " + ladder_text(r) +
         (r.grid_key.empty() ? "" : ", " + last_part(r.grid_key) + " = " + grid_text(r));
}

// The records of one scene, grouped by setup in sweep order.
struct SetupGroup {
  std::string name, engine, key;
  std::vector<std::string> set;
  std::vector<SweepRecord> points;  // grid, then ladder order
  std::string grid_key;             // empty: no grid
};

// One line along a setup's ladder: the whole setup, or one grid value of it.
struct Line {
  std::string title;  // "SETUP", or "SETUP KEY=VALUE" (KEY the grid key's last part)
  std::vector<SweepRecord> points;  // ladder order
};
std::vector<Line> lines_of(const SetupGroup& u);

struct SceneGroup {
  std::string name, file;
  double duration = 0;
  std::optional<double> reference_inversion, reference_stem_contact;
  std::vector<SetupGroup> setups;
};
// Records deduplicated by point id, in sweep order, grouped by scene then setup.
std::vector<SceneGroup> group(const std::vector<SweepRecord>& input);

// A chart of one scene: its SVG (named by the scene's place in the sweep, never by a name read
// from the records) and its caption.
struct ChartFile {
  std::string file, caption;
};
// The charts made_charts would draw for scene number `scene` (0-based), in page order.
std::vector<ChartFile> chart_files(const SceneGroup& s, size_t scene);
// Writes the data and one gnuplot script for every chart of every scene with data, runs gnuplot,
// and returns the SVGs that came out; `note` says what is missing.
std::vector<std::string> render_sweep_charts(const std::filesystem::path& dir, const std::vector<SceneGroup>& scenes,
                                             std::string& note);

// The finding the sweep page opens with: one sentence per engine, from the records alone. Its
// points that are safe in the reference's regime (is_safe, "regime"; of its points, per scene),
// its inversion-time error where both invert, and the setting to use on each scene: the cheapest
// point safe with the inversion within 1 % (10 % when none is) where the reference inverts, the
// cheapest safe in the reference's regime where it does not. "Safe" is the one criterion
// (sweep_record.h) the boundary search and the gates use.
std::vector<std::string> sweep_verdicts(const std::vector<SceneGroup>& scenes);

// The setting to use of one engine on one scene, as sweep_verdicts says it: the point (none when
// no point qualifies), how it qualified ("1pct", "10pct": its inversion-time error is below 1 %
// or 10 %; "regime": the cheapest finished point in the reference's regime, where the reference
// does not invert; "none") and why, in words. `found` is false when the engine has no point there.
struct SettingToUse {
  bool found = false;
  std::optional<SweepRecord> point;
  std::string tier = "none";
  std::string why;
  // The engine's other points that qualify the same way at a CPU time within kCostResolution
  // (10 %) of the point's, cheapest first: a cost difference the machine does not resolve.
  std::vector<SweepRecord> ties;
};
SettingToUse setting_to_use(const SceneGroup& s, const std::string& engine);
// " (within 10 % of its CPU time, not told apart: SETUP SETTING 0.29 s; ...)", or "" without ties.
std::string ties_text(const std::vector<SweepRecord>& ties);
// The engines of the records, in the order their setups first appear.
std::vector<std::string> engines_of(const std::vector<SceneGroup>& scenes);

}  // namespace tippe::sweep_report_detail
