// The verdict the index of published comparisons opens with: the matrix of scenes and engines (each cell the engine's verdict on that scene) and one short sentence per engine, from every scene's comparison.json.
#include <algorithm>
#include <cmath>
#include <map>
#include <string>
#include <vector>

#include "harness/report/report.h"
#include "harness/report/report_text.h"

namespace tippe {

using namespace report_text;

namespace {

// A time in the scene's units: "16.4 s" for SI scenes, "t = 16.4" otherwise.
std::string time_at(const nlohmann::json& scene, double t) {
  return scene_units(scene).time == "s" ? fmt(t, "%.4g") + " s" : "t = " + fmt(t, "%.4g");
}

std::string signed_pct(double rel) { return (rel >= 0 ? "+" : "") + fmt(100 * rel, "%.3g") + " %"; }

}  // namespace

const std::vector<std::string>& verdict_kinds() {
  static const std::vector<std::string> kinds = {"1pct", "10pct", "beyond", "regime", "wrong", "failed"};
  return kinds;
}

std::string verdict_kind_text(const std::string& kind) {
  if (kind == "1pct") return "the reference's regime, inversion time within 1 %";
  if (kind == "10pct") return "the reference's regime, within 10 %";
  if (kind == "beyond") return "the reference's regime, more than 10 % off";
  if (kind == "regime") return "the reference's regime, neither inverts";
  if (kind == "wrong") return "the wrong regime";
  if (kind == "failed") return "ended early (failed)";
  return kind;
}

std::string verdict_colour_name(const std::string& kind) {
  if (kind == "1pct") return "dark green";
  if (kind == "regime") return "light green";
  if (kind == "10pct") return "amber";
  if (kind == "beyond") return "orange";
  if (kind == "wrong") return "red";
  return "grey";
}

VerdictCell verdict_cell(const nlohmann::json& comparison, const nlohmann::json& engine) {
  const nlohmann::json& scene = comparison.at("scene");
  const nlohmann::json& ref = comparison.at("reference").at("summary");
  const nlohmann::json& s = engine.at("summary");
  const bool ref_inverts = has_number(ref, "inversion_time");
  const bool inverts = has_number(s, "inversion_time");
  const bool ok = str(s, "status") == "ok";
  VerdictCell v;
  // The same partition as index_verdicts: in the regime when it inverts as the reference does
  // (an engine that inverted and then ended early keeps that inversion), else ended early, else wrong.
  if (inverts == ref_inverts && (ok || inverts)) {
    const double rel = num(engine.at("metrics"), "inversion_time_rel_error");
    if (!ref_inverts) {
      v.kind = "regime";
      v.text = "rolls to " + time_at(scene, num(s, "final_time")) + ", as the reference";
    } else if (!std::isfinite(rel)) {
      v.kind = "regime";
      v.text = "inverts at " + time_at(scene, num(s, "inversion_time")) + " (error not measured)";
    } else {
      v.kind = std::abs(rel) < 0.01 ? "1pct" : std::abs(rel) < 0.1 ? "10pct" : "beyond";
      v.text = signed_pct(rel);
    }
    if (!ok) v.text += "; then " + str(s, "status") + " at " + time_at(scene, num(s, "status_time"));
  } else if (!ok) {
    v.kind = "failed";
    v.text = str(s, "status") + " at " + time_at(scene, num(s, "status_time"));
  } else {
    v.kind = "wrong";
    v.text = inverts ? "inverts at " + time_at(scene, num(s, "inversion_time")) + "; the reference rolls"
                     : "rolls; the reference inverts at " + time_at(scene, num(ref, "inversion_time"));
  }
  return v;
}

std::vector<std::string> index_verdicts(const std::vector<nlohmann::json>& comparisons) {
  struct Tally {
    std::map<std::string, size_t> kinds;
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
      ++t.kinds[verdict_cell(c, e).kind];
      const bool inverts = has_number(e.at("summary"), "inversion_time");
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
  auto pct = [](double v) { return fmt(100 * v, "%.3g") + " %"; };
  std::vector<std::string> out;
  for (const std::string& engine : order) {
    Tally& t = tally[engine];
    size_t n = 0;
    for (const auto& [kind, count] : t.kinds) n += count;
    const size_t in_regime = t.kinds["1pct"] + t.kinds["10pct"] + t.kinds["beyond"] + t.kinds["regime"];
    std::string s = engine + ": the reference's regime on " + std::to_string(in_regime) + " of " + std::to_string(n) +
                    " scenes";
    if (t.kinds["wrong"]) s += ", the wrong regime on " + std::to_string(t.kinds["wrong"]);
    if (t.kinds["failed"]) s += ", ended early on " + std::to_string(t.kinds["failed"]);
    s += t.both_invert ? "; inversion-time error " + (t.both_invert == 1 ? pct(t.hi) : pct(t.lo) + " to " + pct(t.hi)) +
                             " where both invert (" + std::to_string(t.both_invert) + " scene" +
                             (t.both_invert == 1 ? "" : "s") + ", largest on " + t.worst + ")"
                       : "; no scene where both invert";
    out.push_back(s + ".");
  }
  return out;
}

}  // namespace tippe
