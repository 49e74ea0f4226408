#!/usr/bin/env python3
"""Runs a sanitizer build's CTest suite with a process per shard of a test program instead of a process per test.

Under ASan a test program's process costs 0.2-0.35 s to start and to end whatever the test does
(a 38 MB program; 0.22-0.27 s with no test run, 0.36-0.38 s with LeakSanitizer's scan at exit,
BENCHMARKS.md, "The test programs and CI"); the sanitized suite's 810
GoogleTest tests paid that 810 times (about a third of its CPU). Here each program runs its tests
in a few shards, each one process (`--gtest_filter` naming its tests exactly), the shards on
`--jobs` workers, in rounds across the programs; the tests that are not GoogleTest's (scripts, the
library's consumer) run through CTest as before. What runs is what CTest would run: its test list
(`ctest --show-only=json-v1`) with the label and names left out, disabled tests skipped.

Usage: sanitize-tests.py BUILD --exclude-label slow --exclude-file tests/sanitizer/long-runs.txt --jobs 2
Exit 0 when every shard and CTest passed; 1 otherwise (each failure's output printed); 2 for bad input.
"""
from __future__ import annotations

import argparse
import json
import os
import re
import subprocess
import sys
import time
from concurrent.futures import ThreadPoolExecutor, as_completed

# Tests per shard: a program's tests are dealt out round-robin (neighbours in a file often cost
# alike) to ceil(n / SHARD_TESTS) shards.
SHARD_TESTS = 32
NAME = re.compile(r"^[A-Za-z0-9_./]+$")  # a GoogleTest name, as long-runs.txt may hold them


def fail(msg: str) -> None:
    print(f"sanitize-tests: {msg}", file=sys.stderr)
    sys.exit(2)


def read_exclusions(path: str) -> set[str]:
    names = set()
    with open(path) as f:
        for i, line in enumerate(f, 1):
            line = line.strip()
            if not line or line.startswith("#"):
                continue
            if not NAME.match(line):
                fail(f"{path}:{i}: '{line}' is not a test name (letters, digits, _ . / only)")
            names.add(line)
    return names


def ctest_tests(build: str, exclude_label: str) -> list[dict]:
    args = ["ctest", "--show-only=json-v1"] + (["-LE", exclude_label] if exclude_label else [])
    out = subprocess.run(args, cwd=build, capture_output=True, text=True, check=True).stdout
    return json.loads(out)["tests"]


def props(test: dict) -> dict:
    return {p["name"]: p["value"] for p in test.get("properties", [])}


def gtest_name(command: list[str]) -> str | None:
    for a in command[1:]:
        if a.startswith("--gtest_filter="):
            return a[len("--gtest_filter="):]
    return None


def run_task(task: dict, logs: str) -> dict:
    t0 = time.monotonic()
    log = os.path.join(logs, task["id"] + ".log")
    with open(log, "w") as out:
        try:
            rc = subprocess.run(task["argv"], cwd=task["cwd"], stdout=out, stderr=subprocess.STDOUT,
                                timeout=task["timeout"]).returncode
        except subprocess.TimeoutExpired:
            rc = "timeout"
    text = open(log, errors="replace").read()
    result = {"task": task, "rc": rc, "seconds": time.monotonic() - t0, "log": log, "text": text}
    if task["kind"] == "gtest":
        # Every named test ran (a filter that matched fewer would pass on what it left out).
        # A test's own line ends in its time: "[       OK ] Suite.Name (12 ms)"; a parameterized
        # failure adds ", where GetParam() = ..." before it. The summary's lines have no time.
        def ended(tag: str) -> set[str]:
            return set(re.findall(r"^\[ *" + tag + r" *\] ([^\s,]+)(?:, where .*)? \(\d+ ms\)$", text, re.M))
        passed, skipped, failed = ended("OK"), ended("SKIPPED"), ended("FAILED")
        missing = [n for n in task["names"] if n not in passed | skipped | failed]
        result.update(passed=len(passed), skipped=len(skipped), failed=sorted(failed), missing=missing)
        result["ok"] = rc == 0 and not failed and not missing
    else:
        result["ok"] = rc == 0
    return result


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("build")
    ap.add_argument("--exclude-label", default="slow")
    ap.add_argument("--exclude-file", required=True)
    ap.add_argument("--jobs", type=int, default=os.cpu_count() or 1)
    ap.add_argument("--timeout", type=float, default=900,
                    help="s, per shard (its slowest takes about a minute) and per CTest test")
    a = ap.parse_args()
    if a.jobs < 1:
        fail(f"--jobs {a.jobs}: expected at least 1")
    build = os.path.abspath(a.build)
    excluded = read_exclusions(a.exclude_file)

    programs: dict[str, dict] = {}  # program path -> {"names": [...], "cwd": ...}
    others: list[str] = []
    for t in ctest_tests(build, a.exclude_label):
        p = props(t)
        name = gtest_name(t["command"]) if t.get("command") else None
        if p.get("DISABLED") or (name or t["name"]) in excluded:
            continue
        if name is None:
            others.append(t["name"])
            continue
        prog = programs.setdefault(t["command"][0], {"names": [], "cwd": p.get("WORKING_DIRECTORY", build)})
        prog["names"].append(name)

    # Shards in rounds, the first of every program, then the second of those with two or more...:
    # the programs' costs are unknown here, and so the queue ends in the many-test programs' shards
    # (the hostile-input tables: about 5 s each) rather than in one program's long runs.
    shards = []
    for path, prog in sorted(programs.items()):
        names = prog["names"]
        n = -(-len(names) // SHARD_TESTS)
        shards.append([{"id": f"{os.path.basename(path)}-{i + 1}of{n}", "kind": "gtest", "names": names[i::n],
                        "argv": [path, "--gtest_filter=" + ":".join(names[i::n])], "cwd": prog["cwd"],
                        "timeout": a.timeout} for i in range(n)])
    tasks = [s[i] for i in range(max((len(s) for s in shards), default=0)) for s in shards if i < len(s)]
    if others:
        # In one CTest run, serially: fixtures and DEPENDS order them (the library's consumer).
        regex = "^(" + "|".join(re.escape(n) for n in others) + ")$"
        tasks.insert(0, {"id": "ctest-others", "kind": "ctest", "names": others,
                         "argv": ["ctest", "-R", regex, "--output-on-failure", "-j1",
                                  "--timeout", str(int(a.timeout))],
                         "cwd": build, "timeout": a.timeout * len(others)})

    logs = os.path.join(build, "sanitize-test-logs")
    os.makedirs(logs, exist_ok=True)
    for f in os.listdir(logs):
        os.remove(os.path.join(logs, f))
    total = sum(len(t["names"]) for t in tasks)
    print(f"sanitize-tests: {total} tests: {len(tasks)} processes on {a.jobs} workers "
          f"({len(programs)} GoogleTest programs in shards of up to {SHARD_TESTS}, {len(others)} CTest tests)",
          flush=True)
    bad = []
    done = 0
    with ThreadPoolExecutor(max_workers=a.jobs) as pool:
        for future in as_completed([pool.submit(run_task, t, logs) for t in tasks]):
            r = future.result()
            done += len(r["task"]["names"])
            t = r["task"]
            detail = (f"{r['passed']} passed, {r['skipped']} skipped, {len(r['failed'])} failed"
                      if t["kind"] == "gtest" else f"exit {r['rc']}")
            print(f"[{done}/{total}] {t['id']}: {len(t['names'])} tests, {detail}, {r['seconds']:.1f} s"
                  + ("" if r["ok"] else "  FAILED"), flush=True)
            if not r["ok"]:
                bad.append(r)
    for r in bad:
        t = r["task"]
        print(f"==== {t['id']} (exit {r['rc']}; its output: {r['log']})", file=sys.stderr)
        if t["kind"] == "gtest":
            for n in r["failed"]:
                print(f"failed: {n}", file=sys.stderr)
            for n in r["missing"]:
                print(f"did not finish: {n}", file=sys.stderr)
        print(r["text"][-20000:], file=sys.stderr)
    print(f"sanitize-tests: {'all passed' if not bad else str(len(bad)) + ' processes failed'}")
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
