// The metrics a bound may name, read from a Metrics record, and bounds parsed from text.
#include "harness/records/metric_bounds.h"

#include <cmath>
#include <stdexcept>

#include "harness/io/scene_io.h"
#include "harness/io/text.h"

namespace tippe {

#define TIPPE_GATE_VALUE(field, unit) \
  {#field, [](const Metrics& m) -> std::optional<double> { return static_cast<double>(m.field); }, unit}
#define TIPPE_GATE_OPTIONAL(field, unit) \
  {#field, [](const Metrics& m) -> std::optional<double> { return m.field; }, unit}

const std::vector<GateMetric>& gate_metrics() {
  static const std::vector<GateMetric> table = {
      TIPPE_GATE_OPTIONAL(inversion_time_abs_error, "s, engine - reference"),
      TIPPE_GATE_OPTIONAL(inversion_time_rel_error, "fraction of the reference's time"),
      TIPPE_GATE_OPTIONAL(stem_contact_time_abs_error, "s, engine - reference"),
      TIPPE_GATE_OPTIONAL(stem_contact_time_rel_error, "fraction of the reference's time"),
      TIPPE_GATE_VALUE(tilt_max_error, "rad"),
      TIPPE_GATE_VALUE(tilt_rms_error, "rad"),
      TIPPE_GATE_VALUE(energy_max_error, "/ E0"),
      TIPPE_GATE_VALUE(energy_final_ratio, "E_final / E0 of the engine"),
      TIPPE_GATE_VALUE(energy_gain_events, "count"),
      TIPPE_GATE_VALUE(energy_max_gain, "/ E0"),
      TIPPE_GATE_OPTIONAL(numerical_energy_max, "/ E0, largest |numerical energy| of the ledger (docs/energy-ledger.md)"),
      TIPPE_GATE_OPTIONAL(numerical_energy_final, "/ E0, numerical energy of the ledger at the end"),
      TIPPE_GATE_OPTIONAL(friction_work, "/ E0, work of the friction forces (|value| is compared)"),
      TIPPE_GATE_OPTIONAL(normal_work, "/ E0, work of the normal forces (|value| is compared)"),
      TIPPE_GATE_OPTIONAL(drilling_work, "/ E0, work of the drilling torques (|value| is compared)"),
      TIPPE_GATE_OPTIONAL(impact_energy, "/ E0, energy removed at impacts (|value| is compared)"),
      TIPPE_GATE_OPTIONAL(elastic_energy_max, "/ E0, largest elastic energy in the contact"),
      TIPPE_GATE_VALUE(contact_path_rms_error, "/ R"),
      TIPPE_GATE_VALUE(contact_path_max_error, "/ R"),
      TIPPE_GATE_VALUE(com_path_rms_error, "/ R"),
      TIPPE_GATE_VALUE(com_path_max_error, "/ R"),
      TIPPE_GATE_VALUE(latitude_rms_error, "rad"),
      TIPPE_GATE_OPTIONAL(jellett_drift_ball, "relative"),
      TIPPE_GATE_OPTIONAL(jellett_drift_stem, "relative"),
      TIPPE_GATE_VALUE(jellett_max_relative_drift, "relative"),
      TIPPE_GATE_VALUE(steps, "engine steps"),
      TIPPE_GATE_VALUE(cost_ratio, "engine CPU / reference CPU"),
      TIPPE_GATE_VALUE(compared_until, "s"),
      TIPPE_GATE_OPTIONAL(event_time_max_error, "s, largest over matched events (measure/event_alignment.h)"),
      TIPPE_GATE_OPTIONAL(events_missing, "reference events the engine lacks (count)"),
      TIPPE_GATE_OPTIONAL(events_extra, "engine events the reference lacks (count)"),
  };
  return table;
}

#undef TIPPE_GATE_VALUE
#undef TIPPE_GATE_OPTIONAL

const GateMetric* find_gate_metric(const std::string& name) {
  for (const GateMetric& g : gate_metrics())
    if (name == g.name) return &g;
  return nullptr;
}

std::string gate_metric_problem(const std::string& metric) {
  if (metric == "wall_seconds" || metric == "cpu_seconds" || metric == "real_time_factor")
    return "timing is never gated (it depends on the machine and its load); bound steps or cost_ratio";
  if (metric == "first_wrong_event")
    return "not a number: require the aligned event sequences to agree with require_no_wrong_event = true";
  if (!find_gate_metric(metric)) {
    std::vector<std::string> names;
    for (const auto& g : gate_metrics()) names.emplace_back(g.name);
    return "unknown metric (expected one of: " + join(names, ", ") + ")";
  }
  return {};
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
