// The library's RunSummary (<tippe/tippe.h>) made from a run's record, through the two structs' field lists.
#pragma once

#include "include/tippe/tippe.h"

#include "harness/records/records.h"

namespace tippe {

// The record's summary.json (its `visit`, records.h) read into a RunSummary by the summary's
// `visit` (<tippe/tippe.h>), key by key: no field is copied by hand. Every key of the record
// but "scene_spec" is a field of the summary (LibrarySummary.* checks it); `json` is the
// record's summary.json text, as `tippe run` writes it.
RunSummary to_summary(const RunRecord& r);

}  // namespace tippe
