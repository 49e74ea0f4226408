// The reference cache: a reference run and its self-check stored and accepted only for the same physics and build.
#include "harness/measure/reference_cache.h"

#include <sstream>
#include <stdexcept>
#include <system_error>
#include "harness/io/provenance.h"
#include "harness/records/records.h"
#include "engines/core/registry.h"

namespace tippe {

namespace fs = std::filesystem;
using nlohmann::json;

namespace {

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

}  // namespace

std::optional<SelfCheck> load_cached_self_check(const fs::path& dir, const std::string& hash,
                                                const RunRecord& reference, const SelfCheckMethod& plan) {
  if (dir.empty()) return std::nullopt;
  try {
    const json j = json::parse(read_file_text((dir / "self_check.json").string()));
    if (j.at("format") != "tippe-self-check-1" || j.at("key") != self_check_key(hash, reference, plan))
      return std::nullopt;
    SelfCheck sc = self_check_from_json(j.at("self_check"));
    // The check itself must be the one its key names (a file edited or pieced together is not).
    if (sc.method != plan.method || sc.rtol != plan.rtol || sc.atol != plan.atol) return std::nullopt;
    return sc;
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

}  // namespace tippe
