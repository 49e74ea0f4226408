// Event sequences of an engine run and the reference in one canonical vocabulary, aligned by edit distance (the metrics' first wrong event, extra and missing events, time errors).
#pragma once

#include <limits>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "engines/core/simulator.h"

namespace tippe {

// ---- the canonical vocabulary -------------------------------------------------------------
//
// The reference reports what its contact law decides (stick, slip, impacts, touchdowns, lift-off,
// two-contact phases, inversion and reversion, ...); an engine adapter reports only what the
// shared per-step checks see (engines/core/step_checks.cpp): the first inversion, the first stem
// contact, every change of the set of geoms in contact ("switch", "ball -> both") and the run's
// failure status. Both sides are mapped into the kinds below, the only events both can report;
// everything else is left out of the comparison and counted apart (never as "missing"):
//
//   "inversion"     reference "inversion" (the first only) / engine "inversion". The engines'
//                   probe fires once per run (step_checks.cpp: inverted_), so the reference's later
//                   re-inversions after a "reversion" have no counterpart: left out.
//   "stem_contact"  reference "stem_contact" (first stem touchdown) / engine "stem_contact" (first
//                   stem contact reported by the engine).
//   "surface:S"     S in ball, stem, both, none: the contact surface entered at a "switch" event
//                   on either side (both write "A -> B"). Lift-off, touchdown, impact, flight and
//                   two-contact events of the reference are each followed by the switch they
//                   cause, so they are compared through it and left out as duplicates. Surface
//                   phases shorter than the minimum dwell (below) are merged into their
//                   neighbours on both sides, the same rule for both.
//   "status:X"      a run ending in a failure status X (contact_lost, diverged, unphysical,
//                   clamped, failed): reference "contact_lost"/"failed", engine to_string(RunStatus).
//
// Left out because no engine can report them (the adapters see only geoms in contact, not the
// contact law's state): stick, slip, drill_stick, drill_slip, graze, press, hold, unresolved,
// projection, reversion (and every event name not listed above).
inline constexpr const char* kCanonicalEventKinds[] = {"inversion",    "stem_contact", "surface:ball", "surface:stem",
                                                       "surface:both", "surface:none", "status:X"};

// The minimum dwell of a contact-surface phase, as a fraction of the top's time scale sqrt(R/g).
// Soft contacts (MuJoCo, DART, ODE) lose and regain a contact for one step at a time (hundreds of
// "ball -> none", "none -> ball" pairs a run, milliseconds apart, in the published comparisons)
// and the reference's own impact cascades switch surfaces within milliseconds: a phase shorter
// than a tenth of sqrt(R/g) (3.6 ms on `toy`) is below what the bench samples and reports, and
// comparing it would drown the sequence's order in chatter. It is a setting of the bench, not
// physics: the metrics record the dwell applied (event_min_dwell) beside the verdict.
inline constexpr double kEventMinDwellFraction = 0.1;

// Each aligned sequence holds at most this many events (the alignment costs n * m): an engine
// whose surface chatter survives the dwell rule beyond it has its later events counted as not
// compared, and the note says so.
inline constexpr size_t kMaxAlignedEvents = 1000;

struct CanonicalEvent {
  std::string kind;
  double time = 0.0;
};

struct CanonicalSequence {
  std::vector<CanonicalEvent> events;
  // Events left out of the comparison, by name (a reason for each is above): "stick" -> 3, ...;
  // also "surface (phase < dwell)" for merged surface changes, "after the window" and "beyond
  // the first kMaxAlignedEvents".
  std::map<std::string, long long> not_compared;
};

// The canonical sequence of one run's events (in their order): surface phases shorter than
// `min_dwell` merged, events after `until` left out (counted).
CanonicalSequence canonical_events(const std::vector<Event>& events, double min_dwell,
                                   double until = std::numeric_limits<double>::infinity());

enum class AlignOp { Match, Substitution, Missing, Extra };  // Missing: reference only; Extra: engine only
const char* to_string(AlignOp op);

struct AlignedPair {
  AlignOp op = AlignOp::Match;
  std::optional<size_t> reference, engine;  // indices into the sequences
};

struct EventAlignment {
  std::vector<CanonicalEvent> reference, engine;
  std::vector<AlignedPair> pairs;  // in time order
  long long matched = 0;
  // A substitution counts as one missing and one extra event, so that matched + missing is the
  // reference's count and matched + extra the engine's.
  long long missing = 0, extra = 0, substituted = 0;
  // Largest |t_engine - t_reference| over matched pairs; 0 when none is matched (no matched event
  // is off by anything: a gate on it pairs with "no wrong event").
  double time_max_error = 0.0;
  std::optional<size_t> first_wrong;  // index into pairs of the first pair that is not a match
  std::string first_wrong_text;       // "reference: stem_contact at t=1.23, engine: inversion at t=1.1"; "" when none
};

// Edit-distance alignment (Needleman-Wunsch: match 0, substitution, insertion or deletion 1)
// over the kinds; among alignments of equal cost, the one with the smallest sum of matched time
// errors. Pure.
EventAlignment align_events(const std::vector<CanonicalEvent>& reference, const std::vector<CanonicalEvent>& engine);

// "kind at t=T" of one event of a pair's side ("none" when the side has no event there).
std::string event_text(const std::vector<CanonicalEvent>& side, const std::optional<size_t>& i);
// The not-compared counts as one line: "stick 1, impact 12 (reference); surface (phase < dwell) 40 (engine)".
std::string not_compared_text(const CanonicalSequence& reference, const CanonicalSequence& engine);

}  // namespace tippe
