// The record schemas (schemas/run-summary.schema.json, comparison.schema.json, sweep-record.schema.json): a fixed frame per record, its fields' properties from their `visit`.
#include "harness/records/record_schemas.h"

#include <algorithm>
#include <stdexcept>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "harness/records/comparison.h"
#include "harness/records/fields.h"
#include "harness/records/records.h"
#include "harness/records/sweep_schema.h"

namespace tippe {

namespace {

using ordered = nlohmann::ordered_json;

// What no field list gives: the schema's identity, the "format" each record names, the parts of
// a comparison that are its frame rather than fields (reference, engines, the engine versions);
// the reference's self-check is its `visit`'s.
constexpr const char* kRunSummaryFrame = R"json({
  "$schema": "https://json-schema.org/draft/2020-12/schema",
  "$id": "run-summary.schema.json",
  "title": "tippe run summary (summary.json)",
  "description": "What `tippe run` writes beside trajectory.csv; also the reference/engine summaries inside comparison.json and a sweep's reference summaries.",
  "$defs": {},
  "allOf": [{"$ref": "#/$defs/summary"}, {"required": ["format"]}]
})json";

constexpr const char* kComparisonFrame = R"json({
  "$schema": "https://json-schema.org/draft/2020-12/schema",
  "$id": "comparison.schema.json",
  "title": "tippe comparison (comparison.json)",
  "description": "What `tippe compare` writes: the reference's and each engine's summary and the metrics of each engine against the reference.",
  "type": "object",
  "properties": {
    "format": {"const": "tippe-comparison-1"},
    "scene_name": {"type": "string"},
    "scene_file": {"type": "string"},
    "scene_hash": {"type": "string"},
    "physics_hash": {"type": "string", "description": "hash of the scene's physics (engine tables left out)"},
    "scene": {"type": "object"},
    "provenance": {
      "allOf": [
        {"$ref": "run-summary.schema.json#/$defs/provenance"},
        {
          "type": "object",
          "properties": {"engine_versions": {"type": "object", "additionalProperties": {"type": "string"}}},
          "required": ["engine_versions"]
        }
      ]
    },
    "reference": {
      "type": "object",
      "properties": {
        "cached": {"type": "boolean"},
        "summary": {"$ref": "run-summary.schema.json#/$defs/summary"}
      },
      "required": ["cached", "summary"]
    },
    "engines": {
      "type": "array",
      "items": {
        "type": "object",
        "properties": {
          "engine": {"type": "string"},
          "summary": {"$ref": "run-summary.schema.json#/$defs/summary"},
          "metrics": {"$ref": "#/$defs/metrics"}
        },
        "required": ["engine", "metrics", "summary"]
      }
    }
  },
  "required": ["format", "scene_name", "scene_file", "scene_hash", "physics_hash", "scene", "provenance", "reference", "engines"],
  "$defs": {}
})json";

constexpr const char* kSweepRecordFrame = R"json({
  "$schema": "https://json-schema.org/draft/2020-12/schema",
  "$id": "sweep-record.schema.json",
  "title": "tippe sweep record (one line of records.jsonl)",
  "description": "One point of a sweep: a scene, a setup and a ladder value run on one engine and compared with the reference.",
  "type": "object",
  "properties": {"format": {"const": "tippe-sweep-record-1"}},
  "required": ["format"]
})json";

ordered run_summary_schema() {
  ordered s = ordered::parse(kRunSummaryFrame);
  SchemaBuilder b;
  b.properties["format"] = {{"const", kRunRecordFormat}};
  const RunRecord record{};
  visit(record, b);
  // Written by comparison.json only (to_json(Comparison) bounds the list of switch events).
  b.properties["events_omitted"] = {{"type", "object"},
                                    {"additionalProperties", {{"type", "integer"}}},
                                    {"description", "comparison.json only: events left out of the list, by name"}};
  s["$defs"]["summary"] = b.schema("object");
  s["$defs"]["provenance"] = b.properties["provenance"];
  return s;
}

ordered comparison_schema() {
  ordered s = ordered::parse(kComparisonFrame);
  SchemaBuilder b;
  const Metrics metrics{};
  visit(metrics, b);
  ordered m = b.schema("object");
  m["description"] =
      "An engine's run against the reference (README, 'Metrics'): errors in SI units (m, rad, J/E0), times in s";
  s["$defs"]["metrics"] = m;
  // The reference's self-check: its fields, and whether it came from the cache (the
  // comparison's, written beside them).
  SchemaBuilder check;
  const SelfCheck self_check{};
  visit(self_check, check);
  check.properties["cached"] = {{"type", "boolean"}, {"description", "the self-check came from the reference cache"}};
  check.required.emplace_back("cached");
  s["properties"]["reference"]["properties"]["self_check"] = check.schema("object");
  return s;
}

ordered sweep_record_schema() {
  ordered s = ordered::parse(kSweepRecordFrame);
  SweepSchemaBuilder b;
  const SweepRecord record{};
  visit(record, b);
  for (auto& [key, p] : b.properties.items()) s["properties"][key] = p;
  std::vector<std::string> required = b.required;
  required.emplace_back("format");
  std::sort(required.begin(), required.end());
  s["required"] = required;
  return s;
}

}  // namespace

const std::vector<std::string>& record_schema_names() {
  static const std::vector<std::string> names = {"run-summary", "comparison", "sweep-record"};
  return names;
}

std::string record_schema_text(const std::string& name) {
  if (name == "run-summary") return run_summary_schema().dump(2) + "\n";
  if (name == "comparison") return comparison_schema().dump(2) + "\n";
  if (name == "sweep-record") return sweep_record_schema().dump(2) + "\n";
  throw std::invalid_argument("no record schema \"" + name + "\" (expected run-summary, comparison or sweep-record)");
}

}  // namespace tippe
