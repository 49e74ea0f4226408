// The reference of each scene of a sweep (or its self-check alone): computed once on any rank, cached in OUT/reference/, shared with every rank.
#include "harness/sweep/sweep_detail.h"

#include <cmath>
#include <filesystem>
#include <stdexcept>

#include "engines/core/registry.h"
#include "harness/measure/classify.h"
#include "harness/io/interrupt.h"
#include "harness/io/json_fields.h"
#include "harness/io/text.h"
#include "harness/records/records.h"
#include "harness/measure/run.h"

namespace tippe::sweep_detail {

namespace fs = std::filesystem;
using nlohmann::json;

// A point whose scene's reference failed: a failed record carrying the reference's reason, so that
// the other scenes' points run and the report shows which scene and why.
SweepRecord reference_failed_record(SweepRecord r, const Scene& scene, const Reference& ref) {
  const double nan = std::nan("");
  r.status = to_string(RunStatus::Failed);
  r.status_time = ref.failure_time;
  r.status_detail = "not run: " + ref.failure;
  r.run_class = "failed";
  r.class_time = ref.failure_time;
  r.class_reason = r.status_detail;
  Metrics& m = r.metrics;
  m.inversion_event = m.stem_contact_event = "no_reference";
  for (double* v : {&m.tilt_max_error, &m.tilt_rms_error, &m.energy_max_error, &m.energy_final_ratio,
                    &m.energy_max_gain, &m.contact_path_rms_error, &m.contact_path_max_error, &m.com_path_rms_error,
                    &m.com_path_max_error, &m.latitude_rms_error, &m.jellett_max_relative_drift, &m.wall_seconds,
                    &m.cpu_seconds, &m.real_time_factor, &m.cost_ratio, &m.compared_until})
    *v = nan;
  r.cpu_seconds = r.wall_seconds = 0;
  r.cpu_seconds_repeats = {0.0};
  r.engine_version = "unknown";
  SweepRecord::ReferenceRun f;
  f.status = f.run_class = "failed";
  f.method = scene.run.method;
  f.rtol = scene.run.rtol;
  f.cpu_seconds = f.energy_initial = f.energy_final = f.jellett_max_relative_drift = f.final_tilt = nan;
  r.reference = f;
  return r;
}

SweepRecord::ReferenceRun reference_summary(const Scene& scene, const Reference& ref) {
  SweepRecord::ReferenceRun f;
  f.status = ref.record.status;
  f.method = scene.run.method;
  f.rtol = scene.run.rtol;
  f.cpu_seconds = ref.record.work.cpu_seconds;
  f.steps = ref.record.work.steps;
  f.rhs_evaluations = ref.record.work.rhs_evaluations;
  f.energy_initial = ref.record.energy_initial;
  f.energy_final = ref.record.energy_final;
  f.jellett_max_relative_drift = ref.record.jellett_max_relative_drift;
  f.final_tilt = ref.record.final_tilt;
  f.run_class = to_string(classify_run(scene, ref.record, nullptr, ref.trajectory).kind);
  return f;
}


std::string pack_texts(const std::vector<std::string>& texts) {
  std::string out;
  for (const std::string& t : texts) out += std::to_string(t.size()) + "\n" + t;
  return out;
}

std::vector<std::string> unpack_texts(const std::string& bytes, size_t& pos, size_t count) {
  std::vector<std::string> out;
  for (size_t k = 0; k < count; ++k) {
    const size_t nl = bytes.find('\n', pos);
    if (nl == std::string::npos) throw std::runtime_error("reference message cut short");
    const size_t n = std::stoull(bytes.substr(pos, nl - pos));
    if (nl + 1 + n > bytes.size()) throw std::runtime_error("reference message cut short");
    out.push_back(bytes.substr(nl + 1, n));
    pos = nl + 1 + n;
  }
  return out;
}

std::string reference_text(const std::string& summary, const std::string& csv, const std::optional<SelfCheck>& check) {
  return "R" + pack_texts({summary, csv, check ? to_json(*check).dump() : std::string("null")});
}

ReferenceTexts read_reference_text(const std::string& bytes, size_t& pos) {
  std::vector<std::string> f = unpack_texts(bytes, pos, 3);
  ReferenceTexts r{std::move(f[0]), std::move(f[1]), std::nullopt};
  const json check = json::parse(f[2]);
  if (!check.is_null()) r.self_check = self_check_from_json(check);
  return r;
}

// What a reference's task sends back: 'R' and its two cache files' texts, or 'F' and, for a
// reference that failed, the time and the reason (a result, not an error: its scene's points are
// recorded as failed).
std::string failed_reference_text(double time, const std::string& why) {
  return "F" + pack_texts({json(number(time)).dump(), why});
}
// Reads a failed_reference_text at `pos` into ref; false (pos unmoved) for an 'R' entry.
bool read_failed_reference(const std::string& bytes, size_t& pos, Reference& ref) {
  if (pos >= bytes.size() || (bytes[pos] != 'F' && bytes[pos] != 'R')) throw std::runtime_error("reference message cut short");
  if (bytes[pos] == 'R') {
    ++pos;
    return false;
  }
  ++pos;
  const std::vector<std::string> f = unpack_texts(bytes, pos, 2);
  const json t = json::parse(f[0]);
  ref.failure_time = t.is_number() ? t.get<double>() : std::nan("");
  ref.failure = f[1];
  return true;
}

// Runs the reference at the scene's own tolerances, on whichever process the task lands.
std::string compute_reference_texts(const Scene& scene) {
  CsvTrajectoryText csv;
  TrajectorySink sink({&csv});
  RunRecord record;
  try {
    auto sim = make_simulator(reference_engine().name, scene);
    record = run_simulator(*sim, scene, &sink);
  } catch (const Interrupted&) {
    throw;  // a stop request (the Python module's Ctrl-C) is not a failed reference
  } catch (const std::exception& e) {
    return failed_reference_text(sink.trajectory.size() ? sink.trajectory.t.back() : 0.0,
                                 "the reference run of " + scene.name + " failed: exception: " + e.what());
  }
  if (record.status == to_string(RunStatus::Failed) || sink.trajectory.size() == 0)
    return failed_reference_text(record.status_time, "the reference run of " + scene.name + " failed at t = " +
                                                         num(record.status_time) + ": " + record.status_detail);
  std::optional<SelfCheck> check;
  if (scene.run.self_check) check = run_self_check(scene, record, sink.trajectory);
  return reference_text(to_json(record).dump(2) + "\n", csv.text, check);
}

// Into the cache (the summary last, so that its presence says the trajectory beside it is
// complete) and into memory, read back from the very texts every other rank will read. A failed
// reference is kept in memory only: the next run of the sweep finds its points recorded.
void store_reference(const fs::path& dir, const Scene& scene, const std::string& hash, const std::string& texts,
                     Reference& ref) {
  size_t pos = 0;
  if (read_failed_reference(texts, pos, ref)) return;
  const ReferenceTexts r = read_reference_text(texts, pos);
  fs::create_directories(dir);
  write_file_atomic((dir / "trajectory.csv").string(), r.csv);
  write_file_atomic((dir / "summary.json").string(), r.summary);
  const std::string why = reference_from_text(r.summary, r.csv, scene, hash, dir.string(), ref.record, ref.trajectory);
  if (!why.empty()) throw std::runtime_error("reference of " + scene.name + " does not read back: " + why);
  // Beside the reference it checks, keyed by that reference's provenance (reference_cache.h).
  ref.self_check = r.self_check;
  if (r.self_check) store_self_check(dir, hash, ref.record, *r.self_check);
}

std::string compute_self_check_text(const Scene& scene, const Reference& ref) {
  return to_json(run_self_check(scene, ref.record, ref.trajectory)).dump();
}

void store_self_check_text(const fs::path& dir, const Scene& scene, const std::string& hash, const std::string& text,
                           Reference& ref) {
  try {
    ref.self_check = self_check_from_json(json::parse(text));
  } catch (const std::exception& e) {
    throw std::runtime_error("self-check of the reference of " + scene.name + " does not read back: " + e.what());
  }
  store_self_check(dir, hash, ref.record, *ref.self_check);
}

}  // namespace tippe::sweep_detail
