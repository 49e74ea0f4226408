#!/usr/bin/env python3
"""Checks that the consumer project (tests/consumer, built on the installed tree) reproduces `tippe run`'s summary.json."""
import json
import math
import subprocess
import sys
import tempfile
from pathlib import Path


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
    failures = []

    def same(key, got, want):
        # Both come from the same code on the same build: equal to the last bit, or it is a finding.
        if got != want and not (isinstance(want, float) and math.isnan(want) and math.isnan(got)):
            failures.append(f"{key}: consumer {got!r}, tippe run {want!r}")

    same("scene", fields.get("scene"), cli["scene"])
    same("status", fields.get("status"), cli["status"])
    same("samples", int(fields["samples"]), cli["samples"])
    same("inversion_time", float(fields["inversion_time"]) if "inversion_time" in fields else None,
         cli["inversion_time"])
    for key in ["final_time", "final_tilt", "energy_initial", "energy_final", "jellett_initial", "min_normal_force"]:
        same(key, float(fields[key]), cli[key])
    same("mass", float(fields["mass"]), cli["mass_properties"]["mass"])
    same("events", int(fields["events"]), len(cli["events"]))
    same("event list", events, [(e["name"], e["time"]) for e in cli["events"]])
    if failures:
        print("the consumer's result differs from tippe run's:\n  " + "\n  ".join(failures))
        return 1
    print(f"consumer matches tippe run on {scene}: {len(fields)} fields, {len(events)} events, "
          f"final_tilt {cli['final_tilt']}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
