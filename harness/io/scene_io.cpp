// Reading scene files: TOML -> Scene with every key checked (its [engines.*] tables raw), and command-line overrides.
#include "harness/io/scene_io.h"
#include "harness/io/hash.h"
#include "harness/io/text.h"

#include "harness/io/toml_reader.h"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <initializer_list>
#include <optional>
#include <set>
#include <sstream>

#include <toml++/toml.h>

#include "analytic/mass_properties.h"
#include "harness/io/files.h"

namespace tippe {

namespace {

constexpr double kPi = 3.14159265358979323846;
// A byte budget, not a count, against a typo in sample_interval: a run's trajectory.csv is at
// most kMaxTrajectoryBytes at the longest row (kTrajectoryRowMax), and the same bound caps what a
// run keeps in memory (a sweep's reference holds its CSV text, ~450 bytes a row, and every
// comparison a Trajectory, 92 bytes a row, per run). 1 GiB allows ~1.2e6 samples, 30 times the
// longest shipped scene (extremes/long_horizon: 41900); the count it replaces, 1e8, let ~55 GB through.
constexpr double kMaxTrajectoryBytes = 1024.0 * 1024.0 * 1024.0;
constexpr double kMaxSamples = kMaxTrajectoryBytes / static_cast<double>(kTrajectoryRowMax);
// Below a few machine epsilons (2.2e-16) the integrator's error estimate is rounding noise: no
// step can meet the tolerance and the run only ends by failing.
constexpr double kMinRtol = 1e-15;
// Looser than 1 % the reference is no longer a reference.
constexpr double kMaxRtol = 1e-2;



bool is_bare_key(const std::string& s) {
  return !s.empty() && std::all_of(s.begin(), s.end(), [](char c) {
    return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_' || c == '-';
  });
}

// Interprets a parsed scene document; every error names the file and the dotted key.
class Interpreter : public TomlReader {
 public:
  Interpreter(std::string file, std::set<std::string> overridden) : TomlReader(std::move(file), std::move(overridden)) {}

  void apply_override(toml::table& root, const std::string& text) const {
    const auto eq = text.find('=');
    const std::string key = trim(text.substr(0, eq));
    if (eq == std::string::npos || key.empty())
      fail("--set", "malformed override \"" + text + "\" (expected KEY=VALUE)");
    std::vector<std::string> parts;
    std::stringstream ss(key);
    for (std::string part; std::getline(ss, part, '.');) parts.push_back(part);
    if (key.back() == '.' || parts.empty() ||
        !std::all_of(parts.begin(), parts.end(), is_bare_key))
      fail("--set", "malformed key \"" + key.substr(0, 80) + "\" (expected dotted bare keys, e.g. contact.mu)");
    if (parts.size() > static_cast<size_t>(kMaxTomlKeyParts))
      fail("--set", "the key " + key.substr(0, 40) + "... has " + std::to_string(parts.size()) + " parts, more than " +
                        std::to_string(kMaxTomlKeyParts));

    const std::string value_text = trim(text.substr(eq + 1));
    toml::table parsed;
    bool is_toml = false;
    // An inline table's dotted keys nest as deep as a file's: the same bound, before toml++.
    try {
      check_toml_key_depth(value_text, "--set");
    } catch (const SceneError&) {
      fail("--set", "the value of " + key + " nests dotted keys deeper than " + std::to_string(kMaxTomlKeyParts) +
                        " parts");
    }
    try {
      parsed = toml::parse("v = " + value_text);
      is_toml = parsed.size() == 1 && parsed.contains("v");
    } catch (const toml::parse_error&) {
    }
    if (!is_toml) {
      // A bare word becomes a TOML string, which must be UTF-8; the run's records are JSON,
      // whose writer would otherwise throw only after the whole run.
      if (!is_valid_utf8(value_text)) fail("--set", "the value of " + key + " is not valid UTF-8");
      parsed = toml::table{};
      parsed.insert("v", value_text);
    }

    toml::table* tbl = &root;
    std::string walked;
    for (size_t i = 0; i + 1 < parts.size(); ++i) {
      walked = join_path(walked, parts[i]);
      toml::node* n = tbl->get(parts[i]);
      if (!n) n = &tbl->insert(parts[i], toml::table{}).first->second;
      tbl = n->as_table();
      if (!tbl) fail("--set", "cannot set " + key + ": " + walked + " is not a table");
    }
    parsed.get("v")->visit([&](auto& v) { tbl->insert_or_assign(parts.back(), std::move(v)); });
  }

  Scene interpret(const toml::table& root, const std::string& default_name) {
    Scene s;
    keys(root, "", {"name", "description", "gravity", "notes", "body", "contact", "initial", "run", "engines"});
    const auto name = opt_string(root, "", "name");
    s.name = name.value_or(default_name);
    if (!is_valid_name(s.name))
      fail("name", "\"" + s.name + "\"" + (name ? "" : " (the file's stem)") + " is not a usable name (" + kNameRule +
                       "; it names output directories)");
    s.description = opt_string(root, "", "description").value_or("");
    if (s.description.find_first_of("\r\n") != std::string::npos) fail("description", "must be one line");
    s.gravity = need_number(root, "", "gravity");
    if (!(s.gravity > 0)) out_of_range("gravity", s.gravity, "gravity > 0");
    if (const toml::node* n = root.get("notes")) s.notes = read_notes(*n);

    // contact first: whether a stem exists decides which body keys are required.
    read_contact(need_table(root, "", "contact"), s.contact);
    read_body(need_table(root, "", "body"), s);
    read_initial(need_table(root, "", "initial"), s);
    read_run(need_table(root, "", "run"), s.run);
    if (const toml::node* e = root.get("engines")) read_engines(*e, s);
    return s;
  }

 private:
  // A coefficient that belongs to another friction law: harmless only when it is 0.
  void must_be_zero_if_present(const toml::table& t, const char* key, const char* law) const {
    if (auto v = opt_number(t, "contact", key); v && *v != 0.0)
      fail(join_path("contact", key), std::string("does not apply to friction = \"") + law +
                                          "\" (only 0 is accepted), got " + num(*v));
  }

  void read_contact(const toml::table& t, ContactSpec& c) const {
    keys(t, "contact", {"friction", "mu", "k", "drilling", "drilling_law", "stem", "flight"});
    const auto law = opt_string(t, "contact", "friction");
    if (!law) fail("contact.friction", "missing (required: rolling, viscous, gliding, coulomb or none)");
    if (*law == "rolling") c.friction = FrictionLaw::Rolling;
    else if (*law == "viscous") c.friction = FrictionLaw::Viscous;
    else if (*law == "gliding") c.friction = FrictionLaw::Gliding;
    else if (*law == "coulomb") c.friction = FrictionLaw::Coulomb;
    else if (*law == "none") c.friction = FrictionLaw::None;
    else fail("contact.friction", "unknown law \"" + *law + "\" (expected rolling, viscous, gliding, coulomb or none)");

    if (c.friction == FrictionLaw::Coulomb || c.friction == FrictionLaw::Gliding) {
      // Coulomb: dimensionless; gliding: F_t = -mu F_n v_C, mu in s/m (Rutstam 2012).
      c.mu = need_number(t, "contact", "mu");
      // No upper bound on mu or k: large values are how a scene approaches rolling.
      if (!(c.mu >= 0)) out_of_range("contact.mu", c.mu, "mu >= 0");
    } else {
      must_be_zero_if_present(t, "mu", law->c_str());
    }
    if (c.friction == FrictionLaw::Viscous) {
      c.k = need_number(t, "contact", "k");
      if (!(c.k >= 0)) out_of_range("contact.k", c.k, "k >= 0");
    } else {
      must_be_zero_if_present(t, "k", law->c_str());
    }
    if (c.friction == FrictionLaw::None) {
      must_be_zero_if_present(t, "drilling", law->c_str());
    } else {
      c.drilling = opt_number(t, "contact", "drilling").value_or(0.0);
      if (!(c.drilling >= 0)) out_of_range("contact.drilling", c.drilling, "drilling >= 0");
    }
    // The coupled Coulomb-Contensou law bounds the Coulomb force and the drilling torque
    // jointly: it needs both bounds (mu > 0, mu_d > 0) and the Coulomb law to couple to.
    const std::string drill_law = opt_string(t, "contact", "drilling_law").value_or("decoupled");
    if (drill_law == "decoupled") {
      c.drilling_law = DrillingLaw::Decoupled;
    } else if (drill_law == "coupled") {
      c.drilling_law = DrillingLaw::Coupled;
      if (c.friction != FrictionLaw::Coulomb)
        fail("contact.drilling_law", std::string("\"coupled\" needs friction = \"coulomb\" (it bounds the Coulomb force and the "
                                     "drilling torque jointly), got friction = \"") + *law + "\"");
      if (!(c.mu > 0)) fail("contact.drilling_law", "\"coupled\" needs contact.mu > 0, got " + num(c.mu));
      if (!(c.drilling > 0)) fail("contact.drilling_law", "\"coupled\" needs contact.drilling > 0 (mu_d, the bound of the drilling torque per unit normal force), got " + num(c.drilling));
    } else {
      fail("contact.drilling_law", "unknown law \"" + drill_law + "\" (expected decoupled or coupled)");
    }
    c.stem = opt_bool(t, "contact", "stem").value_or(true);
    c.flight = opt_bool(t, "contact", "flight").value_or(false);
  }

  void read_body(const toml::table& t, Scene& s) const {
    static const char* const direct[] = {"mass", "com_offset", "inertia_transverse", "inertia_axial"};
    keys(t, "body", {"sphere_radius", "stem_radius", "stem_length", "truncation_height", "density", "mass_model",
                     "mass", "com_offset", "inertia_transverse", "inertia_axial"});
    BodyGeometry& b = s.body;
    b.sphere_radius = need_positive(t, "body", "sphere_radius");
    if (s.contact.stem) {
      b.stem_radius = need_positive(t, "body", "stem_radius");
      b.stem_length = need_positive(t, "body", "stem_length");
    } else {
      // Without stem contact the stem may still carry mass, so its size is used when given.
      if (t.contains("stem_radius")) b.stem_radius = need_positive(t, "body", "stem_radius");
      if (t.contains("stem_length")) b.stem_length = need_positive(t, "body", "stem_length");
    }
    b.truncation_height = need_number(t, "body", "truncation_height");
    if (!(b.truncation_height > 0 && b.truncation_height <= b.sphere_radius))
      out_of_range("body.truncation_height", b.truncation_height,
                   "0 < truncation_height <= sphere_radius = " + num(b.sphere_radius));
    const auto problems = geometry_problems(b, s.contact.stem);
    if (!problems.empty()) throw SceneError(body_message(problems.front()));

    size_t given = 0;
    for (const char* k : direct) given += t.contains(k) ? 1 : 0;
    if (given == 4) {
      for (const char* k : {"density", "mass_model"})
        if (t.contains(k))
          fail(join_path("body", k), "not used when mass, com_offset, inertia_transverse and inertia_axial are given; remove it");
      b.mass_model = MassModel::Given;
      b.density = 0.0;
      MassProperties& m = s.mass;
      m.mass = need_positive(t, "body", "mass");
      m.com_offset = need_number(t, "body", "com_offset");
      m.inertia_transverse = need_positive(t, "body", "inertia_transverse");
      m.inertia_axial = need_positive(t, "body", "inertia_axial");
      if (!(std::abs(m.com_offset) < b.sphere_radius))
        out_of_range("body.com_offset", m.com_offset,
                     "-R < com_offset < R, R = sphere_radius = " + num(b.sphere_radius));
      if (m.inertia_axial > 2 * m.inertia_transverse)
        out_of_range("body.inertia_axial", m.inertia_axial,
                     "inertia_axial <= 2 inertia_transverse = " + num(2 * m.inertia_transverse) +
                         ": the triangle inequality of an axisymmetric body");
      return;
    }
    if (given > 0) {
      for (const char* k : direct)
        if (!t.contains(k))
          fail(join_path("body", k), "missing: mass properties given directly need all of mass, com_offset, "
                                     "inertia_transverse and inertia_axial");
    }
    b.density = need_positive(t, "body", "density");
    const auto model = opt_string(t, "body", "mass_model");
    if (!model) fail("body.mass_model", "missing (required with density: \"solid\" or \"seed\")");
    if (*model == "solid") b.mass_model = MassModel::Solid;
    else if (*model == "seed") b.mass_model = MassModel::Seed;
    else fail("body.mass_model", "unknown model \"" + *model + "\" (expected \"solid\" or \"seed\")");
    try {
      s.mass = compute_mass_properties(b);
    } catch (const std::invalid_argument& e) {
      throw SceneError(body_message(e.what()));
    }
  }

  // Messages from the mass-properties code start with "QUANTITY: "; when QUANTITY is a body
  // key it becomes the dotted key, otherwise the whole message is the reason for "body".
  std::string body_message(const std::string& what) const {
    static const std::set<std::string> body_keys = {"sphere_radius", "stem_radius", "stem_length",
                                                    "truncation_height", "density", "mass_model",
                                                    "mass", "com_offset", "inertia_transverse",
                                                    "inertia_axial"};
    const auto colon = what.find(": ");
    const bool keyed = colon != std::string::npos && body_keys.count(what.substr(0, colon));
    return file() + ": body" + (keyed ? "." : ": ") + what;
  }

  // One line each: a note is printed as a line of `tippe run` and a list item of a report.
  std::vector<std::string> read_notes(const toml::node& n) const {
    const auto* a = n.as_array();
    if (!a) fail("notes", "expected an array of strings, got " + toml_value_text(n));
    std::vector<std::string> out;
    for (size_t i = 0; i < a->size(); ++i) {
      const std::string key = "notes[" + std::to_string(i) + "]";
      const auto* str = a->get(i)->as_string();
      if (!str) fail(key, "expected a string, got " + toml_value_text(*a->get(i)));
      if (str->get().empty() || str->get().find_first_of("\r\n") != std::string::npos)
        fail(key, "must be one non-empty line");
      out.push_back(str->get());
    }
    return out;
  }

  void read_initial(const toml::table& t, Scene& s) const {
    keys(t, "initial", {"tilt", "orientation", "position", "spin", "omega", "velocity", "omega_along_contact", "height"});
    InitialSpec& in = s.initial;
    const auto orientation = opt_numbers(t, "initial", "orientation", 4);
    if (orientation) {
      if (t.contains("tilt")) fail("initial.orientation", "give either tilt or orientation, not both");
      // A unit quaternion (w, x, y, z); 1e-9 admits one written with 10 significant digits and
      // refuses one that is not meant as a rotation.
      const double norm = std::sqrt((*orientation)[0] * (*orientation)[0] + (*orientation)[1] * (*orientation)[1] +
                                    (*orientation)[2] * (*orientation)[2] + (*orientation)[3] * (*orientation)[3]);
      if (!(std::abs(norm - 1.0) <= 1e-9))
        fail("initial.orientation", "must be a unit quaternion [w, x, y, z], got norm " + num(norm));
      in.orientation_given = true;
      std::copy(orientation->begin(), orientation->end(), in.orientation.begin());
    } else {
      in.tilt = need_number(t, "initial", "tilt");
      if (!(in.tilt >= 0 && in.tilt <= kPi)) out_of_range("initial.tilt", in.tilt, "0 <= tilt <= pi = " + num(kPi) + " rad");
    }
    if (const auto p = opt_numbers(t, "initial", "position", 2)) std::copy(p->begin(), p->end(), in.position.begin());
    const auto spin = opt_number(t, "initial", "spin");
    const auto omega = opt_numbers(t, "initial", "omega", 3);
    if (spin && omega) fail("initial.omega", "give either spin or omega, not both");
    if (!spin && !omega) fail("initial.spin", "missing (give spin or omega)");
    if (spin) in.spin = *spin;
    if (omega) {
      in.omega_given = true;
      std::copy(omega->begin(), omega->end(), in.omega_B.begin());
    }
    if (const auto v = opt_numbers(t, "initial", "velocity", 2)) {
      if (s.contact.friction == FrictionLaw::Rolling)
        fail("initial.velocity", "not allowed with friction = \"rolling\": the velocity of G is derived for rolling "
                                 "(v_G = R_C x omega)");
      in.velocity_given = true;
      std::copy(v->begin(), v->end(), in.velocity.begin());
    }
    in.omega_along_contact = opt_bool(t, "initial", "omega_along_contact").value_or(false);
    if (in.omega_along_contact && in.omega_given)
      fail("initial.omega_along_contact", "takes its magnitude from spin; it cannot be combined with omega");
    in.height = opt_number(t, "initial", "height").value_or(0.0);
    if (!(in.height >= 0)) out_of_range("initial.height", in.height, "height >= 0");
    if (in.height > 0 && !s.contact.flight)
      fail("initial.height", "a start above the floor needs contact.flight = true");
  }

  void read_run(const toml::table& t, RunSpec& r) const {
    keys(t, "run", {"duration", "sample_interval", "rtol", "atol", "method", "self_check", "energy_gain_rule"});
    r.duration = need_positive(t, "run", "duration");
    r.sample_interval = need_number(t, "run", "sample_interval");
    if (!(r.sample_interval > 0 && r.sample_interval <= r.duration))
      out_of_range("run.sample_interval", r.sample_interval, "0 < sample_interval <= duration = " + num(r.duration));
    if (r.duration / r.sample_interval + 1 > kMaxSamples)
      fail("run.sample_interval",
           num(r.sample_interval) + " gives " + num(r.duration / r.sample_interval + 1) + " samples, up to " +
               num(std::ceil((r.duration / r.sample_interval + 1) * kTrajectoryRowMax / 1048576.0)) +
               " MiB of trajectory, over the budget of " + num(kMaxTrajectoryBytes / 1048576.0) +
               " MiB (expected sample_interval >= " + num(r.duration / (std::floor(kMaxSamples) - 1)) + ")");
    r.rtol = opt_number(t, "run", "rtol").value_or(r.rtol);
    if (!(r.rtol >= kMinRtol && r.rtol <= kMaxRtol))
      out_of_range("run.rtol", r.rtol, num(kMinRtol) + " <= rtol <= " + num(kMaxRtol));
    r.atol = opt_number(t, "run", "atol").value_or(r.atol);
    // atol is in the scene's own units, so only its sign is certain; the bound of 1 is a
    // judgement: it would swamp the states of every shipped scene (of order 1 or smaller).
    if (!(r.atol > 0 && r.atol <= 1)) out_of_range("run.atol", r.atol, "0 < atol <= 1");
    if (const toml::node* m = t.get("method")) {
      const auto* str = m->as_string();
      if (!str) fail("run.method", "expected a string, got " + toml_value_text(*m));
      r.method = str->get();
      if (r.method != "bulirsch_stoer" && r.method != "dopri5" && r.method != "rosenbrock4")
        fail("run.method", "must be \"bulirsch_stoer\", \"dopri5\" or \"rosenbrock4\", got \"" + r.method + "\"");
    }
    r.self_check = opt_bool(t, "run", "self_check").value_or(true);
    if (const toml::node* m = t.get("energy_gain_rule")) {
      const auto* str = m->as_string();
      if (!str) fail("run.energy_gain_rule", "expected a string, got " + toml_value_text(*m));
      r.energy_gain_rule = str->get();
      const std::vector<std::string>& rules = energy_gain_rule_names();
      if (std::find(rules.begin(), rules.end(), r.energy_gain_rule) == rules.end()) {
        std::vector<std::string> quoted;
        for (const std::string& n : rules) quoted.push_back("\"" + n + "\"");
        fail("run.energy_gain_rule", "must be " + join(quoted, " or ") + ", got \"" + r.energy_gain_rule + "\"");
      }
    }
    for (const char* k : {"rtol", "atol", "method", "self_check"})
      if (t.contains(k)) r.alias_keys.push_back(k);
  }

  SettingValue to_setting(const toml::node& n, const std::string& path) const {
    if (const auto* b = n.as_boolean()) return b->get();
    if (const auto* i = n.as_integer()) return static_cast<long long>(i->get());
    if (n.is_floating_point()) return number(n, path);
    if (const auto* s = n.as_string()) return s->get();
    if (const auto* a = n.as_array()) {
      std::vector<double> out;
      for (size_t i = 0; i < a->size(); ++i) out.push_back(number(*a->get(i), path + "[" + std::to_string(i) + "]"));
      return out;
    }
    fail(path, "unsupported value (" + toml_value_text(n) +
                   "; expected a boolean, number, string or array of numbers)");
  }

  void read_engines(const toml::node& node, Scene& s) const {
    const auto* t = node.as_table();
    if (!t) fail("engines", "expected a table of [engines.NAME] tables, got " + toml_value_text(node));
    for (auto&& [name, table] : *t) {
      const std::string prefix = "engines." + std::string(name.str());
      const auto* et = table.as_table();
      if (!et) fail(prefix, "expected a table, got " + toml_value_text(table));
      auto& dst = s.engines[std::string(name.str())];
      for (auto&& [k, v] : *et) dst[std::string(k.str())] = to_setting(v, prefix + "." + std::string(k.str()));
    }
  }
};

}  // namespace

SceneFile read_scene_file(const std::string& path, const std::vector<std::string>& overrides) {
  std::string text;
  try {
    text = read_file_text(path, kMaxInputFileBytes);
  } catch (const std::runtime_error& e) {
    throw SceneError(e.what());
  }
  return parse_scene_file(text, path, overrides);
}

SceneFile parse_scene_file(const std::string& text, const std::string& file_label,
                           const std::vector<std::string>& overrides) {
  // The label is the scene's source_file in every JSON record: checked before any work is done.
  if (!is_valid_utf8(file_label)) throw SceneError(file_label + ": cannot read: the path is not valid UTF-8");
  toml::table root = parse_toml(text, file_label);

  Interpreter interp(file_label, overridden_keys(overrides));
  for (const auto& o : overrides) interp.apply_override(root, o);

  SceneFile f{interp.interpret(root, std::filesystem::path(file_label).stem().string()), text, overrides};
  f.scene.source_file = file_label;
  f.scene.content_hash = scene_content_hash(text, overrides);
  return f;
}

std::string scene_content_hash(const std::string& text, const std::vector<std::string>& overrides,
                               const std::vector<std::pair<std::string, std::string>>& inputs) {
  Fnv1a64 h;
  h.add(text);
  // Each further input under its key, a separator on either side.
  for (const auto& [key, bytes] : inputs) {
    h.add(static_cast<unsigned char>(0));
    h.add(key);
    h.add(static_cast<unsigned char>(0));
    h.add(bytes);
  }
  // A separator keeps {"a", "bc"} and {"ab", "c"} apart.
  for (const auto& o : overrides) {
    h.add(static_cast<unsigned char>(0));
    h.add(o);
  }
  return h.hex();
}

std::set<std::string> overridden_keys(const std::vector<std::string>& overrides) {
  std::set<std::string> keys;
  for (const auto& o : overrides) keys.insert(trim(o.substr(0, o.find('='))));
  return keys;
}

std::string quote_scene_error(const SceneError& e, const std::string& scene_path) {
  std::string msg = e.what();
  const std::string prefix = scene_path + ": ";
  if (msg.rfind(prefix, 0) == 0) msg = msg.substr(prefix.size()) + " (scene " + scene_path + ")";
  return msg;
}

}  // namespace tippe
