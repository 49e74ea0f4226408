// `tippe sweep --merge`: the shard directories of one sweep combined into the directory a whole run would have made.
#include <algorithm>
#include <filesystem>
#include <fstream>
#include <map>
#include <optional>
#include <set>
#include <sstream>
#include <tuple>

#include "harness/io/interrupt.h"
#include "harness/io/output_dir.h"
#include "harness/io/provenance.h"
#include "harness/records/records.h"
#include "harness/io/scene_io.h"
#include "harness/sweep/sweep.h"

namespace tippe {

namespace {

namespace fs = std::filesystem;
using json = nlohmann::json;

struct ShardDir {
  fs::path dir;
  json meta;
  int index = 0, count = 0;
  size_t points = 0;
  std::vector<std::string> ids;  // the shard's points, in plan order
  std::vector<SweepRecord> records;
};

[[noreturn]] void refuse(const std::string& why) { throw SweepInputError(why); }

ShardDir read_shard(const fs::path& dir) {
  ShardDir s;
  s.dir = dir;
  const fs::path meta = dir / "sweep.json", records = dir / "records.jsonl";
  std::error_code ec;
  if (!fs::is_regular_file(meta, ec)) refuse(dir.string() + ": no sweep.json (not a sweep directory)");
  SweepMeta m;
  try {
    m = parse_sweep_meta(read_file_text(meta.string()), meta.string());
  } catch (const std::exception& e) {
    refuse(std::string(e.what()) + " (not a sweep record)");
  }
  if (!m.points) refuse(meta.string() + ": points: missing (not a shard of this version's `tippe sweep --shard`)");
  if (!m.shard)
    refuse(meta.string() + ": shard: not a shard (it holds the whole sweep); merge takes the directories of "
                           "`tippe sweep SWEEP --shard I/N`");
  s.meta = std::move(m.meta);
  s.points = *m.points;
  s.index = m.shard->index;
  s.count = m.shard->count;
  s.ids = std::move(m.shard_point_ids);
  RecordsFile f;
  try {
    f = read_records(records.string());
  } catch (const std::exception& e) {
    refuse(e.what());
  }
  if (f.partial_bytes)
    refuse(records.string() + ": ends in a partial line (" + std::to_string(f.partial_bytes) +
           " bytes): the shard was cut short; run it again to finish it");
  s.records = std::move(f.records);
  return s;
}

std::string shard_name(const ShardDir& s) { return std::to_string(s.index) + "/" + std::to_string(s.count); }

bool same_dir(const fs::path& a, const fs::path& b) {
  std::error_code ec;
  return fs::exists(a, ec) && fs::exists(b, ec) && fs::equivalent(a, b, ec);
}

}  // namespace

MergeOutcome merge_sweeps(const std::vector<std::string>& shard_dirs, const std::string& out_dir, bool restart,
                          const SweepReportWriter& write_report) {
  if (shard_dirs.empty()) refuse("--merge needs the shard directories");
  if (out_dir.empty()) refuse("--merge needs --out DIR for the merged sweep");
  const fs::path out = out_dir;

  // Everything is read and checked before the output directory is touched.
  std::vector<ShardDir> shards;
  // The shard directories are written into sweep.json (merged_from): JSON, so UTF-8.
  for (const std::string& d : shard_dirs)
    if (!is_valid_utf8(d)) refuse(utf8_replaced(d) + ": the path is not valid UTF-8 (sweep.json records it)");
  for (const std::string& d : shard_dirs) {
    if (same_dir(d, out)) refuse(d + ": is the --out directory; merge into a new directory");
    shards.push_back(read_shard(d));
  }
  const ShardDir& first = shards.front();
  const std::string sweep_hash = first.meta["sweep_hash"], plan_hash = first.meta["plan_hash"];  // checked strings
  std::map<int, const ShardDir*> by_index;
  for (const ShardDir& s : shards) {
    const std::string h = s.meta["sweep_hash"], ph = s.meta["plan_hash"];
    if (h != sweep_hash)
      refuse(s.dir.string() + ": sweep_hash: a shard of another sweep file (" + h + ", " + first.dir.string() +
             " has " + sweep_hash + ")");
    if (ph != plan_hash)
      refuse(s.dir.string() + ": plan_hash: a shard of the same sweep file over other scene physics (" + ph + ", " +
             first.dir.string() + " has " + plan_hash + ")");
    if (s.count != first.count)
      refuse(s.dir.string() + ": shard: " + shard_name(s) + " is of another split than " + first.dir.string() + "'s " +
             shard_name(first));
    auto [it, fresh] = by_index.emplace(s.index, &s);
    if (!fresh) refuse(s.dir.string() + ": shard " + shard_name(s) + " given twice (also " + it->second->dir.string() + ")");
  }
  std::string missing;
  for (int i = 0; i < first.count; ++i)
    if (!by_index.count(i)) missing += (missing.empty() ? "" : ", ") + std::to_string(i) + "/" + std::to_string(first.count);
  if (!missing.empty()) refuse("shard(s) " + missing + " missing: every shard of the split must be merged");

  // Each shard holds exactly its own points, each once: nothing lost, nothing twice.
  std::set<std::string> all_ids;
  size_t search_points = 0;  // of those, boundary searches' points beyond the planned ones
  std::vector<const SweepRecord*> merged;
  MergeOutcome outcome;
  std::set<std::string> commits;
  for (const ShardDir& s : shards) {
    const std::set<std::string> own(s.ids.begin(), s.ids.end());
    // A boundary search's points beyond its coarse grid are planned from its records: they belong
    // to the shard that holds the search's planned points.
    std::set<std::tuple<long long, long long, long long>> own_searches;
    for (const SweepRecord& r : s.records)
      if (r.search && own.count(r.point_id)) own_searches.emplace(r.scene_index, r.setup_index, r.grid_index);
    std::set<std::string> seen, searched;
    for (const SweepRecord& r : s.records) {
      if (!own.count(r.point_id) && r.search && own_searches.count({r.scene_index, r.setup_index, r.grid_index})) {
        if (!searched.insert(r.point_id).second) continue;
        if (!all_ids.insert(r.point_id).second) refuse(s.dir.string() + ": point " + r.point_id + " is also in another shard");
        merged.push_back(&r);
        commits.insert(r.git_commit);
        ++search_points;
        continue;
      }
      if (!own.count(r.point_id))
        refuse((s.dir / "records.jsonl").string() + ": point " + r.point_id + " (" + r.scene + ", " + r.setup + ", " +
               r.ladder_key + " = " + ladder_text(r) +
               (r.grid_key.empty() ? std::string() : ", " + r.grid_key + " = " + grid_text(r)) + ") is not of shard " +
               shard_name(s));
      if (!seen.insert(r.point_id).second) continue;  // a duplicate line: the first counts, as in the report
      merged.push_back(&r);
      commits.insert(r.git_commit);
    }
    if (seen.size() != own.size())
      refuse(s.dir.string() + ": " + std::to_string(own.size() - seen.size()) + " of " + std::to_string(own.size()) +
             " points of shard " + shard_name(s) + " unfinished; run the shard again to finish it");
    for (const std::string& id : own)
      if (!all_ids.insert(id).second) refuse(s.dir.string() + ": point " + id + " is also in another shard");
  }
  if (all_ids.size() - search_points != first.points)
    refuse("the shards hold " + std::to_string(all_ids.size()) + " points, the sweep has " +
           std::to_string(first.points));
  if (commits.size() > 1) {
    std::string list;
    for (const std::string& c : commits) list += (list.empty() ? "" : ", ") + c;
    outcome.warnings.push_back("the shards' records come from more than one build (" + list + ")");
  }
  std::stable_sort(merged.begin(), merged.end(), [](const SweepRecord* a, const SweepRecord* b) {
    return std::tie(a->scene_index, a->setup_index, a->grid_index, a->ladder_index) <
           std::tie(b->scene_index, b->setup_index, b->grid_index, b->ladder_index);
  });

  // The output directory: new, or an earlier merge of the same sweep, or begun again (--restart).
  const fs::path meta_file = out / "sweep.json", records_file = out / "records.jsonl";
  std::error_code ec;
  if (fs::exists(meta_file, ec)) {
    std::optional<SweepMeta> old;
    try {
      old = parse_sweep_meta(read_file_text(meta_file.string()), meta_file.string());
    } catch (const std::exception&) {
      // Not a sweep's: refused below unless --restart.
    }
    const bool earlier_merge = old && old->sweep_hash == sweep_hash && old->plan_hash == plan_hash &&
                               old->meta.contains("merged_from");
    if (!earlier_merge && !restart)
      refuse(meta_file.string() + ": " + out.string() +
             " holds another sweep or a run of its own; give another --out, or --restart to begin it again");
  } else if (fs::exists(records_file, ec) && !restart) {
    refuse(records_file.string() + ": records without " + meta_file.string() +
           "; give another --out, or --restart to begin it again");
  }
  // The merged directory is written as one unit beside the old one and swapped in at the end.
  const InterruptGuard guard;
  std::vector<fs::path> inputs(shard_dirs.begin(), shard_dirs.end());
  OutputDir lock(out, OutputKind::Sweep, inputs);
  const fs::path stage = lock.stage(true);
  const fs::path staged_meta = stage / meta_file.filename(), staged_records = stage / records_file.filename();
  if (restart) keep_aside(staged_records);

  json meta = first.meta;
  meta["shard"] = nullptr;
  json from = json::array();
  for (const auto& [i, s] : by_index)
    from.push_back({{"dir", s->dir.string()}, {"index", i}, {"provenance", s->meta.value("provenance", json())}});
  meta["merged_from"] = from;
  meta["provenance"] = to_json(current_provenance());
  write_file_atomic(staged_meta.string(), meta.dump(2) + "\n");

  // The references, so that a later `tippe sweep SWEEP --out DIR` finds them cached.
  for (const auto& [i, s] : by_index) {
    const fs::path refs = s->dir / "reference";
    if (!fs::is_directory(refs, ec)) continue;
    for (const auto& entry : fs::directory_iterator(refs, ec)) {
      const fs::path src = entry.path(), dst = stage / "reference" / src.filename();
      if (!entry.is_directory() || fs::exists(dst / "summary.json", ec) || !fs::exists(src / "summary.json", ec))
        continue;
      fs::create_directories(dst);
      for (const char* name : {"trajectory.csv", "summary.json"})  // the summary last, as in the cache
        write_file_atomic((dst / name).string(), read_file_text((src / name).string()));
    }
  }

  std::string text;
  std::vector<SweepRecord> records;
  for (const SweepRecord* r : merged) {
    text += to_jsonl(*r);
    records.push_back(*r);
  }
  write_file_atomic(staged_records.string(), text);
  if (write_report) write_report(stage.string(), records);
  lock.commit();
  outcome.shards = shards.size();
  outcome.points = records.size();
  return outcome;
}

}  // namespace tippe
