// A run record that ran to its end, the base of the tests' synthetic records (the classification and the gate tests).
#pragma once

#include <string>

#include "harness/records/records.h"

namespace tippe::fixtures {

inline RunRecord ok_record(const std::string& engine) {
  RunRecord r;
  r.engine = engine;
  r.status = "ok";
  return r;
}

}  // namespace tippe::fixtures
