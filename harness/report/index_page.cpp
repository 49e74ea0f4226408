// The published index from the records alone: the verdict matrix (scenes down, engines across), the per-engine sentences, one row per scene, and every sweep with the matrix of its settings to use.
#include <algorithm>
#include <set>
#include <string>
#include <vector>

#include "harness/report/report.h"
#include "harness/report/report_text.h"
#include "harness/report/sweep_analysis.h"
#include "harness/report/sweep_groups.h"

namespace tippe {

using namespace report_text;

namespace {

// The legend: one row per kind, its colour's name in a cell of that colour.
DocTable legend() {
  DocTable t;
  t.css = "legend";
  t.header = {"colour", "verdict"};
  for (const auto& k : verdict_kinds()) t.rows.push_back({DocCell(verdict_colour_name(k), "v-" + k), DocCell(verdict_kind_text(k))});
  return t;
}

// The commits the records were made at, as one phrase ("commit abc" or "commits abc, def").
std::string commits_text(const std::set<std::string>& commits) {
  std::string s;
  for (const auto& c : commits) s += (s.empty() ? "" : ", ") + c;
  return (commits.size() == 1 ? "commit " : "commits ") + (s.empty() ? std::string("unknown") : s);
}

DocTable sweep_matrix(const IndexSweep& sw, const std::string& page) {
  using namespace sweep_report_detail;
  const std::vector<SceneGroup> scenes = group(sw.records);
  const std::vector<std::string> engines = engines_of(scenes);
  DocTable t;
  t.css = "matrix";
  t.row_headers = true;
  t.header.push_back("scene");
  for (const auto& e : engines) t.header.push_back(e);
  for (const SceneGroup& s : scenes) {
    std::vector<DocCell> row = {DocCell(s.name)};
    for (const auto& e : engines) {
      const SettingToUse u = setting_to_use(s, e);
      if (!u.found) {
        row.push_back(DocCell("-"));
      } else if (!u.point) {
        row.push_back(DocCell("none: " + u.why, "v-failed", sw.dir + "/" + page));
      } else {
        const SweepRecord& r = *u.point;
        std::string text = r.setup + " " + short_setting(r);
        if (u.tier != "regime" && r.metrics.inversion_time_rel_error)
          text += " (" + pct(std::abs(*r.metrics.inversion_time_rel_error)) + ")";
        text += ", " + g3(r.cpu_seconds) + " CPU s";
        // A near tie is part of the answer: the cell names how many, the page names them.
        if (!u.ties.empty())
          text += "; " + std::to_string(u.ties.size()) + " other" + (u.ties.size() > 1 ? "s" : "") + " within " +
                  pct(kCostResolution) + " of its CPU time";
        row.push_back(DocCell(text, "v-" + u.tier, sw.dir + "/" + page));
      }
    }
    t.rows.push_back(row);
  }
  return t;
}

}  // namespace

Document index_document(const IndexInput& input, const std::string& page) {
  Document d;
  d.title = "tippe: engine comparison reports";
  d.toc_from = 0;
  d.heading(1, "Tippe top: engines against the analytic reference");
  d.para("Each cell is one engine's verdict on one scene against the analytic reference: whether it is in the "
         "reference's regime (inverts when the reference does, and not otherwise) and, where both invert, its "
         "inversion-time error (engine minus reference, relative). A cell leads to that scene's page.");

  // Engines in the order the records first name them; never a list of names kept here.
  std::vector<std::string> engines;
  std::vector<nlohmann::json> comparisons;
  std::set<std::string> commits;
  for (const auto& [dir, c] : input.comparisons) {
    comparisons.push_back(c);
    for (const auto& e : c.at("engines"))
      if (std::find(engines.begin(), engines.end(), str(e, "engine")) == engines.end()) engines.push_back(str(e, "engine"));
    if (c.contains("provenance")) commits.insert(str(c.at("provenance"), "git_commit"));
  }
  DocTable m;
  m.css = "matrix";
  m.row_headers = true;
  m.header.push_back("scene");
  for (const auto& e : engines) m.header.push_back(e);
  for (const auto& [dir, c] : input.comparisons) {
    std::vector<DocCell> row = {DocCell(str(c, "scene_name"), "", dir + "/" + page)};
    for (const auto& e : engines) {
      const auto& entries = c.at("engines");
      const auto it = std::find_if(entries.begin(), entries.end(), [&](const nlohmann::json& x) { return str(x, "engine") == e; });
      if (it == entries.end()) {
        row.push_back(DocCell("not run"));
        continue;
      }
      const VerdictCell v = verdict_cell(c, *it);
      row.push_back(DocCell(v.text, "v-" + v.kind, dir + "/" + page));
    }
    m.rows.push_back(row);
  }
  d.table(m);
  d.table(legend());
  for (const auto& line : index_verdicts(comparisons)) d.para(line, "verdict");
  d.para("Times are in seconds for SI scenes and in units of √(R/g) (t = ...) for the source's dimensionless top. "
         "Every engine runs the scene as the bench sets it up; the settings each verdict depends on are on the scene's page.",
         "note");

  d.links({{"docs/reading-reports.md", "../docs/reading-reports.md"}},
          "How to read a page, and how every published page is regenerated from a commit:");

  d.heading(2, "Scenes");
  DocTable scenes;
  scenes.header = {"scene", "description", "inversion (reference and engines)"};
  for (const auto& [dir, c] : input.comparisons)
    scenes.rows.push_back({DocCell(str(c, "scene_name"), "", dir + "/" + page), DocCell(str(c.at("scene"), "description")),
                           DocCell(render_summary_line(c))});
  d.table(scenes);

  if (!input.sweeps.empty()) {
    d.heading(2, "Sweeps");
    d.para("Each sweep page is made from its records.jsonl alone. Below each, the setting to use of every engine on "
           "every scene of the sweep: the cheapest point below 1 % inversion-time error (green), else below 10 % "
           "(amber), where the reference inverts; the cheapest finished point in the reference's regime where it "
           "does not (light green); grey: no point qualifies. Never a point the stability map classes unphysical or "
           "diverged.");
    for (const IndexSweep& sw : input.sweeps) {
      d.heading(3, sw.dir);
      d.links({{sw.dir, sw.dir + "/" + page}}, sw.description.empty() ? "" : sw.description + ":");
      for (const SweepRecord& r : sw.records) commits.insert(r.git_commit);
      if (!sw.records.empty()) d.table(sweep_matrix(sw, page));
    }
  }
  d.footer.push_back("Made by tippe report REPORTS --index from the records alone; the records were made at " +
                     commits_text(commits) + ".");
  return d;
}

}  // namespace tippe
