// The metrics of one engine's run against the reference, a pure function of two trajectories and their records.
#include "harness/measure/metrics.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <filesystem>
#include <limits>
#include <set>
#include <string>
#include <vector>
#include "harness/io/json_fields.h"
#include "harness/measure/event_alignment.h"

namespace tippe {

namespace fs = std::filesystem;
using nlohmann::json;

namespace {

// Accumulates |difference| over the common grid.
struct ErrorStats {
  double sum_sq = 0, max = 0;
  long long n = 0;
  void add(double e) {
    if (!std::isfinite(e)) return;
    sum_sq += e * e;
    max = std::max(max, std::abs(e));
    ++n;
  }
  double rms() const { return n ? std::sqrt(sum_sq / static_cast<double>(n)) : kNaN; }
  double maximum() const { return n ? max : kNaN; }
};

// Every per-sample column but t and surface, for code that treats them alike.
template <class T>
auto sampled_columns(T& tr) {
  return std::array{&tr.theta, &tr.energy,  &tr.jellett, &tr.normal_force, &tr.slip_speed,
                    &tr.contact_latitude, &tr.x_C, &tr.y_C, &tr.x_G, &tr.y_G};
}

// The engine's columns on the reference's times ref.t[offset + k], as far as both runs go.
Trajectory engine_on_reference_grid(const Trajectory& ref, const Trajectory& eng, double dt, size_t& offset) {
  offset = 0;
  const size_t n = std::min(ref.size(), eng.size());
  bool aligned = true;
  for (size_t k = 0; k < n && aligned; ++k) aligned = std::abs(ref.t[k] - eng.t[k]) <= 0.5 * dt;
  Trajectory out;
  const auto from = sampled_columns(eng);
  const auto to = sampled_columns(out);
  if (aligned) {
    out.t.assign(ref.t.begin(), ref.t.begin() + static_cast<std::ptrdiff_t>(n));
    out.surface.assign(eng.surface.begin(), eng.surface.begin() + static_cast<std::ptrdiff_t>(n));
    for (size_t c = 0; c < from.size(); ++c)
      to[c]->assign(from[c]->begin(), from[c]->begin() + static_cast<std::ptrdiff_t>(n));
    return out;
  }
  // Different grids (an engine that stopped between grid points, or a run sampled differently):
  // linear interpolation between the engine's samples that bracket each reference time.
  if (eng.size() == 0) return out;
  size_t j = 0;
  for (size_t k = 0; k < ref.size(); ++k) {
    const double t = ref.t[k];
    if (t < eng.t.front() - 1e-12 * std::max(1.0, std::abs(t))) {
      offset = k + 1;
      continue;
    }
    if (t > eng.t.back() + 1e-12 * std::max(1.0, std::abs(t))) break;
    while (j + 1 < eng.size() && eng.t[j + 1] < t) ++j;
    const size_t j1 = std::min(j + 1, eng.size() - 1);
    const double span = eng.t[j1] - eng.t[j];
    const double w = span > 0 ? std::clamp((t - eng.t[j]) / span, 0.0, 1.0) : 0.0;
    out.t.push_back(t);
    out.surface.push_back(w < 0.5 ? eng.surface[j] : eng.surface[j1]);
    for (size_t c = 0; c < from.size(); ++c) to[c]->push_back((1 - w) * (*from[c])[j] + w * (*from[c])[j1]);
  }
  return out;
}

void compare_event(const std::optional<double>& t_ref, const std::optional<double>& t_eng, std::string& which,
                   std::optional<double>& abs_error, std::optional<double>& rel_error) {
  which = t_ref && t_eng ? "both" : t_eng ? "engine_only" : t_ref ? "reference_only" : "neither";
  if (!(t_ref && t_eng)) return;
  abs_error = *t_eng - *t_ref;
  if (*t_ref != 0.0) rel_error = *abs_error / *t_ref;
}

}  // namespace

// ---- metrics --------------------------------------------------------------------------------

bool energy_must_not_rise(const Scene& scene) {
  const ContactSpec& c = scene.contact;
  if (c.friction == FrictionLaw::None) return false;
  if (c.drilling > 0) return true;
  // A law whose coefficient is zero removes nothing: rises there are noise, not injected energy.
  return (c.friction == FrictionLaw::Viscous && c.k > 0) || (c.friction == FrictionLaw::Coulomb && c.mu > 0) ||
         (c.friction == FrictionLaw::Gliding && c.mu > 0);
}

double contact_energy_allowance(const Scene& scene) {
  const double a = scene.mass.mass * scene.gravity * kContactDepthResolution * scene.body.sphere_radius;
  return std::isfinite(a) && a > 0 ? a : 0.0;
}

const char* to_string(EnergyGainRule r) { return energy_gain_rule_names().at(static_cast<size_t>(r)).c_str(); }

std::string energy_counted_text(EnergyGainRule r) {
  switch (r) {
    case EnergyGainRule::Stored:
      return "E plus the elastic energy the contact stores where the engine's contact law gives it";
    case EnergyGainRule::Total:
      return "E itself";
    case EnergyGainRule::Ledger:
      return "the energy the run's ledger says was created";
  }
  return "E itself";
}

EnergyGainRule energy_gain_rule(const Scene& scene) {
  // A name the scene reader did not check (a scene built in code) counts as the default.
  const std::vector<std::string>& names = energy_gain_rule_names();
  const auto it = std::find(names.begin(), names.end(), scene.run.energy_gain_rule);
  return it == names.end() ? kDefaultEnergyGainRule : static_cast<EnergyGainRule>(it - names.begin());
}

bool has_elastic_store(const Trajectory& tr) {
  return tr.elastic_energy.size() == tr.size() && tr.size() > 0 && std::isfinite(tr.elastic_energy[0]);
}

std::vector<double> energy_counted(const Trajectory& tr, EnergyGainRule rule) {
  if (rule == EnergyGainRule::Stored) {
    // E + U - U0 where the run has a store from its first sample on; a later sample without one
    // (a divergence) counts E alone.
    if (!has_elastic_store(tr)) return tr.energy;
    std::vector<double> c(tr.energy);
    const double u0 = tr.elastic_energy[0];
    for (size_t k = 0; k < tr.size(); ++k)
      if (std::isfinite(tr.elastic_energy[k])) c[k] += tr.elastic_energy[k] - u0;
    return c;
  }
  if (rule == EnergyGainRule::Total || tr.numerical_energy.size() != tr.size()) return tr.energy;
  std::vector<double> c(tr.size());
  const double e0 = tr.size() ? tr.energy[0] : 0.0;
  const bool store = tr.elastic_energy.size() == tr.size() && tr.normal_work.size() == tr.size();
  const double u0 = store && has_elastic_store(tr) ? tr.elastic_energy[0] : 0.0;
  for (size_t k = 0; k < tr.size(); ++k) {
    const double n = tr.numerical_energy[k];
    if (!std::isfinite(n)) {
      c[k] = tr.energy[k];  // no ledger at this sample: the total
      continue;
    }
    // With the elastic energy: C = N + (normal work + U - U0), the part of the normal force's
    // work its store does not explain; without: N.
    const double u = store ? tr.elastic_energy[k] : kNaN, wn = store ? tr.normal_work[k] : kNaN;
    c[k] = e0 + n + (std::isfinite(u) && std::isfinite(wn) ? wn + u - u0 : 0.0);
  }
  return c;
}

EnergyGains energy_gains(const Trajectory& tr, double allowance, EnergyGainRule rule) {
  EnergyGains g;
  if (tr.size() < 2) return g;
  const std::vector<double> energy = energy_counted(tr, rule);
  const double e0 = std::abs(energy[0]);
  const double scale = e0 > 0 ? e0 : 1.0;
  const double threshold = kEnergyGainTolerance * scale + allowance;
  g.tolerance = threshold / scale;
  double low = energy[0], low_t = tr.t[0];
  bool above = false;
  for (size_t k = 1; k < tr.size(); ++k) {
    const double e = energy[k];
    if (!std::isfinite(e)) break;  // a divergence, which the class reports on its own
    const double rise = e - low;
    if (rise > threshold) {
      if (!above) {
        ++g.events;
        if (g.events == 1) {
          g.time = tr.t[k];
          g.since = low_t;
          g.rise_at_first = rise / scale;
        }
      }
      above = true;
      g.max_rise = std::max(g.max_rise, rise / scale);
    } else {
      above = false;
    }
    if (e < low) {
      low = e;
      low_t = tr.t[k];
    }
  }
  return g;
}

std::optional<double> friction_work_where_reference_sticks(const std::vector<Event>& reference_events,
                                                          const Trajectory& engine, double until) {
  // What ends a stick: the slip starting again, or the contact set changing under it.
  static const std::set<std::string> ends = {"slip",        "lift",   "flight",      "touchdown",
                                             "two_contact", "impact", "stem_contact", "switch"};
  std::vector<Event> events = reference_events;
  std::stable_sort(events.begin(), events.end(), [](const Event& a, const Event& b) { return a.time < b.time; });
  std::vector<std::pair<double, double>> sticks;
  std::optional<double> from;
  for (const Event& e : events) {
    if (e.time > until) break;
    if (e.name == "stick") {
      if (!from) from = e.time;
    } else if (from && ends.count(e.name)) {
      sticks.emplace_back(*from, e.time);
      from.reset();
    }
  }
  if (from) sticks.emplace_back(*from, until);
  if (sticks.empty() || engine.t.size() < 2 || engine.friction_work.size() != engine.t.size()) return std::nullopt;
  // Each sample interval's work in the share of it that lies in a stick (linear within the
  // interval: the stick's ends fall between samples).
  double work = 0.0;
  size_t j = 0;
  for (size_t k = 1; k < engine.t.size(); ++k) {
    const double a = engine.t[k - 1], b = engine.t[k];
    while (j < sticks.size() && sticks[j].second <= a) ++j;
    if (j == sticks.size()) break;
    if (!(b > a)) continue;
    double inside = 0.0;
    for (size_t i = j; i < sticks.size() && sticks[i].first < b; ++i)
      inside += std::max(0.0, std::min(b, sticks[i].second) - std::max(a, sticks[i].first));
    if (inside > 0) work += (engine.friction_work[k] - engine.friction_work[k - 1]) * std::min(1.0, inside / (b - a));
  }
  if (!std::isfinite(work)) return std::nullopt;
  return work;
}

Metrics compare_runs(const RunRecord& reference, const Trajectory& ref_traj, const RunRecord& engine,
                     const Trajectory& engine_traj, const Scene& scene, std::optional<double> converged_until) {
  Metrics m;
  m.reference_converged_until = converged_until;
  // Inside the window: the reference's event when it has one, else the engine's (a converged
  // reference could have the event later); an event neither has is not known past the window.
  auto judged = [&](const std::optional<double>& t_ref, const std::optional<double>& t_eng) {
    if (!converged_until) return true;
    if (t_ref) return *t_ref <= *converged_until;
    return t_eng && *t_eng <= *converged_until;
  };
  if (judged(reference.inversion_time, engine.inversion_time))
    compare_event(reference.inversion_time, engine.inversion_time, m.inversion_event, m.inversion_time_abs_error,
                  m.inversion_time_rel_error);
  else
    m.inversion_event = "unconverged";
  if (judged(reference.stem_contact_time, engine.stem_contact_time))
    compare_event(reference.stem_contact_time, engine.stem_contact_time, m.stem_contact_event,
                  m.stem_contact_time_abs_error, m.stem_contact_time_rel_error);
  else
    m.stem_contact_event = "unconverged";

  {
    // The event sequences, aligned over the reference's converged window (all of it when
    // unchecked). The dwell is a time of the top's own scale (event_alignment.h); a scene without
    // one (synthetic) merges nothing.
    const double scale = std::sqrt(scene.body.sphere_radius / scene.gravity);
    const double dwell = std::isfinite(scale) && scale > 0 ? kEventMinDwellFraction * scale : 0.0;
    const double until = converged_until ? *converged_until : std::numeric_limits<double>::infinity();
    const CanonicalSequence ref_seq = canonical_events(reference.events, dwell, until);
    const CanonicalSequence eng_seq = canonical_events(engine.events, dwell, until);
    const EventAlignment a = align_events(ref_seq.events, eng_seq.events);
    m.events_reference = static_cast<long long>(a.reference.size());
    m.events_engine = static_cast<long long>(a.engine.size());
    m.events_matched = a.matched;
    m.events_missing = a.missing;
    m.events_extra = a.extra;
    m.event_time_max_error = a.time_max_error;
    if (a.first_wrong) m.first_wrong_event_index = static_cast<long long>(*a.first_wrong);
    m.first_wrong_event = a.first_wrong_text;
    m.events_not_compared = not_compared_text(ref_seq, eng_seq);
    m.event_min_dwell = dwell;
    m.event_alignment_rows = static_cast<long long>(a.pairs.size());
    for (size_t k = 0; k < a.pairs.size() && k < kMaxAlignedEventRowsKept; ++k) {
      const AlignedPair& p = a.pairs[k];
      AlignedEventRow row;
      row.op = to_string(p.op);
      if (p.reference) row.reference_kind = a.reference[*p.reference].kind, row.reference_time = a.reference[*p.reference].time;
      if (p.engine) row.engine_kind = a.engine[*p.engine].kind, row.engine_time = a.engine[*p.engine].time;
      m.event_alignment.push_back(std::move(row));
    }
  }

  const double R = scene.body.sphere_radius;
  const double E0_ref = ref_traj.size() ? ref_traj.energy.front() : reference.energy_initial;
  // Guards against a scene whose energy origin makes E0 = 0: errors are then absolute.
  const double e_scale = std::isfinite(E0_ref) && E0_ref != 0.0 ? std::abs(E0_ref) : 1.0;

  size_t offset = 0;
  const Trajectory eng = engine_on_reference_grid(ref_traj, engine_traj, scene.run.sample_interval, offset);
  ErrorStats tilt, energy, contact, com, latitude;
  size_t compared = 0;
  for (size_t k = 0; k < eng.size(); ++k) {
    const size_t r = offset + k;
    if (converged_until && ref_traj.t[r] > *converged_until) break;
    compared = k + 1;
    tilt.add(eng.theta[k] - ref_traj.theta[r]);
    energy.add((eng.energy[k] - ref_traj.energy[r]) / e_scale);
    contact.add(std::hypot(eng.x_C[k] - ref_traj.x_C[r], eng.y_C[k] - ref_traj.y_C[r]) / R);
    com.add(std::hypot(eng.x_G[k] - ref_traj.x_G[r], eng.y_G[k] - ref_traj.y_G[r]) / R);
    latitude.add(eng.contact_latitude[k] - ref_traj.contact_latitude[r]);
  }
  m.tilt_max_error = tilt.maximum();
  m.tilt_rms_error = tilt.rms();
  m.energy_max_error = energy.maximum();
  m.contact_path_rms_error = contact.rms();
  m.contact_path_max_error = contact.maximum();
  m.com_path_rms_error = com.rms();
  m.com_path_max_error = com.maximum();
  m.latitude_rms_error = latitude.rms();
  m.compared_until = compared ? eng.t[compared - 1] : kNaN;

  if (engine_traj.size()) {
    const double E0 = engine_traj.energy.front();
    m.energy_final_ratio = engine_traj.energy.back() / E0;
    m.energy_gain_rule = to_string(energy_gain_rule(scene));
    if (energy_must_not_rise(scene)) {
      const EnergyGains g = energy_gains(engine_traj, contact_energy_allowance(scene), energy_gain_rule(scene));
      m.energy_gain_events = g.events;
      m.energy_max_gain = g.events ? g.max_rise : 0.0;
    }
  } else {
    m.energy_final_ratio = kNaN;
  }

  // The ledger's totals, / |E0| of the engine's run (absolute when E0 = 0).
  const double e_run = std::isfinite(engine.energy_initial) && engine.energy_initial != 0 ? std::abs(engine.energy_initial) : 1.0;
  auto ledger = [&](double v) -> std::optional<double> {
    if (!std::isfinite(v)) return std::nullopt;
    return v / e_run;
  };
  m.normal_work = ledger(engine.normal_work);
  m.friction_work = ledger(engine.friction_work);
  if (const auto w = friction_work_where_reference_sticks(
          reference.events, engine_traj, converged_until ? *converged_until : std::numeric_limits<double>::infinity()))
    m.friction_work_reference_sticks = ledger(*w);
  m.drilling_work = ledger(engine.drilling_work);
  m.impact_energy = ledger(engine.impact_energy);
  m.elastic_energy_max = ledger(engine.elastic_energy_max);
  m.numerical_energy_max = ledger(engine.numerical_energy_max);
  m.numerical_energy_final = ledger(engine.numerical_energy_final);
  m.jellett_drift_ball = engine.jellett_drift_ball;
  m.jellett_drift_stem = engine.jellett_drift_stem;
  m.jellett_max_relative_drift = engine.jellett_max_relative_drift;
  m.wall_seconds = engine.work.wall_seconds;
  m.cpu_seconds = engine.work.cpu_seconds;
  m.steps = engine.work.steps;
  m.real_time_factor = engine.work.wall_seconds > 0 && std::isfinite(engine.final_time)
                           ? engine.final_time / engine.work.wall_seconds
                           : 0.0;
  const double ref_cpu = reference.work.cpu_seconds;
  m.cost_ratio = ref_cpu > 0 && std::isfinite(engine.work.cpu_seconds) ? engine.work.cpu_seconds / ref_cpu : 0.0;
  return m;
}

}  // namespace tippe
