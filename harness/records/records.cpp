// Run records: their summary numbers, JSON and CSV writers, atomic files.
#include "harness/records/records.h"
#include "harness/io/json_fields.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>
#include <stdexcept>
#include <utility>

#include "harness/io/files.h"
#include "harness/io/g17.h"
#include "harness/io/provenance.h"

namespace tippe {

namespace {

using nlohmann::json;


// The ledger's terms a simulator may not give, as ledger_not_available names them, and where a
// sample holds each.
struct SampleLedgerTerm {
  const char* name;
  double Observation::*value;
};
constexpr SampleLedgerTerm kSampleLedgerTerms[] = {{"normal_work", &Observation::normal_work},
                                                   {"friction_work", &Observation::friction_work},
                                                   {"drilling_work", &Observation::drilling_work},
                                                   {"impact_energy", &Observation::impact_energy},
                                                   {"elastic_energy", &Observation::elastic_energy}};




}  // namespace

Provenance current_provenance() {
  const BuildInfo b = build_info();
  Provenance p{b.git_commit, b.compiler, b.cxx_flags, {}, {}};
  const std::time_t now = std::time(nullptr);
  std::tm tm{};
  gmtime_r(&now, &tm);
  char date[32];
  std::strftime(date, sizeof date, "%Y-%m-%dT%H:%M:%SZ", &tm);
  p.date = date;
  char host[256] = {};
  if (::gethostname(host, sizeof host - 1) == 0) p.hostname = host;
  return p;
}

void fill_ledger(Observation& o, const EnergyLedgerTotals& l, double e0) {
  o.normal_work = l.normal_work;
  o.friction_work = l.friction_work;
  o.drilling_work = l.drilling_work;
  o.impact_energy = l.impact_energy;
  o.elastic_energy = l.elastic_energy;
  // A simulator with no ledger term at all has no numerical remainder to speak of either.
  const bool any = std::isfinite(l.normal_work) || std::isfinite(l.friction_work) || std::isfinite(l.drilling_work) ||
                   std::isfinite(l.impact_energy);
  o.numerical_energy = any ? o.energy - e0 - l.accounted() : kNaN;
}

void SampleSummary::add(const Observation& o, bool contact_switched) {
  if (n_ == 0) {
    first_ = o;
    min_fn_ = o.normal_force;
  }
  last_ = o;
  min_fn_ = std::min(min_fn_, o.normal_force);
  ++n_;
  if (std::isfinite(o.elastic_energy)) elastic_max_ = std::isnan(elastic_max_) ? o.elastic_energy : std::max(elastic_max_, o.elastic_energy);
  if (std::isfinite(o.numerical_energy))
    numerical_max_ = std::isnan(numerical_max_) ? std::abs(o.numerical_energy) : std::max(numerical_max_, std::abs(o.numerical_energy));

  if (contact_switched) run_surface_ = Surface::None;
  if (o.surface != Surface::Ball && o.surface != Surface::Stem) {
    run_surface_ = Surface::None;
    return;
  }
  double drift = 0.0;
  if (o.surface != run_surface_) {
    run_surface_ = o.surface;
    run_j0_ = o.jellett;
  } else {
    drift = jellett_relative_drift(o.jellett, run_j0_);
  }
  auto& slot = o.surface == Surface::Ball ? drift_ball_ : drift_stem_;
  slot = std::max(slot.value_or(0.0), drift);
}

void SampleSummary::fill(RunRecord& r) const {
  r.samples = n_;
  if (n_ == 0) {
    r.final_time = r.final_tilt = r.energy_initial = r.energy_final = r.jellett_initial = kNaN;
    r.min_normal_force = r.jellett_max_relative_drift = kNaN;
    r.jellett_drift_ball = r.jellett_drift_stem = std::nullopt;
    return;
  }
  r.final_time = last_.state.t;
  r.final_tilt = last_.theta;
  r.energy_initial = first_.energy;
  r.energy_final = last_.energy;
  r.jellett_initial = first_.jellett;
  r.min_normal_force = min_fn_;
  r.jellett_drift_ball = drift_ball_;
  r.jellett_drift_stem = drift_stem_;
  r.normal_work = last_.normal_work;
  r.drilling_work = last_.drilling_work;
  r.impact_energy = last_.impact_energy;
  r.elastic_energy_max = elastic_max_;
  r.numerical_energy_max = numerical_max_;
  r.numerical_energy_final = last_.numerical_energy;
  r.ledger_not_available.clear();
  for (const SampleLedgerTerm& t : kSampleLedgerTerms)
    if (std::isnan(last_.*t.value)) r.ledger_not_available.push_back(t.name);
  if (drift_ball_ || drift_stem_)
    r.jellett_max_relative_drift = std::max(drift_ball_.value_or(0.0), drift_stem_.value_or(0.0));
  else
    r.jellett_max_relative_drift = kNaN;
}

json to_json(const RunRecord& r) {
  json j = JsonWriter::write(r);
  j["format"] = kRunRecordFormat;
  return j;
}

json to_json(const Provenance& p) { return JsonWriter::write(p); }

Provenance provenance_from_json(const json& p) { return JsonReader::read<Provenance>(p, ""); }

long long json_integer(const json& j, const char* key) {
  const json& v = j.at(key);
  if (!v.is_number_integer())
    throw json::type_error::create(302, std::string(key) + ": expected an integer, got " +
                                            (v.is_number_float() ? "a float" : v.type_name()), &v);
  if (v.is_number_unsigned() &&
      v.get<std::uint64_t>() > static_cast<std::uint64_t>(std::numeric_limits<long long>::max()))
    throw json::out_of_range::create(406, std::string(key) + ": " + v.dump() + " is out of range", &v);
  return v.get<long long>();
}

const std::vector<std::string>& run_status_names() {
  static const std::vector<std::string> names = {"ok", "contact_lost", "diverged", "unphysical", "clamped", "failed"};
  return names;
}

const std::vector<std::string>& event_names() {
  static const std::vector<std::string> names = [] {
    std::vector<std::string> n = {"drill_slip", "drill_stick", "flight",  "graze",      "hold",  "impact",
                                  "inversion",  "lift",        "press",   "projection", "reversion", "slip",
                                  "stem_contact", "stick",     "switch",  "touchdown",  "two_contact", "unresolved"};
    n.insert(n.end(), run_status_names().begin(), run_status_names().end());
    return n;
  }();
  return names;
}

const std::vector<std::string>& ledger_term_names() {
  static const std::vector<std::string> names = [] {
    std::vector<std::string> n;
    for (const SampleLedgerTerm& t : kSampleLedgerTerms) n.emplace_back(t.name);
    return n;
  }();
  return names;
}

RunRecord from_json(const json& j) {
  // Summaries written before records carried a format have none; any other format is refused.
  if (j.contains("format") && j.at("format") != kRunRecordFormat)
    throw json::other_error::create(
        501, "format: unknown record format " + j.at("format").dump().substr(0, 60) + " (expected " + kRunRecordFormat + ")",
        &j);
  return JsonReader::read<RunRecord>(j, "");
}

const std::vector<std::string>& trajectory_columns() {
  static const std::vector<std::string> cols = {
      "t",        "x_G",        "y_G",        "z_G",        "vx_G",         "vy_G",       "vz_G",
      "qw",       "qx",         "qy",         "qz",         "wx_B",         "wy_B",       "wz_B",
      "theta",    "surface",    "x_C",        "y_C",        "z_C",          "x_C_engine", "y_C_engine",
      "z_C_engine", "normal_force", "slip_speed", "energy", "jellett", "contact_latitude",
      // The energy ledger (Observation), NaN where not available.
      "normal_work", "friction_work", "drilling_work", "impact_energy", "elastic_energy", "numerical_energy"};
  // trajectory_row_values fills kTrajectoryColumns values, one per name here.
  if (cols.size() != kTrajectoryColumns) throw std::logic_error("trajectory_columns and kTrajectoryColumns disagree");
  return cols;
}

CsvTrajectoryWriter::CsvTrajectoryWriter(std::string path) : path_(std::move(path)), tmp_(temp_name(path_)) {
  f_ = std::fopen(tmp_.c_str(), "wb");
  if (!f_) throw OutputError(path_ + ": cannot write: " + errno_text());
  // Rows are formatted into buffer_ in place and handed to the file 64 kB at a time, each block
  // one write (the stream keeps no copy). One fwrite per row cost as much again as a row's copy;
  // a megabyte's buffer cost 190 more page faults than this one (each page first touched), ~6 %
  // of a reference run's CPU, for 8 write calls instead of 115. The buffer is not zeroed.
  capacity_ = size_t{1} << 16;
  buffer_.reset(new char[capacity_]);
  std::setvbuf(f_, nullptr, _IONBF, 0);
  const std::string header = trajectory_csv_header();
  std::memcpy(buffer_.get(), header.data(), header.size());
  used_ = header.size();
}

void CsvTrajectoryWriter::flush_rows() {
  if (used_ && std::fwrite(buffer_.get(), 1, used_, f_) != used_) fail("cannot write");
  used_ = 0;
}

CsvTrajectoryWriter::~CsvTrajectoryWriter() {
  if (f_) {
    std::fclose(f_);
    std::remove(tmp_.c_str());
  }
}

void CsvTrajectoryWriter::fail(const std::string& what) {
  const std::string why = errno_text();
  if (f_) std::fclose(f_);
  f_ = nullptr;
  std::remove(tmp_.c_str());
  throw OutputError(path_ + ": " + what + ": " + why);
}

void trajectory_row_values(const Observation& o, double* values) {
  double* v = values;
  const BodyState& x = o.state;
  const double nan = kNaN;
  *v++ = x.t;
  for (int i = 0; i < 3; ++i) *v++ = x.p_WG[i];
  for (int i = 0; i < 3; ++i) *v++ = x.v_WG[i];
  *v++ = x.q_WB.w();
  *v++ = x.q_WB.x();
  *v++ = x.q_WB.y();
  *v++ = x.q_WB.z();
  for (int i = 0; i < 3; ++i) *v++ = x.w_B[i];
  *v++ = o.theta;
  *v++ = static_cast<double>(static_cast<int>(o.surface));
  for (int i = 0; i < 3; ++i) *v++ = o.p_WC[i];
  for (int i = 0; i < 3; ++i) *v++ = o.engine_contact_valid ? o.p_WC_engine[i] : nan;
  *v++ = o.normal_force;
  *v++ = o.slip_speed;
  *v++ = o.energy;
  *v++ = o.jellett;
  *v++ = o.contact_latitude;
  for (double l : {o.normal_work, o.friction_work, o.drilling_work, o.impact_energy, o.elastic_energy, o.numerical_energy})
    *v++ = l;
}

namespace {

// For each trajectory column, the earlier column whose number it often repeats, or -1: the
// reference reports the engine's contact point as its own, and the contact latitude is the tilt
// while the ball touches. A row copies that column's text when the two doubles have the same
// bits (the same bytes as writing it again: 4 of a reference row's 29 nonzero numbers).
std::array<int, kTrajectoryColumns> trajectory_twin_columns() {
  std::array<int, kTrajectoryColumns> twin;
  twin.fill(-1);
  const auto& cols = trajectory_columns();
  const auto index = [&](const char* name) {
    return static_cast<int>(std::find(cols.begin(), cols.end(), name) - cols.begin());
  };
  const std::pair<const char*, const char*> pairs[] = {
      {"x_C_engine", "x_C"}, {"y_C_engine", "y_C"}, {"z_C_engine", "z_C"}, {"contact_latitude", "theta"}};
  for (const auto& [column, earlier] : pairs) twin[static_cast<size_t>(index(column))] = index(earlier);
  return twin;
}

}  // namespace

size_t format_trajectory_row(const Observation& o, char* line) {
  static const size_t surface_column = static_cast<size_t>(
      std::find(trajectory_columns().begin(), trajectory_columns().end(), "surface") - trajectory_columns().begin());
  static const std::array<int, kTrajectoryColumns> twin = trajectory_twin_columns();
  double values[kTrajectoryColumns];
  trajectory_row_values(o, values);
  // Where each column's text starts and ends in the line, for its twin.
  std::uint16_t begin[kTrajectoryColumns], end_of[kTrajectoryColumns];
  char* p = line;
  char* const end = line + kTrajectoryRowMax;
  for (size_t i = 0; i < kTrajectoryColumns; ++i) {
    begin[i] = static_cast<std::uint16_t>(p - line);
    const int t = twin[i];
    if (t >= 0 && std::memcmp(&values[i], &values[t], sizeof(double)) == 0) {
      // A block the size of any number's text (24 chars at most), through a copy: the twin's
      // text may end just before p.
      char text[32];
      std::memcpy(text, line + begin[t], sizeof text);
      std::memcpy(p, text, sizeof text);
      p += end_of[t] - begin[t];
    } else if (i != surface_column) {
      p = g17(p, end, values[i]);  // std::to_chars(general, 17)'s bytes, faster
    } else {
      for (const char* s = to_string(o.surface); *s;) *p++ = *s++;
    }
    end_of[i] = static_cast<std::uint16_t>(p - line);
    *p++ = ',';
  }
  p[-1] = '\n';
  return static_cast<size_t>(p - line);
}

std::string trajectory_csv_header() {
  std::string header;
  for (const auto& c : trajectory_columns()) header += (header.empty() ? "" : ",") + c;
  return header + '\n';
}

void CsvTrajectoryWriter::write(const Observation& o) {
  if (!f_) throw std::logic_error(path_ + ": write after commit");
  if (capacity_ - used_ < kTrajectoryRowMax) flush_rows();
  used_ += format_trajectory_row(o, buffer_.get() + used_);
}

CsvTrajectoryText::CsvTrajectoryText() : text(trajectory_csv_header()) {}

void CsvTrajectoryText::write(const Observation& o) {
  char line[kTrajectoryRowMax];
  text.append(line, format_trajectory_row(o, line));
}

void CsvTrajectoryWriter::commit() {
  if (!f_) throw std::logic_error(path_ + ": commit twice");
  flush_rows();
  if (std::fflush(f_) != 0) fail("cannot write");
  if (::fsync(::fileno(f_)) != 0) fail("cannot sync");
  const int rc = std::fclose(f_);
  f_ = nullptr;
  if (rc != 0 || std::rename(tmp_.c_str(), path_.c_str()) != 0) {
    const std::string why = errno_text();
    std::remove(tmp_.c_str());
    throw OutputError(path_ + ": cannot commit: " + why);
  }
}

const std::vector<double>& CsvTrajectory::column(const std::string& name) const {
  auto it = values.find(name);
  if (it == values.end()) throw std::out_of_range("trajectory has no column \"" + name + "\"");
  return it->second;
}

CsvTrajectory read_trajectory_csv(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error(path + ": cannot read: " + errno_text());
  return parse_trajectory_csv(in, path);
}

CsvTrajectory parse_trajectory_csv(std::istream& in, const std::string& path) {
  auto split = [](const std::string& line) {
    std::vector<std::string> cells;
    std::stringstream ss(line);
    for (std::string c; std::getline(ss, c, ',');) cells.push_back(c);
    if (!line.empty() && line.back() == ',') cells.emplace_back();
    return cells;
  };
  auto chomp = [](std::string& s) {
    if (!s.empty() && s.back() == '\r') s.pop_back();
  };
  CsvTrajectory tr;
  std::string line;
  if (!std::getline(in, line)) throw std::runtime_error(path + ":1: empty file, expected a header");
  chomp(line);
  tr.columns = split(line);
  size_t surface_col = tr.columns.size();
  std::vector<std::vector<double>*> dst;
  for (size_t i = 0; i < tr.columns.size(); ++i) {
    const std::string& c = tr.columns[i];
    if (c == "surface") {
      surface_col = i;
      dst.push_back(nullptr);
      continue;
    }
    if (tr.values.count(c)) throw std::runtime_error(path + ":1: duplicate column \"" + c + "\"");
    dst.push_back(&tr.values[c]);
  }
  if (surface_col == tr.columns.size() || !tr.values.count("t"))
    throw std::runtime_error(path + ":1: not a trajectory (needs columns t and surface)");

  for (size_t lineno = 2; std::getline(in, line); ++lineno) {
    chomp(line);
    if (line.empty()) continue;
    const auto cells = split(line);
    const std::string where = path + ":" + std::to_string(lineno) + ": ";
    if (cells.size() != tr.columns.size())
      throw std::runtime_error(where + std::to_string(cells.size()) + " cells, header has " +
                               std::to_string(tr.columns.size()));
    for (size_t i = 0; i < cells.size(); ++i) {
      if (i == surface_col) {
        int code = -1;
        for (Surface s : {Surface::None, Surface::Ball, Surface::Stem, Surface::Both})
          if (cells[i] == to_string(s)) code = static_cast<int>(s);
        if (code < 0) throw std::runtime_error(where + "unknown surface \"" + cells[i] + "\"");
        tr.surface.push_back(code);
        continue;
      }
      char* endp = nullptr;
      const double v = std::strtod(cells[i].c_str(), &endp);
      if (cells[i].empty() || *endp != '\0')
        throw std::runtime_error(where + "column " + tr.columns[i] + ": not a number \"" + cells[i] + "\"");
      dst[i]->push_back(v);
    }
  }
  return tr;
}

}  // namespace tippe
