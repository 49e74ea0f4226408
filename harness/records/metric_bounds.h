// The metrics of a comparison record that a bound may name, and bounds written as text ("METRIC <= NUMBER"): shared by gates and sweep searches.
#pragma once

#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "harness/records/comparison.h"

namespace tippe {

// ---- metrics a gate may bound --------------------------------------------------------------

// A numeric field of Metrics a threshold can name: every number of Metrics' `visit` but those it
// marks not_bounded (with the reason: timing, which depends on the machine and its load; counts
// that describe the event sequences; settings of the bench). cost_ratio is a ratio of CPU times
// on the same machine, so it stays. Its unit and meaning are the field's doc (field_list).
struct GateMetric {
  std::string name;
  std::function<std::optional<double>(const Metrics&)> get;  // nullopt: absent in this comparison
};
// Every gate metric, in the order of Metrics' `visit` (the order tables and results list them).
const std::vector<GateMetric>& gate_metrics();
// nullptr for a name that is not a gate metric.
const GateMetric* find_gate_metric(const std::string& name);

struct Threshold {
  std::string metric;  // a gate_metrics() name
  double max = 0;      // |value| <= max passes
};

// ---- bounds as text ---------------------------------------------------------------------------

// "" when `metric` may be gated (a gate metric), else the reason: for a field of Metrics its
// `visit`'s not_bounded reason.
std::string gate_metric_problem(const std::string& metric);
// "" when `x` is a usable threshold of `metric` (>= 0: |value| is compared), else the reason.
std::string threshold_problem(const std::string& metric, double x);
// One bound written as text, "NAME <= NUMBER" or "NAME >= NUMBER" (blanks around either part);
// throws std::invalid_argument with the reason (the caller names the file and key).
struct BoundText {
  std::string name, op;  // op: "<=" or ">="
  double bound = 0;
};
BoundText parse_bound_text(const std::string& text);
// A [check.max] entry as text, "METRIC <= NUMBER", with that entry's rules (a sweep's boundary
// search criterion is one); throws std::invalid_argument with the reason.
Threshold parse_threshold_text(const std::string& text);

// Whether `m` meets the bound: the metric is present, a number, and |value| <= t.max (an absent
// or NaN metric fails, as a gate's row does).
bool within_bound(const Threshold& t, const Metrics& m);

}  // namespace tippe
