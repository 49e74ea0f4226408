#!/usr/bin/env bash
# Installs the dependencies and builds into build/ (warnings are errors): scripts/build.sh [TARGET ...] builds those targets and what they need; no target: everything (the test programs and benchmarks too).
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install-deps.sh
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release -DTIPPE_WERROR=ON >/dev/null
if [ "$#" -eq 0 ]; then
  cmake --build build -j"$(nproc)"
else
  cmake --build build -j"$(nproc)" --target "$@"
fi
