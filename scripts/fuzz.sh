#!/usr/bin/env bash
# Builds the libFuzzer targets with clang in build-asan (shared with scripts/sanitize.sh) and runs them side by side, each for SECONDS: scripts/fuzz.sh SECONDS [TARGET...]
set -euo pipefail
cd "$(dirname "$0")/.."
root="$(pwd)"
seconds="${1:-60}"
shift || true
build="${FUZZ_BUILD_DIR:-$root/build-asan}"
cxx="${FUZZ_CXX:-clang++}"
command -v "$cxx" >/dev/null || { echo "fuzz: $cxx not found (install clang and libclang-rt-14-dev)" >&2; exit 2; }

# -O1 with line tables: fast to build and to fuzz, with file:line in the reports. ASan/UBSan make
# a memory error or undefined behaviour a crash the fuzzer stops on, not a silent corruption.
# The same configuration as scripts/sanitize.sh, so that after it only the targets are built.
cmake -S . -B "$build" -DCMAKE_CXX_COMPILER="$cxx" -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O1 -gline-tables-only" -DTIPPE_SANITIZE=address,undefined \
  -DTIPPE_FUZZ=ON -DTIPPE_BENCHMARKS=OFF -DTIPPE_MPI=OFF >/dev/null
list="$build/fuzz/fuzz_targets.txt"
mapfile -t lines < <(grep -v '^[[:space:]]*$' "$list")
targets=()
for line in "${lines[@]}"; do targets+=("${line%% *}"); done
if [ $# -gt 0 ]; then targets=("$@"); fi
t0=$(date +%s)
cmake --build "$build" -j"${JOBS:-$(nproc)}" --target "${targets[@]}"
echo "fuzz: built ${targets[*]} in $(( $(date +%s) - t0 )) s"

export ASAN_OPTIONS="${ASAN_OPTIONS:-detect_leaks=1:abort_on_error=1:symbolize=1}"
export UBSAN_OPTIONS="${UBSAN_OPTIONS:-print_stacktrace=1:halt_on_error=1}"
# One fuzzer per target, all at once (one core each on the CI machine's two): the wall time is
# SECONDS, not SECONDS per target.
pids=()
for name in "${targets[@]}"; do
  line="$(grep "^$name " "$list" || true)"
  [ -n "$line" ] || { echo "fuzz: unknown target $name (see $list)" >&2; exit 2; }
  read -r -a fields <<<"$line"  # NAME DICT_OR_- SEED_DIR...
  dict="${fields[1]}"
  seeds=("${fields[@]:2}")
  # New inputs go to a scratch corpus (the first directory); the seeds are only read.
  corpus="$build/corpus/$name"
  artifacts="$build/artifacts"
  mkdir -p "$corpus" "$artifacts"
  log="$build/$name.log"
  args=("$corpus" "${seeds[@]}" -max_total_time="$seconds" -rss_limit_mb=2048 -timeout=30
        -print_final_stats=1 -artifact_prefix="$artifacts/$name-")
  [ "$dict" != "-" ] && args+=(-dict="$dict")
  echo "fuzz: $name for $seconds s (log: $log)"
  "$build/fuzz/$name" "${args[@]}" >"$log" 2>&1 &
  pids+=($!)
done
status=0
for i in "${!targets[@]}"; do
  name="${targets[$i]}"
  log="$build/$name.log"
  rc=0
  wait "${pids[$i]}" || rc=$?
  execs="$(sed -n 's/^stat::number_of_executed_units: *//p' "$log" | tail -n 1)"
  rate="$(sed -n 's/^stat::average_exec_per_sec: *//p' "$log" | tail -n 1)"
  cov="$(grep -o 'cov: [0-9]*' "$log" | tail -n 1 || true)"
  echo "fuzz: $name: ${execs:-?} executions, ${rate:-?} exec/s, ${cov:-cov: ?}, exit $rc"
  if [ "$rc" -ne 0 ]; then
    echo "fuzz: $name FAILED; the end of its log:" >&2
    tail -n 60 "$log" >&2
    ls -1 "$build/artifacts" | sed "s|^|fuzz: artifact $build/artifacts/|" >&2
    status=1
  fi
done
exit "$status"
