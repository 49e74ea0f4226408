// The sweep report's boundary section: the largest safe setting per engine across scenes, then each search's bracket, runs, cost and crossings.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <set>
#include <tuple>

#include "harness/report/sweep_analysis.h"
#include "harness/sweep/sweep_search.h"

namespace tippe {

namespace {

std::string g4(double v) {
  char buf[40];
  std::snprintf(buf, sizeof buf, "%.4g", v);
  return buf;
}

std::string line_name(const SearchBoundary& b) {
  return b.setup + (b.grid_key.empty() ? "" : " (" + b.grid_key.substr(b.grid_key.rfind('.') + 1) + " = " + b.grid_label + ")");
}

// The boundary as a cell: the value, marked when the criterion is not monotonic or the search is
// not done; what stands in for it otherwise.
std::string cell(const SearchBoundary& b) {
  const bool larger = larger_is_softer(b.key);
  if (b.status == "not_applicable") return "n/a";
  if (b.status == "incomplete") return "unfinished";
  if (b.status == "none_safe") return "none (" + g4(larger ? b.search.from : b.search.to) + " fails)";
  std::string s = b.status == "all_safe" ? (larger ? ">= " : "<= ") + g4(*b.boundary) : g4(*b.boundary);
  if (!b.monotonic()) s += " (not monotonic)";
  return s;
}

std::string crossing_text(const SearchCrossing& c) {
  return g4(c.lo) + " .. " + g4(c.hi) + (c.lo_passes ? " (passes below)" : " (passes above)") +
         (c.resolved ? "" : " unresolved");
}

}  // namespace

std::vector<ReportPart> boundary_report(const std::vector<SweepRecord>& records) {
  const std::vector<SearchBoundary> bs = search_boundaries(records);
  std::vector<ReportPart> out;
  if (bs.empty()) return out;
  ReportPart h;
  h.kind = ReportPart::H2;
  h.text = "Boundaries: the largest safe setting";
  out.push_back(h);
  ReportPart intro;
  intro.text =
      "Each boundary search brackets where its criterion stops holding on a coarse log grid of the setting, then "
      "bisects each crossing in log10 until the bracket is narrower than its resolution. The boundary is the last "
      "safe value walking from the finest setting towards softer ones (for a time step: the largest safe step); "
      "a criterion that changes more than once on the coarse grid is marked not monotonic, every crossing is "
      "listed, and the boundary given is the first from the fine end. A point is safe (the one criterion of "
      "the page's opening sentence, its regime table and the gates) when the run finished (status ok), the "
      "stability map classes it ok (no divergence, no net energy gain in a dissipative scene " +
      energy_gain_rules_text(records) +
      ", no Jellett drift where "
      "J is conserved), and every term of the criterion holds: \"regime\": it inverts when the reference does "
      "and does not when it does not, within the reference's converged window; \"inversion within TOL\": "
      "where the reference inverts, |relative inversion-time error| <= TOL; \"METRIC <= BOUND\": |METRIC| <= "
      "BOUND. A change of the criterion between two coarse values that goes and "
      "comes back within one coarse interval is not seen.";
  out.push_back(intro);

  // Across scenes: one row per setup, criterion and grid value; one column per scene.
  std::vector<std::string> scenes;
  std::vector<std::string> lines;
  std::map<std::pair<std::string, std::string>, const SearchBoundary*> at;
  // Rows in setup order (the sweep file's), columns in scene order.
  std::vector<const SearchBoundary*> by_setup;
  for (const SearchBoundary& b : bs) by_setup.push_back(&b);
  std::stable_sort(by_setup.begin(), by_setup.end(), [](const SearchBoundary* a, const SearchBoundary* b) {
    return std::tie(a->setup_index, a->grid_index, a->scene_index) < std::tie(b->setup_index, b->grid_index, b->scene_index);
  });
  for (const SearchBoundary& b : bs)
    if (std::find(scenes.begin(), scenes.end(), b.scene) == scenes.end()) scenes.push_back(b.scene);
  for (const SearchBoundary* bp : by_setup) {
    const SearchBoundary& b = *bp;
    const std::string line = line_name(b) + "\n" + b.engine + "\n" + b.quantity + "\n" + b.criterion;
    if (std::find(lines.begin(), lines.end(), line) == lines.end()) lines.push_back(line);
    at.emplace(std::make_pair(line, b.scene), &b);
  }
  ReportPart t;
  t.kind = ReportPart::Tab;
  t.header = {"setup", "engine", "boundary", "criterion"};
  t.header.insert(t.header.end(), scenes.begin(), scenes.end());
  for (const std::string& line : lines) {
    std::vector<std::string> parts;
    size_t pos = 0;
    for (int k = 0; k < 3; ++k) {
      const size_t nl = line.find('\n', pos);
      parts.push_back(line.substr(pos, nl - pos));
      pos = nl + 1;
    }
    parts.push_back(line.substr(pos));
    std::vector<std::string> row = parts;
    for (const std::string& s : scenes) {
      const auto it = at.find({line, s});
      row.push_back(it == at.end() ? "-" : cell(*it->second));
    }
    t.rows.push_back(row);
  }
  ReportPart h3;
  h3.kind = ReportPart::H3;
  h3.text = "Largest safe setting per engine";
  out.push_back(h3);
  out.push_back(t);

  ReportPart h3b;
  h3b.kind = ReportPart::H3;
  h3b.text = "Each search";
  out.push_back(h3b);
  ReportPart d;
  d.kind = ReportPart::Tab;
  d.header = {"scene", "setup", "engine", "criterion", "boundary", "bracket (safe .. unsafe)", "runs",
              "CPU s at the boundary", "crossings on the coarse grid"};
  size_t non_monotonic = 0;
  for (const SearchBoundary& b : bs) {
    std::string bracket = "-";
    if (b.boundary && b.beyond) bracket = g4(*b.boundary) + " .. " + g4(*b.beyond);
    else if (b.status == "all_safe") bracket = "safe over " + g4(b.search.from) + " .. " + g4(b.search.to);
    std::string crossings;
    for (const SearchCrossing& c : b.replay.crossings) crossings += (crossings.empty() ? "" : "; ") + crossing_text(c);
    if (crossings.empty()) crossings = b.replay.coarse_complete() ? "none" : "-";
    if (!b.monotonic()) {
      crossings = "NOT MONOTONIC, " + std::to_string(b.replay.crossings.size()) + " crossings: " + crossings;
      ++non_monotonic;
    }
    char cpu[40] = "-";
    if (b.cpu_seconds) std::snprintf(cpu, sizeof cpu, "%.3g", *b.cpu_seconds);
    d.rows.push_back({b.scene, line_name(b), b.engine, b.criterion, cell(b), bracket, std::to_string(b.runs), cpu,
                      crossings});
  }
  out.push_back(d);
  if (non_monotonic) {
    ReportPart w;
    w.text = std::to_string(non_monotonic) +
             " search(es) found a criterion that changes more than once along the setting: the safe region is not "
             "one interval, and a boundary read off one bracket would hide the others.";
    out.push_back(w);
  }
  return out;
}

}  // namespace tippe
