// The rules for names and UTF-8 text that reach file names, JSON records and reports.
#include "harness/io/names.h"

#include <algorithm>
#include <cstddef>

namespace tippe {

namespace {

// Length of the well-formed UTF-8 sequence at s[i] (RFC 3629: no overlong forms, no surrogates,
// nothing above U+10FFFF), 0 when there is none. What toml++ enforces on a document, checked here
// on the text that does not pass through it.
size_t utf8_sequence(const std::string& s, size_t i) {
  const size_t n = s.size();
  const auto c = static_cast<unsigned char>(s[i]);
  size_t len;
  unsigned lo = 0x80, hi = 0xBF;  // range of the second byte
  if (c < 0x80) len = 1;
  else if (c >= 0xC2 && c <= 0xDF) len = 2;
  else if (c >= 0xE0 && c <= 0xEF) {
    len = 3;
    if (c == 0xE0) lo = 0xA0;
    if (c == 0xED) hi = 0x9F;
  } else if (c >= 0xF0 && c <= 0xF4) {
    len = 4;
    if (c == 0xF0) lo = 0x90;
    if (c == 0xF4) hi = 0x8F;
  } else return 0;
  if (n - i < len) return 0;
  for (size_t k = 1; k < len; ++k) {
    const auto b = static_cast<unsigned char>(s[i + k]);
    if (k == 1 ? (b < lo || b > hi) : (b < 0x80 || b > 0xBF)) return 0;
  }
  return len;
}

}  // namespace

const char* const kNameRule = "letters, digits, '.', '_', '-'";
// Not "." or "..": a character other than '.', or three dots or more.
const char* const kNamePattern = "^([A-Za-z0-9._-]*[A-Za-z0-9_-][A-Za-z0-9._-]*|\\.\\.\\.+)$";

bool is_valid_name(const std::string& n) {
  return !n.empty() && n != "." && n != ".." && std::all_of(n.begin(), n.end(), [](char c) {
    return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_' || c == '-' ||
           c == '.';
  });
}

bool is_valid_utf8(const std::string& s) {
  for (size_t i = 0, len; i < s.size(); i += len)
    if ((len = utf8_sequence(s, i)) == 0) return false;
  return true;
}

std::string utf8_replaced(const std::string& s) {
  std::string out;
  out.reserve(s.size());
  for (size_t i = 0; i < s.size();) {
    const size_t len = utf8_sequence(s, i);
    if (len == 0) {
      out += "\xEF\xBF\xBD";  // U+FFFD
      ++i;
    } else {
      out.append(s, i, len);
      i += len;
    }
  }
  return out;
}

}  // namespace tippe
