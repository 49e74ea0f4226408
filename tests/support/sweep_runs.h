// Running `tippe sweep` (alone or under mpirun) from the tests and comparing the records it leaves, and the sweeps the tests of shards and ranks share.
#pragma once

#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "tests/support/files.h"
#include "tests/support/fixtures.h"
#include "tests/support/process.h"
#include "tests/support/records.h"

namespace tippe::sweep_runs {

// ---- running the binary -----------------------------------------------------------------------

// The command with stdout and stderr into `log`; its exit status (-1: ended by a signal).
inline int run(const std::vector<std::string>& argv, const std::filesystem::path& log) {
  return wait_process(spawn_process(argv, log, log)).code;
}

inline std::vector<std::string> tippe_sweep(std::vector<std::string> args) {
  args.insert(args.begin(), {fixtures::kTippeBinary, "sweep"});
  args.push_back("--no-plots");
  return args;
}

// ---- records ----------------------------------------------------------------------------------

inline std::vector<nlohmann::json> lines_of(const std::filesystem::path& records) {
  std::vector<nlohmann::json> out;
  std::ifstream in(records);
  for (std::string line; std::getline(in, line);)
    if (!line.empty()) out.push_back(nlohmann::json::parse(line));
  return out;
}

// point id -> record without timings; a point written twice fails the test.
inline std::map<std::string, nlohmann::json> records_by_id(const std::filesystem::path& dir) {
  std::map<std::string, nlohmann::json> out;
  for (const nlohmann::json& r : lines_of(dir / "records.jsonl")) {
    const std::string id = r.at("point_id");
    EXPECT_TRUE(out.emplace(id, without_timings(r)).second) << dir << ": point " << id << " written twice";
  }
  return out;
}

// The same points with the same records, a difference named by point and field.
inline void expect_same_records(const std::filesystem::path& expected_dir, const std::filesystem::path& actual_dir) {
  const auto a = records_by_id(expected_dir), b = records_by_id(actual_dir);
  ASSERT_EQ(a.size(), b.size()) << expected_dir << " vs " << actual_dir;
  for (const auto& [id, ra] : a) {
    auto it = b.find(id);
    ASSERT_NE(it, b.end()) << actual_dir << " lacks point " << id;
    if (ra == it->second) continue;
    for (auto f = ra.begin(); f != ra.end(); ++f)
      EXPECT_EQ(f.value(), it->second.value(f.key(), nlohmann::json())) << "point " << id << " field " << f.key();
    FAIL() << "point " << id << " differs";
  }
}

// ---- sweeps the tests of shards and ranks share ------------------------------------------------

static const std::string kSmoke = TIPPE_SOURCE_DIR "/harness/sweeps/smoke.toml";

// One local run of the smoke sweep, shared by the tests that compare against it.
inline const std::filesystem::path& local_smoke() {
  static TempDir dir("tippe-dist-local");
  static bool done = false;
  if (!done) {
    const std::filesystem::path out = dir.path() / "local";
    EXPECT_EQ(run(tippe_sweep({kSmoke, "--out", out.string(), "--jobs", "1"}), dir.path() / "log"), 0)
        << slurp(dir.path() / "log");
    done = true;
  }
  static const std::filesystem::path out = dir.path() / "local";
  return out;
}

// A sweep whose second scene's reference fails on its first step: the stiff scene on an explicit
// method (Bulirsch-Stoer at k = 1e4).
inline std::string failing_reference_sweep(const TempDir& dir) {
  std::string scene = slurp(fixtures::kSourceDir + "/harness/scenes/extremes/k_high.toml");
  const std::string from = "method = \"rosenbrock4\"";
  scene.replace(scene.find(from), from.size(), "method = \"bulirsch_stoer\"");
  dir.write("stiff_explicit.toml", scene);
  return dir.write("fails.toml", "description = \"a reference that fails\"\nscenes = [\"" + fixtures::kSourceDir +
                                     "/harness/scenes/toy.toml\", \"stiff_explicit.toml\"]\n"
                                     "[[setup]]\nname = \"ode\"\nengine = \"ode\"\n"
                                     "ladder.key = \"engines.ode.timestep\"\nladder.values = [1e-3, 2e-3]\n");
}

// A failing reference is a result: its scene's points are recorded failed with its reason, the
// other scene's points run, the report lists the reference as failed, and the sweep exits 0.
inline void expect_failed_reference_recorded(const std::filesystem::path& out, const std::string& log) {
  std::map<std::string, size_t> by_scene, failed;
  for (const nlohmann::json& r : lines_of(out / "records.jsonl")) {
    const std::string scene = r.at("scene");
    ++by_scene[scene];
    if (r.at("status") == "failed") {
      ++failed[scene];
      EXPECT_EQ(r.at("status_detail").get<std::string>().rfind("not run: the reference run of k_high failed at t = ", 0), 0u)
          << r.dump();
      EXPECT_EQ(r.at("class").at("name"), "failed");
      EXPECT_EQ(r.at("reference").at("status"), "failed");
    }
  }
  EXPECT_EQ(by_scene["toy"], 2u) << log;
  EXPECT_EQ(failed["toy"], 0u) << log;
  EXPECT_EQ(by_scene["k_high"], 2u) << log;
  EXPECT_EQ(failed["k_high"], 2u) << log;
  EXPECT_NE(log.find("tippe: warning: the reference run of k_high failed"), std::string::npos) << log;
  const std::string report = slurp(out / "report.md");
  EXPECT_NE(report.find("k_high"), std::string::npos) << report;
  EXPECT_NE(report.find("| failed |"), std::string::npos) << report;
}

// A grid and a categorical ladder: every point is an ordinary point, so shards, merges, resumed
// runs and MPI ranks give the records of one local run.
inline std::string grid_sweep(const TempDir& dir) {
  return dir.write("grid.toml", "description = \"a grid\"\nduration = 0.3\nscenes = [\"" + fixtures::kSourceDir +
                                    "/harness/scenes/toy.toml\"]\n"
                                    "[[setup]]\nname = \"ode\"\nengine = \"ode\"\n"
                                    "ladder = { key = \"engines.ode.timestep\", values = [1e-3, 2e-3] }\n"
                                    "grid = { key = \"engines.ode.friction_model\", values = [\"approx1\", \"box\"] }\n"
                                    "[[setup]]\nname = \"mujoco\"\nengine = \"mujoco\"\n"
                                    "ladder = { key = \"engines.mujoco.body_frame\", values = [\"com\", \"ball_centre\"] }\n");
}

// ---- MPI --------------------------------------------------------------------------------------

// Where mpirun is; "" when not on PATH.
inline std::string mpirun_path() {
  const char* path = std::getenv("PATH");
  std::stringstream ss(path ? path : "");
  for (std::string dir; std::getline(ss, dir, ':');)
    if (!dir.empty() && ::access((std::filesystem::path(dir) / "mpirun").c_str(), X_OK) == 0)
      return (std::filesystem::path(dir) / "mpirun").string();
  return "";
}

// mpirun -np N [--oversubscribe] tippe sweep ARGS. Open MPI refuses root without its two
// allow-run-as-root variables (CI runs as root), and more ranks than cores without --oversubscribe.
inline std::vector<std::string> mpirun_sweep(int np, std::vector<std::string> args) {
  ::setenv("OMPI_ALLOW_RUN_AS_ROOT", "1", 1);
  ::setenv("OMPI_ALLOW_RUN_AS_ROOT_CONFIRM", "1", 1);
  std::vector<std::string> argv = {mpirun_path(), "--oversubscribe", "-np", std::to_string(np)};
  for (const std::string& a : tippe_sweep(std::move(args))) argv.push_back(a);
  return argv;
}

}  // namespace tippe::sweep_runs

// The build found MPI, so mpirun must be there too (openmpi-bin): its absence is a failure.
#define REQUIRE_MPIRUN()                                \
  ASSERT_FALSE(tippe::sweep_runs::mpirun_path().empty()) \
      << "MPI was found at build time but mpirun is not on PATH"
