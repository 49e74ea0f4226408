#!/usr/bin/env python3
"""A reference run's whole process against a plain solver of the same problem, alternating.

`tippe run harness/scenes/rutstam_ball.toml --engine analytic` (12 s, rtol 1e-10, a sample every
1 ms, trajectory.csv written) against build/bench/plain_viscous_ball (Boost.Odeint RKF78 at rtol
1e-10 on the same viscous ball, its samples written as CSV), run one after the other N times.
Prints each one's median wall and CPU seconds (user + system, the child's own) and the ratios, and
the ratio of the least CPU seconds: the sweeps' own measure of a run's cost (a point's CPU time is
the least of its repeats, as a busy machine only ever adds to it).

One sitting is not evidence on a shared or virtual machine: the plain solver's CPU has been seen
to move by 40 % within minutes while the reference's moved a few percent, so a ratio from one
sitting can land on either side of a goal. Hence:
  --sittings K --gap S   K sittings of N alternations, S seconds apart; each sitting's ratio, then
                         their range and median.
  --instructions         each process's user-space instructions under valgrind's callgrind (its
                         "Collected" total), which the machine's load does not move. Kernel work
                         (page faults, writes, fsync) is not in it: read it beside the CPU ratio.
  --ref-interval S       the reference's sample interval alone (the plain solver keeps --interval):
                         with S = the duration the reference writes two samples, which gives the
                         ratio's floor when sampling costs nothing.

Usage: scripts/bench-reference-process.py [--build DIR] [--tippe PATH] [-n N] [--interval S]
       [--ref-interval S] [--sittings K --gap S] [--instructions]
"""
import argparse
import os
import re
import resource
import shutil
import statistics
import subprocess
import sys
import tempfile
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def timed(cmd):
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    t0 = time.perf_counter()
    subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL)
    wall = time.perf_counter() - t0
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    return wall, cpu


def instructions(cmd):
    """User-space instructions of one run of cmd under callgrind (deterministic for one input)."""
    done = subprocess.run(["valgrind", "--tool=callgrind", "--callgrind-out-file=/dev/null"] + cmd,
                          stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
    m = re.search(r"Collected : (\d+)", done.stderr)
    if done.returncode != 0 or not m:
        sys.exit("bench-reference-process: callgrind gave no instruction count for %s:\n%s" % (cmd[0], done.stderr[-2000:]))
    return int(m.group(1))


def sitting(ref_cmd, plain_cmd, n):
    timed(ref_cmd)  # warm the page cache for both
    timed(plain_cmd)
    ref, pl = [], []
    for _ in range(n):
        ref.append(timed(ref_cmd))
        pl.append(timed(plain_cmd))
    med = lambda xs, i: statistics.median(x[i] for x in xs)
    least = lambda xs, i: min(x[i] for x in xs)
    return {"ref_wall": med(ref, 0), "ref_cpu": med(ref, 1), "plain_wall": med(pl, 0), "plain_cpu": med(pl, 1),
            "ref_cpu_min": least(ref, 1), "plain_cpu_min": least(pl, 1)}


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--build", default=os.path.join(ROOT, "build"))
    ap.add_argument("--tippe", help="the tippe binary (default: BUILD/tippe)")
    ap.add_argument("-n", type=int, default=20, help="alternations per sitting (default 20)")
    ap.add_argument("--duration", type=float, default=12.0)
    ap.add_argument("--interval", type=float, default=1e-3, help="sample interval, s (default 1e-3)")
    ap.add_argument("--ref-interval", type=float, help="the reference's sample interval, s (default: --interval)")
    ap.add_argument("--sittings", type=int, default=1, help="sittings of N alternations (default 1)")
    ap.add_argument("--gap", type=float, default=60.0, help="seconds between sittings (default 60)")
    ap.add_argument("--instructions", action="store_true", help="also count instructions under callgrind")
    a = ap.parse_args()
    if a.n < 1 or a.sittings < 1 or a.gap < 0:
        ap.error("-n and --sittings must be at least 1, --gap not negative")
    if a.instructions and not shutil.which("valgrind"):
        ap.error("--instructions needs valgrind on the PATH")
    tippe = a.tippe or os.path.join(a.build, "tippe")
    plain = os.path.join(a.build, "bench", "plain_viscous_ball")
    scene = os.path.join(ROOT, "harness", "scenes", "rutstam_ball.toml")
    ref_interval = a.ref_interval if a.ref_interval is not None else a.interval
    with tempfile.TemporaryDirectory() as tmp:
        ref_cmd = [tippe, "run", scene, "--engine", "analytic", "--quiet", "--out", os.path.join(tmp, "ref"),
                   "--set", "run.duration=%r" % a.duration, "--set", "run.sample_interval=%r" % ref_interval]
        plain_cmd = [plain, repr(a.duration), repr(a.interval), os.path.join(tmp, "plain.csv")]
        results = []
        for k in range(a.sittings):
            if k > 0:
                time.sleep(a.gap)
            results.append(sitting(ref_cmd, plain_cmd, a.n))
            r = results[-1]
            if a.sittings > 1:
                print("sitting %d/%d at %s: cpu %.4f / %.4f s, ratio %.3f (least cpu %.3f, wall %.3f)" % (
                    k + 1, a.sittings, time.strftime("%H:%M:%S"), r["ref_cpu"], r["plain_cpu"],
                    r["ref_cpu"] / r["plain_cpu"], r["ref_cpu_min"] / r["plain_cpu_min"],
                    r["ref_wall"] / r["plain_wall"]), flush=True)
        counts = (instructions(ref_cmd), instructions(plain_cmd)) if a.instructions else None
    print("reference samples every %g s, plain solver every %g s, %g s, %d alternations a sitting" % (
        ref_interval, a.interval, a.duration, a.n))
    if a.sittings == 1:
        r = results[0]
        print("%-28s %10s %10s" % ("", "wall s", "cpu s"))
        print("%-28s %10.4f %10.4f" % ("tippe run --engine analytic", r["ref_wall"], r["ref_cpu"]))
        print("%-28s %10.4f %10.4f" % ("plain RKF78", r["plain_wall"], r["plain_cpu"]))
        print("%-28s %10.3f %10.3f" % ("ratio (medians)", r["ref_wall"] / r["plain_wall"], r["ref_cpu"] / r["plain_cpu"]))
        print("%-28s %10s %10.3f (%.4f / %.4f s)" % ("ratio (least cpu)", "", r["ref_cpu_min"] / r["plain_cpu_min"],
                                                      r["ref_cpu_min"], r["plain_cpu_min"]))
    else:
        for key, name in (("cpu", "cpu"), ("cpu_min", "least cpu"), ("wall", "wall")):
            ratios = [r["ref_" + key] / r["plain_" + key] for r in results]
            print("ratio by %-9s over %d sittings: median %.3f, range %.3f .. %.3f" % (
                name, len(ratios), statistics.median(ratios), min(ratios), max(ratios)))
    if counts:
        print("instructions (callgrind): tippe %.1f M, plain %.1f M, ratio %.3f" % (
            counts[0] / 1e6, counts[1] / 1e6, counts[0] / counts[1]))
    return 0


if __name__ == "__main__":
    sys.exit(main())
