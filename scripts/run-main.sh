#!/usr/bin/env bash
# The main job: install, build the `tippe` command (not the test suite: scripts/test.sh builds that), and compare every engine with the reference on the default scene.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/build.sh tippe
scene="${1:-harness/scenes/source_dimensionless.toml}"
./build/tippe compare "$scene" --jobs "$(nproc)"
