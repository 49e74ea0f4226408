// Synthetic sweep records for the tests of the sweep analysis and of ladders: a record with only what the analysis reads.
#pragma once

#include <optional>
#include <string>

#include "harness/records/sweep_record.h"

namespace tippe::fixtures {

// A record with only what the analysis reads.
inline SweepRecord point(const std::string& engine, const std::string& setup, double value, double cpu,
                         std::optional<double> inversion_error, const std::string& status = "ok") {
  SweepRecord r;
  r.point_id = engine + setup + std::to_string(value);
  r.engine = engine;
  r.setup = setup;
  r.ladder_key = "engines." + engine + ".timestep";
  r.ladder_value = value;
  r.cpu_seconds = cpu;
  r.steps = static_cast<long long>(1.0 / value);
  r.status = status;
  r.reference_inversion_time = 10.0;
  if (inversion_error) {
    r.metrics.inversion_event = "both";
    r.metrics.inversion_time_rel_error = inversion_error;
    r.inversion_time = 10.0 * (1 + *inversion_error);
  } else {
    r.metrics.inversion_event = "reference_only";
  }
  return r;
}

}  // namespace tippe::fixtures
