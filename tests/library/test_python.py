#!/usr/bin/env python3
"""The Python module `tippe` against `tippe run`: the same summary from a scene file and from a dict, the trajectory as arrays."""
import json
import math
import subprocess
import sys
import tempfile
import tomllib
from pathlib import Path

import tippe

# Fields that differ between two runs of the same scene by nature: timings and when/where it ran.
VOLATILE = {("work", "wall_seconds"), ("work", "cpu_seconds"), ("provenance", "date"), ("provenance", "hostname")}


def strip_volatile(d):
    d = json.loads(json.dumps(d))
    for outer, inner in VOLATILE:
        d[outer].pop(inner)
    return d


def main():
    tippe_exe, scene = sys.argv[1:3]
    failures = []

    def check(what, ok):
        if not ok:
            failures.append(what)

    with tempfile.TemporaryDirectory() as tmp:
        out = Path(tmp) / "cli"
        subprocess.run([tippe_exe, "run", scene, "--out", str(out)], check=True, stdout=subprocess.DEVNULL,
                       stderr=subprocess.DEVNULL)
        cli = json.loads((out / "summary.json").read_text())
        csv_header = (out / "trajectory.csv").read_text().split("\n", 1)[0].split(",")

    r = tippe.run_scene_file(scene)
    # Every field of the module's summary.json text equals the CLI's, bit for bit, but the volatile ones.
    check("summary.json of run_scene_file == tippe run's", strip_volatile(json.loads(r.json)) == strip_volatile(cli))
    # Every field of summary.json is an attribute with the JSON's value (None for JSON null), a
    # nested object a Record of its fields; the stub (__init__.pyi) types each (LibrarySummary.*).
    volatile = {outer for outer, _ in VOLATILE}
    for key, want in cli.items():
        got = getattr(r, key)
        if key in volatile:
            got, want = got.to_dict(), dict(want)
            for outer, inner in VOLATILE:
                if outer == key:
                    got.pop(inner), want.pop(inner)
        elif isinstance(want, dict):
            got = got.to_dict()
        elif isinstance(want, list) and want and isinstance(want[0], dict):
            got = [g.to_dict() for g in got]
        check(f".{key} == summary.json's ({got!r} vs {want!r})", got == want)
    check(".mass_properties.mass", r.mass_properties.mass == cli["mass_properties"]["mass"])
    check(".ledger_at_inversion.numerical_energy",
          r.ledger_at_inversion is None if cli["ledger_at_inversion"] is None
          else r.ledger_at_inversion.numerical_energy == cli["ledger_at_inversion"]["numerical_energy"])
    check(".events", [(e.name, e.time) for e in r.events] == [(e["name"], e["time"]) for e in cli["events"]])

    # The trajectory: trajectory.csv's columns, one value per sample.
    t = r.trajectory
    check(f"trajectory columns {list(t)} == trajectory.csv's {csv_header}", list(t) == csv_header)
    check("a trajectory column per sample", all(len(t[c]) == r.samples for c in t))
    check("trajectory ends at final_time, final_tilt",
          t["t"][-1] == r.final_time and t["theta"][-1] == r.final_tilt)
    try:
        import numpy
        check("numpy arrays when numpy is importable", isinstance(t["theta"], numpy.ndarray))
    except ImportError:
        check("lists without numpy", isinstance(t["theta"], list))

    # A scene from a dict with the file's keys: the same physics, hence the same numbers.
    d = tippe.run_scene(tomllib.loads(Path(scene).read_text()))
    for key in ["status", "samples", "inversion_time", "final_time", "final_tilt", "energy_final", "min_normal_force"]:
        check(f"run_scene(dict).{key} == run_scene_file's", getattr(d, key) == getattr(r, key))
    check("run_scene(dict) keeps the scene's name", d.scene == r.scene)

    # Bad input is a ValueError naming the key, as the CLI's message does.
    bad = tomllib.loads(Path(scene).read_text())
    bad["body"]["sphere_radius"] = -1.0
    try:
        tippe.run_scene(bad)
        check("a negative sphere_radius is refused", False)
    except ValueError as e:
        check(f"the message names the key: {e}", "body.sphere_radius" in str(e))
    try:
        tippe.run_scene_file(str(Path(scene).with_name("no-such-scene.toml")))
        check("a missing file is refused", False)
    except ValueError as e:
        check(f"the message names the file: {e}", "no-such-scene.toml" in str(e))

    # A dict that contains itself, or nests without bound, is a ValueError, not a crashed interpreter.
    cyclic = tomllib.loads(Path(scene).read_text())
    cyclic["body"]["self"] = cyclic
    try:
        tippe.run_scene(cyclic)
        check("a dict that contains itself is refused", False)
    except ValueError as e:
        check(f"the message names the cycle: {e}", "body.self" in str(e) and "contains itself" in str(e))
    deep = tomllib.loads(Path(scene).read_text())
    inner = deep["body"]
    for _ in range(100000):
        inner["x"] = {}
        inner = inner["x"]
    try:
        tippe.run_scene(deep)
        check("a dict nested 100000 deep is refused", False)
    except ValueError as e:
        check(f"the message says how deep: {e}", "nested deeper than 64" in str(e))

    if failures:
        print("FAILED:\n  " + "\n  ".join(failures))
        return 1
    print(f"tippe {tippe.__version__}: run_scene_file and run_scene match tippe run on {scene} "
          f"(final_tilt {r.final_tilt}, inversion_time {r.inversion_time}, {r.samples} samples)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
