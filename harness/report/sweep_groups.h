// What the sweep report's files share: the records grouped by scene and setup, the text of settings, and the charts (sweep_charts.cpp).
#pragma once

#include <cstdio>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "sweep.h"

namespace tippe::sweep_report_detail {

inline std::string fmt(const char* f, double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, f, v);
  return buf;
}
inline std::string last_part(const std::string& key) { return key.substr(key.rfind('.') + 1); }

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

}  // namespace tippe::sweep_report_detail
