// Factory functions of the individual simulators, gathered by make_simulator.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "engines/core/simulator.h"

namespace tippe {

std::unique_ptr<Simulator> make_analytic_simulator(const Scene& scene);
std::unique_ptr<Simulator> make_bullet_simulator(const Scene& scene);
std::unique_ptr<Simulator> make_ode_simulator(const Scene& scene);
std::unique_ptr<Simulator> make_mujoco_simulator(const Scene& scene);

// The MJCF text of a scene's MuJoCo model (what `tippe export-mjcf` writes).
std::string mujoco_mjcf(const Scene& scene);
// What a scene's physics has that the MJCF of mujoco_mjcf does not carry (a law the bench applies
// itself each step, such as viscous friction), one sentence each; empty when the file alone is
// the scene.
std::vector<std::string> mujoco_mjcf_missing(const Scene& scene);

// Each throws std::invalid_argument naming the key when the scene's [engines.NAME] table has
// an unknown key, a wrong type or a value out of range.
void validate_bullet_settings(const Scene& scene);
void validate_ode_settings(const Scene& scene);
void validate_mujoco_settings(const Scene& scene);

// Validates the [engines.NAME] table of every engine against its settings struct; throws
// std::invalid_argument naming the key.
void validate_engine_settings(const Scene& scene);

}  // namespace tippe
