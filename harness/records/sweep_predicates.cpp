// The predicates on a sweep record that its readers share (regime, ladder direction, axis text) and a search's criterion.
#include "harness/records/sweep_record.h"

#include <cmath>
#include <cstdio>
#include <stdexcept>
#include <string>
#include <vector>

#include "harness/io/text.h"

namespace tippe {

bool agrees_with_reference_regime(const SweepRecord& r) {
  if (r.reference_inversion_time) return r.inversion_time.has_value();
  return r.status == "ok" && !r.inversion_time;
}

bool larger_is_softer(const std::string& ladder_key) {
  const std::string last =
      ladder_key.substr(ladder_key.rfind('.') == std::string::npos ? 0 : ladder_key.rfind('.') + 1);
  return last.find("iterations") == std::string::npos && last.find("substeps") == std::string::npos;
}

namespace {
std::string axis_text(double value, const std::string& label) {
  if (!std::isfinite(value)) return label;
  char buf[64];
  std::snprintf(buf, sizeof buf, "%g", value);
  return buf;
}
}  // namespace

std::string ladder_text(const SweepRecord& r) { return axis_text(r.ladder_value, r.ladder_label); }
std::string grid_text(const SweepRecord& r) { return axis_text(r.grid_value, r.grid_label); }

// ---- the one criterion of "safe" ------------------------------------------------------------

namespace {


// "1%" -> 0.01, "0.01" -> 0.01; throws for anything else or a value outside (0, 10].
double parse_inversion_tolerance(const std::string& text) {
  std::string t = trim(text);
  bool percent = false;
  if (!t.empty() && t.back() == '%') {
    percent = true;
    t = trim(t.substr(0, t.size() - 1));
  }
  char* end = nullptr;
  const double v = std::strtod(t.c_str(), &end);
  if (t.empty() || end != t.c_str() + t.size() || !std::isfinite(v) || !(v > 0))
    throw std::invalid_argument("\"inversion within " + text + "\": expected a positive number or percentage (\"1%\", \"0.01\")");
  const double f = percent ? v / 100 : v;
  // An error above 10 (1000 %) of the inversion time says nothing a regime would not.
  if (f > 10) throw std::invalid_argument("\"inversion within " + text + "\": above 1000 %");
  return f;
}

}  // namespace

SearchCriterion parse_criterion(const std::string& text) {
  SearchCriterion c;
  c.regime = false;
  const std::string all = trim(text);
  std::vector<std::string> terms;
  for (size_t start = 0;;) {
    const size_t at = all.find(" and ", start);
    terms.push_back(trim(all.substr(start, at == std::string::npos ? std::string::npos : at - start)));
    if (at == std::string::npos) break;
    start = at + 5;
  }
  const std::string expected = " (expected \"regime\", \"inversion within TOL\" or \"METRIC <= BOUND\", joined by \" and \")";
  for (const std::string& t : terms) {
    if (t.empty()) throw std::invalid_argument("an empty term in the criterion \"" + all + "\"" + expected);
    if (t == "regime") {
      c.regime = true;
    } else if (t.rfind("inversion within", 0) == 0) {
      c.inversion = parse_inversion_tolerance(t.substr(16));
    } else {
      try {
        c.bounds.push_back(parse_threshold_text(t));
      } catch (const std::invalid_argument& e) {
        throw std::invalid_argument(std::string(e.what()) + expected);
      }
    }
  }
  return c;
}

std::string criterion_text(const SearchCriterion& c) {
  std::vector<std::string> terms;
  if (c.regime) terms.push_back("regime");
  if (c.inversion) terms.push_back("inversion within " + g6(100 * *c.inversion) + "%");
  for (const Threshold& t : c.bounds) terms.push_back(t.metric + " <= " + g6(t.max));
  std::string out;
  for (const std::string& t : terms) out += (out.empty() ? "" : " and ") + t;
  return out;
}

std::string unsafe_reason(const SearchCriterion& c, const SweepRecord& r) {
  // A run that finishes (status ok) in the reference's regime: a run that inverts at 1.76 s where
  // the reference does at 4.33 s and then falls through the floor (ODE on toy_viscous at dt
  // 0.0115) is in no sense safe, although the regime column, which only asks whether it
  // inverted, counts it.
  if (r.status != "ok") return "status " + r.status;
  // The stability map's class: the same measurement the page's map shows (classify_run).
  if (r.run_class != "ok") return "classed " + r.run_class + (r.class_reason.empty() ? "" : " (" + r.class_reason + ")");
  const bool ref_inverts = r.reference_inversion_time.has_value();
  const bool unconverged = r.metrics.inversion_event == "unconverged";
  if (c.regime) {
    if (unconverged) return "the inversion falls after the reference's converged window";
    if (!agrees_with_reference_regime(r))
      return ref_inverts ? "does not invert (the reference does)" : "inverts (the reference does not)";
  }
  if (c.inversion && ref_inverts) {
    if (unconverged) return "the inversion falls after the reference's converged window";
    const auto& e = r.metrics.inversion_time_rel_error;
    if (!r.inversion_time || !e || !std::isfinite(*e)) return "does not invert (the reference does)";
    if (!(std::abs(*e) <= *c.inversion))
      return "inversion-time error " + g6(100 * std::abs(*e)) + " % > " + g6(100 * *c.inversion) + " %";
  }
  for (const Threshold& t : c.bounds)
    if (!within_bound(t, r.metrics)) return t.metric + " beyond " + g6(t.max);
  return "";
}

bool is_safe(const SearchCriterion& c, const SweepRecord& r) { return unsafe_reason(c, r).empty(); }

}  // namespace tippe
