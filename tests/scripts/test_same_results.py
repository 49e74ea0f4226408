#!/usr/bin/env python3
"""Tests scripts/same-results.py with the build's tippe on both sides, and with stand-ins that change one number of a trajectory, one field of a summary, or refuse a scene.

Usage: test_same_results.py REPO_ROOT TIPPE WORK_DIR
"""
import os
import shutil
import subprocess
import sys
from pathlib import Path

src, tippe, work = Path(sys.argv[1]), sys.argv[2], Path(sys.argv[3])
script = src / "scripts/same-results.py"
failures = 0
SCENES = ["--scenes", "harness/scenes/toy.toml", "harness/scenes/rutstam_ball.toml", "--set", "run.duration=0.05"]


def check(what, ok, out=""):
    global failures
    print(("ok   " if ok else "FAIL ") + what)
    if not ok:
        print(out)
    failures += 0 if ok else 1


def same_results(before, after, *extra):
    done = subprocess.run([sys.executable, str(script), before, after, *extra], capture_output=True, text=True)
    return done.returncode, done.stdout + done.stderr


# A stand-in for the build after a change: runs the real tippe, then alters what it wrote (EDIT is
# Python run on the --out directory `out`), or refuses the scene named REFUSE.
STAND_IN = r'''#!/usr/bin/env python3
import os, subprocess, sys
args = sys.argv[1:]
if REFUSE and any(a.endswith(REFUSE) for a in args):
    print("tippe: the stand-in refuses this scene", file=sys.stderr)
    sys.exit(2)
rc = subprocess.run([TIPPE] + args).returncode
if rc == 0 and "--out" in args:
    out = args[args.index("--out") + 1]
    if os.path.basename(out).startswith(SCENE):
        EDIT
sys.exit(rc)
'''


def stand_in(name, scene_prefix, edit, refuse=""):
    path = work / name
    text = STAND_IN.replace("TIPPE", repr(tippe)).replace("SCENE", repr(scene_prefix))
    path.write_text(text.replace("REFUSE", repr(refuse)).replace("EDIT", edit))
    path.chmod(0o755)
    return str(path)


shutil.rmtree(work, ignore_errors=True)
work.mkdir(parents=True)

# The same build on both sides: every run the same.
rc, out = same_results(tippe, tippe, *SCENES)
check("the same build gives the same results (exit 0)", rc == 0 and out.count("same  ") == 2, out)

# One digit of one trajectory row changed after the run: named, with its line.
last_digit = (
    "p = os.path.join(out, 'trajectory.csv'); t = open(p).read().split('\\n'); r = t[3]; "
    "t[3] = r[:-1] + ('1' if r[-1] != '1' else '2'); open(p, 'w').write('\\n'.join(t))")
rc, out = same_results(tippe, stand_in("digit", "rutstam_ball", last_digit), *SCENES)
check("a changed digit is a difference (exit 1)", rc == 1, out)
check("... named with its scene and line", "DIFF  harness/scenes/rutstam_ball.toml analytic: trajectory.csv from line 4" in out, out)
check("... and the other scene stays the same", "same  harness/scenes/toy.toml analytic" in out, out)

# A summary field changed: named; provenance and the timings are not compared.
field = ("import json; p = os.path.join(out, 'summary.json'); s = json.load(open(p)); "
         "s['final_tilt'] += 1e-15; s['provenance']['hostname'] = 'elsewhere'; s['work']['cpu_seconds'] += 1; "
         "json.dump(s, open(p, 'w'))")
rc, out = same_results(tippe, stand_in("field", "toy", field), *SCENES)
check("a changed summary field is a difference (exit 1)", rc == 1 and "summary.json: final_tilt" in out, out)
check("... provenance and CPU time are not", "provenance" not in out and "cpu_seconds" not in out, out)
untimed = ("import json; p = os.path.join(out, 'summary.json'); s = json.load(open(p)); "
           "s['provenance']['git_commit'] = 'other'; s['work']['wall_seconds'] += 1; json.dump(s, open(p, 'w'))")
rc, out = same_results(tippe, stand_in("untimed", "toy", untimed), *SCENES)
check("another commit's stamp and wall time alone are the same (exit 0)", rc == 0, out)

# A scene one build refuses: a difference; both refusing alike: the same.
refuser = stand_in("refuser", "none", "pass", refuse="toy.toml")
rc, out = same_results(tippe, refuser, *SCENES)
check("a scene refused by one build only is a difference", rc == 1 and "exit 0 against 2" in out, out)
rc, out = same_results(refuser, refuser, *SCENES)
check("a scene both refuse alike is the same", rc == 0 and "both refuse (exit 2)" in out, out)

# Bad input: exit 2 before anything runs.
rc, out = same_results(str(work / "no-such-tippe"), tippe, *SCENES)
check("a binary that does not run: exit 2", rc == 2 and "not a tippe binary" in out, out)
rc, out = same_results(tippe, tippe, "--scenes", "harness/scenes/none-*.toml")
check("no scene matched: exit 2", rc == 2 and "no scene file matched" in out, out)

print("%d failure(s)" % failures)
sys.exit(1 if failures else 0)
