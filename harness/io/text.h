// Small text helpers every reader and writer of the harness shares: trimming, numbers for messages, markup escaping.
#pragma once

#include <cmath>
#include <exception>
#include <cstdio>
#include <sstream>
#include <string>
#include <vector>

namespace tippe {

// Without leading and trailing blanks and tabs.
inline std::string trim(const std::string& s) {
  const auto b = s.find_first_not_of(" \t");
  if (b == std::string::npos) return {};
  const auto e = s.find_last_not_of(" \t");
  return s.substr(b, e - b + 1);
}

// A number in a message: 12 significant digits, enough to tell apart any two values a user types.
inline std::string num(double v) {
  std::ostringstream os;
  os.precision(12);
  os << v;
  return os.str();
}

// A number in a generated message or table at 6 significant digits, as printf's "%.6g" (the
// one such helper: gates, sweep criteria, the classifier, the self-check and the MJCF importer).
inline std::string g6(double v) {
  char buf[40];
  std::snprintf(buf, sizeof buf, "%.6g", v);
  return buf;
}

// A measured value in a CI log or a table: short, yet long enough that a value just over a
// threshold does not print equal to it (6 digits); integral values (steps, counts) print without
// an exponent; nan, inf and -inf as words.
inline std::string short_value(double v) {
  if (std::isnan(v)) return "nan";
  if (std::isinf(v)) return v > 0 ? "inf" : "-inf";
  char buf[64];
  if (v == std::floor(v) && std::abs(v) < 1e15)
    std::snprintf(buf, sizeof buf, "%.0f", v);
  else
    std::snprintf(buf, sizeof buf, "%.6g", v);
  return buf;
}

inline std::string join(const std::vector<std::string>& v, const std::string& sep) {
  std::string out;
  for (const auto& s : v) out += (out.empty() ? "" : sep) + s;
  return out;
}

// What a caught exception says (its what(), or "unknown exception"): a run that throws is a
// result with this as its detail.
inline std::string exception_text(const std::exception_ptr& e) {
  try {
    std::rethrow_exception(e);
  } catch (const std::exception& x) {
    return x.what();
  } catch (...) {
    return "unknown exception";
  }
}

// A dotted key's element: idx("setup", 2) is "setup[2]".
inline std::string idx(const std::string& key, size_t i) { return key + "[" + std::to_string(i) + "]"; }

// Text inside HTML or XML: & < > " ' as entities; bytes that are not UTF-8 replaced (the documents
// declare UTF-8); other control characters, which XML 1.0 does not allow, as '?'. In an attribute
// (`attribute`), newline, tab and carriage return as character references, so that they survive
// attribute-value normalisation.
std::string markup_escape(const std::string& text, bool attribute = false);

}  // namespace tippe
