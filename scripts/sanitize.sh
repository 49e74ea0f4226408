#!/usr/bin/env bash
# Builds the test suite with ASan+UBSan in build-asan and runs CTest (minus `slow`); any sanitizer report fails.
set -euo pipefail
cd "$(dirname "$0")/.."
root="$(pwd)"
build="${SANITIZE_BUILD_DIR:-$root/build-asan}"
cxx="${SANITIZE_CXX:-clang++}"
command -v "$cxx" >/dev/null || { echo "sanitize: $cxx not found" >&2; exit 2; }

# clang: its -fsanitize=undefined also checks float->int conversions that overflow, which g++'s
# does not. -O1 with line tables only (all a stack trace needs) keeps the build and the run
# affordable; asserts stay on (no NDEBUG) so Eigen's and the project's own checks run too.
# TIPPE_FUZZ=ON adds libFuzzer's coverage instrumentation to the parsers' libraries (the sanitizer
# runtime serves it; CMakeLists.txt, TIPPE_FUZZ_COVERAGE), so
# that scripts/fuzz.sh reuses this very build instead of compiling everything a second time.
# TIPPE_MPI=OFF: LeakSanitizer reports Open MPI 4.1's own allocations (a bare MPI_Init/MPI_Finalize
# program: 121 KB in 3351 allocations), which would fail every MPI run here;
# this build also proves that the project builds and tests cleanly without MPI.
t0=$(date +%s)
cmake -S . -B "$build" -DCMAKE_CXX_COMPILER="$cxx" -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O1 -gline-tables-only" -DTIPPE_SANITIZE=address,undefined \
  -DTIPPE_FUZZ=ON -DTIPPE_BENCHMARKS=OFF -DTIPPE_MPI=OFF >/dev/null
cmake --build "$build" -j"${JOBS:-$(nproc)}"
t1=$(date +%s)
echo "sanitize: build $(( t1 - t0 )) s"

# Reports go to files as well as failing the process: tests that run `tippe` as a child process
# send its stderr to /dev/null or a file, and a child's exit code alone could pass a test that
# expects a failure. Any file in $logs after the run fails this script.
logs="$build/sanitizer-logs"
rm -rf "$logs"
mkdir -p "$logs"
supp="$root/tests/sanitizer"
export ASAN_OPTIONS="halt_on_error=1:detect_leaks=1:detect_stack_use_after_return=1:check_initialization_order=1:strict_init_order=1:log_path=$logs/report"
export UBSAN_OPTIONS="halt_on_error=1:print_stacktrace=1:log_path=$logs/report"
export LSAN_OPTIONS="suppressions=$supp/lsan.supp:print_suppressions=0"
# The long system runs of tests/sanitizer/long-runs.txt are left out by name (each with its
# reason there; a line that is not a plain test name stops the script), and the `slow` label.
# Each GoogleTest program runs in shards of up to 32 tests, a process each, rather than a process
# per test as CTest starts them: under ASan a process costs 0.2-0.35 s to start and end whatever
# its test does, and the suite is mostly short tests (BENCHMARKS.md, "The test programs and CI").
# The other tests (scripts, the library's consumer) run through CTest.
rc=0
python3 "$root/scripts/sanitize-tests.py" "$build" --exclude-label slow --exclude-file "$supp/long-runs.txt" \
  --jobs "${JOBS:-$(nproc)}" --timeout 900 || rc=$?
[ "$rc" -eq 2 ] && exit 2
t2=$(date +%s)
echo "sanitize: tests $(( t2 - t1 )) s"

if [ -n "$(ls -A "$logs")" ]; then
  echo "sanitize: sanitizer reports:" >&2
  for f in "$logs"/*; do
    echo "==== $f" >&2
    cat "$f" >&2
  done
  rc=1
fi
[ "$rc" -eq 0 ] && echo "sanitize: clean" || echo "sanitize: FAILED" >&2
exit "$rc"
