// The one checked TOML reader of scene, sweep and gate files: parsing, and every error as "FILE: KEY: reason".
#pragma once

#include <toml++/toml.h>

#include <optional>
#include <set>
#include <string>
#include <vector>

namespace tippe {

// "a table", "an integer", ...: a TOML type in an error message.
const char* toml_type_name(toml::node_type t);
// "a string '0.1'": the type and, for a scalar, the value as TOML, cut to 40 bytes on a whole
// UTF-8 character so that a long or binary value cannot flood the message.
std::string toml_value_text(const toml::node& n);

// The most parts a dotted key or a table header may have. The deepest key of any file the bench
// reads has 4 (setup[i].ladder.key's "engines.NAME.KEY"); toml++ recurses once per part,
// and a 100 KB file with a 50000-part key overflowed the stack (SIGSEGV).
inline constexpr int kMaxTomlKeyParts = 64;

// Throws SceneError "FILE:LINE:COL: a dotted key or table header of more than 64 parts" for the
// first key in `text` that has more parts than kMaxTomlKeyParts. A scan of the bytes (strings and
// comments skipped), done before toml++ parses anything.
void check_toml_key_depth(const std::string& text, const std::string& file);

// Parses `text` as TOML (after check_toml_key_depth); a syntax error throws SceneError
// "FILE:LINE:COL: reason".
toml::table parse_toml(const std::string& text, const std::string& file);
// Reads FILE (at most kMaxInputFileBytes) and parses it; an unreadable file throws SceneError
// naming it and why.
toml::table read_toml_file(const std::string& file, std::string* text = nullptr);

// The checks every file reader shares. Each throws SceneError "FILE: KEY: reason", KEY dotted
// with 0-based indices ("setup[1].ladder.values[2]"): the message names the file, the key and the
// reason, as the command line's exit 2 needs. A key in `overridden` was given with --set; an
// unknown one says so.
class TomlReader {
 public:
  explicit TomlReader(std::string file, std::set<std::string> overridden = {})
      : file_(std::move(file)), overridden_(std::move(overridden)) {}

  const std::string& file() const { return file_; }

  [[noreturn]] void fail(const std::string& key, const std::string& why) const;
  // The one form of every range error: "KEY: VALUE is out of range (expected RANGE)".
  [[noreturn]] void out_of_range(const std::string& key, double v, const std::string& expected) const;
  [[noreturn]] void out_of_range(const std::string& key, const std::string& value, const std::string& expected) const;

  // Refuses a key of `t` that is not in `allowed` ("unknown key (expected one of: ...)").
  void keys(const toml::table& t, const std::string& prefix, const std::vector<std::string>& allowed) const;

  // A node of the given type; a number is an integer or a float and finite.
  double number(const toml::node& n, const std::string& key) const;
  std::string string(const toml::node& n, const std::string& key) const;
  bool boolean(const toml::node& n, const std::string& key) const;
  const toml::array& array(const toml::node& n, const std::string& key) const;
  const toml::table& table(const toml::node& n, const std::string& key) const;

  // Fields of a table, KEY being PREFIX.KEY: optional (absent: nullopt) or required ("missing").
  const toml::table& need_table(const toml::table& t, const std::string& prefix, const char* key) const;
  std::optional<double> opt_number(const toml::table& t, const std::string& prefix, const char* key) const;
  double need_number(const toml::table& t, const std::string& prefix, const char* key) const;
  double need_positive(const toml::table& t, const std::string& prefix, const char* key) const;
  std::optional<bool> opt_bool(const toml::table& t, const std::string& prefix, const char* key) const;
  std::optional<std::string> opt_string(const toml::table& t, const std::string& prefix, const char* key) const;
  // An array of exactly `count` numbers.
  std::optional<std::vector<double>> opt_numbers(const toml::table& t, const std::string& prefix, const char* key,
                                                 size_t count) const;

  // "PREFIX.KEY", or KEY without a prefix.
  static std::string join_path(const std::string& prefix, const std::string& key) {
    return prefix.empty() ? key : prefix + "." + key;
  }

 protected:
  bool overridden(const std::string& path) const { return overridden_.count(path) != 0; }

 private:
  std::string file_;
  std::set<std::string> overridden_;
};

}  // namespace tippe
