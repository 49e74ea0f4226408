// libFuzzer target: arbitrary bytes as records.jsonl and as sweep.json, read back the way `tippe sweep` resumes and `--report` and `--merge` read them; only SweepRecordError may escape.
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <string>

#include "harness/sweep/sweep.h"
#include "harness/report/sweep_analysis.h"

namespace {

// The readers' contract: SweepRecordError ("FILE:LINE: KEY: reason") for anything that is not a
// record, nothing else. What they accept must write back out and read back the same, and the
// report must render from it (the report is rebuilt from records read back).
template <class F>
void check(const char* what, F f) {
  try {
    f();
  } catch (const tippe::SweepRecordError&) {
  } catch (const std::exception& e) {
    std::fprintf(stderr, "fuzz_sweep_records: %s: unexpected exception: %s\n", what, e.what());
    std::abort();
  } catch (...) {
    std::fprintf(stderr, "fuzz_sweep_records: %s: unexpected non-standard exception\n", what);
    std::abort();
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  check("parse_records_text", [&] {
    const tippe::RecordsFile f = tippe::parse_records_text(text, "records.jsonl");
    std::string back;
    for (const tippe::SweepRecord& r : f.records) back += tippe::to_jsonl(r);
    const tippe::RecordsFile again = tippe::parse_records_text(back, "records.jsonl (written back)");
    if (again.records.size() != f.records.size()) {
      std::fprintf(stderr, "fuzz_sweep_records: %zu records read back as %zu\n", f.records.size(), again.records.size());
      std::abort();
    }
    (void)tippe::render_sweep_markdown(f.records);
  });
  check("parse_sweep_meta", [&] { (void)tippe::parse_sweep_meta(text, "sweep.json"); });
  return 0;
}
