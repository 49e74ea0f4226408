// The comparison report's energy-ledger section: per run where its energy went (contact work, impacts, the contact's store, numerical), and the cause of an engine's deviation.
#pragma once

#include <string>

#include <nlohmann/json.hpp>

#include "harness/report/document.h"

namespace tippe {

// Adds "Energy ledger" to `d`: one table, the reference and every engine, of E_final - E0 and
// its account (normal, friction and drilling work, impacts, the contact's elastic energy, the
// numerical remainder), each / |E0| of its run, "n/a" for a term the simulator cannot give;
// then one sentence per engine saying where its energy loss went. Nothing when no run carries
// the ledger (records older than it). `chart`: the page has the ledger chart (kLedgerChartFile,
// report/ledger_chart.h) beside it, shown under the table.
void add_energy_ledger(Document& d, const nlohmann::json& comparison, bool chart = false);

// "by t = 2.13 its energy fell by 0.2 E0 (...); of that change 31 % numerical, 0 % friction work,
// ...; the dominant term: numerical" for one engine entry of a comparison record (without the
// engine's name); empty when its run carries no ledger.
std::string ledger_cause_sentence(const nlohmann::json& comparison, const nlohmann::json& engine_entry);

}  // namespace tippe
