#!/usr/bin/env bash
# Regenerates every published page from one commit: the comparison reports, the sweeps, the extremes battery, the index, BENCHMARKS.md's result tables, and the outputs its speed tables are copied from; refuses a working tree with changes, so every record and page names a commit that holds exactly the code that made it: scripts/publish-all.sh [BUILD_DIR] (default build-publish).
set -euo pipefail

root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
cd "$root"
if [ -n "$(git status --porcelain --untracked-files=normal 2>/dev/null)" ] || ! git rev-parse HEAD >/dev/null 2>&1; then
  echo "publish-all: the working tree has changes (git status): publish from a clean checkout of a commit" >&2
  exit 2
fi
commit="$(git rev-parse --short=12 HEAD)"
build="${1:-build-publish}"
case "$build" in /*) ;; *) build="$root/$build" ;; esac
# A build of this commit (configuring again when HEAD moved, so the binary names this commit).
cmake -S "$root" -B "$build" -DCMAKE_BUILD_TYPE=Release -DTIPPE_WERROR=ON >/dev/null
cmake --build "$build" -j"$(nproc 2>/dev/null || echo 2)" --target tippe
if [ "${PUBLISH_BENCHMARKS:-1}" = 1 ]; then
  cmake --build "$build" -j"$(nproc 2>/dev/null || echo 2)" --target bench_reference bench_engines
fi
echo "publish-all: publishing from commit $commit with $build" >&2

bash scripts/publish-reports.sh "$build"
bash scripts/publish-sweep.sh "$build"
for sweep in modelling horizon boundaries simbody siconos; do
  SWEEP="harness/sweeps/$sweep.toml" bash scripts/publish-sweep.sh "$build"
done
bash scripts/publish-extremes.sh "$build"
# The index last: its sweep matrices read the sweeps just published.
"$build/tippe" report reports --index >/dev/null
# BENCHMARKS.md's result tables, copied from the pages just published (no table by hand).
python3 scripts/benchmarks-tables.py

# The outputs BENCHMARKS.md's speed tables are copied from, each headed by the commit (machine
# dependent: they are not checked by CI, only regenerated here).
if [ "${PUBLISH_BENCHMARKS:-1}" = 1 ]; then
  bench="$root/out/publish-$commit"
  mkdir -p "$bench"
  {
    echo "# commit $commit"
    "$build/bench/bench_reference"
  } >"$bench/bench_reference.txt"
  {
    echo "# commit $commit"
    "$build/bench/bench_engines" --benchmark_repetitions=3 --benchmark_report_aggregates_only=true
  } >"$bench/bench_engines.txt"
  echo "publish-all: benchmark outputs in $bench (copy the numbers into BENCHMARKS.md's tables)" >&2
fi

# Every record must name this commit: a record left from an earlier publication would not.
stale="$(grep -H '"git_commit"' reports/*/comparison.json reports/*/sweep.json reports/*/records.jsonl | grep -v "\"git_commit\": *\"$commit\"" | cut -d: -f1 | sort -u || true)"
if [ -n "$stale" ]; then
  echo "publish-all: records that do not name commit $commit:" >&2
  echo "$stale" >&2
  exit 1
fi
echo "publish-all: every published record names commit $commit; commit reports/ to publish it" >&2
