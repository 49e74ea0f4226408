// The sweep record's field list (sweep_record.h) described as JSON Schema: SweepSchemaBuilder, the visitor that makes schemas/sweep-record.schema.json.
#pragma once

// Each SweepField becomes the property its reader checks for (sweep_record.cpp), so that the
// schema and the reader accept the same records as far as a schema can say:
//  - a field is required unless `since` (absent in older records) or a nullable group (grid);
//  - a number is a number or null (the reader's NaN) unless `not_null`; `at_least` is its minimum;
//  - `range(lo, hi)` an integer within [lo, hi] (hi left out when it is long long's own bound);
//  - `status()`, `run_class()` an enum of the names the reader takes (run_status_names(),
//    run_class_names());
//  - `name()`, `setting_key()` a string with the rule of names as a pattern (kNamePattern);
//  - `label_of(...)` a string of the characters of names and numbers, the rest (a number equal
//    to its axis' value, else a name) in its description, as `criterion()`'s form is;
//  - a part (`std::optional<T>`) and a nullable group: an object or null;
//  - the metrics: comparison.schema.json's, which their own list generates.
// What the reader checks beyond single fields (a search's range as a whole, a label equal to its
// number) is in the descriptions only.

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "harness/io/names.h"
#include "harness/records/records.h"
#include "harness/records/sweep_record.h"

namespace tippe {

class SweepSchemaBuilder {
 public:
  using ordered = nlohmann::ordered_json;
  ordered properties = ordered::object();
  std::vector<std::string> required;

  void operator()(const SweepField& f, const std::string&) {
    ordered p = type("string");
    std::string doc = f.doc();
    switch (f.check()) {
      case SweepField::Check::name:
      case SweepField::Check::key:
        p["pattern"] = kNamePattern;
        break;
      case SweepField::Check::label:
        // Names and number texts ("1e-06", "+5") are made of these; which one, the value says.
        p["pattern"] = "^[A-Za-z0-9._+-]+$";
        doc += std::string(doc.empty() ? "" : "; ") + "the value as text: the number " + f.value_key() +
               " when it is one, else a name (" + kNameRule + ")";
        break;
      case SweepField::Check::status:
        p["enum"] = run_status_names();
        break;
      case SweepField::Check::run_class:
        p["enum"] = run_class_names();
        break;
      case SweepField::Check::criterion:
      case SweepField::Check::none:
        break;
    }
    put(f, std::move(p), doc);
  }
  void operator()(const SweepField& f, const double&) {
    ordered p = f.is_not_null() ? type("number") : type({"number", "null"});
    if (std::isfinite(f.min())) p["minimum"] = bound(f.min());
    put(f, std::move(p));
  }
  void operator()(const SweepField& f, const std::optional<double>&) { put(f, type({"number", "null"})); }
  void operator()(const SweepField& f, const long long&) { put(f, integer(f)); }
  void operator()(const SweepField& f, const int&) { put(f, integer(f)); }
  void operator()(const SweepField& f, const bool&) { put(f, type("boolean")); }
  void operator()(const SweepField& f, const std::vector<std::string>&) {
    ordered p = type("array");
    p["items"] = type("string");
    put(f, std::move(p));
  }
  // The CPU time of every repeat (the reader's only list of numbers): at most kMaxRepeats.
  void operator()(const SweepField& f, const std::vector<double>&) {
    ordered p = type("array");
    p["items"] = type({"number", "null"});
    p["maxItems"] = kMaxRepeats;
    put(f, std::move(p));
  }
  // Settings: every value a setting's text.
  void operator()(const SweepField& f, const nlohmann::json&) {
    ordered p = type("object");
    p["additionalProperties"] = type("string");
    put(f, std::move(p));
  }
  void operator()(const SweepField& f, const Metrics&) {
    put(f, ordered{{"$ref", "comparison.schema.json#/$defs/metrics"}});
  }
  template <class T>
  void operator()(const SweepField& f, const std::optional<T>&) {
    SweepSchemaBuilder b;
    const T part{};
    visit(part, b);
    put(f, b.schema(ordered{"object", "null"}));
  }
  template <class Fields>
  void group(const SweepField& f, Fields&& fields) {
    SweepSchemaBuilder b;
    fields(b);
    put(f, b.schema(f.nullable() ? ordered{"object", "null"} : ordered("object")));
  }

  // {"type", "properties", "required" (sorted)} of the fields visited.
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
  static ordered bound(double m) {
    return m == std::floor(m) && std::fabs(m) < 1e15 ? ordered(static_cast<long long>(m)) : ordered(m);
  }
  static ordered integer(const SweepField& f) {
    ordered p = type("integer");
    p["minimum"] = f.lo();
    if (f.hi() != std::numeric_limits<long long>::max()) p["maximum"] = f.hi();
    return p;
  }
  void put(const SweepField& f, ordered p) { put(f, std::move(p), f.doc()); }
  void put(const SweepField& f, ordered p, const std::string& doc) {
    if (!doc.empty()) p["description"] = doc;
    properties[f.key()] = std::move(p);
    // A nullable group is also read when absent (records from before it).
    if (!f.is_since() && !f.nullable()) required.emplace_back(f.key());
  }
};

}  // namespace tippe
