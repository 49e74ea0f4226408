#!/usr/bin/env python3
"""A reference run's whole process against a plain solver of the same problem, alternating.

`tippe run harness/scenes/rutstam_ball.toml --engine analytic` (12 s, rtol 1e-10, a sample every
1 ms, trajectory.csv written) against build/bench/plain_viscous_ball (Boost.Odeint RKF78 at rtol
1e-10 on the same viscous ball, its samples written as CSV), run one after the other N times.
Prints each one's median wall and CPU seconds (user + system, the child's own) and the ratios.

Usage: scripts/bench-reference-process.py [--build DIR] [--tippe PATH] [-n N] [--interval S]
"""
import argparse
import os
import resource
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


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--build", default=os.path.join(ROOT, "build"))
    ap.add_argument("--tippe", help="the tippe binary (default: BUILD/tippe)")
    ap.add_argument("-n", type=int, default=20, help="alternations (default 20)")
    ap.add_argument("--duration", type=float, default=12.0)
    ap.add_argument("--interval", type=float, default=1e-3, help="sample interval, s (default 1e-3)")
    a = ap.parse_args()
    tippe = a.tippe or os.path.join(a.build, "tippe")
    plain = os.path.join(a.build, "bench", "plain_viscous_ball")
    scene = os.path.join(ROOT, "harness", "scenes", "rutstam_ball.toml")
    with tempfile.TemporaryDirectory() as tmp:
        ref_cmd = [tippe, "run", scene, "--engine", "analytic", "--quiet", "--out", os.path.join(tmp, "ref"),
                   "--set", "run.duration=%r" % a.duration, "--set", "run.sample_interval=%r" % a.interval]
        plain_cmd = [plain, repr(a.duration), repr(a.interval), os.path.join(tmp, "plain.csv")]
        ref, pl = [], []
        timed(ref_cmd)  # warm the page cache for both
        timed(plain_cmd)
        for _ in range(a.n):
            ref.append(timed(ref_cmd))
            pl.append(timed(plain_cmd))
    med = lambda xs, i: statistics.median(x[i] for x in xs)
    print("%-28s %10s %10s" % ("", "wall s", "cpu s"))
    print("%-28s %10.4f %10.4f" % ("tippe run --engine analytic", med(ref, 0), med(ref, 1)))
    print("%-28s %10.4f %10.4f" % ("plain RKF78", med(pl, 0), med(pl, 1)))
    print("%-28s %10.3f %10.3f" % ("ratio (medians)", med(ref, 0) / med(pl, 0), med(ref, 1) / med(pl, 1)))
    return 0


if __name__ == "__main__":
    sys.exit(main())
