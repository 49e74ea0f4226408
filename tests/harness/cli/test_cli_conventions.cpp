// The command line's conventions: unknown subcommands named, --quiet, whole progress lines in a log, '-' for stdout, true sentences, plain numbers.
#include <gtest/gtest.h>

#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "harness/cli/cli.h"
#include "engines/core/settings.h"
#include "tests/support/files.h"
#include "tests/support/process.h"

namespace tippe::test_cli_conventions {
namespace {

namespace fs = std::filesystem;
const std::string kSource = TIPPE_SOURCE_DIR;
const std::string kBinary = std::string(TIPPE_BINARY_DIR) + "/tippe";

struct Output {
  int code = -1;
  std::string out, err;
};

// Runs tippe with stdout and stderr in files (so stderr is not a terminal, as in CI).
Output tippe(const TempDir& dir, std::vector<std::string> args) {
  const fs::path out = fs::path(dir.path()) / "stdout", err = fs::path(dir.path()) / "stderr";
  std::string cmd = "cd '" + dir.path().string() + "' && '" + kBinary + "'";
  for (const std::string& a : args) cmd += " '" + a + "'";
  cmd += " >'" + out.string() + "' 2>'" + err.string() + "'";
  const int status = std::system(cmd.c_str());
  return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, slurp(out), slurp(err)};
}

TEST(Cli, UnknownSubcommandIsNamedWithTheNearestOne) {
  TempDir d{"tippe-cli"};
  Output o = tippe(d, {"compre", "x.toml"});
  EXPECT_EQ(o.code, 2);
  EXPECT_NE(o.err.find("unknown subcommand 'compre' (did you mean 'compare'?)"), std::string::npos) << o.err;
  o = tippe(d, {"frobnicate"});
  EXPECT_EQ(o.code, 2);
  EXPECT_NE(o.err.find("unknown subcommand 'frobnicate'; the subcommands are: run"), std::string::npos) << o.err;
}

TEST(Cli, NearestNameTakesTyposOnly) {
  const std::vector<std::string> names = {"run", "compare", "report", "sweep", "gate", "info"};
  EXPECT_EQ(cli::nearest_name("compre", names), "compare");
  EXPECT_EQ(cli::nearest_name("swep", names), "sweep");
  EXPECT_EQ(cli::nearest_name("rpeort", names), "report");
  EXPECT_EQ(cli::nearest_name("frobnicate", names), "");
  EXPECT_EQ(cli::nearest_name("x", names), "");
}

// Not a terminal: progress comes as whole lines (no carriage return), and --quiet silences it
// wherever it is given; the result on stdout is the same.
TEST(Cli, ProgressIsLinesInALogAndNothingWhenQuiet) {
  TempDir d{"tippe-cli"};
  const std::string scene = kSource + "/harness/scenes/toy.toml";
  const Output loud = tippe(d, {"run", scene, "--set", "run.duration=0.5", "--out", "a"});
  ASSERT_EQ(loud.code, 0) << loud.err;
  EXPECT_EQ(loud.err.find('\r'), std::string::npos) << loud.err;
  EXPECT_NE(loud.err.find("[analytic] t = 0.500 / 0.500 (100%)\n"), std::string::npos) << loud.err;
  for (const std::vector<std::string>& args :
       {std::vector<std::string>{"run", scene, "--set", "run.duration=0.5", "--out", "b", "--quiet"},
        std::vector<std::string>{"--quiet", "run", scene, "--set", "run.duration=0.5", "--out", "c"},
        std::vector<std::string>{"compare", scene, "--set", "run.duration=0.05", "--engines", "ode", "--no-plots",
                                 "--no-cache", "-q", "--out", "d"}}) {
    const Output quiet = tippe(d, args);
    ASSERT_EQ(quiet.code, 0) << quiet.err;
    EXPECT_EQ(quiet.err, "") << args[0];
  }
  const Output cmp = tippe(d, {"compare", scene, "--set", "run.duration=0.05", "--engines", "ode", "--no-plots",
                               "--no-cache", "--out", "e"});
  ASSERT_EQ(cmp.code, 0) << cmp.err;
  EXPECT_EQ(cmp.err.find('\r'), std::string::npos) << cmp.err;
  EXPECT_NE(cmp.err.find("[compare toy]"), std::string::npos) << cmp.err;
}

// `--json -`: stdout is the JSON alone (the table goes to stderr); both on stdout is refused.
TEST(Cli, DashIsStdoutForGateReports) {
  TempDir d{"tippe-cli"};
  d.write("scene.toml", slurp(kSource + "/harness/scenes/toy.toml"));
  const std::string gate = d.write("g.toml", "[[check]]\nname = \"ode-runs\"\nscene = \"scene.toml\"\nengine = \"ode\"\n"
                                             "duration = 0.05\n[check.max]\nenergy_gain_events = 1000\n");
  Output o = tippe(d, {"gate", gate, "--no-cache", "--json", "-"});
  ASSERT_EQ(o.code, 0) << o.err;
  const nlohmann::json j = nlohmann::json::parse(o.out);
  EXPECT_EQ(j.at("gate_file"), gate);
  EXPECT_NE(o.err.find("ode-runs"), std::string::npos) << "the table goes to stderr\n" << o.err;
  o = tippe(d, {"gate", gate, "--no-cache", "--junit", "-"});
  ASSERT_EQ(o.code, 0) << o.err;
  EXPECT_EQ(o.out.rfind("<?xml", 0), 0u) << o.out;
  o = tippe(d, {"gate", gate, "--json", "-", "--junit", "-"});
  EXPECT_EQ(o.code, 2);
  EXPECT_NE(o.err.find("--junit and --json both name stdout"), std::string::npos) << o.err;
}

TEST(Cli, InversionConditionIsATrueSentence) {
  EXPECT_EQ(cli::inversion_condition_text(0.2, 1.1428571428571428), "yes: 1 - alpha = 0.8 < A/C = 1.14286 < 1 + alpha = 1.2");
  EXPECT_EQ(cli::inversion_condition_text(0.2, 1.2857142857142858),
            "no: A/C = 1.28571 >= 1 + alpha = 1.2 (inversion needs 1 - alpha < A/C < 1 + alpha)");
  EXPECT_EQ(cli::inversion_condition_text(0.2, 0.5),
            "no: A/C = 0.5 <= 1 - alpha = 0.8 (inversion needs 1 - alpha < A/C < 1 + alpha)");
}

// Settings are listed with the digits they have and read back exactly.
TEST(Cli, NumbersCarryTheDigitsTheyHave) {
  EXPECT_EQ(round_trip_text(0.2), "0.2");
  EXPECT_EQ(round_trip_text(0.85), "0.85");
  EXPECT_EQ(round_trip_text(-0.0), "0");
  EXPECT_EQ(round_trip_text(1e-4), "0.0001");
  EXPECT_EQ(round_trip_text(1000.0), "1000");
  EXPECT_EQ(round_trip_text(200.0), "200");
  EXPECT_EQ(round_trip_text(-1500.0), "-1500");
  EXPECT_EQ(round_trip_text(1e20), "1e+20");
  for (double v : {0.1, 1.0 / 3.0, 2.0e-300, 1e-4, 123456.789, 9.81, 1000.0, 99999999999999990.0, 1e20})
    EXPECT_EQ(std::stod(round_trip_text(v)), v) << round_trip_text(v);
}

}  // namespace
}  // namespace tippe
