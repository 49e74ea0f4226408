// Sweep records as the tests compare them: without what differs between two runs of the same build on the same input.
#pragma once

#include <nlohmann/json.hpp>

// A sweep record (its JSON) without the CPU and wall times and the ratios made from them: what
// two runs of one sweep share whatever the machine's load, the thread count or the ranks.
inline nlohmann::json without_timings(nlohmann::json r) {
  if (r.contains("work"))
    for (const char* k : {"cpu_seconds", "cpu_seconds_repeats", "wall_seconds"}) r["work"].erase(k);
  if (r.contains("metrics"))
    for (const char* k : {"cpu_seconds", "wall_seconds", "cost_ratio", "real_time_factor"}) r["metrics"].erase(k);
  if (r.contains("reference") && r["reference"].is_object()) r["reference"].erase("cpu_seconds");
  return r;
}
