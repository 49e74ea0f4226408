#!/usr/bin/env bash
# Sweep throughput locally and over MPI ranks, and the coordinator's cost per point (BENCHMARKS.md, "Sweeps over MPI ranks").
# Usage: bash scripts/bench-mpi.sh [OUT_DIR]   (build/ must hold a Release build with MPI)
set -euo pipefail
cd "$(dirname "$0")/.."
out="${1:-out/bench-mpi}"
tippe=./build/tippe
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1  # Open MPI refuses root without them
mkdir -p "$out"

# wall seconds of one command
timed() {
  local t0 t1
  t0=$(date +%s.%N)
  "$@" >/dev/null 2>"$out/last.err" || { cat "$out/last.err" >&2; exit 1; }
  t1=$(date +%s.%N)
  awk -v a="$t0" -v b="$t1" 'BEGIN { printf "%.3f", b - a }'
}
calc() { awk "BEGIN { printf \"%.4f\", $1 }"; }
# CPU seconds of the runs themselves (every repeat), without the sweep's own work (comparing with
# the reference, records, report): the sum of each record's work.cpu_seconds_repeats.
run_seconds() {
  awk 'match($0, /"cpu_seconds_repeats":\[[^]]*\]/) {
         n = split(substr($0, RSTART + 23, RLENGTH - 24), v, ",")
         for (i = 1; i <= n; ++i) s += v[i]
       } END { printf "%.4f", s }' "$1/records.jsonl"
}

modes=("local --jobs 1" "local --jobs 2" "mpirun -np 2" "mpirun -np 3")
command_of() {  # MODE SWEEP DIR [ARGS...]
  local mode="$1" sweep="$2" dir="$3"
  shift 3
  case "$mode" in
    local*) echo "$tippe sweep $sweep --out $dir --no-plots ${mode#local } $*" ;;
    mpirun*) echo "mpirun --oversubscribe ${mode#mpirun } $tippe sweep $sweep --out $dir --no-plots $*" ;;
  esac
}

echo "== throughput: harness/sweeps/default.toml, shard 0/4 =="
printf "%-16s %8s %8s %10s %12s\n" mode points wall_s points/s runs_cpu_s
for mode in "${modes[@]}"; do
  dir="$out/throughput-${mode// /_}"
  rm -rf "$dir"
  w=$(timed $(command_of "$mode" harness/sweeps/default.toml "$dir" --shard 0/4))
  n=$(wc -l < "$dir/records.jsonl")
  printf "%-16s %8d %8.1f %10.3f %12.1f\n" "$mode" "$n" "$w" "$(calc "$n / $w")" "$(run_seconds "$dir")"
done

echo "== coordinator cost per point: harness/sweeps/bench-tiny.toml (200 points of ~1 ms) =="
printf "%-16s %8s %10s %10s %14s\n" mode points wall_s resume_s per_point_ms
for mode in "local --jobs 1" "mpirun -np 2"; do
  dir="$out/tiny-${mode// /_}"
  rm -rf "$dir"
  w=$(timed $(command_of "$mode" harness/sweeps/bench-tiny.toml "$dir"))
  # The same command again: nothing to run, so its time is the fixed cost (start, plan, report).
  r=$(timed $(command_of "$mode" harness/sweeps/bench-tiny.toml "$dir"))
  runs=$(run_seconds "$dir")
  printf "%-16s %8d %10.3f %10.3f %14.3f   (runs themselves: %.3f ms/point)\n" "$mode" 200 "$w" "$r" \
    "$(calc "($w - $r) * 1000 / 200")" "$(calc "$runs * 1000 / 200")"
done
