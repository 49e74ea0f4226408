// Names read back from records never reach a gnuplot script or a path outside the record's directory.
#include <gtest/gtest.h>

#include <filesystem>
#include <stdexcept>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "harness/report/gnuplot.h"
#include "tests/support/files.h"
#include "tests/support/process.h"

namespace test_script_safety {

namespace fs = std::filesystem;
using nlohmann::json;
using namespace tippe;

namespace {

const std::string kSource = TIPPE_SOURCE_DIR;
const std::string kBinary = std::string(TIPPE_BINARY_DIR) + "/tippe";

struct Outcome {
  ChildExit exit;
  std::string err;
};

// Runs tippe with `args` in `cwd`, so that a command an attack makes run in its working directory
// would leave its file there.
Outcome run_tippe(const std::vector<std::string>& args, const fs::path& cwd) {
  std::vector<std::string> argv = {kBinary};
  argv.insert(argv.end(), args.begin(), args.end());
  const fs::path out = cwd / "stdout.txt", err = cwd / "stderr.txt";
  const fs::path old = fs::current_path();
  fs::current_path(cwd);
  const pid_t pid = spawn_process(argv, out, err);
  fs::current_path(old);
  Outcome r;
  r.exit = wait_process_within(pid, 300);
  r.err = slurp(err);
  return r;
}

// What an attacker would put in a name: end the gnuplot string, run a command, reopen a string.
std::string injection(const fs::path& marker) {
  return "x'\nsystem('touch " + marker.string() + "')\nprint '";
}

// Every regular file under `root`, relative to it.
std::vector<std::string> files_under(const fs::path& root) {
  std::vector<std::string> out;
  for (const auto& e : fs::recursive_directory_iterator(root))
    if (e.is_regular_file()) out.push_back(fs::relative(e.path(), root).string());
  std::sort(out.begin(), out.end());
  return out;
}

// A finished comparison of the reference and ODE over a short run, in dir/cmp.
fs::path make_comparison(const TempDir& dir) {
  const fs::path out = dir.path() / "cmp";
  const Outcome r = run_tippe({"compare", kSource + "/harness/scenes/source_dimensionless.toml", "--set", "run.duration=0.3",
                       "--engines", "ode", "--no-cache", "--out", out.string()},
                      dir.path());
  EXPECT_EQ(r.exit.code, 0) << r.err;
  return out;
}

}  // namespace

TEST(GnuplotLiteral, QuotesTheProgramsOwnLabels) {
  EXPECT_EQ(gp_literal("θ (rad)"), "'θ (rad)'");
  EXPECT_EQ(gp_literal("wp-toy-tilt_rms_error.svg"), "'wp-toy-tilt_rms_error.svg'");
}

TEST(GnuplotLiteral, RefusesWhatCouldEndTheStringOrBeExpanded) {
  const std::vector<std::string> bad_labels = {"a'b", "a\nb", "a\rb", "a`id`", "@macro", "$0", "a\\b", "a\"b",
                                               std::string("a\0b", 3)};
  for (const std::string& bad : bad_labels)
    EXPECT_THROW(gp_literal(bad), std::logic_error) << bad;
}

TEST(GnuplotLiteral, AColumnHeaderIsOneDataFieldWhateverItHolds) {
  EXPECT_EQ(gp_column_header("reference (analytic)"), "\"reference (analytic)\"");
  const std::string h = gp_column_header("a\"\nsystem('x')\r");
  EXPECT_EQ(h.find('\n'), std::string::npos);
  EXPECT_EQ(h.find('\r'), std::string::npos);
  EXPECT_EQ(std::count(h.begin(), h.end(), '"'), 2);
}

TEST(ScriptSafety, ThePlotScriptHoldsNoNameFromTheRecord) {
  if (gnuplot_command().empty()) GTEST_SKIP() << "gnuplot not installed";
  TempDir dir{"tippe-safety"};
  const fs::path out = make_comparison(dir);
  const std::string gp = slurp(out / "plots.gp");
  ASSERT_FALSE(gp.empty());
  EXPECT_EQ(gp.find("source_dimensionless"), std::string::npos) << gp;
  EXPECT_EQ(gp.find("ode"), std::string::npos) << gp;
  EXPECT_EQ(gp.find("analytic"), std::string::npos) << gp;
  // The titles still reach the plots, from the data files.
  const std::string svg = slurp(out / "theta.svg");
  EXPECT_NE(svg.find("reference (analytic)"), std::string::npos);
  EXPECT_NE(svg.find(">ode<"), std::string::npos);
}

TEST(ScriptSafety, ASceneNameThatWouldRunACommandIsRefusedOnReport) {
  TempDir dir{"tippe-safety"};
  const fs::path out = make_comparison(dir);
  const fs::path marker = dir.path() / "PWNED";
  json c = json::parse(slurp(out / "comparison.json"));
  c["scene_name"] = injection(marker);
  spit(out / "comparison.json", c.dump(2));
  const auto before = files_under(dir.path());
  const Outcome r = run_tippe({"report", out.string()}, dir.path());
  EXPECT_EQ(r.exit.code, 2) << r.err;
  EXPECT_NE(r.err.find("comparison.json"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("scene_name"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(marker));
  auto after = files_under(dir.path());
  EXPECT_EQ(after, before);
}

TEST(ScriptSafety, AnEngineNameThatIsAPathIsRefusedOnReport) {
  TempDir dir{"tippe-safety"};
  const fs::path out = make_comparison(dir);
  for (const std::string bad : {"x/../../escaped", "..", "reference", "ode\nset output '/tmp/x'"}) {
    json c = json::parse(slurp(out / "comparison.json"));
    c["engines"][0]["engine"] = bad;
    c["engines"][0]["summary"]["engine"] = bad;
    spit(out / "comparison.json", c.dump(2));
    const auto before = files_under(dir.path());
    const Outcome r = run_tippe({"report", out.string()}, dir.path());
    EXPECT_EQ(r.exit.code, 2) << bad << ": " << r.err;
    EXPECT_NE(r.err.find("engines[0]"), std::string::npos) << r.err;
    EXPECT_EQ(files_under(dir.path()), before) << bad;
    EXPECT_FALSE(fs::exists(dir.path().parent_path() / "escaped.csv"));
  }
}

TEST(ScriptSafety, SweepRecordsWithAHostileNameAreRefused) {
  TempDir dir{"tippe-safety"};
  const std::string sweep = dir.write("tiny.toml", "repeats = 1\nscenes = [ { file = \"" + kSource +
                                                       "/harness/scenes/toy.toml\", duration = 0.02 } ]\n"
                                                       "[[setup]]\nname = \"analytic\"\nengine = \"analytic\"\n"
                                                       "ladder.key = \"engines.analytic.rtol\"\nladder.values = [1e-4, 1e-6]\n");
  const fs::path out = dir.path() / "sweep";
  Outcome r = run_tippe({"sweep", sweep, "--out", out.string(), "--jobs", "1"}, dir.path());
  ASSERT_EQ(r.exit.code, 0) << r.err;
  const fs::path marker = dir.path() / "PWNED";
  for (const char* key : {"scene", "setup", "engine"}) {
    std::string text = slurp(out / "records.jsonl");
    const size_t nl = text.find('\n');
    json first = json::parse(text.substr(0, nl));
    first[key] = injection(marker);
    const std::string tampered = first.dump() + text.substr(nl);
    spit(out / "records.jsonl", tampered);
    for (const std::vector<std::string>& args :
         {std::vector<std::string>{"sweep", "--report", out.string()},
          std::vector<std::string>{"sweep", sweep, "--out", out.string(), "--jobs", "1"}}) {
      r = run_tippe(args, dir.path());
      EXPECT_EQ(r.exit.code, 2) << key << ": " << r.err;
      EXPECT_NE(r.err.find("records.jsonl:1"), std::string::npos) << r.err;
      EXPECT_NE(r.err.find(key), std::string::npos) << r.err;
      EXPECT_FALSE(fs::exists(marker)) << key;
      EXPECT_EQ(slurp(out / "records.jsonl"), tampered) << "records rewritten";
    }
    spit(out / "records.jsonl", text);
  }
}

}  // namespace test_script_safety
