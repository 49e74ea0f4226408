// The energy ledger's terms as the report pages show them: one table for the ledger section's columns and sentences and the ledger chart.
#pragma once

#include <cmath>
#include <vector>

#include <nlohmann/json.hpp>

#include "harness/report/report_text.h"

namespace tippe {

// A term of a run's account E_final - E0 as a run summary holds it.
struct LedgerTerm {
  const char* key;     // in the run summary
  const char* header;  // the ledger table's column
  const char* label;   // the chart's legend and bar tooltips
  const char* name;    // how a sentence names it
  double sign;         // with which it enters E_final - E0 (impacts remove energy)
  const char* colour;  // the chart's, from the Okabe-Ito palette (told apart with colour-blindness)
};

// The terms in table and stacking order: the works, the impacts, the numerical remainder last
// (what the others leave of E_final - E0).
inline const std::vector<LedgerTerm>& ledger_terms() {
  static const std::vector<LedgerTerm> t = {
      {"normal_work", "normal work", "normal work", "normal-force work", 1.0, "#E69F00"},
      {"friction_work", "friction work", "friction work", "friction work", 1.0, "#0072B2"},
      {"drilling_work", "drilling work", "drilling work", "drilling-torque work", 1.0, "#009E73"},
      {"impact_energy", "impacts (removed)", "impacts (removed)", "impacts", -1.0, "#CC79A7"},
      {"numerical_energy_final", "numerical (end)", "numerical", "numerical", 1.0, "#D55E00"}};
  return t;
}

// Whether a run summary holds a ledger: a run that kept one always writes its numerical remainder.
inline bool has_ledger(const nlohmann::json& s) { return report_text::has_number(s, "numerical_energy_final"); }

// |E0| of a run, by which its ledger terms are shown; 1 when E0 is 0 or missing.
inline double ledger_scale(const nlohmann::json& s) {
  const double e0 = report_text::num(s, "energy_initial");
  return std::isfinite(e0) && e0 != 0 ? std::abs(e0) : 1.0;
}

}  // namespace tippe
