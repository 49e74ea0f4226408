// The gate result's JSON Schema (schemas/gate-result.schema.json): a fixed frame, the results' properties from CheckResult's and GateRow's `visit`.
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "harness/gating/gate.h"
#include "harness/records/fields.h"

namespace tippe {

namespace {

// What no field list gives: the schema's identity and the frame to_json and `tippe gate --json`
// write around the results (gate_check.cpp, cli_gate.cpp).
constexpr const char* kGateResultFrame = R"json({
  "$schema": "https://json-schema.org/draft/2020-12/schema",
  "$id": "gate-result.schema.json",
  "title": "tippe gate result (tippe gate --json)",
  "description": "The checks of a gate file and whether each passed; the JUnit XML of --junit carries the same rows.",
  "type": "object",
  "properties": {
    "format": {},
    "gate_file": {"type": "string", "description": "the gate file as given"},
    "passed": {"type": "boolean", "description": "every check passed"},
    "checks": {"type": "integer", "minimum": 0, "description": "checks run"},
    "failed": {"type": "integer", "minimum": 0, "description": "checks failed"},
    "results": {}
  },
  "required": ["format", "gate_file", "passed", "checks", "failed", "results"]
})json";

}  // namespace

std::string gate_result_schema_text() {
  nlohmann::ordered_json s = nlohmann::ordered_json::parse(kGateResultFrame);
  s["properties"]["format"] = {{"const", kGateResultFormat}};
  SchemaBuilder b;
  b(Field("results", "one per check, in the gate file's order"), std::vector<CheckResult>{});
  s["properties"]["results"] = b.properties["results"];
  return s.dump(2) + "\n";
}

}  // namespace tippe
