// Small sweep files for the tests that load and run them: a head on the shipped dimensionless scene and one ODE setup, written where a test says.
#pragma once

#include <filesystem>
#include <string>

#include "tests/support/files.h"

namespace tippe::fixtures {

// Writes a sweep file whose scene is the shipped source_dimensionless (absolute path).
inline std::filesystem::path write_sweep(const std::filesystem::path& dir, const std::string& body, const std::string& name = "s.toml") {
  const std::filesystem::path p = dir / name;
  spit(p, body);
  return p;
}

static const std::string kGoodHead = "repeats = 1\nduration = 0.5\nscenes = [\"" TIPPE_SOURCE_DIR "/harness/scenes/source_dimensionless.toml\"]\n";
static const std::string kGoodSetup =
    "[[setup]]\nname = \"ode\"\nengine = \"ode\"\nladder.key = \"engines.ode.timestep\"\n"
    "ladder.values = [1e-3, 5e-4]\n";

}  // namespace tippe::fixtures
