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
    if failures:
        print(f"{len(failures)} schema violations:\n  " + "\n  ".join(failures[:50]))
        return 1
    print("every record matches its schema: " + ", ".join(f"{n} against {s}" for s, n in sorted(counts.items())))
    return 0


if __name__ == "__main__":
    sys.exit(main())
