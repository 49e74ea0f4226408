#!/usr/bin/env bash
# Runs the full extremes battery and publishes it: reports/sweep-extremes/ and reports/sweep-extremes-long/ (scripts/publish-extremes.sh [BUILD_DIR]).
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
for sweep in harness/sweeps/extremes.toml harness/sweeps/extremes-long.toml; do
  SWEEP="$sweep" bash "$root/scripts/publish-sweep.sh" "${1:-build}"
done
