// Output directories own only their files: a randomized property test (random contents, overlaps of inputs and outputs, signals) that no file tippe did not write changes; a signal ends an engine's long stretch between samples; a symbolic link in a report's directory is read through.
#include <gtest/gtest.h>
#include <signal.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <map>
#include <random>
#include <string>
#include <thread>
#include <vector>

#include <nlohmann/json.hpp>

#include "harness/io/output_dir.h"
#include "tests/support/files.h"
#include "tests/support/process.h"

namespace test_output_ownership {

namespace fs = std::filesystem;

namespace {

const std::string kSource = TIPPE_SOURCE_DIR;
const std::string kBinary = std::string(TIPPE_BINARY_DIR) + "/tippe";
const std::string kToy = kSource + "/harness/scenes/toy.toml";

std::vector<std::string> tippe_argv(const std::vector<std::string>& args) {
  std::vector<std::string> argv = {kBinary};
  argv.insert(argv.end(), args.begin(), args.end());
  return argv;
}

// Every regular file and symbolic link under `root` (not following links), by relative name: its
// bytes, or "-> TARGET" for a link.
std::map<std::string, std::string> snapshot(const fs::path& root) {
  std::map<std::string, std::string> out;
  std::error_code ec;
  for (auto it = fs::recursive_directory_iterator(root, ec); it != fs::recursive_directory_iterator(); it.increment(ec)) {
    const fs::path p = it->path();
    const std::string rel = p.lexically_relative(root).string();
    if (fs::is_symlink(fs::symlink_status(p)))
      out[rel] = "-> " + fs::read_symlink(p).string();
    else if (fs::is_regular_file(fs::symlink_status(p)))
      out[rel] = slurp(p);
  }
  return out;
}

// The names the marker of `dir` lists (what tippe wrote there last), plus the marker itself.
std::vector<std::string> tippe_names(const fs::path& dir) {
  std::vector<std::string> names;
  const std::string text = slurp(dir / tippe::kOutputMarker);
  if (text.empty()) return names;
  names.push_back(tippe::kOutputMarker);
  // The parsed marker outlives the loop (a range over a temporary's member would not).
  const nlohmann::json marker = nlohmann::json::parse(text);
  for (const auto& f : marker.at("files")) names.push_back(f.get<std::string>());
  return names;
}

bool under_any(const std::string& rel, const std::vector<std::string>& prefixes) {
  return std::any_of(prefixes.begin(), prefixes.end(), [&](const std::string& p) {
    return rel == p || rel.compare(0, p.size() + 1, p + "/") == 0;
  });
}

}  // namespace

// Random trials: a directory tree of user files, sometimes an earlier tippe output, the scene
// somewhere in it (or out of it), a command (run, compare, export-mjcf) whose --out is chosen
// among those paths, and sometimes a SIGTERM or SIGINT while it runs. Whatever happens, every
// file that tippe did not write keeps its bytes, and the exit code is 0, 2 or 128 + the signal.
// Seeded: a failure names its trial and seed, and reruns the same.
TEST(OutputOwnership, NoFileTippeDidNotWriteChanges) {
  const unsigned seed = 20261203;
  std::mt19937 rng(seed);
  auto pick = [&](int n) { return static_cast<int>(rng() % static_cast<unsigned>(n)); };
  int written = 0, refused = 0, signalled = 0;
  for (int trial = 0; trial < 24; ++trial) {
    SCOPED_TRACE("trial " + std::to_string(trial) + " of seed " + std::to_string(seed));
    TempDir tmp{"tippe-own"};
    const fs::path root = tmp.path() / "w";
    fs::create_directories(root);
    // Random user files: at the top, in p/ and in p/sub/, some empty directories.
    const std::vector<std::string> places = {"", "p/", "p/sub/", "q/"};
    for (int k = pick(5); k > 0; --k)
      spit(root / (places[pick(4)] + "user" + std::to_string(pick(1000)) + (pick(2) ? ".txt" : ".csv")),
           std::string(static_cast<size_t>(pick(200)), static_cast<char>('a' + pick(26))));
    if (pick(3) == 0) fs::create_directories(root / "p/empty");
    // The scene: outside, in p/, or in q/.
    const std::vector<std::string> scene_places = {"scene.toml", "p/my.toml", "q/top.toml"};
    const fs::path scene = root / scene_places[pick(3)];
    spit(scene, slurp(kToy));
    // Sometimes an earlier tippe output: a run or a comparison in o/ or p/.
    const std::vector<std::string> earlier_places = {"o", "p"};
    const fs::path err = tmp.path() / "err.txt";
    if (pick(2) == 0) {
      const fs::path earlier = root / earlier_places[pick(2)];
      const bool run = pick(2) == 0;
      std::vector<std::string> args = {run ? "run" : "compare", kToy, "--set", "run.duration=0.01", "--out", earlier.string()};
      if (!run) args.insert(args.end(), {"--engines", "ode", "--no-cache", "--no-plots"});
      wait_process_within(spawn_process(tippe_argv(args), "/dev/null", err), 60);
    }
    // What tippe did not write: everything but the files the markers list.
    std::vector<std::string> own;
    for (const std::string d : {"o", "p", "q", "fresh"})
      for (const std::string& n : tippe_names(root / d)) own.push_back(d + "/" + n);
    std::map<std::string, std::string> before;
    for (const auto& [name, bytes] : snapshot(root))
      if (!under_any(name, own)) before[name] = bytes;

    // The command and its --out: a fresh directory, one of the above, the scene's directory, the
    // working tree itself, or (export-mjcf) the scene file.
    const std::vector<fs::path> outs = {root / "fresh", root / "o", root / "p", root / "q", root, scene.parent_path()};
    const int command = pick(3);
    std::vector<std::string> args;
    if (command == 2) {
      const fs::path out = pick(2) ? scene : root / "fresh.xml";
      args = {"export-mjcf", scene.string(), "--out", out.string()};
    } else {
      const fs::path out = outs[pick(static_cast<int>(outs.size()))];
      // Sometimes long enough (2 s of ODE) for a signal to land mid-run.
      const std::string duration = pick(3) == 0 ? "run.duration=2" : "run.duration=0.02";
      args = {command == 0 ? "run" : "compare", scene.string(), "--set", duration, "--out", out.string()};
      if (command == 0) args.insert(args.end(), {"--engine", "ode"});
      else args.insert(args.end(), {"--engines", "ode", "--no-cache", "--no-plots", "--no-self-check"});
    }
    const pid_t pid = spawn_process(tippe_argv(args), "/dev/null", err);
    int sig = 0;
    if (pick(3) == 0) {
      sig = pick(2) ? SIGTERM : SIGINT;
      std::this_thread::sleep_for(std::chrono::milliseconds(pick(300)));
      ::kill(pid, sig);
    }
    const ChildExit e = wait_process_within(pid, 60);
    ASSERT_FALSE(e.timed_out) << slurp(err);
    // A signal before the handlers were installed ends the process by the signal itself.
    EXPECT_TRUE(e.code == 0 || e.code == 2 || (sig && (e.code == 128 + sig || e.signal == sig)))
        << "exit " << e.code << " signal " << e.signal << ": " << slurp(err);
    EXPECT_EQ(slurp(err).find("internal"), std::string::npos) << slurp(err);
    written += e.code == 0;
    refused += e.code == 2;
    signalled += sig && e.code != 0 && e.code != 2;
    const std::map<std::string, std::string> after = snapshot(root);
    for (const auto& [name, bytes] : before) {
      const auto it = after.find(name);
      ASSERT_NE(it, after.end()) << name << " is gone after: " << args[0] << " ... " << args[args.size() - 1] << "\n"
                                 << slurp(err);
      EXPECT_EQ(it->second, bytes) << name << " changed";
    }
    // Nothing left beside the directories (staging, temporaries).
    for (const auto& [name, bytes] : after) {
      EXPECT_EQ(name.find(".staging-"), std::string::npos) << name;
      EXPECT_EQ(name.find(".tmp."), std::string::npos) << name;
    }
  }
  // The trials cover the three outcomes: written, refused, ended by a signal.
  std::printf("%d written, %d refused, %d ended by a signal\n", written, refused, signalled);
  EXPECT_GT(written, 0);
  EXPECT_GT(refused, 0);
  EXPECT_GT(signalled, 0);
}

// An engine run's samples far apart (ten seconds of ODE steps between two): a SIGTERM ends it
// within a second, from inside the stepping loop, the earlier run's files as they were.
TEST(OutputOwnership, ASignalEndsAnEngineBetweenSamplesWithinASecond) {
  TempDir dir{"tippe-own"};
  const fs::path out = dir.path() / "out", err = dir.path() / "err.txt";
  for (const std::string cmd : {"run", "compare"}) {
    std::vector<std::string> args = {cmd, kToy, "--set", "run.duration=20", "--set", "run.sample_interval=10", "--set",
                                     "engines.ode.timestep=1e-6", "--out", (out / cmd).string()};
    if (cmd == "run") args.insert(args.end(), {"--engine", "ode"});
    else args.insert(args.end(), {"--engines", "ode", "--no-cache", "--no-plots", "--no-self-check"});
    const pid_t pid = spawn_process(tippe_argv(args), "/dev/null", err);
    std::this_thread::sleep_for(std::chrono::milliseconds(800));
    const auto sent = std::chrono::steady_clock::now();
    ::kill(pid, SIGTERM);
    const ChildExit e = wait_process_within(pid, 10);
    const double waited = std::chrono::duration<double>(std::chrono::steady_clock::now() - sent).count();
    EXPECT_EQ(e.code, 128 + SIGTERM) << cmd << ": " << slurp(err);
    // A second is the bound the interrupt promises; 256 ODE steps take well under a millisecond.
    EXPECT_LT(waited, 1.0) << cmd;
    EXPECT_FALSE(fs::exists(out / cmd)) << cmd;
  }
}

// A report rebuilt over a comparison whose engine CSV is a symbolic link to a file elsewhere:
// read through the link, the link kept where it is, nothing made beside the directory.
TEST(OutputOwnership, ASymbolicLinkInAReportsDirectoryIsReadThrough) {
  TempDir dir{"tippe-own"};
  const fs::path cmp = dir.path() / "cmp", data = dir.path() / "data", err = dir.path() / "err.txt";
  ASSERT_EQ(wait_process_within(spawn_process(tippe_argv({"compare", kToy, "--set", "run.duration=0.05", "--engines", "ode",
                                                          "--no-cache", "--no-plots", "--out", cmp.string()}),
                                              "/dev/null", err),
                                60)
                .code,
            0)
      << slurp(err);
  fs::create_directories(data);
  fs::rename(cmp / "ode.csv", data / "ode.csv");
  fs::create_symlink(data / "ode.csv", cmp / "ode.csv");
  const std::string csv = slurp(data / "ode.csv");
  const ChildExit e = wait_process_within(spawn_process(tippe_argv({"report", cmp.string()}), "/dev/null", err), 60);
  EXPECT_EQ(e.code, 0) << slurp(err);
  EXPECT_TRUE(fs::is_symlink(cmp / "ode.csv"));
  EXPECT_EQ(fs::read_symlink(cmp / "ode.csv"), data / "ode.csv");
  EXPECT_EQ(slurp(data / "ode.csv"), csv);
  std::vector<std::string> beside;
  for (const auto& entry : fs::directory_iterator(dir.path())) beside.push_back(entry.path().filename().string());
  std::sort(beside.begin(), beside.end());
  EXPECT_EQ(beside, (std::vector<std::string>{"cmp", "data", "err.txt"}));
  std::vector<std::string> in_data;
  for (const auto& entry : fs::directory_iterator(data)) in_data.push_back(entry.path().filename().string());
  EXPECT_EQ(in_data, std::vector<std::string>{"ode.csv"});
}

}  // namespace test_output_ownership
