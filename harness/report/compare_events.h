// The comparison report's event-sequence section: per engine the aligned canonical sequences and the first wrong event, as tables.
#pragma once

#include <nlohmann/json.hpp>

#include "harness/report/document.h"

namespace tippe {

// Adds "Event sequences" to `d` from a comparison record (comparison.json as JSON): one summary
// table (per engine: events compared, matched, missing, extra, largest time error, first wrong
// event) and per engine a folded table of the aligned pairs the record keeps, all from the
// metrics. Nothing when no engine's metrics carry the alignment (records older than it).
void add_event_sequences(Document& d, const nlohmann::json& comparison);

}  // namespace tippe
