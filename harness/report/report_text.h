// Small helpers the report pages share: numbers as text, fields of a record read leniently, the units of a scene's axes.
#pragma once

#include <cmath>
#include <cstdio>
#include <string>

#include <nlohmann/json.hpp>

namespace tippe::report_text {

// The report's bands for an event time's relative error (inversion, stem contact) when the
// record states none: green below 1 %, amber below 10 %. The verdict names where the energy went
// for an engine outside the green band.
inline constexpr double kEventTimeGreenBand = 0.01;
inline constexpr double kEventTimeAmberBand = 0.10;

// A number with a printf spec; "-" for NaN and infinities.
inline std::string fmt(double v, const char* spec = "%.4g") {
  if (!std::isfinite(v)) return "-";
  char buf[64];
  std::snprintf(buf, sizeof buf, spec, v);
  return buf;
}
inline bool has_number(const nlohmann::json& j, const char* key) { return j.contains(key) && j.at(key).is_number(); }
inline double num(const nlohmann::json& j, const char* key) {
  return has_number(j, key) ? j.at(key).get<double>() : std::nan("");
}
inline std::string str(const nlohmann::json& j, const char* key) {
  return j.contains(key) && j.at(key).is_string() ? j.at(key).get<std::string>() : std::string();
}

// A run's status for a table: "ok", or the status and when it ended.
inline std::string status_text(const nlohmann::json& summary) {
  const std::string status = str(summary, "status");
  if (status == "ok") return status;
  return status + " at t=" + fmt(num(summary, "status_time"), "%.6g");
}
// The time a run's record ends at.
inline std::string run_time_text(const nlohmann::json& s) { return fmt(num(s, "final_time"), "%.6g"); }

// The units of a scene's time and length, from what the comparison record holds (gravity and
// the ball radius; records carry no unit names). g = 9.81 within 1 %: SI (s, m). g = 1 and R = 1:
// the source's dimensionless top, time in units of sqrt(R/g) and length in R. Anything else:
// "scene units", said as such rather than guessed.
struct SceneUnits {
  std::string time, length;
};
inline SceneUnits scene_units(const nlohmann::json& scene) {
  const double g = num(scene, "gravity");
  const double R = scene.contains("body") ? num(scene.at("body"), "sphere_radius") : std::nan("");
  if (std::isfinite(g) && std::abs(g - 9.81) <= 0.01 * 9.81) return {"s", "m"};
  if (g == 1.0 && R == 1.0) return {"units of √(R/g)", "R"};
  return {"scene time units", "scene length units"};
}

}  // namespace tippe::report_text
