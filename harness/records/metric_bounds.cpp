// The metrics a bound may name, read from a Metrics record, and bounds parsed from text.
#include "harness/records/metric_bounds.h"

#include <cmath>
#include <stdexcept>
#include <string>
#include <utility>

#include "harness/io/scene_io.h"
#include "harness/io/text.h"

namespace tippe {

namespace {

// The value of one numeric field of Metrics, found by its key in Metrics' `visit`.
class MetricValue {
 public:
  explicit MetricValue(std::string key) : key_(std::move(key)) {}
  void operator()(const Field& f, const double& v) { take(f, v); }
  void operator()(const Field& f, const long long& v) { take(f, static_cast<double>(v)); }
  void operator()(const Field& f, const std::optional<double>& v) {
    if (key_ == f.key()) value = v;
  }
  void operator()(const Field& f, const std::optional<long long>& v) {
    if (key_ == f.key() && v) value = static_cast<double>(*v);
  }
  template <class T>
  void operator()(const Field&, const T&) {}
  std::optional<double> value;

 private:
  void take(const Field& f, double v) {
    if (key_ == f.key()) value = v;
  }
  std::string key_;
};

// What Metrics' `visit` says of one key: whether it is a field and, when no bound may name it, why.
class FieldByKey {
 public:
  explicit FieldByKey(std::string key) : key_(std::move(key)) {}
  template <class T>
  void operator()(const Field& f, const T&) {
    if (key_ == f.key()) {
      found = true;
      why = f.not_bounded_why();
    }
  }
  bool found = false;
  std::string why;

 private:
  std::string key_;
};

}  // namespace

const std::vector<GateMetric>& gate_metrics() {
  static const std::vector<GateMetric> table = [] {
    std::vector<GateMetric> t;
    for (const FieldInfo& f : field_list<Metrics>())
      if (f.bounded)
        t.push_back({f.key, [key = f.key](const Metrics& m) {
                       MetricValue v(key);
                       visit(m, v);
                       return v.value;
                     }});
    return t;
  }();
  return table;
}

const GateMetric* find_gate_metric(const std::string& name) {
  for (const GateMetric& g : gate_metrics())
    if (name == g.name) return &g;
  return nullptr;
}

std::string gate_metric_problem(const std::string& metric) {
  if (find_gate_metric(metric)) return {};
  FieldByKey field(metric);
  const Metrics m{};
  visit(m, field);
  if (field.found && !field.why.empty()) return field.why;
  std::vector<std::string> names;
  for (const auto& g : gate_metrics()) names.emplace_back(g.name);
  return "unknown metric (expected one of: " + join(names, ", ") + ")";
}

std::string threshold_problem(const std::string& metric, double x) {
  // No upper bound: metrics differ in unit and scale (steps, seconds, ratios), and a loose
  // threshold is a visible choice of the gate's author, not a typo that hides a failure.
  if (!(x >= 0)) return short_value(x) + " is out of range (expected " + metric + " >= 0: |value| is compared)";
  return {};
}

BoundText parse_bound_text(const std::string& text) {
  const size_t le = text.find("<="), ge = text.find(">=");
  if ((le == std::string::npos) == (ge == std::string::npos))
    throw std::invalid_argument("\"" + utf8_replaced(text.substr(0, 80)) +
                                "\" is not a bound (expected NAME <= NUMBER or NAME >= NUMBER)");
  const size_t at = le != std::string::npos ? le : ge;
  BoundText b;
  b.name = trim(text.substr(0, at));
  b.op = text.substr(at, 2);
  const std::string value = trim(text.substr(at + 2));
  if (b.name.empty()) throw std::invalid_argument("\"" + utf8_replaced(text.substr(0, 80)) + "\": no name before " + b.op);
  char* end = nullptr;
  errno = 0;
  b.bound = value.empty() ? 0.0 : std::strtod(value.c_str(), &end);
  if (value.empty() || end != value.c_str() + value.size() || !std::isfinite(b.bound) ||
      value.find_first_not_of("0123456789+-.eE") != std::string::npos)
    throw std::invalid_argument("\"" + utf8_replaced(value.substr(0, 40)) + "\" after " + b.op +
                                " is not a finite number");
  return b;
}

Threshold parse_threshold_text(const std::string& text) {
  const BoundText b = parse_bound_text(text);
  if (b.op != "<=") throw std::invalid_argument("a metric is bounded from above: " + b.name + " <= NUMBER (|value| is compared)");
  if (const std::string why = gate_metric_problem(b.name); !why.empty()) throw std::invalid_argument(b.name + ": " + why);
  if (const std::string why = threshold_problem(b.name, b.bound); !why.empty()) throw std::invalid_argument(why);
  return Threshold{b.name, b.bound};
}

bool within_bound(const Threshold& t, const Metrics& m) {
  const GateMetric* g = find_gate_metric(t.metric);
  const std::optional<double> v = g ? g->get(m) : std::nullopt;
  return v && !std::isnan(*v) && std::abs(*v) <= t.max;
}

}  // namespace tippe
