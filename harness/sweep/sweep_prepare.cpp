// Deciding what a sweep runs: OUT's record of the sweep checked against this run, the records already there read back as input, the shard's points, the cached references.
#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <map>
#include <memory>
#include <optional>
#include <set>
#include <sstream>
#include <stdexcept>
#include <tuple>

#include "harness/io/output_dir.h"
#include "harness/io/provenance.h"
#include "harness/io/scene_io.h"
#include "harness/records/records.h"
#include "harness/scene/resolve.h"
#include "harness/sweep/sweep_detail.h"

namespace tippe {

namespace fs = std::filesystem;
using nlohmann::json;

namespace sweep_detail {

namespace {

json shard_json(const SweepPlan& plan, const std::optional<SweepShard>& shard, const std::vector<size_t>& share) {
  if (!shard) return nullptr;
  json ids = json::array();
  // The points planned up front: a boundary search's later points follow their search's shard.
  for (size_t i : share)
    if (i < plan.planned) ids.push_back(plan.points[i].id);
  return json{{"index", shard->index}, {"count", shard->count}, {"point_ids", ids}};
}

json sweep_json(const SweepPlan& plan, const json& shard) {
  const Provenance p = current_provenance();
  json scenes = json::array(), setups = json::array();
  for (const Scene& s : plan.scenes) scenes.push_back(s.name);
  for (const SweepSetup& s : plan.spec.setups) setups.push_back(s.name);
  return json{{"format", "tippe-sweep-1"},
              {"sweep_file", plan.spec.file},
              {"sweep_hash", plan.spec.hash},
              {"plan_hash", plan.plan_hash},
              {"description", plan.spec.description},
              {"repeats", plan.spec.repeats},
              {"points", plan.planned},
              {"scenes", scenes},
              {"setups", setups},
              {"sweep_text", plan.spec.text},
              {"shard", shard},
              {"provenance", to_json(p)}};
}


std::string shard_text(const std::optional<SweepShard>& shard) {
  if (!shard) return "the whole sweep";
  return "shard " + std::to_string(shard->index) + "/" + std::to_string(shard->count);
}

}  // namespace

std::string encode(const Prepared& p) {
  std::ostringstream ss;
  auto list = [&](const std::vector<size_t>& v) {
    ss << v.size();
    for (size_t x : v) ss << ' ' << x;
    ss << '\n';
  };
  ss << p.share << ' ' << p.skipped << ' ' << p.cached << ' ' << p.partial_bytes << '\n';
  list(p.todo);
  list(p.needed);
  list(p.to_compute);
  list(p.to_check);
  return ss.str();
}

Prepared decode(const std::string& bytes) {
  std::istringstream ss(bytes);
  Prepared p;
  auto list = [&](std::vector<size_t>& v) {
    size_t n = 0;
    ss >> n;
    v.resize(n);
    for (size_t& x : v) ss >> x;
  };
  ss >> p.share >> p.skipped >> p.cached >> p.partial_bytes;
  list(p.todo);
  list(p.needed);
  list(p.to_compute);
  list(p.to_check);
  if (!ss) throw std::runtime_error("MPI: the coordinator's plan message is cut short");
  return p;
}

Prepared prepare(const SweepPlan& plan, const SweepOptions& o, std::unique_ptr<OutputDir>& lock,
                 std::vector<Reference>& refs) {
  if (o.jobs < 1) throw SweepInputError("jobs must be at least 1, got " + std::to_string(o.jobs));
  if (o.out_dir.empty()) throw SweepInputError("no output directory");
  const fs::path out = o.out_dir;
  const fs::path sweep_file = out / "sweep.json", records_file = out / "records.jsonl";
  std::vector<size_t> share;
  if (o.shard) {
    share = shard_points(plan, *o.shard);
  } else {
    share.resize(plan.points.size());
    for (size_t i = 0; i < share.size(); ++i) share[i] = i;
  }
  const json shard = shard_json(plan, o.shard, share);

  // What OUT holds is checked before anything is written to it.
  bool fresh = true;
  std::error_code ec;
  if (fs::exists(sweep_file, ec)) {
    std::optional<SweepMeta> old;
    try {
      old = parse_sweep_meta(read_file_text(sweep_file.string()), sweep_file.string());
    } catch (const std::exception& e) {
      if (!o.restart)
        throw SweepInputError(std::string(e.what()) + " (not a sweep record); give --restart to begin the directory again");
    }
    if (old) {
      const std::string& h = old->sweep_hash;
      const std::string& ph = old->plan_hash;
      if (h != plan.spec.hash && !o.restart)
        throw SweepInputError(sweep_file.string() + ": sweep_hash: " + out.string() +
                              " was started with another sweep file (hash " + utf8_replaced(h) + ", " + plan.spec.file +
                              " now has " + plan.spec.hash + "); give --restart to begin it again, or another --out");
      if (ph != plan.plan_hash && !o.restart)
        throw SweepInputError(sweep_file.string() + ": plan_hash: the physics of a scene of " + plan.spec.file +
                              " changed since " + out.string() +
                              " was started; give --restart to begin it again, or another --out");
      const json old_shard = old->meta.value("shard", json(nullptr));
      if (old_shard != shard && h == plan.spec.hash && ph == plan.plan_hash && !o.restart)
        throw SweepInputError(sweep_file.string() + ": shard: " + out.string() + " holds " + shard_text(old->shard) +
                              ", this run is " + shard_text(o.shard) +
                              "; give each shard its own --out (or --restart to begin it again)");
      fresh = h != plan.spec.hash || ph != plan.plan_hash || old_shard != shard;
    }
  } else if (fs::exists(records_file, ec) && !o.restart) {
    throw SweepInputError(records_file.string() + ": records without " + sweep_file.string() +
                          "; give --restart to begin the directory again, or another --out");
  }

  // The sweep file and every scene (and model) it reads stay outside OUT.
  std::vector<fs::path> inputs = {plan.spec.file};
  for (const Scene& s : plan.scenes)
    for (const fs::path& f : scene_input_files(s)) inputs.push_back(f);
  lock = std::make_unique<OutputDir>(out, OutputKind::Sweep, inputs);
  if (fresh || o.restart) {
    // Beginning again: earlier records are kept aside, never silently mixed with the new ones.
    keep_aside(records_file);
    write_file_atomic(sweep_file.string(), sweep_json(plan, shard).dump(2) + "\n");
  }

  Prepared p;
  p.share = share.size();
  RecordsFile existing;
  try {
    existing = recover_records(records_file.string());
  } catch (const std::exception& e) {
    throw SweepInputError(std::string(e.what()) + "; give --restart to begin the directory again, or another --out");
  }
  p.partial_bytes = existing.partial_bytes;
  if (existing.partial_bytes)
    std::fprintf(stderr, "tippe: %s: dropped a partial last line (%zu bytes); its point runs again\n",
                 records_file.string().c_str(), existing.partial_bytes);
  // Records read back are input: each must be a point of this run's share, where the plan has it.
  std::map<std::string, size_t> in_share;
  for (size_t i : share) in_share.emplace(plan.points[i].id, i);
  for (size_t k = 0; k < existing.records.size(); ++k) {
    const SweepRecord& r = existing.records[k];
    const std::string where = records_file.string() + ":" + std::to_string(existing.lines[k]) + ": ";
    const auto it = in_share.find(r.point_id);
    if (it == in_share.end())
      throw SweepInputError(where + "point_id: " + utf8_replaced(r.point_id.substr(0, 40)) + " is not a point of " +
                            (o.shard ? shard_text(o.shard) + " of " : std::string()) + plan.spec.file +
                            "'s plan; give --restart to begin the directory again, or another --out");
    const SweepPoint& p = plan.points[it->second];
    for (const auto& [key, got, want] :
         {std::make_tuple("scene_index", r.scene_index, p.scene_index), std::make_tuple("setup_index", r.setup_index, p.setup_index),
          std::make_tuple("ladder_index", r.ladder_index, p.ladder_index),
          std::make_tuple("grid.index", r.grid_index, p.grid_index)})
      if (got != static_cast<long long>(want))
        throw SweepInputError(where + key + ": " + std::to_string(got) + " is not point " + r.point_id + "'s (" +
                              std::to_string(want) + " in the plan); give --restart to begin the directory again");
    // Its class counted gains by the rule the point's scene asks for: a record from a build with
    // another default rule would mix two meanings of "unphysical" on one page.
    const std::string& rule = r.metrics.energy_gain_rule;
    if (!rule.empty() && rule != p.scene.run.energy_gain_rule)
      throw SweepInputError(where + "metrics.energy_gain_rule: \"" + utf8_replaced(rule) + "\" is not point " + r.point_id +
                            "'s (\"" + p.scene.run.energy_gain_rule +
                            "\"); its class counted energy gains by another rule; give --restart to begin the directory again");
  }
  std::set<std::string> done;
  size_t duplicates = 0;
  for (const SweepRecord& r : existing.records) duplicates += !done.insert(r.point_id).second;
  if (duplicates)
    std::fprintf(stderr, "tippe: warning: %s: %zu duplicate point ids (the report uses the first)\n",
                 records_file.string().c_str(), duplicates);

  std::vector<size_t> todo;
  for (size_t i : share)
    if (!done.count(plan.points[i].id)) todo.push_back(i);
  p.skipped = share.size() - todo.size();
  // The two cheapest points of each setup first: a few seconds in, every setup's overhead and
  // seconds per unit of weight are measured and the time left is a real estimate. Then the
  // longest first, so that the last point to finish is a short one and the cores stay busy.
  std::stable_sort(todo.begin(), todo.end(), [&](size_t a, size_t b) {
    return point_weight(plan, plan.points[a]) > point_weight(plan, plan.points[b]);
  });
  std::vector<size_t> order;
  std::map<size_t, int> calibration;
  std::set<size_t> first;
  for (auto it = todo.rbegin(); it != todo.rend(); ++it)
    if (++calibration[plan.points[*it].setup_index] <= 2) {
      order.push_back(*it);
      first.insert(*it);
    }
  for (size_t q : todo)
    if (!first.count(q)) order.push_back(q);
  p.todo = std::move(order);

  for (size_t i = 0; i < plan.scenes.size(); ++i)
    if (std::any_of(p.todo.begin(), p.todo.end(), [&](size_t q) { return plan.points[q].scene_index == i; }))
      p.needed.push_back(i);
  for (size_t i : p.needed) {
    const fs::path dir = out / "reference" / plan.physics_hashes[i];
    // The comparison cache's rule: same physics, same build, complete files. A cached reference
    // without the self-check asked for (absent, unreadable, or made for another reference or
    // method: load_cached_self_check) is kept, and only its self-check runs, as in a comparison.
    const Scene& scene = plan.scenes[i];
    if (!load_cached_reference(dir, scene, plan.physics_hashes[i], refs[i].record, refs[i].trajectory)) {
      p.to_compute.push_back(i);
      continue;
    }
    ++p.cached;
    if (scene.run.self_check) {
      refs[i].self_check =
          load_cached_self_check(dir, plan.physics_hashes[i], refs[i].record, self_check_method(scene.run));
      if (!refs[i].self_check) p.to_check.push_back(i);
    }
  }
  return p;
}

}  // namespace sweep_detail

using sweep_detail::point_weight;

SweepShard parse_shard(const std::string& text) {
  const size_t slash = text.find('/');
  auto number = [&](const std::string& part, long long& v) {
    if (part.empty() || part.size() > 9 || !std::all_of(part.begin(), part.end(), ::isdigit)) return false;
    v = std::stoll(part);
    return true;
  };
  long long i = -1, n = -1;
  if (slash == std::string::npos || !number(text.substr(0, slash), i) || !number(text.substr(slash + 1), n))
    throw std::invalid_argument("--shard \"" + text + "\": expected I/N, e.g. 0/4");
  if (n < 1 || n > 1000000 || i >= n)
    throw std::invalid_argument("--shard \"" + text + "\": I/N needs 1 <= N <= 1000000 and 0 <= I < N");
  return SweepShard{static_cast<int>(i), static_cast<int>(n)};
}

std::vector<size_t> shard_points(const SweepPlan& plan, const SweepShard& shard) {
  // Longest processing time first: the points by a priori weight, heaviest first (ties in plan
  // order), each to the shard with the least weight so far (ties to the lowest shard). A pure
  // function of the plan, so every job of an array computes the same partition.
  // A boundary search is one unit (its later points depend on its earlier records, so they
  // must be in one shard), weighed by its points planned up front; any other point is its own.
  std::vector<size_t> unit_of(plan.points.size());
  std::map<std::tuple<size_t, size_t, size_t>, size_t> search_unit;
  std::vector<double> w;
  for (size_t i = 0; i < plan.points.size(); ++i) {
    const SweepPoint& p = plan.points[i];
    size_t u = w.size();
    if (plan.spec.setups[p.setup_index].search)
      u = search_unit.emplace(std::make_tuple(p.scene_index, p.setup_index, p.grid_index), w.size()).first->second;
    if (u == w.size()) w.push_back(0.0);
    unit_of[i] = u;
    if (i < plan.planned) w[u] += point_weight(plan, p);
  }
  std::vector<size_t> byweight(w.size());
  for (size_t i = 0; i < byweight.size(); ++i) byweight[i] = i;
  std::stable_sort(byweight.begin(), byweight.end(), [&](size_t a, size_t b) { return w[a] > w[b]; });
  std::vector<double> load(static_cast<size_t>(shard.count), 0.0);
  std::vector<bool> unit_mine(w.size(), false);
  for (size_t u : byweight) {
    const size_t s = static_cast<size_t>(std::min_element(load.begin(), load.end()) - load.begin());
    load[s] += w[u];
    unit_mine[u] = s == static_cast<size_t>(shard.index);
  }
  std::vector<size_t> mine;
  for (size_t i = 0; i < plan.points.size(); ++i)
    if (unit_mine[unit_of[i]]) mine.push_back(i);
  return mine;
}

}  // namespace tippe
