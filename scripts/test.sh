#!/usr/bin/env bash
# Install, build everything (the test programs, benchmarks and the Python module besides `tippe`) and run the whole test suite (CTest over GoogleTest).
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/build.sh
cd build
# The JUnit file tells .ci/run which tests ran and passed (ctest -N rewrites LastTest.log).
ctest --output-on-failure -j"$(nproc)" --timeout 900 --output-junit ctest-junit.xml
