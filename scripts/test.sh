#!/usr/bin/env bash
# Install, build and run the whole test suite (CTest over GoogleTest).
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/build.sh
cd build
ctest --output-on-failure -j"$(nproc)" --timeout 900
