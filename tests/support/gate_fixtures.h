// The gate tests' fixtures: a check with its runs' records and metrics to judge, a verdict's row by metric, and a gate directory beside a copy of a scene.
#pragma once

#include <filesystem>
#include <optional>
#include <string>

#include "harness/gating/gate.h"
#include "tests/support/files.h"
#include "tests/support/run_records.h"

namespace tippe::fixtures {

// The scene the tests' gate files name.
static const std::string kGateScene = std::string(TIPPE_SOURCE_DIR) + "/harness/scenes/source_dimensionless.toml";

inline Check fixture_check() {
  Check c;
  c.name = "ode-fixture";
  c.scene = "../scenes/fixture.toml";
  c.engine = "ode";
  c.require_same_events = false;
  c.max = {{"inversion_time_rel_error", 0.01}, {"tilt_rms_error", 0.05}, {"energy_gain_events", 0}};
  return c;
}

inline RunRecord fixture_record(const std::string& engine, std::optional<double> inversion) {
  RunRecord r = ok_record(engine);
  r.inversion_time = inversion;
  r.work.wall_seconds = 0.25;
  return r;
}

inline Metrics fixture_metrics() {
  Metrics m;
  m.inversion_event = "both";
  m.stem_contact_event = "neither";
  m.inversion_time_abs_error = 0.017;
  m.inversion_time_rel_error = 0.001;
  m.tilt_rms_error = 0.02;
  m.tilt_max_error = 0.04;
  m.compared_until = 18.0;
  m.steps = 180000;
  return m;
}

inline const GateRow* row(const CheckResult& r, const std::string& metric) {
  for (const GateRow& g : r.rows)
    if (g.metric == metric) return &g;
  return nullptr;
}

// A gate directory beside a copy of the scene, so that relative scene paths are exercised.
struct GateDir {
  TempDir tmp{"tippe-gate"};
  std::filesystem::path gate;
  GateDir() {
    std::filesystem::create_directories(tmp.path() / "scenes");
    std::filesystem::copy_file(kGateScene, tmp.path() / "scenes" / "source.toml");
    gate = tmp.path() / "gates" / "g.toml";
  }
  std::string write(const std::string& text) {
    spit(gate, text);
    return gate.string();
  }
};

}  // namespace tippe::fixtures
