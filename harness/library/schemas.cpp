// Every generated JSON Schema by name: the records' (records/record_schemas.cpp), the gate result's (gating/gate_schema.cpp) and the advice's (advise/advice_record.cpp).
#include "harness/library/schemas.h"

#include <stdexcept>

#include "harness/advise/advice_record.h"
#include "harness/gating/gate.h"
#include "harness/records/record_schemas.h"

namespace tippe {

const std::vector<std::string>& generated_schema_names() {
  static const std::vector<std::string> names = [] {
    std::vector<std::string> n = record_schema_names();
    n.emplace_back("gate-result");
    n.emplace_back("advice");
    return n;
  }();
  return names;
}

std::string generated_schema_text(const std::string& name) {
  if (name == "gate-result") return gate_result_schema_text();
  if (name == "advice") return advice_schema_text();
  for (const std::string& n : record_schema_names())
    if (n == name) return record_schema_text(name);
  std::string list;
  for (const std::string& n : generated_schema_names()) list += (list.empty() ? "" : ", ") + n;
  throw std::invalid_argument("no generated schema \"" + name + "\" (expected one of " + list + ")");
}

}  // namespace tippe
