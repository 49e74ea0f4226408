// The energy-ledger section of the comparison report: each run's account of its energy and the dominant cause of an engine's loss.
#include "harness/report/compare_ledger.h"

#include <cmath>
#include <string>
#include <utility>
#include <vector>

#include "harness/report/ledger_chart.h"
#include "harness/report/ledger_terms.h"
#include "harness/report/report_text.h"

namespace tippe {

namespace {

using nlohmann::json;
using namespace report_text;

std::string rel(const json& s, const char* key) {
  return has_number(s, key) ? fmt(num(s, key) / ledger_scale(s), "%.3g") : std::string("n/a");
}

// The share of the run's energy loss E0 - E_final each term explains (impacts remove, the work
// terms and the numerical remainder add: each enters with the opposite of its sign in
// E_final - E0, which makes the shares sum to 100 % over the available terms).
struct Share {
  std::string name;
  double percent;
};
std::vector<Share> shares(const json& s) {
  const double loss = num(s, "energy_initial") - num(s, "energy_final");
  std::vector<Share> out;
  if (!(std::isfinite(loss) && loss != 0)) return out;
  for (const LedgerTerm& t : ledger_terms()) {
    if (!has_number(s, t.key)) continue;
    const double removed = -t.sign * num(s, t.key);
    out.push_back({t.name, 100.0 * removed / loss});
  }
  return out;
}

std::string share_text(const std::vector<Share>& sh) {
  std::string t;
  for (const Share& x : sh) t += (t.empty() ? "" : ", ") + fmt(x.percent, "%.3g") + " % " + x.name;
  return t;
}

// The ledger at the engine's first inversion as a summary-like object (energy_initial and the
// totals then), so that the same shares apply: an engine that turns over where the reference
// does not is judged on what it had spent by its flip, not by the end of its run.
json at_inversion(const json& s) {
  const json& p = s.at("ledger_at_inversion");
  json x = s;
  x["final_time"] = p.at("time");
  x["energy_final"] = p.at("energy");
  for (const char* k : {"normal_work", "friction_work", "drilling_work", "impact_energy"}) x[k] = p.at(k);
  x["numerical_energy_final"] = p.at("numerical_energy");
  return x;
}

}  // namespace

std::string ledger_cause_sentence(const json& c, const json& e) {
  const json& s_end = e.at("summary");
  if (!has_ledger(s_end)) return {};
  const bool flip = s_end.contains("ledger_at_inversion") && s_end.at("ledger_at_inversion").is_object();
  const json s = flip ? at_inversion(s_end) : s_end;
  const json& ref = c.at("reference").at("summary");
  const double loss = (num(s, "energy_initial") - num(s, "energy_final")) / ledger_scale(s);
  const std::string t_end = fmt(num(s, "final_time"), "%.6g");
  std::string out = "by t = " + t_end + (flip ? " (its inversion)" : "") + " its energy " +
                    (loss >= 0 ? "fell by " + fmt(loss, "%.3g") : "rose by " + fmt(-loss, "%.3g")) + " E0";
  if (has_ledger(ref))
    out += " (the reference's by its end, t = " + fmt(num(ref, "final_time"), "%.6g") + ": " +
           fmt((num(ref, "energy_initial") - num(ref, "energy_final")) / ledger_scale(ref), "%.3g") + " E0)";
  const std::vector<Share> sh = shares(s);
  if (sh.empty()) return out + ".";
  out += "; of that change " + share_text(sh);
  // The dominant cause: the term with the largest share of the loss (by magnitude), with the
  // reference's friction work beside the engine's, which says whether a contact the reference
  // keeps sticking (no friction work) did work in the engine.
  const Share* top = &sh.front();
  for (const Share& x : sh)
    if (std::abs(x.percent) > std::abs(top->percent)) top = &x;
  out += "; the dominant term: " + top->name;
  if (has_number(s, "friction_work") && has_number(ref, "friction_work"))
    out += " (friction work " + rel(s, "friction_work") + " E0 against the reference's " + rel(ref, "friction_work") +
           " E0 over its whole run to t = " + fmt(num(ref, "final_time"), "%.6g") + ")";
  // The creep or slip of a contact the reference keeps rolling, from the reference's own stick
  // events (over the compared window, not only to the inversion).
  if (e.contains("metrics") && has_number(e.at("metrics"), "friction_work_reference_sticks"))
    out += "; while the reference's contact sticks (in the compared window) the engine's friction did " +
           fmt(num(e.at("metrics"), "friction_work_reference_sticks"), "%.3g") + " E0 of work, the reference's none";
  const json na = s.value("ledger_not_available", json::array());
  if (!na.empty()) {
    std::string list;
    for (const auto& n : na) list += (list.empty() ? "" : ", ") + n.get<std::string>();
    out += "; not available: " + list + " (counted as 0 in the numerical remainder)";
  }
  return out + ".";
}

void add_energy_ledger(Document& d, const json& c, bool chart) {
  const json& ref = c.at("reference").at("summary");
  bool any = has_ledger(ref);
  for (const json& e : c.at("engines")) any = any || has_ledger(e.at("summary"));
  if (!any) return;
  d.heading(2, "Energy ledger");
  d.para("Where each run's energy went (docs/energy-ledger.md): E_final - E0 = normal work + friction work + drilling "
         "work - impacts + numerical, each / |E0| of its run. Work is done on the top by the contact forces, per step "
         "with the engine's own step (F . v_C h); the numerical remainder is the integrator's and the constraint "
         "stabilization's; the elastic energy is what a soft contact stores at most (part of the normal work). n/a: the "
         "simulator cannot give the term (counted as 0 in the remainder).",
         "note");
  DocTable t;
  // The columns: the terms, with the largest elastic energy (stored by a soft contact, part of the
  // normal work) before the numerical remainder, the last term, and the remainder's largest |N| after it.
  std::vector<std::pair<const char*, const char*>> columns;  // summary key, header
  for (const LedgerTerm& term : ledger_terms()) columns.push_back({term.key, term.header});
  columns.insert(columns.end() - 1, {"elastic_energy_max", "elastic max"});
  columns.push_back({"numerical_energy_max", "numerical max |N|"});
  t.header = {"run", "E final - E0"};
  for (const auto& col : columns) t.header.push_back(col.second);
  t.row_headers = true;
  t.css = "detail";
  auto row = [&](const std::string& name, const json& s) {
    const double de = (num(s, "energy_final") - num(s, "energy_initial")) / ledger_scale(s);
    std::vector<DocCell> cells = {DocCell(name), DocCell(fmt(de, "%.3g"))};
    for (const auto& col : columns) cells.push_back(DocCell(rel(s, col.first)));
    t.rows.push_back(cells);
  };
  row("reference", ref);
  for (const json& e : c.at("engines")) row(str(e, "engine"), e.at("summary"));
  d.table(t);
  if (chart)
    d.figure(kLedgerChartFile, "The same accounts as bars: each run's terms / |E0| stacked from 0 (losses left, gains "
                               "right); the black tick is E_final - E0, where the terms must end.");
  std::vector<std::string> lines;
  for (const json& e : c.at("engines"))
    if (const std::string l = ledger_cause_sentence(c, e); !l.empty()) lines.push_back(str(e, "engine") + ": " + l);
  if (!lines.empty()) d.list(lines);
}

}  // namespace tippe
