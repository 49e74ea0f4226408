// The energy ledger as a chart: one stacked bar per run (the reference's first), each term of its account / |E0|.
#pragma once

#include <string>

#include <nlohmann/json.hpp>

namespace tippe {

// The file the comparison report draws the chart into, beside report.md.
inline constexpr const char* kLedgerChartFile = "ledger.svg";

// An SVG of the ledger of every run in a comparison record: per run one horizontal bar from 0,
// its terms stacked by sign (losses to the left, gains to the right) in the order normal work,
// friction work, drilling work, impacts (removed, so negative), numerical remainder, each divided
// by |E0| of that run; a black tick at E_final - E0, which the terms add up to by the ledger's
// definition. A term the run cannot give (n/a in the table) is left out. Drawn by the program
// itself from numbers: no gnuplot, nothing read from the record enters markup unescaped. Empty
// when no run in the record has a ledger.
std::string ledger_chart_svg(const nlohmann::json& comparison);

}  // namespace tippe
