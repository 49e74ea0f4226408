// Boundary searches for the tests: a search's range, its bisection run on a synthetic criterion, the records such a search leaves, and a sweep file with searches.
#pragma once

#include <functional>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "harness/sweep/sweep.h"
#include "harness/sweep/sweep_search.h"
#include "tests/support/fixtures.h"

namespace tippe::fixtures {

inline SweepSearch search(double from, double to, double resolution, const std::string& criterion = "regime") {
  SweepSearch s;
  s.from = from;
  s.to = to;
  s.resolution = resolution;
  s.criterion = criterion;
  return s;
}

// Runs a search on a synthetic criterion the way the sweep does: every point of `next` is run (its
// outcome becomes known), then the search is replayed, until it asks for nothing.
struct Synthetic {
  SearchReplay replay;
  std::map<std::string, bool> run;  // value text -> criterion
  size_t waves = 0;
};
inline Synthetic run_synthetic(const SweepSearch& s, const std::function<bool(double)>& criterion) {
  Synthetic out;
  const auto outcome = [&](const std::string& text) -> std::optional<bool> {
    const auto it = out.run.find(text);
    if (it == out.run.end()) return std::nullopt;
    return it->second;
  };
  for (;;) {
    out.replay = replay_search(s, outcome);
    if (out.replay.finished()) return out;
    ++out.waves;
    for (const SearchStep& st : out.replay.next) out.run[search_value_text(st.value)] = criterion(st.value);
  }
}

// Records of a synthetic search as a sweep would write them: the regime criterion, the reference
// inverting; the run inverts (in the regime) where `passes` says so.
inline std::vector<SweepRecord> synthetic_records(const SweepSearch& s, const std::function<bool(double)>& passes,
                                           const std::string& scene, long long scene_index) {
  const Synthetic r = run_synthetic(s, passes);
  std::vector<SweepRecord> out;
  const auto add = [&](const SearchStep& st) {
    SweepRecord x;
    x.point_id = scene + search_value_text(st.value);
    x.scene = scene;
    x.scene_index = scene_index;
    x.setup = "ode-regime";
    x.engine = "ode";
    x.ladder_key = "engines.ode.timestep";
    x.ladder_value = st.value;
    x.ladder_label = search_value_text(st.value);
    x.ladder_index = st.ladder_index;
    x.search = s;
    x.reference_inversion_time = 4.33;
    if (passes(st.value)) x.inversion_time = 4.4;
    x.cpu_seconds = 1e-4 / st.value;
    out.push_back(x);
  };
  for (const SearchStep& st : r.replay.known) add(st);
  return out;
}

// A sweep file of two searches (one over a grid) and a ladder on the toy scenes.
inline std::string sweep_text(const std::string& extra = "") {
  return "description = \"search planner test\"\n"
         "scenes = [ \"" + kScenesDir + "toy.toml\", { file = \"" + kScenesDir + "toy_viscous.toml\", duration = 4.6 } ]\n"
         "[[setup]]\nname = \"ode-regime\"\nengine = \"ode\"\n"
         "ladder.search = { key = \"engines.ode.timestep\", from = 1e-6, to = 1e-1, criterion = \"regime\" }\n"
         "[[setup]]\nname = \"bullet-grid\"\nengine = \"bullet\"\n"
         "ladder.search = { key = \"engines.bullet.timestep\", from = 1e-5, to = 1e-2, criterion = "
         "\"inversion_time_rel_error <= 0.01\", resolution = 0.1 }\n"
         "grid = { key = \"engines.bullet.friction_directions\", values = [2, 1] }\n"
         "[[setup]]\nname = \"ode-ladder\"\nengine = \"ode\"\n"
         "ladder = { key = \"engines.ode.timestep\", values = [1e-3, 1e-2] }\n" +
         extra;
}

}  // namespace tippe::fixtures
