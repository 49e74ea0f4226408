// Comparison reports from records alone: Markdown for terminals and CI logs, a self-contained HTML page, gnuplot SVG plots.
#pragma once

#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "harness/records/sweep_record.h"
#include "harness/report/document.h"

namespace tippe {

// Every function here reads a comparison.json document (to_json(Comparison)). An optional
// top-level "tolerances" object colours metric cells in the HTML: {"METRIC": {"green": a,
// "amber": b}} makes a value below a green, below b amber, else red (METRIC a key of the
// metrics, e.g. "tilt_rms_error"). Relative event-time errors default to green below 1 %,
// amber below 10 %; an event the reference has and the engine lacks (or the reverse) is red.

// The finding the page opens with: one sentence per engine, from the records alone: its regime
// against the reference's (inverts or not, and when), its inversion-time error, how its run
// ended when not ok.
std::vector<std::string> verdict_sentences(const nlohmann::json& comparison);

// The index of many comparisons opens with one sentence per engine over all of them: on how
// many scenes it is in the reference's regime (and on how many not), its inversion-time errors.
std::vector<std::string> index_verdicts(const std::vector<nlohmann::json>& comparisons);

// One engine's verdict on one scene, a cell of the index's matrix: its kind ("1pct", "10pct",
// "beyond": the reference's regime, both invert, and the inversion-time error's size; "regime":
// neither inverts; "wrong": the wrong regime; "failed": the run ended early without reaching the
// reference's regime) and its text (the signed inversion-time error, or what each side does).
struct VerdictCell {
  std::string kind, text;
};
VerdictCell verdict_cell(const nlohmann::json& comparison, const nlohmann::json& engine_entry);
// Every kind in the order the legend lists them, and each in words.
const std::vector<std::string>& verdict_kinds();
std::string verdict_kind_text(const std::string& kind);
// The name of its colour on the page ("dark green", ...), for the legend and the Markdown index.
std::string verdict_colour_name(const std::string& kind);

// The published index (reports/index.html and reports/README.md): the matrix of verdicts (scenes
// down, engines across, in the order the records name them), the per-engine sentences, one row per
// scene, and every sweep with the matrix of its settings to use. Made from the records alone.
struct IndexSweep {
  std::string dir;          // the sweep's directory, relative to the index
  std::string description;  // its sweep.json's
  std::vector<SweepRecord> records;  // its records.jsonl
};
struct IndexInput {
  std::vector<std::pair<std::string, nlohmann::json>> comparisons;  // scene directory, comparison.json
  std::vector<IndexSweep> sweeps;
};
// page: the file each scene and sweep directory is linked by ("index.html" or "report.md").
Document index_document(const IndexInput& input, const std::string& page);

// The summary table in Markdown: the reference, then one row per engine.
std::string render_summary_table(const nlohmann::json& comparison);
// Plain sentences: an event one side has and the other lacks, energy gain events, runs whose
// status is not ok (with time and detail). Empty when there is nothing to say.
std::vector<std::string> report_findings(const nlohmann::json& comparison);
// One line on who inverts: "reference: inverts at t = 17.25 | ode: inverts at t = 17.28 (+0.14 %) |
// bullet: no inversion (diverged at t = 3.2)"; for indexes of many reports.
std::string render_summary_line(const nlohmann::json& comparison);
// The page as one document: a back-link to the index and links to the data files, the verdict,
// the summary table, findings, plots, the scene, every engine's settings and notes, provenance.
// plot_files: SVG names relative to the page, shown in order with captions; plots_note: said
// where the plots go (e.g. "plots skipped: gnuplot not found"), or below them when some are
// missing; data_files: files beside the page to link besides comparison.json (the trajectories).
Document comparison_document(const nlohmann::json& comparison, const std::vector<std::string>& plot_files,
                             const std::string& plots_note = "", const std::vector<std::string>& data_files = {});
// report.md and index.html (self-contained: inline CSS, no scripts, no network) of that document.
std::string render_markdown(const nlohmann::json& comparison, const std::vector<std::string>& plot_files = {},
                            const std::string& plots_note = "");
std::string render_html(const nlohmann::json& comparison, const std::vector<std::string>& plot_files,
                        const std::string& plots_note = "", const std::vector<std::string>& data_files = {});

// The SVGs render_plots makes, in page order, and their captions.
const std::vector<std::string>& plot_file_names();
std::string plot_caption(const std::string& file);

struct PlotSet {
  std::vector<std::string> files;  // non-empty SVGs written, relative to out_dir
  std::string note;                // "" when every plot was made
};
// Writes plots.gp and decimated plot-*.dat files into out_dir from reference.csv and
// ENGINE.csv there, and runs gnuplot on them. Never throws for a missing gnuplot or trajectory:
// the note says what is missing. Plots it cannot remake (no gnuplot, no trajectory, gnuplot
// failing) that an earlier run left in out_dir stay and are listed in `files`.
PlotSet render_plots(const std::string& out_dir, const nlohmann::json& comparison);

// report.md, index.html and (when `plots`) the SVGs in out_dir, from `comparison` and the
// trajectories beside it; so `tippe report DIR` can regenerate a report from records alone.
// Without `plots`, SVGs already in out_dir are kept and shown.
void write_report(const std::string& out_dir, const nlohmann::json& comparison, bool plots);

}  // namespace tippe
