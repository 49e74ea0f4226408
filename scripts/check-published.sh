#!/usr/bin/env bash
# The published records still follow from the code: reruns three scenes' comparisons and a few points of the default sweep, and fails when a run's status, class, regime or event times (to 1e-6) differ from reports/: scripts/check-published.sh [BUILD_DIR] (default build).
set -euo pipefail

root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build="${1:-build}"
case "$build" in /*) ;; *) build="$root/$build" ;; esac
tippe="$build/tippe"
if [ ! -x "$tippe" ]; then
  echo "check-published: $tippe not found; build it first: cmake --build $build --target tippe" >&2
  exit 2
fi
# PUBLISHED_DIR: the published records to check against (default reports/; a test points it at a
# tampered copy). CHECK_SCENES: scene names under harness/scenes/ (the cheapest three: about 5 CPU
# seconds of engines). CHECK_SWEEP: a sweep file whose points are among PUBLISHED_DIR/CHECK_SWEEP_DIR's
# records (empty: no sweep).
published="${PUBLISHED_DIR:-$root/reports}"
scenes="${CHECK_SCENES-leine_glocker_coupled toy_viscous rutstam_ball}"
sweep="${CHECK_SWEEP-harness/sweeps/published-check.toml}"
sweep_dir="${CHECK_SWEEP_DIR:-sweep-default}"
jobs="${JOBS:-$(nproc 2>/dev/null || echo 2)}"
work="$(mktemp -d "${TMPDIR:-/tmp}/tippe-check-published.XXXXXX")"
trap 'rm -rf "$work"' EXIT

# Scene paths relative to the repository root, as publish-reports.sh runs them.
cd "$root"
rc=0
for name in $scenes; do
  # As publish-reports.sh makes them: a fresh reference, no cache (plots are not compared).
  "$tippe" compare "harness/scenes/$name.toml" --out "$work/$name" --jobs "$jobs" --no-cache --no-plots --quiet >/dev/null
  python3 "$root/scripts/check_published.py" comparison "$published/$name/comparison.json" "$work/$name/comparison.json" || rc=1
done
if [ -n "$sweep" ]; then
  "$tippe" sweep "$sweep" --out "$work/sweep" --jobs "$jobs" --no-plots --quiet >/dev/null
  python3 "$root/scripts/check_published.py" sweep "$published/$sweep_dir/records.jsonl" "$work/sweep/records.jsonl" || rc=1
fi
if [ "$rc" -ne 0 ]; then
  echo "check-published: the code no longer gives the published records (above); republish from a clean checkout: scripts/publish-all.sh" >&2
fi
exit "$rc"
