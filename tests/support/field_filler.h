// A record filled through its field list with a distinct value per field, for the tests of what the list drives (JSON, schemas, the library's summary).
#pragma once

#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "harness/records/fields.h"

namespace tippe {

// Sets every field a `visit` lists to a value no other field has (strings among their choices),
// so that a field written under another's key, or read into another, shows in a round trip.
class Filler {
 public:
  void operator()(const Field& f, std::string& v) {
    v = f.choices() ? f.choices()->at(n_++ % f.choices()->size()) : "text " + std::to_string(n_++);
  }
  void operator()(const Field&, double& v) { v = 0.5 + n_++; }
  void operator()(const Field&, std::optional<double>& v) { v = 0.25 + n_++; }
  void operator()(const Field&, long long& v) { v = n_++; }
  void operator()(const Field&, std::optional<long long>& v) { v = n_++; }
  void operator()(const Field&, bool& v) { v = !v; }
  void operator()(const Field& f, std::vector<std::string>& v) {
    v = {f.choices() ? f.choices()->at(n_++ % f.choices()->size()) : "item " + std::to_string(n_++)};
  }
  void operator()(const Field&, nlohmann::json& v) { v = {{"key", n_++}}; }
  void operator()(const Field&, SettingsList& v) { v = {{"setting", std::to_string(n_++)}}; }
  template <class T, std::enable_if_t<has_visit<T>::value, int> = 0>
  void operator()(const Field&, T& part) { visit(part, *this); }
  template <class T>
  void operator()(const Field&, std::optional<T>& part) {
    part = T{};  // not emplace(): clang finds a nested struct with member initializers not default-constructible here
    visit(*part, *this);
  }
  template <class T>
  void operator()(const Field&, std::vector<T>& parts) {
    parts.resize(2);
    for (T& p : parts) visit(p, *this);
  }

 private:
  int n_ = 1;
};

template <class T>
T filled() {
  T r{};
  Filler f;
  visit(r, f);
  return r;
}

}  // namespace tippe
