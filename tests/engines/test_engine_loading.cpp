// Which engine libraries a `tippe` process maps (a reference run and `tippe --version` need none), the engine modules across their boundary, and the BLAS threads a Siconos run starts.
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <sstream>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "engines/core/fixed_step.h"
#include "engines/mujoco/mujoco_api.h"
#include "engines/core/registry.h"
#include "engines/core/step_checks.h"
#include "tests/support/mapped_files.h"
#include "tests/support/process.h"
#include "harness/io/scene_io.h"
#include "harness/scene/resolve.h"

namespace test_engine_loading {

namespace {

namespace fs = std::filesystem;

// One name part of each engine's own libraries (Bullet, ODE, MuJoCo, DART, Simbody, Siconos).
const char* const kEngineLibraries[] = {"libBullet", "libode", "libmujoco", "libdart", "libSimTK", "libsiconos"};

// One directory per test: CTest runs this program's tests at the same time, each in its own process.
fs::path scratch() {
  const fs::path dir = fs::path(::testing::TempDir()) /
                       ("tippe_engine_loading_" + std::string(::testing::UnitTest::GetInstance()->current_test_info()->name()));
  fs::create_directories(dir);
  return dir;
}

// The shared objects the dynamic loader opened for `tippe ARGS...`, one line each, as the
// loader itself reports them (LD_DEBUG=files: "file=NAME [0];  needed by ..." or "... dynamically
// loaded by ..."), so a library opened later by dlopen counts as well as a linked one.
std::string loaded_libraries(const std::vector<std::string>& args) {
  const fs::path dir = scratch();
  std::vector<std::string> argv = {"env", "-u", "TIPPE_ENGINE_PATH", "LD_DEBUG=files", std::string(TIPPE_BINARY_DIR) + "/tippe"};
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

// Every engine adapter is a module the registry opens on the engine's first use: a process that
// runs only the reference, or prints the version, maps no engine library (and so pays none of their
// relocations at start-up: BENCHMARKS.md, "Engines loaded on demand").
TEST(EngineLoading, ReferenceRunAndVersionMapNoEngineLibrary) {
  if (!tippe::engines_in_modules()) GTEST_SKIP() << "engines linked in (TIPPE_ENGINE_MODULES=OFF)";
  for (const auto& args : {run_args("analytic"), std::vector<std::string>{"--version"}}) {
    const std::string files = loaded_libraries(args);
    ASSERT_FALSE(files.empty()) << "LD_DEBUG=files reported nothing";
    for (const char* lib : kEngineLibraries)
      EXPECT_EQ(files.find(lib), std::string::npos) << "tippe " << args[0] << " mapped " << lib << ":\n" << files;
  }
}

// A module that is not where the registry looks: the command says which engine, which file and
// where it looked, and exits 2 (bad installation, not a bug); the reference still runs.
TEST(EngineLoading, MissingModuleIsAClearErrorAndExit2) {
  if (!tippe::engines_in_modules()) GTEST_SKIP() << "engines linked in (TIPPE_ENGINE_MODULES=OFF)";
  const fs::path dir = scratch();
  const fs::path empty = dir / "no-modules";
  fs::create_directories(empty);
  std::vector<std::string> argv = {"env", "TIPPE_ENGINE_PATH=" + empty.string(), std::string(TIPPE_BINARY_DIR) + "/tippe"};
  std::vector<std::string> args = run_args("ode");
  argv.insert(argv.end(), args.begin(), args.end());
  ChildExit e = wait_process_within(spawn_process(argv, dir / "out.txt", dir / "err.txt"), 120);
  EXPECT_EQ(e.code, 2);
  std::ifstream in(dir / "err.txt");
  std::stringstream err;
  err << in.rdbuf();
  EXPECT_NE(err.str().find("engine \"ode\""), std::string::npos) << err.str();
  EXPECT_NE(err.str().find((empty / "libtippe_engine_ode.so").string()), std::string::npos) << err.str();

  argv.resize(3);
  args = run_args("analytic");
  argv.insert(argv.end(), args.begin(), args.end());
  e = wait_process_within(spawn_process(argv, dir / "out.txt", dir / "err.txt"), 120);
  EXPECT_EQ(e.code, 0);
}

// A module the loader refuses (not a shared object), and a shared object without the entry point:
// the command names the module's path and the loader's reason, and exits 2.
TEST(EngineLoading, UnloadableModuleNamesThePathAndTheLoadersReason) {
  if (!tippe::engines_in_modules()) GTEST_SKIP() << "engines linked in (TIPPE_ENGINE_MODULES=OFF)";
  const fs::path dir = scratch();
  const fs::path bad = dir / "bad-modules";
  fs::create_directories(bad);
  const fs::path module = bad / "libtippe_engine_ode.so";
  struct Case {
    const char* what;
    std::string want;
  };
  // The loader's own words for a file that is no shared object vary ("file too short", "invalid
  // ELF header"): the registry's part of the message is what is asked for.
  for (const Case& c : {Case{"text", "cannot load its module"}, Case{"other", "has no entry point tippe_engine_ode"}}) {
    SCOPED_TRACE(c.what);
    fs::remove(module);
    if (std::string(c.what) == "text") {
      std::ofstream(module) << "not a shared object\n";  // what the loader refuses
    } else {
      // A real module, of another engine: it loads, and has no tippe_engine_ode. (Not a copy of
      // the runtime: a second copy of the bench's own code in one process is an ODR violation.)
      fs::copy_file(fs::path(TIPPE_BINARY_DIR) / "lib" / "tippe" / "engines" / "libtippe_engine_bullet.so", module);
    }
    std::vector<std::string> argv = {"env", "TIPPE_ENGINE_PATH=" + bad.string(), std::string(TIPPE_BINARY_DIR) + "/tippe"};
    const std::vector<std::string> args = run_args("ode");
    argv.insert(argv.end(), args.begin(), args.end());
    const ChildExit e = wait_process_within(spawn_process(argv, dir / "out.txt", dir / "err.txt"), 120);
    EXPECT_EQ(e.code, 2);
    std::ifstream in(dir / "err.txt");
    std::stringstream err;
    err << in.rdbuf();
    EXPECT_NE(err.str().find(module.string()), std::string::npos) << err.str();
    EXPECT_NE(err.str().find(c.want), std::string::npos) << err.str();
  }
}

// The lines of this process's /proc/self/maps that name an engine's library.
std::string mapped_engine_libraries() {
  return mapped_lines(std::vector<std::string>(std::begin(kEngineLibraries), std::end(kEngineLibraries)));
}

tippe::Scene toy() {
  return tippe::load_scene(std::string(TIPPE_SOURCE_DIR) + "/harness/scenes/toy.toml", {"run.duration=0.01"});
}

// In this process (the test program reaches the engines through the registry alone): the
// reference maps no engine library, an engine's first use maps its own. Before the other
// in-process tests: a whole-program run (not CTest's one test per process) has loaded no module yet.
TEST(EngineModules, ReferenceInProcessMapsNoEngineLibraryUntilAnEngineIsMade) {
  if (!tippe::engines_in_modules()) GTEST_SKIP() << "engines linked in (TIPPE_ENGINE_MODULES=OFF)";
  if (tippe::engine_loaded("ode")) GTEST_SKIP() << "an earlier test of this process loaded the ode module";
  const tippe::Scene scene = toy();
  auto ref = tippe::make_simulator("analytic", scene);
  ref->advance_to(0.001);
  if (mapped_engine_libraries().empty()) {
    EXPECT_FALSE(tippe::engine_loaded("ode"));
  } else {
    // Another engine's module from an earlier test in this process: ODE's at least is not there.
    EXPECT_EQ(mapped_engine_libraries().find("libode"), std::string::npos) << mapped_engine_libraries();
  }
  auto ode = tippe::make_simulator("ode", scene);
  EXPECT_TRUE(tippe::engine_loaded("ode"));
  EXPECT_NE(mapped_engine_libraries().find("libode"), std::string::npos) << mapped_engine_libraries();
}

// One type on both sides of the boundary: a simulator made in a module is the runtime's
// CheckedSimulator (FixedStepSimulator for the fixed-step engines) to dynamic_cast, and an
// exception a module throws is caught here by its type.
TEST(EngineModules, TypesAndExceptionsCrossTheModuleBoundary) {
  const tippe::Scene scene = toy();
  for (const std::string& name : tippe::engine_names()) {
    SCOPED_TRACE(name);
    const auto sim = tippe::make_simulator(name, scene);
    ASSERT_TRUE(sim);
    EXPECT_EQ(sim->engine(), name);
    EXPECT_NE(dynamic_cast<const tippe::CheckedSimulator*>(sim.get()), nullptr);
    const bool fixed_step = name == "bullet" || name == "ode" || name == "mujoco" || name == "dart";
    EXPECT_EQ(dynamic_cast<const tippe::FixedStepSimulator*>(sim.get()) != nullptr, fixed_step);
    // A bad key of the engine's table: the module's settings reader throws std::invalid_argument.
    tippe::Scene bad = scene;
    bad.engines[name]["no_such_key"] = 1.0;
    EXPECT_THROW(tippe::engine_info(name).validate(bad), std::invalid_argument);
    EXPECT_THROW(tippe::make_simulator(name, bad), std::invalid_argument);
  }
  // The module's own exception type, thrown in libtippe_engine_mujoco.so.
  EXPECT_THROW(tippe::mujoco_api().import_top(std::string(TIPPE_SOURCE_DIR) + "/no_such_model.xml", "", ""),
               tippe::MjcfImportError);
}

// Names and module files come from the registry without loading anything.
TEST(EngineModules, NamesWithoutLoading) {
  EXPECT_EQ(tippe::available_engines().front(), tippe::reference_engine().name);
  EXPECT_TRUE(tippe::engine_loaded(tippe::reference_engine().name));
  EXPECT_EQ(tippe::engine_module_file("bullet"), "libtippe_engine_bullet.so");
  EXPECT_FALSE(tippe::engine_loaded("no_such_engine"));
  EXPECT_EQ(tippe::find_engine("no_such_engine"), nullptr);
}

namespace {

// What a `tippe run` of Siconos showed of its threads: the most /proc/PID/status listed while it
// ran (polled every 0.5 ms), and whether OpenBLAS was among its mapped files.
struct ThreadsSeen {
  int most = 0;
  bool openblas = false;
  int exit_code = -1;
};

ThreadsSeen siconos_run_threads(const std::string& blas_threads) {
  const fs::path dir = scratch();
  // "" runs tippe without the variable; otherwise with the value given.
  std::vector<std::string> argv = {"env", "-u", "OPENBLAS_NUM_THREADS"};
  if (!blas_threads.empty()) argv.push_back("OPENBLAS_NUM_THREADS=" + blas_threads);
  argv.push_back(std::string(TIPPE_BINARY_DIR) + "/tippe");
  // Long enough (0.1-0.2 s, more under the sanitizers) for thousands of polls after the module loads.
  for (const std::string& a : {std::string("run"), std::string(TIPPE_SOURCE_DIR) + "/harness/scenes/toy_viscous.toml",
                               std::string("--engine"), std::string("siconos"), std::string("--set"),
                               std::string("run.duration=0.5"), std::string("--out"),
                               (dir / ("run-" + blas_threads)).string(), std::string("--quiet")})
    argv.push_back(a);
  const pid_t pid = spawn_process(argv, dir / "out.txt", dir / "err.txt");
  ThreadsSeen seen;
  const std::string status_file = "/proc/" + std::to_string(pid) + "/status";
  const std::string maps_file = "/proc/" + std::to_string(pid) + "/maps";
  const auto end = std::chrono::steady_clock::now() + std::chrono::seconds(300);
  int status = 0;
  while (::waitpid(pid, &status, WNOHANG) != pid) {
    if (std::chrono::steady_clock::now() > end) {
      ::kill(pid, SIGKILL);
      wait_process(pid);
      ADD_FAILURE() << "tippe run --engine siconos still running after 300 s";
      return seen;
    }
    std::ifstream in(status_file);
    std::string line;
    while (std::getline(in, line))
      if (line.rfind("Threads:", 0) == 0) seen.most = std::max(seen.most, std::stoi(line.substr(8)));
    if (!seen.openblas) {
      std::ifstream maps(maps_file);
      std::stringstream text;
      text << maps.rdbuf();
      seen.openblas = text.str().find("openblas") != std::string::npos;
    }
    std::this_thread::sleep_for(std::chrono::microseconds(500));
  }
  seen.exit_code = exit_of(status).code;
  return seen;
}

}  // namespace

// A Siconos run in a `tippe` process starts no BLAS thread team (engines/core/process.h): run
// without OPENBLAS_NUM_THREADS, its most threads are those of a run with the variable at 1; the
// control, the variable at 2, shows that the probe sees a team when OpenBLAS starts one.
TEST(EngineProcess, SiconosRunStartsNoBlasThreadTeam) {
  const std::vector<std::string> names = tippe::available_engines();
  if (std::find(names.begin(), names.end(), "siconos") == names.end()) GTEST_SKIP() << "no Siconos in this build";
  // OpenBLAS starts no team on one CPU, whatever the variable says.
  if (std::thread::hardware_concurrency() < 2) GTEST_SKIP() << "one CPU: OpenBLAS starts no thread team";
  const ThreadsSeen one = siconos_run_threads("1"), unset = siconos_run_threads(""), two = siconos_run_threads("2");
  ASSERT_EQ(one.exit_code, 0);
  ASSERT_EQ(unset.exit_code, 0);
  ASSERT_EQ(two.exit_code, 0);
  if (!one.openblas) GTEST_SKIP() << "Siconos' BLAS here is not OpenBLAS (the libblas.so.3 alternative)";
  EXPECT_GT(two.most, one.most) << "the control: with OPENBLAS_NUM_THREADS=2 the probe saw no more threads";
  EXPECT_EQ(unset.most, one.most) << "without OPENBLAS_NUM_THREADS, a Siconos run had " << unset.most
                                  << " threads at most, against " << one.most << " with it at 1";
}

}  // namespace test_engine_loading
