// The sweep record (one line of records.jsonl) and sweep.json: writing them, and reading them back as checked input.
#include "harness/records/sweep_record.h"
#include "harness/io/json_fields.h"
#include "harness/io/text.h"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>
#include <stdexcept>

#include "harness/io/scene_io.h"
#include "harness/records/records.h"

namespace tippe {

namespace fs = std::filesystem;
using nlohmann::json;

namespace {


// A record read back is input like any file: every field is checked for its type and range, and
// an error names its dotted key ("work.steps: ..."), never a bare json exception or a number
// converted with undefined behaviour (steps = 1e300 read as a long long).
class RecordReader {
 public:
  [[noreturn]] static void fail(const std::string& key, const std::string& why) {
    throw SweepRecordError(key + ": " + why);
  }
  static std::string dotted(const std::string& prefix, const char* key) {
    return prefix.empty() ? std::string(key) : prefix + "." + key;
  }
  static const json& at(const json& j, const std::string& prefix, const char* key) {
    if (!j.is_object()) fail(prefix.empty() ? "record" : prefix, std::string("expected an object, got ") + j.type_name());
    const auto it = j.find(key);
    if (it == j.end()) fail(dotted(prefix, key), "missing");
    return *it;
  }
  static std::string string(const json& j, const std::string& prefix, const char* key) {
    const json& v = at(j, prefix, key);
    if (!v.is_string()) fail(dotted(prefix, key), std::string("expected a string, got ") + v.type_name());
    return v.get<std::string>();
  }
  // A number or null (NaN: not finite when written); `lo` bounds it from below when given.
  static double number(const json& j, const std::string& prefix, const char* key,
                       double lo = -std::numeric_limits<double>::infinity()) {
    const json& v = at(j, prefix, key);
    if (v.is_null()) return std::nan("");
    if (!v.is_number()) fail(dotted(prefix, key), std::string("expected a number or null, got ") + v.type_name());
    const double x = v.get<double>();
    if (!(x >= lo)) fail(dotted(prefix, key), v.dump() + " is out of range (expected >= " + num(lo) + ")");
    return x;
  }
  static std::optional<double> optional(const json& j, const std::string& prefix, const char* key) {
    const double x = number(j, prefix, key);
    if (std::isnan(x)) return std::nullopt;
    return x;
  }
  // An integer in [lo, hi]: a float, a string or a value beyond long long is refused by name.
  static long long integer(const json& j, const std::string& prefix, const char* key, long long lo, long long hi) {
    const json& v = at(j, prefix, key);
    const std::string k = dotted(prefix, key);
    const std::string range = std::to_string(lo) + " <= " + key + " <= " + std::to_string(hi);
    if (!v.is_number_integer())
      fail(k, (v.is_number() ? v.dump() + " is not an integer" : std::string("expected an integer, got ") + v.type_name()) +
                  " (expected " + range + ")");
    long long x = 0;
    if (v.is_number_unsigned()) {
      if (v.get<std::uint64_t>() > static_cast<std::uint64_t>(hi)) fail(k, v.dump() + " is out of range (expected " + range + ")");
      x = static_cast<long long>(v.get<std::uint64_t>());
    } else {
      x = v.get<long long>();
    }
    if (x < lo || x > hi) fail(k, v.dump() + " is out of range (expected " + range + ")");
    return x;
  }
  // A setting key ("engines.ode.timestep"): the rule of names, as it reaches report labels.
  static std::string key(const json& j, const std::string& prefix, const char* k) {
    const std::string v = string(j, prefix, k);
    if (!is_valid_name(v))
      fail(dotted(prefix, k), "\"" + utf8_replaced(v.substr(0, 40)) + "\" is not a usable key (" + kNameRule + ")");
    return v;
  }
  // An axis value as text: a name or a number; the number of `value` (NaN: none) when it is one.
  static std::string label(const json& j, const std::string& prefix, const char* k, double value,
                           const char* value_key) {
    const std::string v = string(j, prefix, k);
    const std::string where = dotted(prefix, k);
    const std::string shown = "\"" + utf8_replaced(v.substr(0, 40)) + "\"";
    const std::optional<double> x = number_text_value(v);
    if (!x && !is_valid_name(v)) fail(where, shown + " is neither a number nor a usable name (" + kNameRule + ")");
    if (!std::isnan(value) && (!x || *x != value))
      fail(where, shown + " is not " + value_key + " " + num(value));
    if (std::isnan(value) && x) fail(where, shown + " is a number, but " + value_key + " is null");
    return v;
  }
  // The number a text is, all of it, finite; nullopt otherwise.
  static std::optional<double> number_text_value(const std::string& v) {
    if (v.empty() || v.size() > 40) return std::nullopt;
    char* end = nullptr;
    const double x = std::strtod(v.c_str(), &end);
    if (end != v.c_str() + v.size() || !std::isfinite(x)) return std::nullopt;
    // strtod reads "inf", "nan", hex and leading blanks; a label is none of those.
    if (v.find_first_not_of("0123456789+-.eE") != std::string::npos) return std::nullopt;
    return x;
  }
  // One of `names`.
  static std::string name(const json& j, const std::string& prefix, const char* key,
                          std::initializer_list<const char*> names) {
    const std::string v = string(j, prefix, key);
    std::string list;
    for (const char* n : names) {
      if (v == n) return v;
      list += (list.empty() ? "" : ", ") + std::string(n);
    }
    fail(dotted(prefix, key), "\"" + utf8_replaced(v.substr(0, 40)) + "\" is not one of " + list);
  }
};

// Bounds of a record's counts: a point's indices are below the plan's size, repeats as in a
// sweep file, work counters are counts (long long holds any a run can reach).
constexpr long long kMaxCount = std::numeric_limits<long long>::max();

json reference_json(const std::optional<SweepRecord::ReferenceRun>& f) {
  if (!f) return nullptr;
  return json{{"status", f->status},
              {"method", f->method},
              {"class", f->run_class},
              {"rtol", number(f->rtol)},
              {"cpu_seconds", number(f->cpu_seconds)},
              {"steps", f->steps},
              {"rhs_evaluations", f->rhs_evaluations},
              {"energy_initial", number(f->energy_initial)},
              {"energy_final", number(f->energy_final)},
              {"jellett_max_relative_drift", number(f->jellett_max_relative_drift)},
              {"final_tilt", number(f->final_tilt)}};
}

// The class a status implies when no trajectory is at hand (records from before classification).
std::string class_of_status(const std::string& status) {
  for (const char* c : {"ok", "diverged", "clamped", "failed", "contact_lost"})
    if (status == c) return status;
  return "failed";
}

json search_json(const std::optional<SweepSearch>& q) {
  if (!q) return nullptr;
  return json{{"criterion", q->criterion},
              {"from", q->from},
              {"to", q->to},
              {"resolution", q->resolution},
              {"per_decade", q->per_decade},
              {"integer", q->integer}};
}

// A record's search, with the rules of `ladder.search` in a sweep file (sweep_search.h).
SweepSearch search_from_json(const json& j) {
  using R = RecordReader;
  SweepSearch q;
  q.criterion = R::string(j, "search", "criterion");
  try {
    parse_criterion(q.criterion);
  } catch (const std::invalid_argument& e) {
    R::fail("search.criterion", e.what());
  }
  q.from = R::number(j, "search", "from", std::numeric_limits<double>::min());
  q.to = R::number(j, "search", "to", q.from);
  q.resolution = R::number(j, "search", "resolution", kMinSearchResolution);
  if (!(q.to > q.from) || !(q.resolution <= kMaxSearchResolution) || std::log10(q.to / q.from) > kMaxSearchDecades)
    R::fail("search", "not a search's range and resolution (expected 0 < from < to, at most " + num(kMaxSearchDecades) +
                          " decades, resolution <= " + num(kMaxSearchResolution) + ")");
  q.per_decade = static_cast<int>(R::integer(j, "search", "per_decade", 1, kMaxSearchPerDecade));
  if (j.contains("integer")) {
    const json& i = j.at("integer");
    if (!i.is_boolean()) R::fail("search.integer", std::string("expected true or false, got ") + i.type_name());
    q.integer = i.get<bool>();
    if (q.integer && (q.from != std::floor(q.from) || q.to != std::floor(q.to)))
      R::fail("search.integer", "from and to of an integer search are whole numbers");
  }
  return q;
}

}  // namespace

json to_json(const SweepRecord& r) {
  json cpu = json::array();
  for (double c : r.cpu_seconds_repeats) cpu.push_back(number(c));
  return json{
      {"format", "tippe-sweep-record-1"},
      {"point_id", r.point_id},
      {"scene", r.scene},
      {"scene_file", r.scene_file},
      {"physics_hash", r.physics_hash},
      {"scene_index", r.scene_index},
      {"setup", r.setup},
      {"engine", r.engine},
      {"set", r.set},
      {"ladder_key", r.ladder_key},
      {"ladder_value", number(r.ladder_value)},
      {"ladder_label", !r.ladder_label.empty() || !std::isfinite(r.ladder_value) ? r.ladder_label
                                                                                 : json(r.ladder_value).dump()},
      {"setup_index", r.setup_index},
      {"ladder_index", r.ladder_index},
      {"grid", r.grid_key.empty() ? json(nullptr)
                                  : json{{"key", r.grid_key},
                                         {"value", number(r.grid_value)},
                                         {"label", r.grid_label},
                                         {"index", r.grid_index}}},
      {"repeats", r.repeats},
      {"duration", number(r.duration)},
      {"status", r.status},
      {"status_time", number(r.status_time)},
      {"status_detail", r.status_detail},
      {"inversion_time", number(r.inversion_time)},
      {"stem_contact_time", number(r.stem_contact_time)},
      {"reference_inversion_time", number(r.reference_inversion_time)},
      {"reference_stem_contact_time", number(r.reference_stem_contact_time)},
      {"metrics", to_json(r.metrics)},
      {"work",
       {{"cpu_seconds", number(r.cpu_seconds)},
        {"cpu_seconds_repeats", cpu},
        {"wall_seconds", number(r.wall_seconds)},
        {"steps", r.steps},
        {"rhs_evaluations", r.rhs_evaluations},
        {"solver_iterations", r.solver_iterations}}},
      {"engine_version", r.engine_version},
      {"git_commit", r.git_commit},
      {"settings", r.settings},
      {"class", {{"name", r.run_class}, {"time", number(r.class_time)}, {"reason", r.class_reason}}},
      {"reference", reference_json(r.reference)},
      {"search", search_json(r.search)},
  };
}

SweepRecord sweep_record_from_json(const json& j) {
  using R = RecordReader;
  const std::string format = R::string(j, "", "format");
  if (format != "tippe-sweep-record-1")
    R::fail("format", "unknown record format \"" + utf8_replaced(format.substr(0, 40)) + "\" (expected tippe-sweep-record-1)");
  const long long max_index = static_cast<long long>(kMaxSweepPoints) - 1;
  SweepRecord r;
  r.point_id = R::string(j, "", "point_id");
  r.scene = R::string(j, "", "scene");
  r.scene_file = R::string(j, "", "scene_file");
  r.physics_hash = R::string(j, "", "physics_hash");
  r.scene_index = R::integer(j, "", "scene_index", 0, max_index);
  r.setup = R::string(j, "", "setup");
  r.engine = R::string(j, "", "engine");
  // Names read back become file names and report labels: the rule of names in input files.
  for (const auto& [key, name] : {std::pair<const char*, const std::string*>{"scene", &r.scene},
                                  {"setup", &r.setup},
                                  {"engine", &r.engine}})
    if (!is_valid_name(*name)) R::fail(key, "\"" + *name + "\" is not a usable name (" + kNameRule + ")");
  const json& set = R::at(j, "", "set");
  if (!set.is_array()) R::fail("set", std::string("expected an array, got ") + set.type_name());
  for (size_t i = 0; i < set.size(); ++i) {
    if (!set[i].is_string()) R::fail("set[" + std::to_string(i) + "]", std::string("expected a string, got ") + set[i].type_name());
    r.set.push_back(set[i].get<std::string>());
  }
  r.ladder_key = R::key(j, "", "ladder_key");
  r.ladder_value = R::number(j, "", "ladder_value");
  // Records from before categorical ladders carry only the number.
  if (j.contains("ladder_label"))
    r.ladder_label = R::label(j, "", "ladder_label", r.ladder_value, "ladder_value");
  else if (std::isnan(r.ladder_value))
    R::fail("ladder_label", "missing (required when ladder_value is null)");
  else
    r.ladder_label = json(r.ladder_value).dump();
  r.setup_index = R::integer(j, "", "setup_index", 0, max_index);
  r.ladder_index = R::integer(j, "", "ladder_index", 0, max_index);
  if (j.contains("grid") && !j.at("grid").is_null()) {
    const json& g = j.at("grid");
    r.grid_key = R::key(g, "grid", "key");
    r.grid_value = R::number(g, "grid", "value");
    r.grid_label = R::label(g, "grid", "label", r.grid_value, "grid.value");
    r.grid_index = R::integer(g, "grid", "index", 0, max_index);
  }
  r.repeats = R::integer(j, "", "repeats", 1, kMaxRepeats);
  r.duration = R::number(j, "", "duration", 0.0);
  // Records are input: the status and the class (which names the report's CSS classes) must be
  // known ones.
  r.status = R::name(j, "", "status", {"ok", "contact_lost", "diverged", "unphysical", "clamped", "failed"});
  r.status_time = R::number(j, "", "status_time");
  r.status_detail = R::string(j, "", "status_detail");
  r.inversion_time = R::optional(j, "", "inversion_time");
  r.stem_contact_time = R::optional(j, "", "stem_contact_time");
  r.reference_inversion_time = R::optional(j, "", "reference_inversion_time");
  r.reference_stem_contact_time = R::optional(j, "", "reference_stem_contact_time");
  try {
    r.metrics = metrics_from_json(R::at(j, "", "metrics"));
  } catch (const json::exception& e) {
    // metrics_from_json names the field in its own words after json's "[json.exception...] ".
    std::string why = e.what();
    if (const size_t close = why.find("] "); close != std::string::npos) why.erase(0, close + 2);
    R::fail("metrics", why);
  }
  const json& w = R::at(j, "", "work");
  r.cpu_seconds = R::number(w, "work", "cpu_seconds", 0.0);
  const json& cpu = R::at(w, "work", "cpu_seconds_repeats");
  if (!cpu.is_array() || cpu.size() > static_cast<size_t>(kMaxRepeats))
    R::fail("work.cpu_seconds_repeats", "expected an array of at most " + std::to_string(kMaxRepeats) + " numbers");
  for (const json& c : cpu) {
    if (!c.is_null() && !c.is_number()) R::fail("work.cpu_seconds_repeats", std::string("expected numbers, got ") + c.type_name());
    r.cpu_seconds_repeats.push_back(c.is_null() ? std::nan("") : c.get<double>());
  }
  r.wall_seconds = R::number(w, "work", "wall_seconds", 0.0);
  r.steps = R::integer(w, "work", "steps", 0, kMaxCount);
  r.rhs_evaluations = R::integer(w, "work", "rhs_evaluations", 0, kMaxCount);
  r.solver_iterations = R::integer(w, "work", "solver_iterations", 0, kMaxCount);
  r.engine_version = R::string(j, "", "engine_version");
  r.git_commit = R::string(j, "", "git_commit");
  r.settings = R::at(j, "", "settings");
  if (!r.settings.is_object()) R::fail("settings", std::string("expected an object, got ") + r.settings.type_name());
  // A setting's value is its text as the engine listed it.
  for (const auto& [k, v] : r.settings.items())
    if (!v.is_string()) R::fail("settings." + utf8_replaced(k.substr(0, 40)), std::string("expected a string, got ") + v.type_name());
  if (j.contains("class")) {
    const json& c = R::at(j, "", "class");
    r.run_class = R::name(c, "class", "name", {"ok", "diverged", "unphysical", "clamped", "failed", "contact_lost"});
    r.class_time = R::number(c, "class", "time");
    r.class_reason = R::string(c, "class", "reason");
  } else {
    r.run_class = class_of_status(r.status);
  }
  if (j.contains("reference") && !j.at("reference").is_null()) {
    const json& x = j.at("reference");
    SweepRecord::ReferenceRun f;
    f.status = R::name(x, "reference", "status", {"ok", "contact_lost", "diverged", "unphysical", "clamped", "failed"});
    f.method = R::string(x, "reference", "method");
    f.run_class = R::name(x, "reference", "class", {"ok", "diverged", "unphysical", "clamped", "failed", "contact_lost"});
    f.rtol = R::number(x, "reference", "rtol", 0.0);
    f.cpu_seconds = R::number(x, "reference", "cpu_seconds", 0.0);
    f.steps = R::integer(x, "reference", "steps", 0, kMaxCount);
    f.rhs_evaluations = R::integer(x, "reference", "rhs_evaluations", 0, kMaxCount);
    f.energy_initial = R::number(x, "reference", "energy_initial");
    f.energy_final = R::number(x, "reference", "energy_final");
    f.jellett_max_relative_drift = R::number(x, "reference", "jellett_max_relative_drift");
    f.final_tilt = R::number(x, "reference", "final_tilt");
    r.reference = f;
  }
  if (j.contains("search") && !j.at("search").is_null()) r.search = search_from_json(j.at("search"));
  return r;
}

// An engine's status detail is not guaranteed UTF-8; a replacement character beats losing the point.
std::string to_jsonl(const SweepRecord& r) {
  return to_json(r).dump(-1, ' ', false, json::error_handler_t::replace) + "\n";
}

size_t complete_lines_length(const std::string& text) {
  const auto last = text.rfind('\n');
  return last == std::string::npos ? 0 : last + 1;
}

RecordsFile parse_records_text(const std::string& text, const std::string& name) {
  RecordsFile f;
  f.complete_bytes = complete_lines_length(text);
  f.partial_bytes = text.size() - f.complete_bytes;
  size_t pos = 0, line = 0;
  while (pos < f.complete_bytes) {
    const size_t end = text.find('\n', pos);
    ++line;
    const std::string l = text.substr(pos, end - pos);
    pos = end + 1;
    if (trim(l).empty()) continue;
    const std::string where = name + ":" + std::to_string(line) + ": ";
    const json j = json::parse(l, nullptr, /*allow_exceptions=*/false);
    if (j.is_discarded()) throw SweepRecordError(where + "not a sweep record: not one JSON value");
    try {
      f.records.push_back(sweep_record_from_json(j));
    } catch (const SweepRecordError& e) {
      throw SweepRecordError(where + e.what());
    }
    f.lines.push_back(line);
  }
  return f;
}

fs::path keep_aside(const fs::path& file) {
  std::error_code ec;
  if (!fs::exists(file, ec)) return {};
  for (int k = 1;; ++k) {
    const fs::path to = file.string() + ".old" + (k == 1 ? std::string() : "." + std::to_string(k));
    if (fs::exists(to, ec)) continue;
    fs::rename(file, to, ec);
    if (ec) throw std::runtime_error(file.string() + ": cannot keep it aside as " + to.string() + ": " + ec.message());
    return to;
  }
}

RecordsFile read_records(const std::string& path) {
  std::error_code ec;
  if (!fs::exists(path, ec)) return {};
  return parse_records_text(read_file_text(path), path);
}

RecordsFile recover_records(const std::string& path) {
  RecordsFile f = read_records(path);
  if (f.partial_bytes == 0) return f;
  const int fd = ::open(path.c_str(), O_WRONLY | O_CLOEXEC);
  if (fd < 0) throw std::runtime_error(path + ": cannot open to drop a partial line: " + std::strerror(errno));
  const bool ok = ::ftruncate(fd, static_cast<off_t>(f.complete_bytes)) == 0 && ::fsync(fd) == 0;
  const int err = errno;
  ::close(fd);
  if (!ok) throw std::runtime_error(path + ": cannot drop a partial line: " + std::strerror(err));
  return f;
}

SweepMeta parse_sweep_meta(const std::string& text, const std::string& name) {
  using R = RecordReader;
  SweepMeta m;
  m.meta = json::parse(text, nullptr, /*allow_exceptions=*/false);
  try {
    if (m.meta.is_discarded()) R::fail("sweep.json", "not JSON");
    m.sweep_hash = R::string(m.meta, "", "sweep_hash");
    m.plan_hash = R::string(m.meta, "", "plan_hash");
    if (m.meta.contains("points"))
      m.points = static_cast<size_t>(R::integer(m.meta, "", "points", 0, static_cast<long long>(kMaxSweepPoints)));
    const json shard = m.meta.value("shard", json(nullptr));
    if (!shard.is_null()) {
      // The bound of parse_shard, so that a shard read back is one `--shard` could have made.
      const long long count = R::integer(shard, "shard", "count", 1, 1000000);
      const long long index = R::integer(shard, "shard", "index", 0, count - 1);
      m.shard = SweepShard{static_cast<int>(index), static_cast<int>(count)};
      const json& ids = R::at(shard, "shard", "point_ids");
      if (!ids.is_array()) R::fail("shard.point_ids", std::string("expected an array, got ") + ids.type_name());
      if (ids.size() > m.points.value_or(kMaxSweepPoints))
        R::fail("shard.point_ids", std::to_string(ids.size()) + " ids, more than the sweep's " +
                                       std::to_string(m.points.value_or(kMaxSweepPoints)) + " points");
      for (size_t i = 0; i < ids.size(); ++i) {
        if (!ids[i].is_string())
          R::fail("shard.point_ids[" + std::to_string(i) + "]", std::string("expected a string, got ") + ids[i].type_name());
        m.shard_point_ids.push_back(ids[i].get<std::string>());
      }
    }
  } catch (const SweepRecordError& e) {
    throw SweepRecordError(name + ": " + e.what());
  }
  return m;
}

}  // namespace tippe
