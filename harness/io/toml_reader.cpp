// The one checked TOML reader: parsing with line and column in syntax errors, and the typed field checks.
#include "harness/io/toml_reader.h"

#include <cmath>
#include <sstream>
#include <stdexcept>

#include "harness/io/scene_io.h"
#include "harness/io/text.h"
#include "harness/io/files.h"

namespace tippe {

const char* toml_type_name(toml::node_type t) {
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

std::string toml_value_text(const toml::node& n) {
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

namespace {

bool bare_key_char(char c) {
  return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_' || c == '-';
}

}  // namespace

void check_toml_key_depth(const std::string& text, const std::string& file) {
  size_t line = 1, col = 1;           // of text[i]
  size_t first_line = 1, first_col = 1;  // of the current key's first part
  int parts = 0;
  bool after_part = false, after_dot = false;
  auto advance = [&](size_t& i) {
    if (text[i] == '\n') {
      ++line;
      col = 1;
    } else {
      ++col;
    }
    ++i;
  };
  auto reset = [&] {
    parts = 0;
    after_part = after_dot = false;
  };
  auto part = [&](size_t at_line, size_t at_col) {
    if (after_dot) {
      ++parts;
    } else {
      parts = 1;
      first_line = at_line;
      first_col = at_col;
    }
    after_part = true;
    after_dot = false;
    if (parts > kMaxTomlKeyParts)
      throw SceneError(file + ":" + std::to_string(first_line) + ":" + std::to_string(first_col) +
                       ": a dotted key or table header of more than " + std::to_string(kMaxTomlKeyParts) +
                       " parts (nested too deep to be a key of this file)");
  };
  for (size_t i = 0; i < text.size();) {
    const char c = text[i];
    const size_t at_line = line, at_col = col;
    if (c == '#') {
      while (i < text.size() && text[i] != '\n') advance(i);
      reset();
    } else if (c == '"' || c == '\'') {
      const bool triple = text.compare(i, 3, std::string(3, c)) == 0;
      for (int k = 0; k < (triple ? 3 : 1); ++k) advance(i);
      while (i < text.size()) {
        if (c == '"' && text[i] == '\\') {
          advance(i);
          if (i < text.size()) advance(i);
          continue;
        }
        if (triple ? text.compare(i, 3, std::string(3, c)) == 0 : text[i] == c) {
          for (int k = 0; k < (triple ? 3 : 1); ++k) advance(i);
          break;
        }
        if (!triple && text[i] == '\n') break;  // unterminated: toml++ says so
        advance(i);
      }
      part(at_line, at_col);
    } else if (bare_key_char(c)) {
      while (i < text.size() && bare_key_char(text[i])) advance(i);
      part(at_line, at_col);
    } else if (c == '.') {
      const bool dotted = after_part;
      advance(i);
      if (dotted) {
        after_part = false;
        after_dot = true;
      } else {
        reset();
      }
    } else if (c == ' ' || c == '\t') {
      advance(i);
    } else {
      advance(i);
      reset();
    }
  }
}

toml::table parse_toml(const std::string& text, const std::string& file) {
  check_toml_key_depth(text, file);
  try {
    return toml::parse(text, file);
  } catch (const toml::parse_error& e) {
    throw SceneError(file + ":" + std::to_string(e.source().begin.line) + ":" +
                     std::to_string(e.source().begin.column) + ": " + std::string(e.description()));
  }
}

toml::table read_toml_file(const std::string& file, std::string* text) {
  std::string bytes;
  try {
    bytes = read_file_text(file, kMaxInputFileBytes);
  } catch (const std::runtime_error& e) {
    throw SceneError(e.what());
  }
  toml::table root = parse_toml(bytes, file);
  if (text) *text = std::move(bytes);
  return root;
}

void TomlReader::fail(const std::string& key, const std::string& why) const {
  throw SceneError(file_ + ": " + key + ": " + why);
}

void TomlReader::out_of_range(const std::string& key, double v, const std::string& expected) const {
  out_of_range(key, num(v), expected);
}

void TomlReader::out_of_range(const std::string& key, const std::string& value, const std::string& expected) const {
  fail(key, value + " is out of range (expected " + expected + ")");
}

void TomlReader::keys(const toml::table& t, const std::string& prefix, const std::vector<std::string>& allowed) const {
  for (auto&& [k, v] : t) {
    (void)v;
    const std::string key(k.str());
    bool known = false;
    for (const auto& a : allowed) known = known || key == a;
    if (known) continue;
    const std::string path = join_path(prefix, key);
    fail(path, "unknown key (expected one of: " + join(allowed, ", ") + ")" +
                   (overridden(path) ? "; it was set with --set" : ""));
  }
}

double TomlReader::number(const toml::node& n, const std::string& key) const {
  double v = 0;
  if (const auto* f = n.as_floating_point())
    v = f->get();
  else if (const auto* i = n.as_integer())
    v = static_cast<double>(i->get());
  else
    fail(key, "expected a number, got " + toml_value_text(n));
  if (!std::isfinite(v)) fail(key, "must be a finite number, got " + num(v));
  return v;
}

std::string TomlReader::string(const toml::node& n, const std::string& key) const {
  const auto* s = n.as_string();
  if (!s) fail(key, "expected a string, got " + toml_value_text(n));
  return s->get();
}

bool TomlReader::boolean(const toml::node& n, const std::string& key) const {
  const auto* b = n.as_boolean();
  if (!b) fail(key, "expected true or false, got " + toml_value_text(n));
  return b->get();
}

const toml::array& TomlReader::array(const toml::node& n, const std::string& key) const {
  const auto* a = n.as_array();
  if (!a) fail(key, "expected an array, got " + toml_value_text(n));
  return *a;
}

const toml::table& TomlReader::table(const toml::node& n, const std::string& key) const {
  const auto* t = n.as_table();
  if (!t) fail(key, "expected a table, got " + toml_value_text(n));
  return *t;
}

const toml::table& TomlReader::need_table(const toml::table& t, const std::string& prefix, const char* key) const {
  const toml::node* n = t.get(key);
  if (!n) fail(join_path(prefix, key), "missing (required table)");
  return table(*n, join_path(prefix, key));
}

std::optional<double> TomlReader::opt_number(const toml::table& t, const std::string& prefix, const char* key) const {
  const toml::node* n = t.get(key);
  if (!n) return std::nullopt;
  return number(*n, join_path(prefix, key));
}

double TomlReader::need_number(const toml::table& t, const std::string& prefix, const char* key) const {
  auto v = opt_number(t, prefix, key);
  if (!v) fail(join_path(prefix, key), "missing (required)");
  return *v;
}

double TomlReader::need_positive(const toml::table& t, const std::string& prefix, const char* key) const {
  const double v = need_number(t, prefix, key);
  if (!(v > 0)) out_of_range(join_path(prefix, key), v, std::string(key) + " > 0");
  return v;
}

std::optional<bool> TomlReader::opt_bool(const toml::table& t, const std::string& prefix, const char* key) const {
  const toml::node* n = t.get(key);
  if (!n) return std::nullopt;
  return boolean(*n, join_path(prefix, key));
}

std::optional<std::string> TomlReader::opt_string(const toml::table& t, const std::string& prefix,
                                                  const char* key) const {
  const toml::node* n = t.get(key);
  if (!n) return std::nullopt;
  return string(*n, join_path(prefix, key));
}

std::optional<std::vector<double>> TomlReader::opt_numbers(const toml::table& t, const std::string& prefix,
                                                           const char* key, size_t count) const {
  const toml::node* n = t.get(key);
  if (!n) return std::nullopt;
  const std::string path = join_path(prefix, key);
  const auto* a = n->as_array();
  if (!a || a->size() != count)
    fail(path, "expected an array of " + std::to_string(count) + " numbers, got " +
                   (a ? "an array of " + std::to_string(a->size()) : toml_value_text(*n)));
  std::vector<double> out;
  for (size_t i = 0; i < a->size(); ++i) out.push_back(number(*a->get(i), idx(path, i)));
  return out;
}

}  // namespace tippe
