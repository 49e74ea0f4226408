// Running a sweep: deciding what runs from OUT, the references, the points on a task farm, shards and the MPI messages.
#include "harness/sweep/sweep.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <map>
#include <memory>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <tuple>

#include "harness/io/append_file.h"
#include "harness/io/interrupt.h"
#include "harness/io/output_dir.h"
#include "harness/io/progress.h"
#include "harness/io/provenance.h"
#include "harness/io/scene_io.h"
#include "harness/scene/resolve.h"
#include "harness/records/records.h"
#include "harness/sweep/sweep_detail.h"
#include "harness/sweep/sweep_progress.h"

namespace tippe {

namespace fs = std::filesystem;
using nlohmann::json;
using namespace sweep_detail;

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

// What the coordinator found in OUT and decided, shared with every rank: which points run, in
// which order, and which references must be computed.
struct Prepared {
  std::vector<size_t> todo;        // indices into plan.points, in the order they are handed out
  std::vector<size_t> needed;      // scenes with a point in todo
  std::vector<size_t> to_compute;  // of those, the ones not in the cache
  std::vector<size_t> to_check;    // of those, the ones in the cache without the self-check asked for
  size_t share = 0, skipped = 0, cached = 0, partial_bytes = 0;
};

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

// The coordinator's half of the start: checks OUT, takes its lock, recovers records.jsonl and
// decides what runs. Throws SweepInputError before anything is written.
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

}  // namespace

std::string from_coordinator(TaskFarm& farm, const std::function<std::string()>& make) {
  std::string message;
  if (farm.coordinator()) {
    try {
      message = "ok\n" + make();
    } catch (const SweepInputError& e) {
      message = std::string("input\n") + e.what();
    } catch (const OutputError& e) {
      // An output directory that cannot be used (held by another tippe, not creatable) is bad input too.
      message = std::string("input\n") + e.what();
    } catch (const std::exception& e) {
      message = std::string("error\n") + e.what();
    }
  }
  farm.broadcast(message);
  const size_t nl = message.find('\n');
  const std::string kind = message.substr(0, nl);
  message.erase(0, nl + 1);
  if (kind == "input") throw SweepInputError(message);
  if (kind != "ok") throw std::runtime_error(message);
  return message;
}

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

SweepOutcome run_sweep(const SweepPlan& plan, const SweepOptions& o) {
  auto farm = make_thread_farm(o.jobs);
  return run_sweep(plan, o, *farm);
}

SweepOutcome run_sweep(const SweepPlan& plan, const SweepOptions& o, TaskFarm& farm) {
  const fs::path out = o.out_dir;
  const fs::path records_file = out / "records.jsonl";
  const auto t0 = std::chrono::steady_clock::now();
  std::vector<Reference> refs(plan.scenes.size());

  // 1. The coordinator decides; its decision (or its refusal) reaches every rank.
  std::unique_ptr<OutputDir> lock;
  Prepared prep;
  const std::string decision = from_coordinator(farm, [&] {
    prep = prepare(plan, o, lock, refs);
    return encode(prep);
  });
  if (!farm.coordinator()) prep = decode(decision);

  SweepOutcome outcome;
  outcome.points = prep.share;
  outcome.skipped = prep.skipped;
  outcome.references_cached = prep.cached;
  outcome.references_computed = prep.to_compute.size();
  outcome.self_checks_computed = prep.to_check.size();
  outcome.partial_bytes_dropped = prep.partial_bytes;

  // 2. Each missing reference is computed once, wherever a worker is free; the coordinator caches it.
  if (farm.coordinator() && o.progress && !prep.to_compute.empty())
    std::fprintf(stderr, "[sweep] computing %zu reference(s)\n", prep.to_compute.size());
  farm.run(
      prep.to_compute.size(), [&](size_t k) { return compute_reference_texts(plan.scenes[prep.to_compute[k]]); },
      [&](size_t k, std::string&& texts) {
        const size_t i = prep.to_compute[k];
        store_reference(out / "reference" / plan.physics_hashes[i], plan.scenes[i], plan.physics_hashes[i], texts,
                        refs[i]);
      });

  // 3. Every rank gets the same texts of every reference it needs, and reads them the way the cache is read.
  if (farm.distributed()) {
    const std::string bytes = from_coordinator(farm, [&] {
      std::string texts;
      for (size_t i : prep.needed) {
        if (!refs[i].failure.empty()) {
          texts += failed_reference_text(refs[i].failure_time, refs[i].failure);
          continue;
        }
        const fs::path dir = out / "reference" / plan.physics_hashes[i];
        texts += reference_text(read_file_text((dir / "summary.json").string()),
                                read_file_text((dir / "trajectory.csv").string()), refs[i].self_check);
      }
      return texts;
    });
    std::string error;
    if (!farm.coordinator()) {
      try {
        size_t pos = 0;
        for (size_t i : prep.needed) {
          if (read_failed_reference(bytes, pos, refs[i])) continue;
          const ReferenceTexts r = read_reference_text(bytes, pos);
          const std::string why = reference_from_text(r.summary, r.csv, plan.scenes[i], plan.physics_hashes[i],
                                                      "the reference of " + plan.scenes[i].name + " from rank 0",
                                                      refs[i].record, refs[i].trajectory);
          if (!why.empty()) throw std::runtime_error(why);
          refs[i].self_check = r.self_check;
        }
      } catch (const std::exception& e) {
        error = e.what();
      }
    }
    error = first_error(farm, error);
    if (!error.empty()) throw std::runtime_error(error);
  }

  // 4. The self-check alone of each cached reference without one, wherever a worker is free (every
  // rank holds the reference now); the coordinator caches it beside the reference and shares it.
  if (!prep.to_check.empty()) {
    if (farm.coordinator() && o.progress)
      std::fprintf(stderr, "[sweep] checking %zu cached reference(s): their self-check only\n", prep.to_check.size());
    farm.run(
        prep.to_check.size(),
        [&](size_t k) { return compute_self_check_text(plan.scenes[prep.to_check[k]], refs[prep.to_check[k]]); },
        [&](size_t k, std::string&& text) {
          const size_t i = prep.to_check[k];
          store_self_check_text(out / "reference" / plan.physics_hashes[i], plan.scenes[i], plan.physics_hashes[i],
                                text, refs[i]);
        });
    if (farm.distributed()) {
      const std::string bytes = from_coordinator(farm, [&] {
        std::vector<std::string> texts;
        for (size_t i : prep.to_check) texts.push_back(to_json(*refs[i].self_check).dump());
        return pack_texts(texts);
      });
      std::string error;
      if (!farm.coordinator()) {
        try {
          size_t pos = 0;
          const std::vector<std::string> texts = unpack_texts(bytes, pos, prep.to_check.size());
          for (size_t k = 0; k < texts.size(); ++k)
            refs[prep.to_check[k]].self_check = self_check_from_json(json::parse(texts[k]));
        } catch (const std::exception& e) {
          error = std::string("the self-checks from rank 0: ") + e.what();
        }
      }
      error = first_error(farm, error);
      if (!error.empty()) throw std::runtime_error(error);
    }
  }

  for (size_t i : prep.needed)
    if (refs[i].failure.empty()) refs[i].summary = reference_summary(plan.scenes[i], refs[i]);
  if (farm.coordinator())
    for (size_t i : prep.needed)
      if (!refs[i].failure.empty()) {
        size_t n = 0;
        for (size_t q : prep.todo) n += plan.points[q].scene_index == i;
        std::fprintf(stderr, "tippe: warning: %s; its %zu point(s) are recorded as failed\n", refs[i].failure.c_str(), n);
      }

  // 5. The points, each run `repeats` times (repeat_schedule: its repeats interleaved with other
  // points' runs), each run on some worker; the coordinator folds a point's repeats into its record
  // and appends its line when the last has come in.
  if (!prep.todo.empty()) {
    const int repeats = plan.spec.repeats;
    // 128 points: between two repeats of a point the 127 others of its block run once (some 60
    // point-lengths on two workers, 25 s in harness/sweeps/simbody.toml), so that a slow spell of
    // the machine does not last through all of a point's repeats. Such spells are why: the same run
    // alone took 0.24 CPU s or 0.37-0.39 s, in spells of one to nine runs (2 to 5 s), with no steal
    // time and on either core (BENCHMARKS.md, "A point's repeats"); in blocks of 32, three points
    // still drew the slow speed in all three rounds. An interrupted sweep runs at most a block's
    // points again. Four per worker on a larger farm, so that a block keeps every worker busy.
    const size_t block = std::max<size_t>(128, 4 * static_cast<size_t>(std::max(farm.workers(), 1)));
    const std::vector<SweepTask> tasks = repeat_schedule(prep.todo.size(), repeats, block);
    std::unique_ptr<RecordAppender> appender;
    std::unique_ptr<SweepProgress> progress;
    std::vector<std::chrono::steady_clock::time_point> started(tasks.size());
    // On the coordinator, per point (index into prep.todo): its first run, and every run's times by round.
    std::vector<std::optional<FirstRun>> firsts(prep.todo.size());
    std::vector<std::vector<std::optional<RepeatTime>>> times(prep.todo.size(),
                                                              std::vector<std::optional<RepeatTime>>(repeats));
    std::vector<int> arrived(prep.todo.size(), 0);
    if (farm.coordinator()) {
      appender = std::make_unique<RecordAppender>(records_file);
      progress = std::make_unique<SweepProgress>(plan, prep.todo, tasks, repeats, prep.share, prep.skipped,
                                                 farm.workers(), farm.distributed() || progress_mode() == ProgressMode::Lines);
    }
    const bool show = o.progress && progress_mode() != ProgressMode::Quiet;
    TaskFarm::Idle idle;
    if (show && farm.coordinator()) idle = [&] { progress->print(false); };
    farm.run(
        tasks.size(),
        [&](size_t k) {
          const SweepPoint& p = plan.points[prep.todo[tasks[k].point]];
          const Reference& ref = refs[p.scene_index];
          return tasks[k].round == 0 ? first_run_text(run_point_first(plan, p, ref))
                                     : repeat_time_text(time_point(plan, p, ref));
        },
        [&](size_t k, std::string&& text) {
          const size_t j = tasks[k].point;
          const int round = tasks[k].round;
          if (round == 0) {
            firsts[j] = read_first_run_text(text);
            const FirstRun& f = *firsts[j];
            if (f.timed && !f.record.cpu_seconds_repeats.empty())
              times[j][0] = RepeatTime{f.record.cpu_seconds_repeats.front(), f.record.wall_seconds};
          } else {
            times[j][static_cast<size_t>(round)] = read_repeat_time_text(text);
          }
          progress->end(k, std::chrono::duration<double>(std::chrono::steady_clock::now() - started[k]).count());
          if (++arrived[j] < repeats) return;
          FirstRun& f = *firsts[j];
          std::vector<RepeatTime> ran;
          for (const auto& t : times[j])
            if (t) ran.push_back(*t);
          set_repeat_times(f, ran);
          appender->append(to_jsonl(f.record));
          progress->point_done();
          firsts[j].reset();
        },
        [&](size_t k) {
          started[k] = std::chrono::steady_clock::now();
          progress->begin(k);
        },
        idle);
    if (show && farm.coordinator()) progress->print(true);
  }
  outcome.ran = prep.todo.size();
  outcome.wall_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();

  if (farm.coordinator() && o.write_report) {
    // The report's files change as one unit: an interrupted rerun of a finished sweep leaves the old report.
    const InterruptGuard guard;
    const std::vector<SweepRecord> records = read_records(records_file.string()).records;
    o.write_report(lock->stage(true).string(), records);
    lock->commit();
  }
  return outcome;
}

}  // namespace tippe
