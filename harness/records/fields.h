// A record's one field list: what a record's `visit` says of each field, and the visitors that write the record as JSON, read it back and describe it as a JSON Schema.
#pragma once

// A record (RunRecord, Metrics, their parts) declares its fields once, as the engine settings do:
//   template <class R, class V> void visit(R& r, V& v)   // R: the record, const or not
//   { v(Field("samples", "rows of trajectory.csv").minimum(0), r.samples); ... }
// JsonWriter writes the fields in that list, JsonReader reads them back with the rules the
// Field gives (required or absent in older records, the values a string may hold, a lower
// bound), SchemaBuilder makes the record's JSON Schema properties from the same list, and
// FieldNames lists the keys (the metric table and the tests use it). A field added to a `visit`
// is written, read, described and listed without another edit.

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <optional>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "harness/io/json_fields.h"
#include "engines/core/simulator.h"

namespace tippe {

// What a `visit` says of one field besides its value.
class Field {
 public:
  Field(const char* key, const char* doc = "") : key_(key), doc_(doc) {}
  // Absent in records written before it: read back as the field's default (required otherwise).
  Field since() const { Field f = *this; f.since_ = true; return f; }
  // A string written as null when empty, and null read back as empty.
  Field empty_as_null() const { Field f = *this; f.empty_as_null_ = true; return f; }
  // The smallest value the schema allows (and a checked reader accepts).
  Field minimum(double m) const { Field f = *this; f.minimum_ = m; return f; }
  // The values a string (or each string of a list) may hold.
  Field one_of(const std::vector<std::string>& names) const { Field f = *this; f.choices_ = &names; return f; }
  // Left out of the metric table: the field is no number a bound may name (a timing, a count
  // that describes rather than judges, a setting of the bench); `why` is what a bound naming it
  // is told.
  Field not_bounded(const char* why = "") const {
    Field f = *this;
    f.bounded_ = false;
    f.not_bounded_why_ = why;
    return f;
  }

  const char* key() const { return key_; }
  const char* doc() const { return doc_; }
  bool is_since() const { return since_; }
  bool is_empty_as_null() const { return empty_as_null_; }
  const std::optional<double>& min() const { return minimum_; }
  const std::vector<std::string>* choices() const { return choices_; }
  bool bounded() const { return bounded_; }
  const char* not_bounded_why() const { return not_bounded_why_; }

 private:
  const char* key_;
  const char* doc_;
  const char* not_bounded_why_ = "";
  bool since_ = false, empty_as_null_ = false, bounded_ = true;
  std::optional<double> minimum_;
  const std::vector<std::string>* choices_ = nullptr;
};

// An integer field of a record (counts of samples, steps, events): a JSON integer within the
// range of long long. Throws nlohmann::json::exception for a missing field or any other value;
// json::get<long long> would convert a float such as 1e300 with undefined behaviour.
long long json_integer(const nlohmann::json& j, const char* key);

// Whether T is a record part with a `visit` of its own (written as a JSON object).
template <class T, class = void>
struct has_visit : std::false_type {};
struct FieldProbe {
  template <class... A>
  void operator()(A&&...) {}
};
template <class T>
struct has_visit<T, std::void_t<decltype(visit(std::declval<T&>(), std::declval<FieldProbe&>()))>> : std::true_type {};

// ---- writing ------------------------------------------------------------------------------------

// Fills a JSON object with a record's fields: non-finite numbers and absent values as null.
class JsonWriter {
 public:
  nlohmann::json out = nlohmann::json::object();

  void operator()(const Field& f, const std::string& v) {
    out[f.key()] = f.is_empty_as_null() && v.empty() ? nlohmann::json(nullptr) : nlohmann::json(v);
  }
  void operator()(const Field& f, const double& v) { out[f.key()] = number(v); }
  void operator()(const Field& f, const std::optional<double>& v) { out[f.key()] = number(v); }
  void operator()(const Field& f, const long long& v) { out[f.key()] = v; }
  void operator()(const Field& f, const std::optional<long long>& v) {
    out[f.key()] = v ? nlohmann::json(*v) : nlohmann::json(nullptr);
  }
  void operator()(const Field& f, const bool& v) { out[f.key()] = v; }
  void operator()(const Field& f, const std::vector<std::string>& v) { out[f.key()] = v; }
  void operator()(const Field& f, const nlohmann::json& v) { out[f.key()] = v; }
  // Settings as an object (key order is not kept: JSON objects are read back sorted by key).
  void operator()(const Field& f, const SettingsList& v) {
    nlohmann::json s = nlohmann::json::object();
    for (const auto& [k, x] : v) s[k] = x;
    out[f.key()] = s;
  }
  void operator()(const Field& f, const std::map<std::string, std::string>& v) { out[f.key()] = v; }
  template <class T, std::enable_if_t<has_visit<T>::value, int> = 0>
  void operator()(const Field& f, const T& part) { out[f.key()] = write(part); }
  template <class T>
  void operator()(const Field& f, const std::optional<T>& part) {
    out[f.key()] = part ? write(*part) : nlohmann::json(nullptr);
  }
  template <class T>
  void operator()(const Field& f, const std::vector<T>& parts) {
    nlohmann::json a = nlohmann::json::array();
    for (const T& p : parts) a.push_back(write(p));
    out[f.key()] = a;
  }

  template <class T>
  static nlohmann::json write(const T& part) {
    JsonWriter w;
    visit(part, w);
    return w.out;
  }
};

// ---- reading --------------------------------------------------------------------------------------

// Reads a record's fields back from a JSON object.
//  - A missing or mistyped required field: nlohmann::json's exceptions (get_number, get_optional,
//    json_integer, get<std::string>).
//  - A field `since` a format change, absent (or null): the field keeps its default. Present, the
//    same reading, except that an optional count, a bounded number, a string and a list of parts
//    are checked by the reader itself.
//  - Every field, `since` or not, is held to its Field's rules: a string (or each string of a
//    list) among its choices, a number or count at or above its minimum (null passes: the
//    schema allows it).
//  - What the reader checks itself (a string among its choices, a bound, a count, a list) fails
//    with "WHERE.KEY: reason" (WHERE: the prefix, e.g. "metrics." or "events[]."): as
//    nlohmann::json::other_error, or as std::invalid_argument for a `checked` reader (the
//    comparison's metrics, whose fields past the first format say so).
class JsonReader {
 public:
  JsonReader(const nlohmann::json& j, std::string where, bool checked = false)
      : j_(j), where_(std::move(where)), checked_(checked) {}

  void operator()(const Field& f, std::string& v) {
    if (f.is_since()) {
      if (absent(f)) return;
      const nlohmann::json& x = j_.at(f.key());
      if (!x.is_string()) fail(f, x.dump() + " is not a string" + (f.is_empty_as_null() ? " or null" : ""));
      v = x.get<std::string>();
      // Empty: the default, what a record written before the field means.
      if (f.choices() && !v.empty()) check_choice(f, v);
      return;
    }
    if (f.is_empty_as_null() && j_.at(f.key()).is_null()) {
      v.clear();
      return;
    }
    v = j_.at(f.key()).get<std::string>();
    if (f.choices()) check_choice(f, v);
  }
  // A number: null reads as NaN (not a number, as written); a number present is checked
  // against the field's minimum.
  void operator()(const Field& f, double& v) {
    if (f.is_since() && !j_.contains(f.key())) return;
    v = get_number(j_, f.key());
    if (f.min() && !std::isnan(v) && !(std::isfinite(v) && v >= *f.min()))
      fail(f, j_.at(f.key()).dump() + " is not a number >= " + bound(*f.min()) + " or null");
  }
  void operator()(const Field& f, std::optional<double>& v) {
    if (f.is_since() && absent(f)) return;
    v = get_optional(j_, f.key());
    if (v && f.min() && !(std::isfinite(*v) && *v >= *f.min()))
      fail(f, j_.at(f.key()).dump() + " is not a number >= " + bound(*f.min()) + " or null");
  }
  void operator()(const Field& f, long long& v) {
    v = json_integer(j_, f.key());
    if (f.min() && static_cast<double>(v) < *f.min()) fail(f, j_.at(f.key()).dump() + " is not a count >= " + bound(*f.min()));
  }
  void operator()(const Field& f, std::optional<long long>& v) {
    if (f.is_since()) {
      if (absent(f)) return;
      const nlohmann::json& x = j_.at(f.key());
      if (!x.is_number_integer() || (f.min() && static_cast<double>(x.get<long long>()) < *f.min()))
        fail(f, x.dump() + " is not a count >= " + bound(f.min().value_or(0)) + " or null");
      v = x.get<long long>();
      return;
    }
    if (j_.at(f.key()).is_null()) {
      v = std::nullopt;
      return;
    }
    v = json_integer(j_, f.key());
    if (f.min() && static_cast<double>(*v) < *f.min())
      fail(f, j_.at(f.key()).dump() + " is not a count >= " + bound(*f.min()) + " or null");
  }
  void operator()(const Field& f, bool& v) {
    if (f.is_since() && !j_.contains(f.key())) return;
    v = j_.at(f.key()).get<bool>();
  }
  void operator()(const Field& f, std::vector<std::string>& v) {
    if (f.is_since() && !j_.contains(f.key())) return;
    v = j_.at(f.key()).get<std::vector<std::string>>();
    if (f.choices())
      for (const std::string& x : v) check_choice(f, x);
  }
  void operator()(const Field& f, nlohmann::json& v) {
    if (f.is_since() && !j_.contains(f.key())) return;
    v = j_.at(f.key());
  }
  void operator()(const Field& f, SettingsList& v) {
    v.clear();
    for (const auto& [k, x] : j_.at(f.key()).items()) {
      if (!x.is_string())
        fail_at(where_ + f.key() + "." + k.substr(0, 40), std::string("expected a string, got ") + x.type_name());
      v.emplace_back(k, x.get<std::string>());
    }
  }
  void operator()(const Field& f, std::map<std::string, std::string>& v) {
    SettingsList list;
    (*this)(f, list);
    v = std::map<std::string, std::string>(list.begin(), list.end());
  }
  template <class T, std::enable_if_t<has_visit<T>::value, int> = 0>
  void operator()(const Field& f, T& part) {
    if (f.is_since() && !j_.contains(f.key())) return;
    part = read<T>(j_.at(f.key()), where_ + f.key() + ".", checked_);
  }
  template <class T>
  void operator()(const Field& f, std::optional<T>& part) {
    if (absent(f) && (f.is_since() || j_.at(f.key()).is_null())) {
      part = std::nullopt;
      return;
    }
    part = read<T>(j_.at(f.key()), where_ + f.key() + ".", checked_);
  }
  template <class T>
  void operator()(const Field& f, std::vector<T>& parts) {
    parts.clear();
    if (f.is_since()) {
      if (absent(f)) return;
      const nlohmann::json& a = j_.at(f.key());
      if (!a.is_array()) fail(f, a.dump().substr(0, 60) + " is not an array");
      for (size_t i = 0; i < a.size(); ++i) {
        const std::string at = where_ + f.key() + "[" + std::to_string(i) + "]";
        if (!a[i].is_object()) fail_at(at, "not an object");
        parts.push_back(read<T>(a[i], at + ".", checked_));
      }
      return;
    }
    for (const nlohmann::json& x : j_.at(f.key())) parts.push_back(read<T>(x, where_ + f.key() + "[].", checked_));
  }

  template <class T>
  static T read(const nlohmann::json& j, const std::string& where, bool checked = false) {
    T part{};
    JsonReader r(j, where, checked);
    visit(part, r);
    return part;
  }

 private:
  // Absent or null.
  bool absent(const Field& f) const { return !j_.contains(f.key()) || j_.at(f.key()).is_null(); }
  [[noreturn]] void fail(const Field& f, const std::string& why) const { fail_at(where_ + f.key(), why); }
  [[noreturn]] void fail_at(const std::string& at, const std::string& why) const {
    if (checked_) throw std::invalid_argument(at + ": " + why);
    throw nlohmann::json::other_error::create(501, at + ": " + why, &j_);
  }
  void check_choice(const Field& f, const std::string& v) const {
    if (!among(v, *f.choices()))
      fail(f, nlohmann::json(v.substr(0, 40)).dump(-1, ' ', false, nlohmann::json::error_handler_t::replace) +
                  " is not one of " + list(*f.choices()));
  }
  static bool among(const std::string& v, const std::vector<std::string>& names) {
    for (const std::string& n : names)
      if (n == v) return true;
    return false;
  }
  static std::string list(const std::vector<std::string>& names) {
    std::string s;
    for (const std::string& n : names) s += (s.empty() ? "" : ", ") + n;
    return s;
  }
  static std::string bound(double m) { return nlohmann::json(m).dump(); }
  const nlohmann::json& j_;
  std::string where_;
  bool checked_;
};

// ---- describing ------------------------------------------------------------------------------------

// A record's fields as JSON Schema (draft 2020-12) "properties" and "required", in `visit` order.
class SchemaBuilder {
 public:
  using ordered = nlohmann::ordered_json;
  ordered properties = ordered::object();
  std::vector<std::string> required;

  void operator()(const Field& f, const std::string&) {
    ordered p = type(f.is_empty_as_null() ? ordered{"string", "null"} : ordered("string"));
    if (f.choices()) p["enum"] = *f.choices();
    put(f, std::move(p));
  }
  void operator()(const Field& f, const double&) { put(f, type({"number", "null"})); }
  void operator()(const Field& f, const std::optional<double>&) { put(f, type({"number", "null"})); }
  void operator()(const Field& f, const long long&) { put(f, type("integer")); }
  void operator()(const Field& f, const std::optional<long long>&) { put(f, type({"integer", "null"})); }
  void operator()(const Field& f, const bool&) { put(f, type("boolean")); }
  void operator()(const Field& f, const std::vector<std::string>&) {
    ordered items = type("string");
    if (f.choices()) items["enum"] = *f.choices();
    ordered p = type("array");
    p["items"] = items;
    put(f, std::move(p));
  }
  void operator()(const Field& f, const nlohmann::json&) { put(f, type("object")); }
  void operator()(const Field& f, const SettingsList&) {
    ordered p = type("object");
    p["additionalProperties"] = type("string");
    put(f, std::move(p));
  }
  void operator()(const Field& f, const std::map<std::string, std::string>&) { (*this)(f, SettingsList{}); }
  template <class T, std::enable_if_t<has_visit<T>::value, int> = 0>
  void operator()(const Field& f, const T&) { put(f, object<T>("object")); }
  template <class T>
  void operator()(const Field& f, const std::optional<T>&) { put(f, object<T>({"object", "null"})); }
  template <class T>
  void operator()(const Field& f, const std::vector<T>&) {
    ordered p = type("array");
    p["items"] = object<T>("object");
    put(f, std::move(p));
  }

  // The schema of a part: {"type", "properties", "required" (sorted)}.
  template <class T>
  static ordered object(ordered object_type) {
    SchemaBuilder b;
    const T part{};
    visit(part, b);
    return b.schema(std::move(object_type));
  }
  ordered schema(ordered object_type) const {
    ordered s = type(std::move(object_type));
    s["properties"] = properties;
    std::vector<std::string> sorted = required;
    std::sort(sorted.begin(), sorted.end());
    s["required"] = sorted;
    return s;
  }

 private:
  static ordered type(ordered t) { return ordered{{"type", std::move(t)}}; }
  void put(const Field& f, ordered p) {
    if (f.min()) {
      const double m = *f.min();
      p["minimum"] = m == std::floor(m) ? ordered(static_cast<long long>(m)) : ordered(m);
    }
    if (*f.doc()) p["description"] = f.doc();
    properties[f.key()] = std::move(p);
    if (!f.is_since()) required.emplace_back(f.key());
  }
};

// ---- listing ------------------------------------------------------------------------------------------

// The keys of a record's fields and what the metric table needs of each: its doc, whether it is
// a number (a count included) and whether a bound may name it.
struct FieldInfo {
  std::string key, doc;
  bool number = false, bounded = false;
  std::optional<double> min;  // the Field's minimum
  bool choices = false;       // the Field's values are a list of names (one_of)
  bool list = false;          // a list of strings
};
class FieldNames {
 public:
  std::vector<FieldInfo> fields;
  template <class T>
  void operator()(const Field& f, const T&) {
    using U = std::decay_t<T>;
    constexpr bool numeric = std::is_same_v<U, double> || std::is_same_v<U, long long> ||
                             std::is_same_v<U, std::optional<double>> || std::is_same_v<U, std::optional<long long>>;
    fields.push_back({f.key(), f.doc(), numeric, numeric && f.bounded(), f.min(), f.choices() != nullptr,
                      std::is_same_v<U, std::vector<std::string>>});
  }
};
template <class T>
std::vector<FieldInfo> field_list() {
  FieldNames n;
  const T part{};
  visit(part, n);
  return n.fields;
}

}  // namespace tippe
