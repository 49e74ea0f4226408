// Which engine libraries a `tippe` process maps: a reference run and `tippe --version` need none.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "support/process.h"

namespace {

namespace fs = std::filesystem;

// One name part of each engine's own library (Bullet's dynamics, ODE, MuJoCo, DART).
const char* const kEngineLibraries[] = {"libBulletDynamics", "libode", "libmujoco", "libdart"};

fs::path scratch() {
  const fs::path dir = fs::path(::testing::TempDir()) / "tippe_engine_loading";
  fs::create_directories(dir);
  return dir;
}

// The shared objects the dynamic loader opened for `tippe ARGS...`, one line each, as the
// loader itself reports them (LD_DEBUG=files: "file=NAME [0];  needed by ..." or "... dynamically
// loaded by ..."), so a library opened later by dlopen counts as well as a linked one.
std::string loaded_libraries(const std::vector<std::string>& args) {
  const fs::path dir = scratch();
  std::vector<std::string> argv = {"env", "LD_DEBUG=files", std::string(TIPPE_BINARY_DIR) + "/tippe"};
  argv.insert(argv.end(), args.begin(), args.end());
  const ChildExit e = wait_process_within(spawn_process(argv, dir / "out.txt", dir / "err.txt"), 120);
  EXPECT_EQ(e.code, 0) << "tippe exited with " << e.code;
  std::ifstream in(dir / "err.txt");
  std::string line, files;
  while (std::getline(in, line))
    if (line.find("file=") != std::string::npos) files += line + "\n";
  return files;
}

std::vector<std::string> run_args(const std::string& engine) {
  return {"run", std::string(TIPPE_SOURCE_DIR) + "/harness/scenes/toy.toml", "--engine", engine, "--set",
          "run.duration=0.01", "--out", (scratch() / ("run-" + engine)).string(), "--quiet"};
}

}  // namespace

// The control: the check sees an engine's library when that engine runs.
TEST(EngineLoading, AnEngineRunMapsItsLibrary) {
  const std::string files = loaded_libraries(run_args("ode"));
  ASSERT_FALSE(files.empty()) << "LD_DEBUG=files reported nothing";
  EXPECT_NE(files.find("libode"), std::string::npos) << files;
}

// Known gap (issue: engines loaded on demand): every engine adapter is linked into the tippe
// binary, so every process maps Bullet, ODE, MuJoCo and DART and their dependencies (34 shared
// objects; most of the dynamic loader's 5-8 ms for `tippe --version` on the CI machine, see
// BENCHMARKS.md). Enabled when the registry opens each engine's module on first use.
TEST(EngineLoading, DISABLED_ReferenceRunAndVersionMapNoEngineLibrary) {
  for (const auto& args : {run_args("analytic"), std::vector<std::string>{"--version"}}) {
    const std::string files = loaded_libraries(args);
    ASSERT_FALSE(files.empty()) << "LD_DEBUG=files reported nothing";
    for (const char* lib : kEngineLibraries)
      EXPECT_EQ(files.find(lib), std::string::npos) << "tippe " << args[0] << " mapped " << lib << ":\n" << files;
  }
}
