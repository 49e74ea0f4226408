// Output directories: one writer at a time, a run's files replaced as one unit, special files written where they are.
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/resource.h>
#include <sys/stat.h>

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <string>
#include <thread>
#include <vector>

#include "harness/io/output_dir.h"
#include "harness/records/records.h"
#include "tests/support/files.h"
#include "tests/support/process.h"

namespace test_output_dir {

namespace fs = std::filesystem;
using namespace tippe;

namespace {

const std::string kSource = TIPPE_SOURCE_DIR;
const std::string kBinary = std::string(TIPPE_BINARY_DIR) + "/tippe";
const std::string kToy = kSource + "/harness/scenes/toy.toml";

std::vector<std::string> tippe_argv(const std::vector<std::string>& args) {
  std::vector<std::string> argv = {kBinary};
  argv.insert(argv.end(), args.begin(), args.end());
  return argv;
}

ChildExit run_tippe(const std::vector<std::string>& args, const fs::path& err) {
  return wait_process_within(spawn_process(tippe_argv(args), "/dev/null", err), 300);
}

// Every entry under `root` (files and directories, names relative to it), sorted.
std::vector<std::string> tree(const fs::path& root) {
  std::vector<std::string> out;
  for (const auto& e : fs::recursive_directory_iterator(root)) out.push_back(fs::relative(e.path(), root).string());
  std::sort(out.begin(), out.end());
  return out;
}

// Names under `root` that a run must never leave behind: temporaries and staging directories.
std::vector<std::string> leftovers(const fs::path& root) {
  std::vector<std::string> out;
  for (const std::string& name : tree(root))
    if (name.find(".tmp.") != std::string::npos || name.find(".staging-") != std::string::npos) out.push_back(name);
  return out;
}

// Every file's bytes under `root`, by relative name.
std::vector<std::pair<std::string, std::string>> contents(const fs::path& root) {
  std::vector<std::pair<std::string, std::string>> out;
  for (const std::string& name : tree(root))
    if (fs::is_regular_file(root / name)) out.emplace_back(name, slurp(root / name));
  return out;
}

// A run of the toy top long enough (seconds of ODE at a small step) to be interrupted midway.
const std::vector<std::string> kLongRun = {"--engine", "ode", "--set", "run.duration=30",
                                           "--set", "engines.ode.timestep=1e-5"};

}  // namespace

TEST(OutputDir, ASecondWriterIsRefusedWhateverHappensToFilesInside) {
  TempDir dir{"tippe-outdir"};
  const fs::path out = dir.path() / "out";
  OutputDir first(out, OutputKind::Run);
  EXPECT_TRUE(fs::is_directory(out));
  // The lock is the directory's own: no file in it to delete.
  EXPECT_TRUE(fs::is_empty(out));
  EXPECT_THROW(OutputDir second(out, OutputKind::Run), OutputError);
  const fs::path err = dir.path() / "err.txt";
  const ChildExit e = run_tippe({"run", kToy, "--set", "run.duration=0.01", "--out", out.string()}, err);
  EXPECT_EQ(e.code, 2) << slurp(err);
  EXPECT_NE(slurp(err).find("in use by another tippe"), std::string::npos) << slurp(err);
}

TEST(OutputDir, ASwapReplacesTheWholeSetAndLeavesNothingBeside) {
  TempDir dir{"tippe-outdir"};
  const fs::path out = dir.path() / "out";
  {
    OutputDir d(out, OutputKind::Run);
    const fs::path s = d.stage(false);
    spit(s / "old.txt", "old");
    spit(s / "kept.txt", "kept");
    d.commit();
  }
  EXPECT_EQ(tree(out), (std::vector<std::string>{kOutputMarker, "kept.txt", "old.txt"}));
  {
    OutputDir d(out, OutputKind::Run);
    const fs::path s = d.stage(false);
    EXPECT_EQ(s.parent_path(), fs::absolute(dir.path()));
    spit(s / "new.txt", "new");
    EXPECT_TRUE(fs::exists(out / "old.txt")) << "nothing changes before the commit";
    d.commit();
  }
  EXPECT_EQ(tree(out), (std::vector<std::string>{kOutputMarker, "new.txt"}));
  EXPECT_TRUE(leftovers(dir.path()).empty());
  {
    // A unit rebuilt beside the records keeps them, as links until replaced.
    OutputDir d(out, OutputKind::Run);
    const fs::path s = d.stage(true);
    EXPECT_EQ(slurp(s / "new.txt"), "new");
    write_file_atomic((s / "report.md").string(), "report");
    d.commit();
  }
  EXPECT_EQ(tree(out), (std::vector<std::string>{kOutputMarker, "new.txt", "report.md"}));
  EXPECT_TRUE(leftovers(dir.path()).empty());
}

TEST(OutputDir, WithoutACommitTheOldSetStaysAndANewEmptyDirectoryGoes) {
  TempDir dir{"tippe-outdir"};
  const fs::path out = dir.path() / "out", fresh = dir.path() / "fresh";
  {
    OutputDir d(out, OutputKind::Run);
    spit(d.stage(false) / "old.txt", "old");
    d.commit();
  }
  {
    OutputDir d(out, OutputKind::Run);
    spit(d.stage(false) / "half.txt", "half");
  }
  EXPECT_EQ(tree(out), (std::vector<std::string>{kOutputMarker, "old.txt"}));
  {
    OutputDir d(fresh, OutputKind::Run);
    d.stage(false);
  }
  EXPECT_FALSE(fs::exists(fresh));
  EXPECT_TRUE(leftovers(dir.path()).empty());
}

TEST(OutputDir, StagingThatAKilledRunLeftIsRemoved) {
  TempDir dir{"tippe-outdir"};
  const fs::path out = dir.path() / "out", stale = dir.path() / ".out.staging-999999999";
  spit(stale / "half.txt", "half");
  OutputDir d(out, OutputKind::Run);
  EXPECT_FALSE(fs::exists(stale));
}

TEST(OutputDir, AFileIsNotADirectory) {
  TempDir dir{"tippe-outdir"};
  const std::string file = dir.write("file.txt", "x");
  EXPECT_THROW(OutputDir d(file, OutputKind::Run), OutputError);
  const fs::path err = dir.path() / "err.txt";
  for (const std::string cmd : {"run", "compare"}) {
    std::vector<std::string> args = {cmd, kToy, "--set", "run.duration=0.01", "--out", file};
    if (cmd == "compare") args.insert(args.end(), {"--engines", "ode", "--no-cache"});
    const ChildExit e = run_tippe(args, err);
    EXPECT_EQ(e.code, 2) << cmd << ": " << slurp(err);
    EXPECT_NE(slurp(err).find("not a directory"), std::string::npos) << slurp(err);
    EXPECT_EQ(slurp(file), "x");
  }
}

TEST(OutputDir, OutThroughASymbolicLinkWritesTheDirectoryItNames) {
  TempDir dir{"tippe-outdir"};
  const fs::path target = dir.path() / "target", link = dir.path() / "link", err = dir.path() / "err.txt";
  fs::create_directory(target);
  fs::create_directory_symlink(target, link);
  const ChildExit e = run_tippe({"run", kToy, "--set", "run.duration=0.01", "--out", link.string()}, err);
  ASSERT_EQ(e.code, 0) << slurp(err);
  EXPECT_TRUE(fs::is_symlink(link));
  EXPECT_TRUE(fs::exists(target / "summary.json"));
  EXPECT_TRUE(leftovers(dir.path()).empty());
}

// A rerun into a finished directory, interrupted midway by SIGTERM or SIGINT, leaves the earlier
// run's files byte for byte and nothing beside them, and says it was interrupted.
TEST(OutputDir, AnInterruptedRerunLeavesTheEarlierRun) {
  TempDir dir{"tippe-outdir"};
  const fs::path out = dir.path() / "out", err = dir.path() / "err.txt";
  ASSERT_EQ(run_tippe({"run", kToy, "--engine", "ode", "--set", "run.duration=0.05", "--out", out.string()}, err).code,
            0)
      << slurp(err);
  const auto before = contents(out);
  for (const int sig : {SIGTERM, SIGINT}) {
    std::vector<std::string> args = {"run", kToy, "--out", out.string()};
    args.insert(args.end(), kLongRun.begin(), kLongRun.end());
    const pid_t pid = spawn_process(tippe_argv(args), "/dev/null", err);
    std::this_thread::sleep_for(std::chrono::milliseconds(700));
    ::kill(pid, sig);
    const ChildExit e = wait_process_within(pid, 60);
    EXPECT_EQ(e.code, 128 + sig) << slurp(err);
    EXPECT_NE(slurp(err).find("interrupted"), std::string::npos) << slurp(err);
    EXPECT_EQ(contents(out), before) << "signal " << sig;
    EXPECT_TRUE(leftovers(dir.path()).empty()) << leftovers(dir.path()).front();
  }
  // The same for a comparison, whose runs go on several threads.
  const fs::path cmp = dir.path() / "cmp";
  ASSERT_EQ(run_tippe({"compare", kToy, "--set", "run.duration=0.05", "--engines", "ode", "--no-cache", "--no-plots",
                       "--out", cmp.string()},
                      err)
                .code,
            0)
      << slurp(err);
  const auto cmp_before = contents(cmp);
  const pid_t pid = spawn_process(tippe_argv({"compare", kToy, "--set", "run.duration=30", "--set",
                                              "engines.ode.timestep=1e-5", "--engines", "ode", "--no-cache",
                                              "--no-plots", "--out", cmp.string()}),
                                  "/dev/null", err);
  std::this_thread::sleep_for(std::chrono::milliseconds(700));
  ::kill(pid, SIGTERM);
  const ChildExit e = wait_process_within(pid, 60);
  EXPECT_EQ(e.code, 128 + SIGTERM) << slurp(err);
  EXPECT_EQ(contents(cmp), cmp_before);
  EXPECT_TRUE(leftovers(dir.path()).empty());
}

// A full disk, simulated with a file size limit (SIGXFSZ ignored, so that write fails with EFBIG
// as it fails with ENOSPC): exit 2 naming the file, the earlier run intact, nothing beside it.
TEST(OutputDir, AFullDiskLeavesTheEarlierRun) {
  TempDir dir{"tippe-outdir"};
  const fs::path out = dir.path() / "out", err = dir.path() / "err.txt";
  ASSERT_EQ(run_tippe({"run", kToy, "--set", "run.duration=0.01", "--out", out.string()}, err).code, 0) << slurp(err);
  const auto before = contents(out);
  const pid_t pid = ::fork();
  if (pid == 0) {
    const int fd = ::open(err.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    ::dup2(fd, 2);
    ::signal(SIGXFSZ, SIG_IGN);
    // Below one trajectory of 2 s (2001 rows of ~450 bytes), above what the process writes before it.
    const rlimit lim{200000, 200000};
    ::setrlimit(RLIMIT_FSIZE, &lim);
    ::execl(kBinary.c_str(), kBinary.c_str(), "run", kToy.c_str(), "--set", "run.duration=2", "--out", out.c_str(),
            static_cast<char*>(nullptr));
    ::_exit(127);
  }
  const ChildExit e = wait_process_within(pid, 120);
  EXPECT_EQ(e.code, 2) << slurp(err);
  EXPECT_NE(slurp(err).find("trajectory.csv"), std::string::npos) << slurp(err);
  EXPECT_EQ(slurp(err).find("internal"), std::string::npos) << slurp(err);
  EXPECT_EQ(contents(out), before);
  EXPECT_TRUE(leftovers(dir.path()).empty());
}

TEST(ResultFile, ProblemsAreFoundBeforeAnyWork) {
  TempDir dir{"tippe-outdir"};
  EXPECT_EQ(result_file_problem((dir.path() / "new" / "deep" / "junit.xml").string()), "");
  EXPECT_EQ(result_file_problem(dir.path().string()), "is a directory");
  const std::string file = dir.write("file.txt", "x");
  EXPECT_NE(result_file_problem(file + "/junit.xml").find("is not a directory"), std::string::npos);
  EXPECT_EQ(result_file_problem("/dev/null"), "");
}

TEST(ResultFile, ALinkADeviceAndAFifoAreWrittenWhereTheyAre) {
  TempDir dir{"tippe-outdir"};
  const fs::path target = dir.path() / "target.xml", link = dir.path() / "link.xml";
  spit(target, "old");
  fs::create_symlink(target, link);
  write_result_file(link.string(), "new");
  EXPECT_TRUE(fs::is_symlink(link));
  EXPECT_EQ(slurp(target), "new");

  write_result_file("/dev/null", "discarded");
  EXPECT_TRUE(fs::is_character_file("/dev/null"));
  // /dev/full fails every write: an error naming it, and the device stays a device.
  if (fs::exists("/dev/full")) {
    EXPECT_THROW(write_result_file("/dev/full", "x"), OutputError);
    EXPECT_TRUE(fs::is_character_file("/dev/full"));
  }

  const fs::path fifo = dir.path() / "fifo";
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0644), 0);
  std::string read_back;
  std::thread reader([&] { read_back = slurp(fifo); });
  write_result_file(fifo.string(), "through the pipe");
  reader.join();
  EXPECT_EQ(read_back, "through the pipe");
  EXPECT_TRUE(fs::is_fifo(fifo));
}

TEST(ResultFile, AnUnwritableJunitIsFoundBeforeTheGateRuns) {
  TempDir dir{"tippe-outdir"};
  const std::string gate = dir.write("gate.toml", "[defaults]\nscene = \"" + kToy +
                                                      "\"\nengine = \"ode\"\nduration = 30.0\n"
                                                      "[[check]]\nname = \"slow\"\n[check.max]\ntilt_rms_error = 1\n");
  const fs::path err = dir.path() / "err.txt";
  const auto t0 = std::chrono::steady_clock::now();
  const ChildExit e = run_tippe({"gate", gate, "--no-cache", "--junit", dir.path().string()}, err);
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  EXPECT_EQ(e.code, 2) << slurp(err);
  EXPECT_NE(slurp(err).find("--junit"), std::string::npos) << slurp(err);
  EXPECT_NE(slurp(err).find("is a directory"), std::string::npos) << slurp(err);
  // A gate that ran would take seconds (30 s of the toy top on ODE and the reference).
  EXPECT_LT(seconds, 5.0) << "the gate ran before the path was checked";
}

}  // namespace test_output_dir
