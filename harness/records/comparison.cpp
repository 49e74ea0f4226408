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

const std::vector<std::string>& aligned_event_ops() {
  static const std::vector<std::string> ops = {"match", "substitution", "missing", "extra"};
  return ops;
}

json to_json(const Metrics& m) { return JsonWriter::write(m); }

// The first format's fields are read with nlohmann::json's exceptions, the later ones (`since`)
// checked with std::invalid_argument "metrics.KEY: reason" (fields.h).
Metrics metrics_from_json(const json& j) {
  Metrics m = JsonReader::read<Metrics>(j, "metrics.", /*checked=*/true);
  if (m.first_wrong_event_index.has_value() == m.first_wrong_event.empty())
    throw std::invalid_argument("metrics.first_wrong_event: present without first_wrong_event_index, or the reverse");
  return m;
}

// ---- hashing --------------------------------------------------------------------------------

std::string physics_hash(const json& scene_json) {
  json physics = scene_json;
  for (const char* key : {"engines", "name", "description", "source_file", "content_hash", "notes"}) physics.erase(key);
  // Whether the reference is checked is not physics: the same reference serves both.
  // Nor how the bench counts an energy gain: it moves no run, only the class.
  if (physics.contains("run") && physics["run"].is_object()) {
    physics["run"].erase("self_check");
    physics["run"].erase("energy_gain_rule");
  }
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


json to_json(const SelfCheck& s) { return JsonWriter::write(s); }

SelfCheck self_check_from_json(const json& j) {
  return JsonReader::read<SelfCheck>(j, "reference.self_check.", /*checked=*/true);
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
