// The sweep report's "Modelling choices" section, made from the records alone.
#pragma once

#include <vector>

#include "harness/records/sweep_record.h"
#include "harness/report/document.h"

namespace tippe {

// Which choices (grid values, or a ladder of non-numbers) move the verdict on each scene, per
// engine in sentences and as one table; nothing when no setup has a choice axis.
void choices_section(const std::vector<SweepRecord>& records, Document& doc);

}  // namespace tippe
