// Tests of the one checked reader of scene, sweep and gate files (harness/io/toml_reader.cpp): out-of-range values, wrong types and non-finite numbers in each file kind, named by file, key and value by the loader and the command alike.
#include <gtest/gtest.h>

#include <filesystem>
#include <string>
#include <vector>

#include "harness/gating/gate.h"
#include "harness/io/scene_io.h"
#include "harness/scene/resolve.h"
#include "harness/sweep/sweep.h"
#include "tests/support/files.h"
#include "tests/support/process.h"
#include "tests/support/fixtures.h"

namespace test_toml_reader {

namespace fs = std::filesystem;
using namespace tippe;

namespace {

using namespace tippe::fixtures;

// ---- out-of-range values, wrong types and non-finite numbers in all three file kinds ----------

// A valid sweep and a valid gate file over kBase (written as scenes/base.toml); every case below
// is one edit of one of them (or of kBase), so that its message is about that edit alone.
const char* const kSweepBase = R"(description = "input table sweep"
repeats = 1
duration = 0.5
scenes = ["../scenes/base.toml"]

[[setup]]
name = "ode"
engine = "ode"
set = ["engines.ode.iterations=20"]
ladder.key = "engines.ode.timestep"
ladder.values = [1e-3, 5e-4]

[[setup]]
name = "reference"
engine = "analytic"
ladder.key = "run.rtol"
ladder.values = [1e-6, 1e-8]
)";

const char* const kGateBase = R"([defaults]
scene = "../scenes/base.toml"
duration = 0.5

[[check]]
name = "ode-default"
engine = "ode"
set = ["engines.ode.timestep=1e-3"]
[check.max]
tilt_rms_error = 0.05
steps = 1000
)";

enum class Kind { Scene, Sweep, Gate };

const char* kind_name(Kind k) { return k == Kind::Scene ? "scene" : k == Kind::Sweep ? "sweep" : "gate"; }

struct FileCase {
  const char* name;
  Kind kind;
  std::string text;
  std::string key;     // the message must start "FILE: KEY: "
  std::string detail;  // the offending value and the expected range (or the reason), after the key
  std::vector<std::string> overrides = {};  // scene files only: --set
  bool cli = false;                         // also through `tippe`: exit 2, the message, nothing written
};

std::vector<FileCase> file_cases() {
  const std::string b = kBase, w = kSweepBase, g = kGateBase;
  const std::string by_density =
      edit(b, "mass = 1.0\ncom_offset = 0.3\ninertia_transverse = 0.4\ninertia_axial = 0.45\n",
           "density = 1.0\nmass_model = \"solid\"\n");
  const std::string drilling = edit(b, "k = 1.0", "k = 1.0\ndrilling = -0.01");
  const Kind S = Kind::Scene, W = Kind::Sweep, G = Kind::Gate;
  return {
      // ---- scene files
      {"rtol_above_range", S, edit(b, "rtol = 1e-10", "rtol = 2"), "run.rtol",
       "2 is out of range (expected 1e-15 <= rtol <= 0.01)", {}, true},
      {"rtol_zero", S, edit(b, "rtol = 1e-10", "rtol = 0"), "run.rtol", "0 is out of range (expected 1e-15 <= rtol"},
      {"rtol_below_rounding", S, edit(b, "rtol = 1e-10", "rtol = 1e-17"), "run.rtol", "1e-17 is out of range"},
      {"atol_negative", S, edit(b, "atol = 1e-12", "atol = -1e-12"), "run.atol",
       "-1e-12 is out of range (expected 0 < atol <= 1)"},
      {"tilt_negative", S, edit(b, "tilt = 0.1", "tilt = -0.1"), "initial.tilt",
       "-0.1 is out of range (expected 0 <= tilt <= pi = 3.14159265359 rad)"},
      {"tilt_just_above_pi", S, edit(b, "tilt = 0.1", "tilt = 3.1416"), "initial.tilt", "3.1416 is out of range"},
      {"sample_interval_zero", S, edit(b, "sample_interval = 0.01", "sample_interval = 0"), "run.sample_interval",
       "0 is out of range (expected 0 < sample_interval <= duration = 25)"},
      {"sample_interval_negative", S, edit(b, "sample_interval = 0.01", "sample_interval = -0.01"),
       "run.sample_interval", "-0.01 is out of range"},
      {"duration_negative", S, edit(b, "duration = 25.0", "duration = -1"), "run.duration",
       "-1 is out of range (expected duration > 0)", {}, true},
      {"gravity_zero", S, edit(b, "gravity = 1", "gravity = 0"), "gravity", "0 is out of range (expected gravity > 0)"},
      {"gravity_minus_inf", S, edit(b, "gravity = 1", "gravity = -inf"), "gravity", "must be a finite number, got -inf"},
      {"spin_nan", S, edit(b, "spin = 5.0", "spin = nan"), "initial.spin", "must be a finite number, got nan"},
      {"velocity_nan", S, edit(b, "velocity = [0.0, 0.0]", "velocity = [nan, 0.0]"), "initial.velocity[0]",
       "must be a finite number, got nan"},
      {"drilling_negative", S, drilling, "contact.drilling", "-0.01 is out of range (expected drilling >= 0)"},
      {"mass_zero", S, edit(b, "mass = 1.0", "mass = 0"), "body.mass", "0 is out of range (expected mass > 0)"},
      {"inertia_transverse_negative", S, edit(b, "inertia_transverse = 0.4", "inertia_transverse = -0.4"),
       "body.inertia_transverse", "-0.4 is out of range (expected inertia_transverse > 0)"},
      {"inertia_axial_above_2A", S, edit(b, "inertia_axial = 0.45", "inertia_axial = 0.9"), "body.inertia_axial",
       "0.9 is out of range (expected inertia_axial <= 2 inertia_transverse = 0.8"},
      {"com_offset_below_minus_R", S, edit(b, "com_offset = 0.3", "com_offset = -1.5"), "body.com_offset",
       "-1.5 is out of range (expected -R < com_offset < R, R = sphere_radius = 1)"},
      {"truncation_height_zero", S, edit(b, "truncation_height = 0.9", "truncation_height = 0"),
       "body.truncation_height", "0 is out of range (expected 0 < truncation_height <= sphere_radius = 1)"},
      {"stem_length_negative", S, edit(b, "stem_length = 1.2", "stem_length = -1.2"), "body.stem_length",
       "-1.2 is out of range (expected stem_length > 0)"},
      {"density_negative", S, edit(by_density, "density = 1.0", "density = -1000"), "body.density",
       "-1000 is out of range (expected density > 0)"},
      {"tilt_a_string", S, edit(b, "tilt = 0.1", "tilt = \"0.1\""), "initial.tilt",
       "expected a number, got a string '0.1'"},
      {"stem_an_integer", S, edit(b, "k = 1.0", "k = 1.0\nstem = 1"), "contact.stem",
       "expected true or false, got an integer 1"},
      {"unknown_run_key", S, edit(b, "atol = 1e-12", "atol = 1e-12\ntolerance = 1e-9"), "run.tolerance",
       "unknown key (expected one of: duration, sample_interval, rtol, atol, method, self_check, energy_gain_rule)"},
      {"set_rtol_out_of_range", S, b, "run.rtol", "0.5 is out of range (expected 1e-15 <= rtol <= 0.01)",
       {"run.rtol=0.5"}, true},
      {"engine_timestep_out_of_range", S, b + "[engines.ode]\ntimestep = 1\n", "engines.ode.timestep",
       "value 1 outside [1e-08, 0.1]"},
      {"engine_iterations_zero", S, b + "[engines.bullet]\nsolver_iterations = 0\n", "engines.bullet.solver_iterations",
       "value 0 outside [1, 1000000]"},

      // ---- sweep files
      {"repeats_above_100", W, edit(w, "repeats = 1", "repeats = 101"), "repeats",
       "101 is out of range (expected 1 <= repeats <= 100)", {}, true},
      {"repeats_negative", W, edit(w, "repeats = 1", "repeats = -3"), "repeats",
       "-3 is out of range (expected 1 <= repeats <= 100)"},
      {"repeats_a_float", W, edit(w, "repeats = 1", "repeats = 2.5"), "repeats",
       "expected an integer (1 <= repeats <= 100), got a float 2.5"},
      {"duration_zero", W, edit(w, "duration = 0.5", "duration = 0"), "duration",
       "0 is out of range (expected duration > 0)"},
      {"duration_nan", W, edit(w, "duration = 0.5", "duration = nan"), "duration", "must be a finite number, got nan"},
      {"duration_a_string", W, edit(w, "duration = 0.5", "duration = \"0.5\""), "duration",
       "expected a number, got a string '0.5'"},
      {"scene_duration_negative", W,
       edit(w, "scenes = [\"../scenes/base.toml\"]", "scenes = [{ file = \"../scenes/base.toml\", duration = -2 }]"),
       "scenes[0].duration", "-2 is out of range (expected duration > 0)"},
      {"duration_below_sample_interval", W, edit(w, "duration = 0.5", "duration = 0.001"), "duration",
       "run.sample_interval: 0.01 is out of range (expected 0 < sample_interval <= duration = 0.001)"},
      {"ladder_timestep_out_of_range", W, edit(w, "ladder.values = [1e-3, 5e-4]", "ladder.values = [1e-3, 0.5]"),
       "setup[0].ladder.values[1]", "engines.ode.timestep: value 0.5 outside [1e-08, 0.1]", {}, true},
      {"ladder_rtol_out_of_range", W, edit(w, "ladder.values = [1e-6, 1e-8]", "ladder.values = [1e-6, 0.5]"),
       "setup[1].ladder.values[1]", "run.rtol: 0.5 is out of range (expected 1e-15 <= rtol <= 0.01)"},
      {"ladder_value_inf", W, edit(w, "ladder.values = [1e-3, 5e-4]", "ladder.values = [1e-3, inf]"),
       "setup[0].ladder.values[1]", "must be a finite number, got inf"},
      // A boolean is a value of a categorical ladder: the engine setting refuses it for a time step.
      {"ladder_value_a_boolean", W, edit(w, "ladder.values = [1e-3, 5e-4]", "ladder.values = [true]"),
       "setup[0].ladder.values[0]", "engines.ode.timestep: expected a number"},
      {"grid_value_the_setting_refuses", W,
       edit(w, "ladder.values = [1e-3, 5e-4]",
            "ladder.values = [1e-3, 5e-4]\ngrid = { key = \"engines.ode.friction_model\", values = [\"approx1\", \"cone\"] }"),
       "setup[0].grid.values[1]", "engines.ode.friction_model: value \"cone\" is not one of: approx1, box"},
      {"set_iterations_zero", W, edit(w, "engines.ode.iterations=20", "engines.ode.iterations=0"), "setup[0].set[0]",
       "engines.ode.iterations: value 0 outside [1, 1000000]"},
      {"unknown_top_key", W, "repeat = 3\n" + w, "repeat",
       "unknown key (expected one of: description, repeats, duration, scenes, setup)"},
      {"setup_in_single_brackets", W,
       edit(w.substr(0, w.find("\n[[setup]]\nname = \"reference\"") + 1), "[[setup]]", "[setup]"), "setup",
       "expected [[setup]] tables, got a table"},

      // ---- gate files
      {"threshold_negative", G, edit(g, "tilt_rms_error = 0.05", "tilt_rms_error = -0.05"),
       "check[0].max.tilt_rms_error", "-0.05 is out of range (expected tilt_rms_error >= 0: |value| is compared)", {},
       true},
      {"threshold_nan", G, edit(g, "tilt_rms_error = 0.05", "tilt_rms_error = nan"), "check[0].max.tilt_rms_error",
       "must be a finite number, got nan"},
      {"threshold_inf", G, edit(g, "steps = 1000", "steps = inf"), "check[0].max.steps",
       "must be a finite number, got inf"},
      {"threshold_minus_inf", G, edit(g, "steps = 1000", "steps = -inf"), "check[0].max.steps",
       "must be a finite number, got -inf"},
      {"threshold_a_string", G, edit(g, "tilt_rms_error = 0.05", "tilt_rms_error = \"0.05\""),
       "check[0].max.tilt_rms_error", "expected a number, got a string '0.05'"},
      {"threshold_in_defaults_negative", G, edit(g, "duration = 0.5\n", "duration = 0.5\nmax = { steps = -1 }\n"),
       "defaults.max.steps", "-1 is out of range (expected steps >= 0: |value| is compared)"},
      {"check_duration_negative", G, edit(g, "engine = \"ode\"\n", "engine = \"ode\"\nduration = -1\n"),
       "check[0].duration", "-1 is out of range (expected duration > 0)"},
      {"defaults_duration_nan", G, edit(g, "duration = 0.5", "duration = nan"), "defaults.duration",
       "must be a finite number, got nan"},
      {"duration_below_sample_interval", G, edit(g, "duration = 0.5", "duration = 0.001"), "defaults.duration",
       "run.sample_interval: 0.01 is out of range (expected 0 < sample_interval <= duration = 0.001)"},
      {"set_timestep_out_of_range", G, edit(g, "engines.ode.timestep=1e-3", "engines.ode.timestep=1"),
       "check[0].set[0]", "engines.ode.timestep: value 1 outside [1e-08, 0.1]", {}, true},
      {"set_rtol_out_of_range", G,
       edit(g, "\"engines.ode.timestep=1e-3\"", "\"engines.ode.timestep=1e-3\", \"run.rtol=2\""), "check[0].set[1]",
       "run.rtol: 2 is out of range (expected 1e-15 <= rtol <= 0.01)"},
      {"status_an_integer", G, edit(g, "engine = \"ode\"\n", "engine = \"ode\"\nstatus = 1\n"), "check[0].status",
       "expected a string, got an integer 1"},
      {"require_same_events_an_integer", G, edit(g, "engine = \"ode\"\n", "engine = \"ode\"\nrequire_same_events = 1\n"),
       "check[0].require_same_events", "expected true or false, got an integer 1"},
      {"unknown_metric", G, edit(g, "steps = 1000", "step = 1000"), "check[0].max.step", "unknown metric"},
  };
}

void PrintTo(const FileCase& c, std::ostream* os) { *os << kind_name(c.kind) << "_" << c.name; }

// Writes the case into `dir` (scenes/, sweeps/ or gates/, beside scenes/base.toml) and returns its path.
std::string write_case(const TempDir& dir, const FileCase& c) {
  dir.write("scenes/base.toml", kBase);
  const std::string sub = c.kind == Kind::Scene ? "scenes/" : c.kind == Kind::Sweep ? "sweeps/" : "gates/";
  return dir.write(sub + c.name + ".toml", c.text);
}

// Loads a file of its kind. Only SceneError may come out of a malformed one.
void load_file(Kind kind, const std::string& path, const std::vector<std::string>& overrides) {
  if (kind == Kind::Scene) load_scene(path, overrides);
  else if (kind == Kind::Sweep) load_sweep(path);
  else load_gate_file(path);
}

struct Outcome {
  int code = -1;  // exit status, -1 when it did not exit
  std::string err;
};

// `tippe ARGS` with stdout to /dev/null and stderr captured (no shell: arguments pass as they are).
Outcome run_tippe(const std::vector<std::string>& args, const fs::path& err_file) {
  std::vector<std::string> argv = {std::string(TIPPE_BINARY_DIR) + "/tippe"};
  argv.insert(argv.end(), args.begin(), args.end());
  Outcome o;
  o.code = wait_process(spawn_process(argv, "/dev/null", err_file)).code;
  o.err = slurp(err_file);
  return o;
}

TEST(FileTable, BasesAreValidAndEveryKindIsCovered) {
  TempDir dir{"tippe-input"};
  const std::string scene = dir.write("scenes/base.toml", kBase);
  const std::string sweep = dir.write("sweeps/base.toml", kSweepBase);
  const std::string gate = dir.write("gates/base.toml", kGateBase);
  EXPECT_NO_THROW(load_scene(scene));
  EXPECT_NO_THROW(load_sweep(sweep));
  EXPECT_NO_THROW(load_gate_file(gate));
  size_t per_kind[3] = {0, 0, 0}, through_cli[3] = {0, 0, 0};
  for (const FileCase& c : file_cases()) {
    ++per_kind[static_cast<int>(c.kind)];
    through_cli[static_cast<int>(c.kind)] += c.cli ? 1 : 0;
  }
  EXPECT_GE(per_kind[0] + per_kind[1] + per_kind[2], 30u);
  EXPECT_GE(per_kind[1], 8u) << "sweep cases";
  EXPECT_GE(per_kind[2], 8u) << "gate cases";
  for (size_t n : through_cli) EXPECT_GE(n, 1u) << "every kind goes through the command at least once";
}

class FileTable : public ::testing::TestWithParam<FileCase> {};

TEST_P(FileTable, ThrowsSceneErrorNamingFileKeyAndValue) {
  const FileCase& c = GetParam();
  TempDir dir{"tippe-input"};
  const std::string path = write_case(dir, c);
  std::string msg;
  try {
    load_file(c.kind, path, c.overrides);
    ADD_FAILURE() << "a malformed input was accepted";
    return;
  } catch (const SceneError& e) {
    msg = e.what();
  } catch (const std::exception& e) {
    FAIL() << "not a SceneError: " << e.what();
  }
  EXPECT_NE(msg.find(std::string(c.name) + ".toml"), std::string::npos) << msg;
  EXPECT_EQ(msg.rfind(path + ": " + c.key + ": ", 0), 0u) << "want \"" << c.key << "\" first in: " << msg;
  EXPECT_NE(msg.find(c.detail), std::string::npos) << "want \"" << c.detail << "\" in: " << msg;
  if (!c.cli) return;

  // The command says the same and exits 2 before writing anything.
  const fs::path out = dir.path() / "out", err = dir.path() / "stderr.txt";
  std::vector<std::string> args;
  if (c.kind == Kind::Scene) {
    args = {"run", path, "--out", out.string()};
    for (const auto& o : c.overrides) args.insert(args.end(), {"--set", o});
  } else if (c.kind == Kind::Sweep) {
    args = {"sweep", path, "--out", out.string(), "--no-plots"};
  } else {
    args = {"gate", path, "--junit", (out / "junit.xml").string(), "--json", (out / "gate.json").string(),
            "--cache", (out / "cache").string()};
  }
  const Outcome o = run_tippe(args, err);
  EXPECT_EQ(o.code, 2) << o.err;
  EXPECT_NE(o.err.find(msg), std::string::npos) << "the command's message differs from the loader's: " << o.err;
  EXPECT_FALSE(fs::exists(out)) << "an invalid input wrote output";
}

INSTANTIATE_TEST_SUITE_P(Files, FileTable, ::testing::ValuesIn(file_cases()),
                         [](const ::testing::TestParamInfo<FileCase>& info) {
                           return std::string(kind_name(info.param.kind)) + "_" + info.param.name;
                         });

}  // namespace

}  // namespace test_toml_reader
