// The reference runs several test programs share: the energy ledger sampled as the harness samples, and the slip-start runs of the Leine-Glocker top and its twin with their checks.
#pragma once

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <optional>
#include <string>
#include <vector>

#include "analytic/initial_state.h"
#include "harness/io/scene_io.h"
#include "harness/scene/resolve.h"
#include "analytic/observables.h"
#include "analytic/reference_model.h"

namespace tippe::fixtures {

// The time of the first event of that name, if any.
inline std::optional<double> first_event(const std::vector<ReferenceEvent>& events, const std::string& name) {
  for (const auto& e : events)
    if (e.name == name) return e.time;
  return std::nullopt;
}

inline Scene shipped_reference_scene(const std::string& name) {
  return load_scene(std::string(TIPPE_SOURCE_DIR) + "/harness/scenes/" + name + ".toml");
}

struct Ledger {
  double worst = 0.0;          // largest |E + ledger - E0| / E0
  double worst_drop = 0.0;     // largest fall of the friction work between samples, / E0
  double worst_rise = 0.0;     // largest rise of E between samples, / E0
  double e_max = 0.0;          // largest E / E0
  std::vector<ReferenceEvent> events;
  ReferenceStatus status = ReferenceStatus::Ok;
  std::string detail;
};

// Samples every sample interval and just before and after every event of a first run (E and the
// ledger jump together at an impact), as the harness runs the reference (sample by sample).
inline Ledger run_ledger(const Scene& s) {
  std::vector<double> times;
  {
    ReferenceModel first(s);
    for (double t = s.run.sample_interval; t < s.run.duration && first.status() == ReferenceStatus::Ok; t += s.run.sample_interval)
      first.advance_to(t);
    for (const auto& e : first.events()) {
      times.push_back(e.time - 1e-9);
      times.push_back(e.time + 1e-9);
    }
  }
  for (double t = s.run.sample_interval; t < s.run.duration; t += s.run.sample_interval) times.push_back(t);
  times.push_back(s.run.duration);
  std::sort(times.begin(), times.end());
  ReferenceModel m(s);
  const BodyModel& b = m.body();
  const double e0 = energy(b, scene_initial_state(s));
  Ledger out;
  double w_prev = 0.0, e_prev = 1.0;
  for (double t : times) {
    if (m.status() != ReferenceStatus::Ok || t > s.run.duration || t <= 0) continue;
    m.advance_to(t);
    if (m.status() != ReferenceStatus::Ok) break;
    const double e = energy(b, m.state()) / e0, w = m.energy_ledger().friction / e0;
    out.worst = std::max(out.worst, std::abs(e + m.energy_ledger().total() / e0 - 1.0));
    out.worst_drop = std::max(out.worst_drop, w_prev - w);
    out.worst_rise = std::max(out.worst_rise, e - e_prev);
    out.e_max = std::max(out.e_max, e);
    w_prev = w;
    e_prev = e;
  }
  out.events = m.events();
  out.status = m.status();
  out.detail = m.status_detail();
  return out;
}

inline int count(const std::vector<ReferenceEvent>& events, const std::string& name) {
  return static_cast<int>(std::count_if(events.begin(), events.end(), [&](const ReferenceEvent& e) { return e.name == name; }));
}

// The Leine-Glocker top at mu = 0.02 from a tilt of 1 rad on `method` (to `duration` s if
// given, else the scene's 30 s), with the checks the tests below share; its events up to 14 s
// (see below for why not later).
inline std::vector<ReferenceEvent> decoupled_slip_start(const char* method, double duration = 0.0) {
  Scene s = shipped_reference_scene("leine_glocker");
  s.contact.mu = 0.02;
  s.initial.tilt = 1.0;
  s.run.method = method;
  if (duration > 0) s.run.duration = duration;
  const Ledger l = run_ledger(s);
  std::printf("leine_glocker mu 0.02 tilt 1, %s: %d slip starts, ledger %.3g E0, friction work drop %.3g E0, E rise %.3g E0, max E %.6f E0\n",
              method, count(l.events, "slip"), l.worst, l.worst_drop, l.worst_rise, l.e_max);
  EXPECT_EQ(l.status, ReferenceStatus::Ok) << method << ": " << l.detail;
  EXPECT_GE(count(l.events, "slip"), 3) << method;
  EXPECT_LT(l.worst, 1e-9) << method;
  EXPECT_LT(l.worst_drop, 1e-10) << method;
  EXPECT_LT(l.worst_rise, 1e-9) << method;
  EXPECT_LE(l.e_max, 1.0 + 1e-9) << method;
  std::vector<ReferenceEvent> out;
  for (const auto& e : l.events)
    if (e.time < 14.0) out.push_back(e);
  return out;
}

// The twin run to 17.6 s (two slip starts) on `method`, sample by sample as the harness runs
// it, with the checks the tests below share; its stick and slip events.
inline std::vector<ReferenceEvent> twin_past_the_slip(const char* method) {
  Scene s = shipped_reference_scene("leine_glocker_twin_coupled");
  s.run.method = method;
  s.run.duration = 17.6;
  ReferenceModel m(s);
  const BodyModel& b = m.body();
  const double e0 = energy(b, m.state());
  double w_prev = 0.0, worst_drop = 0.0, worst_ledger = 0.0;
  for (int k = 1; k <= 17600 && m.status() == ReferenceStatus::Ok; ++k) {
    m.advance_to(1e-3 * k);
    const double w = m.energy_ledger().friction;
    worst_drop = std::max(worst_drop, (w_prev - w) / e0);
    w_prev = w;
    worst_ledger = std::max(worst_ledger, std::abs(energy(b, m.state()) + m.energy_ledger().total() - e0) / e0);
  }
  EXPECT_EQ(m.status(), ReferenceStatus::Ok) << method << ": " << m.status_detail();
  std::vector<ReferenceEvent> out;
  int sticks = 0, slips = 0;
  for (const auto& e : m.events()) {
    if (e.name == "stick" || e.name == "slip") out.push_back(e);
    sticks += e.name == "stick";
    slips += e.name == "slip";
  }
  std::printf("twin to 17.6 s, %s: %d sticks, %d slips; ledger %.3g E0, friction work drop %.3g E0\n", method, sticks, slips,
              worst_ledger, worst_drop);
  EXPECT_EQ(sticks, 3) << method;
  EXPECT_EQ(slips, 3) << method;
  EXPECT_LT(worst_ledger, 1e-9) << method;
  EXPECT_LT(worst_drop, 1e-12) << method;
  return out;
}

}  // namespace tippe::fixtures
