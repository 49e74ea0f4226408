// How the file readers (scenes, sweeps, gates) name a TOML value in an error message: its type and, for a scalar, the value.
#pragma once

#include <toml++/toml.h>

#include <sstream>
#include <string>

namespace tippe {

inline const char* toml_type_name(toml::node_type t) {
  switch (t) {
    case toml::node_type::none: return "nothing";
    case toml::node_type::table: return "a table";
    case toml::node_type::array: return "an array";
    case toml::node_type::string: return "a string";
    case toml::node_type::integer: return "an integer";
    case toml::node_type::floating_point: return "a float";
    case toml::node_type::boolean: return "a boolean";
    case toml::node_type::date: return "a date";
    case toml::node_type::time: return "a time";
    case toml::node_type::date_time: return "a date-time";
  }
  return "?";
}

// "a string '0.1'": the type and, for a scalar, the value as TOML, cut to 40 bytes on a whole
// UTF-8 character so that a long or binary value cannot flood the message.
inline std::string toml_value_text(const toml::node& n) {
  std::string out = toml_type_name(n.type());
  if (n.is_table() || n.is_array()) return out;
  std::ostringstream os;
  n.visit([&os](const auto& v) { os << v; });
  std::string text = os.str();
  if (text.size() > 40) {
    size_t cut = 37;
    while (cut > 0 && (static_cast<unsigned char>(text[cut]) & 0xC0) == 0x80) --cut;
    text = text.substr(0, cut) + "...";
  }
  return out + " " + text;
}

}  // namespace tippe
