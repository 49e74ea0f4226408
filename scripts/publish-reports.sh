#!/usr/bin/env bash
# Regenerates the published comparison reports in reports/ from every harness/scenes/*.toml, and the index from every record there: scripts/publish-reports.sh [BUILD_DIR] (default build).
set -euo pipefail

root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build="${1:-build}"
case "$build" in /*) ;; *) build="$root/$build" ;; esac
tippe="$build/tippe"
if [ ! -x "$tippe" ]; then
  echo "publish-reports: $tippe not found; build it first: cmake --build $build --target tippe" >&2
  exit 2
fi
# One run per core by default; JOBS=N overrides (each scene runs the reference and three engines).
jobs="${JOBS:-$(nproc 2>/dev/null || echo 2)}"
# REPORTS_DIR=DIR writes elsewhere (e.g. to try the script without touching reports/).
reports="${REPORTS_DIR:-$root/reports}"
source "$root/scripts/publish-guard.sh" publish-reports
# Trajectories and plot data stay in a scratch directory: the published pages need only the
# records, the SVGs and the pages themselves.
work="$(mktemp -d "${TMPDIR:-/tmp}/tippe-publish.XXXXXX")"
trap 'rm -rf "$work"' EXIT

# The scene's name key (what tippe calls the scene), else the file stem.
scene_name() {
  local n
  n="$(sed -n 's/^name[[:space:]]*=[[:space:]]*"\([^"]*\)".*/\1/p' "$1" | head -n 1)"
  [ -n "$n" ] && echo "$n" || basename "$1" .toml
}

# Scene paths relative to the repository root, so the records name them the same everywhere.
cd "$root"
mkdir -p "$reports"
for scene in harness/scenes/*.toml; do
  name="$(scene_name "$scene")"
  echo "publish-reports: $scene -> reports/$name/" >&2
  # A fresh reference (no cache): what is published comes from this build alone.
  "$tippe" compare "$scene" --out "$work/$name" --jobs "$jobs" --no-cache
  rm -rf "${reports:?}/$name"
  mkdir -p "$reports/$name"
  cp "$work/$name/comparison.json" "$reports/$name/"
  for svg in "$work/$name"/*.svg; do
    [ -e "$svg" ] && cp "$svg" "$reports/$name/"
  done
  # The pages from the published files alone: they link only what is published (no trajectory
  # CSVs) and show the plots made from the trajectories in the scratch directory.
  "$tippe" report "$reports/$name" >/dev/null
done

# The index (reports/index.html and reports/README.md: the verdict matrix, the per-engine
# sentences, the scenes and the sweeps) from the records alone; docs/reading-reports.md says how
# to read the pages.
"$tippe" report "$reports" --index >/dev/null
echo "publish-reports: wrote $reports/index.html" >&2
