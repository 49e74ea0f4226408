// The JSON helpers every record shares: a non-finite number as null, and null read back as NaN or absent.
#pragma once

#include <cmath>
#include <limits>
#include <optional>

#include <nlohmann/json.hpp>

namespace tippe {

// JSON has no NaN or infinity: they are written as null.
inline nlohmann::json number(double v) { return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(nullptr); }
inline nlohmann::json number(const std::optional<double>& v) { return v ? number(*v) : nlohmann::json(nullptr); }

// j[key] as a number, null read as NaN; throws nlohmann::json's exceptions for a missing key or another type.
inline double get_number(const nlohmann::json& j, const char* key) {
  const nlohmann::json& v = j.at(key);
  return v.is_null() ? std::numeric_limits<double>::quiet_NaN() : v.get<double>();
}
// j[key] as a number, null read as absent.
inline std::optional<double> get_optional(const nlohmann::json& j, const char* key) {
  const nlohmann::json& v = j.at(key);
  if (v.is_null()) return std::nullopt;
  return v.get<double>();
}

}  // namespace tippe
