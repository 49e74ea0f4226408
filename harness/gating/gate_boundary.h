// Gate checks on a sweep's boundary search ([[boundary]] in a gate file): the largest safe setting bounded, so that CI fails when it shrinks.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "harness/gating/gate.h"
#include "harness/sweep/sweep.h"

namespace tippe {

// One [[boundary]] table:
//   name = "ode-safe-step"                       # required, unique among the file's checks and boundaries
//   sweep = "../sweeps/search-tiny.toml"         # a sweep file, relative to the gate file
//   setup = "ode-regime"                         # a setup of it with ladder.search
//   scene = "toy_viscous"                        # a scene of it (by name); optional when it has one
//   grid = "1"                                   # the grid value's label, when the setup has a grid
//   require = "max_safe_timestep >= 1e-3"        # boundary_quantity(key) and a bound (parse_bound_text)
//   allow_non_monotonic = false                  # true: a criterion that comes and goes still passes on its first boundary
struct BoundaryCheck {
  std::string name, sweep, sweep_path, setup, scene, grid;
  BoundText require;
  bool allow_non_monotonic = false;
};

// The [[boundary]] tables of a gate file (none: empty), each checked against its sweep file
// (loaded): throws SceneError "FILE: boundary[i].KEY: reason".
std::vector<BoundaryCheck> load_boundary_checks(const std::string& gate_path, const std::vector<std::string>& check_names);

// Pure: the verdict of a boundary check on the records of its sweep. Rows: the search's state
// ("search": found, all_safe, none_safe, incomplete, not_applicable), monotonic (unless allowed),
// then the bound on the boundary. none_safe fails a ">=" bound on a max_safe quantity (nothing is safe).
CheckResult evaluate_boundary(const BoundaryCheck& check, const std::vector<SweepRecord>& records);

}  // namespace tippe
