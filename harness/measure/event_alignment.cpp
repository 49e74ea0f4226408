// Canonical event sequences and their edit-distance alignment (the vocabulary and its reasons are in the header).
#include "harness/measure/event_alignment.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <set>
#include <utility>

namespace tippe {

namespace {

// The surface a "switch" event enters ("ball -> both" -> "both"); "" when the detail is not of
// that form (never written by either side, but records are input).
std::string switch_target(const std::string& detail) {
  const size_t arrow = detail.find("->");
  if (arrow == std::string::npos) return "";
  size_t b = arrow + 2;
  while (b < detail.size() && detail[b] == ' ') ++b;
  size_t e = detail.size();
  while (e > b && detail[e - 1] == ' ') --e;
  return detail.substr(b, e - b);
}
std::string switch_source(const std::string& detail) {
  const size_t arrow = detail.find("->");
  if (arrow == std::string::npos) return "";
  size_t e = arrow;
  while (e > 0 && detail[e - 1] == ' ') --e;
  return detail.substr(0, e);
}

bool is_failure_status(const std::string& name) {
  static const std::set<std::string> statuses = {"contact_lost", "diverged", "unphysical", "clamped", "failed"};
  return statuses.count(name) > 0;
}

std::string event_time_text(double t) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.4g", t);
  return buf;
}

}  // namespace

CanonicalSequence canonical_events(const std::vector<Event>& events, double min_dwell, double until) {
  CanonicalSequence out;
  // The surface changes first, to judge each phase by its whole length (the next change, of any
  // kind of surface, ends it).
  std::vector<size_t> switches;
  for (size_t i = 0; i < events.size(); ++i)
    if (events[i].name == "switch" && !switch_target(events[i].detail).empty()) switches.push_back(i);
  std::set<size_t> kept_switches;
  std::string current;
  for (size_t k = 0; k < switches.size(); ++k) {
    const Event& e = events[switches[k]];
    if (k == 0) current = switch_source(e.detail);
    const std::string to = switch_target(e.detail);
    const bool short_phase = k + 1 < switches.size() && events[switches[k + 1]].time - e.time < min_dwell;
    if (short_phase || to == current) {
      ++out.not_compared["surface (phase < dwell)"];
      continue;
    }
    kept_switches.insert(switches[k]);
    current = to;
  }
  bool inverted = false;
  for (size_t i = 0; i < events.size(); ++i) {
    const Event& e = events[i];
    std::string kind;
    if (e.name == "inversion") {
      if (inverted) {
        ++out.not_compared["inversion (after the first)"];
        continue;
      }
      inverted = true;
      kind = "inversion";
    } else if (e.name == "stem_contact") {
      kind = "stem_contact";
    } else if (e.name == "switch") {
      if (!kept_switches.count(i)) {
        if (switch_target(e.detail).empty()) ++out.not_compared["switch (unreadable)"];
        continue;
      }
      kind = "surface:" + switch_target(e.detail);
    } else if (is_failure_status(e.name)) {
      kind = "status:" + e.name;
    } else {
      ++out.not_compared[e.name];
      continue;
    }
    if (!(e.time <= until)) {
      ++out.not_compared["after the window"];
      continue;
    }
    if (out.events.size() >= kMaxAlignedEvents) {
      ++out.not_compared["beyond the first " + std::to_string(kMaxAlignedEvents)];
      continue;
    }
    out.events.push_back({kind, e.time});
  }
  return out;
}

const char* to_string(AlignOp op) {
  switch (op) {
    case AlignOp::Match: return "match";
    case AlignOp::Substitution: return "substitution";
    case AlignOp::Missing: return "missing";
    case AlignOp::Extra: return "extra";
  }
  return "?";
}

std::string event_text(const std::vector<CanonicalEvent>& side, const std::optional<size_t>& i) {
  if (!i) return "none";
  return side[*i].kind + " at t=" + event_time_text(side[*i].time);
}

EventAlignment align_events(const std::vector<CanonicalEvent>& reference, const std::vector<CanonicalEvent>& engine) {
  EventAlignment a;
  a.reference = reference;
  a.engine = engine;
  const size_t n = reference.size(), m = engine.size();
  // cost[i][j]: the best alignment of reference[0, i) with engine[0, j), compared as (edits, sum
  // of matched time errors): the edit count decides, the time errors only break ties.
  using Cost = std::pair<long long, double>;
  std::vector<Cost> cost((n + 1) * (m + 1));
  auto at = [&](size_t i, size_t j) -> Cost& { return cost[i * (m + 1) + j]; };
  for (size_t i = 0; i <= n; ++i) at(i, 0) = {static_cast<long long>(i), 0.0};
  for (size_t j = 0; j <= m; ++j) at(0, j) = {static_cast<long long>(j), 0.0};
  auto diagonal = [&](size_t i, size_t j) {  // reference[i - 1] against engine[j - 1]
    const Cost& c = at(i - 1, j - 1);
    if (reference[i - 1].kind == engine[j - 1].kind)
      return Cost{c.first, c.second + std::abs(engine[j - 1].time - reference[i - 1].time)};
    return Cost{c.first + 1, c.second};
  };
  for (size_t i = 1; i <= n; ++i)
    for (size_t j = 1; j <= m; ++j) {
      const Cost up{at(i - 1, j).first + 1, at(i - 1, j).second};
      const Cost left{at(i, j - 1).first + 1, at(i, j - 1).second};
      at(i, j) = std::min({diagonal(i, j), up, left});
    }
  // Trace back, preferring the diagonal on ties (a substitution reads better than a missing and
  // an extra event).
  std::vector<AlignedPair> reversed;
  size_t i = n, j = m;
  while (i > 0 || j > 0) {
    if (i > 0 && j > 0 && at(i, j) == diagonal(i, j)) {
      const bool same = reference[i - 1].kind == engine[j - 1].kind;
      reversed.push_back({same ? AlignOp::Match : AlignOp::Substitution, i - 1, j - 1});
      --i, --j;
    } else if (i > 0 && (j == 0 || at(i, j) == Cost{at(i - 1, j).first + 1, at(i - 1, j).second})) {
      reversed.push_back({AlignOp::Missing, i - 1, std::nullopt});
      --i;
    } else {
      reversed.push_back({AlignOp::Extra, std::nullopt, j - 1});
      --j;
    }
  }
  a.pairs.assign(reversed.rbegin(), reversed.rend());
  for (size_t k = 0; k < a.pairs.size(); ++k) {
    const AlignedPair& p = a.pairs[k];
    switch (p.op) {
      case AlignOp::Match:
        ++a.matched;
        a.time_max_error = std::max(a.time_max_error, std::abs(engine[*p.engine].time - reference[*p.reference].time));
        break;
      case AlignOp::Substitution: ++a.substituted, ++a.missing, ++a.extra; break;
      case AlignOp::Missing: ++a.missing; break;
      case AlignOp::Extra: ++a.extra; break;
    }
    if (p.op != AlignOp::Match && !a.first_wrong) {
      a.first_wrong = k;
      a.first_wrong_text = "reference: " + event_text(reference, p.reference) + ", engine: " + event_text(engine, p.engine);
    }
  }
  return a;
}

std::string not_compared_text(const CanonicalSequence& reference, const CanonicalSequence& engine) {
  auto side = [](const CanonicalSequence& s) {
    std::string text;
    for (const auto& [name, count] : s.not_compared) text += (text.empty() ? "" : ", ") + name + " " + std::to_string(count);
    return text;
  };
  std::string r = side(reference), e = side(engine);
  std::string text;
  if (!r.empty()) text += r + " (reference)";
  if (!e.empty()) text += (text.empty() ? "" : "; ") + e + " (engine)";
  return text;
}

}  // namespace tippe
