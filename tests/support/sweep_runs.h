// Running `tippe sweep` (alone or under mpirun) from the tests and comparing the records it leaves.
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
