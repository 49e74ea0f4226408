// Running a sweep: the references, the points on a task farm (each point's repeats folded into its record), the MPI messages.
#include "harness/sweep/sweep.h"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <optional>
#include <stdexcept>

#include "harness/io/append_file.h"
#include "harness/io/interrupt.h"
#include "harness/io/output_dir.h"
#include "harness/io/progress.h"
#include "harness/io/scene_io.h"
#include "harness/records/records.h"
#include "harness/sweep/sweep_detail.h"
#include "harness/sweep/sweep_progress.h"

namespace tippe {

namespace fs = std::filesystem;
using nlohmann::json;
using namespace sweep_detail;

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
