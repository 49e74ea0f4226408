#!/usr/bin/env python3
"""Checks that the consumer project (tests/consumer, built on the installed tree) reproduces `tippe run`'s summary.json: every field the consumer prints from the summary's field list."""
import json
import math
import subprocess
import sys
import tempfile
from pathlib import Path

# Fields that differ between two runs of the same scene by nature: timings and when/where it ran.
VOLATILE = {"work.wall_seconds", "work.cpu_seconds", "provenance.date", "provenance.hostname"}
# The summary.json fields the library's RunSummary leaves to its JSON text (include/tippe/tippe.h).
ONLY_IN_JSON = {"scene_spec"}


def flatten(value, prefix, out):
    """summary.json as the consumer prints it: "KEY VALUE", a part's fields as "PART.KEY"."""
    if isinstance(value, dict):
        for k, v in value.items():
            flatten(v, f"{prefix}.{k}" if prefix else k, out)
    elif isinstance(value, list) and prefix == "events":
        out[prefix] = str(len(value))
    elif isinstance(value, list):
        out[prefix] = str(len(value))
        for i, v in enumerate(value):
            flatten(v, f"{prefix}.{i}", out)
    else:
        out[prefix] = value


def main():
    tippe, consumer, scene = sys.argv[1:4]
    with tempfile.TemporaryDirectory() as tmp:
        out = Path(tmp) / "cli"
        subprocess.run([tippe, "run", scene, "--out", str(out)], check=True, stdout=subprocess.DEVNULL,
                       stderr=subprocess.DEVNULL)
        cli = json.loads((out / "summary.json").read_text())
    lines = subprocess.run([consumer, scene], check=True, capture_output=True, text=True).stdout.splitlines()
    fields = {}
    events = []
    for line in lines:
        key, _, value = line.partition(" ")
        if key == "event":
            name, time = value.split(" ")
            events.append((name, float(time)))
        else:
            fields[key] = value
    want = {}
    flatten({k: v for k, v in cli.items() if k not in ONLY_IN_JSON}, "", want)
    failures = []

    def same(key, got, want):
        # Both come from the same code on the same build: equal to the last bit, or it is a finding.
        if got != want and not (isinstance(want, float) and math.isnan(want) and math.isnan(got)):
            failures.append(f"{key}: consumer {got!r}, tippe run {want!r}")

    for key in sorted(set(want) | set(fields)):
        if key not in fields or key not in want:
            failures.append(f"{key}: {'only in summary.json' if key in want else 'only in the consumer'}")
            continue
        if key in VOLATILE:
            continue
        w, g = want[key], fields[key]
        if w is None:  # JSON null: an absent value ("null") or a number the record has none for (NaN)
            if g not in ("null", "nan"):
                failures.append(f"{key}: consumer {g!r}, tippe run null")
        elif isinstance(w, bool):
            same(key, g, "true" if w else "false")
        elif isinstance(w, int):
            same(key, int(g), w)
        elif isinstance(w, float):
            same(key, float(g), w)
        else:
            same(key, g, w)
    same("event list", events, [(e["name"], e["time"]) for e in cli["events"]])
    if failures:
        print("the consumer's result differs from tippe run's:\n  " + "\n  ".join(failures))
        return 1
    print(f"consumer matches tippe run on {scene}: {len(fields)} fields, {len(events)} events, "
          f"final_tilt {cli['final_tilt']}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
