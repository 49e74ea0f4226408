#!/usr/bin/env python3
"""Whether two builds give the same results: every shipped scene run by both `tippe` binaries, each file compared.

A change meant to leave every number alone (a faster solve, a tidier file) is checked by running
both builds on the same scenes and engines and comparing what they wrote: `trajectory.csv` byte for
byte, `summary.json` field by field without `provenance` (commit, date, host) and the work's
`cpu_seconds` and `wall_seconds` (everything else, the step and right-hand-side counts included,
must be equal). A scene both builds refuse with the same exit status and message counts as the
same; one refused by one build only is a difference.

Usage: scripts/same-results.py BEFORE/tippe AFTER/tippe [--engines analytic,ode] [--scenes GLOB ...]
                               [--set KEY=VALUE ...] [--jobs N] [--keep DIR]
  --engines   comma-separated (default analytic: the reference, to each scene's own horizon)
  --scenes    globs from the repository root (default harness/scenes/**/*.toml: every shipped scene)
  --set       passed to both runs, e.g. run.duration=1.5 for the engines' runs
  --keep      write the runs under DIR (DIR/before, DIR/after) and keep them
Prints one line per run, `same` or `DIFF` with what differs (the first differing line of the
trajectory, the summary's differing fields). Exit 0: every run the same; 1: a difference; 2: bad
input (a binary that does not run, no scene matched).
"""
import argparse
import concurrent.futures
import glob
import json
import os
import shutil
import subprocess
import sys
import tempfile

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
TIMINGS = ("cpu_seconds", "wall_seconds")


def run(tippe, scene, engine, sets, out):
    cmd = [tippe, "run", scene, "--engine", engine, "--quiet", "--out", out]
    for s in sets:
        cmd += ["--set", s]
    done = subprocess.run(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
    return done.returncode, done.stderr.strip()


def comparable_summary(path):
    with open(path) as f:
        s = json.load(f)
    s.pop("provenance", None)
    for k in TIMINGS:
        s.get("work", {}).pop(k, None)
    return s


def first_difference(a_path, b_path):
    """The first line number (1-based) where two files differ, or None when they are equal."""
    with open(a_path, "rb") as a, open(b_path, "rb") as b:
        la, lb = a.read().split(b"\n"), b.read().split(b"\n")
    if la == lb:
        return None
    for n, (x, y) in enumerate(zip(la, lb), start=1):
        if x != y:
            return n
    return min(len(la), len(lb)) + 1


def compare(before, after):
    """What differs between the runs in directories before and after, as a list of phrases."""
    found = []
    for f in ("trajectory.csv", "summary.json"):
        ha, hb = os.path.exists(os.path.join(before, f)), os.path.exists(os.path.join(after, f))
        if ha != hb:
            found.append("%s written by %s only" % (f, "before" if ha else "after"))
    if found:
        return found
    line = first_difference(os.path.join(before, "trajectory.csv"), os.path.join(after, "trajectory.csv"))
    if line is not None:
        found.append("trajectory.csv from line %d" % line)
    sa = comparable_summary(os.path.join(before, "summary.json"))
    sb = comparable_summary(os.path.join(after, "summary.json"))
    fields = sorted(k for k in set(sa) | set(sb) if sa.get(k) != sb.get(k))
    if fields:
        found.append("summary.json: " + ", ".join(fields))
    return found


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("before")
    ap.add_argument("after")
    ap.add_argument("--engines", default="analytic")
    ap.add_argument("--scenes", nargs="+", default=["harness/scenes/**/*.toml"])
    ap.add_argument("--set", action="append", default=[], dest="sets")
    ap.add_argument("--jobs", type=int, default=os.cpu_count() or 1)
    ap.add_argument("--keep")
    a = ap.parse_args()
    for tippe in (a.before, a.after):
        try:
            ok = subprocess.run([tippe, "--version"], stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL).returncode == 0
        except OSError:
            ok = False
        if not ok:
            print("same-results: %s: not a tippe binary that runs (`%s --version` failed)" % (tippe, tippe), file=sys.stderr)
            return 2
    scenes = sorted({os.path.relpath(p, ROOT) for g in a.scenes for p in glob.glob(os.path.join(ROOT, g), recursive=True)})
    if not scenes:
        print("same-results: --scenes %s: no scene file matched" % " ".join(a.scenes), file=sys.stderr)
        return 2
    engines = [e for e in a.engines.split(",") if e]
    if not engines or a.jobs < 1:
        print("same-results: --engines needs an engine and --jobs at least 1", file=sys.stderr)
        return 2

    work = a.keep or tempfile.mkdtemp(prefix="same-results-")
    pairs = [(scene, engine) for scene in scenes for engine in engines]

    def out_dir(side, scene, engine):
        name = os.path.splitext(scene)[0].replace("harness/scenes/", "").replace("/", "_")
        return os.path.join(work, side, name + "-" + engine)

    runs = [(side, tippe, scene, engine) for scene, engine in pairs
            for side, tippe in (("before", a.before), ("after", a.after))]
    with concurrent.futures.ThreadPoolExecutor(a.jobs) as pool:
        outcomes = pool.map(lambda r: run(r[1], os.path.join(ROOT, r[2]), r[3], a.sets, out_dir(r[0], r[2], r[3])), runs)
        results = {(r[0], r[2], r[3]): o for r, o in zip(runs, outcomes)}

    differ = 0
    last = lambda text: text.splitlines()[-1] if text else ""
    for scene, engine in pairs:
        (rc_b, err_b), (rc_a, err_a) = results[("before", scene, engine)], results[("after", scene, engine)]
        label = ""
        if rc_b != 0 or rc_a != 0:
            found = [] if (rc_b, err_b) == (rc_a, err_a) else [
                "exit %d against %d (%s | %s)" % (rc_b, rc_a, last(err_b), last(err_a))]
            label = "both refuse (exit %d)" % rc_b if not found else ""
        else:
            found = compare(out_dir("before", scene, engine), out_dir("after", scene, engine))
        differ += bool(found)
        print("%-5s %s %s%s" % ("DIFF" if found else "same", scene, engine,
                                ": " + "; ".join(found) if found else (": " + label if label else "")))
    print("same-results: %d of %d runs differ%s" % (differ, len(pairs),
                                                     " (runs kept in %s)" % work if a.keep else ""))
    if not a.keep:
        shutil.rmtree(work, ignore_errors=True)
    return 1 if differ else 0


if __name__ == "__main__":
    sys.exit(main())
