// Tables of scene-file inputs (harness/io/scene_io.cpp): malformed ones named by file and key, odd but valid ones loaded as they say, the same through the in-memory parser (out-of-range values in every file kind: test_toml_reader.cpp).
#include <gtest/gtest.h>

#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include "harness/io/scene_io.h"
#include "harness/scene/resolve.h"
#include "harness/io/toml_reader.h"
#include "tests/support/files.h"
#include "tests/support/fixtures.h"

namespace test_input_table {

namespace fs = std::filesystem;
using namespace tippe;

namespace {

using namespace tippe::fixtures;

std::string replace_all(std::string text, const std::string& from, const std::string& to) {
  for (size_t pos = 0; (pos = text.find(from, pos)) != std::string::npos; pos += to.size()) text.replace(pos, from.size(), to);
  return text;
}

struct Case {
  const char* name;
  std::string text;
  std::vector<std::string> overrides;
  // Empty: the input is valid and must load. Otherwise every fragment must appear in the
  // message, which must start with the file's path.
  std::vector<std::string> fragments;
  std::string file_name = "";  // default: NAME.toml
};

std::vector<Case> cases() {
  const std::string b = kBase;
  const std::string coulomb = edit(b, "friction = \"viscous\"\nk = 1.0", "friction = \"coulomb\"\nmu = 0.3");
  const std::string by_density =
      edit(b, "mass = 1.0\ncom_offset = 0.3\ninertia_transverse = 0.4\ninertia_axial = 0.45\n", "density = 1.0\n");
  const std::string long_key(5000, 'k');
  std::string deep_arrays = "x = " + std::string(300, '[') + std::string(300, ']') + "\n";
  std::string deep_tables = "[a";
  for (int i = 0; i < 300; ++i) deep_tables += ".a";
  deep_tables += "]\n";
  // 100 KB, under the 1 MiB bound: toml++ recursed once per part and overflowed the stack.
  std::string key_50000 = "a";
  for (int i = 1; i < 50000; ++i) key_50000 += ".a";
  std::string bounded_key = "a";
  for (int i = 1; i < kMaxTomlKeyParts; ++i) bounded_key += ".a";
  std::string inline_body = "name = \"base\"\ngravity = 1\n"
                            "body = { sphere_radius = 1.0, stem_radius = 0.25, stem_length = 1.2, truncation_height = 0.9, "
                            "mass = 1.0, com_offset = 0.3, inertia_transverse = 0.4, inertia_axial = 0.45 }\n" +
                            b.substr(b.find("[contact]"));
  return {
      // ---- bytes and TOML syntax: "FILE:LINE:COL: reason"
      {"non_utf8_bytes", edit(b, "test scene", "caf\xe9 \xff"), {}, {":2:", "utf-8"}},
      {"nul_byte", edit(b, "gravity = 1", std::string("gravity = 1\0", 12)), {}, {":3:", "expected digit"}},
      {"control_character_in_string", edit(b, "test scene", "test\x01scene"), {}, {":2:", "control characters"}},
      {"carriage_returns_only", replace_all(b, "\n", "\r"), {}, {":1:", "'\\r'"}},
      {"float_overflow_1e400", edit(b, "spin = 5.0", "spin = 1e400"), {}, {":18:", "'1e400'"}},
      {"integer_overflow", edit(b, "gravity = 1", "gravity = 99999999999999999999"), {}, {":3:", "not representable in 64 bits"}},
      {"duplicate_key", edit(b, "tilt = 0.1", "tilt = 0.1\ntilt = 0.2"), {}, {":18:", "cannot redefine", "'tilt'"}},
      {"duplicate_table", b + "[body]\nmass = 2.0\n", {}, {":25:", "cannot redefine existing table 'body'"}},
      {"deeply_nested_arrays", deep_arrays + b, {}, {":1:", "maximum nested value depth"}},
      // ---- structure: "FILE: KEY: reason"
      {"empty_file", "", {}, {": gravity: missing (required)"}},
      {"only_a_comment", "# a scene file with nothing in it\n", {}, {": gravity: missing (required)"}},
      {"deeply_nested_tables", deep_tables + b, {}, {":1:2:", "a dotted key or table header of more than 64 parts"}},
      // ---- nesting bounded before toml++ recurses (hostile inputs, round 3)
      {"table_header_of_50000_parts", "[" + key_50000 + "]\n" + b, {}, {":1:2:", "more than 64 parts"}},
      {"array_table_header_of_50000_parts", b + "[[" + key_50000 + "]]\n", {}, {":25:3:", "more than 64 parts"}},
      {"dotted_key_of_50000_parts", key_50000 + " = 1\n" + b, {}, {":1:1:", "more than 64 parts"}},
      {"quoted_dotted_key_of_50000_parts", "\"a\"." + key_50000 + " = 1\n" + b, {}, {":1:1:", "more than 64 parts"}},
      {"inline_table_key_of_50000_parts", "x = { " + key_50000 + " = 1 }\n" + b, {}, {":1:7:", "more than 64 parts"}},
      {"key_at_the_bound_is_only_unknown", bounded_key + " = 1\n" + b, {}, {": a: unknown key"}},
      {"set_key_of_50000_parts", b, {key_50000 + "=1"}, {": --set: the key a.a.a", "has 50000 parts, more than 64"}},
      {"set_inline_table_of_50000_parts", b, {"description={" + key_50000 + "=1}"},
       {": --set: the value of description nests dotted keys deeper than 64 parts"}},
      {"array_of_tables_for_a_table", edit(b, "[contact]", "[[contact]]"), {}, {": contact: expected a table, got an array"}},
      {"engines_not_a_table", "engines = 5\n" + b, {}, {": engines: expected a table of [engines.NAME] tables, got an integer"}},
      {"very_long_key", edit(b, "[body]\n", "[body]\n" + long_key + " = 1\n"), {}, {": body." + long_key + ": unknown key"}},
      {"string_where_array_expected", edit(b, "velocity = [0.0, 0.0]", "velocity = \"0, 0\""), {},
       {": initial.velocity: expected an array of 2 numbers, got a string"}},
      {"velocity_of_wrong_length", edit(b, "velocity = [0.0, 0.0]", "velocity = [0.0, 0.0, 0.0]"), {},
       {": initial.velocity: expected an array of 2 numbers, got an array of 3"}},
      {"array_inside_number_array", edit(b, "spin = 5.0", "omega = [[0.0], 0.0, 5.0]"), {},
       {": initial.omega[0]: expected a number, got an array"}},
      {"infinite_array_element", edit(b, "spin = 5.0", "omega = [0.0, 0.0, inf]"), {}, {": initial.omega[2]: must be a finite number"}},
      {"date_where_number_expected", edit(b, "duration = 25.0", "duration = 1979-05-27"), {}, {": run.duration: expected a number, got a date"}},
      {"name_not_a_string", edit(b, "name = \"base\"", "name = 5"), {}, {": name: expected a string, got an integer"}},
      {"name_with_a_path", edit(b, "name = \"base\"", "name = \"../etc\""), {}, {": name: \"../etc\" is not a usable name"}},
      {"file_stem_not_a_name", edit(b, "name = \"base\"\n", ""), {}, {": name: \"bad name\" (the file's stem) is not a usable name"},
       "bad name.toml"},
      {"multi_line_description", edit(b, "\"test scene\"", "\"\"\"two\nlines\"\"\""), {}, {": description: must be one line"}},
      {"negative_gravity", edit(b, "gravity = 1", "gravity = -9.81"), {}, {": gravity: -9.81 is out of range (expected gravity > 0)"}},
      {"friction_not_a_string", edit(b, "friction = \"viscous\"", "friction = 1"), {}, {": contact.friction: expected a string, got an integer"}},
      {"stem_not_a_boolean", edit(b, "k = 1.0", "k = 1.0\nstem = \"yes\""), {}, {": contact.stem: expected true or false, got a string"}},
      {"negative_k", edit(b, "k = 1.0", "k = -1.0"), {}, {": contact.k: -1 is out of range (expected k >= 0)"}},
      {"drilling_without_friction", edit(b, "friction = \"viscous\"\nk = 1.0", "friction = \"none\"\ndrilling = 0.1"), {},
       {": contact.drilling: does not apply to friction = \"none\""}},
      {"mass_model_unknown", edit(by_density, "density = 1.0", "density = 1.0\nmass_model = \"hollow\""), {},
       {": body.mass_model: unknown model \"hollow\""}},
      {"mass_model_missing", by_density, {}, {": body.mass_model: missing (required with density"}},
      {"omega_along_contact_not_a_boolean", edit(b, "spin = 5.0", "spin = 5.0\nomega_along_contact = 1"), {},
       {": initial.omega_along_contact: expected true or false, got an integer"}},
      {"omega_along_contact_with_omega", edit(b, "spin = 5.0", "omega = [0.0, 0.0, 5.0]\nomega_along_contact = true"), {},
       {": initial.omega_along_contact: takes its magnitude from spin"}},
      {"height_without_flight", edit(b, "tilt = 0.1", "tilt = 0.1\nheight = 0.5"), {},
       {": initial.height: a start above the floor needs contact.flight = true"}},
      {"negative_height", edit(b, "tilt = 0.1", "tilt = 0.1\nheight = -0.5"), {}, {": initial.height: -0.5 is out of range (expected height >= 0)"}},
      {"orientation_and_tilt", edit(b, "tilt = 0.1", "tilt = 0.1\norientation = [1.0, 0.0, 0.0, 0.0]"), {},
       {": initial.orientation: give either tilt or orientation, not both"}},
      {"orientation_not_unit", edit(b, "tilt = 0.1", "orientation = [1.0, 0.1, 0.0, 0.0]"), {},
       {": initial.orientation: must be a unit quaternion [w, x, y, z], got norm 1.00498756211"}},
      {"orientation_of_wrong_length", edit(b, "tilt = 0.1", "orientation = [1.0, 0.0, 0.0]"), {},
       {": initial.orientation: expected an array of 4 numbers, got an array of 3"}},
      {"position_of_wrong_length", edit(b, "tilt = 0.1", "tilt = 0.1\nposition = [0.0]"), {},
       {": initial.position: expected an array of 2 numbers, got an array of 1"}},
      {"notes_not_strings", "notes = [1]\n" + b, {}, {": notes[0]: expected a string, got an integer"}},
      {"note_of_two_lines", "notes = [\"a\\nb\"]\n" + b, {}, {": notes[0]: must be one non-empty line"}},
      {"mujoco_model_missing", edit(b, "[run]", "[engines.mujoco]\nmodel = \"no_such_model.xml\"\n\n[run]"), {},
       {": engines.mujoco.model: ", "no_such_model.xml: cannot read: No such file or directory"}},
      {"method_unknown", edit(b, "atol = 1e-12", "atol = 1e-12\nmethod = \"euler\""), {},
       {": run.method: must be \"bulirsch_stoer\", \"dopri5\" or \"rosenbrock4\", got \"euler\""}},
      {"method_not_a_string", edit(b, "atol = 1e-12", "atol = 1e-12\nmethod = 4"), {}, {": run.method: expected a string"}},
      {"energy_gain_rule_unknown", edit(b, "sample_interval = 0.01", "sample_interval = 0.01\nenergy_gain_rule = \"net\""), {},
       {": run.energy_gain_rule: must be \"stored\" or \"total\" or \"ledger\", got \"net\""}},
      {"energy_gain_rule_not_a_string", edit(b, "sample_interval = 0.01", "sample_interval = 0.01\nenergy_gain_rule = 1"), {},
       {": run.energy_gain_rule: expected a string"}},
      {"atol_out_of_range", edit(b, "atol = 1e-12", "atol = 2"), {}, {": run.atol: 2 is out of range (expected 0 < atol <= 1)"}},
      {"too_many_samples", edit(b, "sample_interval = 0.01", "sample_interval = 1e-12"), {},
       {": run.sample_interval: 1e-12 gives 2.5e+13 samples, up to "}},
      // 1e8 samples passed the old count guard: ~55 GB of CSV. The budget is bytes.
      {"samples_over_the_byte_budget", edit(b, "sample_interval = 0.01", "sample_interval = 2.5e-7"), {},
       {": run.sample_interval: 2.5e-07 gives 100000001 samples, up to 100709 MiB of trajectory, over the budget of 1024 MiB"}},
      {"engine_array_with_a_string", b + "[engines.mujoco]\nsolref = [0.002, \"x\"]\n", {},
       {": engines.mujoco.solref[1]: expected a number, got a string"}},
      {"coulomb_negative_mu", edit(coulomb, "mu = 0.3", "mu = -0.3"), {}, {": contact.mu: -0.3 is out of range (expected mu >= 0)"}},
      {"drilling_law_unknown", edit(coulomb, "mu = 0.3", "mu = 0.3\ndrilling = 0.01\ndrilling_law = \"elliptic\""), {},
       {": contact.drilling_law: unknown law \"elliptic\" (expected decoupled or coupled)"}},
      {"drilling_law_not_a_string", edit(coulomb, "mu = 0.3", "mu = 0.3\ndrilling = 0.01\ndrilling_law = 1"), {},
       {": contact.drilling_law: expected a string, got an integer"}},
      {"drilling_law_coupled_with_viscous", edit(b, "k = 1.0", "k = 1.0\ndrilling = 0.01\ndrilling_law = \"coupled\""), {},
       {": contact.drilling_law: \"coupled\" needs friction = \"coulomb\"", "got friction = \"viscous\""}},
      {"drilling_law_coupled_without_drilling", edit(coulomb, "mu = 0.3", "mu = 0.3\ndrilling_law = \"coupled\""), {},
       {": contact.drilling_law: \"coupled\" needs contact.drilling > 0", "got 0"}},
      {"drilling_law_coupled_without_mu", edit(coulomb, "mu = 0.3", "mu = 0\ndrilling = 0.01\ndrilling_law = \"coupled\""), {},
       {": contact.drilling_law: \"coupled\" needs contact.mu > 0, got 0"}},
      {"drilling_law_coupled_valid", edit(coulomb, "mu = 0.3", "mu = 0.3\ndrilling = 0.01\ndrilling_law = \"coupled\""), {}, {}},
      // ---- --set overrides
      {"set_only_equals", b, {"="}, {": --set: malformed override \"=\""}},
      {"set_empty", b, {""}, {": --set: malformed override \"\""}},
      {"set_key_ends_with_dot", b, {"contact.=1"}, {": --set: malformed key \"contact.\""}},
      {"set_key_with_tab", b, {"contact.\tmu=1"}, {": --set: malformed key"}},
      {"set_into_an_array", b, {"initial.velocity.x=1"}, {": --set: cannot set initial.velocity.x: initial.velocity is not a table"}},
      {"set_into_a_string", b, {"name.x=1"}, {": --set: cannot set name.x: name is not a table"}},
      {"set_value_overflows", b, {"run.duration=1e400"}, {": run.duration: expected a number, got a string"}},
      {"set_replaces_a_table", b, {"body={}"}, {": body.sphere_radius: missing (required)"}},
      {"set_newline_in_description", b, {"description=a\nb"}, {": description: must be one line"}},
      // Found by reading the fuzzer's contract: both used to load, run the whole simulation and
      // then fail writing the JSON record ("internal: [json.exception.type_error.316]").
      {"set_value_not_utf8", b, {"description=caf\xe9"}, {": --set: the value of description is not valid UTF-8"}},
      {"set_value_overlong_utf8", b, {"engines.ode.stepper=\xc0\xaf"}, {": --set: the value of engines.ode.stepper is not valid UTF-8"}},
      {"set_value_utf16_surrogate", b, {"description=\xed\xa0\x80"}, {": --set: the value of description is not valid UTF-8"}},
      {"path_not_utf8", b, {}, {": cannot read: the path is not valid UTF-8"}, "caf\xe9.toml"},
      // ---- odd but valid: must load
      {"negative_zero_tilt", edit(b, "tilt = 0.1", "tilt = -0.0"), {}, {}},
      {"byte_order_mark", "\xef\xbb\xbf" + b, {}, {}},
      {"crlf_line_ends", replace_all(b, "\n", "\r\n"), {}, {}},
      {"inline_table_for_body", inline_body, {}, {}},
      {"hex_integer_gravity", edit(b, "gravity = 1", "gravity = 0x10"), {}, {}},
      {"set_unterminated_string_is_a_bare_word", b, {"description=\"abc"}, {}},
      {"set_value_utf8_bare_word", b, {"description=caf\xc3\xa9 \xf0\x9f\x8c\x80"}, {}},
  };
}

void PrintTo(const Case& c, std::ostream* os) { *os << c.name; }

std::string error_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const SceneError& e) {
    return e.what();
  }
  return "";
}

class InputTable : public ::testing::TestWithParam<Case> {};

TEST_P(InputTable, NamesFileAndKeyOrLoads) {
  const Case& c = GetParam();
  TempDir dir{"tippe-input"};
  const std::string path = dir.write(c.file_name.empty() ? std::string(c.name) + ".toml" : c.file_name, c.text);
  const std::string msg = error_of([&] { load_scene(path, c.overrides); });
  // The in-memory parser (what the fuzzer drives) says exactly what load_scene says.
  EXPECT_EQ(error_of([&] { parse_scene_text(c.text, path, c.overrides); }), msg);
  if (c.fragments.empty()) {
    EXPECT_EQ(msg, "") << "a valid input was rejected";
    return;
  }
  ASSERT_NE(msg, "") << "a malformed input was accepted";
  EXPECT_EQ(msg.rfind(path + ":", 0), 0u) << msg;
  for (const auto& f : c.fragments) EXPECT_NE(msg.find(f), std::string::npos) << "want \"" << f << "\" in: " << msg;
}

INSTANTIATE_TEST_SUITE_P(Inputs, InputTable, ::testing::ValuesIn(cases()),
                         [](const ::testing::TestParamInfo<Case>& info) { return std::string(info.param.name); });

// What the valid odd inputs load as.
TEST(InputTable, OddButValidInputsMeanWhatTheySay) {
  const std::string b = kBase;
  const Scene zero = parse_scene_text(edit(b, "tilt = 0.1", "tilt = -0.0"), "z.toml");
  EXPECT_EQ(zero.initial.tilt, 0.0);
  const Scene plain = parse_scene_text(b, "p.toml");
  const Scene crlf = parse_scene_text(replace_all(b, "\n", "\r\n"), "p.toml");
  EXPECT_EQ(scene_to_json(crlf).at("body"), scene_to_json(plain).at("body"));
  EXPECT_NE(crlf.content_hash, plain.content_hash);  // the hash is over the bytes
  const Scene hex = parse_scene_text(edit(b, "gravity = 1", "gravity = 0x10"), "h.toml");
  EXPECT_EQ(hex.gravity, 16.0);
  const Scene bare = parse_scene_text(b, "s.toml", {"description=\"abc"});
  EXPECT_EQ(bare.description, "\"abc");
  const Scene utf8 = parse_scene_text(b, "s.toml", {"description=caf\xc3\xa9"});
  EXPECT_NE(scene_to_json(utf8).dump().find("caf\xc3\xa9"), std::string::npos);
}

TEST(InputTable, InMemoryParserTouchesNoFile) {
  // A label that names no file: parse_scene_text must not try to open it.
  const Scene s = parse_scene_text(kBase, "/nonexistent/dir/x.toml");
  EXPECT_EQ(s.source_file, "/nonexistent/dir/x.toml");
  EXPECT_EQ(s.name, "base");
  const std::string msg = error_of([] { parse_scene_text("gravity = 0\n", "in-memory/scene.toml"); });
  EXPECT_EQ(msg, "in-memory/scene.toml: gravity: 0 is out of range (expected gravity > 0)");
}

}  // namespace

}  // namespace test_input_table
