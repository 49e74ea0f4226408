// The reference cache shared by compare, gate and sweep: a reference run and its self-check kept by physics hash.
#pragma once

#include <filesystem>
#include <optional>
#include <string>
#include "harness/records/comparison.h"
#include "harness/records/trajectory.h"
#include "analytic/scene.h"
#include "harness/measure/self_check.h"

namespace tippe {

// A reference cache entry, DIR/{summary.json, trajectory.csv} (shared by compare, gate and
// sweep): loaded when both files are complete and were made from the physics `hash` by this
// build of the reference (same commit, same version string); false for anything else.
bool load_cached_reference(const std::filesystem::path& dir, const Scene& scene, const std::string& hash,
                           RunRecord& record, Trajectory& trajectory);
// The same rule over the two files' texts (a reference sent from another process); `where`
// names their origin in the reason. Empty: accepted; otherwise why not.
std::string reference_from_text(const std::string& summary_json, const std::string& trajectory_csv,
                                const Scene& scene, const std::string& hash, const std::string& where,
                                RunRecord& record, Trajectory& trajectory);

// DIR/self_check.json: the self-check cached beside a cached reference, for this reference (its
// provenance) and this second method; absent, partial or another one's: nullopt.
std::optional<SelfCheck> load_cached_self_check(const std::filesystem::path& dir, const std::string& hash,
                                                const RunRecord& reference, const SelfCheckMethod& plan);
// Writes DIR/self_check.json; a failure is a warning on stderr (the cache is an optimisation).
void store_self_check(const std::filesystem::path& dir, const std::string& hash, const RunRecord& reference,
                      const SelfCheck& sc);

}  // namespace tippe
