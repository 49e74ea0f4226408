// Side-by-side runs of the reference and engines on one scene, the metrics that compare them, and their records.
#include "compare.h"
#include "progress.h"

#include <algorithm>
#include <array>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <exception>
#include <functional>
#include <filesystem>
#include <fstream>
#include <limits>
#include <memory>
#include <mutex>
#include <set>
#include <sstream>
#include <stdexcept>
#include <unistd.h>

#include "adapters.h"
#include "interrupt.h"
#include "mass_properties.h"
#include "provenance.h"
#include "report/report.h"
#include "scene_io.h"
#include "task_farm.h"

namespace tippe {

namespace {

namespace fs = std::filesystem;
using nlohmann::json;

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

json number(double v) { return std::isfinite(v) ? json(v) : json(nullptr); }
json number(const std::optional<double>& v) { return v ? number(*v) : json(nullptr); }

double get_number(const json& j, const char* key) {
  const json& v = j.at(key);
  return v.is_null() ? kNaN : v.get<double>();
}

std::optional<double> get_optional(const json& j, const char* key) {
  const json& v = j.at(key);
  if (v.is_null()) return std::nullopt;
  return v.get<double>();
}

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

// ---- trajectories ---------------------------------------------------------------------------

Trajectory Trajectory::from_csv(const CsvTrajectory& csv) {
  Trajectory tr;
  tr.t = csv.column("t");
  tr.theta = csv.column("theta");
  tr.energy = csv.column("energy");
  tr.jellett = csv.column("jellett");
  tr.normal_force = csv.column("normal_force");
  tr.slip_speed = csv.column("slip_speed");
  tr.contact_latitude = csv.column("contact_latitude");
  tr.x_C = csv.column("x_C");
  tr.y_C = csv.column("y_C");
  tr.x_G = csv.column("x_G");
  tr.y_G = csv.column("y_G");
  tr.surface = csv.surface;
  return tr;
}

void Trajectory::append(const Observation& o) {
  t.push_back(o.state.t);
  theta.push_back(o.theta);
  energy.push_back(o.energy);
  jellett.push_back(o.jellett);
  normal_force.push_back(o.normal_force);
  slip_speed.push_back(o.slip_speed);
  contact_latitude.push_back(o.contact_latitude);
  x_C.push_back(o.p_WC.x());
  y_C.push_back(o.p_WC.y());
  x_G.push_back(o.state.p_WG.x());
  y_G.push_back(o.state.p_WG.y());
  surface.push_back(static_cast<int>(o.surface));
}

void TrajectorySink::write(const Observation& o) {
  trajectory.append(o);
  for (SampleSink* s : next_) s->write(o);
}

// ---- metrics --------------------------------------------------------------------------------

bool energy_must_not_rise(const Scene& scene) {
  const ContactSpec& c = scene.contact;
  if (c.friction == FrictionLaw::None) return false;
  if (c.drilling > 0) return true;
  // A law whose coefficient is zero removes nothing: rises there are noise, not injected energy.
  return (c.friction == FrictionLaw::Viscous && c.k > 0) || (c.friction == FrictionLaw::Coulomb && c.mu > 0) ||
         (c.friction == FrictionLaw::Gliding && c.mu > 0);
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
    if (energy_must_not_rise(scene)) {
      const double threshold = kEnergyGainTolerance * std::abs(E0);
      for (size_t k = 1; k < engine_traj.size(); ++k) {
        const double rise = engine_traj.energy[k] - engine_traj.energy[k - 1];
        if (rise > threshold) {
          ++m.energy_gain_events;
          m.energy_max_gain = std::max(m.energy_max_gain, rise / std::abs(E0));
        }
      }
    }
  } else {
    m.energy_final_ratio = kNaN;
  }

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

json to_json(const Metrics& m) {
  return json{
      {"inversion_event", m.inversion_event},
      {"inversion_time_abs_error", number(m.inversion_time_abs_error)},
      {"inversion_time_rel_error", number(m.inversion_time_rel_error)},
      {"stem_contact_event", m.stem_contact_event},
      {"stem_contact_time_abs_error", number(m.stem_contact_time_abs_error)},
      {"stem_contact_time_rel_error", number(m.stem_contact_time_rel_error)},
      {"tilt_max_error", number(m.tilt_max_error)},
      {"tilt_rms_error", number(m.tilt_rms_error)},
      {"energy_max_error", number(m.energy_max_error)},
      {"energy_final_ratio", number(m.energy_final_ratio)},
      {"energy_gain_events", m.energy_gain_events},
      {"energy_max_gain", number(m.energy_max_gain)},
      {"contact_path_rms_error", number(m.contact_path_rms_error)},
      {"contact_path_max_error", number(m.contact_path_max_error)},
      {"com_path_rms_error", number(m.com_path_rms_error)},
      {"com_path_max_error", number(m.com_path_max_error)},
      {"latitude_rms_error", number(m.latitude_rms_error)},
      {"jellett_drift_ball", number(m.jellett_drift_ball)},
      {"jellett_drift_stem", number(m.jellett_drift_stem)},
      {"jellett_max_relative_drift", number(m.jellett_max_relative_drift)},
      {"wall_seconds", number(m.wall_seconds)},
      {"cpu_seconds", number(m.cpu_seconds)},
      {"real_time_factor", number(m.real_time_factor)},
      {"steps", m.steps},
      {"cost_ratio", number(m.cost_ratio)},
      {"compared_until", number(m.compared_until)},
      {"reference_converged_until", number(m.reference_converged_until)},
  };
}

Metrics metrics_from_json(const json& j) {
  Metrics m;
  m.inversion_event = j.at("inversion_event").get<std::string>();
  m.inversion_time_abs_error = get_optional(j, "inversion_time_abs_error");
  m.inversion_time_rel_error = get_optional(j, "inversion_time_rel_error");
  m.stem_contact_event = j.at("stem_contact_event").get<std::string>();
  m.stem_contact_time_abs_error = get_optional(j, "stem_contact_time_abs_error");
  m.stem_contact_time_rel_error = get_optional(j, "stem_contact_time_rel_error");
  m.tilt_max_error = get_number(j, "tilt_max_error");
  m.tilt_rms_error = get_number(j, "tilt_rms_error");
  m.energy_max_error = get_number(j, "energy_max_error");
  m.energy_final_ratio = get_number(j, "energy_final_ratio");
  m.energy_gain_events = json_integer(j, "energy_gain_events");
  m.energy_max_gain = get_number(j, "energy_max_gain");
  m.contact_path_rms_error = get_number(j, "contact_path_rms_error");
  m.contact_path_max_error = get_number(j, "contact_path_max_error");
  m.com_path_rms_error = get_number(j, "com_path_rms_error");
  m.com_path_max_error = get_number(j, "com_path_max_error");
  m.latitude_rms_error = get_number(j, "latitude_rms_error");
  m.jellett_drift_ball = get_optional(j, "jellett_drift_ball");
  m.jellett_drift_stem = get_optional(j, "jellett_drift_stem");
  m.jellett_max_relative_drift = get_number(j, "jellett_max_relative_drift");
  m.wall_seconds = get_number(j, "wall_seconds");
  m.cpu_seconds = get_number(j, "cpu_seconds");
  m.real_time_factor = get_number(j, "real_time_factor");
  m.steps = json_integer(j, "steps");
  m.cost_ratio = get_number(j, "cost_ratio");
  m.compared_until = get_number(j, "compared_until");
  // Absent in records written before the reference's self-check.
  if (j.contains("reference_converged_until")) {
    const json& v = j.at("reference_converged_until");
    if (!v.is_null()) {
      const double t = v.get<double>();
      if (!(std::isfinite(t) && t >= 0))
        throw std::invalid_argument("metrics.reference_converged_until: " + v.dump() + " is not a time >= 0 or null");
      m.reference_converged_until = t;
    }
  }
  return m;
}

// ---- hashing --------------------------------------------------------------------------------

std::string physics_hash(const json& scene_json) {
  json physics = scene_json;
  for (const char* key : {"engines", "name", "description", "source_file", "content_hash", "notes"}) physics.erase(key);
  // Whether the reference is checked is not physics: the same reference serves both.
  if (physics.contains("run") && physics["run"].is_object()) physics["run"].erase("self_check");
  // The drilling law at its default is left out: records made before the key existed describe
  // the same physics and keep their hash.
  if (physics.contains("contact") && physics["contact"].is_object() &&
      physics["contact"].value("drilling_law", std::string("decoupled")) == "decoupled")
    physics["contact"].erase("drilling_law");
  // nlohmann::json keeps object keys sorted, so dump() is canonical.
  const std::string text = physics.dump();
  std::uint64_t h = 14695981039346656037ull;
  for (unsigned char c : text) {
    h ^= c;
    h *= 1099511628211ull;
  }
  char buf[17];
  std::snprintf(buf, sizeof buf, "%016llx", static_cast<unsigned long long>(h));
  return buf;
}

std::string physics_hash(const Scene& scene) { return physics_hash(scene_to_json(scene)); }

// ---- the reference's self-check ----------------------------------------------------------------

SelfCheckMethod self_check_method(const RunSpec& run) {
  if (run.method == "rosenbrock4") {
    // Stiff scenes: see compare.h. The bounds are the scene reader's (rtol >= 1e-15; atol > 0).
    return {"rosenbrock4", std::max(run.rtol / 10, 1e-15), run.atol / 10};
  }
  return {run.method == "dopri5" ? "bulirsch_stoer" : "dopri5", run.rtol, run.atol};
}

double self_check_event_tolerance(const Scene& scene) {
  return std::min(std::max(1e3 * scene.run.rtol, 1e-9), 1e-5) * scene.run.duration;
}

namespace {

std::string short_number(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.6g", v);
  return buf;
}

// The earliest of several places where the two runs part.
struct Parting {
  std::optional<double> t;
  std::string reason;
  void consider(double at, std::string why) {
    if (!t || at < *t) {
      t = at;
      reason = std::move(why);
    }
  }
};

}  // namespace

SelfCheck compare_reference_runs(const RunRecord& reference, const Trajectory& ref_traj, const RunRecord& check,
                                 const Trajectory& check_traj, const Scene& scene) {
  SelfCheck sc;
  const SelfCheckMethod plan = self_check_method(scene.run);
  sc.method = plan.method;
  sc.rtol = plan.rtol;
  sc.atol = plan.atol;
  sc.cpu_seconds = check.work.cpu_seconds;
  const std::string a = scene.run.method, b = plan.method == a ? a + " at rtol " + short_number(plan.rtol) : plan.method;
  Parting part;

  // Events, in order: the same names and details, at times within the tolerance.
  const double tol = self_check_event_tolerance(scene);
  const auto& ea = reference.events;
  const auto& eb = check.events;
  const size_t n = std::min(ea.size(), eb.size());
  for (size_t i = 0; i < n; ++i) {
    const Event& x = ea[i];
    const Event& y = eb[i];
    if (x.name != y.name || x.detail != y.detail) {
      part.consider(std::min(x.time, y.time), "event " + std::to_string(i) + ": " + a + " has " + x.name + " (" +
                                                 x.detail + ") at t = " + short_number(x.time) + ", " + b +
                                                 " has " + y.name + " (" + y.detail + ") at t = " +
                                                 short_number(y.time));
      break;
    }
    if (!(std::abs(x.time - y.time) <= tol)) {
      part.consider(std::min(x.time, y.time), "event " + std::to_string(i) + " (" + x.name + ") at t = " +
                                                 short_number(x.time) + " and " + short_number(y.time) +
                                                 ": the times differ by " + short_number(std::abs(x.time - y.time)) +
                                                 " > " + short_number(tol));
      break;
    }
  }
  if (!part.t && ea.size() != eb.size()) {
    const bool ref_longer = ea.size() > eb.size();
    const Event& extra = ref_longer ? ea[n] : eb[n];
    part.consider(extra.time, (ref_longer ? a : b) + " has " + std::to_string((ref_longer ? ea : eb).size() - n) +
                                  " more event(s) from " + extra.name + " at t = " + short_number(extra.time));
  }
  // The reference's own warning: past it, event times are not fixed by the motion.
  for (const auto* events : {&ea, &eb})
    for (const Event& e : *events)
      if (e.name == "unresolved") {
        part.consider(e.time, "unresolved at t = " + short_number(e.time) + ": " + e.detail);
        break;
      }

  // Runs that end differently.
  if (reference.status != check.status)
    part.consider(std::min(reference.status == "ok" ? check.status_time : reference.status_time,
                           check.status == "ok" ? reference.status_time : check.status_time),
                  a + " ends " + reference.status + ", " + b + " " + check.status +
                      (check.status != "ok" ? " at t = " + short_number(check.status_time) + " (" +
                                                  check.status_detail + ")"
                                            : std::string()));

  // The sampled state, on the common grid (both runs sample the same scene's grid).
  const size_t m = std::min(ref_traj.size(), check_traj.size());
  const double E0 = ref_traj.size() ? ref_traj.energy.front() : 1.0;
  const double e_scale = std::isfinite(E0) && E0 != 0.0 ? std::abs(E0) : 1.0;
  for (size_t k = 0; k < m; ++k) {
    if (!(std::abs(ref_traj.t[k] - check_traj.t[k]) <= 0.5 * scene.run.sample_interval)) break;
    if (part.t && ref_traj.t[k] > *part.t) break;
    const double dth = std::abs(ref_traj.theta[k] - check_traj.theta[k]);
    const double de = std::abs(ref_traj.energy[k] - check_traj.energy[k]) / e_scale;
    if (dth <= kSelfCheckStateTolerance && de <= kSelfCheckStateTolerance) continue;
    const double until = k ? ref_traj.t[k - 1] : 0.0;
    const bool tilt = !(dth <= kSelfCheckStateTolerance);
    part.consider(until, std::string(tilt ? "the tilt" : "the energy") + " differs by " +
                             short_number(tilt ? dth : de) + (tilt ? " rad" : " E0") + " > " +
                             short_number(kSelfCheckStateTolerance) + " at t = " + short_number(ref_traj.t[k]));
    break;
  }
  sc.converged_until = part.t;
  sc.reason = part.reason;
  return sc;
}

SelfCheck run_self_check(const Scene& scene, const RunRecord& reference, const Trajectory& ref_traj) {
  Scene second = scene;
  const SelfCheckMethod plan = self_check_method(scene.run);
  second.run.method = plan.method;
  second.run.rtol = plan.rtol;
  second.run.atol = plan.atol;
  TrajectorySink sink;
  const RunRecord check = run_scene(second, reference_engine().name, &sink);
  return compare_reference_runs(reference, ref_traj, check, sink.trajectory, scene);
}

json to_json(const SelfCheck& s) {
  return json{{"method", s.method},
              {"rtol", s.rtol},
              {"atol", s.atol},
              {"converged_until", number(s.converged_until)},
              {"reason", s.reason},
              {"cpu_seconds", number(s.cpu_seconds)}};
}

SelfCheck self_check_from_json(const json& j) {
  SelfCheck s;
  s.method = j.at("method").get<std::string>();
  s.rtol = j.at("rtol").get<double>();
  s.atol = j.value("atol", 0.0);
  const json& cu = j.at("converged_until");
  if (!cu.is_null()) {
    const double t = cu.get<double>();
    if (!(std::isfinite(t) && t >= 0))
      throw std::invalid_argument("reference.self_check.converged_until: " + cu.dump() + " is not a time >= 0 or null");
    s.converged_until = t;
  }
  s.reason = j.at("reason").get<std::string>();
  s.cpu_seconds = get_number(j, "cpu_seconds");
  return s;
}

// ---- records --------------------------------------------------------------------------------

namespace {

// An engine chattering between ball and stem reports a "switch" event per step (10^4 in a few
// seconds of some scenes), which would make comparison.json megabytes long: keep the first ones
// and count the rest.
json summary_with_bounded_events(const RunRecord& r) {
  json j = to_json(r);
  json kept = json::array();
  long long switches = 0;
  for (json& e : j["events"]) {
    if (e.value("name", "") == "switch" && ++switches > kMaxSwitchEventsKept) continue;
    kept.push_back(std::move(e));
  }
  j["events"] = std::move(kept);
  if (switches > kMaxSwitchEventsKept) j["events_omitted"] = {{"switch", switches - kMaxSwitchEventsKept}};
  return j;
}

}  // namespace

json to_json(const Comparison& c) {
  json versions = json::object();
  versions[c.reference.engine.empty() ? reference_engine().name : c.reference.engine] = c.reference.engine_version;
  json engines = json::array();
  for (const EngineResult& e : c.engines) {
    versions[e.run.engine] = e.run.engine_version;
    engines.push_back(
        {{"engine", e.run.engine}, {"summary", summary_with_bounded_events(e.run)}, {"metrics", to_json(e.metrics)}});
  }
  json provenance_with_versions = to_json(c.provenance);
  provenance_with_versions["engine_versions"] = versions;
  json reference = {{"cached", c.reference_cached}, {"summary", summary_with_bounded_events(c.reference)}};
  if (c.self_check) {
    reference["self_check"] = to_json(*c.self_check);
    reference["self_check"]["cached"] = c.self_check_cached;
  }
  return json{
      {"format", "tippe-comparison-1"},
      {"scene_name", c.scene.value("name", "")},
      {"scene_file", c.scene.value("source_file", "")},
      {"scene_hash", c.scene.value("content_hash", "")},
      {"physics_hash", physics_hash(c.scene)},
      {"scene", c.scene},
      {"provenance", provenance_with_versions},
      {"reference", reference},
      {"engines", engines},
  };
}

namespace {

// A name read back from a record names files (ENGINE.csv) and appears in reports: it must pass
// the rule of names in input files, or a shared record could write outside its directory.
void check_record_name(const json& j, const char* key, const std::string& where) {
  const std::string name = j.at(key).get<std::string>();
  if (!is_valid_name(name))
    throw std::invalid_argument(where + key + ": \"" + name + "\" is not a usable name (" + kNameRule + ")");
}

}  // namespace

Comparison comparison_from_json(const json& j) {
  check_record_name(j, "scene_name", "");
  check_record_name(j.at("reference").at("summary"), "engine", "reference.summary.");
  std::set<std::string> engines;
  for (size_t i = 0; i < j.at("engines").size(); ++i) {
    const json& e = j.at("engines").at(i);
    const std::string where = "engines[" + std::to_string(i) + "].";
    check_record_name(e, "engine", where);
    check_record_name(e.at("summary"), "engine", where + "summary.");
    if (e.at("engine") != e.at("summary").at("engine"))
      throw std::invalid_argument(where + "engine: \"" + e.at("engine").get<std::string>() +
                                  "\" differs from its summary's engine");
    if (!engines.insert(e.at("engine").get<std::string>()).second || e.at("engine") == "reference")
      throw std::invalid_argument(where + "engine: \"" + e.at("engine").get<std::string>() +
                                  "\" appears twice (each names its own trajectory file)");
  }
  Comparison c;
  c.scene = j.at("scene");
  c.provenance = provenance_from_json(j.at("provenance"));
  c.reference = from_json(j.at("reference").at("summary"));
  c.reference_cached = j.at("reference").at("cached").get<bool>();
  // Absent (or null) in records of comparisons run without the self-check, and before it existed.
  if (j.at("reference").contains("self_check") && !j.at("reference").at("self_check").is_null()) {
    c.self_check = self_check_from_json(j.at("reference").at("self_check"));
    c.self_check_cached = j.at("reference").at("self_check").value("cached", false);
  }
  for (const json& e : j.at("engines")) c.engines.push_back({from_json(e.at("summary")), metrics_from_json(e.at("metrics"))});
  return c;
}

// ---- running --------------------------------------------------------------------------------

namespace {

// Passes samples on to `inner`; remembers the first failure instead of losing it in the
// simulator's stack. `fatal` rethrows (the run is pointless without this output); otherwise the
// sink just stops forwarding (an optional copy, such as the cache).
class GuardedSink : public SampleSink {
 public:
  GuardedSink(SampleSink* inner, bool fatal) : inner_(inner), fatal_(fatal) {}
  void write(const Observation& o) override {
    if (error || !inner_) return;
    try {
      inner_->write(o);
    } catch (...) {
      error = std::current_exception();
      if (fatal_) throw;
    }
  }
  std::exception_ptr error;

 private:
  SampleSink* inner_;
  bool fatal_;
};

std::string exception_text(const std::exception_ptr& e) {
  try {
    std::rethrow_exception(e);
  } catch (const std::exception& x) {
    return x.what();
  } catch (...) {
    return "unknown exception";
  }
}

// What a run leaves when its simulator could not be built or threw: a record that says so.
RunRecord failed_record(const Scene& scene, const std::string& engine, const std::string& why,
                        const Trajectory& tr) {
  RunRecord r;
  r.provenance = current_provenance();
  r.scene_name = scene.name;
  r.scene_file = scene.source_file;
  r.scene_hash = scene.content_hash;
  r.scene_spec = scene_to_json(scene);
  r.engine = engine;
  r.engine_version = "unknown";
  r.status = to_string(RunStatus::Failed);
  r.status_time = tr.size() ? tr.t.back() : 0.0;
  r.status_detail = why;
  r.mass = scene.mass;
  r.inversion_possible = inversion_possible(scene.mass, scene.body.sphere_radius);
  r.samples = static_cast<long long>(tr.size());
  r.final_time = tr.size() ? tr.t.back() : kNaN;
  r.final_tilt = tr.size() ? tr.theta.back() : kNaN;
  r.energy_initial = tr.size() ? tr.energy.front() : kNaN;
  r.energy_final = tr.size() ? tr.energy.back() : kNaN;
  r.jellett_initial = tr.size() ? tr.jellett.front() : kNaN;
  r.jellett_max_relative_drift = kNaN;
  r.min_normal_force = tr.size() ? *std::min_element(tr.normal_force.begin(), tr.normal_force.end()) : kNaN;
  return r;
}

// One line on stderr for all runs, redrawn in place.
class ProgressBoard {
 public:
  enum State { Waiting, Running, Done, Cached, Stopped };
  ProgressBoard(std::string scene, std::vector<std::string> names, double duration)
      : scene_(std::move(scene)), names_(std::move(names)), duration_(duration), t_(names_.size()),
        state_(names_.size()), why_(names_.size()) {
    for (size_t i = 0; i < names_.size(); ++i) {
      t_[i] = 0.0;
      state_[i] = Waiting;
    }
  }
  void set_time(size_t i, double t) { t_[i].store(t, std::memory_order_relaxed); }
  void set_state(size_t i, State s) { state_[i].store(s); }
  // A run that ended other than ok, with its status; the text is written before the state.
  void stopped(size_t i, const std::string& status) {
    why_[i] = status;
    state_[i].store(Stopped);
  }
  // final_line: the last state, ended with a newline. In Lines mode (not a terminal) a line at
  // most every kProgressLineSeconds, and the last; Quiet: nothing.
  void print(bool final_line = false) {
    const ProgressMode mode = progress_mode();
    if (mode == ProgressMode::Quiet) return;
    const auto now = std::chrono::steady_clock::now();
    if (mode == ProgressMode::Lines && !final_line && printed_ &&
        std::chrono::duration<double>(now - last_).count() < kProgressLineSeconds)
      return;
    printed_ = true;
    last_ = now;
    std::string line = "[compare " + scene_ + "]";
    for (size_t i = 0; i < names_.size(); ++i) {
      line += i ? " | " : " ";
      line += names_[i];
      char buf[64];
      switch (state_[i].load()) {
        case Waiting: line += " waiting"; break;
        case Done: line += " done"; break;
        case Cached: line += " cached"; break;
        case Stopped: line += " " + why_[i]; break;
        case Running:
          std::snprintf(buf, sizeof buf, " t=%.2f/%.2f", t_[i].load(std::memory_order_relaxed), duration_);
          line += buf;
          break;
      }
    }
    if (mode == ProgressMode::Lines) {
      std::fprintf(stderr, "%s\n", line.c_str());
      std::fflush(stderr);
      return;
    }
    // Pads over the tail of a longer previous line.
    const size_t len = line.size();
    if (line.size() < width_) line.append(width_ - line.size(), ' ');
    width_ = len;
    std::fprintf(stderr, "\r%s", line.c_str());
    if (final_line) std::fputc('\n', stderr);
    std::fflush(stderr);
  }

 private:
  bool printed_ = false;
  std::chrono::steady_clock::time_point last_;
  std::string scene_;
  std::vector<std::string> names_;
  double duration_;
  std::vector<std::atomic<double>> t_;
  std::vector<std::atomic<int>> state_;
  std::vector<std::string> why_;
  size_t width_ = 0;
};

struct Task {
  std::string engine;
  const Scene* scene = nullptr;  // the scene to run when not the comparison's (the self-check)
  std::string csv_path;  // "" = no file
  std::string cache_csv_path;  // reference only: a copy for the cache
  RunRecord record;
  Trajectory trajectory;
  std::exception_ptr fatal;  // output failure: the comparison cannot be completed
};

void run_task(Task& task, const Scene& scene, ProgressBoard& board, size_t slot) {
  board.set_state(slot, ProgressBoard::Running);
  std::unique_ptr<Simulator> sim;
  try {
    sim = make_simulator(task.engine, scene);
  } catch (const std::exception& e) {
    // Settings were validated up front: what is left is an engine refusing this scene.
    task.record = failed_record(scene, task.engine, std::string("could not build the simulator: ") + e.what(), {});
    board.stopped(slot, task.record.status);
    return;
  }
  std::unique_ptr<CsvTrajectoryWriter> csv, cache_csv;
  try {
    if (!task.csv_path.empty()) csv = std::make_unique<CsvTrajectoryWriter>(task.csv_path);
  } catch (...) {
    task.fatal = std::current_exception();
    board.stopped(slot, "error");
    return;
  }
  try {
    if (!task.cache_csv_path.empty()) cache_csv = std::make_unique<CsvTrajectoryWriter>(task.cache_csv_path);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "\ntippe: warning: reference cache not written: %s\n", e.what());
    task.cache_csv_path.clear();
  }
  GuardedSink out(csv.get(), true), cache(cache_csv.get(), false);
  TrajectorySink sink({&out, &cache});
  try {
    task.record = run_simulator(*sim, scene, &sink, [&](double t, double) { board.set_time(slot, t); });
  } catch (const Interrupted&) {
    // A signal ends the comparison, not this run: nothing of it is recorded.
    task.fatal = std::current_exception();
    board.stopped(slot, "interrupted");
    return;
  } catch (...) {
    if (out.error) {
      task.fatal = out.error;
      board.stopped(slot, "error");
      return;
    }
    // An adapter that throws is a failed run, not a failed comparison; its samples so far are kept.
    task.record = failed_record(scene, task.engine, "exception: " + exception_text(std::current_exception()),
                                sink.trajectory);
    task.record.engine_version = sim->version();
    task.record.settings = sim->settings();
    task.record.notes = sim->notes();
  }
  task.trajectory = std::move(sink.trajectory);
  sim.reset();
  try {
    if (csv) csv->commit();
  } catch (...) {
    task.fatal = std::current_exception();
  }
  if (cache_csv && !cache.error) {
    try {
      cache_csv->commit();
    } catch (const std::exception& e) {
      std::fprintf(stderr, "\ntippe: warning: reference cache not written: %s\n", e.what());
      cache.error = std::current_exception();
    }
  }
  if (cache.error) task.cache_csv_path.clear();
  if (task.record.status == "ok")
    board.set_state(slot, ProgressBoard::Done);
  else
    board.stopped(slot, task.record.status);
}

void copy_file_atomic(const fs::path& from, const fs::path& to) {
  const fs::path tmp = to.string() + ".tmp." + std::to_string(::getpid());
  fs::copy_file(from, tmp, fs::copy_options::overwrite_existing);
  fs::rename(tmp, to);
}

std::string analytic_version(const Scene& scene) { return make_simulator(reference_engine().name, scene)->version(); }

// DIR/self_check.json: the self-check of the reference cached beside it. Keyed by the physics
// hash, the reference's provenance (commit, host, date: a summary rewritten by a later run no
// longer matches) and the second method and tolerances, so a check made for another reference
// or with another method is never taken for this one's.
json self_check_key(const std::string& hash, const RunRecord& reference, const SelfCheckMethod& plan) {
  return json{{"physics_hash", hash},
              {"reference_git_commit", reference.provenance.git_commit},
              {"reference_hostname", reference.provenance.hostname},
              {"reference_date", reference.provenance.date},
              {"method", plan.method},
              {"rtol", plan.rtol},
              {"atol", plan.atol}};
}

std::optional<SelfCheck> load_cached_self_check(const fs::path& dir, const std::string& hash,
                                                const RunRecord& reference, const SelfCheckMethod& plan) {
  if (dir.empty()) return std::nullopt;
  try {
    const json j = json::parse(read_file_text((dir / "self_check.json").string()));
    if (j.at("format") != "tippe-self-check-1" || j.at("key") != self_check_key(hash, reference, plan))
      return std::nullopt;
    return self_check_from_json(j.at("self_check"));
  } catch (const std::exception&) {
    return std::nullopt;  // absent, partial or from elsewhere: run the check again
  }
}

void store_self_check(const fs::path& dir, const std::string& hash, const RunRecord& reference,
                      const SelfCheck& sc) {
  const SelfCheckMethod plan{sc.method, sc.rtol, sc.atol};
  const json j = {{"format", "tippe-self-check-1"}, {"key", self_check_key(hash, reference, plan)},
                  {"self_check", to_json(sc)}};
  try {
    write_file_atomic((dir / "self_check.json").string(), j.dump(2) + "\n");
  } catch (const std::exception& e) {
    std::fprintf(stderr, "tippe: warning: reference self-check not cached: %s\n", e.what());
  }
}

}  // namespace

bool load_cached_reference(const fs::path& dir, const Scene& scene, const std::string& hash, RunRecord& record,
                           Trajectory& trajectory) {
  const fs::path summary = dir / "summary.json", csv = dir / "trajectory.csv";
  std::error_code ec;
  if (!fs::exists(summary, ec) || !fs::exists(csv, ec)) return false;
  std::string summary_text, csv_text;
  try {
    summary_text = read_file_text(summary.string());
    csv_text = read_file_text(csv.string());
  } catch (const std::runtime_error&) {
    return false;
  }
  return reference_from_text(summary_text, csv_text, scene, hash, dir.string(), record, trajectory).empty();
}

std::string reference_from_text(const std::string& summary_json, const std::string& trajectory_csv,
                                const Scene& scene, const std::string& hash, const std::string& where,
                                RunRecord& record, Trajectory& trajectory) {
  try {
    const RunRecord r = from_json(json::parse(summary_json));
    if (r.engine != reference_engine().name) return where + ": not a reference run (engine " + r.engine + ")";
    if (physics_hash(r.scene_spec) != hash) return where + ": made from other physics";
    if (r.provenance.git_commit != build_info().git_commit)
      return where + ": made by the build of commit " + r.provenance.git_commit + ", this is " +
             build_info().git_commit;
    if (r.engine_version != analytic_version(scene))
      return where + ": made by reference version " + r.engine_version + ", this is " + analytic_version(scene);
    std::istringstream in(trajectory_csv);
    Trajectory tr = Trajectory::from_csv(parse_trajectory_csv(in, where + "/trajectory.csv"));
    if (static_cast<long long>(tr.size()) != r.samples)
      return where + ": trajectory has " + std::to_string(tr.size()) + " samples, the summary " +
             std::to_string(r.samples);
    record = r;
    trajectory = std::move(tr);
    return "";
  } catch (const std::exception& e) {
    return where + ": " + e.what();
  }
}

void check_compare_input(const Scene& scene, const CompareOptions& options) {
  if (options.engines.empty()) throw std::invalid_argument("no engines to compare");
  if (options.jobs < 1) throw std::invalid_argument("jobs must be at least 1, got " + std::to_string(options.jobs));
  const std::vector<std::string> known = available_engines();
  std::set<std::string> seen;
  for (const std::string& e : options.engines) {
    if (std::find(known.begin(), known.end(), e) == known.end()) {
      std::string list;
      for (const auto& k : known) list += (list.empty() ? "" : ", ") + k;
      throw std::invalid_argument("unknown engine \"" + e + "\" (expected one of: " + list + ")");
    }
    if (!seen.insert(e).second) throw std::invalid_argument("engine \"" + e + "\" listed twice");
  }
  validate_engine_settings(scene);
}

Comparison run_comparison(const Scene& scene, const CompareOptions& options) {
  // Every check on the input comes before the first file is written.
  check_compare_input(scene, options);

  Comparison c;
  c.scene = scene_to_json(scene);
  c.provenance = current_provenance();
  const std::string hash = physics_hash(c.scene);
  const fs::path out = options.out_dir;
  if (!out.empty()) fs::create_directories(out);

  std::vector<Task> tasks(options.engines.size() + 1);
  tasks.reserve(tasks.size() + 1);  // room for the self-check: `ref` stays valid
  Task& ref = tasks[0];
  ref.engine = reference_engine().name;
  if (!out.empty()) ref.csv_path = (out / "reference.csv").string();
  fs::path cache_dir;
  if (!options.cache_dir.empty()) {
    cache_dir = fs::path(options.cache_dir) / hash;
    c.reference_cached = load_cached_reference(cache_dir, scene, hash, ref.record, ref.trajectory);
    if (c.reference_cached && !out.empty()) copy_file_atomic(cache_dir / "trajectory.csv", ref.csv_path);
    if (!c.reference_cached) {
      std::error_code ec;
      fs::create_directories(cache_dir, ec);
      if (ec)
        std::fprintf(stderr, "tippe: warning: reference cache %s not usable: %s\n", cache_dir.string().c_str(),
                     ec.message().c_str());
      else
        ref.cache_csv_path = (cache_dir / "trajectory.csv").string();
    }
  }
  for (size_t i = 0; i < options.engines.size(); ++i) {
    tasks[i + 1].engine = options.engines[i];
    if (!out.empty()) tasks[i + 1].csv_path = (out / (options.engines[i] + ".csv")).string();
  }

  // The self-check: from the cache beside a cached reference, else a second reference run in
  // parallel with the engines (it needs nothing from the first until both are done).
  Scene check_scene = scene;
  const SelfCheckMethod plan = self_check_method(scene.run);
  check_scene.run.method = plan.method;
  check_scene.run.rtol = plan.rtol;
  check_scene.run.atol = plan.atol;
  size_t check_slot = 0;  // 0: no self-check run
  if (scene.run.self_check) {
    if (c.reference_cached) {
      if (auto cached = load_cached_self_check(cache_dir, hash, ref.record, plan)) {
        c.self_check = *cached;
        c.self_check_cached = true;
      }
    }
    if (!c.self_check) {
      check_slot = tasks.size();
      tasks.emplace_back();
      tasks.back().engine = reference_engine().name;
      tasks.back().scene = &check_scene;
    }
  }

  std::vector<std::string> names;
  for (size_t i = 0; i < tasks.size(); ++i) names.push_back(i && i == check_slot ? "self-check" : tasks[i].engine);
  ProgressBoard board(scene.name, names, scene.run.duration);
  std::vector<size_t> todo;
  for (size_t i = 0; i < tasks.size(); ++i) {
    if (i == 0 && c.reference_cached)
      board.set_state(0, ProgressBoard::Cached);
    else
      todo.push_back(i);
  }

  // Each simulator is built, run and destroyed on one worker thread (ODE's per-thread state).
  // run_task keeps a run's exception in its task (t.fatal), so every run is attempted.
  // Five redraws a second is enough to see motion without flooding a CI log.
  std::function<void()> redraw;
  if (options.progress) redraw = [&] { board.print(); };
  parallel_for(
      todo.size(), options.jobs,
      [&](size_t k) {
        Task& t = tasks[todo[k]];
        run_task(t, t.scene ? *t.scene : scene, board, todo[k]);
      },
      redraw);
  if (options.progress) board.print(true);

  for (const Task& t : tasks)
    if (t.fatal) std::rethrow_exception(t.fatal);
  if (ref.record.status == to_string(RunStatus::Failed) && ref.trajectory.size() == 0)
    throw std::runtime_error("reference run failed: " + ref.record.status_detail);

  if (!c.reference_cached && !ref.cache_csv_path.empty() && ref.record.status != to_string(RunStatus::Failed)) {
    // The summary goes last: its presence says the trajectory beside it is complete.
    try {
      write_file_atomic((cache_dir / "summary.json").string(), to_json(ref.record).dump(2) + "\n");
    } catch (const std::exception& e) {
      std::fprintf(stderr, "tippe: warning: reference cache not written: %s\n", e.what());
    }
  }

  if (check_slot) {
    const Task& t = tasks[check_slot];
    c.self_check = compare_reference_runs(ref.record, ref.trajectory, t.record, t.trajectory, scene);
    // Beside a reference that is in the cache (loaded, or just written there).
    if (!cache_dir.empty() && ref.record.status != to_string(RunStatus::Failed) &&
        (c.reference_cached || !ref.cache_csv_path.empty()))
      store_self_check(cache_dir, hash, ref.record, *c.self_check);
  }
  const std::optional<double> converged_until = c.self_check ? c.self_check->converged_until : std::nullopt;

  c.reference = ref.record;
  for (size_t i = 1; i < tasks.size(); ++i) {
    if (i == check_slot) continue;
    Metrics m = compare_runs(ref.record, ref.trajectory, tasks[i].record, tasks[i].trajectory, scene, converged_until);
    c.engines.push_back({std::move(tasks[i].record), m});
  }

  if (!out.empty()) {
    const json j = to_json(c);
    write_file_atomic((out / "comparison.json").string(), j.dump(2) + "\n");
    write_report(out.string(), j, options.plots);
  }
  return c;
}

}  // namespace tippe
