// Boundary searches in sweeps: `ladder.search` read from a sweep file, the bisection replayed from records, the plan's waves, and the boundaries found.
#include "harness/sweep/sweep_search.h"
#include "harness/io/text.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <map>
#include <set>
#include <sstream>
#include <stdexcept>
#include <tuple>

#include <nlohmann/json.hpp>

#include "harness/io/scene_io.h"
#include "harness/scene/resolve.h"
#include "harness/io/toml_reader.h"

namespace tippe {

namespace {

using json = nlohmann::json;

// The shortest text that reads back as v.
std::string shortest(double v) { return json(v).dump(); }


}  // namespace

// ---- the file form ----------------------------------------------------------------------------

SweepSearch read_search(const toml::node& node, const std::string& file, const std::string& where, std::string& key) {
  const auto fail = [&](const std::string& k, const std::string& why) -> void {
    throw SceneError(file + ": " + k + ": " + why);
  };
  const auto* t = node.as_table();
  if (!t) fail(where, "expected a table {key, from, to, criterion, resolution}, got " + toml_value_text(node));
  static const char* const allowed[] = {"key", "from", "to", "criterion", "resolution", "per_decade"};
  for (auto&& [k, v] : *t) {
    (void)v;
    const std::string name(k.str());
    if (std::none_of(std::begin(allowed), std::end(allowed), [&](const char* a) { return name == a; }))
      fail(where + "." + name, "unknown key (expected one of: key, from, to, criterion, resolution, per_decade)");
  }
  const auto number = [&](const char* name, bool required, double fallback) {
    const toml::node* n = t->get(name);
    const std::string k = where + "." + name;
    if (!n) {
      if (required) fail(k, "missing (required)");
      return fallback;
    }
    double v = 0;
    if (const auto* f = n->as_floating_point())
      v = f->get();
    else if (const auto* i = n->as_integer())
      v = static_cast<double>(i->get());
    else
      fail(k, "expected a number, got " + toml_value_text(*n));
    if (!std::isfinite(v)) fail(k, "must be a finite number, got " + shortest(v));
    return v;
  };
  const auto string = [&](const char* name) {
    const toml::node* n = t->get(name);
    const std::string k = where + "." + name;
    if (!n) fail(k, "missing (required)");
    const auto* s = n->as_string();
    if (!s) fail(k, "expected a string, got " + toml_value_text(*n));
    return trim(s->get());
  };
  SweepSearch s;
  key = string("key");
  s.from = number("from", true, 0);
  s.to = number("to", true, 0);
  s.integer = t->get("from")->is_integer() && t->get("to")->is_integer();
  if (!(s.from > 0)) fail(where + ".from", shortest(s.from) + " is out of range (expected from > 0: the search is in log10)");
  if (!(s.to > s.from)) fail(where + ".to", shortest(s.to) + " is out of range (expected to > from = " + shortest(s.from) + ")");
  if (std::log10(s.to / s.from) > kMaxSearchDecades)
    fail(where + ".to", shortest(s.to) + " is more than " + shortest(kMaxSearchDecades) + " decades above from = " + shortest(s.from));
  s.criterion = string("criterion");
  try {
    parse_criterion(s.criterion);
  } catch (const std::invalid_argument& e) {
    fail(where + ".criterion", e.what());
  }
  s.resolution = number("resolution", false, s.resolution);
  if (!(s.resolution >= kMinSearchResolution && s.resolution <= kMaxSearchResolution))
    fail(where + ".resolution", shortest(s.resolution) + " is out of range (expected " + shortest(kMinSearchResolution) +
                                    " <= resolution <= " + shortest(kMaxSearchResolution) + ", in log10 units)");
  if (const toml::node* n = t->get("per_decade")) {
    const auto* i = n->as_integer();
    const std::string range = "1 <= per_decade <= " + std::to_string(kMaxSearchPerDecade);
    if (!i) fail(where + ".per_decade", "expected an integer (" + range + "), got " + toml_value_text(*n));
    if (i->get() < 1 || i->get() > kMaxSearchPerDecade)
      fail(where + ".per_decade", std::to_string(i->get()) + " is out of range (expected " + range + ")");
    s.per_decade = static_cast<int>(i->get());
  }
  return s;
}


// ---- the search, replayed ---------------------------------------------------------------------

double search_round(double v) {
  char buf[40];
  std::snprintf(buf, sizeof buf, "%.6g", v);
  return std::strtod(buf, nullptr);
}

std::string search_value_text(double v) {
  // A whole number as an integer (an iteration count must be one); 1e15 keeps it exact.
  if (v == std::floor(v) && std::abs(v) < 1e15) return std::to_string(static_cast<long long>(v));
  return json(v).dump();
}

std::vector<double> search_coarse_grid(const SweepSearch& s) {
  const double lf = std::log10(s.from), lt = std::log10(s.to);
  // 1e-9: a range of exactly k decades is k * per_decade steps, not one more.
  const int n = std::max(1, static_cast<int>(std::ceil((lt - lf) * s.per_decade - 1e-9)));
  std::vector<double> v;
  for (int k = 0; k <= n; ++k) {
    const double x = std::pow(10.0, lf + (lt - lf) * k / n);
    const double value = k == 0 ? s.from : k == n ? s.to : s.integer ? std::round(x) : search_round(x);
    if (v.empty() || value > v.back()) v.push_back(value);  // integers: 1, 2, 2, 3 runs 2 once
  }
  return v;
}

bool SearchReplay::coarse_complete() const {
  return std::all_of(coarse_passes.begin(), coarse_passes.end(), [](const auto& p) { return p.has_value(); });
}

SearchReplay replay_search(const SweepSearch& s, const std::function<std::optional<bool>(const std::string&)>& outcome) {
  SearchReplay r;
  r.coarse = search_coarse_grid(s);
  const long long n = static_cast<long long>(r.coarse.size());
  for (long long k = 0; k < n; ++k) {
    const double v = r.coarse[static_cast<size_t>(k)];
    r.coarse_passes.push_back(outcome(search_value_text(v)));
    (r.coarse_passes.back() ? r.known : r.next).push_back({v, k});
  }
  if (!r.coarse_complete()) return r;
  // Every crossing on the coarse grid is bisected, not only the first: a criterion that comes and
  // goes is reported with each of its boundaries located, and the cost is one bisection per
  // crossing (brackets are independent, so one wave runs a step of each).
  long long bracket = 0;
  for (size_t k = 0; k + 1 < r.coarse.size(); ++k) {
    if (*r.coarse_passes[k] == *r.coarse_passes[k + 1]) continue;
    SearchCrossing c;
    c.lo = r.coarse[k];
    c.hi = r.coarse[k + 1];
    c.lo_passes = *r.coarse_passes[k];
    while (std::log10(c.hi / c.lo) >= s.resolution) {
      const double x = std::pow(10.0, 0.5 * (std::log10(c.lo) + std::log10(c.hi)));
      const double mid = s.integer ? std::round(x) : search_round(x);
      // Neighbouring integers (or 6 digits, which resolution >= 1e-3 keeps away) cannot be split.
      if (!(mid > c.lo && mid < c.hi)) break;
      const long long index = n + bracket * kSearchIndexStride + static_cast<long long>(c.steps);
      const std::optional<bool> o = outcome(search_value_text(mid));
      if (!o) {
        r.next.push_back({mid, index});
        break;
      }
      r.known.push_back({mid, index});
      ++c.steps;
      (*o == c.lo_passes ? c.lo : c.hi) = mid;
    }
    c.resolved = std::log10(c.hi / c.lo) < s.resolution || (s.integer && c.hi - c.lo <= 1);
    r.crossings.push_back(c);
    ++bracket;
  }
  return r;
}

// ---- planning waves ---------------------------------------------------------------------------

bool has_search(const SweepPlan& plan) {
  return std::any_of(plan.spec.setups.begin(), plan.spec.setups.end(), [](const SweepSetup& s) { return s.search.has_value(); });
}

namespace {

std::string point_id_of(const SweepPlan& plan, size_t scene, const SweepSetup& setup, size_t grid,
                        const std::string& text) {
  return setup.has_grid() ? sweep_point_id(plan.physics_hashes[scene], setup, text, plan.spec.repeats, setup.grid_texts[grid])
                          : sweep_point_id(plan.physics_hashes[scene], setup, text, plan.spec.repeats);
}

}  // namespace

std::vector<SearchPoint> search_frontier(const SweepPlan& plan, const std::vector<SweepRecord>& records) {
  std::map<std::string, const SweepRecord*> by_id;
  for (const SweepRecord& r : records) by_id.emplace(r.point_id, &r);  // the first counts, as in the report
  std::set<std::string> in_plan;
  for (const SweepPoint& p : plan.points) in_plan.insert(p.id);
  std::vector<SearchPoint> out;
  for (size_t i = 0; i < plan.scenes.size(); ++i)
    for (size_t u = 0; u < plan.spec.setups.size(); ++u) {
      const SweepSetup& setup = plan.spec.setups[u];
      if (!setup.search || !setup.runs_on(plan.scenes[i].name)) continue;
      const SearchCriterion crit = parse_criterion(setup.search->criterion);
      const size_t grids = setup.has_grid() ? setup.grid_values.size() : 1;
      for (size_t g = 0; g < grids; ++g) {
        const auto outcome = [&](const std::string& text) -> std::optional<bool> {
          const auto it = by_id.find(point_id_of(plan, i, setup, g, text));
          if (it == by_id.end()) return std::nullopt;
          return criterion_passes(crit, *it->second);
        };
        const SearchReplay rp = replay_search(*setup.search, outcome);
        for (const auto* steps : {&rp.known, &rp.next})
          for (const SearchStep& st : *steps) {
            if (st.ladder_index < static_cast<long long>(rp.coarse.size())) continue;  // planned up front
            if (in_plan.count(point_id_of(plan, i, setup, g, search_value_text(st.value)))) continue;
            out.push_back({i, u, g, st.ladder_index, st.value});
          }
      }
    }
  return out;
}

void add_search_points(SweepPlan& plan, const std::vector<SearchPoint>& points) {
  for (const SearchPoint& sp : points) {
    const SweepSetup& setup = plan.spec.setups.at(sp.setup_index);
    const std::string& file = plan.spec.scenes.at(sp.scene_index).path;
    std::vector<std::string> over = plan.scene_overrides.at(sp.scene_index);
    over.insert(over.end(), setup.set.begin(), setup.set.end());
    SweepPoint p;
    p.scene_index = sp.scene_index;
    p.setup_index = sp.setup_index;
    p.grid_index = sp.grid_index;
    p.ladder_index = static_cast<size_t>(sp.ladder_index);
    p.ladder_value = sp.value;
    p.ladder_text = p.ladder_label = search_value_text(sp.value);
    over.push_back(setup.ladder_key + "=" + p.ladder_text);
    if (setup.has_grid()) over.push_back(setup.grid_key + "=" + setup.grid_texts.at(sp.grid_index));
    try {
      p.scene = load_scene(file, over);
    } catch (const SceneError& e) {
      // The coarse grid's values loaded; a value between two of them that does not is the engine's limit.
      throw std::runtime_error(plan.spec.file + ": setup[" + std::to_string(sp.setup_index) +
                               "].ladder.search: the bisection's value " + p.ladder_text + " does not load: " + e.what());
    }
    p.id = point_id_of(plan, sp.scene_index, setup, sp.grid_index, p.ladder_text);
    plan.points.push_back(std::move(p));
  }
}

std::string encode_search_points(const std::vector<SearchPoint>& points) {
  std::ostringstream ss;
  ss << points.size() << '\n';
  for (const SearchPoint& p : points)
    ss << p.scene_index << ' ' << p.setup_index << ' ' << p.grid_index << ' ' << p.ladder_index << ' '
       << search_value_text(p.value) << '\n';
  return ss.str();
}

std::vector<SearchPoint> decode_search_points(const std::string& text) {
  std::istringstream ss(text);
  size_t n = 0;
  ss >> n;
  std::vector<SearchPoint> out;
  for (size_t k = 0; k < n && ss; ++k) {
    SearchPoint p;
    std::string value;
    ss >> p.scene_index >> p.setup_index >> p.grid_index >> p.ladder_index >> value;
    p.value = std::strtod(value.c_str(), nullptr);
    out.push_back(p);
  }
  if (!ss || out.size() != n) throw std::runtime_error("MPI: the coordinator's search wave message is cut short");
  return out;
}

size_t extend_search_plan(SweepPlan& plan, const std::vector<SweepRecord>& records) {
  size_t added = 0;
  for (;;) {
    const std::vector<SearchPoint> f = search_frontier(plan, records);
    if (f.empty()) return added;
    add_search_points(plan, f);
    added += f.size();
  }
}

// ---- boundaries -------------------------------------------------------------------------------

std::string boundary_quantity(const std::string& key) {
  const std::string last = key.substr(key.rfind('.') == std::string::npos ? 0 : key.rfind('.') + 1);
  return (larger_is_softer(key) ? "max_safe_" : "min_safe_") + last;
}

std::vector<SearchBoundary> search_boundaries(const std::vector<SweepRecord>& records) {
  std::map<std::tuple<long long, long long, long long>, std::vector<const SweepRecord*>> groups;
  for (const SweepRecord& r : records)
    if (r.search) groups[{r.scene_index, r.setup_index, r.grid_index}].push_back(&r);
  std::vector<SearchBoundary> out;
  for (const auto& [unit, rs] : groups) {
    const SweepRecord& f = *rs.front();
    SearchBoundary b;
    b.scene = f.scene;
    b.setup = f.setup;
    b.engine = f.engine;
    b.key = f.ladder_key;
    b.grid_key = f.grid_key;
    b.grid_label = f.grid_label;
    b.criterion = f.search->criterion;
    b.scene_index = f.scene_index;
    b.setup_index = f.setup_index;
    b.grid_index = f.grid_index;
    b.search = *f.search;
    b.quantity = boundary_quantity(b.key);
    std::map<std::string, const SweepRecord*> by_label;
    for (const SweepRecord* r : rs) by_label.emplace(r->ladder_label, r);
    b.runs = by_label.size();
    const SearchCriterion crit = parse_criterion(b.criterion);
    b.replay = replay_search(b.search, [&](const std::string& text) -> std::optional<bool> {
      const auto it = by_label.find(text);
      if (it == by_label.end()) return std::nullopt;
      return criterion_passes(crit, *it->second);
    });
    const SearchReplay& rp = b.replay;
    const Threshold* only = crit.only_bound();
    const bool about_inversion = (only && only->metric.rfind("inversion_time", 0) == 0) ||
                                 (!crit.regime && crit.inversion && crit.bounds.empty());
    const bool about_stem = only && only->metric.rfind("stem_contact_time", 0) == 0;
    const bool larger = larger_is_softer(b.key);
    if (about_inversion && std::none_of(rs.begin(), rs.end(), [](const SweepRecord* r) { return r->reference_inversion_time.has_value(); })) {
      b.status = "not_applicable";
    } else if (about_stem && std::none_of(rs.begin(), rs.end(), [](const SweepRecord* r) { return r->reference_stem_contact_time.has_value(); })) {
      b.status = "not_applicable";
    } else if (!rp.finished() || !rp.coarse_complete()) {
      b.status = "incomplete";
    } else {
      // The finest end is the smallest value of a key whose larger values are softer.
      const bool finest_passes = *(larger ? rp.coarse_passes.front() : rp.coarse_passes.back());
      if (!finest_passes) {
        b.status = "none_safe";
      } else if (rp.crossings.empty()) {
        b.status = "all_safe";
        b.boundary = larger ? rp.coarse.back() : rp.coarse.front();
      } else {
        b.status = "found";
        const SearchCrossing& c = larger ? rp.crossings.front() : rp.crossings.back();
        b.boundary = larger ? c.lo : c.hi;
        b.beyond = larger ? c.hi : c.lo;
      }
      if (b.boundary) {
        const auto it = by_label.find(search_value_text(*b.boundary));
        if (it != by_label.end()) b.cpu_seconds = it->second->cpu_seconds;
      }
    }
    out.push_back(std::move(b));
  }
  return out;
}

}  // namespace tippe
