#!/usr/bin/env bash
# Regenerates reports/sweep-default/ (index.html, report.md, SVGs, records.jsonl, sweep.json) from harness/sweeps/default.toml: scripts/publish-sweep.sh [BUILD_DIR] (default build).
set -euo pipefail

root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build="${1:-build}"
case "$build" in /*) ;; *) build="$root/$build" ;; esac
tippe="$build/tippe"
if [ ! -x "$tippe" ]; then
  echo "publish-sweep: $tippe not found; build it first: cmake --build $build --target tippe" >&2
  exit 2
fi
# One run per core by default; JOBS=N overrides.
jobs="${JOBS:-$(nproc 2>/dev/null || echo 2)}"
# SWEEP=FILE publishes another sweep (into reports/sweep-<its name>/); REPORTS_DIR=DIR writes
# elsewhere than reports/.
sweep="${SWEEP:-harness/sweeps/default.toml}"
reports="${REPORTS_DIR:-$root/reports}"
source "$root/scripts/publish-guard.sh" publish-sweep
name="sweep-$(basename "$sweep" .toml)"
# The sweep runs in a scratch directory (fresh: what is published comes from this build alone).
# SWEEP_OUT=DIR runs it there instead and keeps it, so that an interrupted publish resumes where
# it stopped when run again with the same SWEEP_OUT.
if [ -n "${SWEEP_OUT:-}" ]; then
  work="$SWEEP_OUT"
else
  scratch="$(mktemp -d "${TMPDIR:-/tmp}/tippe-publish-sweep.XXXXXX")"
  trap 'rm -rf "$scratch"' EXIT
  work="$scratch/$name"
fi

# Paths relative to the repository root, so the records name the scenes the same everywhere.
cd "$root"
echo "publish-sweep: $sweep -> $reports/$name/ (jobs $jobs)" >&2
"$tippe" sweep "$sweep" --out "$work" --jobs "$jobs"

rm -rf "${reports:?}/$name"
mkdir -p "$reports/$name"
cp "$work/index.html" "$work/report.md" "$work/records.jsonl" "$work/sweep.json" "$reports/$name/"
for svg in "$work"/*.svg; do
  [ -e "$svg" ] && cp "$svg" "$reports/$name/"
done
echo "publish-sweep: wrote $reports/$name/index.html" >&2
