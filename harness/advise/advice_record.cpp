// The advice as a record: filled from a finished advice, written as JSON and described as JSON Schema, all from its field list.
#include "harness/advise/advice_record.h"

#include "harness/sweep/sweep_search.h"

namespace tippe {

AdviceRecord advice_record(const AdviceResult& result) {
  AdviceRecord a;
  a.scene = result.scene_name;
  a.criterion = result.criterion;
  a.reference_inverts = result.reference_inverts;
  a.reference_inversion_time = result.reference_inversion;
  a.duration = result.duration;
  a.runs = static_cast<long long>(result.runs);
  a.repeats = result.repeats;
  a.gate_written = result.gate_written;
  for (const AdviceEngine& e : result.engines) {
    EngineAdvice x;
    x.engine = e.engine;
    x.knob = e.knob;
    x.configurations_searched = static_cast<long long>(e.configs.size());
    x.configurations_not_searched = static_cast<long long>(e.unsearched.size());
    x.sensitivity = e.sensitivity;
    if (e.chosen) {
      const AdviceConfig& c = e.configs.at(*e.chosen);
      x.configuration = c.text();
      x.settings = c.set();
      x.settings.push_back("engines." + e.engine + "." + e.knob + "=" + search_value_text(e.step));
      x.advised_step = e.step;
      x.largest_safe_step = e.boundary;
      if (e.beyond > 0) x.first_unsafe_step = e.beyond;
      x.cpu_seconds = e.cpu_seconds;
      x.confirm_point = e.confirm_point;
      x.near_ties = advice_ties_text(e);
    } else {
      x.reason = e.reason;
    }
    for (size_t i = 0; i < e.configs.size(); ++i) {
      const AdviceConfig& c = e.configs[i];
      SearchedConfiguration sc;
      sc.configuration = c.text();
      sc.settings = c.set();
      if (i < e.boundaries.size()) {
        const SearchBoundary& b = e.boundaries[i];
        sc.status = b.status;
        sc.largest_safe_step = b.boundary;
        sc.first_unsafe_step = b.beyond;
        sc.runs = static_cast<long long>(b.runs);
      }
      x.searched.push_back(std::move(sc));
    }
    for (const AdviceConfig& c : e.unsearched) x.not_searched.push_back(c.text());
    a.engines.push_back(std::move(x));
  }
  return a;
}

nlohmann::json to_json(const AdviceRecord& record) {
  nlohmann::json j = JsonWriter::write(record);
  j["format"] = kAdviceFormat;
  return j;
}

std::string advice_json_text(const AdviceRecord& record) { return to_json(record).dump(2) + "\n"; }

std::string advice_schema_text() {
  nlohmann::ordered_json s = {
      {"$schema", "https://json-schema.org/draft/2020-12/schema"},
      {"$id", "advice.schema.json"},
      {"title", "tippe advice (OUT/advice.json)"},
      {"description",
       "What `tippe advise` found: per engine the cheapest configuration that is safe under the one criterion, "
       "confirmed by a run, or why there is none; advice.toml is the gate that keeps it."}};
  SchemaBuilder b;
  b.properties["format"] = {{"const", kAdviceFormat}};
  b.required.emplace_back("format");
  const AdviceRecord record{};
  visit(record, b);
  const nlohmann::ordered_json body = b.schema("object");
  for (const auto& [k, v] : body.items()) s[k] = v;
  return s.dump(2) + "\n";
}

}  // namespace tippe
