// Running one simulator on a scene into a run record, sample by sample.
#pragma once

#include <functional>
#include <string>

#include "harness/records/records.h"
#include "analytic/scene.h"
#include "engines/core/simulator.h"

namespace tippe {

// Called after every sample with the sample's time and the run's duration.
using ProgressFn = std::function<void(double t, double duration)>;

// A run record with what the scene alone decides: provenance (now), the scene's name, file, hash
// and spec, its mass properties and whether it can invert; the run fills the rest.
RunRecord record_of_scene(const Scene& scene);

// Samples the simulator on the grid t_k = k * sample_interval, k = 0..floor(duration /
// sample_interval) (the last point snapped to duration when within rounding), streams each
// observation to `sink` (may be null), and stops after the first sample taken once the status
// leaves ok (that sample carries its own, earlier, time). Fills every field of the record.
RunRecord run_simulator(Simulator& sim, const Scene& scene, SampleSink* sink, ProgressFn progress = {});
// make_simulator(engine, scene) followed by run_simulator; std::invalid_argument from
// make_simulator (unknown engine, bad setting) passes through.
RunRecord run_scene(const Scene& scene, const std::string& engine, SampleSink* sink, ProgressFn progress = {});

}  // namespace tippe
