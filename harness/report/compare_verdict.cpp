// The comparison's verdict in words: one sentence per engine against the reference, and the one-line summary `tippe compare` prints.
#include "harness/report/report.h"

#include <cmath>
#include <string>
#include <vector>

#include "harness/report/compare_ledger.h"
#include "harness/report/report_text.h"

namespace tippe {

using nlohmann::json;
using namespace report_text;

std::string render_summary_line(const json& c) {
  auto side = [](const json& s, const std::string& name, const std::string& rel) {
    std::string t = name + ": ";
    t += has_number(s, "inversion_time") ? "inverts at t = " + fmt(num(s, "inversion_time"), "%.6g") + rel
                                         : "no inversion to t = " + run_time_text(s);
    if (str(s, "status") != "ok") t += " (" + status_text(s) + ")";
    return t;
  };
  std::string line = side(c.at("reference").at("summary"), "reference", "");
  for (const json& e : c.at("engines")) {
    const double rel = num(e.at("metrics"), "inversion_time_rel_error");
    line += " | " + side(e.at("summary"), str(e, "engine"),
                         std::isfinite(rel) ? " (" + fmt(100 * rel, "%+.2g") + " %)" : std::string());
  }
  return line;
}

namespace {

std::string ended_text(const json& s) {
  return str(s, "status") + " at t = " + fmt(num(s, "status_time"), "%.6g");
}

std::string percent_late(double rel) {
  if (!std::isfinite(rel)) return "";
  if (rel == 0) return "at the same time";
  return fmt(100 * std::abs(rel), "%.3g") + " % " + (rel > 0 ? "late" : "early");
}

// The caveat for an engine's event past the end of the reference's converged window (its
// self-check): the verdict stands on a reference that is not trusted there.
std::string past_window(const json& metrics, const json& summary) {
  if (!has_number(metrics, "reference_converged_until") || !has_number(summary, "inversion_time")) return "";
  const double until = num(metrics, "reference_converged_until");
  if (!(num(summary, "inversion_time") > until)) return "";
  return "; it inverts after t = " + fmt(until, "%.6g") +
         ", where the reference's self-check says the reference is no longer converged, so this rests on an "
         "unconverged reference";
}

}  // namespace

std::vector<std::string> verdict_sentences(const json& c) {
  std::vector<std::string> out;
  const json& ref = c.at("reference").at("summary");
  const bool ref_inverts = has_number(ref, "inversion_time");
  const std::string ref_inv = fmt(num(ref, "inversion_time"), "%.6g");
  if (str(ref, "status") != "ok")
    out.push_back("The reference itself ended early (" + ended_text(ref) + "): every verdict below holds only up to then.");
  for (const json& e : c.at("engines")) {
    const std::string engine = str(e, "engine");
    const json& s = e.at("summary");
    const json& m = e.at("metrics");
    const bool ok = str(s, "status") == "ok";
    const bool inverts = has_number(s, "inversion_time");
    const std::string inv = fmt(num(s, "inversion_time"), "%.6g");
    const std::string early = ok ? "" : ", then its run ended early (" + ended_text(s) + ")";
    std::string t = engine + ": ";
    if (ref_inverts && inverts) {
      const double rel = num(m, "inversion_time_rel_error");
      t += "inverts like the reference, ";
      t += std::isfinite(rel) ? percent_late(rel) + " (t = " + inv + " against the reference's " + ref_inv + ")"
                              : "at t = " + inv + " against the reference's " + ref_inv +
                                    " (error not measured: " + str(m, "inversion_event") + ")";
      t += past_window(m, s) + early + ".";
    } else if (ref_inverts) {
      t += ok ? "does not invert by the end of its run (t = " + run_time_text(s) + ") while the reference inverts at t = " +
                    ref_inv + ": the wrong regime, no inversion time to compare."
              : "its run ended early (" + ended_text(s) + ") without inverting; the reference inverts at t = " + ref_inv +
                    ": neither its regime nor an inversion time can be compared.";
    } else if (inverts) {
      t += "inverts at t = " + inv + " while the reference does not invert to t = " + run_time_text(ref) +
           ": the wrong regime, no inversion time to compare" + past_window(m, s) + early + ".";
    } else {
      t += ok ? "does not invert to t = " + run_time_text(s) +
                    ", like the reference (the reference's regime); there is no inversion time to compare."
              : "its run ended early (" + ended_text(s) + ") without inverting; the reference does not invert to t = " +
                    run_time_text(ref) + ".";
    }
    // Where the engine deviates (another regime, an early end, or an inversion time off by more
    // than the report's 1 % green band), the verdict names where its energy went.
    const double rel = num(m, "inversion_time_rel_error");
    const bool deviates = !ok || ref_inverts != inverts || (std::isfinite(rel) && std::abs(rel) > kEventTimeGreenBand);
    if (deviates)
      if (const std::string cause = ledger_cause_sentence(c, e); !cause.empty()) t += " Energy: " + cause;
    out.push_back(t);
  }
  return out;
}

}  // namespace tippe
