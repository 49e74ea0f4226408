// The comparison record: writing comparison.json and reading it back as checked input; the physics hash.
#include "harness/records/comparison.h"

#include <cmath>
#include <filesystem>
#include <limits>
#include <set>
#include <tuple>
#include <utility>
#include <stdexcept>
#include "harness/io/json_fields.h"
#include "harness/io/scene_io.h"
#include "engines/core/registry.h"

namespace tippe {

namespace fs = std::filesystem;
using nlohmann::json;

namespace {

json count(const std::optional<long long>& v) { return v ? json(*v) : json(nullptr); }

// The event alignment's fields, absent in records written before it existed: read as absent.
// Present, each is checked (a count >= 0, a time >= 0, a string or null).
void read_event_alignment(const json& j, Metrics& m) {
  auto optional_count = [&](const char* key, std::optional<long long>& out) {
    if (!j.contains(key) || j.at(key).is_null()) return;
    const json& v = j.at(key);
    if (!v.is_number_integer() || v.get<long long>() < 0)
      throw std::invalid_argument(std::string("metrics.") + key + ": " + v.dump() + " is not a count >= 0 or null");
    out = v.get<long long>();
  };
  auto optional_time = [&](const char* key, std::optional<double>& out) {
    if (!j.contains(key) || j.at(key).is_null()) return;
    const json& v = j.at(key);
    if (!v.is_number() || !(std::isfinite(v.get<double>()) && v.get<double>() >= 0))
      throw std::invalid_argument(std::string("metrics.") + key + ": " + v.dump() + " is not a time >= 0 or null");
    out = v.get<double>();
  };
  auto optional_text = [&](const char* key, std::string& out) {
    if (!j.contains(key) || j.at(key).is_null()) return;
    if (!j.at(key).is_string())
      throw std::invalid_argument(std::string("metrics.") + key + ": " + j.at(key).dump() + " is not a string or null");
    out = j.at(key).get<std::string>();
  };
  optional_count("events_reference", m.events_reference);
  optional_count("events_engine", m.events_engine);
  optional_count("events_matched", m.events_matched);
  optional_count("events_missing", m.events_missing);
  optional_count("events_extra", m.events_extra);
  optional_time("event_time_max_error", m.event_time_max_error);
  optional_count("first_wrong_event_index", m.first_wrong_event_index);
  optional_text("first_wrong_event", m.first_wrong_event);
  optional_text("events_not_compared", m.events_not_compared);
  optional_time("event_min_dwell", m.event_min_dwell);
  optional_count("event_alignment_rows", m.event_alignment_rows);
  if (j.contains("event_alignment") && !j.at("event_alignment").is_null()) {
    const json& rows = j.at("event_alignment");
    if (!rows.is_array()) throw std::invalid_argument("metrics.event_alignment: " + rows.dump() + " is not an array");
    static const std::set<std::string> ops = {"match", "substitution", "missing", "extra"};
    for (size_t i = 0; i < rows.size(); ++i) {
      const json& r = rows.at(i);
      const std::string where = "metrics.event_alignment[" + std::to_string(i) + "]";
      if (!r.is_object() || !r.contains("op") || !r.at("op").is_string() || !ops.count(r.at("op").get<std::string>()))
        throw std::invalid_argument(where + ".op: expected one of match, substitution, missing, extra");
      AlignedEventRow row;
      row.op = r.at("op").get<std::string>();
      for (const auto& [side, kind, time] : {std::tuple<const char*, std::string*, std::optional<double>*>{
                                                 "reference", &row.reference_kind, &row.reference_time},
                                             {"engine", &row.engine_kind, &row.engine_time}}) {
        const std::string tkey = std::string("t_") + side;
        if (r.contains(side) && !r.at(side).is_null()) {
          if (!r.at(side).is_string()) throw std::invalid_argument(where + "." + side + ": not a string or null");
          *kind = r.at(side).get<std::string>();
        }
        if (r.contains(tkey) && !r.at(tkey).is_null()) {
          if (!r.at(tkey).is_number()) throw std::invalid_argument(where + "." + tkey + ": not a number or null");
          *time = r.at(tkey).get<double>();
        }
      }
      m.event_alignment.push_back(std::move(row));
    }
  }
  if (m.first_wrong_event_index.has_value() == m.first_wrong_event.empty())
    throw std::invalid_argument("metrics.first_wrong_event: present without first_wrong_event_index, or the reverse");
}

}  // namespace

json to_json(const Metrics& m) {
  json rows = json::array();
  for (const AlignedEventRow& r : m.event_alignment)
    rows.push_back({{"op", r.op},
                    {"reference", r.reference_kind.empty() ? json(nullptr) : json(r.reference_kind)},
                    {"t_reference", number(r.reference_time)},
                    {"engine", r.engine_kind.empty() ? json(nullptr) : json(r.engine_kind)},
                    {"t_engine", number(r.engine_time)}});
  return json{
      {"inversion_event", m.inversion_event},
      {"inversion_time_abs_error", number(m.inversion_time_abs_error)},
      {"inversion_time_rel_error", number(m.inversion_time_rel_error)},
      {"stem_contact_event", m.stem_contact_event},
      {"stem_contact_time_abs_error", number(m.stem_contact_time_abs_error)},
      {"stem_contact_time_rel_error", number(m.stem_contact_time_rel_error)},
      {"tilt_max_error", number(m.tilt_max_error)},
      {"tilt_rms_error", number(m.tilt_rms_error)},
      {"energy_max_error", number(m.energy_max_error)},
      {"energy_final_ratio", number(m.energy_final_ratio)},
      {"energy_gain_events", m.energy_gain_events},
      {"energy_max_gain", number(m.energy_max_gain)},
      {"energy_gain_rule", m.energy_gain_rule},
      {"normal_work", number(m.normal_work)},
      {"friction_work", number(m.friction_work)},
      {"drilling_work", number(m.drilling_work)},
      {"impact_energy", number(m.impact_energy)},
      {"elastic_energy_max", number(m.elastic_energy_max)},
      {"numerical_energy_max", number(m.numerical_energy_max)},
      {"numerical_energy_final", number(m.numerical_energy_final)},
      {"contact_path_rms_error", number(m.contact_path_rms_error)},
      {"contact_path_max_error", number(m.contact_path_max_error)},
      {"com_path_rms_error", number(m.com_path_rms_error)},
      {"com_path_max_error", number(m.com_path_max_error)},
      {"latitude_rms_error", number(m.latitude_rms_error)},
      {"jellett_drift_ball", number(m.jellett_drift_ball)},
      {"jellett_drift_stem", number(m.jellett_drift_stem)},
      {"jellett_max_relative_drift", number(m.jellett_max_relative_drift)},
      {"wall_seconds", number(m.wall_seconds)},
      {"cpu_seconds", number(m.cpu_seconds)},
      {"real_time_factor", number(m.real_time_factor)},
      {"steps", m.steps},
      {"cost_ratio", number(m.cost_ratio)},
      {"compared_until", number(m.compared_until)},
      {"reference_converged_until", number(m.reference_converged_until)},
      {"events_reference", count(m.events_reference)},
      {"events_engine", count(m.events_engine)},
      {"events_matched", count(m.events_matched)},
      {"events_missing", count(m.events_missing)},
      {"events_extra", count(m.events_extra)},
      {"event_time_max_error", number(m.event_time_max_error)},
      {"first_wrong_event_index", count(m.first_wrong_event_index)},
      {"first_wrong_event", m.first_wrong_event.empty() ? json(nullptr) : json(m.first_wrong_event)},
      {"events_not_compared", m.events_not_compared},
      {"event_min_dwell", number(m.event_min_dwell)},
      {"event_alignment", rows},
      {"event_alignment_rows", count(m.event_alignment_rows)},
  };
}

Metrics metrics_from_json(const json& j) {
  Metrics m;
  m.inversion_event = j.at("inversion_event").get<std::string>();
  m.inversion_time_abs_error = get_optional(j, "inversion_time_abs_error");
  m.inversion_time_rel_error = get_optional(j, "inversion_time_rel_error");
  m.stem_contact_event = j.at("stem_contact_event").get<std::string>();
  m.stem_contact_time_abs_error = get_optional(j, "stem_contact_time_abs_error");
  m.stem_contact_time_rel_error = get_optional(j, "stem_contact_time_rel_error");
  m.tilt_max_error = get_number(j, "tilt_max_error");
  m.tilt_rms_error = get_number(j, "tilt_rms_error");
  m.energy_max_error = get_number(j, "energy_max_error");
  m.energy_final_ratio = get_number(j, "energy_final_ratio");
  m.energy_gain_events = json_integer(j, "energy_gain_events");
  m.energy_max_gain = get_number(j, "energy_max_gain");
  // The rule and the ledger are absent in records written before them.
  if (j.contains("energy_gain_rule")) {
    m.energy_gain_rule = j.at("energy_gain_rule").get<std::string>();
    // Empty: what to_json writes for a record from before the rule (it counted the total).
    if (!m.energy_gain_rule.empty() && m.energy_gain_rule != "ledger" && m.energy_gain_rule != "total")
      throw std::invalid_argument("metrics.energy_gain_rule: \"" + m.energy_gain_rule + "\" is not ledger or total");
  }
  const std::pair<const char*, std::optional<double>*> ledger[] = {{"normal_work", &m.normal_work},
                                                                    {"friction_work", &m.friction_work},
                                                                    {"drilling_work", &m.drilling_work},
                                                                    {"impact_energy", &m.impact_energy},
                                                                    {"elastic_energy_max", &m.elastic_energy_max},
                                                                    {"numerical_energy_max", &m.numerical_energy_max},
                                                                    {"numerical_energy_final", &m.numerical_energy_final}};
  for (const auto& [key, field] : ledger)
    if (j.contains(key)) *field = get_optional(j, key);
  m.contact_path_rms_error = get_number(j, "contact_path_rms_error");
  m.contact_path_max_error = get_number(j, "contact_path_max_error");
  m.com_path_rms_error = get_number(j, "com_path_rms_error");
  m.com_path_max_error = get_number(j, "com_path_max_error");
  m.latitude_rms_error = get_number(j, "latitude_rms_error");
  m.jellett_drift_ball = get_optional(j, "jellett_drift_ball");
  m.jellett_drift_stem = get_optional(j, "jellett_drift_stem");
  m.jellett_max_relative_drift = get_number(j, "jellett_max_relative_drift");
  m.wall_seconds = get_number(j, "wall_seconds");
  m.cpu_seconds = get_number(j, "cpu_seconds");
  m.real_time_factor = get_number(j, "real_time_factor");
  m.steps = json_integer(j, "steps");
  m.cost_ratio = get_number(j, "cost_ratio");
  m.compared_until = get_number(j, "compared_until");
  // Absent in records written before the reference's self-check.
  if (j.contains("reference_converged_until")) {
    const json& v = j.at("reference_converged_until");
    if (!v.is_null()) {
      const double t = v.get<double>();
      if (!(std::isfinite(t) && t >= 0))
        throw std::invalid_argument("metrics.reference_converged_until: " + v.dump() + " is not a time >= 0 or null");
      m.reference_converged_until = t;
    }
  }
  read_event_alignment(j, m);
  return m;
}

// ---- hashing --------------------------------------------------------------------------------

std::string physics_hash(const json& scene_json) {
  json physics = scene_json;
  for (const char* key : {"engines", "name", "description", "source_file", "content_hash", "notes"}) physics.erase(key);
  // Whether the reference is checked is not physics: the same reference serves both.
  if (physics.contains("run") && physics["run"].is_object()) physics["run"].erase("self_check");
  // The drilling law at its default is left out: records made before the key existed describe
  // the same physics and keep their hash.
  if (physics.contains("contact") && physics["contact"].is_object() &&
      physics["contact"].value("drilling_law", std::string("decoupled")) == "decoupled")
    physics["contact"].erase("drilling_law");
  // nlohmann::json keeps object keys sorted, so dump() is canonical.
  const std::string text = physics.dump();
  std::uint64_t h = 14695981039346656037ull;
  for (unsigned char c : text) {
    h ^= c;
    h *= 1099511628211ull;
  }
  char buf[17];
  std::snprintf(buf, sizeof buf, "%016llx", static_cast<unsigned long long>(h));
  return buf;
}

std::string physics_hash(const Scene& scene) { return physics_hash(scene_to_json(scene)); }


json to_json(const SelfCheck& s) {
  return json{{"method", s.method},
              {"rtol", s.rtol},
              {"atol", s.atol},
              {"converged_until", number(s.converged_until)},
              {"reason", s.reason},
              {"cpu_seconds", number(s.cpu_seconds)}};
}

SelfCheck self_check_from_json(const json& j) {
  SelfCheck s;
  s.method = j.at("method").get<std::string>();
  s.rtol = j.at("rtol").get<double>();
  s.atol = j.value("atol", 0.0);
  const json& cu = j.at("converged_until");
  if (!cu.is_null()) {
    const double t = cu.get<double>();
    if (!(std::isfinite(t) && t >= 0))
      throw std::invalid_argument("reference.self_check.converged_until: " + cu.dump() + " is not a time >= 0 or null");
    s.converged_until = t;
  }
  s.reason = j.at("reason").get<std::string>();
  s.cpu_seconds = get_number(j, "cpu_seconds");
  return s;
}

// ---- records --------------------------------------------------------------------------------

namespace {

// An engine chattering between ball and stem reports a "switch" event per step (10^4 in a few
// seconds of some scenes), which would make comparison.json megabytes long: keep the first ones
// and count the rest.
json summary_with_bounded_events(const RunRecord& r) {
  json j = to_json(r);
  json kept = json::array();
  long long switches = 0;
  for (json& e : j["events"]) {
    if (e.value("name", "") == "switch" && ++switches > kMaxSwitchEventsKept) continue;
    kept.push_back(std::move(e));
  }
  j["events"] = std::move(kept);
  if (switches > kMaxSwitchEventsKept) j["events_omitted"] = {{"switch", switches - kMaxSwitchEventsKept}};
  return j;
}

}  // namespace

json to_json(const Comparison& c) {
  json versions = json::object();
  versions[c.reference.engine.empty() ? reference_engine().name : c.reference.engine] = c.reference.engine_version;
  json engines = json::array();
  for (const EngineResult& e : c.engines) {
    versions[e.run.engine] = e.run.engine_version;
    engines.push_back(
        {{"engine", e.run.engine}, {"summary", summary_with_bounded_events(e.run)}, {"metrics", to_json(e.metrics)}});
  }
  json provenance_with_versions = to_json(c.provenance);
  provenance_with_versions["engine_versions"] = versions;
  json reference = {{"cached", c.reference_cached}, {"summary", summary_with_bounded_events(c.reference)}};
  if (c.self_check) {
    reference["self_check"] = to_json(*c.self_check);
    reference["self_check"]["cached"] = c.self_check_cached;
  }
  return json{
      {"format", "tippe-comparison-1"},
      {"scene_name", c.scene.value("name", "")},
      {"scene_file", c.scene.value("source_file", "")},
      {"scene_hash", c.scene.value("content_hash", "")},
      {"physics_hash", physics_hash(c.scene)},
      {"scene", c.scene},
      {"provenance", provenance_with_versions},
      {"reference", reference},
      {"engines", engines},
  };
}

namespace {

// A name read back from a record names files (ENGINE.csv) and appears in reports: it must pass
// the rule of names in input files, or a shared record could write outside its directory.
void check_record_name(const json& j, const char* key, const std::string& where) {
  const std::string name = j.at(key).get<std::string>();
  if (!is_valid_name(name))
    throw std::invalid_argument(where + key + ": \"" + name + "\" is not a usable name (" + kNameRule + ")");
}

}  // namespace

Comparison comparison_from_json(const json& j) {
  check_record_name(j, "scene_name", "");
  check_record_name(j.at("reference").at("summary"), "engine", "reference.summary.");
  std::set<std::string> engines;
  for (size_t i = 0; i < j.at("engines").size(); ++i) {
    const json& e = j.at("engines").at(i);
    const std::string where = "engines[" + std::to_string(i) + "].";
    check_record_name(e, "engine", where);
    check_record_name(e.at("summary"), "engine", where + "summary.");
    if (e.at("engine") != e.at("summary").at("engine"))
      throw std::invalid_argument(where + "engine: \"" + e.at("engine").get<std::string>() +
                                  "\" differs from its summary's engine");
    if (!engines.insert(e.at("engine").get<std::string>()).second || e.at("engine") == "reference")
      throw std::invalid_argument(where + "engine: \"" + e.at("engine").get<std::string>() +
                                  "\" appears twice (each names its own trajectory file)");
  }
  Comparison c;
  c.scene = j.at("scene");
  c.provenance = provenance_from_json(j.at("provenance"));
  c.reference = from_json(j.at("reference").at("summary"));
  c.reference_cached = j.at("reference").at("cached").get<bool>();
  // Absent (or null) in records of comparisons run without the self-check, and before it existed.
  if (j.at("reference").contains("self_check") && !j.at("reference").at("self_check").is_null()) {
    c.self_check = self_check_from_json(j.at("reference").at("self_check"));
    c.self_check_cached = j.at("reference").at("self_check").value("cached", false);
  }
  for (const json& e : j.at("engines")) c.engines.push_back({from_json(e.at("summary")), metrics_from_json(e.at("metrics"))});
  return c;
}

}  // namespace tippe
