// Tests of sweeps over MPI ranks (harness/sweep/mpi_farm.cpp): mpirun -np 2 and 3, grids, shards, a job killed and resumed, bad input and failing references giving a local run's records; a build without MPI refuses to run as one of many ranks; only the MPI module maps libmpi.
#include <gtest/gtest.h>
#include <signal.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "harness/sweep/mpi_farm.h"
#include "harness/sweep/sweep.h"
#include "tests/support/files.h"
#include "tests/support/fixtures.h"
#include "tests/support/process.h"
#include "tests/support/sweep_runs.h"

namespace test_mpi_farm {

namespace fs = std::filesystem;
using namespace tippe;
using nlohmann::json;
using namespace tippe::sweep_runs;

namespace {

#ifdef TIPPE_HAVE_MPI

const std::string& kSource = fixtures::kSourceDir;

TEST(SweepMpi, TwoAndThreeRanksGiveTheRecordsOfOneJob) {
  REQUIRE_MPIRUN();
  TempDir dir("tippe-mpi");
  const fs::path log = dir.path() / "log";
  for (int np : {2, 3}) {
    const fs::path out = dir.path() / ("np" + std::to_string(np));
    ASSERT_EQ(run(mpirun_sweep(np, {kSmoke, "--out", out.string()}), log), 0) << slurp(log);
    EXPECT_NE(slurp(log).find(std::to_string(np - 1) + " worker rank(s) (MPI, " + std::to_string(np) + " ranks)"),
              std::string::npos)
        << slurp(log);
    expect_same_records(local_smoke(), out);
    // The references were computed once each (one cache entry per scene) and the report written.
    size_t refs = 0;
    for (const auto& e : fs::directory_iterator(out / "reference")) refs += fs::exists(e.path() / "summary.json");
    EXPECT_EQ(refs, 2u);
    EXPECT_TRUE(fs::exists(out / "index.html"));
    const json a = json::parse(slurp(local_smoke() / "sweep.json")), b = json::parse(slurp(out / "sweep.json"));
    EXPECT_EQ(a["plan_hash"], b["plan_hash"]);
  }
}

TEST(SweepMpi, GridAndCategoricalLaddersRunUnderMpiAsOneLocalRun) {
  REQUIRE_MPIRUN();
  TempDir dir("tippe-grid-mpi");
  const std::string sweep = grid_sweep(dir);
  const fs::path log = dir.path() / "log", local = dir.path() / "local", np2 = dir.path() / "np2";
  ASSERT_EQ(run(tippe_sweep({sweep, "--out", local.string(), "--jobs", "1"}), log), 0) << slurp(log);
  ASSERT_EQ(run(mpirun_sweep(2, {sweep, "--out", np2.string()}), log), 0) << slurp(log);
  expect_same_records(local, np2);
}

TEST(SweepMpi, ShardsRunUnderMpiToo) {
  REQUIRE_MPIRUN();
  TempDir dir("tippe-mpi-shard");
  const fs::path log = dir.path() / "log";
  std::vector<std::string> merge = {"--merge"};
  for (int i = 0; i < 2; ++i) {
    const std::string d = (dir.path() / ("s" + std::to_string(i))).string();
    ASSERT_EQ(run(mpirun_sweep(2, {kSmoke, "--shard", std::to_string(i) + "/2", "--out", d}), log), 0) << slurp(log);
    merge.push_back(d);
  }
  merge.insert(merge.end(), {"--out", (dir.path() / "merged").string()});
  ASSERT_EQ(run(tippe_sweep(merge), log), 0) << slurp(log);
  expect_same_records(local_smoke(), dir.path() / "merged");
}

// The pids of the processes whose parent is `parent` (mpirun's ranks).
std::vector<pid_t> children_of(pid_t parent) {
  std::vector<pid_t> out;
  for (const auto& e : fs::directory_iterator("/proc")) {
    const std::string name = e.path().filename();
    if (name.find_first_not_of("0123456789") != std::string::npos) continue;
    std::ifstream stat(e.path() / "stat");
    std::string line;
    std::getline(stat, line);
    const size_t close = line.rfind(')');
    if (close == std::string::npos) continue;
    std::istringstream rest(line.substr(close + 2));
    char state = 0;
    pid_t ppid = 0;
    rest >> state >> ppid;
    if (ppid == parent) out.push_back(static_cast<pid_t>(std::stol(name)));
  }
  return out;
}

TEST(SweepMpi, AJobKilledMidwayCompletesWhenStartedAgainWithNothingLostOrTwice) {
  REQUIRE_MPIRUN();
  TempDir dir("tippe-mpi-kill");
  // Twelve ODE points of ~0.2 s each: long enough to kill the job between two of them.
  std::string values;
  for (int i = 0; i < 12; ++i) values += (i ? ", " : "") + std::to_string(1.0e-5 + i * 1.0e-6);
  const std::string sweep = dir.write("kill.toml", "description = \"killed midway\"\nscenes = [ { file = \"" + kSource +
                                                       "/harness/scenes/toy.toml\", duration = 2.0 } ]\n"
                                                       "[[setup]]\nname = \"ode\"\nengine = \"ode\"\n"
                                                       "ladder.key = \"engines.ode.timestep\"\nladder.values = [" +
                                                       values + "]\n");
  const fs::path out = dir.path() / "out", log = dir.path() / "log";
  const pid_t job = spawn_process(mpirun_sweep(3, {sweep, "--out", out.string()}), log, log);
  // Kill every rank (a node lost, a job cancelled) once some but not all points are in.
  size_t seen = 0;
  for (int i = 0; i < 12000 && seen < 3; ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
    seen = lines_of(out / "records.jsonl").size();
  }
  ASSERT_GE(seen, 3u) << "the job never got going: " << slurp(log);
  const std::vector<pid_t> ranks = children_of(job);
  EXPECT_EQ(ranks.size(), 3u);
  for (pid_t r : ranks) ::kill(r, SIGKILL);
  EXPECT_NE(wait_process(job).code, 0) << "mpirun should report its killed ranks";
  const size_t after_kill = lines_of(out / "records.jsonl").size();
  ASSERT_LT(after_kill, 12u) << "the job finished before it was killed; the test proves nothing";

  ASSERT_EQ(run(mpirun_sweep(3, {sweep, "--out", out.string()}), log), 0) << slurp(log);
  EXPECT_NE(slurp(log).find("(" + std::to_string(after_kill) + " from an earlier run, " +
                            std::to_string(12 - after_kill) + " run now)"),
            std::string::npos)
      << slurp(log);
  const auto resumed = records_by_id(out);  // a point written twice fails here
  EXPECT_EQ(resumed.size(), 12u);
  EXPECT_EQ(lines_of(out / "records.jsonl").size(), 12u);

  // And they are the records of an uninterrupted local run.
  const fs::path local = dir.path() / "local";
  ASSERT_EQ(run(tippe_sweep({sweep, "--out", local.string(), "--jobs", "2"}), log), 0) << slurp(log);
  expect_same_records(local, out);
}

TEST(SweepMpi, BadInputStopsEveryRankWithTheMessageOnce) {
  REQUIRE_MPIRUN();
  TempDir dir("tippe-mpi-bad");
  const fs::path log = dir.path() / "log";
  // --jobs is for one process.
  EXPECT_EQ(run(mpirun_sweep(2, {kSmoke, "--out", (dir.path() / "a").string(), "--jobs", "2"}), log), 2);
  EXPECT_NE(slurp(log).find("--jobs is for a run in one process"), std::string::npos) << slurp(log);
  // A malformed sweep file: every rank stops, the message is printed once (by rank 0).
  const std::string bad = dir.write("bad.toml", "description = \"x\"\nrepeats = 0\n");
  EXPECT_EQ(run(mpirun_sweep(3, {bad, "--out", (dir.path() / "b").string()}), log), 2);
  const std::string text = slurp(log);
  const size_t first = text.find("tippe: error: ");
  ASSERT_NE(first, std::string::npos) << text;
  EXPECT_EQ(text.find("tippe: error: ", first + 1), std::string::npos) << "printed more than once:\n" << text;
  EXPECT_NE(text.find("repeats"), std::string::npos) << text;
  EXPECT_FALSE(fs::exists(dir.path() / "b"));
  // An output directory of another sweep: refused by rank 0 before anything is written.
  const fs::path other = dir.path() / "other";
  fs::create_directories(other);
  spit(other / "sweep.json", "{\"sweep_hash\": \"0000000000000000\", \"plan_hash\": \"0\"}\n");
  EXPECT_EQ(run(mpirun_sweep(2, {kSmoke, "--out", other.string()}), log), 2);
  EXPECT_NE(slurp(log).find("was started with another sweep file"), std::string::npos) << slurp(log);
  EXPECT_FALSE(fs::exists(other / "records.jsonl"));
}

TEST(SweepMpi, AReferenceFailingOnAWorkerIsRecordedAsALocalRunRecordsIt) {
  REQUIRE_MPIRUN();
  TempDir dir("tippe-mpi-fail");
  const std::string sweep = failing_reference_sweep(dir);
  const fs::path log = dir.path() / "log";
  const fs::path local = dir.path() / "local";
  ASSERT_EQ(run(tippe_sweep({sweep, "--out", local.string(), "--jobs", "2"}), log), 0) << slurp(log);
  for (int np : {2, 3}) {
    const fs::path out = dir.path() / ("np" + std::to_string(np));
    const ChildExit e = wait_process_within(spawn_process(mpirun_sweep(np, {sweep, "--out", out.string()}), log, log), 120);
    ASSERT_FALSE(e.timed_out) << "the job hung:\n" << slurp(log);
    EXPECT_EQ(e.code, 0) << slurp(log);
    const std::string text = slurp(log);
    EXPECT_EQ(text.find("tippe: warning: "), text.rfind("tippe: warning: ")) << "printed more than once:\n" << text;
    expect_failed_reference_recorded(out, text);
    expect_same_records(local, out);
  }
}

TEST(SweepMpi, OneRankRunsAsALocalSweep) {
  REQUIRE_MPIRUN();
  TempDir dir("tippe-mpi-one");
  const fs::path out = dir.path() / "out", log = dir.path() / "log";
  ASSERT_EQ(run(mpirun_sweep(1, {kSmoke, "--out", out.string(), "--jobs", "1"}), log), 0) << slurp(log);
  EXPECT_NE(slurp(log).find("with 1 job(s)"), std::string::npos) << slurp(log);
  expect_same_records(local_smoke(), out);
}

// The tippe command maps no MPI library at start-up (a reference run, --version): only the MPI
// module links it, opened under a launcher; the loader lists what the command needs.
TEST(SweepMpi, TheCommandMapsNoMpiLibraryUntilALauncherStartsIt) {
  TempDir dir("tippe-mpi-maps");
  const fs::path log = dir.path() / "log";
  ::setenv("LD_TRACE_LOADED_OBJECTS", "1", 1);
  const int rc = run({fixtures::kTippeBinary, "--version"}, log);
  ::unsetenv("LD_TRACE_LOADED_OBJECTS");
  ASSERT_EQ(rc, 0) << slurp(log);
  EXPECT_NE(slurp(log).find("libtippe_runtime"), std::string::npos) << slurp(log);
  EXPECT_EQ(slurp(log).find("libmpi"), std::string::npos) << slurp(log);
  EXPECT_EQ(slurp(log).find("libopen-pal"), std::string::npos) << slurp(log);
  EXPECT_FALSE(mpi_library_version().empty());  // the module opens and answers
}

#else

TEST(SweepMpi, ABuildWithoutMpiRefusesToRunAsOneOfManyRanks) {
  TempDir dir("tippe-nompi");
  ::setenv("OMPI_COMM_WORLD_SIZE", "2", 1);
  const fs::path log = dir.path() / "log";
  const int rc = run(tippe_sweep({kSmoke, "--out", (dir.path() / "out").string()}), log);
  ::unsetenv("OMPI_COMM_WORLD_SIZE");
  EXPECT_EQ(rc, 2);
  EXPECT_NE(slurp(log).find("built without MPI"), std::string::npos) << slurp(log);
  EXPECT_FALSE(fs::exists(dir.path() / "out"));
  EXPECT_EQ(mpi_library_version(), "");
}

#endif

}  // namespace

}  // namespace test_mpi_farm
