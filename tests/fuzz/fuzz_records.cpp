// libFuzzer target: arbitrary bytes as a run record or comparison.json through the JSON readers; only json exceptions may escape.
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <stdexcept>
#include <string>

#include <nlohmann/json.hpp>

#include "harness/measure/compare.h"
#include "harness/records/records.h"

namespace {

// Each reader's contract: nlohmann::json::exception for a missing or mistyped field, and, where
// the reader says so (`invalid_argument_ok`: comparison_from_json refuses a record name that could
// name a path, an engine twice or one that differs from its summary's), std::invalid_argument;
// nothing else. What it accepts must write back out (the report rewrites what it read).
template <class Read, class Write>
void check(const char* what, Read read, Write write, bool invalid_argument_ok = false) {
  try {
    (void)write(read()).dump();
  } catch (const nlohmann::json::exception&) {
  } catch (const std::invalid_argument& e) {
    if (!invalid_argument_ok) {
      std::fprintf(stderr, "fuzz_records: %s: unexpected exception: %s\n", what, e.what());
      std::abort();
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "fuzz_records: %s: unexpected exception: %s\n", what, e.what());
    std::abort();
  } catch (...) {
    std::fprintf(stderr, "fuzz_records: %s: unexpected non-standard exception\n", what);
    std::abort();
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  // Files that are not JSON stop at the parser, which reports them without throwing here.
  const nlohmann::json j = nlohmann::json::parse(data, data + size, nullptr, /*allow_exceptions=*/false);
  if (j.is_discarded()) return 0;
  // summary.json, and the reference's summary inside comparison.json
  check("from_json", [&] { return tippe::from_json(j); }, [](const tippe::RunRecord& r) { return tippe::to_json(r); });
  check("comparison_from_json", [&] { return tippe::comparison_from_json(j); },
        [](const tippe::Comparison& c) { return tippe::to_json(c); }, /*invalid_argument_ok=*/true);
  check("metrics_from_json", [&] { return tippe::metrics_from_json(j); },
        [](const tippe::Metrics& m) { return tippe::to_json(m); });
  // The reference cache is keyed by the physics hash of a record's scene_spec.
  check("physics_hash", [&] { return tippe::physics_hash(j); }, [](const std::string& h) { return nlohmann::json(h); });
  return 0;
}
