#!/usr/bin/env python3
"""Runs Leine and Glocker's tippe top in an implementation nobody here wrote, for docs/findings/leine-glocker-coupled.md.

The model is the tippe-top benchmark of the public repository JonasBreuling/PyNonsmooth (checked
at commit 93c16cd): "Tippetop_Leine2003", Leine and Glocker 2003, Chapter 5, as coded for
Capobianco, Harsch, Eugster and Leine 2021 (IJNME, Section 10.6), solved by its Moreau
time-stepping. This script only sets the published parameters and start, runs it and prints
what the bench compares: the first stem contact, the first crossing of pi/2, the largest tilt
and when, and the tilt range from 2 s on. It is not part of the build or the tests; it needs a
checkout of that repository (give its path) and Debian's python3-numpy and python3-tqdm.

  python3 scripts/independent-leine-glocker.py CHECKOUT --step 1e-5 --until 1.45
  python3 scripts/independent-leine-glocker.py CHECKOUT --patch uniform --step 3e-6 --until 1.45
  python3 scripts/independent-leine-glocker.py CHECKOUT --transverse 9e-7 --step 1e-4 --until 10
  python3 scripts/independent-leine-glocker.py CHECKOUT --patch point --quaternion --until 3
"""
import argparse
import math
import os
import sys


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("checkout", help="path to a checkout of JonasBreuling/PyNonsmooth")
    ap.add_argument("--step", type=float, default=1e-4, help="Moreau step (s)")
    ap.add_argument("--until", type=float, default=1.45, help="end time (s)")
    ap.add_argument("--patch", choices=["hertzian", "uniform", "point"], default="hertzian",
                    help="drilling bound mu * Rbar: the model's own Rbar = 3 pi / 16 a (Hertzian pressure, "
                         "a = 0.5 mm), the scene's 2/3 a (uniform pressure), or a point contact")
    ap.add_argument("--transverse", type=float, default=8e-7, help="A, the transverse inertia (kg m^2); Friedl's twin: 9e-7")
    ap.add_argument("--tolerance", type=float, default=1e-12, help="fixed-point tolerance on the impulses (N s)")
    ap.add_argument("--quaternion", action="store_true",
                    help="the model's unit-quaternion variant (its Euler angles are singular at tilt 0, "
                         "where a rolling top stays)")
    a = ap.parse_args()
    if not os.path.isdir(os.path.join(a.checkout, "benchmarks", "tippetop")):
        print(f"independent-leine-glocker: {a.checkout}: not a PyNonsmooth checkout (no benchmarks/tippetop)", file=sys.stderr)
        sys.exit(2)
    sys.path[:0] = [a.checkout, os.path.join(a.checkout, "benchmarks", "tippetop")]
    try:
        import numpy as np
        import tqdm  # noqa: F401 (the solver's progress bar)
    except ImportError as e:
        print(f"independent-leine-glocker: {e.name} is missing: install Debian's python3-numpy and python3-tqdm",
              file=sys.stderr)
        sys.exit(2)
    try:
        from tippetop_system import Tippetop_Leine2003, Tippetop_quaternion
        from solvers.moreau import Moreau
    except ImportError as e:
        print(f"independent-leine-glocker: {a.checkout}: {e} (not the expected PyNonsmooth checkout?)", file=sys.stderr)
        sys.exit(2)

    # The model takes the patch radius R and bounds the drilling torque by mu * (3 pi / 16) R.
    radius = {"hertzian": 0.5e-3, "uniform": (2.0 / 3.0 * 0.5e-3) / (3.0 * math.pi / 16.0), "point": 1e-9}[a.patch]
    model = Tippetop_quaternion if a.quaternion else Tippetop_Leine2003
    # m, A, C, g, a1 (G to ball centre), a2 (G to stem-tip centre), r1, r2, R, e_N, e_F, mu,
    # prox r, z0 (G's height at the start), tilt, spin about the symmetry axis
    top = model(6e-3, a.transverse, 7e-7, 9.81, 3e-3, 1.6e-2, 1.5e-2, 5e-3, radius, 0, 0, 0.3, 0.001,
                1.2015e-2, 0.1, 180.0)
    t, q = Moreau(top, 0, a.until, a.step, fix_point_tol=a.tolerance).solve()[:2]
    gap = np.array([top.g_N(ti, qi) for ti, qi in zip(t, q)])
    tilt = np.array([top.theta(ti, qi) for ti, qi in zip(t, q)])
    stem = np.flatnonzero(gap[:, 1] <= 0)
    past = np.flatnonzero(tilt > math.pi / 2)
    late = tilt[t >= 2.0]
    k = int(np.argmax(tilt))
    print(f"patch {a.patch}, A {a.transverse:g}, step {a.step:g}, until {a.until:g} s")
    print("first stem contact:", f"{t[stem[0]]:.6f} s" if stem.size else "none")
    print("first tilt past pi/2:", f"{t[past[0]]:.4f} s" if past.size else "none")
    print(f"largest tilt: {tilt[k]:.4f} rad at {t[k]:.4f} s")
    if late.size:
        print(f"tilt from 2 s on: [{late.min():.4f}, {late.max():.4f}] rad, final {tilt[-1]:.4f} rad")


if __name__ == "__main__":
    main()
