#!/usr/bin/env python3
"""Tests scripts/sanitize-tests.py on a CTest directory of its own: a stand-in GoogleTest program's tests run in shards, each named test must finish, failures and exclusions are honoured.

Usage: test_sanitize_tests.py REPO_ROOT WORK_DIR
"""
import shutil
import subprocess
import sys
from pathlib import Path

src, work = Path(sys.argv[1]), Path(sys.argv[2])
script = src / "scripts/sanitize-tests.py"
failures = 0


def check(what, ok):
    global failures
    print(("ok   " if ok else "FAIL ") + what)
    failures += 0 if ok else 1


# A stand-in for a GoogleTest program: runs the tests its filter names (exact names), printing
# GoogleTest's lines; a name with "Fails" fails, one with "Crashes" ends the process as a sanitizer
# would (abort, no summary). Each start appends its filter to calls.txt.
FAKE = r'''#!/usr/bin/env python3
import os, sys
names = [a for a in sys.argv[1:] if a.startswith("--gtest_filter=")][0].split("=", 1)[1].split(":")
with open(os.path.join(os.path.dirname(__file__), "calls.txt"), "a") as f:
    f.write(":".join(names) + "\n")
for n in names:
    print("[ RUN      ] " + n, flush=True)
    if "Crashes" in n:
        os._exit(134)
    print(("[  FAILED  ] " if "Fails" in n else "[       OK ] ") + n + " (0 ms)")
sys.exit(1 if any("Fails" in n for n in names) else 0)
'''


def make_build(names, other_ok=True):
    build = work / "build"
    shutil.rmtree(build, ignore_errors=True)
    build.mkdir(parents=True)
    fake = build / "test_fake"
    fake.write_text(FAKE)
    fake.chmod(0o755)
    lines = []
    for n in names:
        lines.append(f'add_test([=[{n}]=] "{fake}" "--gtest_filter={n}" "--gtest_also_run_disabled_tests")')
        lines.append(f'set_tests_properties([=[{n}]=] PROPERTIES WORKING_DIRECTORY "{build}")')
    lines.append('set_tests_properties([=[Suite.Slow]=] PROPERTIES LABELS slow)' if "Suite.Slow" in names else "")
    lines.append(f'add_test(Other.Script "{sys.executable}" "-c" "import sys; sys.exit({0 if other_ok else 1})")')
    (build / "CTestTestfile.cmake").write_text("\n".join(lines) + "\n")
    return build


def run(build, exclusions="Suite.Excluded\n"):
    ex = work / "exclude.txt"
    ex.write_text("# a comment\n\n" + exclusions)
    return subprocess.run([sys.executable, str(script), str(build), "--exclude-label", "slow", "--exclude-file",
                           str(ex), "--jobs", "2", "--timeout", "60"], capture_output=True, text=True)


def calls(build):
    path = build / "calls.txt"
    return path.read_text().split() if path.exists() else []


# 70 passing tests: three shards (up to 32 each), every test once; the excluded and the slow one not.
names = [f"Suite.T{i}" for i in range(70)] + ["Suite.Excluded", "Suite.Slow", "Param/Suite.Case/one"]
b = make_build(names)
r = run(b)
ran = [n for c in calls(b) for n in c.split(":")]
check(f"all pass: exit 0 ({r.returncode}: {r.stderr[-300:]!r})", r.returncode == 0)
check(f"three processes for 71 tests ({len(calls(b))})", len(calls(b)) == 3)
check("every test once", sorted(ran) == sorted(n for n in names if n not in ("Suite.Excluded", "Suite.Slow")))
check("the CTest test ran", "ctest-others: 1 tests, exit 0" in r.stdout)

# A failing test fails the run and is named; so does a test its process never finished.
b = make_build(["Suite.A", "Suite.Fails", "Suite.B"])
r = run(b)
check(f"a failure: exit 1 ({r.returncode})", r.returncode == 1)
check("the failing test named", "failed: Suite.Fails" in r.stderr)
b = make_build(["Suite.A", "Suite.Crashes", "Suite.B"])
r = run(b)
check(f"a crash: exit 1 ({r.returncode})", r.returncode == 1)
check("the tests after it named as not finished",
      "did not finish: Suite.Crashes" in r.stderr and "did not finish: Suite.B" in r.stderr)
b = make_build(["Suite.A"], other_ok=False)
r = run(b)
check(f"a failing CTest test: exit 1 ({r.returncode})", r.returncode == 1)

# An exclusion line that is not a test name stops it before anything runs.
b = make_build(["Suite.A"])
r = run(b, "Suite.A; echo x\n")
check(f"a bad exclusion: exit 2 ({r.returncode})", r.returncode == 2 and "is not a test name" in r.stderr)
check("nothing ran", calls(b) == [])

sys.exit(1 if failures else 0)
