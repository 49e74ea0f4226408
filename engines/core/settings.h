// Reading engine settings from a scene's [engines.NAME] table into plain structs, and listing them.
#pragma once

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <set>
#include <sstream>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <vector>

#include "analytic/scene.h"
#include "engines/core/simulator.h"

namespace tippe {

// The shortest text that reads back as exactly v ("0.2", not "0.20000000000000001"): what a
// record or a model file needs to reproduce a number, without the digits it does not have.
// printf's %g at the fewest significant digits that read back exactly: "0.0001" rather than the
// shortest "1e-04", as people write it; whole numbers below 1e17 in full ("1000", not "1e+03").
inline std::string round_trip_text(double v) {
  if (v == 0.0) v = 0.0;  // "-0" reads as 0 anyway; keep the text plain
  char buf[64];
  int digits = 1;
  for (; digits <= 17; ++digits) {
    std::snprintf(buf, sizeof buf, "%.*g", digits, v);
    if (std::strtod(buf, nullptr) == v) break;
  }
  // %g goes to an exponent once the number has more integer digits than significant ones; as
  // many significant digits as integer ones print it plainly, and more digits still read back.
  const int integer_digits = std::isfinite(v) && std::abs(v) >= 1 ? static_cast<int>(std::log10(std::abs(v))) + 1 : 0;
  if (integer_digits > digits && integer_digits <= 17) std::snprintf(buf, sizeof buf, "%.*g", integer_digits, v);
  return buf;
}

// Applies the entries of one [engines.NAME] table to a settings struct. The struct exposes
//   template <class V> void visit(V& v) { v("timestep", timestep); ... }
// Unknown keys, wrong types and values outside a field's range raise std::invalid_argument
// with the key named.
class SettingsReader {
 public:
  SettingsReader(std::string engine, const std::map<std::string, SettingValue>& table)
      : engine_(std::move(engine)), table_(table) {}

  void operator()(const char* key, double& field, double lo, double hi) {
    auto it = find(key);
    if (!it) return;
    double v;
    if (auto p = std::get_if<double>(it)) v = *p;
    else if (auto q = std::get_if<long long>(it)) v = static_cast<double>(*q);
    else fail(key, "expected a number");
    if (!(v >= lo && v <= hi)) fail(key, "value " + fmt(v) + " outside [" + fmt(lo) + ", " + fmt(hi) + "]");
    field = v;
  }
  void operator()(const char* key, int& field, int lo, int hi) {
    auto it = find(key);
    if (!it) return;
    auto q = std::get_if<long long>(it);
    if (!q) fail(key, "expected an integer");
    if (*q < lo || *q > hi) fail(key, "value " + std::to_string(*q) + " outside [" + std::to_string(lo) + ", " + std::to_string(hi) + "]");
    field = static_cast<int>(*q);
  }
  void operator()(const char* key, bool& field) {
    auto it = find(key);
    if (!it) return;
    auto b = std::get_if<bool>(it);
    if (!b) fail(key, "expected true or false");
    field = *b;
  }
  void operator()(const char* key, std::string& field, const std::vector<std::string>& choices) {
    auto it = find(key);
    if (!it) return;
    auto s = std::get_if<std::string>(it);
    if (!s) fail(key, "expected a string");
    bool ok = false;
    std::string list;
    for (const auto& c : choices) {
      ok = ok || c == *s;
      list += (list.empty() ? "" : ", ") + c;
    }
    if (!ok) fail(key, "value \"" + *s + "\" is not one of: " + list);
    field = *s;
  }
  // A free string (a path, a name): any value of the right type.
  void operator()(const char* key, std::string& field) {
    auto it = find(key);
    if (!it) return;
    auto s = std::get_if<std::string>(it);
    if (!s) fail(key, "expected a string");
    field = *s;
  }
  void operator()(const char* key, std::vector<double>& field, size_t n) {
    auto it = find(key);
    if (!it) return;
    auto a = std::get_if<std::vector<double>>(it);
    if (!a || a->size() != n) fail(key, "expected an array of " + std::to_string(n) + " numbers");
    for (double x : *a)
      if (!std::isfinite(x)) fail(key, "non-finite number");
    field = *a;
  }
  // Call after visiting: every key in the table must have been used.
  void finish() const {
    for (const auto& kv : table_)
      if (!used_.count(kv.first))
        throw std::invalid_argument("engines." + engine_ + "." + kv.first + ": unknown setting");
  }

 private:
  const SettingValue* find(const char* key) {
    auto it = table_.find(key);
    if (it == table_.end()) return nullptr;
    used_.insert(key);
    return &it->second;
  }
  [[noreturn]] void fail(const char* key, const std::string& why) const {
    throw std::invalid_argument("engines." + engine_ + "." + key + ": " + why);
  }
  static std::string fmt(double v) {
    std::ostringstream os;
    os << v;
    return os.str();
  }
  std::string engine_;
  const std::map<std::string, SettingValue>& table_;
  std::set<std::string> used_;
};

// Lists a settings struct as key=value strings (round-trip precision for numbers).
class SettingsLister {
 public:
  void operator()(const char* key, double& field, double, double) { put(key, num(field)); }
  void operator()(const char* key, int& field, int, int) { put(key, std::to_string(field)); }
  void operator()(const char* key, bool& field) { put(key, field ? "true" : "false"); }
  void operator()(const char* key, std::string& field, const std::vector<std::string>&) { put(key, field); }
  void operator()(const char* key, std::string& field) { put(key, field); }
  void operator()(const char* key, std::vector<double>& field, size_t) {
    std::string s = "[";
    for (size_t i = 0; i < field.size(); ++i) s += (i ? ", " : "") + num(field[i]);
    put(key, s + "]");
  }
  SettingsList list;

 private:
  void put(const char* key, std::string v) { list.emplace_back(key, std::move(v)); }
  static std::string num(double v) { return round_trip_text(v); }
};

// One setting as the documentation lists it (docs/engines.md, `tippe info --markdown`): its key,
// its type, its default and the values it accepts, all from the settings struct's `visit`.
struct SettingDoc {
  std::string key, type, default_value, allowed;
};
class SettingsDescriber {
 public:
  void operator()(const char* key, double& field, double lo, double hi) {
    put(key, "number", round_trip_text(field), "[" + round_trip_text(lo) + ", " + round_trip_text(hi) + "]");
  }
  void operator()(const char* key, int& field, int lo, int hi) {
    put(key, "integer", std::to_string(field), "[" + std::to_string(lo) + ", " + std::to_string(hi) + "]");
  }
  void operator()(const char* key, bool& field) { put(key, "boolean", field ? "true" : "false", "true, false"); }
  void operator()(const char* key, std::string& field, const std::vector<std::string>& choices) {
    std::string list;
    for (const auto& c : choices) list += (list.empty() ? "\"" : ", \"") + c + "\"";
    put(key, "string", "\"" + field + "\"", list);
  }
  void operator()(const char* key, std::string& field) { put(key, "string", "\"" + field + "\"", "any string"); }
  void operator()(const char* key, std::vector<double>& field, size_t n) {
    std::string s = "[";
    for (size_t i = 0; i < field.size(); ++i) s += (i ? ", " : "") + round_trip_text(field[i]);
    put(key, "array", s + "]", std::to_string(n) + " finite numbers");
  }
  std::vector<SettingDoc> list;

 private:
  void put(const char* key, std::string type, std::string value, std::string allowed) {
    list.push_back({key, std::move(type), std::move(value), std::move(allowed)});
  }
};

template <class Settings>
std::vector<SettingDoc> describe_settings(Settings s) {
  SettingsDescriber d;
  s.visit(d);
  return d.list;
}

template <class Settings>
Settings read_settings(const std::string& engine, const Scene& scene) {
  Settings s;
  auto it = scene.engines.find(engine);
  if (it == scene.engines.end()) return s;
  SettingsReader r(engine, it->second);
  s.visit(r);
  r.finish();
  return s;
}

template <class Settings>
SettingsList list_settings(Settings s) {
  SettingsLister l;
  s.visit(l);
  return l.list;
}

// The keys several engines share, one bound per meaning: an engine's `visit` calls these for
// them, so a value one engine accepts no other refuses for the same key.
namespace shared_settings {

// The fixed step, in the scene's time unit (s, or the dimensionless unit): from 1e-8 (below, a
// run of the shipped horizons takes 1e9 steps and more) to 0.1, the coarsest step any shipped
// ladder or boundary search tries (harness/sweeps/) and the bound ODE and MuJoCo always had.
// Bullet and DART accepted up to 1, where the shortest shipped run (3 s) is three steps.
template <class V>
void timestep(V& v, double& field) { v("timestep", field, 1e-8, 0.1); }
// A solver's iteration budget (ODE's quickstep, MuJoCo's, Bullet's, DART's PGS).
template <class V>
void iterations(V& v, const char* key, int& field) { v(key, field, 1, 1000000); }
// A fraction of an error or a softness corrected per step: ERP, CFM and their variants.
template <class V>
void fraction(V& v, const char* key, double& field) { v(key, field, 0.0, 1.0); }
// The friction coefficient an engine's contact stands in for rolling with (scene friction "rolling").
template <class V>
void rolling_mu(V& v, double& field) { v("rolling_mu", field, 0.0, 1e15); }
// The stem's collision shape: the capsule, or the sphere of its tip alone.
template <class V>
void stem_shape(V& v, std::string& field) { v("stem_shape", field, {"capsule", "tip_sphere"}); }

}  // namespace shared_settings

}  // namespace tippe
