#!/usr/bin/env python3
"""The Python package `tippe` against the `tippe` command, verb by verb: the same records (byte for byte but the timings), the same error messages, Ctrl-C that stops a comparison, the examples.

Usage: test_python_verbs.py VERB TIPPE_EXE SOURCE_DIR (VERB: run, compare, errors, interrupt, import_advise,
sweep, gate, engines, examples). Each runs in seconds on short scenes and horizons.
"""
import csv
import json
import math
import os
import re
import shutil
import signal
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import tippe

# Lines of a record that differ between two runs of the same input by nature: timings and
# when/where it ran (a key of these holds a number or a string measured now).
VOLATILE_KEYS = ("wall_seconds", "cpu_seconds", "cpu_seconds_repeats", "real_time_factor", "cost_ratio", "date",
                 "hostname", "seconds")
VOLATILE_LINE = re.compile(r'^(\s*"(?:' + "|".join(VOLATILE_KEYS) + r')": ).*?(,?)$')

failures = []


def check(what, ok):
    if not ok:
        failures.append(what)


def masked(text):
    """A JSON text (dump(2)) with each volatile key's value replaced: the rest must be byte-equal."""
    return "\n".join(VOLATILE_LINE.sub(r"\1X\2", line) for line in text.split("\n"))


def masked_line(line):
    """A records.jsonl line (dump()) with the volatile values replaced."""
    return re.sub(r'"(' + "|".join(VOLATILE_KEYS) + r')":(-?[0-9.eE+-]+|"[^"]*"|null|\[[^\]]*\])', r'"\1":X', line)


def same_text(what, mine, cli):
    a, b = masked(mine), masked(cli)
    if a != b:
        for i, (x, y) in enumerate(zip(a.split("\n"), b.split("\n"))):
            if x != y:
                check(f"{what}: line {i + 1} differs: {x!r} (python) vs {y!r} (cli)", False)
                return
        check(f"{what}: lengths differ", False)


def cli(tippe_exe, *args, expect=0, cwd=None):
    p = subprocess.run([tippe_exe, "-q", *args], capture_output=True, text=True, cwd=cwd)
    if p.returncode != expect:
        raise AssertionError(f"tippe {' '.join(args)}: exit {p.returncode} (expected {expect}): {p.stderr}")
    return p


def read_csv(path):
    with open(path, newline="") as f:
        rows = list(csv.reader(f))
    return {name: [r[i] for r in rows[1:]] for i, name in enumerate(rows[0])}


def cli_error(tippe_exe, *args, cwd=None):
    """The message `tippe` prints for bad input (exit 2), without its "tippe: error: " prefix."""
    p = cli(tippe_exe, *args, expect=2, cwd=cwd)
    line = p.stderr.strip().split("\n")[0]
    assert line.startswith("tippe: error: "), line
    return line[len("tippe: error: "):]


def raises_value_error(call):
    try:
        call()
    except ValueError as e:
        return str(e)
    return None


def test_run(exe, src, tmp):
    scene = str(src / "harness/scenes/rutstam_ball.toml")
    cli(exe, "run", scene, "--out", str(tmp / "ref"))
    r = tippe.run(scene, progress=False)
    same_text("run(): summary.json", r.json, (tmp / "ref/summary.json").read_text())
    # The fields are the record's, as attributes (nested objects too).
    summary = json.loads((tmp / "ref/summary.json").read_text())
    for key in summary:
        if key not in ("work", "provenance"):
            check(f"run().{key} == summary.json's", getattr(r, key) == summary[key])
    check("run().mass_properties.mass", r.mass_properties.mass == summary["mass_properties"]["mass"])
    # The trajectory: trajectory.csv's columns, the same doubles (17 digits read back exactly).
    t = r.trajectory
    table = read_csv(tmp / "ref/trajectory.csv")
    check(f"trajectory columns {list(t)} == trajectory.csv's", list(t) == list(table))
    import numpy

    check("numpy arrays", isinstance(t["theta"], numpy.ndarray) and t["theta"].dtype == numpy.float64)
    for c in table:
        if c == "surface":
            check("surface names", t[c] == table[c])
            continue
        want = [float(v) for v in table[c]]
        got = t[c].tolist()
        check(f"column {c} == trajectory.csv's",
              all(a == b or (math.isnan(a) and math.isnan(b)) for a, b in zip(got, want)) and len(got) == len(want))
    df = t.to_pandas()
    check("to_pandas: one row per sample", len(df) == r.samples and list(df.columns) == list(table))
    # An engine with a setting as a keyword is `--engine E --set engines.E.KEY=VALUE`.
    short = ["run.duration=0.5"]
    cli(exe, "run", scene, "--engine", "ode", "--set", short[0], "--set", "engines.ode.timestep=0.0005",
        "--out", str(tmp / "ode"))
    o = tippe.run(scene, "ode", set=short, timestep=0.0005, progress=False)
    same_text("run(engine=ode, timestep=...): summary.json", o.json, (tmp / "ode/summary.json").read_text())
    # A dict with the file's keys: the same physics, the same numbers.
    import tomllib

    d = tippe.run(tomllib.loads(Path(scene).read_text()), progress=False)
    check("run(dict) == run(file)", (d.final_tilt, d.inversion_time, d.samples) == (r.final_tilt, r.inversion_time, r.samples))
    # A callback sees the run's time rise to its duration.
    seen = []
    tippe.run(scene, set=short, progress=lambda run, t, duration: seen.append((run, t, duration)))
    check(f"progress callback ({len(seen)} calls)", seen and seen[-1] == ("analytic", 0.5, 0.5) and
          all(a[1] <= b[1] for a, b in zip(seen, seen[1:])))


def test_compare(exe, src, tmp):
    scene = str(src / "harness/scenes/toy_viscous.toml")
    args = ["--engines", "ode,mujoco", "--set", "run.duration=1", "--no-cache", "--no-plots"]
    cli(exe, "compare", scene, *args, "--out", str(tmp / "cli"))
    # Another Python thread runs meanwhile: the comparison holds no GIL.
    import threading

    ticks, done = [0], threading.Event()

    def tick():
        while not done.is_set():
            ticks[0] += 1
            time.sleep(0.001)

    ticker = threading.Thread(target=tick)
    ticker.start()
    t0 = time.monotonic()
    c = tippe.compare(scene, ["ode", "mujoco"], set=["run.duration=1"], cache=None, out=str(tmp / "py"),
                      progress=False)
    elapsed = time.monotonic() - t0
    done.set()
    ticker.join()
    # At most one tick per ms, at least one per 10 ms of a loaded machine.
    check(f"a thread ran during compare: {ticks[0]} ticks in {elapsed:.2f} s", ticks[0] >= elapsed * 100 * 0.5)
    cli_json = (tmp / "cli/comparison.json").read_text()
    same_text("compare(): comparison.json", c.json, cli_json)
    check("compare(out=): the file is the record", (tmp / "py/comparison.json").read_text() == c.json)
    check("compare(out=): report written", (tmp / "py/index.html").exists() and (tmp / "py/report.md").exists())
    check("fields as attributes", [e.engine for e in c.engines] == ["ode", "mujoco"] and
          c.reference.summary.engine == "analytic" and c.scene_name == "toy_viscous")
    # Each run's trajectory: the CSV's values for the columns kept.
    for name, file in [("reference", "reference.csv"), ("ode", "ode.csv"), ("mujoco", "mujoco.csv")]:
        table = read_csv(tmp / "cli" / file)
        got = c.trajectories[name]["theta"].tolist()
        check(f"{name} theta == {file}'s", got == [float(v) for v in table["theta"]])
    df = c.to_pandas()
    check("to_pandas: a row per engine with the metrics",
          list(df.index) == ["ode", "mujoco"] and
          df.loc["ode", "tilt_rms_error"] == json.loads(cli_json)["engines"][0]["metrics"]["tilt_rms_error"])
    # str() is what `tippe compare` prints before its report line (timings aside).
    printed = cli(exe, "compare", scene, *args, "--out", str(tmp / "cli2")).stdout
    first = lambda text: [l.split("|")[:8] for l in text.split("\n") if l.startswith("| ")]
    check("str(comparison) is the command's table", first(str(c)) == first(printed))
    # Progress per run through a callback, without the default board.
    seen = set()
    tippe.compare(scene, ["ode"], set=["run.duration=0.2"], cache=None, self_check=False,
                  progress=lambda run, t, d: seen.add(run))
    check(f"compare progress callback runs {seen}", seen == {"reference", "ode"})
    import matplotlib

    matplotlib.use("Agg")
    from tippe._objects import COMPARISON_FIGURES

    for figure in COMPARISON_FIGURES:
        ax = c.plot(figure)
        check(f"plot({figure}) draws a line per run", len(ax.get_lines()) >= 2)


def test_errors(exe, src, tmp):
    scene = src / "harness/scenes/rutstam_ball.toml"
    bad = tmp / "bad.toml"
    bad.write_text(scene.read_text().replace("sphere_radius = ", "sphere_radius = -1.0 #"))
    want = cli_error(exe, "run", str(bad), "--out", str(tmp / "x"))
    got = raises_value_error(lambda: tippe.run(str(bad), progress=False))
    check(f"run(bad scene): ValueError {got!r} == the CLI's {want!r}", got == want)
    check("load_scene(bad scene) too", raises_value_error(lambda: tippe.load_scene(str(bad))) == want)
    check("the message names file and key", "bad.toml" in want and "body.sphere_radius" in want)
    check("tippe.InputError is a ValueError", issubclass(tippe.InputError, ValueError))
    # A bad engine setting (compare checks before it writes anything).
    sets = ["--set", "engines.ode.timestep=-1"]
    want = cli_error(exe, "compare", str(scene), "--engines", "ode", *sets, "--out", str(tmp / "y"))
    got = raises_value_error(lambda: tippe.compare(str(scene), ["ode"], set=["engines.ode.timestep=-1"],
                                                   out=str(tmp / "z"), progress=False))
    check(f"compare(bad setting): {got!r} == the CLI's {want!r}", got == want)
    check("nothing written", not (tmp / "z").exists())
    got = raises_value_error(lambda: tippe.run(str(scene), "ode", timestep=-1, progress=False))
    check(f"run(ode, timestep=-1): names the key: {got!r}", got and "engines.ode.timestep" in got)
    missing = str(tmp / "no-such.xml")
    want = cli_error(exe, "import-mjcf", missing, "--out", str(tmp / "m.toml"))
    got = raises_value_error(lambda: tippe.import_mjcf(missing, out=str(tmp / "m.toml")))
    check(f"import_mjcf(missing): {got!r} == {want!r}", got == want)
    bad_sweep = tmp / "bad-sweep.toml"
    bad_sweep.write_text('description = "x"\nscenes = []\n')
    want = cli_error(exe, "sweep", str(bad_sweep), "--out", str(tmp / "s"))
    got = raises_value_error(lambda: tippe.sweep(str(bad_sweep), out=str(tmp / "s")))
    check(f"sweep(bad): {got!r} == {want!r}", got == want)
    bad_gate = tmp / "bad-gate.toml"
    bad_gate.write_text('[[check]]\nname = "x"\n')
    want = cli_error(exe, "gate", str(bad_gate))
    got = raises_value_error(lambda: tippe.gate(str(bad_gate)))
    check(f"gate(bad): {got!r} == {want!r}", got == want)
    # A dict that contains itself is a ValueError, not a crashed interpreter.
    import tomllib

    cyclic = tomllib.loads(scene.read_text())
    cyclic["body"]["self"] = cyclic
    got = raises_value_error(lambda: tippe.run(cyclic, progress=False))
    check(f"a cyclic dict: {got!r}", got and "body.self" in got and "contains itself" in got)


# Run in a child interpreter: a timer sends SIGINT to the process while compare runs.
INTERRUPT_CHILD = r"""
import os, signal, sys, threading, time, tippe
scene, out = sys.argv[1:3]
threading.Timer(1.0, lambda: os.kill(os.getpid(), signal.SIGINT)).start()
t0 = time.monotonic()
try:
    tippe.compare(scene, jobs=1, cache=None, out=out, progress=False)
    print("finished", time.monotonic() - t0)
except KeyboardInterrupt:
    print("interrupted", time.monotonic() - t0)
"""


def test_interrupt(exe, src, tmp):
    # toy_viscous on every engine, one at a time: ~30 s uninterrupted on a free core.
    scene = str(src / "harness/scenes/toy_viscous.toml")
    out = tmp / "cmp"
    p = subprocess.run([sys.executable, "-c", INTERRUPT_CHILD, scene, str(out)], capture_output=True, text=True,
                       timeout=120)
    words = p.stdout.split()
    check(f"compare stopped by SIGINT: {p.stdout!r} {p.stderr[-300:]!r}",
          p.returncode == 0 and words[:1] == ["interrupted"] and float(words[1]) < 10)
    check("nothing half-written", not out.exists() and not any(tmp.glob("cmp*")))
    # The stop request is cleared: the next call in the same process runs.
    code = INTERRUPT_CHILD + "\nprint(tippe.run(scene, set=['run.duration=0.1'], progress=False).status)\n"
    p = subprocess.run([sys.executable, "-c", code, scene, str(out)], capture_output=True, text=True, timeout=120)
    check(f"a run after the interrupt: {p.stdout!r}", p.stdout.split()[-1:] == ["ok"])


def test_import_advise(exe, src, tmp):
    model = str(src / "docs/advise-example-top.xml")
    cli(exe, "import-mjcf", model, "--out", str(tmp / "cli.toml"))
    s = tippe.import_mjcf(model, out=str(tmp / "py.toml"))
    check("import_mjcf(out=) writes the CLI's scene",
          (tmp / "py.toml").read_text() == (tmp / "cli.toml").read_text().replace("name = \"cli\"", "name = \"py\""))
    check("the scene's fields", s.name == "py" and s.body.sphere_radius > 0)
    mem = tippe.import_mjcf(model)
    check("import_mjcf() without out: a scene in memory", mem.name == "advise-example-top" and "[engines.mujoco]" in mem.toml)
    args = ["--engines", "ode", "--max-runs", "12", "--duration", "0.3", "--from", "1e-3", "--resolution", "0.3",
            "--no-plots"]
    printed = cli(exe, "advise", str(tmp / "cli.toml"), "--out", str(tmp / "adv-cli"), *args).stdout
    a = tippe.advise(str(tmp / "py.toml"), out=str(tmp / "adv-py"), engines=["ode"], max_runs=12, duration=0.3,
                     step_from=1e-3, resolution=0.3, progress=False)
    check("advice fields", a.engines[0].engine == "ode" and a.runs == int(re.search(r"runs: (\d+)", printed)[1]))
    check("the advice is advice.json's record", a.json == (tmp / "adv-py/advice.json").read_text()
          and len(a.engines[0].searched) == a.engines[0].configurations_searched)
    # The advice is the cheapest configuration by CPU time, and which one that is (and which others
    # are within 10 % of it) can differ between two runs of the search when costs are near: the
    # verb and the command are compared on the same records, a copy of the command's directory,
    # which the verb resumes (every run already there) to the same advice.
    shutil.copytree(tmp / "adv-cli", tmp / "adv-same")
    same = tippe.advise(str(tmp / "cli.toml"), out=str(tmp / "adv-same"), engines=["ode"], max_runs=12, duration=0.3,
                        step_from=1e-3, resolution=0.3, progress=False)
    check(f"str(advice) is the command's lines: {str(same)!r}", str(same) == printed.split("\nruns:")[0])
    check("advice.toml as the command writes it",
          (tmp / "adv-same/advice.toml").read_text() == (tmp / "adv-cli/advice.toml").read_text())
    # A scene object (a dict) is written for the advice's own files.
    check("advise(Scene) runs", tippe.advise(mem, out=str(tmp / "adv-mem"), engines=["ode"], max_runs=12,
                                             duration=0.3, step_from=1e-3, resolution=0.3, progress=False).runs > 0)


def test_sweep(exe, src, tmp):
    sweep = str(src / "harness/sweeps/search-tiny.toml")
    cli(exe, "sweep", sweep, "--out", str(tmp / "cli"), "--no-plots", "--jobs", "2")
    r = tippe.sweep(sweep, out=str(tmp / "py"), jobs=2, progress=False)
    lines = (tmp / "cli/records.jsonl").read_text().splitlines()
    mine = (tmp / "py/records.jsonl").read_text().splitlines()
    # Points finish in any order on 2 jobs: compare them by id.
    key = lambda line: re.search(r'"point_id":"([^"]*)"', line)[1]
    check("sweep(): records.jsonl as the command's",
          sorted(map(masked_line, mine), key=key) == sorted(map(masked_line, lines), key=key))
    check("records as objects", len(r.records) == len(mine) == r.points and
          [x.to_dict() for x in r.records] == [json.loads(l) for l in mine])
    df = r.to_pandas()
    check(f"to_pandas: a row per point ({len(df)})", len(df) == r.points and "metrics.tilt_rms_error" in df)
    import matplotlib

    matplotlib.use("Agg")
    ax = r.plot("tilt_rms_error")
    check("plot(): the work-precision figure, a line per setup", len(ax.get_lines()) == 1)
    again = tippe.sweep(sweep, out=str(tmp / "py"), progress=False)
    check("a rerun resumes", again.ran == 0 and again.skipped == r.points)
    # A dict with a sweep file's keys, scenes relative to the current directory.
    import tomllib

    d = tomllib.loads(Path(sweep).read_text())
    d["scenes"] = [{"file": str(src / "harness/scenes/toy_viscous.toml"), "duration": 4.6}]
    rd = tippe.sweep(d, out=str(tmp / "dict"), progress=False)
    check("sweep(dict) == sweep(file)", sorted(x.point_id for x in rd.records) == sorted(x.point_id for x in r.records))


def test_gate(exe, src, tmp):
    gate = str(src / "harness/gates/examples/failing.toml")
    cli(exe, "gate", gate, "--no-cache", "--json", str(tmp / "g.json"), expect=1)
    g = tippe.gate(gate, cache=None, progress=False)
    same_text("gate(): the --json record", g.json, (tmp / "g.json").read_text())
    check("a failing gate is falsy", not g and g.passed is False)
    check("the results' fields", [c.name for c in g.results] == ["ode-inversion-tight", "ode-energy"])


def test_engines(exe, src, tmp):
    version = cli(exe, "--version").stdout.split("\n")
    listed = [l.strip().split(":")[0] for l in version[1:] if l.strip()]
    e = tippe.engines()
    check(f"engines() names {[x.name for x in e]} == tippe --version's {listed}", [x.name for x in e] == listed)
    check("__version__", version[0].startswith(f"tippe {tippe.__version__} "))
    import tomllib

    project = tomllib.loads((src / "pyproject.toml").read_text())["project"]
    check(f"pyproject.toml's version {project['version']} == __version__", project["version"] == tippe.__version__)
    ode = next(x for x in e if x.name == "ode")
    ts = next(s for s in ode.settings if s.key == "timestep")
    check(f"a setting's default and bounds: {ts.to_dict()}", ts.type == "number" and ts.default > 0 and
          len(ts.bounds) == 2 and ts.bounds[0] <= ts.default <= ts.bounds[1])


def test_examples(exe, src, tmp):
    env = dict(os.environ, MPLBACKEND="Agg")
    for script in sorted((src / "examples/python").glob("*.py")):
        t0 = time.monotonic()
        p = subprocess.run([sys.executable, str(script)], cwd=tmp, capture_output=True, text=True, env=env,
                           timeout=120)
        check(f"{script.name} runs: {p.stderr[-500:]}", p.returncode == 0)
        print(f"{script.name}: {time.monotonic() - t0:.1f} s")


def main():
    verb, exe, src = sys.argv[1], sys.argv[2], Path(sys.argv[3])
    with tempfile.TemporaryDirectory() as tmp:
        globals()["test_" + verb](exe, src, Path(tmp))
    if failures:
        print("FAILED:\n  " + "\n  ".join(failures))
        return 1
    print(f"tippe {tippe.__version__}: {verb} matches the command line")
    return 0


if __name__ == "__main__":
    sys.exit(main())
