// The advice as a record (OUT/advice.json): one field list per engine's advice, from which its JSON and its schema (schemas/advice.schema.json) follow.
#pragma once

#include <optional>
#include <string>
#include <type_traits>
#include <vector>

#include <nlohmann/json.hpp>

#include "harness/advise/advise.h"
#include "harness/records/fields.h"

namespace tippe {

inline constexpr const char* kAdviceFormat = "tippe-advice-1";

// One configuration an engine's search covered, and what its boundary search found: why it
// was or was not advised (the page's table of searched configurations).
struct SearchedConfiguration {
  std::string configuration;              // "integrator = RK4, cone = elliptic"; "its defaults": no axes
  std::vector<std::string> settings;      // engines.E.KEY=VALUE, one per axis
  std::string status;                     // the search's (SearchBoundary::status); empty: no records yet
  std::optional<double> largest_safe_step, first_unsafe_step;
  long long runs = 0;
};
template <class R, class V>
std::enable_if_t<std::is_same_v<std::remove_const_t<R>, SearchedConfiguration>> visit(R& a, V& v) {
  v(Field("configuration", "the values of the engine's categorical axes (\"its defaults\": it declares none)"),
    a.configuration);
  v(Field("settings", "the configuration as --set arguments"), a.settings);
  v(Field("status",
          "the boundary search's outcome: found, all_safe, none_safe, incomplete or not_applicable; null: no "
          "records")
        .empty_as_null(),
    a.status);
  v(Field("largest_safe_step", "the largest safe value of the cost knob found; null: none").minimum(0),
    a.largest_safe_step);
  v(Field("first_unsafe_step", "the smallest unsafe value above it; null: none in the searched range").minimum(0),
    a.first_unsafe_step);
  v(Field("runs", "runs of this search").minimum(0), a.runs);
}

// One engine's advice, flat: what the page's sentence and the gate say of it.
struct EngineAdvice {
  std::string engine, knob;
  std::string configuration;              // "integrator = RK4, cone = elliptic"; empty: no advice
  std::vector<std::string> settings;      // engines.E.KEY=VALUE, the cost knob's advised value last
  std::optional<double> advised_step;     // the largest safe step / kAdviceMargin, confirmed by a run
  std::optional<double> largest_safe_step, first_unsafe_step;
  std::optional<double> cpu_seconds;      // of the confirming point: the least of its runs
  std::string confirm_point;              // its point id in confirm/records.jsonl
  std::vector<std::string> near_ties;     // configurations not told apart from it by CPU time
  std::string reason;                     // why there is no advice
  long long configurations_searched = 0, configurations_not_searched = 0;
  std::vector<std::string> sensitivity;   // one sentence per axis
  std::vector<SearchedConfiguration> searched;  // in search order
  std::vector<std::string> not_searched;        // configurations left out by the budget
};
template <class R, class V>
std::enable_if_t<std::is_same_v<std::remove_const_t<R>, EngineAdvice>> visit(R& a, V& v) {
  v(Field("engine"), a.engine);
  v(Field("knob", "the cost knob searched, a key of [engines.ENGINE] (the time step)"), a.knob);
  v(Field("configuration", "the advised values of the engine's categorical axes; null: no advice").empty_as_null(),
    a.configuration);
  v(Field("settings", "the advised settings as --set arguments, the cost knob's value last (empty: no advice)"),
    a.settings);
  v(Field("advised_step", "the largest safe step found / the margin, confirmed safe by a run; null: no advice")
        .minimum(0),
    a.advised_step);
  v(Field("largest_safe_step", "the advised configuration's boundary: the largest safe value of the knob found")
        .minimum(0),
    a.largest_safe_step);
  v(Field("first_unsafe_step", "the smallest unsafe value above it; null: safe to the end of the searched range")
        .minimum(0),
    a.first_unsafe_step);
  v(Field("cpu_seconds", "s: CPU of the confirming point, the least of its runs (the record's repeats)").minimum(0),
    a.cpu_seconds);
  v(Field("confirm_point", "the confirming run's point id (confirm/records.jsonl); null: none").empty_as_null(),
    a.confirm_point);
  v(Field("near_ties",
          "the other configurations whose confirming run is safe at a CPU time within 10 % of the advised one's "
          "(a difference the machine's noise could reverse), cheapest first: \"CONFIGURATION, KNOB STEP (CPU CPU s)\""),
    a.near_ties);
  v(Field("reason", "why there is no advice; null: there is").empty_as_null(), a.reason);
  v(Field("configurations_searched", "configurations whose boundary was searched").minimum(0),
    a.configurations_searched);
  v(Field("configurations_not_searched", "configurations left out by the run budget (--max-runs)").minimum(0),
    a.configurations_not_searched);
  v(Field("sensitivity", "per categorical axis, how far it moved the boundary"), a.sensitivity);
  v(Field("searched", "every configuration searched, in order, with its boundary (advice written before the "
                      "field: absent)")
        .since(),
    a.searched);
  v(Field("not_searched", "the configurations left out by the run budget (advice written before the field: "
                          "absent)")
        .since(),
    a.not_searched);
}

// The whole advice: the scene, the one criterion of "safe", the reference's answer, each engine's.
struct AdviceRecord {
  std::string scene, criterion;
  bool reference_inverts = false;
  std::optional<double> reference_inversion_time;
  double duration = 0;
  long long runs = 0;
  long long repeats = 1;
  bool gate_written = false;
  std::vector<EngineAdvice> engines;
};
template <class R, class V>
std::enable_if_t<std::is_same_v<std::remove_const_t<R>, AdviceRecord>> visit(R& a, V& v) {
  v(Field("scene", "the scene's name"), a.scene);
  v(Field("criterion", "the one criterion of safe every search, confirming run and gate used"), a.criterion);
  v(Field("reference_inverts", "whether the reference inverts within the duration"), a.reference_inverts);
  v(Field("reference_inversion_time", "s; null: no inversion").minimum(0), a.reference_inversion_time);
  v(Field("duration", "s: the horizon of every run").minimum(0), a.duration);
  v(Field("runs", "search and confirming runs").minimum(0), a.runs);
  v(Field("repeats", "runs of each confirming point, interleaved; its CPU time is their least (advice written "
                     "before the field: 1)")
        .since()
        .minimum(1),
    a.repeats);
  v(Field("gate_written", "advice.toml was written (some engine has advice)"), a.gate_written);
  v(Field("engines", "one per engine, in the order asked"), a.engines);
}

// The record of a finished advice (what run_advise returns).
AdviceRecord advice_record(const AdviceResult& result);
// {"format": kAdviceFormat, ...the record's fields}.
nlohmann::json to_json(const AdviceRecord& record);
// OUT/advice.json's text (what the Python verb returns too).
std::string advice_json_text(const AdviceRecord& record);
// schemas/advice.schema.json: the frame and the fields of the two lists.
std::string advice_schema_text();

}  // namespace tippe
