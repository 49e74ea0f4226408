// The JSON Schemas of the records whose fields a `visit` lists (schemas/*.schema.json), generated from those lists.
#pragma once

#include <string>
#include <vector>

namespace tippe {

// The records' schemas generated here, by file stem: "run-summary", "comparison", "sweep-record".
// The gate result's is generated above the records (gating/gate.h); library/schemas.h lists
// every generated schema, for `tippe info --schema` and the test that compares them with schemas/.
const std::vector<std::string>& record_schema_names();
// The text of schemas/NAME.schema.json (2-space indent, '\n' at the end): the record's fixed
// frame with the properties of its fields from their `visit`. A test compares it with the
// committed file. Throws std::invalid_argument for a name not in record_schema_names().
std::string record_schema_text(const std::string& name);

}  // namespace tippe
