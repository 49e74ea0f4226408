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
                          const std::vector<std::string>& names) {
    const std::string v = string(j, prefix, key);
    std::string list;
    for (const std::string& n : names) {
      if (v == n) return v;
      list += (list.empty() ? "" : ", ") + n;
    }
    fail(dotted(prefix, key), "\"" + utf8_replaced(v.substr(0, 40)) + "\" is not one of " + list);
  }
};

// The class a status implies when no trajectory is at hand (records from before classification).
std::string class_of_status(const std::string& status) {
  for (const char* c : {"ok", "diverged", "clamped", "failed", "contact_lost"})
    if (status == c) return status;
  return "failed";
}

// Writes a sweep record's fields (its `visit`, sweep_record.h) into a JSON object: numbers that
// are not finite as null, a part or group as an object (null when absent).
class SweepWriter {
 public:
  json out = json::object();

  void operator()(const SweepField& f, const std::string& v) {
    // A label of a record from before labels: the number's text.
    if (f.check() == SweepField::Check::label && f.is_since() && v.empty() && std::isfinite(f.value()))
      out[f.key()] = json(f.value()).dump();
    else
      out[f.key()] = v;
  }
  void operator()(const SweepField& f, double v) { out[f.key()] = number(v); }
  void operator()(const SweepField& f, const std::optional<double>& v) { out[f.key()] = number(v); }
  void operator()(const SweepField& f, long long v) { out[f.key()] = v; }
  void operator()(const SweepField& f, int v) { out[f.key()] = v; }
  void operator()(const SweepField& f, bool v) { out[f.key()] = v; }
  void operator()(const SweepField& f, const std::vector<std::string>& v) { out[f.key()] = v; }
  void operator()(const SweepField& f, const std::vector<double>& v) {
    json a = json::array();
    for (double x : v) a.push_back(number(x));
    out[f.key()] = a;
  }
  void operator()(const SweepField& f, const json& v) { out[f.key()] = v; }
  void operator()(const SweepField& f, const Metrics& m) { out[f.key()] = to_json(m); }
  template <class T>
  void operator()(const SweepField& f, const std::optional<T>& part) {
    out[f.key()] = part ? write(*part) : json(nullptr);
  }
  template <class Fields>
  void group(const SweepField& f, Fields&& fields) {
    if (f.is_null()) {
      out[f.key()] = nullptr;
      return;
    }
    SweepWriter w;
    fields(w);
    out[f.key()] = std::move(w.out);
  }

  template <class T>
  static json write(const T& part) {
    SweepWriter w;
    visit(part, w);
    return std::move(w.out);
  }
};

// Reads a sweep record's fields back with the checks its `visit` names (RecordReader's rules
// and messages: "PREFIX.KEY: reason").
class SweepRecordReader {
 public:
  using R = RecordReader;
  SweepRecordReader(const json& j, std::string prefix) : j_(j), prefix_(std::move(prefix)) {}

  void operator()(const SweepField& f, std::string& v) {
    const std::string where = R::dotted(prefix_, f.key());
    switch (f.check()) {
      case SweepField::Check::name:
        v = R::string(j_, prefix_, f.key());
        // Names read back become file names and report labels: the rule of names in input files.
        if (!is_valid_name(v)) R::fail(where, "\"" + v + "\" is not a usable name (" + kNameRule + ")");
        return;
      case SweepField::Check::key:
        v = R::key(j_, prefix_, f.key());
        return;
      case SweepField::Check::label:
        if (f.is_since() && !j_.contains(f.key())) {
          if (std::isnan(f.value()))
            R::fail(where, std::string("missing (required when ") + f.value_key() + " is null)");
          v = json(f.value()).dump();
          return;
        }
        v = R::label(j_, prefix_, f.key(), f.value(), f.value_key());
        return;
      // Records are input: the status and the class (which names the report's CSS classes)
      // must be known ones.
      case SweepField::Check::status:
        v = R::name(j_, prefix_, f.key(), run_status_names());
        return;
      case SweepField::Check::run_class:
        v = R::name(j_, prefix_, f.key(), run_class_names());
        return;
      case SweepField::Check::criterion:
        v = R::string(j_, prefix_, f.key());
        try {
          parse_criterion(v);
        } catch (const std::invalid_argument& e) {
          R::fail(where, e.what());
        }
        return;
      case SweepField::Check::none:
        v = R::string(j_, prefix_, f.key());
        return;
    }
  }
  void operator()(const SweepField& f, double& v) {
    if (f.is_not_null()) {
      const json& x = R::at(j_, prefix_, f.key());
      if (!x.is_number()) R::fail(R::dotted(prefix_, f.key()), std::string("expected a number, got ") + x.type_name());
    }
    v = R::number(j_, prefix_, f.key(), f.min());
  }
  void operator()(const SweepField& f, std::optional<double>& v) { v = R::optional(j_, prefix_, f.key()); }
  void operator()(const SweepField& f, long long& v) { v = R::integer(j_, prefix_, f.key(), f.lo(), f.hi()); }
  void operator()(const SweepField& f, int& v) { v = static_cast<int>(R::integer(j_, prefix_, f.key(), f.lo(), f.hi())); }
  void operator()(const SweepField& f, bool& v) {
    if (f.is_since() && !j_.contains(f.key())) return;
    const json& b = R::at(j_, prefix_, f.key());
    if (!b.is_boolean()) R::fail(R::dotted(prefix_, f.key()), std::string("expected true or false, got ") + b.type_name());
    v = b.get<bool>();
  }
  void operator()(const SweepField& f, std::vector<std::string>& v) {
    const std::string where = R::dotted(prefix_, f.key());
    const json& a = R::at(j_, prefix_, f.key());
    if (!a.is_array()) R::fail(where, std::string("expected an array, got ") + a.type_name());
    v.clear();
    for (size_t i = 0; i < a.size(); ++i) {
      if (!a[i].is_string()) R::fail(where + "[" + std::to_string(i) + "]", std::string("expected a string, got ") + a[i].type_name());
      v.push_back(a[i].get<std::string>());
    }
  }
  // The CPU time of every repeat: numbers or null, at most kMaxRepeats.
  void operator()(const SweepField& f, std::vector<double>& v) {
    const std::string where = R::dotted(prefix_, f.key());
    const json& a = R::at(j_, prefix_, f.key());
    if (!a.is_array() || a.size() > static_cast<size_t>(kMaxRepeats))
      R::fail(where, "expected an array of at most " + std::to_string(kMaxRepeats) + " numbers");
    v.clear();
    for (const json& c : a) {
      if (!c.is_null() && !c.is_number()) R::fail(where, std::string("expected numbers, got ") + c.type_name());
      v.push_back(c.is_null() ? std::nan("") : c.get<double>());
    }
  }
  // Settings: an object whose every value is a setting's text as the engine listed it.
  void operator()(const SweepField& f, json& v) {
    const std::string where = R::dotted(prefix_, f.key());
    v = R::at(j_, prefix_, f.key());
    if (!v.is_object()) R::fail(where, std::string("expected an object, got ") + v.type_name());
    for (const auto& [k, x] : v.items())
      if (!x.is_string()) R::fail(where + "." + utf8_replaced(k.substr(0, 40)), std::string("expected a string, got ") + x.type_name());
  }
  void operator()(const SweepField& f, Metrics& m) {
    try {
      m = metrics_from_json(R::at(j_, prefix_, f.key()));
    } catch (const json::exception& e) {
      // metrics_from_json names the field in its own words after json's "[json.exception...] ".
      std::string why = e.what();
      if (const size_t close = why.find("] "); close != std::string::npos) why.erase(0, close + 2);
      R::fail(R::dotted(prefix_, f.key()), why);
    }
  }
  // A part absent or null in the record: none.
  template <class T>
  void operator()(const SweepField& f, std::optional<T>& part) {
    if (!j_.contains(f.key()) || j_.at(f.key()).is_null()) {
      part = std::nullopt;
      return;
    }
    T p{};
    SweepRecordReader r(j_.at(f.key()), R::dotted(prefix_, f.key()));
    visit(p, r);
    check(p);
    part = p;
  }
  // A group: absent (since) or null (nullable) reads nothing.
  template <class Fields>
  void group(const SweepField& f, Fields&& fields) {
    if (f.is_since() && !j_.contains(f.key())) return;
    if (f.nullable() && (!j_.contains(f.key()) || j_.at(f.key()).is_null())) return;
    SweepRecordReader r(R::at(j_, prefix_, f.key()), R::dotted(prefix_, f.key()));
    fields(r);
  }

 private:
  static void check(const SweepRecord::ReferenceRun&) {}
  // A search's range as a whole, with the rules of `ladder.search` (sweep_search.h).
  static void check(const SweepSearch& q) {
    if (!(q.to > q.from) || !(q.resolution <= kMaxSearchResolution) || std::log10(q.to / q.from) > kMaxSearchDecades)
      R::fail("search", "not a search's range and resolution (expected 0 < from < to, at most " + num(kMaxSearchDecades) +
                            " decades, resolution <= " + num(kMaxSearchResolution) + ")");
    if (q.integer && (q.from != std::floor(q.from) || q.to != std::floor(q.to)))
      R::fail("search.integer", "from and to of an integer search are whole numbers");
  }
  const json& j_;
  std::string prefix_;
};

}  // namespace

const std::vector<std::string>& run_class_names() {
  static const std::vector<std::string> names = {"ok", "diverged", "unphysical", "clamped", "failed", "contact_lost"};
  return names;
}

json to_json(const SweepRecord& r) {
  json j = SweepWriter::write(r);
  j["format"] = "tippe-sweep-record-1";
  return j;
}

SweepRecord sweep_record_from_json(const json& j) {
  using R = RecordReader;
  const std::string format = R::string(j, "", "format");
  if (format != "tippe-sweep-record-1")
    R::fail("format", "unknown record format \"" + utf8_replaced(format.substr(0, 40)) + "\" (expected tippe-sweep-record-1)");
  SweepRecord r;
  SweepRecordReader reader(j, "");
  visit(r, reader);
  if (!j.contains("class")) r.run_class = class_of_status(r.status);
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
