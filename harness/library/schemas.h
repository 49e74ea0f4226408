// Every JSON Schema generated from field lists (schemas/NAME.schema.json): the records' and the gate result's, for `tippe info --schema` and the test that compares them with the committed files.
#pragma once

#include <string>
#include <vector>

namespace tippe {

// By file stem: the records' (records/record_schemas.h: run-summary, comparison, sweep-record)
// then the gate result's (gating/gate.h: gate-result). The list sits above gating, so that the
// records layer, which makes most of them, needs to know nothing of gates.
const std::vector<std::string>& generated_schema_names();
// The text of schemas/NAME.schema.json (2-space indent, '\n' at the end). Throws
// std::invalid_argument naming the generated schemas for any other name.
std::string generated_schema_text(const std::string& name);

}  // namespace tippe
