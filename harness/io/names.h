// The rules for names and UTF-8 text that reach file names, JSON records and reports.
#pragma once

#include <string>

namespace tippe {

// The rule for every name that becomes part of a file name or a report (scene, setup, check and
// engine names, in input files and in records read back): letters, digits, '.', '_', '-', not
// empty, not "." or "..". No such name can hold a path separator, a quote or a newline.
bool is_valid_name(const std::string& name);
// What a message says a name must be ("letters, digits, '.', '_', '-'").
extern const char* const kNameRule;
// The same rule as a JSON Schema pattern (ECMA-262, with only the tokens JSON Schema advises for
// portable patterns: no lookahead), for the schemas of records whose names are checked so.
extern const char* const kNamePattern;

// Whether `s` is well-formed UTF-8 (RFC 3629). Every path and name that reaches a JSON record or
// an XML report is checked with it first: nlohmann::json throws on invalid UTF-8 while writing.
bool is_valid_utf8(const std::string& s);
// `s` with every byte that is not part of a well-formed UTF-8 sequence replaced by U+FFFD, for
// text that must be shown (an XML report, a message) whatever its bytes.
std::string utf8_replaced(const std::string& s);

}  // namespace tippe
