// `tippe compare` (reference and engines on one scene, with a report) and `tippe report` (the report regenerated from records).
#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <memory>
#include <thread>

#include "engines/core/registry.h"
#include "harness/cli/cli.h"
#include "harness/library/verbs.h"
#include "harness/measure/compare.h"
#include "harness/report/report.h"
#include "harness/io/files.h"
#include "harness/io/scene_io.h"
#include "harness/scene/resolve.h"
#include "harness/records/sweep_record.h"

namespace tippe::cli {

namespace {

namespace fs = std::filesystem;

struct CompareCliOptions {
  std::string scene;
  std::vector<std::string> engines = engine_names();
  std::string out;
  int jobs = 0;  // 0: one per core, at most one per run
  std::vector<std::string> sets;
  std::string cache = "out/.reference-cache";
  bool no_cache = false;
  bool no_plots = false;
  bool no_self_check = false;
};

void print_table_and_findings(const nlohmann::json& j) { std::printf("%s", comparison_summary_text(j).c_str()); }

int compare(const CompareCliOptions& o) {
  Scene scene = load_scene(o.scene, o.sets);
  if (o.no_self_check) scene.run.self_check = false;
  CompareRequest request;
  request.engines = o.engines;
  request.jobs = o.jobs;
  request.out = o.out.empty() ? (fs::path("out") / (scene.name + "-compare")).string() : o.out;
  request.cache = o.no_cache ? "" : o.cache;
  request.plots = !o.no_plots;
  const Comparison c = compare_scene(scene, request);
  print_table_and_findings(to_json(c));
  std::printf("report: %s\n", (fs::path(request.out) / "index.html").string().c_str());
  return 0;
}

nlohmann::json read_comparison(const fs::path& file) {
  std::ifstream in(file);
  if (!in) throw UsageError(file.string() + ": cannot read (not a comparison directory?)");
  nlohmann::json j;
  try {
    j = nlohmann::json::parse(in);
    comparison_from_json(j);  // checks that every field the report reads is there
  } catch (const nlohmann::json::exception& e) {
    throw UsageError(file.string() + ": not a comparison record: " + e.what());
  } catch (const std::invalid_argument& e) {
    throw UsageError(file.string() + ": " + e.what());
  }
  return j;
}

// One verdict sentence per engine over every DIR/*/comparison.json (the published index's).
int index_verdict(const std::string& dir) {
  std::vector<fs::path> files;
  std::error_code ec;
  for (const auto& entry : fs::directory_iterator(dir, ec))
    if (fs::exists(entry.path() / "comparison.json")) files.push_back(entry.path() / "comparison.json");
  if (ec) throw UsageError(dir + ": cannot list (" + ec.message() + ")");
  if (files.empty()) throw UsageError(dir + ": no SCENE/comparison.json in it");
  std::sort(files.begin(), files.end());
  std::vector<nlohmann::json> comparisons;
  for (const auto& f : files) comparisons.push_back(read_comparison(f));
  for (const auto& line : index_verdicts(comparisons)) std::printf("%s\n", line.c_str());
  return 0;
}

// The published index from DIR/*/comparison.json and DIR/*/records.jsonl (with sweep.json): DIR/index.html
// and DIR/README.md, each written whole (the records are only read).
int write_index(const std::string& dir) {
  IndexInput input;
  std::vector<fs::path> subdirs;
  std::error_code ec;
  for (const auto& entry : fs::directory_iterator(dir, ec))
    if (entry.is_directory()) subdirs.push_back(entry.path());
  if (ec) throw UsageError(dir + ": cannot list (" + ec.message() + ")");
  std::sort(subdirs.begin(), subdirs.end());
  for (const fs::path& p : subdirs) {
    const std::string name = p.filename().string();
    if (fs::exists(p / "comparison.json")) {
      input.comparisons.push_back({name, read_comparison(p / "comparison.json")});
    } else if (fs::exists(p / "records.jsonl") && fs::exists(p / "sweep.json")) {
      IndexSweep sw;
      sw.dir = name;
      try {
        const nlohmann::json meta = nlohmann::json::parse(read_file_text((p / "sweep.json").string(), kMaxInputFileBytes));
        if (meta.contains("description") && meta.at("description").is_string()) sw.description = meta.at("description");
        sw.records = read_records((p / "records.jsonl").string()).records;
      } catch (const std::exception& e) {
        throw UsageError((p / "records.jsonl").string() + " or sweep.json: " + e.what());
      }
      input.sweeps.push_back(std::move(sw));
    }
  }
  if (input.comparisons.empty()) throw UsageError(dir + ": no SCENE/comparison.json in it");
  const std::string html = render_document_html(index_document(input, "index.html"));
  const std::string md = render_document_markdown(index_document(input, "report.md"));
  write_file_atomic((fs::path(dir) / "index.html").string(), html);
  write_file_atomic((fs::path(dir) / "README.md").string(), md);
  std::printf("index: %s\n", (fs::path(dir) / "index.html").string().c_str());
  return 0;
}

int report(const std::string& dir, bool no_plots, bool summary_line) {
  const nlohmann::json j = read_comparison(fs::path(dir) / "comparison.json");
  if (summary_line) {
    std::printf("%s\n", render_summary_line(j).c_str());
    return 0;
  }
  // The rebuilt report replaces the old one as a unit; the records stay as they are.
  const InterruptGuard interrupts;
  OutputDir out(dir, OutputKind::Comparison);
  write_report(out.stage(true).string(), j, !no_plots);
  out.commit();
  print_table_and_findings(j);
  std::printf("report: %s\n", (fs::path(dir) / "index.html").string().c_str());
  return 0;
}

}  // namespace

Command setup_compare(CLI::App& app) {
  auto o = std::make_shared<CompareCliOptions>();
  CLI::App* sub = app.add_subcommand(
      "compare", "Run the analytic reference and engines on one scene; write comparison.json, trajectories and a report");
  add_scene_options(sub, o->scene, o->sets);
  // One comma-separated value per --engines, so that the scene may follow it.
  sub->add_option("--engines", o->engines, "Engines to compare, comma-separated (" + engine_list_text(available_engines()) + ")")
      ->delimiter(',')
      ->allow_extra_args(false)
      ->check(CLI::IsMember(available_engines()))
      ->capture_default_str();
  sub->add_option("--out", o->out, "Output directory (default out/<scene name>-compare)");
  sub->add_option("--jobs,-j", o->jobs, "Runs in parallel (default: one per core)")->check(CLI::Range(1, kMaxJobs));
  sub->add_option("--cache", o->cache, "Reference cache directory")->capture_default_str();
  sub->add_flag("--no-cache", o->no_cache, "Always run the reference; leave the cache alone");
  sub->add_flag("--no-plots", o->no_plots, "Skip the gnuplot SVGs");
  sub->add_flag("--no-self-check", o->no_self_check,
                "Skip the reference's self-check (a second reference run with another method; same as "
                "--set run.self_check=false)");
  return {sub, [o] { return compare(*o); }};
}

Command setup_report(CLI::App& app) {
  auto dir = std::make_shared<std::string>();
  auto no_plots = std::make_shared<bool>(false), summary_line = std::make_shared<bool>(false),
       index = std::make_shared<bool>(false), write = std::make_shared<bool>(false);
  CLI::App* sub = app.add_subcommand(
      "report", "Regenerate report.md, index.html and plots of a `tippe compare` directory from its records");
  sub->add_option("dir", *dir, "Directory written by tippe compare")->required();
  sub->add_flag("--no-plots", *no_plots, "Skip the gnuplot SVGs");
  sub->add_flag("--summary-line", *summary_line, "Only print who inverts, on one line (writes nothing)");
  sub->add_flag("--index-verdict", *index,
                "DIR holds one comparison directory per scene: print one verdict sentence per engine over all of "
                "them (writes nothing)");
  sub->add_flag("--index", *write,
                "DIR holds one comparison directory per scene and sweep directories: write DIR/index.html and "
                "DIR/README.md (the verdict matrix, the per-engine sentences, the scenes and the sweeps) from their "
                "records alone");
  return {sub, [dir, no_plots, summary_line, index, write] {
            return *write ? write_index(*dir) : *index ? index_verdict(*dir) : report(*dir, *no_plots, *summary_line);
          }};
}

}  // namespace tippe::cli
