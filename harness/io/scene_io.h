// Scene files: TOML -> Scene with every key checked (its [engines.*] tables raw), command-line overrides, and Scene -> JSON.
#pragma once

#include <stdexcept>
#include <filesystem>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "harness/io/names.h"  // is_valid_name and the UTF-8 rules, which a scene's name and path meet
#include "analytic/scene.h"

namespace tippe {

// Invalid scene input. The message is always "FILE: KEY: reason" with KEY dotted
// ("body.stem_radius", "engines.NAME.KEY", "--set" for a malformed override), except
// for TOML syntax errors, which read "FILE:LINE:COL: reason", and an unreadable file
// ("FILE: cannot read: reason"). A value outside its range reads
// "FILE: KEY: VALUE is out of range (expected RANGE)"; a wrong type names the value too
// ("expected a number, got a string '0.1'", as TOML writes it).
class SceneError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// A scene error quoted by another file's reader (a sweep or gate naming the scene): the scene's own
// message without its "FILE: " prefix, with the scene file named at the end.
std::string quote_scene_error(const SceneError& e, const std::string& scene_path);

// A scene as its file says it: every key checked but the [engines.NAME] tables, which are only
// copied (bool, integer -> long long, float -> double, string, array of numbers -> vector<double>).
// What the tables mean (each engine's settings, the reference's, an engine's files) is the
// resolve step's, one layer up (scene/resolve.h: load_scene), the only way a run gets a Scene.
struct SceneFile {
  Scene scene;                         // engines raw; content_hash = scene_content_hash(text, overrides)
  std::string text;                    // the file's bytes
  std::vector<std::string> overrides;  // as given, in order
};

// Reads a scene file. `overrides` are "KEY=VALUE" strings (KEY dotted, VALUE a TOML value or,
// if it does not parse as one, a bare string) applied to the parsed document before it is
// interpreted, creating tables as needed.
//
// Rules beyond "every key known, every type right, every number finite" (integers are
// accepted for floats, booleans are not numbers):
//  - required: gravity (> 0), body.sphere_radius, body.truncation_height (0 < h <= R),
//    contact.friction, initial.tilt ([0, pi]) or initial.orientation (a unit quaternion
//    [w, x, y, z], |q| within 1e-9 of 1; not both), one of initial.spin / initial.omega,
//    run.duration (> 0), run.sample_interval (> 0, <= duration, at most ~1.2e6 samples: a 1 GiB
//    budget of trajectory bytes).
//    body.stem_radius and body.stem_length are required unless contact.stem = false; when
//    given they must be positive and, for every scene, pass geometry_problems(body, stem).
//  - optional with defaults: name (file stem; letters, digits, '.', '_', '-'), description
//    (one line), contact.drilling (0), contact.stem (true), contact.flight (false),
//    initial.velocity (not given), initial.position ([0, 0], G's x and y),
//    initial.omega_along_contact (false), initial.height (0, >= 0), notes (one line each),
//    run.rtol (1e-10, in [1e-15, 1e-2]), run.atol (1e-12, in (0, 1]): the older spelling of
//    [engines.analytic] rtol and atol (method and self_check too), where the shipped scenes give them.
//  - mass: either density (> 0) and mass_model ("solid" | "seed"), both required, then
//    compute_mass_properties(body); or all four of mass, com_offset, inertia_transverse,
//    inertia_axial (MassModel::Given; density and mass_model must then be absent), with
//    M, A, C > 0, |d| < R and C <= 2A.
//  - friction laws: coulomb needs mu >= 0 (dimensionless), viscous needs k >= 0 (F_t = -k v_C,
//    N s/m), gliding needs mu >= 0 (F_t = -mu F_n v_C, Rutstam 2012: mu in s/m). A coefficient
//    of another law (mu with viscous, k with coulomb or gliding, ...) is accepted only when it is 0, so one template can
//    carry every key without silently changing the physics; drilling (>= 0) applies to every
//    law but "none", where it too must be 0. contact.drilling_law: "decoupled" (default) or
//    "coupled" (Leine and Glocker's ellipse), which needs friction = "coulomb", mu > 0 and
//    drilling > 0.
//  - initial: rolling derives the velocity of G, so initial.velocity is rejected with it;
//    omega_along_contact takes its magnitude from spin and so cannot be combined with omega.
//  - [engines.NAME] tables: each a table, each value one of the types above.
// A path that is not valid UTF-8, and a --set value that is not valid UTF-8 and not a TOML value,
// are rejected: records are JSON.
// SceneFile::scene.source_file is `path` as given.
SceneFile read_scene_file(const std::string& path, const std::vector<std::string>& overrides = {});

// What read_scene_file does once it has the file's bytes: `text` is parsed and checked as above,
// `file_label` takes the place of the path in messages, the default name (its stem) and
// Scene::source_file. Touches no file; SceneError is the only exception it throws for any input.
SceneFile parse_scene_file(const std::string& text, const std::string& file_label,
                           const std::vector<std::string>& overrides = {});

// A scene's content hash: FNV-1a 64 (16 hex digits) over the file's bytes, then for each further
// input file (KEY, BYTES) '\0' KEY '\0' BYTES (so a changed input file is a changed scene), then
// for each override '\0' OVERRIDE.
std::string scene_content_hash(const std::string& text, const std::vector<std::string>& overrides,
                               const std::vector<std::pair<std::string, std::string>>& inputs = {});

// The dotted keys of "KEY=VALUE" overrides, trimmed (to tell which keys a --set gave).
std::set<std::string> overridden_keys(const std::vector<std::string>& overrides);

// Every field of a scene, its mass properties and engine tables, for run records.
nlohmann::json scene_to_json(const Scene& scene);

// One engine setting as JSON (arrays of numbers become JSON arrays).
nlohmann::json setting_to_json(const SettingValue& value);

}  // namespace tippe
