#!/usr/bin/env python3
"""Validates every record the commands write (tippe run, compare, sweep, gate on small inputs) and the published ones against schemas/."""
import json
import subprocess
import sys
from pathlib import Path

try:
    import jsonschema
except ImportError:
    sys.exit("validate_records: python3-jsonschema is missing (scripts/install-deps.sh installs it)")

# Short runs of the toy top (0.3 s: it slips, then rolls) keep every command under a second.
SWEEP = """description = "records against schemas"
repeats = 1
scenes = [ {{ file = {scene}, duration = 0.3 }} ]
[[setup]]
name = "reference"
engine = "analytic"
ladder.key = "engines.analytic.rtol"
ladder.values = [1e-6, 1e-8]
[[setup]]
name = "ode"
engine = "ode"
ladder.key = "engines.ode.timestep"
ladder.values = [1e-3]
"""
# One check passes and one fails (an energy error of 1e-12 is beyond any engine), so both kinds of result appear.
GATE = """[defaults]
scene = {scene}
engine = "ode"
duration = 0.3
[[check]]
name = "ode-passes"
[check.max]
tilt_rms_error = 1.0
[[check]]
name = "ode-fails"
[check.max]
energy_max_error = 1e-12
"""


def load_schemas(schema_dir):
    schemas = {p.name: json.loads(p.read_text()) for p in schema_dir.glob("*.schema.json")}
    for name, schema in schemas.items():
        jsonschema.Draft202012Validator.check_schema(schema)
    base = schema_dir.resolve().as_uri() + "/"
    store = {base + name: schema for name, schema in schemas.items()}

    def validator(name):
        resolver = jsonschema.RefResolver(base_uri=base + name, referrer=schemas[name], store=store)
        return jsonschema.Draft202012Validator(schemas[name], resolver=resolver)

    return validator


def edited(record, path, value):
    """A copy of the record with the field at `path` (keys) set to `value`, or removed when it is DROP."""
    copy = json.loads(json.dumps(record))
    *outer, last = path
    target = copy
    for key in outer:
        target = target[key]
    if value is DROP:
        del target[last]
    else:
        target[last] = value
    return copy


DROP = object()
# Edits of a written record and whether the schema must still take it: for the sweep record,
# what its reader (sweep_record.cpp) takes (a record without a reference, or from before classes,
# searches and labels) and refuses; for the gate result, what the command never writes.
SWEEP_RECORD_EDITS = [
    (("reference",), None, True), (("reference",), DROP, True), (("class",), DROP, True),
    (("search",), DROP, True), (("ladder_label",), DROP, True), (("grid",), DROP, True), (("duration",), None, True),
    (("status",), "exploded", False), (("class", "name"), "fine", False), (("reference", "class"), "fine", False),
    (("scene",), "a/b", False), (("setup",), "..", False), (("ladder_key",), "a key", False),
    (("repeats",), 0, False), (("repeats",), 101, False), (("scene_index",), -1, False),
    (("scene_index",), 100000, False), (("work", "steps"), -1, False), (("work", "cpu_seconds_repeats"), [1.0] * 101, False),
    (("search",), {"criterion": "regime", "from": 1, "to": 10, "resolution": 0.1, "per_decade": 21}, False),
    (("search",), {"criterion": "regime", "from": None, "to": 10, "resolution": 0.1, "per_decade": 2}, False),
    (("search",), {"criterion": "regime", "from": 1, "to": 10, "resolution": 0.1, "per_decade": 2}, True),
    (("reference", "steps"), 1.5, False), (("metrics",), None, False), (("format",), "tippe-sweep-record-2", False),
]
GATE_RESULT_EDITS = [
    (("checks",), -1, False), (("results", 0, "rows", 0, "kind"), "bogus", False), (("gate_file",), DROP, False),
    (("results", 0, "seconds"), None, True),
]


def edited_records(validator, work):
    """Failures of the schemas on edited copies of the first sweep record and of the gate result."""
    failures = []
    sweep_record = json.loads((work / "sweep" / "records.jsonl").read_text().splitlines()[0])
    gate_result = json.loads((work / "gate.json").read_text())
    for schema, record, edits, takes, refuses in (
            ("sweep-record.schema.json", sweep_record, SWEEP_RECORD_EDITS, "its reader takes it", "its reader refuses it"),
            ("gate-result.schema.json", gate_result, GATE_RESULT_EDITS, "the command writes it", "the command never writes it")):
        for path, value, valid in edits:
            errors = list(validator(schema).iter_errors(edited(record, path, value)))
            shown = "dropped" if value is DROP else json.dumps(value)[:40]
            if valid and errors:
                failures.append(f"{schema}: {'/'.join(map(str, path))} {shown}: refused, but {takes}: {errors[0].message[:120]}")
            if not valid and not errors:
                failures.append(f"{schema}: {'/'.join(map(str, path))} {shown}: taken, but {refuses}")
    return failures


def run(cmd, ok=(0,)):
    p = subprocess.run(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
    if p.returncode not in ok:
        sys.exit(f"validate_records: {' '.join(map(str, cmd))} exited {p.returncode}:\n{p.stderr}")


def main():
    tippe, source, work = sys.argv[1], Path(sys.argv[2]).resolve(), Path(sys.argv[3])
    validator = load_schemas(source / "schemas")
    scene = source / "harness" / "scenes" / "toy.toml"
    if work.exists():
        subprocess.run(["rm", "-rf", str(work)], check=True)
    work.mkdir(parents=True)
    # json.dumps writes a TOML basic string for any path (the same escapes).
    (work / "sweep.toml").write_text(SWEEP.format(scene=json.dumps(str(scene))))
    (work / "gate.toml").write_text(GATE.format(scene=json.dumps(str(scene))))
    run([tippe, "run", scene, "--set", "run.duration=0.3", "--out", work / "run"])
    run([tippe, "compare", scene, "--set", "run.duration=0.3", "--out", work / "compare", "--no-plots", "--no-cache"])
    run([tippe, "sweep", work / "sweep.toml", "--out", work / "sweep", "--no-plots"])
    run([tippe, "gate", work / "gate.toml", "--json", work / "gate.json", "--no-cache", "--no-self-check"], ok=(1,))

    # (schema, file, one record per line)
    produced = [("run-summary.schema.json", work / "run" / "summary.json", False),
                ("comparison.schema.json", work / "compare" / "comparison.json", False),
                ("sweep-record.schema.json", work / "sweep" / "records.jsonl", True),
                ("sweep.schema.json", work / "sweep" / "sweep.json", False),
                ("gate-result.schema.json", work / "gate.json", False)]
    produced += [("run-summary.schema.json", p, False) for p in sorted((work / "sweep").glob("reference/*/summary.json"))]
    published = [("comparison.schema.json", p, False) for p in sorted(source.glob("reports/*/comparison.json"))]
    published += [("sweep-record.schema.json", p, True) for p in sorted(source.glob("reports/sweep-*/records.jsonl"))]
    published += [("sweep.schema.json", p, False) for p in sorted(source.glob("reports/sweep-*/sweep.json"))]

    failures, counts = [], {}
    for schema, path, lines in produced + published:
        if not path.exists():
            failures.append(f"{path}: not written")
            continue
        text = path.read_text()
        records = [json.loads(line) for line in text.splitlines() if line.strip()] if lines else [json.loads(text)]
        if not records:
            failures.append(f"{path}: no record")
        for n, record in enumerate(records, 1):
            for error in validator(schema).iter_errors(record):
                where = "/".join(map(str, error.absolute_path)) or "(top)"
                failures.append(f"{path}{':' + str(n) if lines else ''}: {where}: {error.message[:200]}")
        counts[schema] = counts.get(schema, 0) + len(records)
    failures += edited_records(validator, work)
    if failures:
        print(f"{len(failures)} schema violations:\n  " + "\n  ".join(failures[:50]))
        return 1
    print("every record matches its schema: " + ", ".join(f"{n} against {s}" for s, n in sorted(counts.items())))
    return 0


if __name__ == "__main__":
    sys.exit(main())
